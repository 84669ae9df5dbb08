import math

import numpy as np
import pytest

import motorbus

from motorbus import motion
from motorbus.drives import arcus, dmac, pmc007, unitek


def test_plan_trapezoid_and_sample():
    p = motion.plan(1000, max_velocity=100, max_acceleration=1000)
    assert p.duration == pytest.approx(10.1, abs=1e-12)
    s = motion.sample(p, 11)
    assert s["t"].shape == (11,)
    assert s["p"][-1] == 1000.0
    assert s["v"][5] == pytest.approx(100.0)
    assert p.at(0.05) == pytest.approx((1.25, 50.0, 1000.0, 0.0))


def test_plan_jerk_limited_continuous():
    p = motion.plan(5.0, v0=0.5, max_velocity=2, max_acceleration=4, max_jerk=20)
    s = motion.sample(p, 2001)
    assert s["p"][-1] == 5.0
    assert np.abs(s["v"]).max() <= 2 + 1e-12
    assert np.abs(s["a"]).max() <= 4 + 1e-12
    assert np.abs(np.diff(s["a"])).max() < 20 * p.duration / 2000 * 1.01  # acceleration continuous


def test_step_times_numpy():
    p = motion.plan(1000, max_velocity=500, max_acceleration=5000)
    t, d = motion.step_times(p, t0_ns=10)
    assert t.dtype == np.int64 and d.dtype == np.int8
    assert len(t) == 1000 and (d == 1).all()
    assert (np.diff(t) > 0).all()
    assert t[0] > 10


def test_limit_exceeded_names_limit():
    with pytest.raises(motion.LimitExceeded) as e:
        motion.plan_velocity(motion.MotionState(), 150, motion.Limits(100, 1000))
    assert e.value.limit == "max_velocity"
    assert e.value.excess == pytest.approx(50)
    assert isinstance(e.value, ValueError)


def test_arcus_appendix_a_examples():
    assert arcus.arcus_max_acc_ms(20000, 100) == pytest.approx(19900)
    assert arcus.arcus_window_for_hspd(900000).number == 7
    assert arcus.arcus_max_acc_ms(900000, 1000) == pytest.approx(23050, abs=2)
    params, window, notes = arcus.arcus_effective(arcus.ArcusProfileParams(hspd=1000, lspd=5, acc_ms=0.5))
    assert (params.lspd, params.acc_ms, window) == (10, 2, 1)
    assert len(notes) == 2


def test_arcus_motion_on_the_fly():
    a = arcus.ArcusMotion(arcus.ArcusProfileParams(hspd=1000, lspd=100, acc_ms=100))
    assert a.move(0, 10000) == ""
    assert a.move(0, 300000) == "?Index out of Range"
    a.move(0, 10000)
    assert a.change_target(5.0, 1000) == ""
    assert a.profile.end_position == 1000
    assert a.change_speed(1.0, 20000) in ("?Speed out of range", "")
    idle = arcus.ArcusMotion()
    assert idle.change_target(0.0, 5) == "?Motor is not moving"


def test_dmac_half_second_example():
    p = dmac.DmacProfileParams(high_speed=60000, accel_time_ms=1000)
    assert dmac.dmac_ramp_time(p, 0, 30000) == pytest.approx(0.5)
    d = dmac.DmacMotion(p)
    d.move_to(0.0, 100000)
    assert d.profile.end_position == 100000
    with pytest.raises(motion.LimitExceeded):
        dmac.DmacProfileParams(high_speed=500000)


def test_dmac_interpolation_sums_reach_targets():
    lim = [motion.Limits(5000, 20000)] * 3
    segs = dmac.dmac_interpolation([0, 0, 0], [10000, -3333, 7], lim, period_ms=50)
    assert segs.shape[1] == 3
    assert segs.sum(axis=0).tolist() == [10000, -3333, 7]
    with pytest.raises(motion.LimitExceeded) as e:
        dmac.dmac_interpolation([0], [10], lim[:1], period_ms=1)
    assert (e.value.limit, e.value.requested, e.value.allowed) == ("#INTERPOL_TIME", 1, 2)
    with pytest.raises(motion.LimitExceeded, match=r"#INTERPOL_TIME: requested 139 is outside 2\.\.138"):
        dmac.dmac_interpolation([0], [10], lim[:1], period_ms=139)
    # the generic splitter takes any period from 1 ms: the 2..138 ms range is the DMAC's
    one = motion.plan_synchronized([0], [10], lim[:1])
    assert sum(s[0] for s in motion.split_interpolation(one, 1)) == 10
    with pytest.raises(motion.LimitExceeded):
        motion.split_interpolation(one, 0)


def test_synchronized_axes_finish_together():
    lim = [motion.Limits(100, 1000), motion.Limits(50, 200)]
    ps = motion.plan_synchronized([0, 0], [1000, 10], lim)
    assert ps[0].duration == pytest.approx(ps[1].duration, abs=1e-12)
    assert [p.end_position for p in ps] == [1000, 10]


def test_stepnloop_from_python():
    s = motion.StepNLoop()
    with pytest.raises(motorbus.InvalidArgument):
        s.begin("teleport")
    assert s.begin("move")
    assert s.begin(motion.SnlActivity.MOVE)
    assert s.status == 1
    action, corr, idle = s.motion_done(300)
    assert (action, corr, idle) == (2, 300.0, False)
    assert s.status_name == "CORRECTING"


def test_pmc007_cia402_unitek_models():
    assert pmc007.pmc007_gear_acceleration(1) == 77440
    p = pmc007.pmc007_position_profile(motion.MotionState(), 20000,
                                       pmc007.Pmc007ProfileParams(speed=5610, accel_gear=8, decel_gear=8))
    assert p.end_position == 20000
    c = motion.Cia402ProfilePosition(motion.Cia402ProfileParams(1000, 10000, 10000))
    assert c.new_setpoint(0.0, 5000)
    assert c.new_setpoint(1.0, 0)
    assert not c.new_setpoint(1.5, 7)
    assert c.profile.end_position == 0
    u = unitek.unitek_speed_profile(motion.MotionState(), 3277, unitek.UnitekRampParams(3000, 1000, 500), 1.0)
    assert u.final_velocity == pytest.approx(3277 / 32767 * 3000 / 60 * 65536)
    with pytest.raises(motion.LimitExceeded):
        motion.Cia402ProfileParams(motion_profile_type=5)


def test_motor_model_and_homing_on_sim_clock():
    from motorbus._core.runtime import SimClock

    clk = SimClock()
    cfg = motion.MotorConfig()
    cfg.home = motion.SwitchConfig(True, 5000, 5400)
    cfg.plus_limit = motion.SwitchConfig(True, 20000)
    m = motion.MotorModel(clk, cfg)
    events = []
    m.add_listener(events.append)
    h = arcus.ArcusHoming(m, arcus.ArcusProfileParams(hspd=3200, lspd=100, acc_ms=100),
                           arcus.ArcusHomingOptions(rz=True))
    h.start("H", 1)
    for _ in range(1000):
        if not h.running:
            break
        clk.advance(10_000_000)
        m.update()
    assert h.result == 1  # Done
    assert m.pulse_count == 0
    assert m.physical_position == pytest.approx(5000, abs=1e-3)
    kinds = [e.kind for e in events]
    assert motion.MotorEventKind.HOME_ON in kinds
    home = events[kinds.index(motion.MotorEventKind.HOME_ON)]
    assert home.t_ns > 0 and home.direction == 1
    assert m.encoder == round(5000 * 4000 / 3200)
    with pytest.raises(ValueError):
        h.start("X", 1)


def test_shapes_and_arrays_for_plotting():
    t = motion.plan(1000, max_velocity=100, max_acceleration=1000)
    s = motion.plan(1000, max_velocity=100, max_acceleration=1000, shape="s_curve")
    q = motion.plan(1000, max_velocity=100, max_acceleration=1000, shape="sin2")
    assert t.duration == pytest.approx(s.duration) == pytest.approx(q.duration)
    a = motion.sample(q, 1001)["a"]
    assert a.max() == pytest.approx(2000, rel=1e-3)  # same ramp time: peak = 2x average
    with pytest.raises(ValueError):
        motion.plan(1, max_velocity=1, max_acceleration=1, shape="square")
    arc = arcus.ArcusMotion(arcus.ArcusProfileParams(hspd=1000, lspd=100, acc_ms=100))
    arc.move(0, 5000)
    arr = motion.sample(arc.profile, 200)
    assert arr["v"][1] >= 100  # starts from LSPD
    assert arr["p"][-1] == 5000

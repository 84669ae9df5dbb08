"""ArcusClient against the simulator on a pty, on simulated time."""
from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

import motorbus
import motorbus._core as core
from motorbus.drives.arcus import (ArcusClient, LatchStatus, MotorStatus, SnlStatus, SyncCondition, SyncStatus,
                                   make_sim, open_line)

S = 1_000_000_000  # ns


class Rig:
    def __init__(self, *sims, clock):
        self.clock = clock
        self.sims = sims
        self.server = core.serial.PtyLineServer(list(sims), 0, None)
        self.link = open_line(self.server.slave_path, baud=0, timeout=0.2)

    def client(self, address=1, **kw):
        return ArcusClient(self.link, address, **kw)

    def run(self, seconds):
        self.clock.advance(int(seconds * S))

    def close(self):
        self.link.port.close()
        self.server.close()


@pytest.fixture
def rig():
    clock = core.runtime.SimClock()
    r = Rig(make_sim("01", clock=clock), clock=clock)
    yield r
    r.close()


def test_factory_defaults(rig):
    d = rig.client()
    assert (d.idle_current, d.run_current, d.idle_time) == (1000, 1600, 500)
    assert d.device_name == "DMC01"
    assert d.snl_enabled and d.snl_tolerance == 20 and d.snl_error_range == 1000
    assert d.snl_max_attempts == 10 and d.snl_idle_tolerance == 5
    assert d.outputs_at_boot == 7 and d.alarm_outputs and not d.enabled_at_boot
    assert (d.limit_correction, d.node_id, d.polarity, d.response_type) == (1000, 1, 0, 0)
    assert (d.baud_code, d.can_bit_rate_code, d.comm_mode) == (1, 5, 0)
    assert d.status == MotorStatus(0)
    assert d.snl_status is SnlStatus.IDLE


def test_trapezoid_move_positions_and_times(rig):
    d = rig.client()
    d.snl_enabled = False
    d.enable()
    d.acceleration = 100
    d.move(1000)
    rig.run(0.05)
    assert d.status == MotorStatus.ACCELERATING
    rig.run(0.45)
    assert d.status == MotorStatus.CONSTANT_SPEED
    assert abs(d.position - 455) <= 2
    rig.run(0.6)
    assert not d.status.moving
    assert (d.position, d.encoder) == (1000, 1250)


def test_stepnloop_move_in_counts(rig):
    d = rig.client()
    d.enable()
    d.move(4000)
    rig.run(0.1)
    assert d.snl_status is SnlStatus.MOVING
    rig.run(6)
    assert (d.encoder, d.position, d.delta) == (4000, 4000, 0)
    assert rig.sims[0].physical_position == pytest.approx(3200)


def test_moving_and_state_errors_are_typed(rig):
    d = rig.client()
    d.snl_enabled = False
    d.enable()
    d.jog(1)
    with pytest.raises(motorbus._core.ArcusMoving) as e:
        d.move(10)
    assert e.value.reply == "?Moving" and e.value.code == "Moving"
    assert isinstance(e.value, motorbus.DriveFault)
    with pytest.raises(motorbus._core.ArcusMotorNotMoving):
        d.change_target(5)
    d.abort()
    rig.sims[0].force_limit(-1, True)
    d.jog(-1)
    rig.run(0.01)
    assert d.status & MotorStatus.MINUS_LIMIT_ERROR
    with pytest.raises(motorbus._core.ArcusStateError):
        d.jog(-1)
    d.clear()
    assert d.status == MotorStatus.MINUS_LIMIT
    with pytest.raises(motorbus._core.ArcusIndexOutOfRange):
        d.command("DI7")
    with pytest.raises(motorbus._core.ArcusUnknownCommand):
        d.command("FOO")


def test_on_the_fly_target_and_speed(rig):
    d = rig.client()
    d.snl_enabled = False
    d.enable()
    d.move(10000)
    rig.run(1)
    d.change_target(2500)
    rig.run(10)
    assert d.position == 2500
    d.jog(1)
    rig.run(1)
    d.change_speed(3000)
    rig.run(1)
    assert d.speed == 3000
    with pytest.raises(motorbus._core.ArcusSpeedOutOfRange):
        d.change_speed(50000)
    d.stop()
    rig.run(1)
    assert not d.moving


def test_homing_routines(rig):
    d = rig.client()
    d.snl_enabled = False
    d.enable()
    d.home_correction = 200
    d.home("HL", 1)
    rig.run(30)
    assert (d.position, d.encoder) == (0, 0)
    assert rig.sims[0].physical_position == pytest.approx(8000, abs=0.5)
    d.move(1000)  # off the index (8000 = 1600 + 2 x 3200 is one)
    rig.run(3)
    d.home("Z", 1)
    rig.run(40)
    assert d.position == 0
    assert rig.sims[0].physical_position == pytest.approx(11200, abs=0.01)
    with pytest.raises(motorbus.InvalidArgument):
        d.home("Q", 1)


def test_latch_sync_and_io(rig):
    d = rig.client()
    sim = rig.sims[0]
    d.snl_enabled = False
    d.enable()
    d.enable_latch()
    assert d.latch_status is LatchStatus.WAITING
    d.sync_position = 600
    d.sync_condition = SyncCondition.GREATER
    d.sync_on()
    assert d.sync_status is SyncStatus.WAITING
    d.move(1000)
    rig.run(0.6)
    px = sim.pulse_position
    sim.set_input(2, True)
    rig.run(2)
    assert d.latch_status is LatchStatus.TRIGGERED
    assert d.latched_position == px
    assert d.sync_status is SyncStatus.OCCURRED and d.digital_output(2)
    assert d.sync_condition is SyncCondition.GREATER
    assert d.digital_inputs == 0b10 and d.digital_input(2)


def test_currents_after_curt(rig):
    d = rig.client()
    d.snl_enabled = False
    d.enable()
    rig.run(1)
    assert d.current == 1000
    d.jog(1)
    assert d.current == 1600
    d.abort()
    rig.run(0.4)
    assert d.current == 1600
    rig.run(0.2)
    assert d.current == 1000


def test_store_persists_and_power_cycle_applies(tmp_path):
    clock = core.runtime.SimClock()
    store = tmp_path / "dmx.flash"
    sim = make_sim("01", clock=clock, store_path=str(store))
    r = Rig(sim, clock=clock)
    try:
        d = r.client()
        d.set_device_name(7)
        d.response_type = 1
        d.idle_current = 500
        d.store()
        sim.power_cycle()
        assert sim.address == 7
        d7 = r.client(7)
        assert d7.idle_current == 500  # RT=1 replies "#07500" are accepted
        assert "DN=7" in store.read_text()
    finally:
        r.close()


def test_rs485_line_with_several_devices():
    clock = core.runtime.SimClock()
    sims = [make_sim(f"{a:02d}", clock=clock, snl=False, eo_boot=True) for a in (1, 2, 42, 99)]
    r = Rig(*sims, clock=clock)
    try:
        clients = {a: r.client(a) for a in (1, 2, 42, 99)}
        for a, c in clients.items():
            c.set_position(a * 10)
        assert [c.position for c in clients.values()] == [10, 20, 420, 990]
        clients[1].broadcast_command("J-")
        r.run(0.5)
        assert all(c.moving for c in clients.values())
        clients[42].abort()
        assert not clients[42].moving and clients[99].moving
        clients[1].broadcast_command("ABORT")
        assert not any(c.moving for c in clients.values())
        with pytest.raises(motorbus.TimeoutError):
            ArcusClient(r.link, 5, query_retries=0).position
    finally:
        r.close()


def test_context_manager_aborts_on_exception(rig):
    d = rig.client()
    d.snl_enabled = False
    d.enable()
    with pytest.raises(RuntimeError):
        with rig.client(on_error="quick_stop") as c:
            c.jog(1)
            rig.run(0.5)
            assert c.moving
            raise RuntimeError("boom")
    assert not d.moving  # ABORT was sent on the way out
    with rig.client() as c:  # a clean exit leaves the motor alone
        c.jog(1)
    assert d.moving
    d.abort()


def test_on_error_words_stop_and_disable(rig):
    d = rig.client()
    d.snl_enabled = False
    d.enable()
    with pytest.raises(RuntimeError):
        with rig.client() as c:  # default on_error="stop": STOP, decelerating
            c.jog(1)
            rig.run(0.5)
            raise RuntimeError("boom")
    assert d.moving and d.status & MotorStatus.DECELERATING
    rig.run(1)
    assert not d.moving
    with pytest.raises(RuntimeError):
        with rig.client(on_error="disable") as c:  # EO=0: the pulses stop, the power is off
            c.jog(1)
            rig.run(0.5)
            raise RuntimeError("boom")
    assert not d.moving and not d.enabled
    for bad in ("abort", "halt", 1):
        with pytest.raises(motorbus.InvalidArgument):
            rig.client(on_error=bad)
        with pytest.raises(motorbus.InvalidArgument):
            rig.client(on_exit=bad)


def test_motor_stopped_at_process_exit(tmp_path):
    """A script that exits while jogging: atexit sends STOP."""
    script = textwrap.dedent(
        """
        import atexit, time
        state = {}
        def report():
            time.sleep(0.6)   # STOP decelerates over ACC = 300 ms
            print("BUSY" if state["sim"].busy else "STOPPED", flush=True)
        atexit.register(report)  # registered before the arcus module: runs after its handler (LIFO)
        import motorbus._core as core
        from motorbus.drives.arcus import ArcusClient, make_sim
        sim = state["sim"] = make_sim("01", snl=False, eo_boot=True)
        server = core.serial.PtyLineServer([sim], 0, None)
        c = ArcusClient(server.slave_path, 1, baud=0)
        c.jog(1)
        assert c.moving
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60,
                         env={"PYTHONPATH": str(__import__("pathlib").Path(motorbus.__file__).parents[1])})
    assert "STOPPED" in out.stdout, out.stderr


def test_make_sim_arguments():
    assert make_sim("DMC05").address == 5
    assert make_sim(12).address == 12
    for bad in ("00", "100", "ab", ""):
        with pytest.raises(motorbus.InvalidArgument):
            make_sim(bad)
    with pytest.raises(motorbus.InvalidArgument):
        make_sim("01", nonsense=1)
    sim = make_sim("03", response_type=1)
    assert sim.on_line(b"@03EX") == b"#030\0"


def test_real_time_sim_and_wait_idle():
    """The default (real-time) simulator, as `motorbus sim serve` runs it."""
    sim = make_sim("01", snl=False, eo_boot=True)
    with core.serial.PtyLineServer([sim], 0, None) as server:
        with ArcusClient(server.slave_path, 1, baud=0) as d:
            d.high_speed = 100000
            d.low_speed = 1000
            d.acceleration = 10
            d.move(2000)  # about 30 ms
            d.wait_idle(timeout=5)
            assert d.position == 2000
            assert d.encoder == 2500
            with pytest.raises(motorbus.TimeoutError):
                d.jog(1)
                d.wait_idle(timeout=0.05)
            d.abort()
            assert not d.moving


def test_typed_records_and_phase_enum():
    from motorbus.drives.arcus import ArcusCommandInfo, ArcusMotion, ArcusPhase, ArcusProfileParams

    rows = {c.name: c for c in core.arcus.commands()}
    assert isinstance(rows["HSPD"], ArcusCommandInfo)
    assert rows["HSPD"].query and rows["HSPD"].set and not rows["HSPD"].action
    assert rows["DI"].indexed == 6
    a = ArcusMotion(ArcusProfileParams(hspd=1000, lspd=100, acc_ms=100, dec_ms=100))
    assert a.phase(0.0) == ArcusPhase.IDLE
    a.move(0, 1000)
    assert [a.phase(t) for t in (0.05, 0.5, a.profile.duration - 0.05)] == [
        ArcusPhase.ACCEL, ArcusPhase.CONST, ArcusPhase.DECEL]
    assert a.phase(a.profile.duration + 1) == ArcusPhase.IDLE

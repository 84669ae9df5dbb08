"""ArcusDrive (motorbus.Drive over ArcusClient) and its plugin, against the
simulator served on a pty in real time."""
from __future__ import annotations

import asyncio
import os
import time

import pytest

import motorbus
import motorbus._core as core
from motorbus import aio
from motorbus import drive as mdrive
from motorbus import registry
from motorbus.drives import arcus
from motorbus.drives.arcus import (ArcusDrive, ArcusHomingError, ArcusMotorDisabled, MotorStatus, SnlStatus,
                                   make_sim, open_line)

MM = mdrive.Units("mm", 0.01)  # 100 counts per mm


class Served:
    def __init__(self, **options):
        options.setdefault("eo_boot", True)
        self.sim = make_sim("01", **options)
        self.server = core.serial.PtyLineServer([self.sim], 0, None)
        self.path = self.server.slave_path

    def open(self, **kw):
        kw.setdefault("units", MM)
        kw.setdefault("line", self.path)
        d = motorbus.open_drive("arcus", address="01", **kw)
        # Short, brisk moves: well under a second of real time.
        d.params["HSPD"] = 20000
        d.params["ACC"] = 20
        return d

    def close(self):
        self.server.close()


@pytest.fixture
def served():
    s = Served(home=(400, 800))
    yield s
    s.close()


def test_plugin_descriptor():
    p = registry.drive_plugin("arcus")
    assert p is arcus.ArcusDrive
    assert (p.kind, p.transport, p.default_address, p.default_baud) == ("arcus", "serial", "01", 9600)
    assert p.line_settings == arcus.LINE_SETTINGS
    assert set(p.sim_options) >= {"eo_boot", "snl", "home", "plus_limit", "store_path"}
    assert p.store_options("/tmp/st", "05") == {"store_path": os.path.join("/tmp/st", "arcus-05.store")}
    assert (p.check_address("1"), p.check_address("01"), p.check_address("DMC07")) == ("01", "01", "07")
    for bad in ("00", "100", "x", ""):
        with pytest.raises(motorbus.InvalidArgument):
            p.check_address(bad)
    with pytest.raises(motorbus.InvalidArgument, match="known"):
        p.make_sim("01", colour="red")


def test_move_in_user_units_reads_back_within_one_count(served):
    with served.open() as d:
        assert d.kind == "arcus" and not d.has_watchdog
        assert mdrive.Capability.HOMING in d.capabilities and mdrive.Capability.WATCHDOG not in d.capabilities
        d.enable()
        d.move_to(12.34)                      # 1234 encoder counts (StepNLoop on)
        assert abs(d.position - 12.34) <= 0.01
        assert served.sim.encoder_position == 1234
        st = d.status
        assert st.enabled and not st.moving and st.at_target and not st.fault
        assert st.raw == (MotorStatus(0), SnlStatus.IDLE)
        d.move_by(-2.34)
        assert abs(d.position - 10.0) <= 0.01


def test_velocity_of_a_move_is_for_that_move_only(served):
    with served.open() as d:
        d.enable()
        d.move_to(5, velocity=150.0)          # 15000 counts/s for this move
        assert abs(d.position - 5) <= 0.2     # within SLT (20 counts)
        assert d.params["HSPD"] == 20000      # the drive's own speed is back


def test_open_loop_positions_are_pulses(served):
    with served.open() as d:
        d.params["SL"] = False
        d.enable()
        d.move_to(10)                         # 1000 pulses: PX; the encoder reads 1250 counts
        assert d.position == pytest.approx(10.0)
        assert served.sim.encoder_position == 1250
        assert d.status.raw[1] is SnlStatus.DISABLED


def test_jog_has_a_signed_velocity_then_stop(served):
    with served.open() as d:
        d.enable()
        d.jog(-50)                            # -5000 counts/s
        time.sleep(0.05)
        assert d.status.moving
        assert d.velocity < 0
        d.stop()
        d.wait_idle(timeout=5)
        assert d.velocity == 0


def test_motion_of_a_disabled_motor_is_refused(served):
    with served.open() as d:
        d.disable()
        with pytest.raises(ArcusMotorDisabled):
            d.move_to(1)
        with pytest.raises(ArcusMotorDisabled):
            d.jog(1)
        with pytest.raises(ArcusMotorDisabled):
            d.home()
        assert not d.status.enabled


def test_home_default_and_named_methods(served):
    with served.open() as d:
        d.enable()
        d.home()                              # H+: toward the switch at 400..800 steps
        st = d.status
        assert st.homed and not st.moving and not st.fault
        assert d.position > 0                 # zeroed at the switch edge, stopped past it by the deceleration
        d.move_to(-5)
        d.home("hl+")                         # the manual's words, any case
        assert d.status.homed and d.position == 0.0
        for bad in ("H", "X+", 1, "home"):
            with pytest.raises(motorbus.InvalidArgument, match="H\\+"):
                d.home(bad)


def test_home_into_a_limit_raises_the_homing_error():
    s = Served(plus_limit=600, home=(5000, 5400))
    try:
        with s.open() as d:
            d.enable()
            with pytest.raises(ArcusHomingError, match="homing failed") as failed:
                d.home("H+")                  # the limit comes first
            e = failed.value                  # a MoveFailed whose class says why
            assert isinstance(e, motorbus.LimitReached) and e.side == 1 and e.outcome == "limit"
            assert "MST bit 7" in e.reason and d.status.last_move.state == "limit"
            assert not d.status.homed and d.status.fault and d.status.limit_positive
            d.clear_faults()
            assert not d.status.fault
    finally:
        s.close()


def test_fault_then_clear_faults(served):
    with served.open() as d:
        d.enable()
        served.sim.force_limit(-1, True)     # the minus limit switch is hit
        d.jog(-10)
        with pytest.raises(motorbus.LimitReached) as failed:
            d.wait_idle(timeout=5)           # a jog a limit ended
        assert failed.value.side == -1
        st = d.status
        assert st.fault and st.limit_negative
        assert st.raw == (MotorStatus.MINUS_LIMIT | MotorStatus.MINUS_LIMIT_ERROR, SnlStatus.LIMIT_ERROR)
        with pytest.raises(arcus._core.ArcusStateError):
            d.move_to(1)
        served.sim.force_limit(-1, None)
        d.clear_faults()
        assert not d.status.fault
        d.move_to(1)
        assert abs(d.position - 1) <= 0.01


def test_stall_is_a_fault_cleared_by_clear_faults(served):
    with served.open() as d:
        d.enable()
        served.sim.set_blocked(True)
        with pytest.raises(motorbus.MoveStalled, match="SLS 10") as failed:
            d.move_to(50)
        assert failed.value.code == 10 and failed.value.position < 50
        assert d.status.fault and d.status.raw[1] is SnlStatus.STALL_ERROR
        served.sim.set_blocked(False)
        d.clear_faults()
        assert not d.status.fault


def test_params_read_write_describe_and_refusals(served):
    with served.open() as d:
        assert "HSPD" in d.params and "hspd" in d.params and "NOPE" not in d.params
        d.params["hspd"] = 12345
        assert d.params["HSPD"] == 12345 == d.native.high_speed
        info = d.params.describe("CURR")
        assert (info.type, info.minimum, info.maximum, info.unit, info.default, info.persists) == \
            ("int", 100, 2500, "mA", 1600, True)
        assert d.params.describe("HSPD").persists is False
        assert d.params["SLR"] == pytest.approx(0.8) and d.params.describe("SLR").type == "float"
        assert d.params["SL"] is True and d.params["EDO"] is True
        assert d.params["ID"] == "DriveMax-CAN"
        assert d.params["DN"] == 1
        d.params["POL"] = 2
        assert d.native.polarity == 2
        with pytest.raises(KeyError):
            d.params["NOPE"]
        with pytest.raises(motorbus.InvalidArgument, match="NOPE"):
            d.params["NOPE"] = 1
        with pytest.raises(motorbus.InvalidArgument, match="CURR=50"):
            d.params["CURR"] = 50
        with pytest.raises(motorbus.InvalidArgument, match="read-only"):
            d.params["CUR"] = 100
        with pytest.raises(motorbus.InvalidArgument, match="integer"):
            d.params["HSPD"] = 1000.5
        with pytest.raises(motorbus.InvalidArgument, match="number"):
            d.params["HSPD"] = "fast"
        assert set(d.params) >= {"HSPD", "LSPD", "ACC", "DEC", "EDEC", "SCV", "SSPDM", "CURR", "CURI", "CURT",
                                 "SL", "SLT", "SLE", "SLA", "SLM", "SLR", "POL", "EDO", "EOBOOT", "DOBOOT", "LCA"}


def test_store_keeps_stored_params_over_a_power_cycle(tmp_path):
    opts = arcus.ArcusDrive.store_options(str(tmp_path), "01")
    s = Served(**opts)
    try:
        with s.open() as d:
            d.params["CURR"] = 2000
            d.params["HSPD"] = 5000           # not a flash item
            d.store()
            s.sim.power_cycle()
            assert d.params["CURR"] == 2000 and d.params["HSPD"] == 1000
        assert (tmp_path / "arcus-01.store").exists()
    finally:
        s.close()


@pytest.mark.parametrize("how, moving_after, enabled_after", [
    ("stop", True, True),          # STOP decelerates
    ("quick_stop", False, True),   # ABORT
    ("disable", False, False),     # EO=0: no motion is done
])
def test_on_error_words(served, how, moving_after, enabled_after):
    # One line shared by the watching client and the Drive: the port is exclusive
    # (a second process or object opening the same path is refused).
    line = open_line(served.path)
    watch = arcus.ArcusClient(line, "01", on_exit=None)
    try:
        with pytest.raises(RuntimeError, match="boom"):
            with served.open(on_error=how, line=line) as d:
                d.params["DEC"] = 500
                d.params["EDEC"] = True
                d.enable()
                d.jog(100)
                raise RuntimeError("boom")
        assert watch.moving is moving_after
        assert watch.enabled is enabled_after
        with pytest.raises(motorbus.InvalidArgument):
            served.open(on_error="abort", line=line)
    finally:
        watch.abort()
        watch.close()
        line.port.close()


def test_link_loss_raises_link_down():
    s = Served()
    d = s.open()
    d.enable()
    d.jog(10)
    s.close()                                # the line is gone; the motor keeps jogging (no watchdog)
    with pytest.raises(motorbus.LinkDown):
        d.position
    with pytest.raises(motorbus.LinkDown):
        d.stop()
    d.close()


def test_shared_line_is_not_closed_with_the_drive(served):
    line = open_line(served.path, timeout=0.2)
    d = motorbus.open_drive("arcus", line=line, address=1)
    d.close()
    c = arcus.ArcusClient(line, "01")
    assert c.id == "DriveMax-CAN"
    c.close()
    line.port.close()


# ---- the awaitable face (motorbus.aio): the same hooks, awaited -------------------------------
# What only this kind does: the homing error raised from _homing_done, the refusal of a
# move longer than one X (the drive's "?X" caught and the position read on the worker),
# HSPD put back after a cancelled move, and the drives of one RS-485 line moving at once.

async def test_aio_homing_into_a_limit_raises_the_homing_error():
    s = Served(plus_limit=600, home=(5000, 5400))
    try:
        x = await aio.open_drive("arcus", line=s.path, address="01", units=MM)
        async with x:
            await x.params.set("HSPD", 20000)
            await x.enable()
            with pytest.raises(arcus.ArcusHomingLimit, match="homing failed") as failed:
                await x.home("H+", timeout=10)
            assert failed.value.side == 1 and "MST bit 7" in failed.value.reason
            st = await x.status()
            assert st.last_move.state == "limit" and not st.homed and st.limit_positive
            assert s.sim.motor_status & MotorStatus.PLUS_LIMIT_ERROR
    finally:
        s.close()


async def test_aio_a_move_longer_than_one_x_is_refused_naming_it(served):
    x = await aio.open_drive("arcus", line=served.path, address="01", units=MM)
    async with x:
        await x.enable()
        with pytest.raises(motorbus.InvalidArgument, match=r"at most 262143 in one X \(Table 11.0\)"):
            await x.move_to(3000)                    # 300000 counts
        assert (await x.status()).last_move is None and served.sim.encoder_position == 0


async def test_aio_cancelled_move_stops_the_shaft_and_puts_hspd_back(served):
    x = await aio.open_drive("arcus", line=served.path, address="01", units=MM)
    async with x:
        await x.params.set("HSPD", 20000)
        await x.params.set("ACC", 20)
        await x.enable()
        task = asyncio.create_task(x.move_to(1500, velocity=100.0))   # 10000 counts/s for this move
        while served.sim.encoder_position < 500:     # under way (real time; no fixed sleep)
            await asyncio.sleep(0.01)
        task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await task
        # At rest, seen from the simulator: the STOP went out and the shaft stayed put.
        assert not served.sim.busy
        here = served.sim.encoder_position
        await asyncio.sleep(0.1)
        assert served.sim.encoder_position == here and 500 <= here < 150000
        last = (await x.status()).last_move
        assert last.state == "interrupted" and "cancellation" in last.reason
        assert last.position == pytest.approx(here / 100, abs=0.2)
        assert await x.params.get("HSPD") == 20000   # the move's velocity= is undone


async def test_aio_two_drives_on_one_line_move_at_once():
    sims = [make_sim("01", eo_boot=True), make_sim("02", eo_boot=True)]
    server = core.serial.PtyLineServer(sims, 0, None)
    line = open_line(server.slave_path)
    try:
        axes = [await aio.open_drive("arcus", line=line, address=a, units=MM) for a in ("01", "02")]
        for x in axes:
            await x.params.set("HSPD", 20000)
            await x.enable()
        await asyncio.gather(axes[0].move_to(12.0), axes[1].move_to(-7.5))
        assert [s.encoder_position for s in sims] == [pytest.approx(1200, abs=20), pytest.approx(-750, abs=20)]
        # Readings of both, many at once, queue on the line's one worker and all come back.
        readings = await asyncio.gather(*(x.position() for _ in range(200) for x in axes))
        assert set(readings[0::2]) == {await axes[0].position()} and set(readings[1::2]) == {await axes[1].position()}
        for x in axes:
            await x.aclose()
    finally:
        line.port.close()
        server.close()

"""DmacDrive through motorbus.open_drive on a served pty in real time: params,
homing, faults, units, status, link loss and the safety words; blocking, and awaited
through motorbus.aio for what only the DMAC does."""
from __future__ import annotations

import asyncio
import time

import pytest

import motorbus
from motorbus import aio, faces
from motorbus.drive import Units, open_drive
from motorbus.drives.dmac import DmacErrorWord, DmacStatus, HomingFailed, HomingTimedOut, make_sim, open_line
from motorbus.serial import PtyLineServer, open_port


@pytest.fixture()
def rig():
    sim = make_sim("00", reference_switch=3000)  # IN5 turns on at 0.3 rev
    server = PtyLineServer([sim])
    d = open_drive("dmac", line=server.slave_path, address="00", units=Units("mm", 0.01))
    d.params["#ACCEL_TIME"] = 20
    d.params["DECEL_TIME"] = 20
    yield d, sim, server
    d.close()
    server.close()


def test_enable_move_and_status(rig):
    d, sim, _ = rig
    d.enable()
    assert d.status.enabled and not d.status.fault
    d.move_to(50.0, velocity=500.0)           # 5000 increments at 50000 inc/s
    assert d.position == 50.0
    assert d.params["#HIGH_SPEED"] == 60000    # the move's 30000 was for that move only
    d.move_by(-20.0)
    assert d.position == 30.0
    st = d.status
    assert not st.moving and st.at_target and isinstance(st.raw[0], DmacStatus)
    assert "DMAC 00" in st.text


def test_params_describe_and_refusals(rig):
    d, _, _ = rig
    info = d.params.describe("HIGH_SPEED")
    assert (info.name, info.default, info.maximum, info.persists, info.unit) == ("#HIGH_SPEED", 60000, 400000, True, "0.01 rpm")
    assert d.params.describe("#STATUS").writable is False
    assert "#LOW_SPEED" in d.params
    with pytest.raises(KeyError):
        d.params["#NOPE"]
    with pytest.raises(motorbus.InvalidArgument):
        d.params["#TORQUE_RATIO"] = 101
    with pytest.raises(motorbus.InvalidArgument):
        d.params["#SPEED"] = 5
    d.params["TORQUE_RATIO"] = 70
    assert d.params["#TRA"] == 70


def test_home_reference_and_here(rig):
    d, sim, _ = rig
    d.enable()
    d.params["#LOW_SPEED"] = 60000            # search at 600 rpm: the switch is 0.3 rev away
    d.home()
    assert d.status.homed and d.position == 0.0
    assert sim.read("#CAPTURE") == 3000       # where IN5 rose, in the old frame
    d.move_to(10.0)
    d.home("here")
    assert d.position == 0.0
    with pytest.raises(motorbus.InvalidArgument):
        d.home("index")


def test_home_without_a_switch_fails_typed():
    sim = make_sim("00", positive_end_switch=2000)
    with PtyLineServer([sim]) as server:
        with open_drive("dmac", line=server.slave_path, address="00") as d:
            d.enable()
            d.native.hard_ends("ALL")
            d.params["#LOW_SPEED"] = 60000
            with pytest.raises(HomingFailed) as failed:
                d.home(timeout=5)             # the end-stop at 2000 comes before IN5 at 3000
            e = failed.value
            assert isinstance(e, motorbus.LimitReached) and e.side == 1 and "IN5 reference edge" in e.reason
            assert 2000 <= e.position < 3000 and not d.status.homed


def test_fault_then_clear(rig):
    d, sim, _ = rig
    d.enable()
    sim.set_supply_voltage(11000)             # undervoltage on a DMAC34
    st = d.status
    assert st.fault and not st.enabled and DmacErrorWord.UNDERVOLTAGE in st.raw[1]
    with pytest.raises(motorbus.DriveFault, match=r"cause is still present .*SUPPLY_VOLTAGE 11 V.*clear_faults\(\)"):
        d.move_to(1.0)
    with pytest.raises(motorbus.DriveFault, match="latched again at once.*undervoltage.*still present"):
        d.clear_faults()
    sim.set_supply_voltage(32000)
    d.clear_faults()
    assert not d.status.fault
    d.move_to(1.0)
    assert d.position == 1.0


def test_jog_then_stop_and_quick_stop(rig):
    d, _, _ = rig
    d.enable()
    d.jog(100.0)
    assert d.status.moving
    d.stop()
    d.wait_idle(timeout=5)
    d.jog(-100.0)
    d.quick_stop()
    assert not d.status.moving


def test_exception_in_with_stops_and_link_loss_raises_linkdown():
    sim = make_sim("00")
    server = PtyLineServer([sim])
    d = open_drive("dmac", line=server.slave_path, address="00", on_error="quick_stop")
    with pytest.raises(RuntimeError):
        with d:
            d.enable()
            d.jog(1000.0)
            raise RuntimeError("boom")
    assert not sim.state().status & int(DmacStatus.MOVEMENT)   # HALT: at rest at once
    d2 = open_drive("dmac", line=server.slave_path, address="00")
    server.close()
    with pytest.raises(motorbus.LinkDown):
        d2.position
    d2.close()


def test_plugin_fields():
    plugin = motorbus.registry.drive_plugin("dmac")
    assert (plugin.kind, plugin.transport, plugin.default_address, plugin.default_baud) == ("dmac", "serial", "00", 38400)
    assert plugin.check_address("7") == "07"
    with pytest.raises(motorbus.InvalidArgument):
        plugin.check_address("64")
    with pytest.raises(motorbus.InvalidArgument):
        open_drive("dmac", line="/dev/null", address="00", on_error="brake")


# ---- the awaitable face (motorbus.aio): what only the DMAC does -----------------------------
# The Drive API cases awaited for every kind are test_aio_drive.py's; these await the DMAC's
# own logic (the IN5 homing steps, #HIGH_SPEED for one move, a refusal in the Drive's words),
# the same coroutines drive.home()/move_to() above run blocking.

class _NoExchangeOnTheLoop:
    """Stands in for ``drive.native`` while a test awaits: a hook that reached past
    ``drive.io`` would block the loop with a line transaction (``drive.io`` keeps the client)."""

    def __init__(self, native):
        self._native = native

    def __getattr__(self, name):
        assert name in ("address", "link"), f"native.{name} called on the loop's thread"
        return getattr(self._native, name)


@pytest.fixture()
def awaited(rig):
    d, sim, _ = rig
    native, d.native = d.native, _NoExchangeOnTheLoop(d.native)
    yield aio.Drive(d, stop_timeout=5.0), sim
    d.native = native


def _at_rest(sim) -> bool:
    return not sim.state().status & int(DmacStatus.MOVEMENT)


async def test_aio_homing_backs_off_a_switch_already_on_then_finds_its_edge(awaited):
    axis, sim = awaited
    await axis.params.set("#LOW_SPEED", 60000)
    await axis.enable()
    await axis.move_to(50.0, timeout=10)         # 5000 increments: IN5 (on from 3000) is on
    assert sim.read("#INPUT") & (1 << 4)
    await axis.home(timeout=20)                   # backoff, stop, search, return to 0
    st = await axis.status()
    assert st.homed and st.last_move.ok and await axis.position() == 0.0
    assert sim.read("#CAPTURE") == 3000 and _at_rest(sim)
    assert not sim.state().status & int(DmacStatus.REFERENCE)      # no search left armed


async def test_aio_homing_with_no_switch_times_out_naming_the_edge_and_stops_the_search():
    sim = make_sim("00", reference_switch=None)
    with PtyLineServer([sim]) as server:
        with open_drive("dmac", line=server.slave_path, address="00") as d:
            axis = aio.Drive(d)
            await axis.params.set("#LOW_SPEED", 60000)
            await axis.enable()
            with pytest.raises(HomingTimedOut, match="IN5 reference edge") as failed:
                await axis.home(timeout=0.3)
            assert isinstance(failed.value, motorbus.MoveTimedOut)
            deadline = time.monotonic() + 5
            while not _at_rest(sim):                                # STOP on #DECEL_TIME
                assert time.monotonic() < deadline, "the search was not stopped"
                await asyncio.sleep(0.01)
            assert not sim.state().status & int(DmacStatus.REFERENCE)
            assert (await axis.status()).last_move.state == "timeout"


async def test_aio_cancelled_move_at_a_velocity_stops_and_puts_high_speed_back(awaited):
    axis, sim = awaited
    await axis.enable()
    move = asyncio.create_task(axis.move_to(400.0, velocity=100.0, timeout=60))   # #HIGH_SPEED 6000
    deadline = time.monotonic() + 5
    # Moving at the move's own speed, as the module says; a position() queued on the line's
    # worker behind MOVE_TO has come back, so the command is answered and the move started.
    while _at_rest(sim) or sim.read("#HIGH_SPEED") != 6000:
        assert time.monotonic() < deadline, "the move never started at its velocity"
        await asyncio.sleep(0.005)
    await axis.position()
    move.cancel()
    with pytest.raises(asyncio.CancelledError):
        await move
    here = sim.state().position                   # at rest when the cancellation arrives
    assert _at_rest(sim) and 0 < here < 40000
    await asyncio.sleep(0.05)
    assert sim.state().position == here
    assert sim.read("#HIGH_SPEED") == 60000       # the move's 6000 was for that move only
    last = (await axis.status()).last_move
    assert last.state == "interrupted" and "cancellation" in last.reason


async def test_aio_move_refused_by_a_latched_fault_says_its_cause(awaited):
    axis, sim = awaited
    await axis.enable()
    sim.set_supply_voltage(11000)                 # undervoltage on a DMAC34
    with pytest.raises(motorbus.DriveFault, match=r"cause is still present .*SUPPLY_VOLTAGE 11 V.*clear_faults\(\)"):
        await axis.move_to(1.0)
    with pytest.raises(motorbus.DriveFault, match="latched again at once.*undervoltage.*still present"):
        await axis.clear_faults()
    sim.set_supply_voltage(32000)
    await axis.clear_faults()
    await axis.enable()
    await axis.move_to(1.0, timeout=10)
    assert sim.state().position == 100


async def test_aio_two_modules_of_one_line_move_at_once_on_one_worker():
    sims = [make_sim("00"), make_sim("01")]
    with PtyLineServer(sims) as server:
        port = open_port(server.slave_path, 38400)
        link = open_line(port)
        drives = [open_drive("dmac", line=link, address=a, units=Units("mm", 0.01)) for a in ("00", "01")]
        try:
            axes = [aio.Drive(d) for d in drives]
            assert drives[0]._io_link() is drives[1]._io_link() is link
            await asyncio.gather(*(a.enable() for a in axes))
            workers = faces.worker_threads()
            await asyncio.gather(axes[0].move_to(30.0, timeout=10), axes[1].move_to(-20.0, timeout=10),
                                 *(a.position() for a in axes for _ in range(100)))
            assert faces.worker_threads() <= max(workers, 1)      # the line's one worker, no more
            assert [s.state().position for s in sims] == [3000, -2000]
        finally:
            for d in drives:
                d.close()
            port.close()

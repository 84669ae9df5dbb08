"""The CA face of ``motorbus serve`` seen by independent Channel Access clients.

One simulated twin (one axis of each built-in kind, the pytest plugin's default bench
with the fast test profiles of drive_kinds) is served by ``motorbus.serve.epics.start_ca``
on 127.0.0.1 from a thread with its own event loop, as the service runs it.  The clients
are the ones facilities use, each over a real CA circuit:

- ophyd-async ``Motor`` (aioca, libca): the per-kind matrix (it is the cheapest client):
  connect with its strict type checks, move, zero-length move, stop, soft-limit
  violation, set-position, home, a drive fault during a move;
- ophyd ``EpicsMotor`` in a bluesky ``scan`` under a RunEngine, and a fault that fails
  its MoveStatus;
- pyepics ``Motor``: ``move(wait=True)``, limits (-12 client-side, -4 with LVIO from the
  server), ``set_position``, the ``_able`` record, RBV severity after a fault;
- caproto's command-line tools as child processes: ``caproto-put -c`` moving while
  ``caproto-monitor`` sees DMOV 1 -> 0 -> 1, and a refused put.

Where an axis stands is read on its simulator (drive_kinds' ``shaft``), never through
the face under test.
"""
from __future__ import annotations

import asyncio
import atexit
import importlib.util
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("caproto")
pytest.importorskip("aioca")
pytest.importorskip("epicscorelibs")
# ophyd (1.5 s to import), ophyd-async and bluesky load in the fixtures that use them: under
# xdist every worker collects this module, and only one runs it.
for _name in ("ophyd_async", "ophyd", "bluesky"):
    if importlib.util.find_spec(_name) is None:
        pytest.skip(f"{_name} is not installed", allow_module_level=True)

import epicscorelibs.path.pyepics  # noqa: E402,F401  before epics: pyepics then loads the wheel's libca, aioca's
import epics  # noqa: E402
import pytest_asyncio  # noqa: E402
from aioca import CANothing, camonitor, caput, purge_channel_caches  # noqa: E402

import ca_env  # noqa: E402
from motorbus.pytest_plugin import default_bench  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from drive_kinds import KINDS, OUT_OF_TREE  # noqa: E402  fast profiles, the simulators' shafts

pytestmark = pytest.mark.timeout(120)   # not `threaded`: see NOT_THREADED in tests/conftest.py

ECA_PUTFAIL = 160             # libca caerr.h: DEFMSG(CA_K_WARNING, 20), "Channel write request failed"
BUILTIN = sorted(k for k in KINDS if k not in OUT_OF_TREE)
PREFIX = "MBTEST26:"          # this module's names: a client's cached channel never reaches another module's server
SLOW = 20.0                   # mm/s (VELO) for the moves a test cuts short: long enough to act on mid-move
FAST = 100.0                  # mm/s for the others
STEP = 2.0                    # mm: a short move


class _Params:
    """Collects what a kind's fast profile (drive_kinds setup) writes."""

    def __init__(self) -> None:
        self.params: dict = {}


def bench_data() -> dict:
    """The plugin's default twin (one axis per kind, named after it), built-in kinds only,
    in mm with the fast test profiles."""
    data = default_bench()
    data["axis"] = {n: a for n, a in data["axis"].items() if a["kind"] in BUILTIN}
    used = {a.get("line") for a in data["axis"].values()} | {a.get("bus") for a in data["axis"].values()}
    data["line"] = {k: v for k, v in data["line"].items() if k in used}
    data["bus"] = {k: v for k, v in data["bus"].items() if k in used}
    for axis in data["axis"].values():
        kind = KINDS[axis["kind"]]
        profile = _Params()
        kind.setup(profile)
        axis["units"] = {"name": "mm", "scale": kind.scale}
        axis["params"] = profile.params
        if kind.sim_options:
            axis["sim"] = dict(kind.sim_options)
    return data


@pytest.fixture(scope="module")
def twin():
    ca_env.configure()
    ca_env.start_repeater()
    served = ca_env.ServedTwin(bench_data(), prefix=PREFIX).start()
    assert sorted(served.bench.axes) == BUILTIN
    # Served until the process exits, closed after libca's context: pyepics destroys that
    # context at exit (finalize_libca, registered when the first client starts, after
    # this), and once aioca has used it too, ca_context_destroy blocks 30 s if the server
    # has gone first.  atexit runs the last registered first.
    atexit.register(served.close)
    yield served
    served.quiesce()


def pv(axis: str, field: str = "") -> str:
    return f"{PREFIX}{axis}" + (f".{field}" if field else "")


def shaft(twin, axis: str) -> float:
    """Where the axis' motor stands, mm, read on its simulator."""
    kind = KINDS[axis]
    return kind.shaft(twin.sims[axis]) * kind.scale


def at_rest(twin, axis: str, timeout: float = 10.0) -> float:
    """The shaft's position once it no longer moves (two reads 20 ms apart agree: the
    simulators step in whole counts, and a count is 0.01 mm)."""
    at = shaft(twin, axis)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        time.sleep(0.02)
        now, at = at, shaft(twin, axis)
        if now == at:
            return at
    raise AssertionError(f"{axis} still moves: {at}")


def wait_for_motion(twin, axis: str, start: float, timeout: float = 10.0, move=None) -> float:
    """Blocks until the shaft left ``start`` (the move is under way); returns where it is.
    ``move``: the client's pending move (a future), whose early end is the failure shown."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        now = shaft(twin, axis)
        if abs(now - start) > 0.05:
            return now
        if move is not None and move.done():
            raise AssertionError(f"{axis}: the move ended before it started: {move.exception()!r}")
        time.sleep(0.002)
    raise AssertionError(f"{axis} never started moving from {start}")


async def wait_for_motion_async(twin, axis: str, start: float, move, timeout: float = 10.0) -> float:
    """wait_for_motion, letting the loop run (the client's move is a task on it)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        now = shaft(twin, axis)
        if abs(now - start) > 0.05:
            return now
        if move.done():
            raise AssertionError(f"{axis}: the move ended before it started: {move.exception()!r}")
        await asyncio.sleep(0.002)
    raise AssertionError(f"{axis} never started moving from {start}")


def far(axis: str) -> float:
    """How far (mm) a move goes that a test cuts short: 1.5 s at SLOW; UNITEK takes no
    per-move speed (VELO does nothing there) and runs fast, so drive_kinds' far target."""
    return KINDS[axis].far if axis == "unitek" else 30.0


def tolerance(axis: str) -> float:
    """How close a move lands, mm: the sims stop within a count or two."""
    return 3 * KINDS[axis].scale


LIMIT_FAULT = ("arcus", "arcus-canopen")    # their fault during a move: the - limit switch closes


def provoke_fault(twin, axis: str) -> None:
    """A drive fault while the axis moves (toward -).  The steppers' limit switch closes in
    the direction of travel (a LimitReached: the move fails); every other kind faults."""
    sim = twin.sims[axis]
    if axis in LIMIT_FAULT:
        sim.force_limit(-1, True)
    else:
        KINDS[axis].fault(sim, None)


def remove_fault(twin, axis: str) -> None:
    """Takes the fault's cause away on the simulator and clears the drive's latch on the
    service's loop (a test's cleanup, not what is under test), enabled again."""
    sim = twin.sims[axis]
    if axis in LIMIT_FAULT:
        sim.force_limit(-1, None)
    else:
        KINDS[axis].unfault(sim)
    drive = twin.bench[axis]

    async def clear() -> None:
        await drive.clear_faults()
        await drive.enable()

    twin.run(clear())


# -- ophyd-async Motor (aioca): every kind ------------------------------------------------

@pytest_asyncio.fixture(scope="module", loop_scope="module")
async def motors(twin):
    from ophyd_async.epics.motor import Motor

    found = {}
    for axis in BUILTIN:
        m = Motor(pv(axis), name=axis.replace("-", "_"))
        await m.connect(timeout=10)      # every signal's CA type and enum strings checked here
        found[axis] = m
    yield found
    # Channels closed while their server still runs: left open, libca's context teardown
    # at exit waits out their disconnection (30 s).
    purge_channel_caches()


class Pulses:
    """DMOV's monitor updates, collected (aioca), from the subscription's first value on."""

    def __init__(self, name: str) -> None:
        self.values: list[int] = []
        self.first = asyncio.Event()
        self.sub = camonitor(name, self._update, all_updates=True)   # each update, none merged

    def _update(self, value) -> None:
        self.values.append(int(value))
        self.first.set()

    async def __aenter__(self) -> "Pulses":
        await asyncio.wait_for(self.first.wait(), 5)
        return self

    async def __aexit__(self, *exc) -> None:
        self.sub.close()

    async def until(self, pattern: list[int], timeout: float = 10.0) -> None:
        deadline = time.monotonic() + timeout
        while self.values != pattern and time.monotonic() < deadline:
            await asyncio.sleep(0.01)
        assert self.values == pattern


async def _settle_velocity(m, velocity: float) -> None:
    await m.velocity.set(velocity)
    assert await m.velocity.get_value() == pytest.approx(velocity)


def fast(vmax: float) -> float:
    """A quick speed, mm/s: VMAX where the kind declares one (0 means none, the record's
    rule) and it is lower than FAST."""
    return vmax if 0 < vmax < FAST else FAST


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.parametrize("axis", BUILTIN)
async def test_ophyd_async_moves_and_zero_length_move(twin, motors, axis):
    m = motors[axis]
    assert await m.motor_egu.get_value() == "mm"
    assert await m.motor_resolution.get_value() == pytest.approx(KINDS[axis].scale)
    await _settle_velocity(m, fast(await m.max_velocity.get_value()))
    start = await m.user_readback.get_value()
    assert start == pytest.approx(shaft(twin, axis), abs=tolerance(axis))
    target = round(start + STEP, 2)
    async with Pulses(pv(axis, "DMOV")) as dmov:
        await m.set(target)          # put-callback: returns at the end of motion
        assert shaft(twin, axis) == pytest.approx(target, abs=tolerance(axis))
        await dmov.until([1, 0, 1])
    assert await m.user_readback.get_value() == pytest.approx(target, abs=tolerance(axis))
    assert at_rest(twin, axis) == pytest.approx(target, abs=tolerance(axis))
    # A move to where it stands still pulses DMOV (the record's rule) and completes.
    async with Pulses(pv(axis, "DMOV")) as dmov:
        await m.set(target)
        await dmov.until([1, 0, 1])
    assert at_rest(twin, axis) == pytest.approx(target, abs=tolerance(axis))


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.parametrize("axis", BUILTIN)
async def test_ophyd_async_stop_mid_move(twin, motors, axis):
    m = motors[axis]
    await _settle_velocity(m, SLOW)
    start = at_rest(twin, axis)
    target = round(start + far(axis), 2)       # 1.5 s at SLOW
    # A STOP from another writer (no client-side cancel): the drive stops, VAL := RBV, and
    # the pending put-callback (the device's move, awaited through aioca: ophyd-async's own
    # set loses failures) fails, a cut-short move being a failed one for CA clients
    # (docs/epics.md, a deliberate difference from the record).
    moving = asyncio.ensure_future(caput(pv(axis), target, wait=True, timeout=60))
    await wait_for_motion_async(twin, axis, start, moving)
    await caput(pv(axis, "STOP"), 1)
    with pytest.raises(CANothing) as failed:
        await asyncio.wait_for(moving, 10)
    assert failed.value.errorcode == ECA_PUTFAIL
    assert int(await _get(pv(axis, "STOP"))) == 0       # reset at once
    stopped = at_rest(twin, axis)
    assert start + 0.05 < stopped < target - 1.0
    assert await m.user_setpoint.get_value() == pytest.approx(stopped, abs=tolerance(axis))
    assert await m.user_readback.get_value() == pytest.approx(stopped, abs=tolerance(axis))
    assert await m.motor_done_move.get_value() == 1
    # ophyd-async's own stop(): the device reports the cut-short move as failed.
    start = stopped
    moving = asyncio.ensure_future(m.set(round(start - far(axis), 2)))
    await wait_for_motion_async(twin, axis, start, moving)
    await m.stop()
    with pytest.raises(RuntimeError, match="stopped"):
        await asyncio.wait_for(moving, 10)
    assert start - far(axis) + 1.0 < at_rest(twin, axis) < start - 0.05


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.parametrize("axis", BUILTIN)
async def test_ophyd_async_limit_violation_and_set_position(twin, motors, axis):
    from ophyd_async.epics.motor import MotorLimitsError

    m = motors[axis]
    await _settle_velocity(m, fast(await m.max_velocity.get_value()))
    here = await m.user_readback.get_value()
    limits = await m.low_limit_travel.get_value(), await m.high_limit_travel.get_value()
    await m.low_limit_travel.set(here - 10.0)
    await m.high_limit_travel.set(here + 10.0)
    try:
        # The limits are served (dial limits too), so the device refuses before any put...
        assert await m.dial_high_limit_travel.get_value() != 0 or await m.dial_low_limit_travel.get_value() != 0
        with pytest.raises(MotorLimitsError):
            await m.set(here + 20.0)
        # ...and a put-callback that goes round it (aioca's, what the device's setpoint does)
        # is refused by the record: ECA_PUTFAIL, LVIO, no motion.
        with pytest.raises(CANothing) as refused:
            await caput(pv(axis), here + 20.0, wait=True, timeout=10)
        assert refused.value.errorcode == ECA_PUTFAIL
        assert await m.user_setpoint.get_value() == pytest.approx(here, abs=tolerance(axis))
        assert int(await _get(pv(axis, "LVIO"))) == 1
        assert at_rest(twin, axis) == pytest.approx(here, abs=tolerance(axis))
        # Inside them it moves, and LVIO clears.
        await m.set(here + 1.0)
        assert int(await _get(pv(axis, "LVIO"))) == 0
        assert at_rest(twin, axis) == pytest.approx(here + 1.0, abs=tolerance(axis))
    finally:
        await m.low_limit_travel.set(limits[0])
        await m.high_limit_travel.set(limits[1])
    # Set-position (SET=Set, then VAL): the readback takes the new value, the motor stays.
    stands = at_rest(twin, axis)
    offset_before = await m.offset.get_value()
    await m.set_use_switch.set("Set")
    try:
        await m.user_setpoint.set(100.0, timeout=10)
    finally:
        await m.set_use_switch.set("Use")
    assert await m.user_readback.get_value() == pytest.approx(100.0, abs=tolerance(axis))
    assert at_rest(twin, axis) == pytest.approx(stands, abs=tolerance(axis))
    # From there a move is in the new coordinates: 1 mm forward in user units.
    await m.set(101.0)
    assert at_rest(twin, axis) == pytest.approx(stands + 1.0, abs=tolerance(axis))
    assert await m.user_readback.get_value() == pytest.approx(101.0, abs=tolerance(axis))
    # Back to the dial's coordinates for the tests after this one.
    await m.offset.set(offset_before)


async def _get(name: str):
    from aioca import caget

    return await caget(name, timeout=5)


HOME_FROM = {"arcus": 79.0}      # the ARCUS simulator's home switch: steps 8000-8400 (docs/drives/arcus.md)


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.parametrize("axis", BUILTIN)
async def test_ophyd_async_home(twin, motors, axis):
    from ophyd_async.core import observe_value
    from ophyd_async.epics.core import epics_signal_rw

    m = motors[axis]
    homf = epics_signal_rw(int, pv(axis, "HOMF"), wait=False)   # a plain put; DMOV tells the end
    await homf.connect(timeout=5)
    await _settle_velocity(m, fast(await m.max_velocity.get_value()))
    # Just below where each simulator's forward search ends (its home switch), so it ends soon.
    await m.set(HOME_FROM.get(axis, -3.0))
    seen: list[int] = []

    async def watch() -> None:
        async for v in observe_value(m.motor_done_move, timeout=30):
            seen.append(v)
            if seen[-2:] == [0, 1]:
                return

    watcher = asyncio.ensure_future(watch())
    await asyncio.sleep(0.05)
    await homf.set(1)
    await asyncio.wait_for(watcher, 30)
    assert await homf.get_value() == 0       # the record resets HOMF when homing ends
    status = await twin_status(twin, axis)
    assert status.homed and not status.fault
    assert await m.user_readback.get_value() == pytest.approx(await twin_position(twin, axis), abs=tolerance(axis))


async def _in(twin, coro):
    return await asyncio.wrap_future(asyncio.run_coroutine_threadsafe(coro, twin.loop))


async def twin_status(twin, axis):
    return await _in(twin, twin.bench[axis].status())


async def twin_position(twin, axis):
    return await _in(twin, twin.bench[axis].position())


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.parametrize("axis", BUILTIN)
async def test_ophyd_async_fault_during_move_fails_the_move(twin, motors, axis):
    m = motors[axis]
    await _settle_velocity(m, SLOW)
    start = at_rest(twin, axis)
    # The move as the device makes it (a put-callback on VAL, aioca), awaited directly:
    # ophyd-async's Signal.set loses a failed put (test_ophyd_async_set_loses_a_failed_put).
    moving = asyncio.ensure_future(caput(pv(axis), round(start - far(axis), 2), wait=True, timeout=60))
    await wait_for_motion_async(twin, axis, start, moving)
    provoke_fault(twin, axis)
    try:
        with pytest.raises(CANothing) as failed:       # the put failed: not a success
            await asyncio.wait_for(moving, 15)
        assert failed.value.errorcode == ECA_PUTFAIL
        assert at_rest(twin, axis) > start - far(axis) + 1.0
        if axis in LIMIT_FAULT:
            # A limit switch is no alarm unless HLSV says so (the record's rule): LLS tells.
            assert await m.low_limit_switch.get_value() == 1
        else:
            # RBV carries the record's alarm: MAJOR.
            reading = await m.user_readback.read()
            assert reading[m.user_readback.name]["alarm_severity"] == 2
    finally:
        remove_fault(twin, axis)
    # The next good move clears it.
    await _settle_velocity(m, fast(await m.max_velocity.get_value()))
    here = await m.user_readback.get_value()
    await m.set(round(here + 1.0, 2))
    reading = await m.user_readback.read()
    assert reading[m.user_readback.name]["alarm_severity"] == 0
    assert at_rest(twin, axis) == pytest.approx(round(here + 1.0, 2), abs=tolerance(axis))


# -- nothing leaves loopback ----------------------------------------------------------------

def test_beacons_and_searches_stay_on_loopback(twin):
    from caproto._utils import get_beacon_address_list

    beacons = get_beacon_address_list()
    assert beacons and all(host == "127.0.0.1" for host, _ in beacons), beacons
    assert ("255.255.255.255", ca_env.repeater_port()) not in beacons
    # And on the wire: every connected UDP socket of this process (the server's beacon
    # sockets among them) points at 127.0.0.1, none at a broadcast address.
    peers = ca_env.connected_udp_peers()
    assert ("127.0.0.1", ca_env.repeater_port()) in peers, peers
    assert all(host == "127.0.0.1" for host, _ in peers), peers
    assert twin.face.interfaces == ["127.0.0.1"]
    assert twin.face.port == ca_env.server_port()
    env = twin.face.client_env()
    assert env["EPICS_CA_AUTO_ADDR_LIST"] == "NO"
    assert env["EPICS_CA_ADDR_LIST"] == f"127.0.0.1:{ca_env.server_port()}"


# -- ophyd EpicsMotor in a bluesky scan ---------------------------------------------------------

OPHYD_AXES = tuple(BUILTIN)         # one scan steps every simulated kind together


@pytest.fixture(scope="module")
def RE():
    from bluesky import RunEngine

    RE = RunEngine({})
    yield RE
    RE.loop.call_soon_threadsafe(RE.loop.stop)


@pytest.fixture(scope="module")
def epics_motors(twin):
    from ophyd import EpicsMotor

    found = {}
    for axis in OPHYD_AXES:
        # settle_time: without it ophyd can drop the next move's status when the RunEngine
        # issues it inside ophyd's own DMOV callback (ophyd#782), and a scan hangs.
        m = EpicsMotor(pv(axis), name=axis, settle_time=0.05)
        m.wait_for_connection(timeout=10)
        found[axis] = m
    return found


def test_ophyd_epics_motor_scan_ends_on_targets(twin, epics_motors, RE):
    from bluesky.plans import scan

    motors = [epics_motors[a] for a in OPHYD_AXES]
    for m in motors:
        m.velocity.put(fast(epics.caget(pv(m.name, "VMAX"))), wait=True)
    starts = {m.name: at_rest(twin, m.name) for m in motors}
    docs: list = []
    # Both axes stepped together, 3 points 1 mm apart from where each stands: the scan's
    # events hold each motor's readback at each point.
    args = []
    for m in motors:
        args += [m, round(starts[m.name] + 1.0, 2), round(starts[m.name] + 3.0, 2)]
    RE(scan(motors, *args, 3), lambda name, doc: docs.append((name, doc)))
    events = [d for n, d in docs if n == "event"]
    stop = [d for n, d in docs if n == "stop"][0]
    assert stop["exit_status"] == "success"
    assert len(events) == 3
    for m in motors:
        got = [e["data"][m.name] for e in events]
        want = [starts[m.name] + 1.0, starts[m.name] + 2.0, starts[m.name] + 3.0]
        assert got == pytest.approx(want, abs=tolerance(m.name))
        assert at_rest(twin, m.name) == pytest.approx(starts[m.name] + 3.0, abs=tolerance(m.name))


def test_ophyd_epics_motor_fault_fails_its_move_status(twin, epics_motors):
    from ophyd.utils import UnknownStatusFailure  # noqa: F401  (what ophyd may raise; any failure counts)

    m = epics_motors["cia402"]
    m.velocity.put(SLOW, wait=True)
    start = at_rest(twin, "cia402")
    status = m.move(round(start - far("cia402"), 2), wait=False)
    wait_for_motion(twin, "cia402", start)
    provoke_fault(twin, "cia402")
    try:
        with pytest.raises(Exception):
            status.wait(15)
        assert status.done and not status.success
        assert m.user_readback.alarm_severity == 2
    finally:
        remove_fault(twin, "cia402")
    m.velocity.put(fast(epics.caget(pv("cia402", "VMAX"))), wait=True)
    here = m.user_readback.get()
    m.move(round(here + 1.0, 2), wait=True, timeout=15)
    assert m.user_readback.alarm_severity == 0


# -- pyepics Motor --------------------------------------------------------------------------------

PYEPICS_AXIS = "unitek"


@pytest.fixture(scope="module")
def pyepics_motor(twin):
    m = epics.Motor(pv(PYEPICS_AXIS), timeout=10)     # refuses anything whose RTYP is not 'motor'
    m.put("VELO", fast(m.get("VMAX")), wait=True)
    # pyepics checks every move against LLM <= target <= HLM, so 0/0 (the record's "no
    # limits") refuses all of them: soft limits as an IOC's database would set them.
    m.put("LLM", -10000.0, wait=True)
    m.put("HLM", 10000.0, wait=True)
    yield m
    m.put("LLM", 0.0, wait=True)
    m.put("HLM", 0.0, wait=True)


def test_pyepics_motor_move_wait_limits_set_position_able(twin, pyepics_motor):
    m, axis = pyepics_motor, PYEPICS_AXIS
    assert m.get("RTYP") == "motor"
    assert m.disabled == 0 and epics.caget(pv(axis) + "_able", as_string=True) == "Enable"
    here = m.get_position(readback=True)
    assert m.move(round(here + STEP, 2), wait=True, timeout=30) == 0
    assert at_rest(twin, axis) == pytest.approx(here + STEP, abs=tolerance(axis))
    assert m.get("DMOV") == 1 and m.get("LVIO") == 0
    here = m.get_position(readback=True)
    llm, hlm = m.get("LLM"), m.get("HLM")
    m.put("LLM", here - 5.0, wait=True)
    m.put("HLM", here + 5.0, wait=True)
    try:
        assert m.move(here + 10.0, wait=True) == -12                        # pyepics' own check
        assert m.move(here + 10.0, wait=True, ignore_limits=True) == -4     # the record's: LVIO
        assert m.get("LVIO") == 1
        assert m.get("VAL") == pytest.approx(here, abs=tolerance(axis))
        assert at_rest(twin, axis) == pytest.approx(here, abs=tolerance(axis))
    finally:
        m.put("LLM", llm, wait=True)
        m.put("HLM", hlm, wait=True)
    # Disabled through the _able record: a move is refused, nothing moves; enabled again, it moves.
    stands = at_rest(twin, axis)
    assert epics.caput(pv(axis) + "_able", "Disable", wait=True) == 1
    try:
        assert epics.caget(pv(axis) + "_able", use_monitor=False) == 1
        m.move(stands + 1.0, wait=True, timeout=10)
        time.sleep(0.1)
        assert at_rest(twin, axis) == pytest.approx(stands, abs=tolerance(axis))
    finally:
        epics.caput(pv(axis) + "_able", "Enable", wait=True)
    assert m.move(stands + 1.0, wait=True, timeout=30) == 0
    assert at_rest(twin, axis) == pytest.approx(stands + 1.0, abs=tolerance(axis))
    stands = at_rest(twin, axis)
    off = m.get("OFF")
    m.set_position(50.0)
    try:
        # Back in Use mode (read from the server: the monitor of a field other than VAL may
        # still be on its way when the put's completion arrives, as in an IOC).
        assert epics.caget(pv(axis, "SET"), use_monitor=False) == 0
        assert m.get_position(readback=True) == pytest.approx(50.0, abs=tolerance(axis))
        assert at_rest(twin, axis) == pytest.approx(stands, abs=tolerance(axis))
        assert m.move(51.0, wait=True, timeout=30) == 0
        assert at_rest(twin, axis) == pytest.approx(stands + 1.0, abs=tolerance(axis))
    finally:
        m.put("OFF", off, wait=True)


@pytest.mark.parametrize("axis", BUILTIN)
def test_pyepics_motor_moves_and_refuses_past_the_soft_limit_on_every_kind(twin, axis):
    m = epics.Motor(pv(axis), timeout=10)
    m.put("VELO", fast(m.get("VMAX")), wait=True)
    here = m.get_position(readback=True)
    llm, hlm = m.get("LLM"), m.get("HLM")
    m.put("LLM", here - 5.0, wait=True)
    m.put("HLM", here + 5.0, wait=True)
    try:
        assert m.move(round(here + STEP, 2), wait=True, timeout=30) == 0
        assert at_rest(twin, axis) == pytest.approx(here + STEP, abs=tolerance(axis))
        assert m.get("DMOV") == 1
        assert m.move(here + 10.0, wait=True, ignore_limits=True) == -4     # the record refused it: LVIO
        assert at_rest(twin, axis) == pytest.approx(here + STEP, abs=tolerance(axis))
    finally:
        m.put("LLM", llm, wait=True)
        m.put("HLM", hlm, wait=True)


def test_pyepics_motor_sees_a_fault_in_rbv_severity(twin, pyepics_motor):
    m, axis = pyepics_motor, PYEPICS_AXIS
    m.put("VELO", SLOW, wait=True)
    start = at_rest(twin, axis)
    done = threading.Event()
    result: list = []
    mover = threading.Thread(target=lambda: (result.append(m.move(start - far(axis), wait=True, timeout=60)),
                                             done.set()))
    mover.start()
    wait_for_motion(twin, axis, start)
    provoke_fault(twin, axis)
    try:
        assert done.wait(15)
        mover.join()
        # pyepics ignores a put-callback's status (it returns 0): the record's alarm is where
        # the failure shows.
        rbv = epics.PV(pv(axis, "RBV"), form="ctrl")
        assert rbv.get_ctrlvars(timeout=5) is not None
        assert rbv.severity == 2
        assert epics.caget(pv(axis, "SEVR")) == 2
        assert at_rest(twin, axis) > start - far(axis) + 1.0
    finally:
        remove_fault(twin, axis)
    m.put("VELO", fast(m.get("VMAX")), wait=True)
    here = m.get_position(readback=True)
    assert m.move(here + 1.0, wait=True, timeout=30) == 0
    assert epics.caget(pv(axis, "SEVR")) == 0


# -- caproto's command-line tools --------------------------------------------------------------

CLI_AXIS = "pmc007"


def _tool(name: str) -> str:
    return str(Path(sys.executable).with_name(name))


@pytest.mark.parametrize("axis", BUILTIN)
def test_caproto_put_completes_at_the_end_of_motion_and_monitor_sees_dmov_pulse(twin, axis):
    epics.caput(pv(axis, "VELO"), fast(epics.caget(pv(axis, "VMAX"))), wait=True)
    here = at_rest(twin, axis)
    target = round(here + 5.0, 2)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    monitor = subprocess.Popen([_tool("caproto-monitor"), "--no-repeater", "--maximum", "3",
                                "--format", "{pv_name} {response.data}", pv(axis, "DMOV")],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    try:
        first = monitor.stdout.readline()          # subscribed: its first update is the current value
        assert re.fullmatch(rf"{re.escape(pv(axis, 'DMOV'))} \[1\]\n", first), first
        put = subprocess.run([_tool("caproto-put"), "-c", "--no-repeater", "-w", "30", pv(axis), str(target)],
                             capture_output=True, text=True, env=env, timeout=60)
        # caproto-put exits 0 either way: success prints the old and the new value.
        assert put.returncode == 0 and "New :" in put.stdout and "Error" not in put.stdout, put.stdout + put.stderr
        # -c waited for the completion, which comes at rest on the target.
        assert shaft(twin, axis) == pytest.approx(target, abs=tolerance(axis))
        rest, _ = monitor.communicate(timeout=30)
    finally:
        if monitor.poll() is None:
            monitor.kill()
            monitor.wait()
    assert re.findall(r"\[(\d)\]", first + rest) == ["1", "0", "1"], first + rest
    assert at_rest(twin, axis) == pytest.approx(target, abs=tolerance(axis))


def test_caproto_put_outside_the_soft_limits_fails_and_does_not_move(twin):
    axis = CLI_AXIS
    here = at_rest(twin, axis)
    hlm = epics.caget(pv(axis, "HLM"))
    llm = epics.caget(pv(axis, "LLM"))
    epics.caput(pv(axis, "LLM"), here - 5.0, wait=True)
    epics.caput(pv(axis, "HLM"), here + 5.0, wait=True)
    try:
        put = subprocess.run([_tool("caproto-put"), "-c", "--no-repeater", "-w", "30", pv(axis), str(here + 10.0)],
                             capture_output=True, text=True, timeout=60)
        # caproto-put prints the server's refusal (and exits 0): ECA_PUTFAIL, with the reason.
        assert "ECA_PUTFAIL" in put.stdout and "LVIO" in put.stdout and "New :" not in put.stdout, put.stdout
        assert epics.caget(pv(axis, "LVIO")) == 1
        assert at_rest(twin, axis) == pytest.approx(here, abs=tolerance(axis))
    finally:
        epics.caput(pv(axis, "LLM"), llm, wait=True)
        epics.caput(pv(axis, "HLM"), hlm, wait=True)


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.xfail(strict=True, reason=(
    "ophyd-async 0.21.3: SignalW.set runs the put inside stamina's retry_context; aioca's CANothing is a "
    "falsy exception (__bool__ is its ok flag) and concurrent.futures.Future.result() (tenacity's outcome) "
    "tests `if self._exception:`, so a failed put-callback is returned as success.  Motor.set does not "
    "fail on a refused or faulted move; aioca's caput (above) and ophyd's EpicsMotor do."))
async def test_ophyd_async_set_loses_a_failed_put(twin, motors):
    m = motors["cia402"]
    here = await m.user_readback.get_value()
    limits = await m.low_limit_travel.get_value(), await m.high_limit_travel.get_value()
    await m.low_limit_travel.set(here - 1.0)
    await m.high_limit_travel.set(here + 1.0)
    try:
        with pytest.raises(CANothing):
            await m.user_setpoint.set(here + 5.0, timeout=10)
    finally:
        await m.low_limit_travel.set(limits[0])
        await m.high_limit_travel.set(limits[1])
        assert int(await _get(pv("cia402", "LVIO"))) == 1    # the record did refuse it

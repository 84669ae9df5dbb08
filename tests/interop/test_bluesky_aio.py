"""motorbus.ophyd on motorbus.aio: a bluesky plan moving 12 axes at once, with no executor.

A simulated bench of 12 axes of four kinds whose logic is awaitable: the
out-of-tree toy stepper and DMAC modules on two RS-485 lines (each line a pty
served by a line server), CiA 402 and PMC007 drives on one CAN bus served over
socketcand on 127.0.0.1; each axis an ophyd-async device.  One RunEngine plan sets
all 12 moving, reads every readback mid-move, stops two of them mid-move
(``bps.stop``: a toy stepper and a CiA 402 drive) and waits for the rest.
Asserted from outside (the simulators): the ten others stand on their targets,
the two stopped ones rest short of theirs and were moving when the stop came.
Asserted on the RunEngine's loop: its default executor was never made
(``run_in_executor`` is never called), no executor thread exists, and the link
workers (motorbus.faces) number no more than the links, fewer than the axes.
"""
from __future__ import annotations

import asyncio
import sys
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("ophyd_async")
pytest.importorskip("bluesky")

import bluesky.plan_stubs as bps  # noqa: E402
from bluesky import RunEngine  # noqa: E402
from bluesky.utils import FailedStatus  # noqa: E402
from ophyd_async.plan_stubs import ensure_connected  # noqa: E402

import motorbus  # noqa: E402
from motorbus import Bench, aio, faces, registry  # noqa: E402
from motorbus.ophyd import MotorbusMotor, devices_from_bench  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from drive_kinds import KINDS, OUT_OF_TREE  # noqa: E402  fast profiles, the simulators' shafts

pytestmark = pytest.mark.threaded

SCALE = 0.01                  # mm per native unit, every kind here
FAST = 5.0                    # mm: the ten axes that arrive
SLOW = 50.0                   # mm at SLOW_SPEED: the two stopped on the way (5 s if never stopped)
SLOW_SPEED = 10.0             # mm/s, through the device's velocity signal
#: (axis, kind, line or None, address): 4 toy steppers and 4 DMAC modules on two
#: lines, 2 CiA 402 and 2 PMC007 drives on one CAN bus.
AXES = ([(f"toy{a}", "toy", "ra", a) for a in "1234"] + [(f"dmac{a}", "dmac", "rb", a) for a in ("00", "01", "02", "03")]
        + [(f"cia{n}", "cia402", None, n) for n in (5, 6)] + [(f"pmc{n}", "pmc007", None, n) for n in (7, 8)])
STOPPED = ("toy3", "cia6")    # one on a line, one on the bus
EXECUTOR_THREADS = ("asyncio_", "ThreadPoolExecutor")


class _Params:
    """Collects what a kind's fast profile (drive_kinds.KINDS setup) writes."""

    def __init__(self) -> None:
        self.params: dict = {}


def _description() -> dict:
    data: dict = {"line": {"ra": {"port": "/dev/ttyUSB-ra"}, "rb": {"port": "/dev/ttyUSB-rb"}},
                  "bus": {"can0": {"spec": "socketcan:can0"}}, "axis": {}}    # sim=True serves ptys, socketcand
    for name, kind, line, address in AXES:
        profile = _Params()
        KINDS[kind].setup(profile)
        axis = {"kind": kind, "address": address, "units": {"name": "mm", "scale": SCALE},
                "params": profile.params}
        axis.update({"line": line} if line else {"bus": "can0"})
        if KINDS[kind].sim_options:
            axis["sim"] = dict(KINDS[kind].sim_options)
        data["axis"][name] = axis
    return data


@pytest.fixture(scope="module")
def bench():
    if not hasattr(motorbus._core, "toy"):
        pytest.skip("built without MOTORBUS_TESTS (the out-of-tree toy kind's C++ is not in _core)")
    with pytest.MonkeyPatch.context() as mp:
        mp.syspath_prepend(str(OUT_OF_TREE["toy"]))
        mp.setattr(registry, "_cache", {})       # the entry points read again, with the toy package's
        with Bench.from_dict(_description(), sim=True) as b:
            b.apply()
            for drive in b.axes.values():
                drive.clear_faults()
                drive.enable()
            yield b
            b.stop_all()


def _shaft(bench: Bench, name: str) -> float:
    """Where the axis stands, in mm, read on its simulator (not through any Drive)."""
    return KINDS[bench.config[name].kind].shaft(bench.sims[name]) * SCALE


def _at_rest(bench: Bench, name: str) -> float:
    """The shaft's position once it no longer moves (read twice, 0.1 s apart)."""
    at = _shaft(bench, name)
    for _ in range(50):
        time.sleep(0.1)
        now, at = at, _shaft(bench, name)
        if now == at:
            return at
    raise AssertionError(f"{name} still moves: {at}")


def _links_idle(timeout: float = 5.0) -> None:
    """Waits for link workers of earlier tests to end (they end after an idle second)."""
    deadline = time.monotonic() + timeout
    while faces.worker_threads() and time.monotonic() < deadline:
        time.sleep(0.05)


def _read_all(motors):
    """Every device's readback, read by the RunEngine (``bps.rd``)."""
    out = {}
    for name, m in motors.items():
        out[name] = yield from bps.rd(m)
    return out


def _stop_and_wait(motors):
    for name in STOPPED:
        yield from bps.stop(motors[name])
    yield from bps.wait("run")
    for name in STOPPED:        # one group each: a group's first failure ends bluesky's wait on it
        yield from bps.wait(name)
    yield from bps.null()        # where a failure still held by the RunEngine is thrown in


def _pardoning(plan, errors):
    """Runs ``plan``, collecting the FailedStatus the RunEngine throws into it instead of
    ending the run there (the stopped axes' statuses fail, as they should)."""
    response = None
    while True:
        try:
            msg = plan.send(response)
        except StopIteration as done:
            return done.value
        try:
            response = yield msg
        except FailedStatus as e:
            errors.append(e)
            response = None


@pytest.fixture
def RE():
    RE = RunEngine({}, call_returns_result=True)
    executor_calls: list = []
    real = RE.loop.run_in_executor

    def run_in_executor(*args, **kwargs):     # counted, then done, so a use shows up as a failure below
        executor_calls.append(args)
        return real(*args, **kwargs)

    RE.loop.run_in_executor = run_in_executor
    RE.executor_calls = executor_calls
    yield RE
    RE.loop.call_soon_threadsafe(RE.loop.stop)


def _links(bench: Bench) -> int:
    """How many links the bench's drives talk over in the awaitable face (each drive's
    ``io`` names the link its calls queue on: a serial line, a CANopen node's SDO client,
    a bus): the most link workers its 12 axes may use at once."""
    return len({id(d.io._link) for d in bench.axes.values()})


def test_twelve_axes_move_at_once_with_readbacks_and_a_mid_move_stop_and_no_executor(bench, RE):
    _links_idle()
    preexisting = {t.ident for t in threading.enumerate()}
    motors = devices_from_bench(bench)
    kinds = {bench.config[n].kind for n in motors}
    assert len(motors) == 12 and kinds == {"toy", "dmac", "cia402", "pmc007"}
    # Every kind's logic is awaitable (coroutine hooks over self.io), so nothing blocks the loop.
    for kind in kinds:
        assert asyncio.iscoroutinefunction(registry.drive_plugin(kind)._move_to), kind
    RE(ensure_connected(*motors.values()))
    start = {n: _shaft(bench, n) for n in motors}
    targets = {n: start[n] + (SLOW if n in STOPPED else FAST) for n in motors}
    threads_before = {t.ident for t in threading.enumerate()}
    seen: dict = {}

    def plan():
        statuses = {}
        for name in STOPPED:
            yield from bps.abs_set(motors[name].velocity, SLOW_SPEED, wait=True)
        for name, m in motors.items():
            statuses[name] = yield from bps.abs_set(m, targets[name], group=name if name in STOPPED else "run")
        yield from bps.sleep(0.5)
        # Readbacks while all of it runs: every device read on the loop, mid-move.
        seen["mid"] = yield from _read_all(motors)
        seen["at_stop"] = {n: _shaft(bench, n) for n in STOPPED}
        seen["links"] = faces.worker_threads()
        seen["threads"] = [t.name for t in threading.enumerate()]
        # executor threads this test did not find there (another module of this worker may
        # have left its own loop's executor thread behind: not the RunEngine's)
        seen["executors"] = [t.name for t in threading.enumerate()
                             if t.ident not in preexisting and t.name.startswith(EXECUTOR_THREADS)]
        seen["done_before_stop"] = [statuses[n].done for n in STOPPED]
        # The stopped moves fail their statuses: the RunEngine throws a FailedStatus in
        # at whichever message comes next, which _pardoning collects.
        yield from _pardoning(_stop_and_wait(motors), seen.setdefault("cut_errors", []))
        return statuses

    statuses = RE(plan()).plan_result
    end = RE(_read_all(motors)).plan_result

    # No executor: the loop's default executor was never made nor asked for, no executor
    # thread ran; the drive calls went to the link workers, one per link at most.
    assert RE.executor_calls == []
    assert RE.loop._default_executor is None
    assert seen["executors"] == []
    assert [t.name for t in threading.enumerate()
            if t.ident not in threads_before and t.name.startswith(EXECUTOR_THREADS)] == []
    assert 1 <= seen["links"] <= _links(bench) < len(motors), (seen["links"], _links(bench))
    assert len([n for n in seen["threads"] if n.startswith("motorbus-link-")]) == seen["links"]

    # The ten others arrived: the simulators stand on their targets, the readbacks say so.
    for name in motors:
        if name in STOPPED:
            continue
        assert statuses[name].done and statuses[name].success, name
        assert _at_rest(bench, name) == pytest.approx(targets[name], abs=SCALE / 2), name
        assert end[name] == pytest.approx(targets[name], abs=SCALE / 2), name

    # The stop arrived while the two moved: their statuses were still running, and the
    # shaft had gone on past the readback read a moment before.
    assert seen["done_before_stop"] == [False, False]
    for name in STOPPED:
        assert start[name] < seen["mid"][name] < seen["at_stop"][name] < targets[name], (name, seen)
    # They fail their statuses (the RunEngine throws in one FailedStatus of those that
    # failed between two messages: it keeps one) and rest short of the target, stopped
    # by this program's stop(), sent before ophyd-async cancelled the move (the
    # cancellation's own stop would name itself).
    failed = {id(e.args[0]) for e in seen["cut_errors"]}
    assert failed and failed <= {id(statuses[n]) for n in STOPPED}, seen["cut_errors"]
    for name in STOPPED:
        status = statuses[name]
        assert status.done and not status.success
        assert "was stopped" in str(status.exception())
        at = _at_rest(bench, name)
        assert seen["at_stop"][name] <= at < start[name] + SLOW / 2, (name, at)
        assert end[name] == pytest.approx(at, abs=SCALE / 2)
        last = bench[name].status.last_move
        assert last.state == "interrupted" and "stop() of this program" in last.reason, last



def _stopped_by_the_cancellation(bench: Bench, name: str, before: float) -> None:
    """The axis rests short of its slow move's target, stopped by the twin when the
    move's task was cancelled."""
    assert before < _at_rest(bench, name) < before + SLOW / 2
    last = bench[name].status.last_move
    assert last.state == "interrupted" and "cancellation" in last.reason, last


def test_devices_from_an_aio_bench_use_its_twins_and_a_cancelled_set_stops_the_motor(bench):
    """The devices of an aio.Bench go through the bench's own twins; cancelling the
    set's task (as a RunEngine abort does) stops the motor through the twin."""
    name = "pmc8"

    async def go():
        twins = aio.Bench(bench)
        motors = devices_from_bench(twins, [name])
        m = motors[name]
        assert list(motors) == [name] and m.twin is twins[name] and m.drive is bench[name]
        await m.connect()
        await m.velocity.set(SLOW_SPEED)
        before = await twins[name].position()
        assert await m.user_setpoint.get_value() == pytest.approx(before)    # read at connect
        status = m.set(before + SLOW)
        await asyncio.sleep(0.3)
        assert _shaft(bench, name) > before
        status.task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await status
        return before

    _stopped_by_the_cancellation(bench, name, asyncio.run(go()))


def test_a_stop_that_fails_still_ends_the_move(bench):
    """The device's stop raises the kind's error, and the move is cancelled all the same:
    the twin's cancellation stops the motor and the status ends."""
    name = "toy2"

    async def go():
        m = MotorbusMotor(bench[name], name=name, velocity=SLOW_SPEED)
        await m.connect()
        before = await m.twin.position()

        async def refused() -> None:
            raise motorbus.LinkDown("toy2: the line is gone (as the test says)")

        status = m.set(before + SLOW)
        await asyncio.sleep(0.3)
        m.twin.stop = refused
        with pytest.raises(motorbus.LinkDown, match="as the test says"):
            await m.stop()
        with pytest.raises(RuntimeError, match="was stopped"):
            await status
        return before

    _stopped_by_the_cancellation(bench, name, asyncio.run(go()))


def test_building_a_device_talks_to_nothing_and_any_loop_connects_it(bench):
    """No loop is taken and no exchange made when a device is built; two loops in turn
    each connect and read it."""
    closed = motorbus.open_drive("toy", line=bench.lines["ra"], address="1", units=motorbus.Units("mm", SCALE))
    closed.close()
    m = MotorbusMotor(closed, name="gone")        # built from a closed drive: nothing was asked of it
    with pytest.raises(motorbus.ClosedError):
        asyncio.run(m.connect())

    m = MotorbusMotor(bench["toy1"], name="toy1")
    for _ in range(2):                            # two loops, one after the other

        async def read():
            await m.connect(force_reconnect=True)
            return await m.user_readback.get_value()

        assert asyncio.run(read()) == pytest.approx(_shaft(bench, "toy1"), abs=SCALE / 2)


@pytest.mark.parametrize("what", [None, "x", 3.0])
def test_a_device_needs_a_drive(what):
    with pytest.raises(motorbus.InvalidArgument, match="motorbus.Drive or motorbus.aio.Drive"):
        MotorbusMotor(what)
    with pytest.raises(motorbus.InvalidArgument, match="motorbus.Bench or motorbus.aio.Bench"):
        devices_from_bench(what)

"""The Drive API awaited (motorbus.aio): test_drive_api.py's cases, every kind through
its served simulator (serial kinds on a pty, CAN kinds behind socketcand on
127.0.0.1), plus what only the awaitable face has: a cancelled move stops the
motor, 1 000 awaits at once on one loop, two loops in two threads.

Every awaited call runs the same coroutine logic as the blocking face
(motorbus.faces); a guard on each drive's native client fails the test if a
hook still calls the drive directly on the event loop's thread (a blocking call
that would freeze every other axis), apart from plain attributes with no exchange.
"""
from __future__ import annotations

import asyncio
import threading
import time
from typing import Any

import pytest

import motorbus
from motorbus import Units, aio, faces

from drive_kinds import KINDS, kind, rig  # noqa: F401  (fixtures)

# Served simulators only (the way a bench is wired); the in-process links are the
# blocking tests' business.
pytestmark = pytest.mark.parametrize("rig", ["transport"], indirect=True)

#: Native attributes a hook may read on the loop thread: plain data, no exchange.
PLAIN = {"address", "node_id", "link", "kind", "model", "table"}


class LoopThreadGuard:
    """Stands in for ``drive.native`` and records every attribute a hook reads on the
    loop's thread while an awaited call runs (the awaitable face), so the test can
    say which exchange would have blocked the loop.  ``drive.io`` keeps the real client
    (its calls run on the link's worker)."""

    def __init__(self, native: Any) -> None:
        object.__setattr__(self, "_native", native)
        object.__setattr__(self, "on_loop", set())

    def __getattr__(self, name: str) -> Any:
        if not faces.blocking() and name not in PLAIN:
            try:
                asyncio.get_running_loop()
                self.on_loop.add(name)
            except RuntimeError:
                pass
        return getattr(self._native, name)

    def __setattr__(self, name: str, value: Any) -> None:
        if not faces.blocking():
            self.on_loop.add(name + "=")
        setattr(self._native, name, value)


@pytest.fixture
def axis(rig, kind):
    """The awaitable twin of the rig's drive, its native client guarded."""
    guard = LoopThreadGuard(rig.drive.native)
    rig.drive.native = guard
    twin = aio.Drive(rig.drive, stop_timeout=10.0)
    yield twin
    rig.drive.native = guard._native
    assert not guard.on_loop, f"{kind.kind}: native calls made on the event loop's thread: {sorted(guard.on_loop)}"


async def test_enable_move_to_in_user_units_and_read_back(axis, kind):
    assert axis.kind == kind.kind and axis.units == Units("mm", kind.scale)
    kind.setup(axis.sync)
    await axis.enable()
    assert (await axis.status()).enabled
    await axis.move_to(12.34, timeout=10)
    assert await axis.position() == pytest.approx(12.34, abs=kind.scale)
    st = await axis.status()
    assert not st.moving and st.at_target and not st.fault and st.last_move.ok
    await axis.move_by(-2.34, timeout=10)
    assert await axis.position() == pytest.approx(10.0, abs=kind.scale)


async def test_jog_then_stop(axis, kind):
    kind.setup(axis.sync)
    await axis.enable()
    start = await axis.position()
    await axis.jog(kind.jog)
    deadline = time.monotonic() + 5
    while await axis.velocity() < kind.jog * 0.9:
        assert time.monotonic() < deadline, "never reached the jog speed"
        await asyncio.sleep(0.01)
    assert (await axis.status()).moving
    await axis.stop()
    await axis.wait_idle(timeout=10)
    assert await axis.velocity() == 0
    assert await axis.position() > start


async def test_home(axis, kind):
    kind.setup(axis.sync)
    await axis.enable()
    await axis.home(kind.home, timeout=20)
    st = await axis.status()
    assert st.homed and not st.fault
    assert await axis.position() == pytest.approx(0.0, abs=kind.scale)


async def test_an_exception_inside_async_with_stops_the_motor(axis, kind, rig):
    kind.setup(axis.sync)
    await axis.enable()
    with pytest.raises(RuntimeError, match="script failed"):
        async with axis:
            await axis.jog(kind.jog)
            await asyncio.sleep(0.05)
            raise RuntimeError("script failed")
    assert axis.closed
    other = rig.reopen()                 # seen from another Drive object: it comes to rest
    other.wait_idle(timeout=5)
    assert other.velocity == 0


async def test_fault_then_clear_faults(axis, kind, rig):
    kind.setup(axis.sync)
    await axis.enable()
    kind.fault(rig.sim, axis.sync)
    deadline = time.monotonic() + 5
    while not (await axis.status()).fault:
        assert time.monotonic() < deadline, "the drive never reported the fault"
        await asyncio.sleep(0.01)
    with pytest.raises(motorbus.DriveFault):
        await axis.move_to(2.0, timeout=5)
    kind.unfault(rig.sim)
    await axis.clear_faults()
    assert not (await axis.status()).fault
    await axis.enable()
    await axis.move_to(1.0, timeout=10)
    assert await axis.position() == pytest.approx(1.0, abs=kind.scale)


async def test_params_get_set(axis, kind):
    await axis.params.set(kind.param, kind.value)
    assert await axis.params.get(kind.param) == kind.value
    assert kind.param in axis.params and len(axis.params) > 3
    with pytest.raises(KeyError):
        await axis.params.get("NO_SUCH_PARAMETER")
    info = axis.params.describe(kind.param)
    if info.maximum is not None:
        with pytest.raises(motorbus.InvalidArgument, match=r"outside"):
            await axis.params.set(kind.param, info.maximum + 1)
        assert await axis.params.get(kind.param) == kind.value


async def _moving(axis: aio.Drive) -> None:
    deadline = time.monotonic() + 5
    while not (await axis.status()).moving:
        assert time.monotonic() < deadline, "the move never started"
        await asyncio.sleep(0.005)


def here_short_of(kind: Any, rig: Any) -> bool:
    """The simulator's shaft (read from outside) stands short of the kind's far target."""
    return kind.shaft(rig.sim) * kind.scale < kind.far


async def _cancel_once_moving(axis: aio.Drive, kind: Any, target: float, **options: Any) -> None:
    """Starts an awaited move to ``target``, cancels its task once the drive moves, and
    checks that the await ends in CancelledError."""
    kind.setup(axis.sync)
    await axis.enable()
    move = asyncio.create_task(axis.move_to(target, timeout=60, **options))
    await _moving(axis)
    move.cancel()
    with pytest.raises(asyncio.CancelledError):
        await move


async def test_cancelling_an_awaited_move_stops_the_motor(axis, kind, rig):
    await _cancel_once_moving(axis, kind, kind.far)
    # When the CancelledError arrives the shaft is already at rest, seen from outside
    # (the simulator itself, not a drive object), and stays there, short of the target.
    here = kind.shaft(rig.sim)
    await asyncio.sleep(0.1)
    assert kind.shaft(rig.sim) == here
    assert here_short_of(kind, rig)
    last = (await axis.status()).last_move
    assert last.state == "interrupted" and "cancellation" in last.reason
    await axis.move_to(1.0, timeout=20)                 # the axis takes the next move
    assert await axis.position() == pytest.approx(1.0, abs=kind.scale)


async def test_readbacks_while_a_move_starts_do_not_judge_it(axis, kind):
    """Another task reading the status while the move's command is still on its way sees
    a drive at rest that has not started yet: that must not end the move as interrupted."""
    kind.setup(axis.sync)
    await axis.enable()
    move = asyncio.create_task(axis.move_to(5.0, timeout=30))
    seen = set()
    while not move.done():
        last = (await axis.status()).last_move
        seen.add(None if last is None else last.state)
    await move
    assert seen <= {None, "running", "done"}, seen
    assert (await axis.status()).last_move.state == "done"
    assert await axis.position() == pytest.approx(5.0, abs=kind.scale)


async def test_stop_on_cancel_false_leaves_the_motor_going(axis, kind, rig):
    await _cancel_once_moving(axis, kind, 60.0, stop_on_cancel=False)
    here = kind.shaft(rig.sim)
    await asyncio.sleep(0.1)
    assert kind.shaft(rig.sim) != here              # fire-and-forget, as asked: still turning
    await axis.wait_idle(timeout=30)
    assert await axis.position() == pytest.approx(60.0, abs=kind.scale)


@pytest.mark.parametrize("kind", ["toy"], indirect=True)
async def test_a_cancelled_move_not_at_rest_within_stop_timeout_is_recorded_as_still_moving(axis, kind, rig):
    """The toy's STOP ramps down over about half a second: with no time allowed for rest
    the outcome must say the motor was still moving, not judge a shaft still turning."""
    axis.stop_timeout = 0.0
    await _cancel_once_moving(axis, kind, kind.far)
    last = (await axis.status()).last_move
    assert last.state == "timeout" and "no rest within 0 s" in last.reason, last
    assert "still moving at" in str(last.error)
    await axis.wait_idle(timeout=10)                    # the stop was sent: it does come to rest
    assert here_short_of(kind, rig)


async def test_a_thousand_awaits_at_once(axis, kind):
    kind.setup(axis.sync)
    await axis.enable()
    await axis.move_to(3.0, timeout=10)
    before = threading.active_count()
    readings = await asyncio.gather(*(axis.position() if i % 2 else axis.status() for i in range(1000)))
    assert all(r == pytest.approx(3.0, abs=kind.scale) for r in readings[1::2])
    assert all(not s.moving for s in readings[0::2])
    assert threading.active_count() <= before + 1      # at most the link's worker, never a thread per await


def test_two_loops_in_two_threads(rig, kind):
    """Two event loops, each in its own thread, awaiting readings of one Drive at once
    (twins made in each loop and one made outside both): the loop is taken when a call
    is awaited, so no object belongs to a loop."""
    kind.setup(rig.drive)
    rig.drive.enable()
    shared = aio.Drive(rig.drive)
    results: dict = {}

    def run(name: str, drive: Any) -> None:
        async def main() -> None:
            twin = aio.Drive(drive) if name == "a" else shared
            results[name] = [await twin.position() for _ in range(20)], (await twin.status()).enabled
        try:
            asyncio.run(main())
        except BaseException as e:  # noqa: BLE001 - reported below
            results[name] = e

    threads = [threading.Thread(target=run, args=(n, d)) for n, d in (("a", rig.drive), ("b", rig.drive))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    assert set(results) == {"a", "b"}
    for name, got in results.items():
        assert not isinstance(got, BaseException), f"loop {name}: {got!r}"
        positions, enabled = got
        assert len(positions) == 20 and enabled

"""Every kind x every outcome a move can have, against simulators served by another process.

One served twin (``motorbus sim serve --bench FILE --control``) per test, so a fault injected
in one test cannot leak into the next.  The test process opens the bench file the service
wrote (ptys, socketcand on 127.0.0.1), starts a long move, provokes one outcome in the
serving process (its ``sim_faults``), from a second process (``motorbus stop``) or from this
one, and asserts the typed error, its reason and the position reached.  The outcomes a kind
cannot produce are skipped with the reason (its docs page says the same).
"""
from __future__ import annotations

import math
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import motorbus
from motorbus import faces, registry
from motorbus.drive import (LimitReached, MoveFailed, MoveFaulted, MoveInterrupted, MoveStalled,
                            MoveTimedOut)

sim = pytest.importorskip("motorbus.sim")
ServedBench = getattr(sim, "ServedBench", None)
pytestmark = [pytest.mark.timeout(120),
              pytest.mark.skipif(ServedBench is None, reason="motorbus.sim.ServedBench not available")]

KINDS = sorted(registry.drive_kinds())
#: Native units several seconds of travel away at each kind's default speed (others: 100 000).
FAR: dict = {"unitek": 20_000_000}


def window(axis) -> float:
    """The kind's in-position window (its hook: a coroutine where it reads the drive)."""
    async def read() -> float:
        value = axis._in_position_window()
        return await value if hasattr(value, "__await__") else value
    return faces.run(read())


#: outcome -> (the sim_faults name that provokes it, the error expected)
INJECTED = {
    "limit": ("limit", LimitReached),
    "fault": ("fault", MoveFaulted),
    "stall": ("stall", MoveStalled),
    "stop_input": ("stop_input", MoveInterrupted),
}
OUTCOMES = ["done", *INJECTED, "stop_here", "stop_other_process", "timeout"]


def bench_text(kind: str) -> str:
    """A bench file with one axis of ``kind`` (native units), as a user would write it."""
    plugin = registry.drive_plugin(kind)
    address = plugin.default_address
    addr = f'"{address}"'
    if plugin.transport == "serial":
        link = '[line.l]\nport = "/dev/null"\n'
        where = 'line = "l"'
    else:
        link = '[bus.b]\nspec = "virtual:outcomes"\n'
        where = 'bus = "b"'
    extra = 'sim = { calibrated = true }\n' if kind == "unitek" else ""
    return f'{link}\n[axis.a]\nkind = "{kind}"\n{where}\naddress = {addr}\n{extra}'


@pytest.fixture
def served(tmp_path):
    def start(kind: str):
        src = tmp_path / "bench.toml"
        src.write_text(bench_text(kind))
        return ServedBench(src)
    opened = []

    def factory(kind):
        s = start(kind)
        opened.append(s)
        return s
    yield factory
    for s in opened:
        s.close()


def far_target(drive) -> float:
    """A target several seconds of travel away at the drive's own speed (user = native units)."""
    return drive.position + FAR.get(drive.kind, 100_000)


def open_axis(served):
    bench = motorbus.Bench.load(served.bench_file)
    axis = bench["a"]
    axis.clear_faults()
    axis.enable()
    return bench, axis


def wait_until_moving(axis, away_from: float, deadline: float = 5.0) -> None:
    t_end = time.monotonic() + deadline
    while time.monotonic() < t_end:
        if abs(axis.position - away_from) > 50:
            return
        time.sleep(0.02)
    raise AssertionError(f"{axis.kind}: the move did not start")


@pytest.mark.parametrize("outcome", OUTCOMES)
@pytest.mark.parametrize("kind", KINDS)
def test_a_move_ends_at_its_target_or_raises_why(served, kind, outcome):
    plugin = registry.drive_plugin(kind)
    faults = plugin.sim_faults()
    if outcome in INJECTED and INJECTED[outcome][0] not in faults:
        pytest.skip(f"the {kind} simulator cannot produce {outcome!r} (its docs page says how a move ends there)")
    if outcome == "stop_other_process" and plugin.transport == "serial":
        pytest.skip(f"{kind}: a serial line carries one conversation, a second process cannot open it "
                    "(a stop from elsewhere on the line is tested in test_outcomes_serial.py)")
    twin = served(kind)
    bench, axis = open_axis(twin)
    with bench:
        start = axis.position
        if outcome == "done":
            target = start + 2000
            axis.move_to(target, timeout=30)
            assert abs(axis.position - target) <= max(window(axis), 0) + 1e-9
            last = axis.status.last_move
            assert last.ok and last.target == pytest.approx(target)
            return
        target = far_target(axis)
        if outcome == "timeout":
            with pytest.raises(MoveTimedOut) as failed:
                axis.move_to(target, timeout=0.5)
            assert isinstance(failed.value, motorbus.TimeoutError)
        else:
            axis.move_to(target, wait=False)
            wait_until_moving(axis, start)
            if outcome in INJECTED:
                name, error = INJECTED[outcome]
                options = {"direction": 1} if outcome == "limit" else {}
                twin.inject("a", name, **options)
            elif outcome == "stop_here":
                error = MoveInterrupted
                threading.Timer(0.05, axis.stop).start()
            else:   # another process stops the axis through the same served transport
                error = MoveInterrupted
                out = subprocess.run([sys.executable, "-m", "motorbus", "stop", str(twin.bench_file), "a"],
                                     capture_output=True, text=True, timeout=60)
                assert out.returncode == 0, out.stderr
            with pytest.raises(MoveFailed) as failed:
                axis.wait_idle(timeout=30)
            assert type(failed.value) is error or isinstance(failed.value, error), repr(failed.value)
        e = failed.value
        # Where it stopped: past the start, short of the target, and what the drive reads now.
        assert start < e.position < target, (start, e.position, target)
        if outcome != "timeout":
            assert e.position == pytest.approx(axis.position, abs=max(1.0, window(axis)))
        assert e.target == pytest.approx(target)
        assert e.reason and e.axis == "a"
        assert str(e).startswith("a: ")
        if outcome == "limit":
            assert e.side in (1, 0)
        last = axis.status.last_move
        assert last is not None and not last.ok and last.state == e.outcome
        assert not axis.status.at_target
        axis.stop()

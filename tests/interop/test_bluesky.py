"""A real bluesky RunEngine scanning the simulated bench through motorbus.ophyd.

One bench, simulated behind the transports a real one uses (an Arcus on a pty,
CiA 402 and the other CAN kinds on a virtual bus served over socketcand on
127.0.0.1), one axis of every registered kind; each axis an ophyd-async device
from ``devices_from_bench``.  The documents a ``scan`` emits are compared with
the scan points and with the simulators' own positions.
"""
from __future__ import annotations

import math
import sys
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("ophyd_async")
bluesky = pytest.importorskip("bluesky")

import bluesky.plan_stubs as bps  # noqa: E402
from bluesky import RunEngine  # noqa: E402
from bluesky.plans import scan  # noqa: E402
from bluesky.run_engine import call_in_bluesky_event_loop  # noqa: E402
from bluesky.utils import FailedStatus, RunEngineInterrupted  # noqa: E402
from ophyd_async.plan_stubs import ensure_connected  # noqa: E402

import motorbus  # noqa: E402
from motorbus import Bench, registry  # noqa: E402
from motorbus.drives.arcus import ArcusMotorDisabled  # noqa: E402
from motorbus.ophyd import MotorbusMotor, MoveLimitError, devices_from_bench  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from drive_kinds import KINDS, OUT_OF_TREE  # noqa: E402  per-kind address, scale, fast profile, sim options

pytestmark = pytest.mark.threaded


class _Params:
    """Collects what a KINDS setup() writes, to put it in the bench description."""

    def __init__(self) -> None:
        self.params: dict = {}


def _bench_description() -> dict:
    """One axis of every registered kind: serial kinds each on a line, CAN kinds on one bus."""
    data: dict = {"bus": {"can0": {"spec": "socketcan:can0"}}, "line": {}, "axis": {}}
    taken: set = set()
    for kind in sorted(registry.drive_kinds()):
        k = KINDS[kind]
        plugin = registry.drive_plugin(kind)
        name = kind.replace("-", "_")
        address = k.address
        if plugin.transport == "can" and address.isdigit():   # two kinds may share a default node-ID
            node = int(address)
            while node in taken:
                node += 1
            taken.add(node)
            address = str(node)
        captured = _Params()
        k.setup(captured)
        axis = {"kind": kind, "address": address, "units": {"name": "mm", "scale": k.scale},
                "params": captured.params}
        if plugin.transport == "serial":
            data["line"][name] = {"port": f"/dev/ttyUSB-{name}"}
            axis["line"] = name
        else:
            axis["bus"] = "can0"
        if k.sim_options:
            axis["sim"] = dict(k.sim_options)
        if k.open_options:
            axis["options"] = dict(k.open_options)
        data["axis"][name] = axis
    return data


@pytest.fixture(scope="module")
def bench():
    with Bench.from_dict(_bench_description(), sim=True) as b:
        b.apply()
        yield b


@pytest.fixture
def motors(bench):
    for drive in bench.axes.values():
        drive.clear_faults()
        drive.enable()
    devices = devices_from_bench(bench)
    yield devices
    bench.stop_all()
    for drive in bench.axes.values():
        drive.wait_idle(timeout=10)


@pytest.fixture(scope="module")
def RE():
    return RunEngine({}, call_returns_result=True)


def _run(RE, plan):
    """Runs a plan, returning its documents as (name, doc) pairs."""
    docs: list = []
    RE(plan, lambda name, doc: docs.append((name, doc)))
    return docs


def _step(drive) -> float:
    return abs(drive.units.scale)


def test_the_bench_has_the_axes_the_issue_asks_for(bench, motors):
    kinds = {d.kind for d in bench.axes.values()}
    assert {"arcus", "cia402"} <= kinds
    assert kinds == set(registry.drive_kinds())
    assert set(motors) == set(bench)
    for name, m in motors.items():
        assert isinstance(m, MotorbusMotor) and m.name == name and m.drive is bench[name]


@pytest.mark.parametrize("axis", sorted(k.replace("-", "_") for k in KINDS if k not in OUT_OF_TREE))
def test_scan_readings_are_the_scan_points(bench, motors, RE, axis):
    motor = motors[axis]
    other = next(n for n in motors if n != axis)     # a second axis' readback as the detector
    detector = motors[other]
    RE(ensure_connected(*motors.values()))
    start = bench[axis].position
    points = [start + p for p in (1.0, 1.5, 2.0, 2.5, 3.0)]
    docs = _run(RE, scan([detector], motor, points[0], points[-1], len(points)))

    names = [n for n, _ in docs]
    assert names[0] == "start" and names[-1] == "stop"
    assert docs[-1][1]["exit_status"] == "success"
    descriptor = next(d for n, d in docs if n == "descriptor")
    assert descriptor["data_keys"][axis]["units"] == "mm"
    assert descriptor["data_keys"][axis]["source"]
    config = descriptor["configuration"][axis]["data"]
    assert config[f"{axis}-motor_egu"] == "mm"
    assert config[f"{axis}-low_limit_travel"] == -math.inf and config[f"{axis}-high_limit_travel"] == math.inf

    events = [d for n, d in docs if n == "event"]
    assert len(events) == len(points)
    step = _step(bench[axis])
    for event, point in zip(events, points):
        assert event["data"][axis] == pytest.approx(point, abs=step)
        assert event["data"][other] == pytest.approx(bench[other].position, abs=_step(bench[other]))
    # The simulator itself stands on the last point, at rest.
    assert bench[axis].position == pytest.approx(points[-1], abs=step)
    assert not bench[axis].status.moving


def test_mv_and_rd(bench, motors, RE):
    x, z = motors["arcus"], motors["cia402"]
    RE(ensure_connected(x, z))
    RE(bps.mv(x, 4.25, z, -3.5))
    assert bench["arcus"].position == pytest.approx(4.25, abs=0.01)
    assert bench["cia402"].position == pytest.approx(-3.5, abs=0.01)

    assert RE(bps.rd(x)).plan_result == pytest.approx(4.25, abs=0.01)
    location = RE(bps.locate(x)).plan_result
    assert location["setpoint"] == 4.25
    assert location["readback"] == pytest.approx(4.25, abs=0.01)


def test_a_failed_plan_stops_the_motor_it_moved(bench, motors, RE):
    """The RunEngine stops every device it set when a plan fails mid-move."""
    z = motors["cia402"]
    sim_drive = bench["cia402"]
    sim_drive.params["0x6081"] = 500          # slow: 5 mm/s, so the move is still on when the plan fails
    RE(ensure_connected(z))
    start = sim_drive.position

    def plan():
        yield from bps.abs_set(z, start + 50.0, wait=False)
        yield from bps.sleep(0.3)
        raise RuntimeError("plan failed mid-move")

    try:
        with pytest.raises(RuntimeError, match="plan failed mid-move"):
            RE(plan())
        try:        # the move's own wait (on the device's thread) may have judged it first
            sim_drive.wait_idle(timeout=5)
        except motorbus.MoveInterrupted as e:
            assert "stop() of this program" in str(e)
        assert sim_drive.status.last_move.state == "interrupted"   # the stop cut the move short
        at = sim_drive.position
        assert start < at < start + 10.0, at     # stopped on the way, far from the target
        time.sleep(0.2)
        assert not sim_drive.status.moving
        assert sim_drive.position == at          # and it stays there
    finally:
        sim_drive.params["0x6081"] = 20000


def test_abort_from_a_pause_stops_the_motor(bench, motors, RE):
    """Ctrl-C's path: a pause requested mid-move stops the motor; abort ends the run."""
    import threading

    x = motors["arcus"]
    drive = bench["arcus"]
    drive.params["HSPD"] = 500                # 5 mm/s
    RE(ensure_connected(x))
    start = drive.position
    timer = threading.Timer(0.3, RE.request_pause, kwargs={"defer": False})
    try:
        timer.start()
        with pytest.raises(RunEngineInterrupted):      # the first point is far: paused while moving there
            RE(scan([], x, start + 40.0, start + 41.0, 2))
        assert RE.state == "paused"
        RE.abort("test")
        try:        # the move's own wait may have judged it first
            drive.wait_idle(timeout=5)
        except motorbus.MoveInterrupted:
            pass
        assert drive.status.last_move.state == "interrupted"
        assert not drive.status.moving
        assert start < drive.position < start + 10.0
    finally:
        timer.cancel()
        drive.params["HSPD"] = 20000


def test_stop_on_the_device_stops_the_axis(bench, motors):
    import asyncio

    z = motors["cia402"]
    drive = bench["cia402"]
    drive.params["0x6081"] = 500

    async def go():
        await z.connect()
        status = z.set(drive.position + 50.0)
        await asyncio.sleep(0.2)
        assert drive.status.moving
        await z.stop(success=False)
        with pytest.raises(RuntimeError, match="was stopped"):
            await status
        return status

    try:
        status = asyncio.run(go())
        assert status.done and not status.success
        try:
            drive.wait_idle(timeout=5)
        except motorbus.MoveInterrupted:
            pass
        assert not drive.status.moving
    finally:
        drive.params["0x6081"] = 20000


@pytest.mark.parametrize("axis,error", [("arcus", ArcusMotorDisabled), ("cia402", motorbus.DriveFault)])
def test_a_move_the_drive_refuses_fails_the_status_with_its_error(bench, motors, RE, axis, error):
    m = motors[axis]
    RE(ensure_connected(m))
    bench[axis].disable()
    before = bench[axis].position
    with pytest.raises(FailedStatus) as failed:
        RE(bps.mv(m, before + 5.0))
    cause = failed.value.__cause__
    assert isinstance(cause, error), repr(cause)
    assert "enable" in str(cause)
    assert bench[axis].position == before


def test_a_target_beyond_the_drives_soft_limit_fails_before_moving(bench, motors, RE):
    dmac = bench["dmac"]
    m = motors["dmac"]
    RE(ensure_connected(m))
    dmac.params["#NEGATIVE_END"] = -1000     # increments (1/10000 rev): -10 mm at 0.01 mm each
    dmac.params["#POSITIVE_END"] = 2000
    dmac.native.soft_ends(True)
    try:
        assert dmac.travel_limits == pytest.approx((-10.0, 20.0))
        before = dmac.position
        with pytest.raises(FailedStatus) as failed:
            RE(bps.mv(m, 25.0))
        assert isinstance(failed.value.__cause__, MoveLimitError)
        assert "[-10, 20] mm" in str(failed.value.__cause__)
        assert dmac.position == before and not dmac.status.moving
        cfg = call_in_bluesky_event_loop(m.read_configuration())
        assert cfg["dmac-low_limit_travel"]["value"] == pytest.approx(-10.0)
        assert cfg["dmac-high_limit_travel"]["value"] == pytest.approx(20.0)
    finally:
        dmac.native.soft_ends(False)
    assert dmac.travel_limits == (-math.inf, math.inf)




def test_a_move_stopped_by_a_limit_fails_the_status_with_limit_reached(bench, motors, RE):
    """The Drive API's outcome reaches the RunEngine: a limit switch mid-move fails the
    status with LimitReached (its side, where it stopped), not a success."""
    z = motors["cia402"]
    drive = bench["cia402"]
    drive.params["0x6081"] = 500              # slow: the limit closes while it moves
    RE(ensure_connected(z))
    start = drive.position
    faults = registry.drive_plugin("cia402").sim_faults()
    timer = threading.Timer(0.3, faults["limit"], args=(bench.sims["cia402"],), kwargs={"direction": 1})
    try:
        timer.start()
        with pytest.raises(FailedStatus) as failed:
            RE(bps.mv(z, start + 40.0))
        cause = failed.value.__cause__
        assert isinstance(cause, motorbus.LimitReached), repr(cause)
        assert cause.side == 1 and start < cause.position < start + 40.0
        assert cause.target == pytest.approx(start + 40.0)
    finally:
        timer.cancel()
        drive.params["0x6081"] = 20000
        bench.sims["cia402"].force_limit(1, False)     # the switch opens again
        drive.clear_faults()
        drive.enable()
        drive.move_to(start, timeout=30)

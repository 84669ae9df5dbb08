"""The PMC007 Drive awaited (motorbus.aio) for what only this kind does, through simulators
served behind socketcand on 127.0.0.1 (real time): a cancelled homing leaves speed mode
and its 6003h is put back; a move refused with abort 08000022 names the status read on the
bus's worker; the velocity (two 600Ch samples a window apart) sleeps the task, not the
loop; two nodes on one bus share its worker and move at once.  The Drive API's common
cases awaited for every kind are test_aio_drive.py's."""
from __future__ import annotations

import asyncio
import time

import pytest

import motorbus
from motorbus import aio
from motorbus.sim import SimBench

pytestmark = pytest.mark.threaded


@pytest.fixture
def served():
    """Two simulated PMC007 (nodes 5 and 6) on one bus served by socketcand; the bus spec."""
    with SimBench(["pmc007:5,6"]) as bench:
        srv = bench.can.servers[0]
        yield bench, f"socketcand:{srv.host}:{srv.port}/can0"


async def _until(condition, what: str, seconds: float = 5.0) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < deadline, what
        await asyncio.sleep(0.005)


async def test_a_cancelled_homing_leaves_speed_mode_and_puts_6003h_back(served):
    bench, spec = served
    sim = bench.sims[("pmc007", "5")]
    x = await aio.open_drive("pmc007", bus=spec, address=5, home_speed=2000)
    async with x:
        await x.params.set("maximum_speed", 20000)
        await x.params.set("motor_position", 4000)   # 5000 steps from the EXT1 switch (below -1000)
        await x.enable()
        task = asyncio.create_task(x.home("ext1", timeout=10))
        await _until(lambda: sim.position < 3800, "the homing never started")
        task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await task
        # At rest, seen from the simulator, short of the switch: the stop left speed mode.
        assert not sim.busy and sim.velocity == 0
        here = sim.position
        await asyncio.sleep(0.1)
        assert sim.position == here and -1000 < here < 3800
        assert await x.params.get("operation_mode") == 0
        assert not (await x.status()).homed
        # The next move settles the homing: 6003h is the drive's own again, and the move
        # runs at it to its target.
        await x.move_to(here + 500, timeout=10)
        assert await x.params.get("maximum_speed") == 20000
        assert sim.position == here + 500 and (await x.status()).last_move.ok


async def test_a_refused_move_names_the_status_read_on_the_worker(served):
    bench, spec = served
    sim = bench.sims[("pmc007", "5")]
    x = await aio.open_drive("pmc007", bus=spec, address=5)
    async with x:
        await x.enable()
        sim.inject_error(1)                          # UVLO: the drive refuses steps (08000022)
        with pytest.raises(motorbus.DriveFault, match=r"move refused \(08000022\): 6000h 0x01 \(UVLO\), "
                                                      r"6001h 0x00 \(none\), enabled=True"):
            await x.move_by(300)
        assert sim.position == 0 and (await x.status()).last_move is None
        await x.clear_faults()
        await x.move_by(300, timeout=10)
        assert sim.position == 300


async def test_velocity_sleeps_the_task_not_the_loop(served):
    bench, spec = served
    sim = bench.sims[("pmc007", "5")]
    x = await aio.open_drive("pmc007", bus=spec, address=5)
    async with x:
        x.sync.velocity_window = 0.2                 # long enough to count the loop's ticks in it
        await x.params.set("maximum_speed", 2000)
        await x.enable()
        await x.jog(2000)
        await _until(lambda: sim.velocity == 2000, "the jog never reached its speed")
        ticks = 0

        async def tick() -> None:
            nonlocal ticks
            while True:
                await asyncio.sleep(0.01)
                ticks += 1

        ticker = asyncio.create_task(tick())
        try:
            v = await x.velocity()
        finally:
            ticker.cancel()
        assert v == pytest.approx(2000, rel=0.2)
        assert ticks >= 5                            # a blocking sleep would have let none run
        await x.stop()
        await _until(lambda: not sim.busy, "the jog did not stop")
        assert await x.velocity() == 0.0


async def test_two_nodes_on_one_bus_share_its_worker_and_move_at_once(served):
    bench, spec = served
    sims = [bench.sims[("pmc007", "5")], bench.sims[("pmc007", "6")]]
    bus = motorbus.open_bus(spec)
    try:
        axes = [await aio.open_drive("pmc007", bus=bus, address=a) for a in (5, 6)]
        # One worker for the bus: the two nodes' SDO transfers queue there as on the wire.
        assert axes[0].sync.io._link is bus and axes[1].sync.io._link is bus
        for x in axes:
            await x.params.set("maximum_speed", 20000)
            await x.enable()
        await asyncio.gather(axes[0].move_to(3000, timeout=10), axes[1].move_to(-1500, timeout=10))
        assert [s.position for s in sims] == [3000, -1500]
        readings = await asyncio.gather(*(x.position() for _ in range(200) for x in axes))
        assert set(readings[0::2]) == {3000.0} and set(readings[1::2]) == {-1500.0}
        for x in axes:
            await x.aclose()
    finally:
        bus.close()

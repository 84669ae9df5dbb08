"""The CiA 402 kinds (cia402, arcus-canopen) awaited through motorbus.aio: what only
these kinds do, beyond test_aio_drive.py's cases for every kind.  Each simulator is
served over socketcand on 127.0.0.1 and opened as a bench opens it; the shaft is read
from the simulator itself.

* the outcomes' reasons need SDO reads after the motor stopped (603Fh, 60FDh, 607Dh,
  2003h): awaited, they are the blocking face's;
* a cancelled move is halted, and the 6081h its ``velocity=`` changed is written back;
  a cancelled homing leaves the axis at rest and not homed;
* two nodes of one bus move at once under ``gather``, and a node that does not answer
  holds up no other node's exchanges (each node's own SDO channel and worker);
* ``aio.Bench.move_together`` starts two cia402 nodes on one SYNC;
* the DMX-CAN's 200Eh store handshake (its client polls for 0.1 s) leaves the loop free.
"""
from __future__ import annotations

import asyncio
import time

import pytest

import motorbus
from motorbus import aio, registry
from motorbus.drive import LimitReached, MoveStalled
from motorbus.sim import SimBench

ADDRESS = {"cia402": "5", "arcus-canopen": "1"}
FAR = 200_000          # native units, several seconds away at 20 000/s


def shaft(kind: str, sim) -> int:
    """Where the simulated motor is, read from the simulator (not through a drive object)."""
    return sim.position if kind == "cia402" else sim.pulse_position


class Rig:
    def __init__(self, kind: str, bench: SimBench, address: str) -> None:
        self.kind = kind
        self.sim = bench.sims[(kind, address)]
        srv = bench.can.servers[0]
        self.drive = motorbus.open_drive(kind, bus=f"socketcand:{srv.host}:{srv.port}/can0", address=address)
        self.twin = aio.Drive(self.drive, stop_timeout=10.0)
        self.faults = registry.drive_plugin(kind).sim_faults()

    def shaft(self) -> int:
        return shaft(self.kind, self.sim)


def _profile(d) -> None:
    d.params["0x6081"] = 20000
    if d.kind == "cia402":
        d.params["0x6083"] = d.params["0x6084"] = 100000
    else:
        d.params["0x6083"] = d.params["0x6084"] = 20       # ms (manual 000: accelerations are times)


@pytest.fixture(params=sorted(ADDRESS))
def rig(request):
    kind = request.param
    with SimBench([f"{kind}:{ADDRESS[kind]}"]) as bench:
        r = Rig(kind, bench, ADDRESS[kind])
        r.drive.enable()
        _profile(r.drive)
        try:
            yield r
        finally:
            r.drive.close()


async def until_moving(rig: Rig, start: float) -> None:
    deadline = time.monotonic() + 5
    while abs(rig.shaft() - start) < 500:
        assert time.monotonic() < deadline, "the move did not start"
        await asyncio.sleep(0.01)


@pytest.mark.parametrize("outcome", ["limit", "stall"])
async def test_awaited_outcomes_carry_the_drives_reasons(rig, outcome):
    start = await rig.twin.position()
    move = asyncio.create_task(rig.twin.move_to(start + FAR, timeout=30))
    await until_moving(rig, start)
    if outcome == "limit":
        rig.faults["limit"](rig.sim, direction=1)
        with pytest.raises(LimitReached) as failed:
            await move
        assert failed.value.side == 1 and "+limit" in failed.value.reason
    else:
        rig.faults["stall"](rig.sim)
        with pytest.raises(MoveStalled) as failed:
            await move
        if rig.kind == "cia402":
            assert failed.value.code == 0x8611 and failed.value.reason == "fault 0x8611 following error"
        else:
            assert failed.value.code == 10 and failed.value.reason == "StepNLoop error: stall (2003h = 10)"
    e = failed.value
    assert start < e.position < start + FAR and e.position == pytest.approx(await rig.twin.position(), abs=1.0)
    last = (await rig.twin.status()).last_move
    assert last.state == e.outcome and last.error is e


async def test_a_cancelled_move_is_halted_and_6081h_is_put_back(rig):
    await rig.twin.params.set("0x6081", 5000)
    start = await rig.twin.position()
    move = asyncio.create_task(rig.twin.move_to(start + FAR, velocity=30000, timeout=30))
    await until_moving(rig, start)
    assert await rig.twin.params.get("0x6081") == 30000      # in effect during the move
    move.cancel()
    with pytest.raises(asyncio.CancelledError):
        await move
    here = rig.shaft()                          # at rest when the CancelledError arrives
    await asyncio.sleep(0.1)
    assert rig.shaft() == here and abs(here - start) >= 500
    assert await rig.twin.params.get("0x6081") == 5000       # put back, as after any end of the move
    st = await rig.twin.status()
    assert not st.moving and st.enabled                       # a halt, not a quick stop: still enabled
    assert st.last_move.state == "interrupted" and "cancellation" in st.last_move.reason
    await rig.twin.move_to(start, timeout=30)                 # and the axis takes the next move
    assert (await rig.twin.status()).last_move.ok


async def test_a_cancelled_homing_stops_and_leaves_the_axis_not_homed(rig):
    await rig.twin.params.set("0x6099:01", 500)      # a slow search: cancelled long before the switch
    await rig.twin.params.set("0x6099:02", 200)
    homing = asyncio.create_task(rig.twin.home(20, timeout=30))
    start = rig.shaft()
    await asyncio.sleep(0.3)
    assert rig.shaft() != start                      # searching
    homing.cancel()
    with pytest.raises(asyncio.CancelledError):
        await homing
    here = rig.shaft()
    await asyncio.sleep(0.1)
    assert rig.shaft() == here
    assert not (await rig.twin.status()).homed


async def test_two_nodes_of_one_bus_move_at_once():
    """Under gather, both nodes' set-points and polls go out side by side, so both shafts
    are seen turning at the same time."""
    with SimBench(["cia402:5", "cia402:6"]) as bench:
        rigs = [Rig("cia402", bench, a) for a in ("5", "6")]
        try:
            for r in rigs:
                r.drive.enable()
                _profile(r.drive)
            both_moving = False

            async def watch() -> None:
                nonlocal both_moving
                while True:
                    positions = [r.shaft() for r in rigs]
                    both_moving = both_moving or (0 < positions[0] < 30000 and -30000 < positions[1] < 0)
                    await asyncio.sleep(0.005)

            watcher = asyncio.create_task(watch())
            await asyncio.gather(rigs[0].twin.move_to(30000, timeout=30), rigs[1].twin.move_to(-30000, timeout=30))
            watcher.cancel()
            assert both_moving
            assert [r.shaft() for r in rigs] == [30000, -30000]
        finally:
            for r in rigs:
                r.drive.close()


async def test_a_silent_node_does_not_hold_up_another_nodes_exchanges():
    """Each node's exchanges queue on that node's own SDO channel and worker only: while
    reads of a node that does not answer wait out their SDO timeouts, another node on the
    same Bus object gives its readings."""
    with SimBench(["cia402:5"]) as bench:
        srv = bench.can.servers[0]
        bus = motorbus.open_bus(f"socketcand:{srv.host}:{srv.port}/can0")
        present = aio.Drive(motorbus.open_drive("cia402", bus=bus, address=5))
        silent = aio.Drive(motorbus.open_drive("cia402", bus=bus, address=9, timeout=0.3))   # no simulator at 9
        try:
            done: list = []

            async def lost() -> None:
                with pytest.raises(motorbus.TimeoutError):
                    await silent.position()
                done.append("node 9 timed out")

            async def readings() -> None:
                await asyncio.sleep(0.05)                # node 9's read is on the wire first
                assert await asyncio.gather(*(present.position() for _ in range(20))) == [0.0] * 20
                # Back while node 9's first request still waits for its answer (reads queued
                # behind node 9's would have come back only after that timeout).
                done.append(("node 5 read", silent.sync.native.sdo.counters.timeouts))

            await asyncio.gather(lost(), readings())
            assert done == [("node 5 read", 0), "node 9 timed out"]
            assert silent.sync.native.sdo.counters.timeouts == 2      # then it was asked once more
        finally:
            silent.sync.close()
            present.sync.close()
            bus.close()


async def test_move_together_awaited_starts_both_nodes_on_one_sync():
    axes = {name: {"kind": "cia402", "bus": "can0", "address": node} for name, node in (("a", 5), ("b", 6))}
    description = {"bus": {"can0": {"spec": "socketcand:10.0.0.5:29536/can0"}}, "axis": axes}
    async with await aio.Bench.from_dict(description, sim=True) as bench:   # the bus served over socketcand
        for name in ("a", "b"):
            await bench[name].enable()
            await bench[name].params.set("0x6081", 20000)
        report = await bench.move_together({"a": 3000, "b": -2000}, timeout=30)
        assert report.method == "CANopen SYNC" and report.skew == 0.0
        sims = [bench.sync.sims[n] for n in ("a", "b")]
        assert [s.pdo.counters.rpdo_applied for s in sims] == [1, 1]   # each took its set-point from the RPDO
        assert [s.position for s in sims] == [3000, -2000]
        assert (await bench["a"].status()).last_move.ok and (await bench["b"].status()).last_move.ok


async def test_the_dmx_can_store_handshake_leaves_the_loop_free():
    """200Eh reads 1 for 0.1 s on a served DMX-CAN (SERVED_STORE_TIME) while the client
    polls it: that polling runs on the node's worker, and the loop keeps ticking."""
    with SimBench(["arcus-canopen:1"]) as bench:
        rig = Rig("arcus-canopen", bench, "1")
        try:
            loop = asyncio.get_running_loop()
            beats: list = []

            def beat() -> None:             # the loop's pulse: one per 5 ms while it is free
                beats.append(time.monotonic())
                pulse[0] = loop.call_later(0.005, beat)
            pulse = [loop.call_soon(beat)]
            await asyncio.sleep(0)
            t0 = time.monotonic()
            await rig.twin.store()
            took = time.monotonic() - t0
            pulse[0].cancel()
            during = [t for t in beats if t0 < t < t0 + took]
            assert took >= 0.1                      # the handshake did wait for the drive
            assert len(during) >= 2, f"the loop ran {len(during)} times during a {took:.2f} s store"
            assert rig.drive.native.read(0x200E, 0) == 0
        finally:
            rig.drive.close()

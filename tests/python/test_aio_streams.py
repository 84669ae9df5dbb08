"""The awaitable buses and streams (issue 25): ``await bus.arecv()``, ``async for frame
in bus`` / ``bus.frames()`` on the virtual bus and over socketcand on 127.0.0.1 (bytes,
order, one wake-up per burst, a tiny queue's counted overflow, cancellation, the end
when the bus closes, two loops in two threads), ``poller.chunks()`` from simulated
drives that are asked (SDO, ASCII) and that push (TPDOs, UNITEK cyclic registers), and
``aio.discover`` not blocking the loop."""
from __future__ import annotations

import asyncio
import itertools
import threading
import time

import numpy as np
import pytest

import motorbus
from motorbus import Bench, Frame, Poller, faces
from motorbus._core.can import open_virtual
from motorbus.aio.discovery import discover as aio_discover
from motorbus.bus import AioBus, aio_open_bus
from motorbus.bus_server import BusServers
from motorbus.drives import cia402
from motorbus.socketcand import SocketcandServer, open_socketcand
from test_poller import _can_bench, _prepare_can
from test_socketcand import served  # noqa: F401 - the fixture: a virtual bus served over socketcand

_hubs = itertools.count()


def hub() -> str:
    return f"aio-streams-{next(_hubs)}"


def frame_of(i: int) -> Frame:
    """Frame i of a test sequence: id and 2 data bytes from i (order and bytes both checkable)."""
    return Frame(0x100 + (i % 0x600), bytes([i & 0xFF, (i >> 8) & 0xFF]))


def check_sequence(frames, n, start=0):
    assert len(frames) == n
    for k, f in enumerate(frames):
        i = start + k
        assert (f.id, f.data) == (0x100 + (i % 0x600), bytes([i & 0xFF, (i >> 8) & 0xFF])), f"frame {k}: {f}"


async def streamed(stream, sender_bus, n):
    """Sends frames 0..n-1 from sender_bus on a thread while ``async for`` collects n of them."""
    sender = threading.Thread(target=lambda: [sender_bus.send(frame_of(i)) for i in range(n)])
    sender.start()
    got = []
    async for frame in stream:
        got.append(frame)
        if len(got) == n:
            break
    sender.join()
    return got


class LoopTicks:
    """``async with LoopTicks(0.005) as ticks:`` counts (``ticks.n``) how often the loop ran a task
    that sleeps ``every`` seconds meanwhile: the proof that the awaited call did not block it."""

    def __init__(self, every: float) -> None:
        self.every, self.n = every, 0

    async def _tick(self) -> None:
        while True:
            self.n += 1
            await asyncio.sleep(self.every)

    async def __aenter__(self) -> "LoopTicks":
        self._task = asyncio.ensure_future(self._tick())
        return self

    async def __aexit__(self, *exc) -> None:
        self._task.cancel()


def wait_until(cond, timeout=5.0):
    """A blocking wait (deliberately keeps the loop from running)."""
    end = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.001)


# ---- virtual bus -------------------------------------------------------------------------------
@pytest.mark.threaded
async def test_async_for_on_the_virtual_bus_keeps_bytes_and_order():
    name = hub()
    with open_virtual(name) as tx, open_virtual(name) as rx:
        stream = rx.frames()
        check_sequence(await streamed(stream, tx, 600), 600)
        assert stream.overflows == 0 and stream.received == 600
        assert stream.wakeups <= 600                 # never more than one per frame (test_a_burst...: one per burst)
        # The stream is a subscription of its own: recv()'s queue still has every frame (the
        # bus thread hands a frame to its subscribers before its recv() queue: wait for the last).
        queued = []
        while len(queued) < 600:
            more = rx.recv_many(1000, timeout=2.0)
            assert more, f"recv() queue stopped at {len(queued)} frames"
            queued += more
        check_sequence(queued, 600)
        stream.close()


@pytest.mark.threaded
async def test_a_burst_wakes_the_loop_once():
    name = hub()
    with open_virtual(name) as tx, open_virtual(name) as rx:
        stream = rx.frames(queue=1024)
        bridge = faces.bridge_for()
        waiting = asyncio.ensure_future(stream.batch())
        await asyncio.sleep(0)                       # the task arms the stream and waits
        before = bridge.completions.wakeups
        for i in range(200):                         # the loop does not run meanwhile: one burst
            tx.send(frame_of(i))
        wait_until(lambda: stream.received == 200)
        first = await waiting
        rest = await stream.batch(max=1000)
        check_sequence(first + rest, 200)
        assert len(first) == 1                       # the burst's first frame woke the loop...
        assert stream.wakeups == 1                   # ...once: the other 199 were taken without a wake-up
        assert bridge.completions.wakeups - before == 1
        stream.close()


@pytest.mark.threaded
async def test_a_tiny_queue_drops_the_newest_and_counts_them():
    name = hub()
    with open_virtual(name) as tx, open_virtual(name) as rx:
        async with rx.frames(queue=4) as stream:
            for i in range(10):
                tx.send(frame_of(i))
            wait_until(lambda: stream.received == 10)
            got = await stream.batch(max=100)
            check_sequence(got, 4)                       # the oldest four, in order
            assert stream.overflows == 6
            assert await stream.batch(timeout=0.05) == []
            tx.send(frame_of(10))                        # room again
            check_sequence(await stream.batch(timeout=5), 1, start=10)
            assert stream.overflows == 6


@pytest.mark.threaded
async def test_filters_choose_the_frames_of_a_stream():
    name = hub()
    with open_virtual(name) as tx, open_virtual(name) as rx:
        async with rx.frames(filters=[{"can_id": 0x180, "can_mask": 0x780}]) as tpdo1:   # TPDO1 of any node
            for cob in (0x181, 0x701, 0x18A, 0x205, 0x185):
                tx.send(Frame(cob, bytes([cob & 0xFF])))
            got = []
            async for f in tpdo1:
                got.append(f)
                if len(got) == 3:
                    break
            assert [(f.id, f.data) for f in got] == [(0x181, b"\x81"), (0x18A, b"\x8a"), (0x185, b"\x85")]
            assert tpdo1.received == 3


@pytest.mark.threaded
async def test_arecv_is_recv_awaited_same_queue_and_filters():
    name = hub()
    with open_virtual(name) as tx, open_virtual(name) as rx:
        rx.set_filters([{"can_id": 0x123, "can_mask": 0x7FF}])
        assert await rx.arecv(timeout=0) is None
        assert await rx.arecv(timeout=0.02) is None
        waiter = asyncio.ensure_future(rx.arecv())
        await asyncio.sleep(0.01)
        tx.send(Frame(0x100, b"\x00"))              # filtered out
        tx.send(Frame(0x123, b"\xde\xad"))
        got = await asyncio.wait_for(waiter, 5)
        assert (got.id, got.data) == (0x123, b"\xde\xad")
        for i in range(5):
            tx.send(Frame(0x123, bytes([i])))
        wait_until(lambda: rx.counters.rx_frames == 7)
        many = await rx.arecv_many(3)
        assert [f.data for f in many] == [b"\x00", b"\x01", b"\x02"]
        assert rx.recv(0).data == b"\x03"           # the blocking recv() reads the same queue
        assert (await rx.arecv(1)).data == b"\x04"
        await tx.asend(Frame(0x123, b"\x05"))
        assert (await rx.arecv(5)).data == b"\x05"


@pytest.mark.threaded
async def test_asend_waits_on_a_full_medium_without_blocking_the_loop():
    name = hub()
    # 1 kbit/s: a frame takes ~65 ms on the wire, so a 2-frame transmit queue fills at once.
    with open_virtual(name, bitrate=1000, tx_queue=2) as tx, open_virtual(name, bitrate=1000) as rx:
        async with LoopTicks(0.005) as ticks:
            t0 = time.monotonic()
            for i in range(6):
                await tx.asend(frame_of(i), timeout=5)
            waited = time.monotonic() - t0
        assert waited > 0.1                          # the medium was full: asend had to wait...
        assert ticks.n >= 2                          # ...and the loop ran meanwhile
        with pytest.raises(motorbus.TimeoutError, match="stayed full"):
            for i in range(6, 40):
                await tx.asend(frame_of(i), timeout=0.01)
        got = [await rx.arecv(5) for _ in range(6)]
        check_sequence(got, 6)


@pytest.mark.threaded
async def test_cancelling_an_async_for_leaves_the_bus_usable():
    name = hub()
    with open_virtual(name) as tx, open_virtual(name) as rx:
        stream = rx.frames()
        seen = []

        async def consume():
            async for f in stream:
                seen.append(f)

        task = asyncio.ensure_future(consume())
        tx.send(frame_of(0))
        for _ in range(500):
            if seen:
                break
            await asyncio.sleep(0.002)
        task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await task
        check_sequence(seen, 1)
        check_sequence(rx.recv_many(10, timeout=0), 1)   # recv()'s queue had frame 0 too
        # A cancelled arecv is withdrawn: the next frame goes to the next reader, not to a dead one.
        waiter = asyncio.ensure_future(rx.arecv())
        await asyncio.sleep(0.01)
        waiter.cancel()
        with pytest.raises(asyncio.CancelledError):
            await waiter
        tx.send(frame_of(1))
        check_sequence([await rx.arecv(5)], 1, start=1)
        # The cancelled stream goes on: the frame it had not yet been given is still there.
        check_sequence([await asyncio.wait_for(stream.__anext__(), 5)], 1, start=1)
        tx.send(frame_of(2))
        assert rx.recv(5).data == frame_of(2).data   # blocking recv() unaffected
        stream.close()


@pytest.mark.threaded
async def test_closing_the_bus_ends_the_iteration_after_its_frames():
    name = hub()
    tx, rx = open_virtual(name), open_virtual(name)
    stream = rx.frames()
    got = []

    async def consume():
        async for f in stream:
            got.append(f)
        return "ended"

    task = asyncio.ensure_future(consume())
    for i in range(3):
        tx.send(frame_of(i))
    wait_until(lambda: stream.received == 3)
    waiter = asyncio.ensure_future(rx.arecv_many(10))
    await asyncio.sleep(0.01)
    rx.close()
    assert await asyncio.wait_for(task, 5) == "ended"
    check_sequence(got, 3)
    assert len(await waiter) == 3                    # recv()'s queue had them: handed out before the close
    with pytest.raises(motorbus.ClosedError):
        await rx.arecv(1)
    with pytest.raises(motorbus.ClosedError):
        rx.frames()._rx.take(1)                      # a stream made after the close is ended at once
    assert [f async for f in rx.frames()] == []
    tx.close()


@pytest.mark.threaded
async def test_the_awaitable_twin_has_the_blocking_names(served):
    server, node = served
    async with await aio_open_bus(f"socketcand:127.0.0.1:{server.port}/can0") as bus:   # opened off the loop
        assert bus.channel == bus.sync.channel and bus.state == "active"
        bus.set_filters([{"can_id": 0x181, "can_mask": 0x7FF}])             # the bus's own, as is
        stream = bus.frames()
        await asyncio.sleep(0.05)
        node.send(Frame(0x701, b"\x05"))
        node.send(Frame(0x181, b"\x01\x02"))
        f = await bus.recv(5)
        assert (f.id, f.data) == (0x181, b"\x01\x02")
        got = []
        while len(got) < 2:                                                 # the stream: unfiltered, both
            got += await stream.batch(timeout=5)
        assert [g.id for g in got] == [0x701, 0x181]
        await bus.send(Frame(0x201, b"\xaa"))
        assert node.recv(5).data == b"\xaa"
        assert await bus.recv_many(10, timeout=0.02) == []
        sync = bus.sync
    assert sync.closed                                                     # async with closed it
    with pytest.raises(motorbus.InvalidArgument, match="aio.Bus"):
        AioBus("virtual:x")


async def test_bad_arguments_are_named():
    with open_virtual(hub()) as bus:
        with pytest.raises(motorbus.InvalidArgument, match="arecv timeout"):
            await bus.arecv(timeout=-1)
        with pytest.raises(motorbus.InvalidArgument, match="arecv_many max"):
            await bus.arecv_many(0)
        with pytest.raises(motorbus.InvalidArgument, match="frames queue"):
            bus.frames(queue=0)
        with pytest.raises(motorbus.InvalidArgument, match="filters"):
            bus.frames(filters=[{"mask": 1}])


@pytest.mark.threaded
def test_two_loops_in_two_threads_each_get_every_frame():
    name = hub()
    tx = open_virtual(name)
    results: dict[int, list] = {}
    ready = threading.Barrier(3)

    def consumer(k: int) -> None:
        async def main():
            with open_virtual(name) as rx:
                stream = rx.frames()
                ready.wait()
                frames = []
                async for f in stream:
                    frames.append(f)
                    if len(frames) == 300:
                        break
                stream.close()
                results[k] = (frames, faces.bridge_for())
        asyncio.run(main())

    threads = [threading.Thread(target=consumer, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    ready.wait()
    for i in range(300):
        tx.send(frame_of(i))
    for t in threads:
        t.join(20)
    tx.close()
    assert set(results) == {0, 1}
    for frames, _ in results.values():
        check_sequence(frames, 300)
    assert results[0][1] is not results[1][1]       # one completion queue per loop


@pytest.mark.threaded
def test_a_wait_that_outlives_its_loop_touches_no_python():
    """A loop closed with waits still armed: the bus thread completes them into the dead loop's
    queue (C++ only, nothing of Python), and the bus and the stream go on for a new loop."""
    name = hub()
    with open_virtual(name) as tx, open_virtual(name) as rx:
        stream = rx.frames()
        loop = asyncio.new_event_loop()
        tasks = [loop.create_task(stream.batch()), loop.create_task(rx.arecv())]
        loop.run_until_complete(asyncio.sleep(0.01))            # both armed
        loop.close()                                             # abandoned, not cancelled
        for t in tasks:
            t._log_destroy_pending = False                       # abandoned on purpose
        del tasks, loop
        tx.send(frame_of(0))                                     # completes both dead waits
        tx.send(frame_of(1))
        wait_until(lambda: stream.received == 2)

        async def later():
            return await stream.batch(timeout=5), await rx.arecv(5)

        from_stream, from_recv = asyncio.run(later())
        check_sequence(from_stream, 1, start=1)                  # frame 0 went to the dead loop's wait
        check_sequence([from_recv], 1, start=1)
        stream.close()


# ---- socketcand on 127.0.0.1 -----------------------------------------------------------------
@pytest.mark.threaded
async def test_async_for_over_socketcand(served):
    server, node = served
    with open_socketcand("127.0.0.1", server.port, "can0") as client:
        stream = client.frames()
        await asyncio.sleep(0.05)                    # the client's rawmode is set up
        check_sequence(await streamed(stream, node, 400), 400)
        assert stream.overflows == 0
        # Both ways: what the client sends awaited reaches the node, bytes intact.
        for i in range(400, 410):
            await client.asend(frame_of(i))
        check_sequence([node.recv(5) for _ in range(10)], 10, start=400)
        # And arecv over TCP (recv()'s queue holds the 400 first: the stream took none of them).
        check_sequence(client.recv_many(1000, timeout=0), 400)
        node.send(Frame(0x7E5, b"\x01\x02\x03\x04\x05\x06\x07\x08"))
        f = await client.arecv(5)
        assert (f.id, f.data) == (0x7E5, b"\x01\x02\x03\x04\x05\x06\x07\x08")
        stream.close()


@pytest.mark.threaded
async def test_a_socketcand_server_going_away_ends_the_stream_with_linkdown():
    name = hub()
    bus, node = open_virtual(name), open_virtual(name)
    server = SocketcandServer(bus)
    client = open_socketcand("127.0.0.1", server.port, "can0")
    stream = client.frames()
    await asyncio.sleep(0.05)
    node.send(frame_of(0))
    check_sequence([await asyncio.wait_for(stream.__anext__(), 5)], 1)
    waiting = asyncio.ensure_future(stream.__anext__())
    await asyncio.sleep(0.01)
    server.close()                                   # TCP EOF: the link is lost for good
    try:
        with pytest.raises(motorbus.LinkDown):
            await asyncio.wait_for(waiting, 10)
        check_sequence(client.recv_many(10, timeout=0), 1)
        with pytest.raises(motorbus.LinkDown):
            await client.arecv(1)
    finally:
        client.close()
        node.close()
        bus.close()


# ---- pollers and pushed streams --------------------------------------------------------------
def _move(bench):
    z, u = bench["z"], bench["u"]
    z.move_to(300.0)                # 3000 increments at 20000 inc/s
    u.move_by(20000)
    z.wait_idle(timeout=10)
    u.wait_idle(timeout=10)
    time.sleep(0.1)                 # a few samples at rest


async def _collect(poller, rows, until):
    chunks = []
    async for chunk in poller.chunks(rows):
        chunks.append(chunk)
        if until.done():
            poller.stop()           # the iteration ends with the rows still in the rings
    return chunks


def _joined(chunks):
    return {k: np.concatenate([c[k] for c in chunks]) for k in chunks[0]}


@pytest.mark.parametrize("mode", ["ask", "capture"])
async def test_poller_chunks_from_simulated_drives(mode):
    """mode="ask": SDO reads of the CiA 402 drive, register reads of the UNITEK one;
    mode="capture": its TPDO stream and the UNITEK cyclic registers."""
    with _can_bench() as bench:
        _prepare_can(bench)
        z, u = bench["z"], bench["u"]
        poller = Poller(bench.axes, rate_hz=200, mode=mode, keep=None)
        assert poller.modes == {"z": mode, "u": mode}
        moved = asyncio.ensure_future(asyncio.to_thread(_move, bench))   # the test's blocking calls, off the loop
        chunks = await asyncio.wait_for(_collect(poller, 20, moved), 30)
        await moved
        assert len(chunks) >= 3
        assert all(len(c["t"]) >= 20 for c in chunks[:-1])              # each chunk at least `rows` rows
        data = _joined(chunks)
        t = data["t"]
        assert np.allclose(np.diff(t), 0.005)                            # one row per deadline, none lost or repeated
        # The chunks are the blocking Poller's rows: frame() retained exactly what they carried.
        frame = poller.frame()
        assert set(frame) == set(data)
        for k in frame:
            np.testing.assert_array_equal(frame[k], data[k])
        for axis, drive in (("z", z), ("u", u)):
            pos = data[f"{axis}.position"][~np.isnan(data[f"{axis}.position"])]
            assert pos[-1] == pytest.approx(drive.position, abs=1e-9), axis
            assert len(pos[(pos > pos[0]) & (pos < drive.position)]) >= 3, f"{axis}: no chunk caught the move"
            assert np.all(np.diff(pos) >= 0)
            status = data[f"{axis}.status"][~np.isnan(data[f"{axis}.status"])]
            assert status[-1] == drive.status.raw
        assert z.position == pytest.approx(300.0)
        assert poller.overflowed == 0
        stats = poller.stats["z+u"]
        assert stats["captured"] == (["z", "u"] if mode == "capture" else [])


@pytest.mark.threaded
async def test_chunks_count_what_a_slow_consumer_lost_and_cancel_cleanly():
    with _can_bench() as bench:
        _prepare_can(bench)
        with Poller({"z": bench["z"]}, fields=("position",), rate_hz=500, capacity=16, mode="capture") as poller:
            chunks = poller.chunks(8)
            first = await asyncio.wait_for(chunks.__anext__(), 10)
            assert len(first["t"]) >= 8
            time.sleep(0.2)                          # the loop stalls: ~100 rows into a 16-row ring
            second = await asyncio.wait_for(chunks.__anext__(), 10)
            assert len(second["t"]) <= 16
            assert poller.overflowed > 50
            # Cancelling a waiting iteration withdraws its wait; the poller goes on.
            waiting = asyncio.ensure_future(chunks.__anext__())
            await asyncio.sleep(0)
            waiting.cancel()
            with pytest.raises(asyncio.CancelledError):
                await waiting
            assert poller.running
            again = poller.chunks(8)
            assert len((await asyncio.wait_for(again.__anext__(), 10))["t"]) >= 8
            by_default = poller.chunks()                 # a tenth of a second (50 rows) > the ring: 16
            assert len((await asyncio.wait_for(by_default.__anext__(), 10))["t"]) >= 16
            with pytest.raises(motorbus.InvalidArgument, match="rows"):
                await poller.chunks(0).__anext__()
            with pytest.raises(motorbus.InvalidArgument, match="rows"):
                await poller.chunks(17).__anext__()
        assert not poller.running
        rest = [c async for c in poller.chunks(8)]   # a stopped poller: what is left, then the end
        assert all(len(c["t"]) > 0 for c in rest)


async def test_chunks_of_a_poller_not_started_is_refused():
    with _can_bench() as bench:
        poller = Poller({"z": bench["z"]}, rate_hz=100, start=False)
        with pytest.raises(motorbus.InvalidArgument, match="not started"):
            await poller.chunks().__anext__()
        poller.stop()


# ---- discovery -----------------------------------------------------------------------------
@pytest.fixture
def canopen_bus():
    servers = BusServers(f"virtual:{hub()}", socketcand=["127.0.0.1:0"], channel="can0")
    nodes = [cia402.make_sim(n) for n in (9, 77)]
    for n in nodes:
        n.attach(servers.endpoint())
    srv = servers.servers[0]
    yield f"socketcand:{srv.host}:{srv.port}/can0"
    for n in nodes:
        n.close()
    servers.close()


@pytest.mark.threaded
async def test_discover_awaited_finds_the_nodes_without_blocking_the_loop(canopen_bus):
    notes = []
    async with LoopTicks(0.002) as ticks:
        result = await aio_discover(buses=[canopen_bus], kinds=["cia402"], sdo_timeout=0.1, progress=notes.append)
    assert {(f.kind, f.address) for f in result.found} == {("cia402", "9"), ("cia402", "77")}
    assert result.seconds > 0.05 and ticks.n >= 3   # the loop went on while the scan ran
    assert any("node(s)" in n for n in notes)       # progress lines, on the loop's thread
    with pytest.raises(motorbus.InvalidArgument, match="progress"):
        await aio_discover(buses=[canopen_bus], progress="yes")


@pytest.mark.threaded
async def test_discover_cancelled_raises_at_once_and_a_later_one_works(canopen_bus):
    # Four scans of >= 0.3 s each (the SDO timeout of the absent nodes): > 1.2 s if waited for.
    task = asyncio.ensure_future(aio_discover(buses=[canopen_bus] * 4, kinds=["cia402"], sdo_timeout=0.3))
    await asyncio.sleep(0.05)
    t0 = time.monotonic()
    task.cancel()
    with pytest.raises(asyncio.CancelledError):
        await task
    assert time.monotonic() - t0 < 0.5
    result = await aio_discover(buses=[canopen_bus], kinds=["cia402"], sdo_timeout=0.1)
    assert len(result.found) == 2

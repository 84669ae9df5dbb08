"""The awaitable CANopen facade: ``await node.sdo[...].get()`` / ``set()``, uploads and
downloads of any size, NMT waits and PDO configuration, awaited against our LocalNode
over the virtual bus and over a socketcand server on 127.0.0.1; many awaits at once,
two loops in two threads, cancellation, completions after the loop is gone."""
import asyncio
import gc
import itertools
import os
import struct
import threading

import pytest

import motorbus
from motorbus import _core
from motorbus.canopen import (HeartbeatService, LocalNode, Network, ObjectDictionary, PdoService, SdoAbortError,
                              SdoClient, SdoTimeout)
from motorbus.canopen import sdo as sdo_mod
from motorbus.socketcand import SocketcandServer

_hub = itertools.count()


def threads_alive():
    """Threads of this process, C++ ones included."""
    return len(os.listdir("/proc/self/task"))
DEVICE_TYPE = 0x00020192


def make_od(node_id=5):
    od = ObjectDictionary()
    od.add_variable(0x1000, "Device type", "u32", "ro", default=DEVICE_TYPE + node_id)
    od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "ro", default="motorbus drive")
    od.add_record(0x1018, "Identity object")
    od.add_member(0x1018, 1, "Vendor-ID", "u32", "ro", default=0x12E)
    od.add_variable(0x2000, "Offset", "i16", "rw", default=-5)
    od.add_variable(0x2001, "Gain", "f32", "rw", default=1.5)
    od.add_variable(0x2002, "Enabled", "BOOLEAN", "rw", default=1)
    od.add_variable(0x2003, "Baud index", "u8", "rw", low=0, high=8, default=4)
    od.add_variable(0x2201, "Blob", "DOMAIN", "rw", max_size=1 << 20)
    od.add_variable(0x6041, "Statusword", "u16", "ro", pdo_mappable=True, default=0x0637)
    od.add_variable(0x6064, "Position actual value", "i32", "ro", pdo_mappable=True, default=-100)
    return od


class Rig:
    """LocalNodes on one endpoint of a virtual hub; a Network on another endpoint
    (virtual) or on a socketcand client of a server exposing the hub (socketcand)."""

    def __init__(self, transport, node_ids=(5,), sdo_timeout=0.5):
        name = f"aio-canopen-{next(_hub)}"
        self.dev = _core.can.open_virtual(name)
        self.ods = {n: make_od(n) for n in node_ids}
        self.nodes = {n: LocalNode(self.dev, n, self.ods[n]) for n in node_ids}
        self.server = None
        if transport == "socketcand":
            self.server_bus = _core.can.open_virtual(name)
            self.server = SocketcandServer(self.server_bus)
            host = f"socketcand:127.0.0.1:{self.server.port}/can0"
        else:
            host = f"virtual:{name}"
        self.network = Network(host, sdo_timeout=sdo_timeout)
        self.remote = {n: self.network.add_node(n, self.ods[n]) for n in node_ids}

    def close(self):
        self.network.close()
        for n in self.nodes.values():
            n.close()
        if self.server is not None:
            self.server.close()
            self.server_bus.close()
        self.dev.close()


@pytest.fixture(params=["virtual", "socketcand"])
def rig(request):
    r = Rig(request.param)
    yield r
    r.close()


@pytest.fixture
def vrig():
    r = Rig("virtual")
    yield r
    r.close()


async def test_get_and_set_are_typed_as_value_and_raw(rig):
    node = rig.remote[5]
    assert await node.sdo["Device type"].get() == DEVICE_TYPE + 5
    assert await node.sdo["Identity object"]["Vendor-ID"].get() == 0x12E
    assert await node.sdo["Offset"].get() == -5                    # signed per the OD
    assert await node.sdo["Gain"].get() == 1.5                     # REAL32
    assert await node.sdo["Enabled"].get() is True                 # BOOLEAN
    assert await node.sdo["Manufacturer device name"].get() == "motorbus drive"   # segmented upload
    await node.sdo["Offset"].set(-1234)
    await node.sdo["Gain"].set(-0.25)
    await node.sdo["Enabled"].set(False)
    assert rig.ods[5][0x2000].value == -1234                       # what the served node holds
    assert rig.ods[5][0x2001].value == -0.25
    assert rig.ods[5][0x2002].value == 0
    # .raw twins: integers as int, the rest as bytes; the blocking face agrees.
    assert await node.sdo[0x2000].get_raw() == -1234
    assert await node.sdo["Gain"].get_raw() == struct.pack("<f", -0.25)   # not an integer type: bytes
    assert await node.sdo[0x1008].get_raw() == b"motorbus drive"
    await node.sdo[0x2003].set_raw(7)
    assert node.sdo[0x2003].raw == 7 and rig.ods[5][0x2003].value == 7


async def test_out_of_range_write_is_the_blocking_calls_abort(rig):
    node = rig.remote[5]
    with pytest.raises(SdoAbortError) as e:
        await node.sdo["Baud index"].set(9)          # high limit 8
    assert e.value.code == 0x06090031
    with pytest.raises(SdoAbortError) as e:
        await node.sdo.upload_async(0x7777, 0)
    assert e.value.code == 0x06020000
    assert await node.sdo["Baud index"].get() == 4   # the channel goes on


async def test_uploads_and_downloads_of_any_size(rig):
    node = rig.remote[5]
    data = bytes((i * 31 + 7) & 0xFF for i in range(5000))
    await node.sdo.download_async(0x2201, 0, data)                       # segmented
    assert rig.ods[5][0x2201].raw == data
    assert await node.sdo.upload_async(0x2201, 0) == data
    big = bytes(range(256)) * 120                                        # 30 KiB, block both ways
    await node.sdo.download_async(0x2201, 0, big, block=True)
    assert await node.sdo.upload_async(0x2201, 0, block=True) == big
    await node.sdo.download_async(0x2201, 0, b"ab", segmented=True)
    assert rig.ods[5][0x2201].raw == b"ab"
    # A bare SdoClient too.
    assert await sdo_mod.upload_async(node.sdo.client, 0x1000) == (DEVICE_TYPE + 5).to_bytes(4, "little")


async def test_no_od_needs_a_size_for_integers(rig):
    client = rig.remote[5].sdo.client
    from motorbus.canopen.sdo import SdoVariables
    bare = SdoVariables(client)
    await bare[0x2000][0].set_raw(77, size=2, signed=True)
    assert rig.ods[5][0x2000].value == 77
    assert await bare[0x2000][0].get_raw() == (77).to_bytes(2, "little")
    with pytest.raises(motorbus.InvalidArgument, match="size"):
        await bare[0x2000][0].set_raw(77)
    with pytest.raises(motorbus.InvalidArgument, match="data type"):
        await bare[0x2000][0].get()


async def test_timeout_is_sdo_timeout_and_the_loop_keeps_running():
    name = f"aio-canopen-silent-{next(_hub)}"
    with motorbus.open_bus(f"virtual:{name}") as bus, motorbus.open_bus(f"virtual:{name}") as tap:
        client = SdoClient(bus, 9, timeout=0.15)       # nobody serves node 9
        ticks = 0

        async def ticker():
            nonlocal ticks
            while True:
                await asyncio.sleep(0.01)
                ticks += 1

        t = asyncio.create_task(ticker())
        loop = asyncio.get_running_loop()
        t0 = loop.time()
        with pytest.raises(SdoTimeout):
            await sdo_mod.upload_async(client, 0x1000)
        elapsed = loop.time() - t0
        t.cancel()
        assert 0.14 <= elapsed < 2.0
        assert ticks >= 5                               # the loop ran on while we waited
        # The abort 0x05040000 with the multiplexer went out after the request.
        frames = [tap.recv(0.5) for _ in range(2)]
        assert [bytes(f.data) for f in frames] == [bytes([0x40, 0, 0x10, 0, 0, 0, 0, 0]),
                                                   bytes([0x80, 0, 0x10, 0, 0, 0, 4, 5])]
        assert client.counters.timeouts == 1


async def test_nmt_waits(rig):
    vrig = rig
    node = vrig.remote[5]
    local = vrig.nodes[5]
    hb = HeartbeatService(local, producer_ms=20)
    assert await node.nmt.wait_for_heartbeat_async(1.0) == "PRE-OPERATIONAL"
    node.nmt.state = "OPERATIONAL"
    await node.nmt.wait_for_state_async("OPERATIONAL", 1.0)
    assert node.nmt.state == "OPERATIONAL"
    waiting = asyncio.ensure_future(node.nmt.wait_for_bootup_async(2.0))
    await asyncio.sleep(0.05)
    assert not waiting.done()
    node.nmt.state = "RESET"
    await waiting                                    # the boot-up after the reset
    assert await vrig.network.nmt.wait_for_state_async(5, "PRE-OPERATIONAL", 1.0)
    await node.sdo.download_async(0x1017, 0, (0).to_bytes(2, "little"))   # producer off
    sent = hb.heartbeats_sent
    with pytest.raises(motorbus.TimeoutError, match="boot-up"):
        await node.nmt.wait_for_bootup_async(0.1)
    assert await vrig.network.nmt.wait_for_heartbeat_async(5, 0.1) is None
    assert hb.heartbeats_sent == sent
    with pytest.raises(motorbus.InvalidArgument, match="NMT state.*'RUNNING'"):
        await node.nmt.wait_for_state_async("RUNNING", 0.1)


async def test_pdo_configuration_awaited(rig):
    vrig = rig
    PdoService(vrig.nodes[5])
    node = vrig.remote[5]
    cfg = await node.tpdo[1].configure_async(transmission_type=255, event_timer_ms=100,
                                             mapping=[(0x6041, 0, 16), (0x6064, 0, 32)])
    assert cfg.mapping == [(0x6041, 0, 16), (0x6064, 0, 32)]
    assert cfg.transmission_type == 255 and cfg.event_timer_ms == 100
    # What the node holds, read over awaited SDO, and the channel read back.
    assert await node.sdo.upload_async(0x1A00, 0) == b"\x02"
    assert await node.sdo.upload_async(0x1A00, 1) == (0x60410010).to_bytes(4, "little")
    again = await node.tpdo[1].read_async()
    assert again.mapping == cfg.mapping and again.cob_id & 0x7FF == 0x185


async def test_a_thousand_concurrent_reads_across_nodes(rig_many):
    r, transport = rig_many
    threads_before = threads_alive()
    ids = [1 + k % len(r.remote) for k in range(1000)]
    tasks = [asyncio.ensure_future(r.remote[n].sdo["Device type"].get()) for n in ids]
    await asyncio.sleep(0)                      # all started
    threads_during = threads_alive()
    values = await asyncio.gather(*tasks)
    assert values == [DEVICE_TYPE + n for n in ids]
    assert threads_during <= threads_before      # no thread per wait
    bridge = motorbus.faces.bridge_for()
    assert bridge.completions.wakeups < bridge.completions.pushed   # completions batched


@pytest.fixture(params=["virtual", "socketcand"])
def rig_many(request):
    r = Rig(request.param, node_ids=range(1, 17))
    yield r, request.param
    r.close()


def test_two_loops_in_two_threads_at_once():
    r = Rig("virtual", node_ids=(1, 2, 3, 4))
    try:
        results, errors = {}, []

        def run(k):
            async def main():
                return await asyncio.gather(*[r.remote[n].sdo["Device type"].get()
                                              for _ in range(50) for n in r.remote])
            try:
                results[k] = asyncio.run(main())
            except Exception as e:  # noqa: BLE001 - asserted below
                errors.append(e)

        threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        assert not errors
        want = [DEVICE_TYPE + n for _ in range(50) for n in r.remote]
        assert results == {0: want, 1: want}
    finally:
        r.close()


async def test_cancelling_an_awaited_transfer_leaves_the_channel_usable(vrig):
    node = vrig.remote[5]
    vrig.ods[5][0x2201].raw = bytes(range(256)) * 2000      # 512 KB: a long segmented upload
    transfer = asyncio.ensure_future(node.sdo.upload_async(0x2201, 0))
    await asyncio.sleep(0.01)
    assert not transfer.done()
    transfer.cancel()
    with pytest.raises(asyncio.CancelledError):
        await transfer
    assert node.sdo.client.async_pending == 0
    # The server was told (abort 0x08000000) and the next transfers run at once.
    assert await node.sdo["Device type"].get() == DEVICE_TYPE + 5
    assert node.sdo["Offset"].raw == -5
    assert vrig.nodes[5].counters.sdo.aborts_received >= 1
    # A cancelled wait on a queued transfer drops it before it reaches the wire.
    queued = [asyncio.ensure_future(node.sdo["Offset"].get()) for _ in range(5)]
    await asyncio.sleep(0)
    queued[3].cancel()
    done = await asyncio.gather(*queued, return_exceptions=True)
    assert done[:3] == [-5, -5, -5] and done[4] == -5 and isinstance(done[3], asyncio.CancelledError)


async def test_awaited_and_blocking_calls_share_a_client():
    r = Rig("virtual")
    try:
        node = r.remote[5]
        loop = asyncio.get_running_loop()
        awaited = asyncio.gather(*[node.sdo["Offset"].get() for _ in range(200)])
        blocking = loop.run_in_executor(None, lambda: [node.sdo["Device type"].raw for _ in range(50)])
        a, b = await asyncio.gather(awaited, blocking)
        assert a == [-5] * 200 and b == [DEVICE_TYPE + 5] * 50
        assert node.sdo.client.counters.aborts_received == 0
    finally:
        r.close()


def test_a_transfer_completing_after_its_loop_closed_does_not_crash():
    r = Rig("virtual", sdo_timeout=0.1)
    try:
        node, silent = r.remote[5], r.network.add_node(9)      # nobody serves node 9
        r.ods[5][0x2201].raw = bytes(range(256)) * 40       # 1 463 segments
        loop = asyncio.new_event_loop()

        async def start():
            asyncio.ensure_future(node.sdo.upload_async(0x2201, 0))
            asyncio.ensure_future(silent.sdo.upload_async(0x1000, 0))
            await asyncio.sleep(0)

        loop.run_until_complete(start())
        loop.close()                                          # the transfers run on
        del loop
        gc.collect()
        assert silent.sdo.client.async_pending == 1          # its deadline was the loop's
        # A blocking call behind it fires that deadline itself (the completion goes to
        # the dead loop's queue, touching no Python), then times out on its own.
        with pytest.raises(SdoTimeout):
            silent.sdo.upload(0x1000)
        assert silent.sdo.client.async_pending == 0
        assert silent.sdo.client.counters.timeouts == 2
        for _ in range(1000):
            if node.sdo.client.async_pending == 0:
                break
            threading.Event().wait(0.01)
        assert node.sdo.client.async_pending == 0
        assert node.sdo["Device type"].raw == DEVICE_TYPE + 5   # and the client works on
    finally:
        r.close()


async def test_closing_the_network_fails_pending_awaits_with_closed_error():
    name = f"aio-canopen-close-{next(_hub)}"
    network = Network(f"virtual:{name}", sdo_timeout=5.0)
    node = network.add_node(9)                                # nobody serves it
    pending = [asyncio.ensure_future(node.sdo.upload_async(0x1000, 0)) for _ in range(3)]
    await asyncio.sleep(0.01)
    network.close()
    for p in pending:
        with pytest.raises(motorbus.ClosedError):
            await p


async def test_a_simulated_pmc007_awaited_over_socketcand():
    """The PMC007 simulator (C++, served on a virtual hub) through a socketcand server:
    its identity read, a parameter written and read back, a bad value refused."""
    from motorbus.drives import pmc007
    name = f"aio-pmc007-{next(_hub)}"
    clock = _core.runtime.SimClock(1_000_000_000)
    sim_bus, server_bus = _core.can.open_virtual(name), _core.can.open_virtual(name)
    sim = pmc007.make_sim(5, clock=clock, bus=sim_bus)
    server = SocketcandServer(server_bus)
    net = Network(f"socketcand:127.0.0.1:{server.port}/can0", sdo_timeout=0.5)
    try:
        node = net.add_node(5, _core.pmc007.object_dictionary())
        assert await node.sdo["Manufacturer device name"].get() == "PMC007 (motorbus sim)"
        await node.sdo[0x6003].set(1234)                     # Maximum speed
        assert await node.sdo[0x6003].get() == 1234
        assert sim.od[0x6003].value == 1234                  # the simulator holds it
        values = await asyncio.gather(*[node.sdo[0x6003].get() for _ in range(50)])
        assert values == [1234] * 50
    finally:
        net.close()
        server.close()
        sim.close()
        server_bus.close()
        sim_bus.close()


async def test_a_loop_of_awaited_reads_does_not_starve_the_loop(vrig):
    """An awaited read that is the loop's only one polls briefly for its answer
    instead of sleeping; a task doing such reads back to back still yields to the
    loop (every 16 answers), so a timer keeps firing meanwhile."""
    node = vrig.remote[5]
    loop = asyncio.get_running_loop()
    fired = []

    async def ticker():
        while True:
            await asyncio.sleep(0.0005)
            fired.append(loop.time())

    t = asyncio.create_task(ticker())
    await asyncio.sleep(0.001)
    start = loop.time()
    for _ in range(2000):
        assert await node.sdo["Offset"].get() == -5
    took = loop.time() - start
    t.cancel()
    during = [x for x in fired if x >= start]
    # Never more than a few ms between two ticks while the reads ran.
    gaps = [b - a for a, b in zip([start] + during, during + [start + took])]
    assert len(during) >= 3 and max(gaps) < 0.2, (len(during), max(gaps), took)


async def test_closing_a_network_on_a_bus_it_does_not_own_fails_pending_awaits():
    name = f"aio-canopen-close-{next(_hub)}"
    with motorbus.open_bus(f"virtual:{name}") as bus:
        network = Network(bus, sdo_timeout=5.0)
        node = network.add_node(9)                            # nobody serves it
        pending = asyncio.ensure_future(node.sdo.upload_async(0x1000))
        await asyncio.sleep(0.01)
        network.close()                                       # the bus stays open
        with pytest.raises(motorbus.ClosedError):
            await pending
        with pytest.raises(motorbus.ClosedError):
            node.sdo.upload(0x1000)
        assert not bus.closed

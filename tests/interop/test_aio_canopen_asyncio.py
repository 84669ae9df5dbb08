"""Awaited SDO across libraries, over python-can's `virtual` interface:

* canopen-asyncio 2.4.1 (module ``canopen_asyncio``) as the awaiting client of our
  LocalNode: expedited and segmented, both directions, many awaited at once;
* our awaitable client (``await node.sdo[...].get()``) against canopen-asyncio's
  LocalNode (its SDO server), typed values and a segmented string, and the abort
  its server answers for a missing object.
"""
import asyncio
import itertools
import logging

import can
import pytest

import motorbus
from motorbus.canopen import LocalNode, Network, ObjectDictionary, SdoAbortError

canopen_asyncio = pytest.importorskip("canopen_asyncio")
from canopen_asyncio.async_guard import AllowBlocking  # noqa: E402

logging.getLogger("canopen_asyncio").setLevel(logging.CRITICAL)
_chan = itertools.count()


def our_od(node_id):
    od = ObjectDictionary()
    od.add_variable(0x1000, "Device type", "u32", "ro", default=0x40192 + node_id)
    od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "ro", default="motorbus node")
    od.add_variable(0x6064, "Position actual value", "i32", "rw")
    od.add_variable(0x2201, "Blob", "DOMAIN", "rw", max_size=1 << 16)
    return od


def their_od(co, node_id):
    od = co.ObjectDictionary()
    for index, name, dtype, access, default in [
            (0x1000, "Device type", co.objectdictionary.UNSIGNED32, "ro", 0x40192 + node_id),
            (0x6064, "Position actual value", co.objectdictionary.INTEGER32, "rw", -7),
            (0x2001, "Gain", co.objectdictionary.REAL32, "rw", 1.5),
            (0x1008, "Manufacturer device name", co.objectdictionary.VISIBLE_STRING, "ro", "canopen-asyncio node")]:
        v = co.objectdictionary.ODVariable(name, index, 0)
        v.data_type, v.access_type, v.default = dtype, access, default
        od.add_object(v)
    return od


async def test_canopen_asyncio_awaits_our_local_nodes():
    channel = f"aio-interop-{next(_chan)}"
    bus = motorbus.open_bus(can.Bus(interface="virtual", channel=channel))
    ods = {n: our_od(n) for n in range(1, 9)}
    nodes = [LocalNode(bus, n, ods[n]) for n in ods]
    net = canopen_asyncio.Network(loop=asyncio.get_running_loop())
    try:
        with AllowBlocking():
            net.connect(interface="virtual", channel=channel)
            remote = {n: net.add_node(n, their_od(canopen_asyncio, n)) for n in ods}
        values = await asyncio.gather(*[remote[n].sdo["Device type"].aget_raw() for n in ods])
        assert values == [0x40192 + n for n in ods]
        await remote[3].sdo["Position actual value"].aset_raw(-1234)
        assert ods[3][0x6064].value == -1234
        assert await remote[3].sdo.aupload(0x1008, 0) == b"motorbus node"          # segmented
        data = bytes(range(200))
        await remote[4].sdo.adownload(0x2201, 0, data)                               # segmented down
        assert ods[4][0x2201].raw == data
    finally:
        with AllowBlocking():
            net.disconnect()
        for n in nodes:
            n.close()
        bus.close()


async def test_our_awaitable_client_against_canopen_asyncio_local_node():
    channel = f"aio-interop-{next(_chan)}"
    server = canopen_asyncio.Network()         # no loop: its server runs on python-can's notifier thread
    server.connect(interface="virtual", channel=channel)
    local = server.create_node(6, their_od(canopen_asyncio, 6))
    ours = Network(motorbus.open_bus(can.Bus(interface="virtual", channel=channel)), sdo_timeout=2.0)
    try:
        od = ObjectDictionary()
        od.add_variable(0x1000, "Device type", "u32", "ro")
        od.add_variable(0x6064, "Position actual value", "i32", "rw")
        od.add_variable(0x2001, "Gain", "f32", "rw")
        od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "ro")
        node = ours.add_node(6, od)
        assert await node.sdo["Device type"].get() == 0x40192 + 6
        assert await node.sdo["Position actual value"].get() == -7
        assert await node.sdo["Gain"].get() == 1.5
        assert await node.sdo["Manufacturer device name"].get() == "canopen-asyncio node"   # segmented up
        await node.sdo["Position actual value"].set(99)
        with AllowBlocking():
            assert local.sdo["Position actual value"].raw == 99
        reads = await asyncio.gather(*[node.sdo["Position actual value"].get() for _ in range(20)])
        assert reads == [99] * 20
        with pytest.raises(SdoAbortError) as e:
            await node.sdo.upload_async(0x7777, 0)
        assert e.value.code == 0x06020000
    finally:
        ours.close()
        with AllowBlocking():
            server.disconnect()

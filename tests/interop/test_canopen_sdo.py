"""SDO interop with the `canopen` package over python-can's `virtual` interface.

* canopen's RemoteNode (its SDO client) against our LocalNode: expedited,
  segmented, block upload and download of 1 KiB and 64 KiB; our EDS export is
  what canopen loads as the node's dictionary.
* our SdoClient against canopen's LocalNode: expedited, segmented, and block
  (canopen's server has no block mode: it refuses block download, so our
  client falls back to segmented, and switches block upload to a plain one).
"""
import itertools

import can
import canopen
import pytest

import motorbus
from motorbus.canopen import LocalNode, ObjectDictionary, SdoAbortError, SdoClient

_chan = itertools.count()


def payload(n):
    return bytes((i * 13 + (i >> 8)) & 0xFF for i in range(n))


def our_od():
    od = ObjectDictionary()
    od.add_variable(0x1000, "Device type", "u32", "ro", default=0x40192)
    od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "ro", default="motorbus node")
    od.add_variable(0x2003, "Baud index", "u8", "rw", low=0, high=8, default=4)
    od.add_variable(0x6064, "Position actual value", "i32", "rw", pdo_mappable=True)
    od.add_variable(0x2201, "Blob", "DOMAIN", "rw", max_size=1 << 20)
    return od


@pytest.fixture
def ours_served(tmp_path):
    """Our LocalNode (node 5) on a python-can virtual channel; canopen's network as the client."""
    channel = f"mb-sdo-{next(_chan)}"
    pc = can.Bus(interface="virtual", channel=channel)
    bus = motorbus.open_bus(pc)
    od = our_od()
    node = LocalNode(bus, 5, od)
    eds = tmp_path / "ours.eds"
    od.save_eds(str(eds))
    network = canopen.Network()
    network.connect(interface="virtual", channel=channel)
    remote = network.add_node(5, str(eds))
    remote.sdo.RESPONSE_TIMEOUT = 2.0
    yield od, remote
    network.disconnect()
    node.close()
    bus.close()


def test_canopen_client_expedited(ours_served):
    od, remote = ours_served
    assert remote.sdo.upload(0x1000, 0) == (0x40192).to_bytes(4, "little")
    assert remote.sdo["Device type"].raw == 0x40192  # found by name in our exported EDS
    remote.sdo["Position actual value"].raw = -1234
    assert od[0x6064].value == -1234
    remote.sdo.download(0x2003, 0, b"\x07")
    assert od["Baud index"].value == 7
    with pytest.raises(canopen.SdoAbortedError) as e:
        remote.sdo.download(0x2003, 0, b"\x09")
    assert e.value.code == 0x06090031


def test_canopen_client_segmented(ours_served):
    od, remote = ours_served
    assert remote.sdo.upload(0x1008, 0) == b"motorbus node"
    remote.sdo.download(0x2201, 0, payload(100), force_segment=True)
    assert od[0x2201].raw == payload(100)


@pytest.mark.parametrize("n", [1024, 8192])  # 64 KiB segmented takes canopen ~6 s: block covers it
def test_canopen_client_segmented_sizes(ours_served, n):
    od, remote = ours_served
    data = payload(n)
    remote.sdo.download(0x2201, 0, data)
    assert od[0x2201].raw == data
    assert remote.sdo.upload(0x2201, 0) == data


@pytest.mark.parametrize("n", [1024, 65536])
def test_canopen_client_block(ours_served, n):
    od, remote = ours_served
    data = payload(n)
    with remote.sdo.open(0x2201, 0, "wb", size=len(data), block_transfer=True) as f:
        f.write(data)
    assert od[0x2201].raw == data
    od[0x2201].raw = data[::-1]
    with remote.sdo.open(0x2201, 0, "rb", block_transfer=True) as f:
        back = f.read()
    assert back == data[::-1]


@pytest.fixture
def theirs_served():
    """canopen's LocalNode (node 6) on a python-can virtual channel; our SdoClient as the client."""
    channel = f"mb-sdo-{next(_chan)}"
    network = canopen.Network()
    network.connect(interface="virtual", channel=channel)
    cod = canopen.ObjectDictionary()
    for index, name, dtype, value in [
        (0x2000, "U8", canopen.objectdictionary.UNSIGNED8, 8),
        (0x2001, "I32", canopen.objectdictionary.INTEGER32, -5),
        (0x2002, "Name", canopen.objectdictionary.VISIBLE_STRING, "canopen local node"),
        (0x2003, "Blob", canopen.objectdictionary.DOMAIN, None),
    ]:
        var = canopen.objectdictionary.ODVariable(name, index, 0)
        var.data_type = dtype
        var.access_type = "rw"
        if value is not None:
            var.default = value
        cod.add_object(var)
    local = canopen.LocalNode(6, cod)
    network.add_node(local)
    pc = can.Bus(interface="virtual", channel=channel)
    bus = motorbus.open_bus(pc)
    # canopen's LocalNode has no block server: block transfers reach it only
    # through the explicit fall-back to segmented (off by default).
    sdo = SdoClient(bus, 6, timeout=1.0, block_fallback=True)
    yield local, sdo
    bus.close()
    network.disconnect()


def test_our_client_expedited_against_canopen(theirs_served):
    local, sdo = theirs_served
    assert sdo.read_u8(0x2000) == 8
    assert sdo.read_i32(0x2001) == -5
    sdo.write_i32(0x2001, 0, 123456)
    assert local.sdo.upload(0x2001, 0) == (123456).to_bytes(4, "little", signed=True)
    with pytest.raises(SdoAbortError) as e:
        sdo.upload(0x5555, 0)
    assert e.value.code == 0x06020000


@pytest.mark.parametrize("n", [100, 1024])
def test_our_client_segmented_against_canopen(theirs_served, n):
    local, sdo = theirs_served
    assert sdo.read_string(0x2002) == "canopen local node"
    data = payload(n)
    sdo.download(0x2003, 0, data, segmented=True)
    assert local.sdo.upload(0x2003, 0) == data
    assert sdo.upload(0x2003, 0) == data


def test_our_client_block_falls_back_against_canopen(theirs_served):
    local, sdo = theirs_served
    data = payload(1024)
    sdo.download(0x2003, 0, data, block=True)  # canopen's server answers 0x05040001 (B16)
    assert local.sdo.upload(0x2003, 0) == data
    assert sdo.counters.fallbacks == 1
    # For block upload canopen's server switches protocol (answers a plain upload, no CRC): followed
    # because block_fallback=True accepts CRC-less answers, and counted as a fallback (without it,
    # an unallowed switch is refused: issue 28 item 5).
    assert sdo.upload(0x2003, 0, block=True) == data
    assert sdo.counters.fallbacks == 2

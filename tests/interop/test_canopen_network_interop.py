"""Our Network reads and writes, by name, a node served by the `canopen`
package: canopen's LocalNode on a python-can bus of our own (interface
"motorbus", a virtual hub), our Network on the same hub; both sides load the
same EDS file (which we exported)."""
import itertools

import can
import canopen
import pytest

from motorbus.canopen import Network, ObjectDictionary, SdoAbortError

_hub = itertools.count()


@pytest.fixture()
def served(tmp_path):
    od = ObjectDictionary()
    od.add_variable(0x1000, "Device type", "u32", "ro", default=0x00020192)
    od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "ro", default="canopen node")
    od.add_record(0x1018, "Identity object")
    od.add_member(0x1018, 1, "Vendor-ID", "u32", "ro", default=0x12E)
    od.add_variable(0x2000, "Offset", "i16", "rw", default=-5)
    od.add_variable(0x2001, "Gain", "f32", "rw", default=1.5)
    eds = tmp_path / "node.eds"
    od.save_eds(str(eds))
    channel = f"virtual:co-net-{next(_hub)}"
    pc = can.Bus(interface="motorbus", channel=channel)
    theirs = canopen.Network(pc)
    theirs.connect()
    local = theirs.create_node(7, str(eds))
    with Network(channel, sdo_timeout=1.0) as ours:
        yield ours, local, eds
    theirs.disconnect()


def test_our_network_reads_and_writes_canopen_local_node_by_name(served):
    ours, local, eds = served
    node = ours.add_node(7, str(eds))
    assert node.sdo["Device type"].raw == 0x00020192
    assert node.sdo["Identity object"]["Vendor-ID"].raw == 0x12E
    assert node.sdo["Manufacturer device name"].value == "canopen node"   # segmented upload
    assert node.sdo["Offset"].raw == -5
    assert node.sdo["Gain"].value == 1.5
    node.sdo["Offset"].raw = -300
    assert local.sdo["Offset"].raw == -300
    node.sdo["Gain"].value = 0.25
    assert local.sdo["Gain"].raw == 0.25
    with pytest.raises(SdoAbortError):
        node.sdo["Device type"].raw = 1                  # read-only in their dictionary too

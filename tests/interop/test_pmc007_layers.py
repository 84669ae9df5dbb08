"""The PMC007 adapter stands on the CANopen layer (issue 24 item 4), checked from both ends.

* Its dictionary, as Python sees it, is the C++ table handed up typed: every entry is a
  ``motorbus.canopen.Variable`` whose encode/decode is the C++ codec; an SDO write by name of
  every data type the dictionary has round-trips through the simulator over socketcand, and
  the bytes on the node are the manual's little-endian encoding.
* ``Drive.move_to`` walked down to the wire: the frames one move sends, recorded as a candump
  log on the bench's bus, are byte for byte the SDO requests the manual's objects make
  (6001h controller status, 6003h maximum speed, 601Ch absolute displacement command).
* No CANopen vendor module packs or unpacks values itself (struct, int.to_bytes/from_bytes,
  a table of type sizes): the source says so.
"""
from __future__ import annotations

import pathlib
import re
import time

import pytest

import motorbus
from motorbus import _core
from motorbus.canopen import DataType, ObjectDictionary, Variable
from motorbus.drives import pmc007
from motorbus.drives.pmc007 import Pmc007
from motorbus.sim import SimBench
from polling import wait_for

NODE = 5


@pytest.fixture
def bench():
    name = f"virtual:pmc007-layers-{time.monotonic_ns()}"
    with SimBench([f"pmc007:{NODE}"], bus=name) as b:
        srv = b.can.servers[0]
        yield b, f"socketcand:{srv.host}:{srv.port}/can0"


def test_the_dictionary_python_sees_is_the_typed_cpp_table():
    od = _core.pmc007.object_dictionary(NODE)
    assert isinstance(od, ObjectDictionary)
    assert len(pmc007.OBJECTS) == 210
    assert all(isinstance(v, Variable) for v in pmc007.OBJECTS.values())
    # Names from the table, types from the table (not from strings rebuilt in Python).
    start = pmc007.OBJECTS["start_speed"]
    assert (start.index, start.subindex, start.data_type, start.access) == (0x6006, 0, DataType.UNSIGNED16, "rw")
    speed = pmc007.OBJECTS["maximum_speed"]
    assert speed.data_type == DataType.INTEGER32
    assert speed.value_range == (-32000, 32000)     # the table's limits (003 §4.5.4)
    assert pmc007.OBJECTS["controller_status"].value_range == (0, 255)   # no limits: the type's range
    # The entry's codec is the C++ one (the same bytes as canopen.encode_value, and the manual's).
    assert speed.encode(-1200) == _core.canopen.encode_value(DataType.INTEGER32, -1200) == b"\x50\xfb\xff\xff"
    assert speed.decode(b"\x50\xfb\xff\xff") == -1200
    assert start.encode(600) == b"\x58\x02"
    with pytest.raises(motorbus.InvalidArgument, match="Start speed: 70000 does not fit UNSIGNED16"):
        start.encode(70000)
    name = pmc007.OBJECTS["manufacturer_device_name"]
    assert name.data_type == DataType.VISIBLE_STRING and name.decode(b"PMC007") == "PMC007"
    # A client's dictionary is its node's: $NODEID defaults evaluated for that node.
    assert _core.pmc007.object_dictionary(9)[0x1800, 1].default == 0x189
    assert _core.pmc007.storage(0x6006) == _core.pmc007.Storage.ROM
    assert _core.pmc007.storage(0x600C) == _core.pmc007.Storage.RAM


# One object of every data type the dictionary has, written by name at both ends of its
# range and read back over socketcand (VISIBLE_STRING objects are all const: read only).
ROUND_TRIPS = {
    DataType.UNSIGNED8: ("acceleration_coefficient", (0, 8)),            # 6008h, limits 0..8
    DataType.UNSIGNED16: ("start_speed", (0, 0xFFFF)),                   # 6006h, the whole U16
    DataType.UNSIGNED32: ("communication_cycle_period", (0, 0xFFFFFFFF)),  # 1006h
    DataType.INTEGER32: ("motor_position", (-(1 << 31), (1 << 31) - 1)),  # 600Ch sets the counter
}


def test_an_sdo_write_by_name_of_every_type_round_trips_over_socketcand(bench):
    b, spec = bench
    types = {v.data_type for v in pmc007.OBJECTS.values()}
    assert types == set(ROUND_TRIPS) | {DataType.VISIBLE_STRING}, "a new data type needs a round trip here"
    with motorbus.open_bus(spec) as bus, Pmc007(bus, NODE, on_error=None, on_exit=None) as c:
        for dtype, (name, values) in ROUND_TRIPS.items():
            var = pmc007.OBJECTS[name]
            assert var.data_type == dtype
            for value in values:
                c.write(name, value)
                assert c.read(name) == value
                # On the node: the manual's little-endian bytes of the type's size (uploaded raw).
                signed = dtype == DataType.INTEGER32
                assert c.sdo.upload(var.index, var.subindex) == value.to_bytes(var.size, "little", signed=signed)
                assert c[f"0x{var.index:04X}:{var.subindex:02X}"] == value
        assert c.read("manufacturer_device_name") == "PMC007 (motorbus sim)"
        with pytest.raises(motorbus.InvalidArgument, match="does not fit UNSIGNED8"):
            c.write("acceleration_coefficient", 256)          # refused by the codec, nothing sent
        with pytest.raises(motorbus.canopen.SdoAbortError) as e:
            c.write("acceleration_coefficient", 9)            # fits U8: the device's limit answers
        assert e.value.code in (0x06090030, 0x06090031)       # value range / value too high


def _sdo(cob: int, *data: int) -> tuple[int, bytes]:
    return cob, bytes(data) + bytes(8 - len(data))


def test_a_move_to_walked_down_to_the_wire_bytes(bench, tmp_path):
    b, spec = bench
    log = tmp_path / "move.log"
    tap = b.can.endpoint()                     # the bench's bus: every frame either way
    with motorbus.open_drive("pmc007", bus=spec, address=NODE, on_error=None, on_exit=None) as axis:
        axis.enable()
        rec = motorbus.Recorder(tap, str(log))
        # The recorder listens once it has seen a whole exchange (1000h: not part of the move).
        wait_for(lambda: axis.native.read("device_type") == 0 and rec.count >= 2, 3.0)
        axis.move_to(3200, velocity=1500, wait=False)
        axis.wait_idle(timeout=30)
        assert axis.position == 3200
        rec.stop()
    tap.close()
    entries, bad = motorbus.read_log(str(log))
    assert bad == 0
    frames = [(e.frame.id, bytes(e.frame.data)) for e in entries]
    last_warm_up = max(i for i, f in enumerate(frames) if f[1][1:3] == b"\x00\x10")
    frames = frames[last_warm_up + 1:]
    rx, tx = 0x600 + NODE, 0x580 + NODE
    # The manual's objects (003 §4.5): 6001h controller status (U8: busy?), 6003h maximum
    # speed (I32, read to be put back after the move, then 1500 = 0x05DC), 601Ch absolute
    # displacement command (I32, 3200 = 0x0C80).  Expedited SDO: 40h upload; 23h download
    # of 4 bytes; answers 4Fh (1 byte) / 43h (4 bytes) / 60h.
    assert frames[:10] == [
        _sdo(rx, 0x40, 0x01, 0x60, 0x00), _sdo(tx, 0x4F, 0x01, 0x60, 0x00, 0x00),
        _sdo(rx, 0x40, 0x03, 0x60, 0x00), (tx, frames[3][1]),
        _sdo(rx, 0x23, 0x03, 0x60, 0x00, 0xDC, 0x05, 0x00, 0x00), _sdo(tx, 0x60, 0x03, 0x60, 0x00),
        _sdo(rx, 0x23, 0x1C, 0x60, 0x00, 0x80, 0x0C, 0x00, 0x00), _sdo(tx, 0x60, 0x1C, 0x60, 0x00),
    ] + frames[8:10]
    assert frames[3][1][:4] == bytes([0x43, 0x03, 0x60, 0x00])     # 6003h read back: 4 bytes


def test_the_client_is_a_node_profile_standing_on_its_bus(bench):
    b, spec = bench
    with motorbus.open_bus(spec) as bus, Pmc007(bus, NODE, on_error=None, on_exit=None) as c:
        assert isinstance(c, motorbus.canopen.RemoteNode) and c.network is None and c.id == NODE
        assert c.sdo["Start speed"].raw == 400                 # the node facade, by the table's names
        assert c.variable("0x6006").od is c.object_dictionary[0x6006, 0]
        cob = c.configure_tpdo(1, ["motor_position"], event_timer_ms=20)
        assert c.tpdo[1].mapping == [(0x600C, 0, 32)] and c.tpdo[1].cob_id == cob == 0x180 + NODE
        c.nmt(0x01)                                              # start: PDOs flow
        c.write("motor_position", -5)
        assert c.tpdo[1].wait_for_reception(2.0) == {(0x600C, 0): -5}   # signed, from the entry
        with pytest.raises(motorbus.InvalidArgument, match="come with a Network"):
            c.emcy
    for good, node in ((5, 5), ("05", 5), ("0x7F", 127), (" 12 ", 12)):
        assert motorbus.canopen.check_node_id(good, "x") == node
    for bad in (0, 128, "node", True, "9" * 20):
        with pytest.raises(motorbus.InvalidArgument, match="x address"):
            motorbus.canopen.check_node_id(bad, "x")


def test_cia402_and_arcus_canopen_adapters_read_and_write_by_typed_cpp_dictionaries():
    from motorbus.drives import arcus_canopen, cia402
    generic, arcus = cia402.Cia402Drive.object_dictionary(), arcus_canopen.ArcusCanopenDrive.object_dictionary()
    assert isinstance(generic, ObjectDictionary) and isinstance(arcus, ObjectDictionary)
    # The same rows as the C++ tables the simulators serve, typed by them.
    assert {(r[0], r[1]) for r in cia402.OBJECTS} <= {(i, s) for i in generic.indices() for s in generic.subindices(i)}
    assert generic[0x607A, 0].data_type == DataType.INTEGER32 and generic[0x607A, 0].encode(-1) == b"\xff" * 4
    assert generic[0x6041, 0].decode(b"\x37\x06") == 0x0637
    assert arcus[0x2004, 2].value_range == (100, 2500)             # Run current, mA: the table's range
    assert arcus[0x6060, 0].access == "wo" and arcus[0x6060, 0].encode(-1) == b"\xff"


VENDORS = ["pmc007.py", "cia402.py", "arcus_canopen.py"]


@pytest.mark.parametrize("module", VENDORS)
def test_no_canopen_vendor_packs_values_itself(module):
    """Values go through the dictionary's C++ codecs and the PDO layer: a vendor module that
    imports struct, converts ints to bytes or keeps a table of type sizes re-encodes."""
    text = (pathlib.Path(pmc007.__file__).parent / module).read_text()
    for pattern in (r"^import struct|^from struct", r"\.to_bytes\(", r"\.from_bytes\(", r"_SIZES\b",
                    r'"U16":\s*2'):
        assert not re.search(pattern, text, re.M), f"{module}: {pattern}"

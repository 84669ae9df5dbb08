"""The DMX-CAN's CANopen persona served by `motorbus sim serve` over socketcand,
reached by independent peers: python-can (raw frames, byte for byte) and the
`canopen` package (RemoteNode SDO reads of the whole dictionary, BaseNode402
through the state machine, a profile-position move and a homing).

The manual's CANopen chapters give values, not frames (spec §3.5): each worked
example is asserted as the CiA 301 expedited frame that carries it.
"""
import json
import pathlib
import signal
import subprocess
import sys
import time

import can
import canopen
import pytest

DATA = json.loads((pathlib.Path(__file__).parents[1] / "data/arcus_canopen/seed_examples.json").read_text())
SEED = DATA["arcus_dmx_canopen"]
NODE = SEED["node_id_default"]

# Spec can-drives.md §3.2 (Table 10.1, CANopen tables' defaults): index, sub, type, access, default.
# None = a live value (checked elsewhere).
OD = [
    (0x1000, 0, "U32", "const", 0x0192), (0x1001, 0, "U8", "ro", 0), (0x1008, 0, "VS", "ro", b"DMC"),
    (0x1018, 0, "U8", "ro", 4), (0x1018, 1, "U32", "ro", 0), (0x1018, 2, "U32", "ro", 0),
    (0x1018, 3, "U32", "ro", 112), (0x1018, 4, "U32", "ro", 0),
    (0x2000, 0, "U8", "rw", 1), (0x2001, 0, "U8", "ro", 5), (0x2001, 1, "U32", "rw", 1),
    (0x2001, 2, "U32", "rw", 10), (0x2001, 3, "U32", "rw", 10), (0x2001, 4, "U32", "rw", 5),
    (0x2001, 5, "U32", "rw", 1000), (0x2002, 0, "I32", "ro", 0), (0x2003, 0, "U16", "ro", 0),
    (0x2004, 0, "U8", "ro", 4), (0x2004, 1, "U16", "ro", None), (0x2004, 2, "U16", "rw", 1500),
    (0x2004, 3, "U16", "rw", 500), (0x2004, 4, "U16", "rw", 500), (0x2005, 0, "U8", "rw", 7),
    (0x2006, 0, "U8", "rw", 0), (0x2007, 0, "U8", "rw", 0), (0x2008, 0, "U8", "ro", 0),
    (0x2009, 0, "U8", "ro", 2), (0x2009, 1, "I32", "ro", 0), (0x2009, 2, "I32", "ro", 0),
    (0x200A, 0, "U8", "rw", 2), (0x200B, 0, "U8", "rw", 5), (0x200C, 0, "U8", "rw", 1),
    (0x200D, 0, "U8", "rw", 0), (0x200E, 0, "U8", "rw", 0),
    (0x6040, 0, "U16", "rw", 0), (0x6041, 0, "U16", "ro", None), (0x6060, 0, "I8", "wo", None),
    (0x6061, 0, "I8", "ro", 0), (0x6064, 0, "I32", "ro", 0), (0x606C, 0, "I32", "ro", 0),
    (0x607A, 0, "I32", "rw", 0), (0x607C, 0, "I32", "rw", 0), (0x607E, 0, "U8", "rw", 0),
    (0x6081, 0, "U32", "rw", None), (0x6082, 0, "U32", "rw", None), (0x6083, 0, "U32", "rw", None),
    (0x6084, 0, "U32", "rw", None), (0x6086, 0, "I16", "rw", 0), (0x6098, 0, "I8", "rw", 35),
    (0x6099, 0, "U8", "ro", 2), (0x6099, 1, "U32", "rw", None), (0x6099, 2, "U32", "rw", None),
    (0x609A, 0, "U32", "rw", None), (0x60FD, 0, "U32", "ro", 0), (0x60FE, 0, "U32", "rw", 0x0003_0000),
    # 60FEh at boot: 2005h = 7, but with 2000h = 1 and StepNLoop on DO1 is "in position" (on) and DO3 "alarm" (off).
    (0x60FF, 0, "I32", "rw", 0), (0x6402, 0, "U16", "ro", SEED["motor_type_6402"]),
    (0x6502, 0, "U32", "ro", SEED["supported_modes_6502"]),
]
_TYPES = {"U8": canopen.objectdictionary.UNSIGNED8, "U16": canopen.objectdictionary.UNSIGNED16,
          "U32": canopen.objectdictionary.UNSIGNED32, "I8": canopen.objectdictionary.INTEGER8,
          "I16": canopen.objectdictionary.INTEGER16, "I32": canopen.objectdictionary.INTEGER32,
          "VS": canopen.objectdictionary.VISIBLE_STRING}


def _object_dictionary() -> canopen.ObjectDictionary:
    od = canopen.ObjectDictionary()
    records = {}
    for index, sub, dtype, access, _default in OD:
        var = canopen.objectdictionary.ODVariable(f"o{index:04X}_{sub}", index, sub)
        var.data_type = _TYPES[dtype]
        var.access_type = access
        if any(i == index and s != 0 for i, s, *_ in OD):
            rec = records.get(index)
            if rec is None:
                rec = records[index] = canopen.objectdictionary.ODRecord(f"r{index:04X}", index)
                od.add_object(rec)
            rec.add_member(var)
        else:
            od.add_object(var)
    return od


@pytest.fixture(scope="module")
def served():
    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", "--bus", "virtual:bench",
                             "--socketcand", "127.0.0.1:0", "--drive", f"arcus-canopen:{NODE}"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    word, hostport, channel = proc.stdout.readline().split()
    assert word == "socketcand" and channel == "can0"
    host, port = hostport.rsplit(":", 1)
    yield host, int(port)
    proc.send_signal(signal.SIGINT)
    assert proc.wait(10) == 0


@pytest.fixture
def bus(served):
    host, port = served
    b = can.Bus(interface="socketcand", host=host, port=port, channel="can0")
    yield b
    b.shutdown()


def _exchange(bus, request: bytes, reply_id: int = 0x580 + NODE, send_id: int = 0x600 + NODE) -> bytes:
    bus.send(can.Message(arbitration_id=send_id, data=request, is_extended_id=False))
    deadline = time.monotonic() + 2
    while time.monotonic() < deadline:
        m = bus.recv(0.5)
        if m is not None and m.arbitration_id == reply_id:
            return bytes(m.data)
    raise AssertionError(f"no reply on 0x{reply_id:03X} to {request.hex(' ')}")


def _reset(bus):
    """NMT reset node: the drive power-cycles and sends its boot-up (B-A03)."""
    bus.send(can.Message(arbitration_id=0, data=bytes([0x81, NODE]), is_extended_id=False))
    deadline = time.monotonic() + 2
    while time.monotonic() < deadline:
        m = bus.recv(0.5)
        if m is not None and m.arbitration_id == 0x700 + NODE:
            assert bytes(m.data) == b"\x00"
            return
    raise AssertionError("no boot-up after NMT reset node")


def test_worked_examples_byte_for_byte(bus):
    _reset(bus)
    # E-A01/E-A02: node 1 by default, request 0x600 + n, reply 0x580 + n.
    assert SEED["sdo_request_id"] == "0x600 + node" and SEED["sdo_reply_id"] == "0x580 + node"
    assert _exchange(bus, bytes.fromhex("40 0C 20 00 00 00 00 00")) == bytes.fromhex("4F 0C 20 00 01 00 00 00")
    # E-A03: 6402h = 768 (U16), E-A04: 6502h = 37.
    assert _exchange(bus, bytes.fromhex("40 02 64 00 00 00 00 00")) == bytes.fromhex("4B 02 64 00 00 03 00 00")
    assert _exchange(bus, bytes.fromhex("40 02 65 00 00 00 00 00")) == bytes.fromhex("43 02 65 00 25 00 00 00")
    # E-A07: 1008h = "DMC" (3 bytes), E-A08: 1018h:03 = 112.
    assert _exchange(bus, bytes.fromhex("40 08 10 00 00 00 00 00")) == bytes.fromhex("47 08 10 00 44 4D 43 00")
    assert _exchange(bus, bytes.fromhex("40 18 10 03 00 00 00 00")) == bytes.fromhex("43 18 10 03 70 00 00 00")
    # E-A05: modes 1, 3, 6 accepted, anything else refused; 6060h is write-only.
    for mode in SEED["modes_of_operation"]:
        assert _exchange(bus, bytes([0x2F, 0x60, 0x60, 0, int(mode), 0, 0, 0])) == bytes.fromhex("60 60 60 00 00 00 00 00")
    for bad in (0, 2, 4, 5, 7, -1):
        assert _exchange(bus, bytes([0x2F, 0x60, 0x60, 0, bad & 0xFF, 0, 0, 0])) == bytes.fromhex("80 60 60 00 30 00 09 06")
    assert _exchange(bus, bytes.fromhex("40 60 60 00 00 00 00 00")) == bytes.fromhex("80 60 60 00 01 00 01 06")
    # E-A06: the nine homing methods, nothing else.
    for method in SEED["homing_methods"]:
        assert _exchange(bus, bytes([0x2F, 0x98, 0x60, 0, int(method), 0, 0, 0]))[0] == 0x60
        assert _exchange(bus, bytes.fromhex("40 98 60 00 00 00 00 00")) == bytes([0x4F, 0x98, 0x60, 0, int(method), 0, 0, 0])
    for bad in (1, 6, 21, 32, 36, -1):
        assert _exchange(bus, bytes([0x2F, 0x98, 0x60, 0, bad & 0xFF, 0, 0, 0])) == bytes.fromhex("80 98 60 00 30 00 09 06")
    # E-A09: bit-rate codes 1..9, default 5 (125 kbit/s).
    assert _exchange(bus, bytes.fromhex("40 0B 20 00 00 00 00 00")) == bytes.fromhex("4F 0B 20 00 05 00 00 00")
    for bad in (0, 10):
        assert _exchange(bus, bytes([0x2F, 0x0B, 0x20, 0, bad, 0, 0, 0])) == bytes.fromhex("80 0B 20 00 30 00 09 06")
    # E-A10: the CANopen tables' defaults (StepNLoop 1/10/10/5/1000, currents 1500/500/500).
    for sub, value in ((1, 1), (2, 10), (3, 10), (4, 5), (5, 1000)):
        assert _exchange(bus, bytes([0x40, 0x01, 0x20, sub, 0, 0, 0, 0])) == bytes([0x43, 0x01, 0x20, sub]) + value.to_bytes(4, "little")
    for sub, value in ((2, 1500), (3, 500), (4, 500)):
        assert _exchange(bus, bytes([0x40, 0x04, 0x20, sub, 0, 0, 0, 0])) == bytes([0x4B, 0x04, 0x20, sub]) + value.to_bytes(2, "little") + b"\0\0"


def test_expedited_only_and_the_cia301_abort_codes(bus):
    _reset(bus)
    abort = lambda index, sub, code: bytes([0x80, index & 0xFF, index >> 8, sub]) + code.to_bytes(4, "little")  # noqa: E731
    # Segmented download and block transfers are refused (B-A02).
    assert _exchange(bus, bytes.fromhex("21 08 10 00 10 00 00 00")) == abort(0x1008, 0, 0x05040001)
    assert _exchange(bus, bytes.fromhex("A4 08 10 00 7F 00 00 00")) == abort(0x1008, 0, 0x05040001)
    assert _exchange(bus, bytes.fromhex("C6 08 10 00 10 00 00 00")) == abort(0x1008, 0, 0x05040001)
    # Objects outside Table 10.1, a missing sub-index, read-only and const objects, sizes, ranges.
    assert _exchange(bus, bytes.fromhex("40 17 10 00 00 00 00 00")) == abort(0x1017, 0, 0x06020000)
    assert _exchange(bus, bytes.fromhex("40 62 60 00 00 00 00 00")) == abort(0x6062, 0, 0x06020000)
    assert _exchange(bus, bytes.fromhex("40 01 20 06 00 00 00 00")) == abort(0x2001, 6, 0x06090011)
    assert _exchange(bus, bytes.fromhex("2B 41 60 00 00 00 00 00")) == abort(0x6041, 0, 0x06010002)
    assert _exchange(bus, bytes.fromhex("23 00 10 00 00 00 00 00")) == abort(0x1000, 0, 0x06010002)
    assert _exchange(bus, bytes.fromhex("2F 08 20 00 01 00 00 00")) == abort(0x2008, 0, 0x06010002)  # C-A01
    assert _exchange(bus, bytes.fromhex("23 40 60 00 0F 00 00 00")) == abort(0x6040, 0, 0x06070012)
    assert _exchange(bus, bytes.fromhex("2F 7A 60 00 01 00 00 00")) == abort(0x607A, 0, 0x06070013)
    assert _exchange(bus, bytes.fromhex("2F 00 20 00 02 00 00 00")) == abort(0x2000, 0, 0x06090030)
    assert _exchange(bus, bytes.fromhex("2F 0C 20 00 00 00 00 00")) == abort(0x200C, 0, 0x06090030)
    assert _exchange(bus, bytes.fromhex("2F 0C 20 00 80 00 00 00")) == abort(0x200C, 0, 0x06090030)
    assert _exchange(bus, bytes.fromhex("2B 04 20 02 63 00 00 00")) == abort(0x2004, 2, 0x06090030)
    assert _exchange(bus, bytes.fromhex("2B 04 20 02 C5 09 00 00")) == abort(0x2004, 2, 0x06090030)
    # 2004h is printed U8 but holds 2500: 2- and 4-byte writes both work (C-A02).
    assert _exchange(bus, bytes.fromhex("23 04 20 02 B0 04 00 00")) == bytes.fromhex("60 04 20 02 00 00 00 00")
    assert _exchange(bus, bytes.fromhex("40 04 20 02 00 00 00 00")) == bytes.fromhex("4B 04 20 02 B0 04 00 00")
    # Another node's requests are not answered, and an abort from the client gets no reply.
    bus.send(can.Message(arbitration_id=0x600 + NODE, data=abort(0x6041, 0, 0x05040000), is_extended_id=False))
    bus.send(can.Message(arbitration_id=0x600 + NODE + 1, data=bytes.fromhex("40 00 10 00 00 00 00 00"),
                         is_extended_id=False))
    m = bus.recv(0.2)
    assert m is None, m


def test_canopen_remote_node_reads_every_object_with_its_documented_default(served):
    host, port = served
    bus = can.Bus(interface="socketcand", host=host, port=port, channel="can0")
    net = canopen.Network(bus)
    net.connect = lambda *a, **k: None
    net.notifier = can.Notifier(bus, net.listeners, 1)
    try:
        net.send_message(0, bytes([0x81, NODE]))  # a fresh power-up
        time.sleep(0.2)
        node = net.add_node(NODE, _object_dictionary())
        assert len(OD) == 58 and len({i for i, *_ in OD}) == 41
        for index, sub, dtype, access, default in OD:
            entry = node.sdo[index] if not any(i == index and s for i, s, *_ in OD) else node.sdo[index][sub]
            if access == "wo":
                with pytest.raises(canopen.SdoAbortedError) as e:
                    entry.raw
                assert e.value.code == 0x06010001
                continue
            value = entry.data if dtype == "VS" else entry.raw
            if default is not None:
                assert value == default, f"0x{index:04X}:{sub:02X}"
    finally:
        net.notifier.stop()
        bus.shutdown()


def test_canopen_base_node_402_enables_moves_and_homes(served):
    host, port = served
    bus = can.Bus(interface="socketcand", host=host, port=port, channel="can0")
    net = canopen.Network(bus)
    net.connect = lambda *a, **k: None
    net.notifier = can.Notifier(bus, net.listeners, 1)
    try:
        net.send_message(0, bytes([0x81, NODE]))
        time.sleep(0.2)
        node = canopen.BaseNode402(NODE, _object_dictionary())
        net.add_node(node)
        node.setup_402_state_machine(read_pdos=False)
        assert node.state == "SWITCH ON DISABLED"
        node.op_mode = "PROFILED POSITION"
        node.state = "OPERATION ENABLED"
        assert node.statusword & 0x6F == 0x27
        node.sdo[0x6081].raw = 20000   # counts/s (StepNLoop on)
        node.sdo[0x6082].raw = 100
        node.sdo[0x6083].raw = 20      # ms
        node.sdo[0x6084].raw = 20
        node.sdo[0x607A].raw = 1000
        node.controlword = 0x1F        # new set-point, absolute
        deadline = time.monotonic() + 2
        while not node.statusword & 0x1000:  # set-point acknowledge
            assert time.monotonic() < deadline
        node.controlword = 0x0F
        deadline = time.monotonic() + 5
        while not node.statusword & 0x0400:  # target reached
            assert time.monotonic() < deadline
            time.sleep(0.01)
        assert node.sdo[0x6064].raw == 1000
        assert node.sdo[0x606C].raw == 0
        assert node.sdo[0x2003].raw == 0     # StepNLoop idle, in position
        # Homing method 19 (manual 000: home input, positive direction): 6064h = 0 at home.
        node.sdo[0x6098].raw = 19
        node.sdo[0x6099][1].raw = 20000
        node.sdo[0x6099][2].raw = 2000
        node.sdo[0x609A].raw = 20
        assert node.homing(timeout=10) is True
        assert node.sdo[0x6064].raw == 0
        assert node.op_mode == "HOMING"
        node.state = "SWITCH ON DISABLED"
        assert node.statusword & 0x4F == 0x40
    finally:
        net.notifier.stop()
        bus.shutdown()

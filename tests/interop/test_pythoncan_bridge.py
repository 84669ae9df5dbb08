"""motorbus <-> python-can in both directions."""
import can
import pytest

import motorbus
from motorbus import Frame


def _ids_data(frames):
    return [(f.arbitration_id, f.is_extended_id, bytes(f.data)) for f in frames]


CASES = [(0x000, False, b""), (0x7FF, False, bytes(range(8))), (0x1FFFFFFF, True, b"\x01\x02\x03"),
         (0x123, False, b"\xAA" * 5), (0x0, True, b"\x00")]


def test_open_bus_wraps_a_python_can_bus():
    pc_peer = can.Bus(interface="virtual", channel="bridge-1")
    wrapped = motorbus.open_bus(can.Bus(interface="virtual", channel="bridge-1"))
    try:
        for cid, ext, data in CASES:
            wrapped.send(Frame(cid, data, extended=ext))
        got = [pc_peer.recv(1.0) for _ in CASES]
        assert _ids_data(got) == CASES
        for cid, ext, data in CASES:
            pc_peer.send(can.Message(arbitration_id=cid, is_extended_id=ext, data=data))
        back = [wrapped.recv(1.0) for _ in CASES]
        assert [(f.id, f.extended, f.data) for f in back] == CASES
        pc_peer.send(can.Message(arbitration_id=0x55, is_remote_frame=True, dlc=3))
        rtr = wrapped.recv(1.0)
        assert (rtr.id, rtr.rtr, rtr.dlc) == (0x55, True, 3)
    finally:
        wrapped.close()
        pc_peer.shutdown()


def test_python_can_interface_entry_point():
    """can.Bus(interface='motorbus') resolves through the can.interface entry point."""
    mb = motorbus.open_bus("virtual:ep-1")
    pc = can.Bus(interface="motorbus", channel="virtual:ep-1")
    try:
        assert type(pc).__module__ == "motorbus.pycan"
        pc.send(can.Message(arbitration_id=0x1ABCDEF0, is_extended_id=True, data=b"\x10\x20"))
        f = mb.recv(1.0)
        assert (f.id, f.extended, f.data) == (0x1ABCDEF0, True, b"\x10\x20")
        mb.send(Frame(0x321, b"\x09"))
        m = pc.recv(1.0)
        assert (m.arbitration_id, m.is_extended_id, bytes(m.data)) == (0x321, False, b"\x09")
        with pytest.raises(can.CanOperationError):
            pc.send(can.Message(arbitration_id=0x800, is_extended_id=False))
    finally:
        pc.shutdown()
        mb.close()


def test_python_can_filters_on_motorbus_interface():
    mb = motorbus.open_bus("virtual:ep-2")
    pc = can.Bus(interface="motorbus", channel="virtual:ep-2",
                 can_filters=[{"can_id": 0x580, "can_mask": 0x780, "extended": False}])
    try:
        for i in (0x581, 0x601, 0x5FF):
            mb.send(Frame(i))
        assert [pc.recv(1.0).arbitration_id, pc.recv(1.0).arbitration_id] == [0x581, 0x5FF]
        assert pc.recv(0.02) is None
    finally:
        pc.shutdown()
        mb.close()


def test_canopen_network_runs_on_a_motorbus_bus():
    """canopen's Network connected through the motorbus python-can interface sends NMT frames."""
    import canopen

    mb = motorbus.open_bus("virtual:ep-co")
    net = canopen.Network()
    net.connect(interface="motorbus", channel="virtual:ep-co")
    try:
        net.nmt.send_command(0x01)  # start all nodes
        f = mb.recv(1.0)
        assert (f.id, f.data) == (0x000, b"\x01\x00")
    finally:
        net.disconnect()
        mb.close()

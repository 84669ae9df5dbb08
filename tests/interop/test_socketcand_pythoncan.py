"""python-can's socketcand interface against OUR SocketcandServer, and our
client against our server, in the same setting.

python-can is the reference peer: if its handshake (exact `< hi >` / `< ok >`
replies), its `< send >` spelling (single-digit hex bytes) and its frame parser
(contiguous data, empty data field) work against our server, real socketcand
clients will too.
"""
from __future__ import annotations

import itertools
import time

import can
import pytest

from motorbus import Frame
from motorbus._core.can import open_virtual
from motorbus.socketcand import SocketcandServer, open_socketcand
from polling import wait_for

_ids = itertools.count()


@pytest.fixture
def served():
    name = f"interop-sockd-{next(_ids)}"
    bus, node = open_virtual(name), open_virtual(name)
    server = SocketcandServer(bus)
    yield server, node
    server.close()
    node.close()
    bus.close()


def pc_bus(server, channel="vcan0"):
    b = can.Bus(interface="socketcand", host="127.0.0.1", port=server.port, channel=channel)
    time.sleep(0.005)  # past the rawmode settle window before traffic starts
    return b


def recv_data(bus, timeout=2.0):
    """Next data message from python-can (skips nothing: any None is a failure)."""
    msg = bus.recv(timeout)
    assert msg is not None, "python-can received nothing"
    return msg


CASES = [
    (ext, can_id, n)
    for ext, can_id in ((False, 0x000), (False, 0x123), (False, 0x7FF),
                        (True, 0x00000000), (True, 0x0ABCDEF0), (True, 0x1FFFFFFF))
    for n in range(9)
]


def payload(n: int) -> bytes:
    return bytes((0x0A + 0x11 * i) & 0xFF for i in range(n))  # includes single-digit bytes like 0x0A


def test_pythoncan_sends_every_id_width_and_dlc_to_the_bus(served):
    server, node = served
    pc = pc_bus(server)
    try:
        for ext, can_id, n in CASES:
            pc.send(can.Message(arbitration_id=can_id, is_extended_id=ext, data=payload(n)))
        for ext, can_id, n in CASES:
            got = node.recv(2)
            assert got is not None
            assert (got.id, got.extended, got.data) == (can_id, ext, payload(n))
        assert server.stats.bad_elements == 0
        assert wait_for(lambda: server.stats.frames_to_bus == len(CASES))
    finally:
        pc.shutdown()


def test_pythoncan_receives_every_id_width_and_dlc_from_the_bus(served):
    server, node = served
    pc = pc_bus(server)
    try:
        assert wait_for(lambda: server.stats.clients_active == 1)
        before = time.time()
        for ext, can_id, n in CASES:
            node.send(Frame(can_id, payload(n), extended=ext))
        for ext, can_id, n in CASES:
            msg = recv_data(pc)
            assert msg.arbitration_id == can_id
            assert msg.is_extended_id == ext
            assert bytes(msg.data) == payload(n)
            assert msg.dlc == n
            # socketcand sends wall-clock time; so do we
            assert before - 1 < msg.timestamp < time.time() + 1
    finally:
        pc.shutdown()


def test_several_pythoncan_clients_see_each_others_frames(served):
    server, node = served
    clients = [pc_bus(server) for _ in range(3)]
    try:
        assert wait_for(lambda: server.stats.clients_active == 3)
        for k, sender in enumerate(clients):
            sender.send(can.Message(arbitration_id=0x100 + k, is_extended_id=False, data=[k, 0xEE]))
            for j, other in enumerate(clients):
                if j == k:
                    continue
                msg = recv_data(other)
                assert (msg.arbitration_id, bytes(msg.data)) == (0x100 + k, bytes([k, 0xEE]))
            got = node.recv(2)  # and the rest of the bus saw it too
            assert (got.id, got.data) == (0x100 + k, bytes([k, 0xEE]))
        for c in clients:  # nobody hears their own frame back
            assert c.recv(0.05) is None
    finally:
        for c in clients:
            c.shutdown()


def test_pythoncan_and_our_client_on_the_same_server(served):
    server, node = served
    pc = pc_bus(server)
    ours = open_socketcand("127.0.0.1", server.port, "vcan0")
    try:
        assert wait_for(lambda: server.stats.clients_active == 2)
        time.sleep(0.005)
        ours.send(Frame(0x1FFFFFFF, b"\x01\x02\x03\x04\x05\x06\x07\x08", extended=True))
        msg = recv_data(pc)
        assert (msg.arbitration_id, msg.is_extended_id, bytes(msg.data)) == (
            0x1FFFFFFF, True, b"\x01\x02\x03\x04\x05\x06\x07\x08")
        pc.send(can.Message(arbitration_id=0x7FF, is_extended_id=False, data=b""))
        got = ours.recv(2)
        assert (got.id, got.extended, got.data) == (0x7FF, False, b"")
        # both reached the rest of the bus
        assert node.recv(2).id == 0x1FFFFFFF
        assert node.recv(2).id == 0x7FF
    finally:
        pc.shutdown()
        ours.close()


def test_our_client_against_our_server_every_id_width_and_dlc(served):
    server, node = served
    with open_socketcand("127.0.0.1", server.port, "vcan0") as ours:
        time.sleep(0.005)
        for ext, can_id, n in CASES:
            ours.send(Frame(can_id, payload(n), extended=ext))
        for ext, can_id, n in CASES:
            got = node.recv(2)
            assert (got.id, got.extended, got.data) == (can_id, ext, payload(n))
        for ext, can_id, n in CASES:
            node.send(Frame(can_id, payload(n), extended=ext))
        for ext, can_id, n in CASES:
            got = ours.recv(2)
            assert (got.id, got.extended, got.data) == (can_id, ext, payload(n))


def test_pythoncan_clients_answer_each_other_without_the_poll_stall(served):
    """Two python-can clients of our server in request/reply: the later-connected one's
    frame to the earlier one used to wait out the server's 50 ms poll() timeout.
    20 round trips must take far less than 20 x 50 ms (loose bound; latency is
    measured in bench/socketcand_roundtrip.py)."""
    server, _node = served
    early, late = pc_bus(server), pc_bus(server)
    try:
        assert wait_for(lambda: server.stats.clients_active == 2)
        time.sleep(0.005)
        rounds = 20
        start = time.perf_counter()
        for i in range(rounds):
            late.send(can.Message(arbitration_id=0x601, is_extended_id=False, data=bytes((0x40, i))))
            m = recv_data(early)
            assert (m.arbitration_id, bytes(m.data)) == (0x601, bytes((0x40, i)))
            early.send(can.Message(arbitration_id=0x581, is_extended_id=False, data=bytes((0x60, i))))
            m = recv_data(late)
            assert (m.arbitration_id, bytes(m.data)) == (0x581, bytes((0x60, i)))
        took = time.perf_counter() - start
        assert took < 0.5, f"{rounds} round trips took {took * 1e3:.0f} ms"
    finally:
        early.shutdown()
        late.shutdown()

"""socketcand client/server and SocketCAN from Python (over 127.0.0.1, virtual buses)."""
from __future__ import annotations

import itertools
import socket
import time

import pytest

import motorbus
from motorbus import Frame
from motorbus._core.can import open_virtual
from motorbus.socketcand import (
    SocketcandServer,
    open_socketcan,
    open_socketcand,
    socketcan_unavailable_reason,
)
from polling import wait_for

_hub_ids = itertools.count()


def hub() -> str:
    return f"py-sockd-{next(_hub_ids)}"


@pytest.fixture
def served():
    name = hub()
    bus, node = open_virtual(name), open_virtual(name)
    server = SocketcandServer(bus)
    yield server, node
    server.close()
    node.close()
    bus.close()


def raw_client(port: int) -> socket.socket:
    s = socket.create_connection(("127.0.0.1", port), timeout=2)
    return s


def read_element(s: socket.socket) -> str:
    buf = b""
    while not buf.endswith(b">"):
        buf += s.recv(1)
    return buf.decode()


def handshake(s: socket.socket) -> None:
    assert read_element(s) == "< hi >"
    s.sendall(b"< open can0 >")
    assert read_element(s) == "< ok >"
    s.sendall(b"< rawmode >")
    assert read_element(s) == "< ok >"


def test_frames_both_ways_every_width_and_dlc(served):
    server, node = served
    assert server.port > 0 and server.host == "127.0.0.1"
    with open_socketcand("127.0.0.1", server.port, "can0") as bus:
        assert isinstance(bus, motorbus.Bus) and bus.link_up
        assert wait_for(lambda: server.stats.clients_active == 1)
        time.sleep(0.005)
        frames = [
            Frame(i, bytes(range(0xA0, 0xA0 + n)), extended=ext)
            for ext, i in ((False, 0), (False, 0x7FF), (True, 0), (True, 0x1FFFFFFF))
            for n in range(9)
        ]
        for f in frames:
            bus.send(f)
        for f in frames:
            got = node.recv(2)
            assert got == f and got.data == f.data and got.extended == f.extended
        for f in frames:
            node.send(f)
        for f in frames:
            got = bus.recv(2)
            assert got == f and got.timestamp_ns > 0
        assert wait_for(lambda: server.stats.frames_to_bus == len(frames))
        assert server.stats.frames_to_clients == len(frames)
        assert bus.counters.parse_errors == 0


def test_open_bus_spec_reaches_the_server(served):
    server, node = served
    with motorbus.open_bus(f"socketcand:127.0.0.1:{server.port}/vcan0") as bus:
        time.sleep(0.005)
        node.send(Frame(0x42, b"\x01\x02"))
        got = bus.recv(2)
        assert (got.id, got.data) == (0x42, b"\x01\x02")
        assert bus.channel == f"socketcand:127.0.0.1:{server.port}/vcan0"


def test_k9_k10_error_replies_and_session_survives(served):
    server, node = served
    s = raw_client(server.port)
    handshake(s)
    s.sendall(b"< bogus >")
    assert read_element(s) == "< error unknown command >"
    s.sendall(b"< send 123 9 1 2 3 4 5 6 7 8 9 >")
    assert read_element(s) == "< error dlc: above 8 >"
    s.sendall(b"< send 123 2 1 >")
    assert read_element(s) == "< error send: byte count differs from dlc >"
    s.sendall(b"< send 1ABCDEF0 2 a bc >")
    got = node.recv(2)
    assert (got.id, got.extended, got.data) == (0x1ABCDEF0, True, b"\x0a\xbc")
    assert server.stats.error_replies == 3
    s.close()


def test_k14_slow_loris_is_cut_off():
    name = hub()
    bus = open_virtual(name)
    with SocketcandServer(bus, element_timeout=0.1) as server:
        s = raw_client(server.port)
        handshake(s)
        s.sendall(b"< sen")
        s.settimeout(2)
        assert s.recv(100) == b""  # closed by the server
        assert server.stats.timeouts == 1
    bus.close()


def test_wrong_channel_and_closed_server_are_typed_errors():
    bus = open_virtual(hub())
    server = SocketcandServer(bus, channel="can0")
    with pytest.raises(motorbus.LinkDown, match="unknown bus can1"):
        open_socketcand("127.0.0.1", server.port, "can1")
    client = open_socketcand("127.0.0.1", server.port, "can0")
    port = server.port
    server.close()
    assert wait_for(lambda: not client.link_up)
    assert "closed" in client.link_down_reason
    with pytest.raises(motorbus.LinkDown):
        client.send(Frame(1))
    with pytest.raises(motorbus.LinkDown):
        open_socketcand("127.0.0.1", port, "can0", connect_timeout=1)
    client.close()
    bus.close()


def test_k15_client_queue_option_is_exposed(served):
    server, _ = served
    assert server.client_drops == []
    assert server.stats.queue_drops == 0


def test_socketcan_on_this_kernel():
    why = socketcan_unavailable_reason()
    if why is not None:
        assert "EAFNOSUPPORT" in why
        with pytest.raises(motorbus.LinkDown, match="EAFNOSUPPORT"):
            open_socketcan("vcan0")
        pytest.skip(why)
    try:
        a, b = open_socketcan("vcan0"), open_socketcan("vcan0")
    except motorbus.LinkDown as e:
        pytest.skip(f"CAN works but no vcan0: {e}")
    a.send(Frame(0x321, b"\x01"))
    assert b.recv(2).id == 0x321


def test_socketcan_bad_interface_name_is_invalid_argument():
    with pytest.raises((motorbus.InvalidArgument, motorbus.LinkDown)):
        open_socketcan("x" * 20)


def test_client_to_client_round_trips_through_bus_serve_do_not_stall():
    """Two clients of `motorbus bus serve --socketcand` (a separate process) answer each
    other: the frame to the earlier-connected client used to wait for the server's 50 ms
    poll() timeout, so 20 request/reply round trips took ~1 s.  The bound is loose on
    purpose (loaded machines); bench/socketcand_roundtrip.py measures the latency."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "bus", "serve", f"virtual:{hub()}",
                             "--socketcand", "127.0.0.1:0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        kind, hostport, channel = proc.stdout.readline().split()
        assert kind == "socketcand"
        host, port = hostport.rsplit(":", 1)
        with open_socketcand(host, int(port), channel) as early, \
                open_socketcand(host, int(port), channel) as late:
            time.sleep(0.01)  # past the server's rawmode settle time
            rounds = 20
            start = time.perf_counter()
            for i in range(rounds):
                late.send(Frame(0x601, bytes((0x40, i))))
                got = early.recv(2)
                assert got is not None and (got.id, got.data) == (0x601, bytes((0x40, i)))
                early.send(Frame(0x581, bytes((0x60, i))))
                got = late.recv(2)
                assert got is not None and (got.id, got.data) == (0x581, bytes((0x60, i)))
            took = time.perf_counter() - start
            assert took < 0.5, f"{rounds} round trips took {took * 1e3:.0f} ms"
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        finally:
            if proc.poll() is None:
                proc.kill()

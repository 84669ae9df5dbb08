"""motorbus.serial from Python: ports, the line link, Python LineDevices on a pty server."""
from __future__ import annotations

import gc
import os
import threading
import time

import pytest

import motorbus
from motorbus.serial import LineDevice, LineLink, PtyLineServer, PtyPair, ReplyTooLong, TtyPort, open_port


class Echo(LineDevice):
    def on_line(self, line: bytes) -> bytes:
        return b"E:" + line + b"\r\n"


class Addressed(LineDevice):
    """Answers '<addr>...' requests; silent otherwise; '?' to over-long lines."""

    def __init__(self, addr: bytes, max_req: int = 32):
        super().__init__()
        self.addr = addr
        self.max_req = max_req
        self.seen: list[bytes] = []

    def on_line(self, line):
        self.seen.append(line)
        if not line.startswith(self.addr):
            return None
        return self.addr + b"=" + line[len(self.addr):] + b"\r\n"

    def max_request(self):
        return self.max_req

    def on_overlong(self):
        return self.addr + b"?\r\n"



def _reply_after_request(peer, reply):
    """Answers once the request has arrived (a slow, sanitized run must not have
    the reply flushed as stale input before the request is even sent)."""
    def run():
        peer.read(64, timeout=2.0)
        peer.write(reply)

    threading.Thread(target=run, daemon=True).start()

def test_pty_pair_passes_every_byte_value():
    with PtyPair() as pty:
        assert pty.slave_path.startswith("/dev/pts/")
        peer = pty.open_slave()
        data = bytes(range(256))
        pty.port.write(data)
        got = b""
        while len(got) < 256:
            got += peer.read(256, timeout=1.0)
        assert got == data
        assert pty.port.read(16, timeout=0.01) == b""


def test_tty_port_baud_standard_and_arbitrary():
    with PtyPair() as pty:
        port = TtyPort(pty.slave_path, 115200)
        assert port.baud == 115200
        port.baud = 250000
        assert port.baud == 250000
        port.close()
        assert not port.is_open
        with pytest.raises(motorbus.ClosedError):
            port.write(b"x")
    with pytest.raises(motorbus.InvalidArgument):
        open_port("/no/such/tty", 9600)


def test_python_line_device_on_server():
    with PtyLineServer([Echo()]) as server:
        link = LineLink(open_port(server.slave_path, 115200))
        assert link.transact("1PX") == b"E:1PX"
        assert link.transact(b"\xff\x00z") == b"E:\xff\x00z"
        assert link.counters.replies == 2
        assert link.counters.bytes_out == 4 + 4
        assert server.counters.lines == 2


def test_multidrop_each_device_decides():
    a, b = Addressed(b"01"), Addressed(b"02")
    with PtyLineServer([a, b]) as server:
        link = LineLink(open_port(server.slave_path), reply_timeout=1.0)
        assert link.transact("02READ") == b"02=READ"
        assert link.transact("01READ") == b"01=READ"
        assert a.seen == [b"02READ", b"01READ"] and b.seen == a.seen
        with pytest.raises(motorbus.TimeoutError):
            link.transact("09READ", timeout=0.03)
        assert link.counters.timeouts == 1


def test_a15_overlong_request_and_resync():
    dev = Addressed(b"1", max_req=8)
    with PtyLineServer([dev]) as server:
        link = LineLink(open_port(server.slave_path), reply_timeout=1.0)
        assert link.transact(b"1" + b"x" * 300) == b"1?"
        assert link.transact("1ok") == b"1=ok"
        assert server.counters.overlong_lines == 1


def test_a3_reply_too_long_is_protocol_error_with_data():
    with PtyPair() as pty:
        peer = pty.open_slave()
        link = LineLink(pty.port, max_line=8, reply_timeout=1.0)
        _reply_after_request(peer, b"0123456789ABCDEF\r\n")
        with pytest.raises(ReplyTooLong) as ei:
            link.transact("Q")
        assert isinstance(ei.value, motorbus.ProtocolError)
        assert ei.value.data == b"0123456789ABCDEF"
        assert link.counters.overlong_lines == 1
        _reply_after_request(peer, b"ok\r\n")
        assert link.transact("Q") == b"ok"


def test_a1_a8_timeout_then_late_reply_flushed():
    with PtyPair() as pty:
        peer = pty.open_slave()
        link = LineLink(pty.port, reply_timeout=0.15)
        def partial_reply():  # a partial that never ends, sent once the request is in
            peer.read(16, timeout=1.0)
            peer.write(b"12")

        threading.Thread(target=partial_reply).start()
        with pytest.raises(motorbus.TimeoutError):
            link.transact("A")
        assert link.counters.timeouts == 1
        peer.write(b"34\r\n")  # the late tail
        time.sleep(0.05)
        _reply_after_request(peer, b"fresh\r\n")
        assert link.transact("B", timeout=1.0) == b"fresh"
        assert link.counters.stale_bytes == 4


def test_a11_terminator_sets():
    with PtyPair() as pty:
        peer = pty.open_slave()
        link = LineLink(pty.port, reply_terminators=b"\0", reply_timeout=1.0)
        assert link.reply_terminators == [b"\0"]
        _reply_after_request(peer, b"12\r\n\0")
        assert link.transact("@0PX") == b"12\r\n"
        link2 = LineLink(pty.port, reply_terminators=["\r", "\r\n"], flush_before_request=False)
        peer.write(b"a\r\nb\r")
        assert link2.read_line(1.0) == b"a"
        assert link2.read_line(1.0) == b"b"
        assert link2.read_line(0.01) is None


def test_echo_suppression_and_turnaround():
    class EchoingAdapter(LineDevice):
        # Models an RS-485 adapter that hears its own transmission.
        def on_line(self, line):
            return line + b"\r" + b"ACK:" + line + b"\r\n"

    with PtyLineServer([EchoingAdapter()]) as server:
        link = LineLink(open_port(server.slave_path), echo_suppression=True, turnaround=0.001,
                        reply_timeout=1.0)
        assert link.transact("01READ #POS") == b"ACK:01READ #POS"
        assert link.counters.echo_bytes == len(b"01READ #POS\r")


def test_device_exception_is_unraisable_and_server_survives():
    class Broken(LineDevice):
        def on_line(self, line):
            if line == b"boom":
                raise RuntimeError("sim bug")
            return b"fine\r\n"

    seen = []
    old = __import__("sys").unraisablehook
    __import__("sys").unraisablehook = lambda u: seen.append(u.exc_value)
    try:
        with PtyLineServer([Broken()]) as server:
            link = LineLink(open_port(server.slave_path), reply_timeout=1.0)
            with pytest.raises(motorbus.TimeoutError):
                link.transact("boom", timeout=0.05)
            assert link.transact("x") == b"fine"
    finally:
        __import__("sys").unraisablehook = old
    assert any(isinstance(e, RuntimeError) for e in seen)


def test_str_replies_and_custom_terminator():
    class Dev(LineDevice):
        def request_terminator(self):
            return "\n"

        def on_line(self, line):
            return "got " + line.decode() + "\r\n"

    with PtyLineServer([Dev()]) as server:
        link = LineLink(open_port(server.slave_path), request_terminator="\n", reply_timeout=1.0)
        assert link.transact("abc") == b"got abc"


def test_attach_and_close_and_gc_do_not_leak_or_hang():
    gc.collect()
    before = len(os.listdir("/proc/self/fd"))
    for _ in range(3):
        server = PtyLineServer()
        server.attach(Echo())
        link = LineLink(open_port(server.slave_path), reply_timeout=1.0)
        assert link.transact("x") == b"E:x"
        link.port.close()
        del link, server
        gc.collect()
    assert len(os.listdir("/proc/self/fd")) == before
    s = PtyLineServer([Echo()])
    s.close()
    s.close()
    assert not s.running


def test_concurrent_python_threads_share_one_link():
    with PtyLineServer([Echo()]) as server:
        link = LineLink(open_port(server.slave_path), reply_timeout=2.0)
        errors = []

        def worker(n):
            for i in range(20):
                req = f"{n}-{i}"
                if link.transact(req) != b"E:" + req.encode():
                    errors.append(req)

        threads = [threading.Thread(target=worker, args=(n,)) for n in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert errors == []
        assert link.counters.replies == 80


def test_link_down_when_adapter_unplugged():
    pty = PtyPair()
    link = LineLink(pty.port, reply_timeout=1.0)
    peer = pty.open_slave()
    pty.release_slave()
    peer.close()
    with pytest.raises(motorbus.LinkDown):
        link.transact("x")
    pty.close()


def test_bad_arguments():
    with PtyPair() as pty:
        with pytest.raises(motorbus.InvalidArgument):
            LineLink(pty.port, reply_terminators=[])
        with pytest.raises(motorbus.InvalidArgument):
            LineLink(pty.port, max_line=0)
        with pytest.raises(motorbus.InvalidArgument):
            LineLink(pty.port, turnaround=-1.0)
        link = LineLink(pty.port)
        with pytest.raises(motorbus.InvalidArgument):
            link.transact(123)


def test_server_on_an_existing_port_and_echo_device():
    from motorbus.serial import EchoLineDevice

    with PtyPair() as pty:
        server = PtyLineServer([EchoLineDevice(prefix=b"P:")], port=pty.open_slave())
        assert server.slave_path == ""
        link = LineLink(pty.port, reply_timeout=1.0)
        assert link.transact("abc") == b"P:abc"
        assert EchoLineDevice().on_line(b"x") == b"x\r\n"
        server.close()

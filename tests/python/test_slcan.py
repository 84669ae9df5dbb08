"""motorbus SLCAN from Python: codec, SlcanServer on a pty, open_slcan through it."""
from __future__ import annotations

import os
import time

import pytest
import serial  # pyserial

import motorbus
from motorbus import _core
from motorbus.slcan import SlcanDecoder, SlcanEventKind, SlcanServer, open_slcan, slcan_encode


def _hub(tag: str) -> str:
    return f"slcan-py-{os.getpid()}-{tag}"


def test_encode_every_kind():
    assert slcan_encode(_core.can.Frame(0x123, b"\xde\xad")) == b"t1232DEAD\r"
    assert slcan_encode(_core.can.Frame(0x1FFFFFFF, b"", extended=True)) == b"T1FFFFFFF0\r"
    assert slcan_encode(_core.can.Frame(0x7FF, rtr=True, dlc=8)) == b"r7FF8\r"
    assert slcan_encode(_core.can.Frame(1, b"\x01"), timestamp_ms=0xEA5F) == b"t001101EA5F\r"
    with pytest.raises(motorbus.InvalidArgument):
        slcan_encode(_core.can.Frame(1), timestamp_ms=60000)


def test_decoder_hostile_rows_and_recovery():
    d = SlcanDecoder()
    events = d.feed(b"t8000\rt1239\rt12G0\rt1230EA60\r" + b"7" * 100 + b"\r\az\rF24\rt7ff1ab\r")
    K = SlcanEventKind
    kinds = [e.kind for e in events]
    assert kinds == [K.MALFORMED] * 4 + [K.OVERFLOW, K.NACK, K.TX_ACK, K.STATUS, K.FRAME]
    assert events[7].state == "error-passive"
    f = events[8].frame
    assert (f.id, f.data) == (0x7FF, b"\xab")  # lowercase accepted (L9)
    c = d.counters
    assert (c.rx_errors, c.rx_over_errors, c.frames) == (4, 1, 1)
    assert d.feed(b"t12") == [] and d.pending == 3
    assert d.discard_partial() and d.pending == 0


@pytest.mark.threaded
def test_server_with_pyserial_peer_answers_and_forwards():
    inner = _core.can.open_virtual(_hub("a"))
    peer = _core.can.open_virtual(_hub("a"))
    with SlcanServer(inner) as server, serial.Serial(server.pty_path, timeout=2) as tty:
        tty.write(b"V\rS6\rO\r")
        assert tty.read_until(b"\r") == b"V1013\r"
        assert tty.read(2) == b"\r\r"
        peer.send(motorbus.Frame(0x321, b"\x01\x02"))
        assert tty.read_until(b"\r") == b"t32120102\r"
        tty.write(b"T000001232BEEF\r")
        assert tty.read_until(b"\r") == b"Z\r"
        got = peer.recv(timeout=2)
        assert (got.id, got.extended, got.data) == (0x123, True, b"\xbe\xef")
        tty.write(b"t8000\r")  # L8 on the adapter side: refused
        assert tty.read(1) == b"\a"
        assert server.stats.transmitted == 1


@pytest.mark.threaded
def test_open_slcan_through_server_both_directions():
    inner = _core.can.open_virtual(_hub("b"))
    peer = _core.can.open_virtual(_hub("b"))
    with SlcanServer(inner) as server:
        with open_slcan(server.pty_path, 500000) as bus:
            assert isinstance(bus, motorbus.Bus) and bus.link_up
            frames = [motorbus.Frame(i, bytes(range(i % 9))) for i in range(0, 0x7FF, 97)]
            frames += [motorbus.Frame(0x1FFFFFFF, b"\xff" * 8, extended=True),
                       motorbus.Frame(0x7FF, rtr=True, dlc=3)]
            for f in frames:
                bus.send(f)
            bus.flush_tx(2.0)
            assert [peer.recv(timeout=2) for _ in frames] == frames
            for f in frames:
                peer.send(f)
            assert [bus.recv(timeout=2) for _ in frames] == frames
            assert bus.query_status(1.0) == 0
            assert bus.stats.nacks == 0


@pytest.mark.threaded
def test_open_bus_spec_reaches_open_slcan():
    inner = _core.can.open_virtual(_hub("c"))
    with SlcanServer(inner) as server:
        with motorbus.open_bus(f"slcan:{server.pty_path}@250000") as bus:
            assert bus.channel.startswith("slcan:")


def test_open_slcan_errors_are_typed():
    with pytest.raises(motorbus.InvalidArgument):
        open_slcan("/nonexistent/tty", 500000)
    inner = _core.can.open_virtual(_hub("d"))
    with SlcanServer(inner) as server:
        with pytest.raises(motorbus.InvalidArgument):
            open_slcan(server.pty_path, 83333)


@pytest.mark.threaded
def test_server_on_an_existing_serial_port():
    """SlcanServer(bus, port=...) serves a given device; here the slave of our own pty."""
    import os
    import select
    import tty as ttymod
    master, slave = os.openpty()
    ttymod.setraw(slave)
    inner = _core.can.open_virtual(_hub("e"))
    try:
        with SlcanServer(inner, port=os.ttyname(slave), baud=0) as server:
            assert server.pty_path is None
            os.write(master, b"V\r")
            deadline = time.monotonic() + 3
            got = b""
            while not got.endswith(b"\r") and time.monotonic() < deadline:
                if select.select([master], [], [], 0.1)[0]:
                    got += os.read(master, 64)
            assert got == b"V1013\r"
    finally:
        os.close(master)
        os.close(slave)


class _ScriptedAdapter:
    """A fake Lawicel adapter on a pty master, answering each command line via `script`."""

    def __init__(self, script):
        import os
        import threading
        import tty as ttymod
        self.master, self._slave = os.openpty()
        ttymod.setraw(self._slave)
        self.path = os.ttyname(self._slave)
        self.script = script
        self._stop = False
        self._t = threading.Thread(target=self._run, daemon=True)
        self._t.start()

    def _run(self):
        import os
        import select
        buf = b""
        while not self._stop:
            if not select.select([self.master], [], [], 0.05)[0]:
                continue
            buf += os.read(self.master, 4096)
            while b"\r" in buf:
                line, _, buf = buf.partition(b"\r")
                reply = self.script(line)
                if reply:
                    os.write(self.master, reply)

    def inject(self, data: bytes) -> None:
        import os
        os.write(self.master, data)

    def close(self):
        import os
        self._stop = True
        self._t.join()
        os.close(self.master)
        os.close(self._slave)


def _lawicel(line: bytes) -> bytes:
    if line[:1] in (b"t", b"r"):
        return b"z\r"
    if line[:1] in (b"T", b"R"):
        return b"Z\r"
    if line == b"F":
        return b"F20\r"
    return b"\r"


@pytest.mark.threaded
def test_l10_nack_surfaces_as_protocol_error_with_the_frame():
    adapter = _ScriptedAdapter(lambda l: b"\a" if l == b"t1230" else _lawicel(l))
    try:
        with open_slcan(adapter.path, 500000) as bus:
            bus.send(motorbus.Frame(0x122))
            bus.send(motorbus.Frame(0x123))  # refused by the adapter
            with pytest.raises(motorbus.ProtocolError) as info:
                bus.flush_tx(2.0)
            assert "123#" in str(info.value)
            assert bus.counters.tx_dropped == 1
            assert (bus.stats.acks, bus.stats.nacks) == (1, 1)
            bus.flush_tx(1.0)  # reported once
            # L12: F20 = error passive
            assert bus.query_status(1.0) == 0x20
            assert bus.state == "error-passive"
    finally:
        adapter.close()


@pytest.mark.threaded
def test_bad_lines_are_counted_and_the_next_frame_arrives():
    adapter = _ScriptedAdapter(_lawicel)
    try:
        with open_slcan(adapter.path, 500000) as bus:
            adapter.inject(b"7" * 100 + b"\rt12G0\rt8000\rt1239\rQ\r" + b"t1232CAFE\r")
            f = bus.recv(timeout=2)
            assert (f.id, f.data) == (0x123, b"\xca\xfe")
            c = bus.counters
            assert (c.overruns, c.parse_errors, c.ignored) == (1, 3, 1)
    finally:
        adapter.close()


def test_silent_adapter_times_out_with_a_hint():
    adapter = _ScriptedAdapter(lambda l: b"")
    try:
        with pytest.raises(motorbus.TimeoutError, match="wait_for_acks"):
            open_slcan(adapter.path, 500000, open_timeout=0.1)
    finally:
        adapter.close()

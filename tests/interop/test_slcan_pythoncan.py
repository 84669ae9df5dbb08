"""python-can's `slcan` interface (the reference SLCAN implementation) against ours.

* python-can <-> SlcanServer: python-can is the host, our server the adapter
  (it answers python-can's C / S6 / O and z/Z for every frame).
* python-can <-> SlcanBus: both are hosts joined by a null-modem pty pair;
  python-can never answers commands, so SlcanBus runs with wait_for_acks=False.

Every id width (11/29-bit incl. the max ids), every DLC 0-8 and RTR, both ways,
asserting ids, flags, DLC and bytes.
"""
from __future__ import annotations

import os
import select
import threading
import time
import tty

import can
import pytest
from can.interfaces.slcan import slcanBus

import motorbus
from motorbus import _core
from motorbus.slcan import SlcanServer, open_slcan


def _frames() -> list[tuple[int, bool, bool, int, bytes]]:
    """(id, extended, rtr, dlc, data) for every id width, DLC and RTR."""
    out = []
    for ext, ids in ((False, (0x000, 0x001, 0x123, 0x7FF)),
                     (True, (0x00000000, 0x00000001, 0x12345678, 0x1FFFFFFF))):
        for can_id in ids:
            for dlc in range(9):
                out.append((can_id, ext, False, dlc, bytes((0x11 * (i + 1) + can_id) & 0xFF for i in range(dlc))))
                out.append((can_id, ext, True, dlc, b""))
    return out


FRAMES = _frames()


def _to_msg(f) -> can.Message:
    can_id, ext, rtr, dlc, data = f
    return can.Message(arbitration_id=can_id, is_extended_id=ext, is_remote_frame=rtr, dlc=dlc,
                       data=None if rtr else data)


def _to_frame(f) -> motorbus.Frame:
    can_id, ext, rtr, dlc, data = f
    return motorbus.Frame(can_id, data, extended=ext, rtr=rtr, dlc=dlc if rtr else None)


def _msg_tuple(m: can.Message):
    return (m.arbitration_id, m.is_extended_id, m.is_remote_frame, m.dlc,
            b"" if m.is_remote_frame else bytes(m.data))


def _frame_tuple(f: motorbus.Frame):
    return (f.id, f.extended, f.rtr, f.dlc, f.data)


def _pycan_recv_all(bus: can.BusABC, n: int) -> list:
    got = []
    while len(got) < n:
        m = bus.recv(timeout=3.0)
        assert m is not None, f"python-can received only {len(got)} of {n} frames"
        got.append(_msg_tuple(m))
    return got


def _exchange_every_frame(bus, peer):
    """Every FRAMES entry python-can -> adapter -> virtual bus, then back; exact and in order."""
    for f in FRAMES:
        bus.send(_to_msg(f))
    got = []
    for _ in FRAMES:
        fr = peer.recv(timeout=3.0)
        assert fr is not None, f"bus received only {len(got)} of {len(FRAMES)}"
        got.append(_frame_tuple(fr))
    assert got == FRAMES
    for f in FRAMES:
        peer.send(_to_frame(f))
    assert _pycan_recv_all(bus, len(FRAMES)) == FRAMES


@pytest.fixture
def hub():
    name = f"slcan-interop-{os.getpid()}-{id(object())}"
    inner = _core.can.open_virtual(name)
    peer = _core.can.open_virtual(name)
    yield inner, peer
    inner.close()
    peer.close()


@pytest.mark.threaded
def test_pythoncan_host_against_our_server(hub):
    inner, peer = hub
    with SlcanServer(inner) as server:
        bus = can.Bus(interface="slcan", channel=server.pty_path, bitrate=500000, sleep_after_open=0)
        try:
            _exchange_every_frame(bus, peer)
            assert server.stats.transmitted == len(FRAMES)
            assert server.stats.transmit_failed == 0
        finally:
            bus.shutdown()
        deadline = time.monotonic() + 3
        while server.is_open and time.monotonic() < deadline:  # python-can's shutdown sends C
            time.sleep(0.01)
        assert not server.is_open


class NullModem:
    """Two ptys whose masters are cross-connected: each side opens a slave path."""

    def __init__(self) -> None:
        self.m1, s1 = os.openpty()
        self.m2, s2 = os.openpty()
        for s in (s1, s2):
            tty.setraw(s)
        self.path1, self.path2 = os.ttyname(s1), os.ttyname(s2)
        self._slaves = (s1, s2)  # held open so the masters never see a hang-up
        self._stop = False
        self._t = threading.Thread(target=self._pump, daemon=True)
        self._t.start()

    def _pump(self) -> None:
        peer = {self.m1: self.m2, self.m2: self.m1}
        while not self._stop:
            r, _, _ = select.select([self.m1, self.m2], [], [], 0.05)
            for fd in r:
                try:
                    data = os.read(fd, 65536)
                except OSError:
                    return
                os.write(peer[fd], data)

    def close(self) -> None:
        self._stop = True
        self._t.join()
        for fd in (self.m1, self.m2, *self._slaves):
            os.close(fd)


@pytest.mark.threaded
def test_pythoncan_host_against_our_slcanbus():
    modem = NullModem()
    try:
        ours = open_slcan(modem.path1, 500000, wait_for_acks=False)
        theirs = can.Bus(interface="slcan", channel=modem.path2, bitrate=500000, sleep_after_open=0)
        try:
            for f in FRAMES:
                ours.send(_to_frame(f))
            assert _pycan_recv_all(theirs, len(FRAMES)) == FRAMES
            for f in FRAMES:
                theirs.send(_to_msg(f))
            got = []
            for _ in FRAMES:
                fr = ours.recv(timeout=3.0)
                assert fr is not None, f"SlcanBus received only {len(got)} of {len(FRAMES)}"
                got.append(_frame_tuple(fr))
            assert got == FRAMES
            # python-can's C / S6 / O / bare CR lines were ignored, never parse errors
            assert ours.counters.parse_errors == 0
        finally:
            theirs.shutdown()
            ours.close()
    finally:
        modem.close()


# ---- CR LF hosts (docs/slcan.md "Line endings") ------------------------------
# A host that ends commands with CR LF used to lose every second frame: the LF
# led the next command, which our adapter answered with BEL and dropped.

class _CrLfSlcanBus(slcanBus):
    """python-can's own slcan bus, ending every command (C, S6, O and each frame) with CR LF."""

    LINE_TERMINATOR = b"\r\n"


@pytest.mark.threaded
def test_pythoncan_host_with_crlf_line_endings_loses_no_frame(hub):
    inner, peer = hub
    with SlcanServer(inner) as server:
        bus = _CrLfSlcanBus(channel=server.pty_path, bitrate=500000, sleep_after_open=0)
        try:
            # python-can does not wait for answers: the O after "C\r\nS6\r\n" lands soon
            deadline = time.monotonic() + 3
            while not server.is_open and time.monotonic() < deadline:
                time.sleep(0.01)
            assert server.is_open
            _exchange_every_frame(bus, peer)
            assert server.stats.transmitted == len(FRAMES)
            # The only BELs are the three python-can's open sequence earns with CR
            # too (C, S6, "" for no data bitrate, O, O): C while closed, the empty
            # line and the second O.  Before the fix every frame after the first
            # drew one as well.
            assert server.stats.invalid_commands == 3
        finally:
            bus.shutdown()


@pytest.mark.threaded
def test_pyserial_host_writing_crlf_and_nul_padded_lines(hub):
    """Raw bytes from pyserial: CR LF, LF alone and NUL pads; every frame arrives, every reply is z."""
    import serial  # pyserial

    inner, peer = hub
    n = 200
    with SlcanServer(inner) as server:
        port = serial.Serial(server.pty_path, 115200, timeout=3.0)
        try:
            port.write(b"S6\r\nO\r\n")
            assert port.read(2) == b"\r\r"
            ends = (b"\r\n", b"\n", b"\r\n\x00\x00", b"\x00\r\n")
            lines = b"".join(b"t%03X2%02X%02X" % (0x100 + i, i, 0xFF - i) + ends[i % 4] for i in range(n))
            port.write(lines)
            # i % 4 == 3 puts a NUL inside the line: that one is refused, never mangled.
            expected = b"".join(b"\a" if i % 4 == 3 else b"z\r" for i in range(n))
            assert port.read(len(expected)) == expected
            got = []
            while (fr := peer.recv(timeout=0.5)) is not None:
                got.append((fr.id, fr.data))
            assert got == [(0x100 + i, bytes((i, 0xFF - i))) for i in range(n) if i % 4 != 3]
            assert server.stats.transmitted == n - n // 4
            assert server.stats.invalid_commands == n // 4
        finally:
            port.close()

"""pyserial as the independent peer of motorbus.serial, both directions.

pyserial opens the pty slave path exactly as it would open /dev/ttyUSB0.
"""
from __future__ import annotations

import threading

import pytest

serial = pytest.importorskip("serial")

from motorbus.serial import LineDevice, LineLink, PtyLineServer, PtyPair  # noqa: E402


class Echo(LineDevice):
    def on_line(self, line: bytes) -> bytes:
        return b"E:" + line + b"\r\n"


def test_pyserial_client_against_our_server():
    with PtyLineServer([Echo()]) as server:
        with serial.Serial(server.slave_path, 115200, timeout=1.0) as ser:
            ser.write(b"hello\r")
            assert ser.read_until(b"\r\n") == b"E:hello\r\n"
            # Split request, every byte value except the terminator.
            payload = bytes(b for b in range(256) if b != 0x0D)
            ser.write(payload[:100])
            ser.flush()
            ser.write(payload[100:] + b"\r")
            assert ser.read_until(b"\r\n", size=600) == b"E:" + payload + b"\r\n"
        assert server.counters.lines == 2


def test_pyserial_device_against_our_line_link():
    """pyserial plays the drive; our LineLink is the host."""
    with PtyPair() as pty:
        with serial.Serial(pty.slave_path, 9600, timeout=1.0) as dev:
            stop = threading.Event()
            requests = []

            def drive():
                while not stop.is_set():
                    line = dev.read_until(b"\r")
                    if not line.endswith(b"\r"):
                        continue
                    requests.append(line)
                    # A reply split in two writes, NUL-terminated (Protocol A style).
                    dev.write(b"+12")
                    dev.flush()
                    dev.write(b"34\0")

            t = threading.Thread(target=drive, daemon=True)
            t.start()
            link = LineLink(pty.port, reply_terminators=[b"\0"], reply_timeout=1.0)
            assert link.transact("@01PX") == b"+1234"
            assert link.transact(b"@01PY") == b"+1234"
            stop.set()
            link.send("@01X")  # unblock read_until
            t.join(2.0)
            assert requests[:2] == [b"@01PX\r", b"@01PY\r"]


def test_pyserial_reads_our_raw_bytes_unchanged():
    with PtyPair() as pty:
        with serial.Serial(pty.slave_path, 115200, timeout=1.0) as ser:
            data = bytes(range(256)) * 4
            pty.port.write(data)
            assert ser.read(len(data)) == data
            ser.write(data)
            got = b""
            while len(got) < len(data):
                chunk = pty.port.read(4096, timeout=1.0)
                assert chunk
                got += chunk
            assert got == data

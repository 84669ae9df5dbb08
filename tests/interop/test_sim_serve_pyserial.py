"""`motorbus sim serve` in its own process, with pyserial as the independent client.

The manuals' worked examples (tests/vectors/seed_examples.json) that need no
simulated-time set-up, byte for byte, on the ptys the command prints.
"""
import json
import pathlib
import signal
import subprocess
import sys
import time

import pytest
import serial

VECTORS = json.loads((pathlib.Path(__file__).parents[1] / "vectors" / "seed_examples.json").read_text())


@pytest.fixture(scope="module")
def served():
    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", "--pty", "--drive", "arcus:01",
                             "--drive", "dmac:00,01,02,03,04"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    lines = {}
    for _ in range(2):
        spec, path = proc.stdout.readline().split()
        lines[spec] = path
    yield lines
    proc.send_signal(signal.SIGINT)
    assert proc.wait(10) == 0  # Ctrl-C ends the server cleanly
    # (The pty numbers may be reused by other processes at once, so their
    # paths are not checked here; the pty tests of motorbus.serial check fds.)


def _arcus(port, send, expect_reply=True, timeout=1.0):
    port.reset_input_buffer()
    port.write(send.encode())
    if not expect_reply:
        time.sleep(0.1)
        return port.read(port.in_waiting or 1) if port.in_waiting else b""
    out = b""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not out.endswith(b"\0"):
        out += port.read(1)
    return out


def test_prints_one_line_per_serial_line(served):
    assert set(served) == {"arcus:01", "dmac:00,01,02,03,04"}
    assert all(p.startswith("/dev/pts/") for p in served.values())


def test_arcus_examples_byte_for_byte(served):
    ex = {e["send"]: e for e in VECTORS["arcus_dmx_ascii"]["exchanges"]}
    with serial.Serial(served["arcus:01"], 9600, timeout=0.05) as port:
        assert _arcus(port, "@01EO=1\r") == b"OK\0"
        assert _arcus(port, "@01EX=1000\r") == b"OK\0"
        assert _arcus(port, "@01EX\r") == ex["@01EX\r"]["reply_rt0"].encode()
        assert _arcus(port, "@01FOO\r") == ex["@01FOO\r"]["reply_rt0"].encode()
        assert _arcus(port, "@01T500\r") == ex["@01T500\r"]["reply_rt0"].encode()  # idle
        assert _arcus(port, "@01J+\r") == ex["@01J+\r"]["reply_rt0"].encode()
        assert _arcus(port, "@01X1000\r") == ex["@01X1000\r"]["reply_rt0"].encode()  # while moving
        assert _arcus(port, "@00ABORT\r", expect_reply=False) == b""  # broadcast: acts, no reply
        assert _arcus(port, "@01ABORT\r") == ex["@01ABORT\r"]["reply_rt0"].encode()


def test_dmac_examples_byte_for_byte(served):
    by_send = {e["send"]: e for e in VECTORS["dmac_ascii"]["exchanges"]}
    with serial.Serial(served["dmac:00,01,02,03,04"], 38400, timeout=1.0) as port:
        def ask(text):
            port.reset_input_buffer()
            port.write(text.encode() + b"\r")
            return port.read_until(b"\r\n", size=512)

        for send, setup in (("00READ #ACCEL_TIME", "00#ACCEL_TIME:=123"), ("00READ h#ACCEL_TIME", "00#ACCEL_TIME:=256"),
                            ("00READ b#ACCEL_TIME", "00#ACCEL_TIME:=100"), ("01READ h#OUTPUT", "01#OUTPUT:=7")):
            port.write(setup.encode() + b"\r")  # commands have no reply on a DMAC
            assert ask(send) == by_send[send]["reply"].encode() + b"\r\n"
        assert ask("04REQUEST_VERSION") == by_send["04REQUEST_VERSION"]["reply"].encode() + b"\r\n"

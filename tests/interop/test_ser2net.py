"""A real ser2net (the Debian package, started here on 127.0.0.1) in front of the pty of
`motorbus sim serve`, as a lab's serial gateway would stand in front of an RS-485 line.

The line is served at 19 200 baud with --strict-baud: requests sent at another rate arrive
garbled and go unanswered, as on a real UART.  ser2net offers it twice:
- raw TCP (``socket://``), with the gateway's own setting of 19 200 — the client sets nothing;
- RFC 2217 (``rfc2217://``), configured at 9 600: only a client whose baud reaches the line
  through COM-PORT-OPTION gets answers.
The manual's worked examples (tests/vectors/seed_examples.json) must come back byte for byte
through both, the typed client must work through both, pyserial's own RFC 2217 client is the
independent cross-check, and a dropped connection must raise LinkDown, not hang.
"""
from __future__ import annotations

import json
import os
import pathlib
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest
import serial  # pyserial

import motorbus
from motorbus import _core
from motorbus.serial import open_port
from motorbus.drives.arcus import ArcusClient

pytestmark = pytest.mark.skipif(shutil.which("ser2net") is None and not os.path.exists("/usr/sbin/ser2net"),
                                reason="ser2net is not installed (Debian package ser2net; make deps installs it)")

SER2NET = shutil.which("ser2net") or "/usr/sbin/ser2net"
VECTORS = json.loads((pathlib.Path(__file__).parents[1] / "vectors" / "seed_examples.json").read_text())
# The examples that need no motion set-up (the moving/idle ones are covered by test_arcus_pyserial.py).
EXAMPLES = [e for e in VECTORS["arcus_dmx_ascii"]["exchanges"] if "while" not in e and e["reply_rt0"] is not None]
LINE_BAUD = 19200


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def served_pty():
    """`motorbus sim serve` with one DMX-CAN at 01, its line at 19 200 baud, strict."""
    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", "--drive", "arcus:01",
                             "--baud", str(LINE_BAUD), "--strict-baud"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    spec, path = proc.stdout.readline().split()
    assert spec == "arcus:01"
    yield path
    proc.send_signal(signal.SIGINT)
    assert proc.wait(10) == 0


class Ser2net:
    """One ser2net process serving ``pty`` as raw TCP and as RFC 2217 on free loopback ports."""

    def __init__(self, pty: str, tmp: pathlib.Path):
        self.raw_port, self.rfc2217_port = _free_port(), _free_port()
        config = tmp / "ser2net.yaml"
        config.write_text(
            "connection: &raw\n"
            f"  accepter: tcp,127.0.0.1,{self.raw_port}\n"
            f"  connector: serialdev,{pty},{LINE_BAUD}n81,local\n"
            "connection: &rfc2217\n"
            f"  accepter: telnet(rfc2217),tcp,127.0.0.1,{self.rfc2217_port}\n"
            f"  connector: serialdev,{pty},9600n81,local\n")
        # -n: stay in the foreground; -u: no UUCP lock files (the pty is ours).
        # Not under the sanitizer run's preloaded ASan runtime: ser2net is not ours to check.
        env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "ASAN_OPTIONS", "UBSAN_OPTIONS")}
        self.proc = subprocess.Popen([SER2NET, "-n", "-u", "-c", str(config), "-P", str(tmp / "ser2net.pid")],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        deadline = time.monotonic() + 10
        for port in (self.raw_port, self.rfc2217_port):
            while True:
                try:
                    socket.create_connection(("127.0.0.1", port), timeout=1).close()
                    break
                except OSError:
                    if time.monotonic() > deadline or self.proc.poll() is not None:
                        raise RuntimeError(f"ser2net did not listen on 127.0.0.1:{port}")
                    time.sleep(0.05)
        # The probe connections above must be gone before a test connects (ser2net refuses
        # a second user of a port with "Port already in use").
        time.sleep(0.2)

    @property
    def raw_url(self) -> str:
        return f"socket://127.0.0.1:{self.raw_port}"

    @property
    def rfc2217_url(self) -> str:
        return f"rfc2217://127.0.0.1:{self.rfc2217_port}"

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(10)


@pytest.fixture
def gateway(served_pty, tmp_path):
    g = Ser2net(served_pty, tmp_path)
    yield g
    g.kill()


def _replay(port: _core.serial.Port, example: dict) -> bytes:
    """One manual example, after the set-up it needs (EX reads back what EX= wrote)."""
    if example["send"] == "@01EX\r":
        assert _exchange(port, "@01EX=1000\r") == b"OK\0"
    return _exchange(port, example["send"])


def _exchange(port: _core.serial.Port, request: str, timeout: float = 2.0) -> bytes:
    """Sends one request and reads up to and including the NUL that ends a DMX-CAN reply."""
    port.write(request.encode())
    out = b""
    deadline = time.monotonic() + timeout
    while not out.endswith(b"\0") and time.monotonic() < deadline:
        out += port.read(64, 0.05)
    return out


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda e: e["send"].strip())
def test_manual_examples_byte_for_byte_over_raw_tcp(gateway, example):
    with open_port(gateway.raw_url) as port:
        assert isinstance(port, _core.serial.TcpPort)
        assert _replay(port, example) == example["reply_rt0"].encode()


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda e: e["send"].strip())
def test_manual_examples_byte_for_byte_over_rfc2217(gateway, example):
    with open_port(gateway.rfc2217_url, LINE_BAUD) as port:
        assert isinstance(port, _core.serial.Rfc2217Port) and port.baud == LINE_BAUD
        assert _replay(port, example) == example["reply_rt0"].encode()


@pytest.mark.parametrize("via", ["raw", "rfc2217"])
def test_typed_client_moves_through_the_gateway(gateway, via):
    url = gateway.raw_url if via == "raw" else gateway.rfc2217_url
    with ArcusClient(url, "01", baud=LINE_BAUD, timeout=1.0) as drive:
        assert drive.command("ID") == "DriveMax-CAN"
        drive.enable()
        drive.move(drive.position + 250)
        deadline = time.monotonic() + 10
        while drive.status.moving and time.monotonic() < deadline:
            time.sleep(0.02)
        assert not drive.status.moving
        drive.move(drive.position - 250)     # back where the next test expects it
        while drive.status.moving and time.monotonic() < deadline:
            time.sleep(0.02)
        drive.disable()


def test_rfc2217_baud_reaches_the_line(gateway):
    """ser2net's own setting for this port is 9 600: the line (19 200, strict) garbles that,
    so an answer proves the client's COM-PORT-OPTION baud was applied on the pty."""
    with ArcusClient(gateway.rfc2217_url, "01", baud=9600, timeout=0.3, query_retries=0) as wrong:
        with pytest.raises(motorbus.TimeoutError):
            wrong.command("ID")
    time.sleep(0.2)   # ser2net frees the port after the previous user has gone
    with ArcusClient(gateway.rfc2217_url, "01", baud=LINE_BAUD, timeout=1.0) as right:
        assert right.command("ID") == "DriveMax-CAN"


def test_pyserial_rfc2217_client_agrees(gateway):
    """The independent RFC 2217 client against the same gateway gives the same bytes."""
    # ign_set_control: ser2net cannot set DTR/RTS on a pty (TIOCMSET fails), so it never
    # acknowledges pyserial's SET_CONTROL; the baud and framing go through as for motorbus.
    port = serial.serial_for_url(gateway.rfc2217_url + "?ign_set_control", LINE_BAUD, timeout=0.05)
    try:
        for example in EXAMPLES:
            if example["send"] == "@01EX\r":
                port.write(b"@01EX=1000\r")
                time.sleep(0.1)
                port.reset_input_buffer()
            port.write(example["send"].encode())
            out = b""
            deadline = time.monotonic() + 2
            while not out.endswith(b"\0") and time.monotonic() < deadline:
                out += port.read(64)
            assert out == example["reply_rt0"].encode(), example["send"]
    finally:
        port.close()


def test_a_dropped_gateway_raises_link_down_not_a_hang(gateway):
    drive = ArcusClient(gateway.raw_url, "01", timeout=1.0)
    try:
        assert drive.position == drive.position      # a working link first
        gateway.kill()
        t0 = time.monotonic()
        with pytest.raises(motorbus.LinkDown):
            drive.command("ID")
        assert time.monotonic() - t0 < 1.0           # at once, not after the reply timeout
    finally:
        drive.close()


def test_a_blocked_read_wakes_with_link_down_when_the_gateway_dies(gateway):
    port = open_port(gateway.rfc2217_url, LINE_BAUD)
    outcome: list = []

    def wait_forever():
        try:
            outcome.append(port.read(16, None))      # no timeout: only data or the link's end wakes it
        except Exception as e:                       # noqa: BLE001 - the type is what is checked
            outcome.append(e)

    waiter = threading.Thread(target=wait_forever)
    waiter.start()
    time.sleep(0.2)
    t0 = time.monotonic()
    gateway.kill()
    waiter.join(5)
    try:
        assert not waiter.is_alive(), "read(timeout=None) still blocked 5 s after the gateway died"
        assert isinstance(outcome[0], motorbus.LinkDown), outcome
        assert time.monotonic() - t0 < 1.0
    finally:
        port.close()

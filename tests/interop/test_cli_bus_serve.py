"""`motorbus bus serve` as a separate process, joined by python-can clients."""
import os
import signal
import subprocess
import sys
import time

import can
import pytest

import motorbus
from polling import recv_id


def _serve(*args):
    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "bus", "serve", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc


def _read_lines(proc, n, timeout=20.0):
    lines = []
    deadline = time.time() + timeout
    while len(lines) < n and time.time() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        lines.append(line.split())
    assert len(lines) == n, (lines, proc.stderr.read() if proc.poll() is not None else "")
    return lines


def _stop(proc):
    proc.send_signal(signal.SIGINT)
    try:
        rc = proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
    return rc


@pytest.mark.skipif(not hasattr(motorbus._core, "SlcanServer"), reason="SLCAN backend not built")
def test_python_can_slcan_clients_share_a_served_bus():
    proc = _serve("virtual:cli-slcan", "--slcan-pty", "--slcan-pty")
    try:
        (k1, p1), (k2, p2) = _read_lines(proc, 2)
        assert k1 == k2 == "slcan" and os.path.exists(p1) and os.path.exists(p2)
        a = can.Bus(interface="slcan", channel=p1, bitrate=500000)
        b = can.Bus(interface="slcan", channel=p2, bitrate=500000)
        try:
            time.sleep(0.2)  # both adapters opened
            a.send(can.Message(arbitration_id=0x1ABCDE, is_extended_id=True, data=b"\x01\x02\x03"))
            m = recv_id(b, 0x1ABCDE, timeout=3.0, poll=0.2)
            assert m is not None and bytes(m.data) == b"\x01\x02\x03" and m.is_extended_id
            b.send(can.Message(arbitration_id=0x7FF, is_extended_id=False, data=bytes(range(8))))
            m = recv_id(a, 0x7FF, timeout=3.0, poll=0.2)
            assert m is not None and bytes(m.data) == bytes(range(8))
        finally:
            a.shutdown()
            b.shutdown()
    finally:
        assert _stop(proc) == 0
    assert proc.poll() == 0


@pytest.mark.skipif(not (hasattr(motorbus._core, "SocketcandServer") and hasattr(motorbus._core, "SlcanServer")),
                    reason="socketcand/SLCAN backends not built")
def test_socketcand_and_slcan_clients_see_each_other():
    proc = _serve("virtual:cli-mixed", "--socketcand", "127.0.0.1:0", "--slcan-pty")
    try:
        (k1, hostport, channel), (k2, pty) = _read_lines(proc, 2)
        assert (k1, k2, channel) == ("socketcand", "slcan", "can0")
        host, port = hostport.rsplit(":", 1)
        sc = can.Bus(interface="socketcand", host=host, port=int(port), channel=channel)
        sl = can.Bus(interface="slcan", channel=pty, bitrate=500000)
        try:
            time.sleep(0.2)
            sc.send(can.Message(arbitration_id=0x123, is_extended_id=False, data=b"\xAA"))
            m = recv_id(sl, 0x123, timeout=3.0, poll=0.2)
            assert m is not None and bytes(m.data) == b"\xAA"
            sl.send(can.Message(arbitration_id=0x321, is_extended_id=False, data=b"\xBB\xCC"))
            m = recv_id(sc, 0x321, timeout=3.0, poll=0.2)
            assert m is not None and bytes(m.data) == b"\xBB\xCC"
        finally:
            sc.shutdown()
            sl.shutdown()
    finally:
        assert _stop(proc) == 0


def test_counters_on_sigusr1_and_on_exit_and_the_channel_is_announced():
    proc = _serve("virtual:cli-report", "--socketcand", "127.0.0.1:0", "--channel", "vcan7")
    try:
        ((kind, hostport, channel),) = _read_lines(proc, 1)
        assert (kind, channel) == ("socketcand", "vcan7")
        host, port = hostport.rsplit(":", 1)
        a = can.Bus(interface="socketcand", host=host, port=int(port), channel="vcan7")
        b = can.Bus(interface="socketcand", host=host, port=int(port), channel="vcan7")
        try:
            time.sleep(0.2)
            for i in range(5):
                a.send(can.Message(arbitration_id=0x123, is_extended_id=False, data=bytes([i])))
            for i in range(5):
                m = recv_id(b, 0x123, timeout=3.0, poll=0.2)
                assert m is not None and bytes(m.data) == bytes([i])
            proc.send_signal(signal.SIGUSR1)
            line = proc.stderr.readline()
            assert line.startswith(f"socketcand {hostport} vcan7: clients 2 active / 2 accepted"), line
            assert "to bus 5," in line and "dropped 0" in line
        finally:
            a.shutdown()
            b.shutdown()
    finally:
        assert _stop(proc) == 0
    last = proc.stderr.read()
    assert f"socketcand {hostport} vcan7:" in last and "to bus 5," in last

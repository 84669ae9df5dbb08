"""HOSTILE_INPUTS.md 2.9, protocol A rows, against the Python ArcusClient and the
simulator on a real pty.  A Python LineDevice in front of the simulator
corrupts the replies the way a bad line or a confused device would."""
from __future__ import annotations

import time

import pytest
import serial

import motorbus
import motorbus._core as core
from motorbus.drives.arcus import ArcusClient, make_sim, open_line


class Tamper(core.serial.LineDevice):
    """Passes lines to the simulator; `mangle(reply) -> bytes` rewrites its answers."""

    def __init__(self, sim):
        super().__init__()
        self.sim = sim
        self.mangle = None

    def on_line(self, line):
        reply = self.sim.on_line(line)
        return self.mangle(reply) if self.mangle else reply


@pytest.fixture
def rig():
    clock = core.runtime.SimClock()
    sim = make_sim("01", clock=clock)
    dev = Tamper(sim)
    server = core.serial.PtyLineServer([dev], 0, None)
    link = open_line(server.slave_path, baud=0, timeout=0.1)
    client = ArcusClient(link, 1, on_exit=None)
    yield dev, client, sim
    link.port.close()
    server.close()


def test_a1_no_terminator_times_out_then_resyncs(rig):
    dev, c, _ = rig
    dev.mangle = lambda r: r[:-1]
    with pytest.raises(motorbus.TimeoutError):
        c.position
    dev.mangle = None
    c.set_position(321)
    assert c.position == 321


def test_a2_bytes_after_nul_are_flushed(rig):
    dev, c, _ = rig
    dev.mangle = lambda r: r + b"555\0"
    c.set_position(9)
    assert c.position == 9
    assert c.position == 9


def test_a3_overlong_reply(rig):
    dev, c, _ = rig
    dev.mangle = lambda r: b"7" * 400 + b"\0"
    with pytest.raises(motorbus.ProtocolError):
        c.position
    dev.mangle = None
    assert c.position == 0


def test_a5_unknown_command_is_typed_and_not_retried(rig):
    dev, c, _ = rig
    before = c.counters.requests
    with pytest.raises(motorbus._core.ArcusUnknownCommand) as e:
        c.command("FOO", idempotent=True)
    assert e.value.reply == "?FOO" and e.value.command == "FOO"
    assert c.counters.requests == before + 1


def test_a6_reply_for_another_address(rig):
    dev, c, _ = rig
    dev.mangle = lambda r: b"#02" + r
    with pytest.raises(motorbus.ProtocolError):
        c.position
    dev.mangle = lambda r: b"#01" + r
    assert c.position == 0


@pytest.mark.parametrize("bad", [b"-", b"+99999999999", b"1e3", b"10 00", b"+5", b"OK", b"0x10"])
def test_a7_numeric_garbage(rig, bad):
    dev, c, _ = rig
    dev.mangle = lambda r: bad + b"\0"
    with pytest.raises(motorbus.ProtocolError):
        c.position
    dev.mangle = None
    assert c.position == 0


def test_a8_late_reply_is_discarded(rig):
    dev, c, _ = rig

    def slow_once(r):
        dev.mangle = None
        time.sleep(0.25)  # answers after the client's 0.1 s timeout
        return r

    dev.mangle = slow_once
    with pytest.raises(motorbus.TimeoutError):
        c.high_speed = 2500  # a set: not retried
    time.sleep(0.3)  # the late "OK" is now waiting in the input buffer
    assert c.position == 0  # flushed before the request, not taken as the answer to PX
    assert c.high_speed == 2500


def test_a8_late_reply_glued_to_the_next_one_is_rejected(rig):
    """A late value arriving together with the next answer cannot be flushed:
    the grammar check catches it (a set must be answered OK)."""
    dev, c, _ = rig
    held = []
    dev.mangle = lambda r: held.append(r) or b""
    with pytest.raises(motorbus.TimeoutError):
        c.position
    dev.mangle = lambda r: held.pop(0) + r if held else r
    with pytest.raises(motorbus.ProtocolError):
        c.high_speed = 2500
    dev.mangle = None
    assert c.high_speed == 2500


def test_a10_noise_is_skipped_and_counted(rig):
    dev, c, _ = rig
    dev.mangle = lambda r: b"\xff\xfe\0\x80\0" + r
    assert c.position == 0
    assert c.counters.noise_lines == 2
    dev.mangle = None
    assert c.high_speed == 1000


def test_a11_only_nul_terminates(rig):
    dev, c, _ = rig
    dev.mangle = lambda r: r[:-1] + b"\r\n"
    with pytest.raises(motorbus.TimeoutError):
        c.position
    dev.mangle = None
    assert c.position == 0


def test_a13_power_cycle_then_boot_state(rig):
    dev, c, sim = rig
    c.high_speed = 4000
    sim.power_cycle()
    assert c.high_speed == 1000
    assert not c.enabled


def test_a14_motion_not_retried_query_retried(rig):
    dev, c, sim = rig
    c.enable()  # a disabled motor does no motion (manual §6)
    seen = []

    def swallow(r):
        seen.append(r)
        return b""

    dev.mangle = swallow
    with pytest.raises(motorbus.TimeoutError):
        c.jog(1)
    assert len(seen) == 1
    with pytest.raises(motorbus.TimeoutError):
        c.position
    assert len(seen) == 3  # one retry for the query
    dev.mangle = None
    assert c.moving  # the jog did start: query, do not resend
    c.abort()


def test_a15_simulator_survives_hostile_lines_on_the_pty():
    sim = make_sim("01")
    with core.serial.PtyLineServer([sim], 0, None) as server, serial.Serial(server.slave_path, 115200, timeout=0.2) as p:
        p.write(bytes(range(256)) * 20 + b"\r")
        p.write(b"@01" + b"Z" * 300 + b"\r")
        p.write(b"@01\x00\x01\x02\r")
        time.sleep(0.2)
        p.reset_input_buffer()
        p.write(b"@01ID\r")
        assert p.read_until(b"\0") == b"DriveMax-CAN\0"
        assert server.running

"""The Arcus simulator on a pty, with pyserial as the independent client.

Every ASCII example of manual 000 (tests/vectors/seed_examples.json,
key arcus_dmx_ascii) is replayed byte for byte, in both reply formats.
"""
from __future__ import annotations

import json
import pathlib
import time

import pytest
import serial  # pyserial

import motorbus._core as core
from motorbus.drives.arcus import LINE_SETTINGS, make_sim

VECTORS = json.loads((pathlib.Path(__file__).parents[1] / "vectors" / "seed_examples.json").read_text())
ARCUS = VECTORS["arcus_dmx_ascii"]


def read_reply(port: serial.Serial, timeout: float = 2.0) -> bytes:
    """Reads up to and including the NUL, like a host program would."""
    deadline = time.monotonic() + timeout
    out = b""
    while time.monotonic() < deadline:
        chunk = port.read(1)
        if chunk:
            out += chunk
            if chunk == b"\0":
                return out
    return out


@pytest.fixture
def line():
    """A DMX-CAN at 01 on a pty, driven by simulated time."""
    clock = core.runtime.SimClock()
    sim = make_sim("01", clock=clock)
    server = core.serial.PtyLineServer([sim], 0, None)
    port = serial.Serial(server.slave_path, 9600, timeout=0.05)
    yield sim, clock, port
    port.close()
    server.close()


def _prepare(sim, port, exchange):
    """Puts the device in the state the example needs ("while": moving / idle)."""
    if exchange.get("while") == "moving":
        port.write(b"@01EO=1\r")  # powered: a disabled motor does no motion (manual §6)
        assert read_reply(port) == b"OK\0"
        port.write(b"@01J+\r")
        assert read_reply(port) == b"OK\0"
    if exchange["send"] == "@01EX\r":
        port.write(b"@01EX=1000\r")
        assert read_reply(port) == b"OK\0"


@pytest.mark.parametrize("exchange", ARCUS["exchanges"], ids=lambda e: e["send"].strip())
def test_seed_example_rt0_byte_for_byte(line, exchange):
    sim, _, port = line
    _prepare(sim, port, exchange)
    port.reset_input_buffer()
    port.write(exchange["send"].encode())
    expected = exchange["reply_rt0"]
    if expected is None:
        # Broadcast: the device acts but sends nothing.
        assert read_reply(port, timeout=0.3) == b""
        assert not sim.busy
    else:
        assert read_reply(port) == expected.encode()


@pytest.mark.parametrize("exchange", [e for e in ARCUS["exchanges"] if "reply_rt1" in e],
                         ids=lambda e: e["send"].strip())
def test_seed_example_rt1_byte_for_byte(tmp_path, exchange):
    # RT=1 takes effect after STORE and a power cycle, as the manual says.
    clock = core.runtime.SimClock()
    store = tmp_path / "flash.txt"
    sim = make_sim("01", clock=clock, store_path=str(store))
    with core.serial.PtyLineServer([sim], 0, None) as server:
        with serial.Serial(server.slave_path, 9600, timeout=0.05) as port:
            for cmd, reply in ((b"@01RT=1\r", b"OK\0"), (b"@01STORE\r", b"OK\0")):
                port.write(cmd)
                assert read_reply(port) == reply
            sim.power_cycle()
            _prepare_rt1(port, exchange)
            port.write(exchange["send"].encode())
            assert read_reply(port) == exchange["reply_rt1"].encode()


def _prepare_rt1(port, exchange):
    if exchange["send"] == "@01EX\r":
        port.write(b"@01EX=1000\r")
        assert read_reply(port) == b"#01OK\0"


def test_abort_stops_a_jog_and_broadcast_reaches_every_device():
    clock = core.runtime.SimClock()
    sims = [make_sim(a, clock=clock, eo_boot=True, snl=False) for a in ("01", "02", "03")]
    with core.serial.PtyLineServer(sims, 0, None) as server, serial.Serial(server.slave_path, 9600, timeout=0.05) as port:
        for a in ("01", "02", "03"):
            port.write(f"@{a}J+\r".encode())
            assert read_reply(port) == b"OK\0"
        clock.advance(500_000_000)
        assert all(s.busy for s in sims)
        port.write(b"@00ABORT\r")
        assert read_reply(port, timeout=0.3) == b""
        assert not any(s.busy for s in sims)
        port.write(b"@02PX\r")
        px = read_reply(port)
        assert px.endswith(b"\0") and int(px[:-1]) > 0


def test_line_settings_match_the_manual():
    assert LINE_SETTINGS["request_terminator"] == b"\r"
    assert LINE_SETTINGS["reply_terminators"] == [b"\0"]


def test_a15_overlong_and_binary_request_lines_then_resync(line):
    sim, _, port = line
    port.write(b"\xff" * 5000 + b"\r")
    port.write(b"@01" + bytes(range(1, 31)) + b"\r")
    time.sleep(0.2)
    port.reset_input_buffer()
    port.write(b"@01PX=77\r")
    assert read_reply(port) == b"OK\0"
    port.write(b"@01PX\r")
    assert read_reply(port) == b"77\0"


def test_a1_half_a_request_then_a_full_one(line):
    """The host dies mid-request; the next complete line still works."""
    sim, _, port = line
    port.write(b"@01P")
    time.sleep(0.05)
    port.write(b"\r@01ID\r")
    # "@01P" is an unknown command: the device answers "?P" first.
    assert read_reply(port) == b"?P\0"
    assert read_reply(port) == b"DriveMax-CAN\0"


def _mst(port) -> int:
    port.write(b"@01MST\r")
    return int(read_reply(port)[:-1])


def test_mst_examples_of_the_manual(line):
    """0 idle; 2 accelerating; 9 constant speed with the home input on; 64 minus limit error."""
    sim, clock, port = line
    examples = {int(k): v for k, v in ARCUS["mst_examples"].items()}
    assert set(examples) == {0, 2, 9, 64}
    for cmd in (b"@01SL=0\r", b"@01EO=1\r", b"@01HSPD=1000\r", b"@01ACC=100\r"):
        port.write(cmd)
        assert read_reply(port) == b"OK\0"
    assert _mst(port) == 0
    port.write(b"@01J+\r")
    assert read_reply(port) == b"OK\0"
    clock.advance(50_000_000)
    assert _mst(port) == 2
    clock.advance(8_100_000_000)  # about 8100 steps: inside the home switch (8000..8400)
    assert _mst(port) == 9
    port.write(b"@01ABORT\r")
    assert read_reply(port) == b"OK\0"
    sim.force_home(False)  # stopped on the switch; 64 is the limit error alone
    sim.force_limit(-1, True)
    port.write(b"@01J-\r")
    assert read_reply(port) == b"OK\0"
    clock.advance(1_000_000)
    sim.force_limit(-1, False)
    assert _mst(port) == 64


@pytest.mark.parametrize("ex", ARCUS["accel_limits_examples"], ids=lambda e: f"HSPD{e['HSPD']}")
def test_appendix_a_accel_examples(line, ex):
    assert core.arcus.acc_range(ex["HSPD"], ex["LSPD"]) == (ex["min_acc_ms"], ex["max_acc_ms"])
    # The simulator adjusts ACC into that range, as the manual says.
    _, _, port = line
    for cmd in (f"@01HSPD={ex['HSPD']}\r", f"@01LSPD={ex['LSPD']}\r", "@01ACC=999999\r"):
        port.write(cmd.encode())
        assert read_reply(port) == b"OK\0"
    port.write(b"@01ACC\r")
    assert read_reply(port) == f"{ex['max_acc_ms']}\0".encode()


@pytest.mark.parametrize("w", ARCUS["speed_windows_appendix_a"], ids=lambda w: w["hspd_pps"])
def test_appendix_a_windows(w):
    lo_text = w["hspd_pps"].split("-")[0]
    scale = {"K": 1_000, "M": 1_000_000}
    lo = float(lo_text[:-1]) * scale[lo_text[-1]] if lo_text[-1] in scale else float(lo_text)
    hspd = int(lo) + 1
    lo_ms, hi_ms = core.arcus.acc_range(hspd, w["min_lspd"])
    assert lo_ms == w["min_acc_ms"]
    # max ACC = ((HSPD - LSPD) / delta) x 1000 ms (truncated to 10 ms, as the manual's example).
    assert hi_ms == max(lo_ms, (hspd - w["min_lspd"]) * 100 // w["delta"] * 10)



# ---- defects found by the audit against the manual (each failed before its fix) ----

def _say(port, cmd: str) -> bytes:
    port.write(f"@01{cmd}\r".encode())
    return read_reply(port)[:-1]


def _ok(port, *cmds: str) -> None:
    for cmd in cmds:
        assert _say(port, cmd) == b"OK", cmd


def test_pol_bits_7_and_8_invert_in_position_and_alarm_outputs(line):
    """Tables 7.2 and 7.11: bit 7 In Position Output, bit 8 Alarm Output (SL=1, EDO=1)."""
    sim, clock, port = line
    _ok(port, "EO=1", "X1000")
    clock.advance(3_000_000_000)
    assert (_say(port, "DO1"), _say(port, "DO3")) == (b"1", b"0")   # in position, no alarm
    _ok(port, "POL=128")
    assert (_say(port, "DO1"), _say(port, "DO3")) == (b"0", b"0")
    _ok(port, "POL=256")
    assert (_say(port, "DO1"), _say(port, "DO3")) == (b"1", b"1")
    _ok(port, "POL=384")
    sim.disturb(1000)  # 1250 counts > SLE while idle: correction range error, the alarm
    assert _say(port, "SLS") == b"8"
    assert (_say(port, "DO1"), _say(port, "DO3")) == (b"1", b"0")


def test_slr_reads_and_sets_the_stepnloop_ratio(tmp_path):
    """Table 7.10 lists SLR (stored); syntax as docs/drives/arcus.md: x.xxx pulses per count."""
    clock = core.runtime.SimClock()
    sim = make_sim("01", clock=clock, store_path=str(tmp_path / "flash.txt"))
    with core.serial.PtyLineServer([sim], 0, None) as server, serial.Serial(server.slave_path, 9600, timeout=0.05) as port:
        assert _say(port, "SLR") == b"0.800"
        _ok(port, "SLR=1.25")
        assert _say(port, "SLR") == b"1.250"
        assert _say(port, "SLR=0") == b"?SLR=0"
        assert _say(port, "SLR=1000") == b"?SLR=1000"
        assert _say(port, "SLR=x") == b"?SLR=x"
        _ok(port, "STORE", "SLR=2")
        sim.power_cycle()
        assert _say(port, "SLR") == b"1.250"


def test_abort_clears_the_stepnloop_limit_error(line):
    """Table 11.0, ABORT: "used for clearing the StepNLoop error status"; MST bits need CLR."""
    sim, clock, port = line
    sim.force_limit(1, True)
    _ok(port, "EO=1", "J+")
    clock.advance(10_000_000)
    assert _say(port, "SLS") == b"11"
    assert _say(port, "MST") == b"160"
    _ok(port, "ABORT")
    assert _say(port, "SLS") == b"0"
    assert _say(port, "MST") == b"160"
    assert _say(port, "X0") == b"?State Error"
    _ok(port, "CLR")
    assert _say(port, "MST") == b"32"


def test_sync_equal_output_is_a_pulse_while_positions_are_equal(line):
    """Chapter 7, Sync Output, condition 1: on only while encoder == SYNP; SYNS stays 2."""
    sim, clock, port = line
    _ok(port, "EO=1", "SYNP=500", "SYNC=1", "SYNO", "X500")
    clock.advance(3_000_000_000)
    assert _say(port, "EX") == b"500"
    assert (_say(port, "SYNS"), _say(port, "DO2")) == (b"2", b"1")
    _ok(port, "X1000")
    clock.advance(3_000_000_000)
    assert _say(port, "EX") == b"1000"
    assert (_say(port, "SYNS"), _say(port, "DO2")) == (b"2", b"0")


def test_disabled_motor_does_no_motion(line):
    """§6: "When motor is disabled, no motion is done" (EO=0 at boot, StepNLoop on)."""
    sim, clock, port = line
    assert _say(port, "EO") == b"0"
    _ok(port, "X3000")
    clock.advance(5_000_000_000)
    assert (_say(port, "PX"), _say(port, "EX"), _say(port, "MST"), _say(port, "SLS")) == (b"0", b"0", b"0", b"0")
    _ok(port, "EO=1", "J+")
    clock.advance(500_000_000)
    assert int(_say(port, "MST")) & 7
    _ok(port, "EO=0")
    assert int(_say(port, "MST")) & 7 == 0
    px = _say(port, "PX")
    clock.advance(1_000_000_000)
    assert _say(port, "PX") == px


def test_slm_correction_uses_idle_current(line):
    """Table 7.5, SLM: the additional correction runs on idle current (CUR = CURI)."""
    sim, clock, port = line
    _ok(port, "EO=1", "X2000")
    clock.advance(5_000_000_000)
    assert _say(port, "CUR") == b"1000"
    sim.disturb(40)                 # 50 counts: a correction at run current
    assert (_say(port, "SLS"), _say(port, "CUR")) == (b"2", b"1600")
    clock.advance(100_000_000)
    sim.disturb(8)                  # leaves 10 counts > SLM after the first correction
    clock.advance(450_000_000)
    assert (_say(port, "SLS"), _say(port, "CUR")) == (b"2", b"1000")
    clock.advance(2_000_000_000)
    assert (_say(port, "SLS"), _say(port, "EX")) == (b"0", b"2000")

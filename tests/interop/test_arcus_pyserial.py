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
    clock = core.SimClock()
    sim = make_sim("01", clock=clock)
    server = core.PtyLineServer([sim], 0, None)
    port = serial.Serial(server.slave_path, 9600, timeout=0.05)
    yield sim, clock, port
    port.close()
    server.close()


def _prepare(sim, port, exchange):
    """Puts the device in the state the example needs ("while": moving / idle)."""
    if exchange.get("while") == "moving":
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
    clock = core.SimClock()
    store = tmp_path / "flash.txt"
    sim = make_sim("01", clock=clock, store_path=str(store))
    with core.PtyLineServer([sim], 0, None) as server:
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
    clock = core.SimClock()
    sims = [make_sim(a, clock=clock, eo_boot=True, snl=False) for a in ("01", "02", "03")]
    with core.PtyLineServer(sims, 0, None) as server, serial.Serial(server.slave_path, 9600, timeout=0.05) as port:
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
    assert core.arcus_acc_range(ex["HSPD"], ex["LSPD"]) == (ex["min_acc_ms"], ex["max_acc_ms"])
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
    lo_ms, hi_ms = core.arcus_acc_range(hspd, w["min_lspd"])
    assert lo_ms == w["min_acc_ms"]
    # max ACC = ((HSPD - LSPD) / delta) x 1000 ms (truncated to 10 ms, as the manual's example).
    assert hi_ms == max(lo_ms, (hspd - w["min_lspd"]) * 100 // w["delta"] * 10)

"""Every DMAC ASCII example of the manual (tests/vectors/seed_examples.json,
key dmac_ascii), byte for byte, with pyserial as the independent client on the
pty the simulators are served on (one multi-drop line, modules 00..04)."""
from __future__ import annotations

import json
import pathlib

import pytest

serial = pytest.importorskip("serial")

from motorbus._core import SimClock  # noqa: E402
from motorbus.drives.dmac import LINE_SETTINGS, XON_ERROR, make_sim  # noqa: E402
from motorbus.serial import PtyLineServer  # noqa: E402

VECTORS = json.loads((pathlib.Path(__file__).parents[1] / "vectors" / "seed_examples.json").read_text())["dmac_ascii"]
CR = LINE_SETTINGS["request_terminator"]
CRLF = LINE_SETTINGS["reply_terminators"][0]


@pytest.fixture()
def line():
    clock = SimClock()
    sims = {a: make_sim(f"{a:02d}", clock=clock) for a in range(5)}
    with PtyLineServer(list(sims.values())) as server:
        with serial.Serial(server.slave_path, 38400, timeout=1.0) as ser:
            yield ser, sims, clock


def ask(ser, text: str) -> bytes:
    ser.reset_input_buffer()
    ser.write(text.encode() + CR)
    return ser.read_until(CRLF, size=512)


def silent(ser, text: str) -> bytes:
    """Commands other than READ have no reply on a DMAC."""
    ser.write(text.encode() + CR)
    ser.timeout = 0.05
    got = ser.read(64)
    ser.timeout = 1.0
    return got


def prepare(ser, sims, clock, ex):
    send = ex["send"]
    addr = int(send[:2])
    if "#ACCEL_TIME" in send:
        assert silent(ser, f"{addr:02d}#ACCEL_TIME:={ex['value']}") == b""
    elif "#OUTPUT" in send:
        assert silent(ser, f"{addr:02d}#OUTPUT:={ex['value']}") == b""
    elif "#INPUT" in send:
        for bit in range(10):
            sims[addr].set_input(bit + 1, bool(ex["value"] >> bit & 1))
    elif "#STATUS" in send:
        # busy + movement + power on + S-curve
        assert silent(ser, f"{addr:02d}S_CURVE ON, MOVE_SPEED 20000") == b""
        clock.advance(10_000_000)
    elif "#ERROR" in send:
        for bit in range(32):
            if ex["value"] >> bit & 1:
                sims[addr].inject_error(bit + 1)
    elif "#SUPPLY_VOLTAGE" in send:
        sims[addr].set_supply_voltage(ex["value"])
    elif "#SPEED" in send:
        assert silent(ser, f"{addr:02d}MOVE_SPEED {ex['value']}") == b""
        clock.advance(2_000_000_000)
    elif send.startswith(f"{addr:02d}READ_SEQ"):
        n = int(send.split()[-1])
        for cmd in ("OPEN_SEQ", f":{n} {ex['line']}", "CLOSE_SEQ"):
            assert silent(ser, f"{addr:02d}{cmd}") == b""


@pytest.mark.parametrize("ex", VECTORS["exchanges"], ids=[e["send"] for e in VECTORS["exchanges"]])
def test_manual_exchange_byte_for_byte(line, ex):
    ser, sims, clock = line
    prepare(ser, sims, clock, ex)
    assert ask(ser, ex["send"]) == ex["reply"].encode() + CRLF


def test_manual_writes_take_effect_and_answer_nothing(line):
    ser, sims, clock = line
    for w in VECTORS["writes"]:
        assert silent(ser, w) == b"", w
    assert ask(ser, "00READ #ACCEL_TIME") == b"00#ATI=+100\r\n"       # last of :=123, :=H100, :=B1100100
    assert ask(ser, "00READ h#V20") == b"00#V20=hFFFFFFD8\r\n"
    assert ask(ser, "00READ #V10.3") == b"00#V10.3=+1\r\n"
    # The global "#HIGH_SPEED:=10000, MOVE_TO 1234" reached every module; only 00 answers globals.
    clock.advance(10_000_000_000)
    assert ask(ser, "READ #POSITION") == b"00#POS=+1234\r\n"
    for a in range(5):
        assert ask(ser, f"{a:02d}READ #HSP") == f"{a:02d}#HSP=+10000".encode() + CRLF
        assert sims[a].read("#POSITION") == 1234


def test_twos_complement_and_factory_table(line):
    ser, sims, clock = line
    tc = VECTORS["twos_complement_example"]
    silent(ser, f"01#V1:={tc['value']}")
    assert ask(ser, "01READ h#V1") == f"01#V1={tc['hex']}".encode() + CRLF
    silent(ser, "02#HIGH_SPEED:=1, #POSITIVE_END:=5, #M3:=9, MODULE_RESET ALL")
    for name, value in VECTORS["factory_reset_all"].items():
        assert sims[2].read(name) == value, name
    assert ask(ser, "02READ #M3") == b"02#M3=+0\r\n"


def test_accel_scaling_example(line):
    ser, sims, clock = line
    ex = VECTORS["accel_scaling_example"]
    silent(ser, f"00#ACCEL_TIME:={ex['ACCEL_TIME_ms']}, "
                f"#HIGH_SPEED:={ex['HIGH_SPEED']}, MOVE_SPEED {ex['MOVE_SPEED']}")
    clock.advance(int(ex["accel_time_s"] * 1e9) - 2_000_000)
    assert sims[0].state()["speed"] < ex["MOVE_SPEED"]
    clock.advance(2_000_000)
    assert ask(ser, "00READ #SPEED") == f"00#SPE=+{ex['MOVE_SPEED']}".encode() + CRLF


def test_xon_error_is_the_single_byte_0x17(line):
    ser, sims, clock = line
    assert VECTORS["xon_error_byte"] == XON_ERROR.hex()
    silent(ser, "03#INTERPOL_FIFOSIZE:=1, MOVE_INTERPOL 5")
    ser.reset_input_buffer()
    ser.write(b"03MOVE_INTERPOL 5\r")
    assert ser.read(1) == XON_ERROR
    ser.timeout = 0.05
    assert ser.read(8) == b""  # nothing else, no terminator
    ser.timeout = 1.0
    assert ask(ser, "03MOVE_INTERPOL 5, READ #ICO") == XON_ERROR + b"03#ICO=+1\r\n"


def test_hostile_bytes_from_pyserial_then_valid_frame(line):
    """A10/A15: noise, binary and an over-long line on the wire; the next frame still works."""
    ser, sims, clock = line
    ser.write(bytes(range(256)) + b"\r")
    ser.write(b"\xff" * 300 + b"\r")
    ser.write(b"00READ #POSITION" + b"X" * 400 + b"\r")
    assert ask(ser, "00#ERROR:=0, READ #POSITION") == b"00#POS=+0\r\n"

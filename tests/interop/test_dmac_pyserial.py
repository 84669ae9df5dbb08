"""Every DMAC ASCII example of the manual (tests/vectors/seed_examples.json,
key dmac_ascii), byte for byte, with pyserial as the independent client on the
pty the simulators are served on (one multi-drop line, modules 00..04)."""
from __future__ import annotations

import json
import pathlib

import pytest

serial = pytest.importorskip("serial")

from motorbus._core.runtime import SimClock  # noqa: E402
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
            # DMAC34s start with the brake applied (factory BRAKE ON, annex 7.1):
            # release it on every module, as a user does before moving.
            ser.write(b"BRAKE OFF" + CR)
            ser.timeout = 0.05
            assert ser.read(16) == b""
            ser.timeout = 1.0
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


def handled(ser, addr: int) -> None:
    """Returns once the server has handled every line sent before: an answered READ comes
    after them on the one line.  Time is advanced only then -- a loaded machine may take
    longer than silent()'s 50 ms to hand a line to the simulator."""
    assert ask(ser, f"{addr:02d}READ #POSITION").startswith(f"{addr:02d}#POS=".encode())


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
        handled(ser, addr)
        clock.advance(10_000_000)
    elif "#ERROR" in send:
        for bit in range(32):
            if ex["value"] >> bit & 1:
                sims[addr].inject_error(bit + 1)
    elif "#SUPPLY_VOLTAGE" in send:
        sims[addr].set_supply_voltage(ex["value"])
    elif "#SPEED" in send:
        assert silent(ser, f"{addr:02d}MOVE_SPEED {ex['value']}") == b""
        handled(ser, addr)
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
    assert sims[0].state().speed < ex["MOVE_SPEED"]
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


# ---- defects found by the audit against the manual (one test each) -------------------------
def value(reply: bytes) -> int:
    return int(reply.split(b"=")[1])


def test_busy_ends_at_the_target_velocity(line):
    """3.5.4: BUSY (#STATUS.29 and OUT1) holds until the target velocity is reached."""
    ser, sims, clock = line
    silent(ser, "00#ACCEL_TIME:=1000, MOVE_SPEED 30000")  # 0.5 s ramp to 300 rpm
    clock.advance(400 * 1_000_000)
    assert ask(ser, "00READ #STATUS.29") == b"00#STA.29=+1\r\n"
    assert sims[0].physical_outputs() & 1
    clock.advance(101 * 1_000_000)
    assert ask(ser, "00READ #SPEED") == b"00#SPE=+30000\r\n"
    assert ask(ser, "00READ #STATUS.29") == b"00#STA.29=+0\r\n"   # was +1 for as long as it turned
    assert ask(ser, "00READ #STATUS.26") == b"00#STA.26=+1\r\n"   # still moving
    assert not sims[0].physical_outputs() & 1


def test_replies_wait_line_delay(line):
    """5.13: the module answers #LINE_DELAY (factory 3000 us) after the request."""
    import time
    ser, sims, clock = line
    ser.reset_input_buffer()
    t0 = time.monotonic()
    ser.write(b"00READ #LINE_DELAY" + CR)
    assert ser.read_until(CRLF) == b"00#LDE=+3000\r\n"
    # A lower bound the sim guarantees (it sleeps before answering), not a speed.
    assert time.monotonic() - t0 >= 0.003
    silent(ser, "00#LINE_DELAY:=100")
    assert ask(ser, "00READ #LINE_DELAY") == b"00#LDE=+100\r\n"


def test_supply_and_temperature_faults_stop_and_latch(line):
    """2.1, 5.5, 5.25: under/over-voltage and thermal faults stop the motor and latch."""
    ser, sims, clock = line
    silent(ser, "00MOVE_SPEED 20000")
    clock.advance(200 * 1_000_000)
    sims[0].set_supply_voltage(11000)                      # DMAC34: below 20 V
    assert ask(ser, "00READ h#ERROR") == b"00#ERR=h00000008\r\n"  # bit 4 undervoltage
    assert ask(ser, "00READ #STATUS.31") == b"00#STA.31=+1\r\n"
    assert ask(ser, "00READ #STATUS.26") == b"00#STA.26=+0\r\n"   # motion stopped
    assert ask(ser, "00READ #STATUS.25") == b"00#STA.25=+0\r\n"   # power off
    silent(ser, "00#ERROR:=0")                                      # still too low: latches again
    assert ask(ser, "00READ h#ERROR") == b"00#ERR=h00000008\r\n"
    sims[0].set_supply_voltage(32000)
    assert ask(ser, "00#ERROR:=0, READ h#ERROR") == b"00#ERR=h00000000\r\n"
    sims[1].set_supply_voltage(171000)                     # DMAC34: above 170 V
    assert ask(ser, "01READ h#ERROR") == b"01#ERR=h00000010\r\n"  # bit 5 overvoltage
    sims[2].set_temperature("driver", 900)                 # above 85 degC
    assert ask(ser, "02READ h#ERROR") == b"02#ERR=h00000002\r\n"  # bit 2 thermal
    assert ask(ser, "02READ #DTE") == b"02#DTE=+900\r\n"


def test_overlong_frame_sets_the_syntax_bit_of_its_module(line):
    """4: a frame over 256 characters is rejected (#ERROR bit 12), silently, and runs nothing."""
    ser, sims, clock = line
    ser.write(b"01#V1:=7, MOVE_TO 5000" + b" " * 300 + CR)
    assert ask(ser, "01READ h#ERROR") == b"01#ERR=h00000800\r\n"  # was h00000000 on the pty
    assert ask(ser, "00READ h#ERROR") == b"00#ERR=h00000000\r\n"
    assert ask(ser, "01READ #V1") == b"01#V1=+0\r\n"


def test_brake_is_applied_after_a_reset(line):
    """Annex 7.1: BRAKE's factory value is ON (DMAC34)."""
    ser, sims, clock = line
    assert ask(ser, "03READ #STATUS.21") == b"03#STA.21=+0\r\n"  # the fixture released it
    silent(ser, "03MODULE_RESET")
    assert ask(ser, "03READ #STATUS.21") == b"03#STA.21=+1\r\n"


def test_power_sc_brakes_and_power_off_freewheels(line):
    """4.15: POWER SC's resisting torque stops the rotor far sooner than POWER OFF."""
    ser, sims, clock = line
    for a in (0, 1):
        silent(ser, f"{a:02d}#ACCEL_TIME:=100, MOVE_SPEED 60000")   # 600 rpm
    clock.advance(500 * 1_000_000)
    p = [value(ask(ser, f"{a:02d}READ #POSITION")) for a in (0, 1)]
    silent(ser, "00POWER SC")
    silent(ser, "01POWER OFF")
    assert ask(ser, "00READ #STATUS.26") == b"00#STA.26=+1\r\n"  # both still turning
    assert ask(ser, "01READ #STATUS.26") == b"01#STA.26=+1\r\n"
    clock.advance(5_000_000_000)
    sc, off = (value(ask(ser, f"{a:02d}READ #POSITION")) - p[a] for a in (0, 1))
    assert abs(sc - 2000) <= 2 and abs(off - 20000) <= 2  # v*tau: 20 ms vs 0.2 s


def test_module_reset_stops_short_circuited(line):
    """4.8: MODULE_RESET powers off, then the rotor is stopped short-circuited."""
    ser, sims, clock = line
    silent(ser, "02#ACCEL_TIME:=100, MOVE_SPEED 60000")
    clock.advance(500 * 1_000_000)
    p0 = value(ask(ser, "02READ #POSITION"))
    silent(ser, "02MODULE_RESET")
    assert ask(ser, "02READ #STATUS.26") == b"02#STA.26=+1\r\n"  # was an instant halt
    clock.advance(1_000_000_000)
    assert ask(ser, "02READ #STATUS.26") == b"02#STA.26=+0\r\n"
    assert abs(value(ask(ser, "02READ #POSITION")) - p0 - 2000) <= 2


def test_analog_inputs_per_model():
    """5.8, annex 7.2: #INPUT_ANALOG on a DMAC17/23, #INPUT_A1/#INPUT_A2 on a DMAC34."""
    clock = SimClock()
    d34 = make_sim("00", clock=clock, model="DMAC34-1")
    d23 = make_sim("01", clock=clock, model="DMAC23-1")
    d34.set_analog(1, -3200)
    d34.set_analog(2, 1500)
    d23.set_analog(1, 4520)
    with pytest.raises(Exception, match="1 only"):
        d23.set_analog(2, 1)
    with PtyLineServer([d34, d23]) as server, serial.Serial(server.slave_path, 38400, timeout=1.0) as ser:
        assert silent(ser, "00READ #INPUT_ANALOG") == b""   # a DMAC34 has no #IAN
        assert ask(ser, "00READ h#ERROR") == b"00#ERR=h00000800\r\n"
        assert ask(ser, "00READ #IA1") == b"00#IA1=-3200\r\n"
        assert ask(ser, "00READ #IA2") == b"00#IA2=+1500\r\n"
        assert ask(ser, "01READ #INPUT_ANALOG") == b"01#IAN=+4520\r\n"
        assert silent(ser, "01READ #IA1") == b""

"""Issue 23 items 17 and 18 (DMAC), with pyserial as the independent client on the
simulators' pty: UltraSYNC (#INTERPOL_MODE:=-1, manual 5.11) makes every chained
module wait for the segment to be finished on all of them; during MODULE_RESET's
run-down #SPEED is the rotor's measured speed (5.24), #PROFILE_SPEED the module's
computed one (nothing: the power stage is off)."""
from __future__ import annotations

import time

import pytest

serial = pytest.importorskip("serial")

from motorbus._core.runtime import SimClock  # noqa: E402
from motorbus.drives.dmac import chain_ultrasync, make_sim  # noqa: E402
from motorbus.serial import PtyLineServer  # noqa: E402
from motorbus.sim import SimBench  # noqa: E402

CR, CRLF = b"\r", b"\r\n"
MS = 1_000_000


def ask(ser, text: str) -> bytes:
    ser.reset_input_buffer()
    ser.write(text.encode() + CR)
    return ser.read_until(CRLF, size=512)


def value(reply: bytes) -> int:
    assert reply.endswith(CRLF), reply
    return int(reply.split(b"=")[1])


def silent(ser, text: str) -> None:
    """Commands other than READ get no reply on a DMAC."""
    ser.write(text.encode() + CR)
    ser.timeout = 0.05
    got = ser.read(64)
    ser.timeout = 1.0
    assert got == b"", got


@pytest.fixture()
def chained():
    """Modules 00 (X) and 01 (Y) on one line, IN6/OUT1 chained; Y braked to 5000 inc/s."""
    clock = SimClock()
    x, y = make_sim("00", clock=clock), make_sim("01", clock=clock)
    chain_ultrasync([x, y])
    y.set_speed_limit(5000)
    with PtyLineServer([x, y]) as server, serial.Serial(server.slave_path, 38400, timeout=1.0) as ser:
        silent(ser, "BRAKE OFF")
        yield ser, clock


def interpolate(ser, mode: int) -> None:
    for a in ("00", "01"):
        silent(ser, f"{a}#INTERPOL_MODE:={mode}, #INTERPOL_TIME:=100")
        for _ in range(3):
            silent(ser, f"{a}MOVE_INTERPOL 1000")   # 1000 inc in 100 ms = 10000 inc/s (Y: 200 ms)
    silent(ser, "SYNCHRO INTERPOL")


def positions(ser) -> tuple[int, int]:
    return value(ask(ser, "00READ #POSITION")), value(ask(ser, "01READ #POSITION"))


def test_ultrasync_every_axis_waits_for_the_braked_one(chained):
    ser, clock = chained
    assert ask(ser, "00READ #INTERPOL_MODE") == b"00#IMO=+0\r\n"      # factory: SimpleSYNC
    interpolate(ser, -1)
    assert ask(ser, "01READ #INTERPOL_MODE") == b"01#IMO=-1\r\n"
    clock.advance(150 * MS)
    assert positions(ser) == (1000, 750)         # X finished segment 1 at 100 ms and waits for Y
    assert ask(ser, "00READ #SPEED") == b"00#SPE=+0\r\n"              # at rest on the segment's end
    assert ask(ser, "00READ #STATUS.26") == b"00#STA.26=+1\r\n"       # still in its interpolated move
    assert ask(ser, "00READ #INTERPOL_COUNT") == b"00#ICO=+3\r\n"     # segment 1 not released yet
    clock.advance(100 * MS)                      # t = 250: Y ended segment 1 at 200, both started 2
    assert positions(ser) == (1500, 1250)
    assert ask(ser, "00READ #INTERPOL_COUNT") == b"00#ICO=+2\r\n"
    assert ask(ser, "00READ #SPEED") == b"00#SPE=+6000\r\n"           # 10000 inc/s = 60 rpm
    clock.advance(200 * MS)                      # t = 450: segment 3 started on both at 400
    assert positions(ser) == (2500, 2250)
    clock.advance(200 * MS)                      # t = 650: done together at 600
    assert positions(ser) == (3000, 3000)
    for a in ("00", "01"):
        assert ask(ser, f"{a}READ #STATUS.26") == f"{a}#STA.26=+0\r\n".encode()
        assert ask(ser, f"{a}READ #INTERPOL_COUNT") == f"{a}#ICO=+0\r\n".encode()


def test_simplesync_each_axis_times_its_own_segments(chained):
    ser, clock = chained
    interpolate(ser, 0)
    clock.advance(250 * MS)
    assert positions(ser) == (2500, 1250)        # X keeps its own 100 ms timer: it runs ahead
    clock.advance(100 * MS)
    assert positions(ser) == (3000, 1750)
    assert ask(ser, "00READ #STATUS.26") == b"00#STA.26=+0\r\n"


def test_ultrasync_a_stopped_axis_releases_the_others(chained):
    ser, clock = chained
    interpolate(ser, -1)
    clock.advance(150 * MS)
    assert positions(ser) == (1000, 750)
    silent(ser, "01HALT")                         # Y leaves the interpolation (HALT empties its FIFO)
    clock.advance(MS)
    assert value(ask(ser, "01READ #POSITION")) == 750
    clock.advance(200 * MS)                       # X no longer waits for anybody
    assert positions(ser) == (3000, 750)


def test_ultrasync_on_a_served_line_keeps_the_axes_within_one_segment():
    """`motorbus sim serve --drive dmac:00,01`: the modules of one line are chained.
    Real time, so the check is an invariant, not a time: X (20 ms segments) may never
    be more than one segment ahead of Y (200 ms segments)."""
    with SimBench(["dmac:00,01"]) as b:
        with serial.Serial(b.lines[0].pty_path, 38400, timeout=1.0) as ser:
            silent(ser, "BRAKE OFF")
            silent(ser, "00#INTERPOL_MODE:=-1, #INTERPOL_TIME:=20")
            silent(ser, "01#INTERPOL_MODE:=-1, #INTERPOL_TIME:=200")
            for a in ("00", "01"):
                for _ in range(3):
                    silent(ser, f"{a}MOVE_INTERPOL 1000")
            silent(ser, "SYNCHRO INTERPOL")
            samples = 0
            end = time.monotonic() + 5
            while True:
                px = value(ask(ser, "00READ #POSITION"))
                py = value(ask(ser, "01READ #POSITION"))     # read after X: Y can only be further
                assert px <= (py // 1000 + 1) * 1000, (px, py)
                samples += 1
                if px == py == 3000:
                    break
                assert time.monotonic() < end, (px, py)
            assert samples >= 3


def test_module_reset_run_down_speed_is_measured_and_profile_speed_is_nothing():
    clock = SimClock()
    sim = make_sim("02", clock=clock)
    with PtyLineServer([sim]) as server, serial.Serial(server.slave_path, 38400, timeout=1.0) as ser:
        silent(ser, "02BRAKE OFF, #ACCEL_TIME:=100, MOVE_SPEED 60000")   # 600 rpm = 100 000 inc/s
        clock.advance(500 * MS)
        assert ask(ser, "02READ #SPEED") == b"02#SPE=+60000\r\n"
        assert ask(ser, "02READ #PROFILE_SPEED") == b"02#PSP=+60000\r\n"
        silent(ser, "02MODULE_RESET")
        prev_p, prev_s = value(ask(ser, "02READ #POSITION")), value(ask(ser, "02READ #SPEED"))
        assert prev_s == 60000                                          # the rotor does not stop at once
        seen_moving = 0
        for _ in range(40):                                             # 40 ms of the run-down, 1 ms apart
            clock.advance(MS)
            p, s = value(ask(ser, "02READ #POSITION")), value(ask(ser, "02READ #SPEED"))
            assert value(ask(ser, "02READ #PROFILE_SPEED")) == 0          # powered off: no computed speed
            moved = p - prev_p                                          # increments in this millisecond
            mean = (prev_s + s) / 2 * 10000 / 6000 / 1000               # the speeds read, as inc/ms
            assert abs(moved - mean) <= 0.05 * mean + 1.5, (moved, prev_s, s)
            if moved:
                assert s != 0, f"#SPEED 0 while the position moved by {moved}"
                assert ask(ser, "02READ #STATUS.26") == b"02#STA.26=+1\r\n"
                seen_moving += 1
            prev_p, prev_s = p, s
        assert seen_moving >= 30
        clock.advance(1000 * MS)
        p = value(ask(ser, "02READ #POSITION"))
        assert ask(ser, "02READ #SPEED") == b"02#SPE=+0\r\n"
        clock.advance(100 * MS)
        assert value(ask(ser, "02READ #POSITION")) == p                 # at rest when #SPEED says 0


def test_power_off_freewheel_speed_is_measured_too():
    clock = SimClock()
    sim = make_sim("03", clock=clock)
    with PtyLineServer([sim]) as server, serial.Serial(server.slave_path, 38400, timeout=1.0) as ser:
        silent(ser, "03BRAKE OFF, #ACCEL_TIME:=100, MOVE_SPEED -30000")
        clock.advance(500 * MS)
        silent(ser, "03POWER OFF")
        clock.advance(200 * MS)                                         # one time constant (0.2 s)
        s = value(ask(ser, "03READ #SPEED"))
        assert s == pytest.approx(-30000 / 2.718281828, rel=0.01)
        assert ask(ser, "03READ #PROFILE_SPEED") == b"03#PSP=+0\r\n"


def test_ultrasync_through_the_native_client():
    """motorbus's DmacClient on the same pty: set_interpolation(mode=-1) and synchro."""
    from motorbus.drives.dmac import DmacClient, open_line, synchro

    clock = SimClock()
    x, y = make_sim("00", clock=clock), make_sim("01", clock=clock)
    chain_ultrasync([x, y])
    y.set_speed_limit(5000)
    with PtyLineServer([x, y]) as server:
        link = open_line(server.slave_path, timeout=0.5)
        cx, cy = DmacClient(link, address=0), DmacClient(link, address=1)
        try:
            for c in (cx, cy):
                c.brake(False)
            for c in (cx, cy):
                c.set_interpolation(100, 64, -1)
                assert c.read("#INTERPOL_MODE") == -1
                c.move_interpol(1000)
                c.move_interpol(1000)
            synchro(link, "INTERPOL")
            assert cx.position == 0                  # a query: the line has processed the broadcast
            clock.advance(150 * MS)
            assert (cx.position, cy.position) == (1000, 750)
            clock.advance(300 * MS)
            assert (cx.position, cy.position) == (2000, 2000)
        finally:
            cx.close()
            cy.close()

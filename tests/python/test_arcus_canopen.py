"""The DMX-CAN as one drive with two front ends (ASCII and CANopen), on a SimClock.

Every exchange goes through the simulator's own entry points: ``on_line`` (what the
pty server feeds it) and ``on_can_frame`` (what the CAN subscription feeds it), so
time is exact and nothing sleeps.
"""
from __future__ import annotations

import pytest

import motorbus
from motorbus import _core
from motorbus.drives import arcus_canopen as ac

MS = 1_000_000
NODE = 1


def sdo(sim, *payload: int, node: int = NODE) -> bytes:
    """One SDO request in, the reply payload out (b"" = silent)."""
    replies = sim.on_can_frame(_core.can.Frame(0x600 + node, bytes(payload)))
    sdo_replies = [f for f in replies if f.id == 0x580 + node]
    return bytes(sdo_replies[0].data) if sdo_replies else b""


def write(sim, index: int, sub: int, value: int, size: int, signed: bool = False) -> bytes:
    cs = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
    data = value.to_bytes(size, "little", signed=signed or value < 0) + bytes(4 - size)
    return sdo(sim, cs, index & 0xFF, index >> 8, sub, *data)


def read(sim, index: int, sub: int = 0, signed: bool = False) -> int:
    r = sdo(sim, 0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0)
    assert r[0] in (0x4F, 0x4B, 0x47, 0x43), r.hex(" ")
    size = 4 - ((r[0] >> 2) & 3)
    return int.from_bytes(r[4:4 + size], "little", signed=signed)


def ascii(sim, cmd: str) -> str:
    return sim.on_line(f"@01{cmd}").rstrip(b"\0").decode()


def ok(reply: bytes, index: int, sub: int = 0) -> None:
    assert reply == bytes([0x60, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]), reply.hex(" ")


@pytest.fixture
def clock():
    return _core.runtime.SimClock()


# ---- the persona switch (B-A01, B-A04, B-A05) ------------------------------------------

def test_factory_fresh_unit_talks_rs232_then_can_after_store_and_power_cycle_and_back(tmp_path, clock):
    store = str(tmp_path / "dmx.store")
    sim = ac.make_sim(NODE, clock, protocol="ascii", store_path=store)
    assert sim.active_protocol == 0
    assert sdo(sim, 0x40, 0x00, 0x10, 0, 0, 0, 0, 0) == b""        # silent on CAN
    assert ascii(sim, "CM") == "0"
    assert ascii(sim, "CM=2") == "OK" and ascii(sim, "CURR=1200") == "OK"
    sim.power_cycle()                                                 # not stored: discarded
    assert sim.active_protocol == 0 and ascii(sim, "CM") == "0" and ascii(sim, "CURR") == "1600"
    assert ascii(sim, "CM=2") == "OK" and ascii(sim, "CURR=1200") == "OK"
    assert sdo(sim, 0x40, 0x00, 0x10, 0, 0, 0, 0, 0) == b""        # still RS-232 until the power cycle
    assert ascii(sim, "STORE") == "OK"
    boot = sim.on_can_frame(_core.can.Frame(0x000, bytes([0x81, NODE])))
    assert boot == []                                                 # NMT means nothing to a serial unit
    sim.power_cycle()
    assert sim.active_protocol == 2
    assert sim.on_line("@01CM") == b""                                # the serial line is silent now
    assert read(sim, 0x2004, 2) == 1200                               # the settings came along
    assert read(sim, 0x200A) == 2
    # And back: 200Ah = 0 over CAN, read back at once, in effect after store + power cycle.
    ok(write(sim, 0x2004, 2, 1300, 2), 0x2004, 2)
    ok(write(sim, 0x200A, 0, 0, 1), 0x200A)
    assert read(sim, 0x200A) == 0 and sim.active_protocol == 2
    ok(write(sim, 0x200E, 0, 1, 1), 0x200E)
    assert read(sim, 0x200E) == 0                                     # the store finished
    replies = sim.on_can_frame(_core.can.Frame(0x000, bytes([0x81, NODE])))  # NMT reset node = power cycle
    assert [(f.id, bytes(f.data)) for f in replies] == []             # it came up on RS-232: no boot-up
    assert sim.active_protocol == 0
    assert sdo(sim, 0x40, 0x00, 0x10, 0, 0, 0, 0, 0) == b""
    assert ascii(sim, "CM") == "0" and ascii(sim, "CURR") == "1300"


def test_node_id_and_bit_rate_take_effect_only_after_store_and_power_cycle(tmp_path, clock):
    sim = ac.make_sim(NODE, clock, store_path=str(tmp_path / "s"))
    ok(write(sim, 0x200C, 0, 9, 1), 0x200C)
    ok(write(sim, 0x200B, 0, 9, 1), 0x200B)
    assert read(sim, 0x200C) == 9 and sim.can_node_id == NODE and sim.can_bit_rate == 5
    sim.power_cycle()                                                 # without a store: discarded
    assert read(sim, 0x200C) == 1
    ok(write(sim, 0x200C, 0, 9, 1), 0x200C)
    ok(write(sim, 0x200E, 0, 1, 1), 0x200E)
    replies = sim.on_can_frame(_core.can.Frame(0x000, bytes([0x81, 0])))  # reset all nodes
    assert [(f.id, bytes(f.data)) for f in replies] == [(0x709, b"\x00")]
    assert sim.can_node_id == 9
    assert sdo(sim, 0x40, 0x00, 0x10, 0, 0, 0, 0, 0) == b""
    assert sdo(sim, 0x40, 0x00, 0x10, 0, 0, 0, 0, 0, node=9) == bytes.fromhex("43 00 10 00 92 01 00 00")


def test_store_persists_table_8_40_and_nothing_else(tmp_path, clock):
    sim = ac.make_sim(NODE, clock, store_path=str(tmp_path / "s"))
    stored = [(0x2000, 0, 0, 1), (0x2001, 3, 25, 4), (0x2004, 4, 800, 2), (0x2005, 0, 5, 1), (0x2006, 0, 1, 1),
              (0x607C, 0, 77, 4), (0x607E, 0, 0x40, 1), (0x6086, 0, 1, 2)]
    volatile = [(0x6081, 0, 5000, 4), (0x6083, 0, 50, 4), (0x6098, 0, 17, 1), (0x6099, 1, 3000, 4),
                (0x607A, 0, 1234, 4), (0x2007, 0, 1, 1)]
    before = {(i, s): read(sim, i, s) for i, s, _v, _n in volatile}
    for i, s, v, n in stored + volatile:
        ok(write(sim, i, s, v, n), i, s)
    ok(write(sim, 0x200E, 0, 1, 1), 0x200E)
    sim.power_cycle()
    for i, s, v, _n in stored:
        assert read(sim, i, s) == v, hex(i)
    for i, s, _v, _n in volatile:
        assert read(sim, i, s) == before[(i, s)], hex(i)


def test_store_and_clear_handshakes_read_1_while_busy(clock):
    sim = ac.make_sim(NODE, clock, store_time=0.05, clear_time=0.01)
    ok(write(sim, 0x200E, 0, 1, 1), 0x200E)
    assert read(sim, 0x200E) == 1
    clock.advance(49 * MS)
    assert read(sim, 0x200E) == 1
    clock.advance(1 * MS)
    assert read(sim, 0x200E) == 0
    ok(write(sim, 0x200D, 0, 1, 1), 0x200D)
    assert read(sim, 0x200D) == 1
    clock.advance(10 * MS)
    assert read(sim, 0x200D) == 0


# ---- one motion, two front ends ---------------------------------------------------------

def _sample(sim, clock, position, until_idle, step_ms=5, limit=400):
    t0 = clock.now()
    out = []
    for _ in range(limit):
        out.append(((clock.now() - t0) // MS, position()))
        if until_idle():
            return out
        clock.advance(step_ms * MS)
    raise AssertionError("the move never ended")


def test_the_same_move_through_both_personas_gives_the_same_positions_and_timings(tmp_path, clock):
    store = str(tmp_path / "s")
    sim = ac.make_sim(NODE, clock, protocol="ascii", store_path=store)
    for cmd in ("EO=1", "HSPD=20000", "LSPD=100", "ACC=20", "DEC=20", "X1000"):
        assert ascii(sim, cmd) == "OK"
    by_ascii = _sample(sim, clock, lambda: int(ascii(sim, "EX")), lambda: ascii(sim, "SLS") == "0"
                       and int(ascii(sim, "MST")) & 7 == 0)

    assert ascii(sim, "CM=2") == "OK" and ascii(sim, "STORE") == "OK"
    sim.power_cycle()                     # the counters restart at 0 where the shaft is
    for index, value in ((0x6081, 20000), (0x6082, 100), (0x6083, 20), (0x6084, 20)):
        ok(write(sim, index, 0, value, 4), index)
    ok(write(sim, 0x6060, 0, 1, 1), 0x6060)
    for cw in (0x06, 0x07, 0x0F):
        ok(write(sim, 0x6040, 0, cw, 2), 0x6040)
    ok(write(sim, 0x607A, 0, 1000, 4), 0x607A)
    ok(write(sim, 0x6040, 0, 0x1F, 2), 0x6040)
    assert read(sim, 0x6041) & 0x1000                     # set-point acknowledged
    by_canopen = _sample(sim, clock, lambda: read(sim, 0x6064, signed=True),
                         lambda: bool(read(sim, 0x6041) & 0x0400))
    assert by_canopen == by_ascii
    assert by_ascii[-1][1] == 1000 and by_ascii[-1][0] > 50


# ---- CiA 402 as manual 000 §8 names it ----------------------------------------------------

def _enable(sim, mode: int) -> None:
    ok(write(sim, 0x6060, 0, mode, 1), 0x6060)
    for cw in (0x06, 0x07, 0x0F):
        ok(write(sim, 0x6040, 0, cw, 2), 0x6040)
    assert read(sim, 0x6041) & 0x6F == 0x27


def test_state_machine_transitions_and_motor_power(clock):
    sim = ac.make_sim(NODE, clock)
    assert read(sim, 0x6041) & 0x4F == 0x40                          # Switch on disabled at power-up
    ok(write(sim, 0x6040, 0, 0x0F, 2), 0x6040)                        # D1: no jump to Operation enabled
    assert read(sim, 0x6041) & 0x4F == 0x40
    ok(write(sim, 0x6040, 0, 0x06, 2), 0x6040)
    assert read(sim, 0x6041) & 0x6F == 0x21 and sim.on_line("@01EO") == b""  # (serial silent: CAN unit)
    ok(write(sim, 0x6040, 0, 0x07, 2), 0x6040)                        # T1: motor enabled
    assert read(sim, 0x6041) & 0x6F == 0x23
    ok(write(sim, 0x6040, 0, 0x06, 2), 0x6040)                        # T2
    assert read(sim, 0x6041) & 0x6F == 0x21
    _enable(sim, 1)
    assert read(sim, 0x6061) == 1
    ok(write(sim, 0x6040, 0, 0x07, 2), 0x6040)                        # T4
    assert read(sim, 0x6041) & 0x6F == 0x23
    ok(write(sim, 0x6040, 0, 0x00, 2), 0x6040)                        # T6: disable voltage
    assert read(sim, 0x6041) & 0x4F == 0x40


def test_profile_position_relative_and_set_of_set_points(clock):
    sim = ac.make_sim(NODE, clock)
    for index, value in ((0x6081, 20000), (0x6082, 100), (0x6083, 20), (0x6084, 20)):
        ok(write(sim, index, 0, value, 4), index)
    _enable(sim, 1)
    ok(write(sim, 0x607A, 0, 500, 4), 0x607A)
    ok(write(sim, 0x6040, 0, 0x5F, 2), 0x6040)                        # relative
    clock.advance(20 * MS)
    # Single set-point (bit 5 = 0) while moving: not acknowledged (B-A12).
    ok(write(sim, 0x6040, 0, 0x4F, 2), 0x6040)
    ok(write(sim, 0x6040, 0, 0x5F, 2), 0x6040)
    assert not read(sim, 0x6041) & 0x1000
    # Set of set-points (bit 5 = 1): buffered, played after this move.
    ok(write(sim, 0x6040, 0, 0x4F, 2), 0x6040)
    ok(write(sim, 0x6040, 0, 0x7F, 2), 0x6040)
    assert read(sim, 0x6041) & 0x1000
    ok(write(sim, 0x6040, 0, 0x4F, 2), 0x6040)
    for _ in range(200):
        clock.advance(5 * MS)
        if read(sim, 0x6041) & 0x0400:
            break
    assert read(sim, 0x6064, signed=True) == 1000


def test_a_buffered_set_point_starts_the_instant_the_move_before_it_ends(clock):
    sim = ac.make_sim(NODE, clock)
    for index, value in ((0x6081, 20000), (0x6082, 100), (0x6083, 20), (0x6084, 20)):
        ok(write(sim, index, 0, value, 4), index)
    _enable(sim, 1)
    # One relative 500-count move alone: how long it takes, to the millisecond.
    ok(write(sim, 0x607A, 0, 500, 4), 0x607A)
    ok(write(sim, 0x6040, 0, 0x5F, 2), 0x6040)
    ok(write(sim, 0x6040, 0, 0x4F, 2), 0x6040)
    single = 0
    while not read(sim, 0x6041) & 0x0400:
        clock.advance(1 * MS)
        single += 1
    assert read(sim, 0x6064) == 500
    # The same move twice as a set of set-points, nobody looking in between: the
    # second starts where the first ended, so both are done after 2 x single.
    ok(write(sim, 0x6040, 0, 0x5F, 2), 0x6040)
    ok(write(sim, 0x6040, 0, 0x4F, 2), 0x6040)
    clock.advance(2 * MS)
    ok(write(sim, 0x6040, 0, 0x7F, 2), 0x6040)
    assert read(sim, 0x6041) & 0x1000
    ok(write(sim, 0x6040, 0, 0x4F, 2), 0x6040)
    clock.advance((2 * single - 2) * MS)
    assert read(sim, 0x6064) == 1500 and read(sim, 0x6041) & 0x0400


def test_profile_velocity_halt_and_polarity(clock):
    sim = ac.make_sim(NODE, clock)
    ok(write(sim, 0x6083, 0, 10, 4), 0x6083)
    ok(write(sim, 0x6084, 0, 10, 4), 0x6084)
    _enable(sim, 3)
    ok(write(sim, 0x60FF, 0, -4000, 4), 0x60FF)
    clock.advance(100 * MS)
    assert read(sim, 0x606C, signed=True) == -4000
    assert read(sim, 0x6041) & 0x0400                                 # target velocity reached
    ok(write(sim, 0x6040, 0, 0x10F, 2), 0x6040)                       # halt
    clock.advance(100 * MS)
    assert read(sim, 0x606C, signed=True) == 0
    at = read(sim, 0x6064, signed=True)
    assert at < 0
    ok(write(sim, 0x607E, 0, 0xC0, 1), 0x607E)                        # both polarities reversed
    assert read(sim, 0x6064, signed=True) == -at
    ok(write(sim, 0x6040, 0, 0x0F, 2), 0x6040)                        # release: resume at 60FFh
    clock.advance(100 * MS)
    assert read(sim, 0x606C, signed=True) == -4000                    # shown with the polarity
    assert sim.encoder_position > at                                  # the motor runs the other way now


@pytest.mark.parametrize("method, final_sign", [(19, 1), (20, -1), (7, 1), (11, -1), (33, 1), (34, -1)])
def test_homing_methods_with_the_manuals_directions(clock, method, final_sign):
    # The home switch sits on the positive side of a motor started at -2000 steps... or
    # negative side when started at +12000: the search direction decides whether it is found.
    start = -2000.0 if final_sign > 0 else 12000.0
    sim = ac.make_sim(NODE, clock, start_position=start)
    for sub, value in ((1, 20000), (2, 2000)):
        ok(write(sim, 0x6099, sub, value, 4), 0x6099, sub)
    ok(write(sim, 0x609A, 0, 20, 4), 0x609A)
    ok(write(sim, 0x6098, 0, method, 1), 0x6098)
    _enable(sim, 6)
    ok(write(sim, 0x6040, 0, 0x1F, 2), 0x6040)
    for _ in range(2000):
        clock.advance(5 * MS)
        sw = read(sim, 0x6041)
        if sw & 0x2000 or sw & 0x1400 == 0x1400:
            break
    assert sw & 0x3400 == 0x1400, hex(sw)                             # attained, no error
    assert read(sim, 0x6064, signed=True) == 0
    moved = sim.physical_position - start
    assert moved * final_sign > 0                                      # in the manual's direction


def test_homing_35_and_limit_homing(clock):
    sim = ac.make_sim(NODE, clock, start_position=1234, minus_limit=-3000.0)
    ok(write(sim, 0x6098, 0, 35, 1), 0x6098)
    _enable(sim, 6)
    ok(write(sim, 0x6040, 0, 0x1F, 2), 0x6040)
    assert read(sim, 0x6041) & 0x3400 == 0x1400 and read(sim, 0x6064) == 0
    # 18: negative limit (manual 000; CiA 402 would say positive), back off by 607Ch.
    ok(write(sim, 0x6040, 0, 0x0F, 2), 0x6040)
    ok(write(sim, 0x607C, 0, 400, 4), 0x607C)
    ok(write(sim, 0x6098, 0, 18, 1), 0x6098)
    for sub, value in ((1, 20000), (2, 2000)):
        ok(write(sim, 0x6099, sub, value, 4), 0x6099, sub)
    ok(write(sim, 0x609A, 0, 20, 4), 0x609A)
    ok(write(sim, 0x6040, 0, 0x1F, 2), 0x6040)
    for _ in range(2000):
        clock.advance(5 * MS)
        if read(sim, 0x6041) & 0x1400 == 0x1400:
            break
    assert read(sim, 0x6041) & 0x3400 == 0x1400
    assert sim.physical_position < 0                                  # it went to the negative limit


@pytest.mark.parametrize("method, side", [(17, 1), (18, -1)])
def test_limit_homing_goes_to_the_manuals_limit_and_backs_off_by_the_home_offset(clock, method, side):
    sim = ac.make_sim(NODE, clock, minus_limit=-3000.0, plus_limit=3000.0)
    ok(write(sim, 0x607C, 0, 500, 4), 0x607C)                         # counts (StepNLoop on): 400 steps
    ok(write(sim, 0x6098, 0, method, 1), 0x6098)
    for sub, value in ((1, 20000), (2, 2000)):
        ok(write(sim, 0x6099, sub, value, 4), 0x6099, sub)
    ok(write(sim, 0x609A, 0, 20, 4), 0x609A)
    _enable(sim, 6)
    ok(write(sim, 0x6040, 0, 0x1F, 2), 0x6040)
    for _ in range(2000):
        clock.advance(5 * MS)
        if read(sim, 0x6041) & 0x1400 == 0x1400:
            break
    assert read(sim, 0x6041) & 0x3400 == 0x1400
    assert read(sim, 0x6064) == 0
    assert sim.physical_position == pytest.approx(side * (3000 - 400), abs=2)


def test_limit_error_is_a_fault_until_the_clear_error_handshake(clock):
    # (Controlword bit 7 alone also recovers, transition 6: tests/interop/test_arcus_canopen_audit.py.)
    sim = ac.make_sim(NODE, clock)
    _enable(sim, 3)
    sim.force_limit(1, True)
    ok(write(sim, 0x60FF, 0, 2000, 4), 0x60FF)
    sw = read(sim, 0x6041)
    assert sw & 0x4F == 0x08 and sw & 0x0800                          # Fault, internal limit active
    assert read(sim, 0x2003) == 11 and read(sim, 0x1001) == 1
    ok(write(sim, 0x200D, 0, 1, 1), 0x200D)
    assert read(sim, 0x200D) == 0 and read(sim, 0x1001) == 0
    ok(write(sim, 0x6040, 0, 0x00, 2), 0x6040)
    ok(write(sim, 0x6040, 0, 0x80, 2), 0x6040)                        # rising edge of bit 7
    assert read(sim, 0x6041) & 0x4F == 0x40
    sim.force_limit(1, None)


def test_stall_is_a_fault(clock):
    sim = ac.make_sim(NODE, clock)
    for index, value in ((0x6081, 20000), (0x6083, 20), (0x6084, 20)):
        ok(write(sim, index, 0, value, 4), index)
    _enable(sim, 1)
    sim.set_blocked(True)
    ok(write(sim, 0x607A, 0, 20000, 4), 0x607A)
    ok(write(sim, 0x6040, 0, 0x1F, 2), 0x6040)
    clock.advance(500 * MS)
    assert read(sim, 0x6041) & 0x4F == 0x08
    assert read(sim, 0x2003) == 10                                     # stall error


def test_profile_velocity_changes_speed_on_the_fly_and_reverses_through_a_stop(clock):
    sim = ac.make_sim(NODE, clock)
    ok(write(sim, 0x6083, 0, 10, 4), 0x6083)
    ok(write(sim, 0x6084, 0, 10, 4), 0x6084)
    _enable(sim, 3)
    ok(write(sim, 0x60FF, 0, 4000, 4), 0x60FF)
    clock.advance(100 * MS)
    assert read(sim, 0x606C, signed=True) == 4000
    ok(write(sim, 0x60FF, 0, 8000, 4), 0x60FF)
    speeds = []
    for _ in range(40):
        clock.advance(5 * MS)
        speeds.append(read(sim, 0x606C, signed=True))
    assert min(speeds) >= 4000 and speeds[-1] == 8000                # never stopped on the way
    ok(write(sim, 0x60FF, 0, -2000, 4), 0x60FF)
    speeds = []
    for _ in range(80):
        clock.advance(5 * MS)
        speeds.append(read(sim, 0x606C, signed=True))
    assert 0 in speeds and speeds[-1] == -2000                        # a reversal goes through 0


def test_a_mode_written_while_moving_takes_over_once_idle(clock):
    sim = ac.make_sim(NODE, clock)
    ok(write(sim, 0x6083, 0, 10, 4), 0x6083)
    ok(write(sim, 0x6084, 0, 10, 4), 0x6084)
    _enable(sim, 3)
    ok(write(sim, 0x60FF, 0, 3000, 4), 0x60FF)
    clock.advance(50 * MS)
    ok(write(sim, 0x6060, 0, 1, 1), 0x6060)
    assert read(sim, 0x6061) == 3                                     # still running in PV
    # StepNLoop cannot be switched while the motor runs (the units would change under it).
    assert write(sim, 0x2001, 1, 0, 4) == bytes.fromhex("80 01 20 01 22 00 00 08")
    ok(write(sim, 0x6040, 0, 0x10F, 2), 0x6040)                       # halt
    clock.advance(50 * MS)
    assert read(sim, 0x6061) == 1                                     # idle: PP took over
    assert read(sim, 0x606C) == 0


def test_quick_stop_stops_at_once_and_disables(clock):
    sim = ac.make_sim(NODE, clock)
    _enable(sim, 3)
    ok(write(sim, 0x60FF, 0, 3000, 4), 0x60FF)
    clock.advance(200 * MS)
    ok(write(sim, 0x6040, 0, 0x02, 2), 0x6040)
    assert read(sim, 0x606C) == 0
    assert read(sim, 0x6041) & 0x4F == 0x40


# ---- the client and the Drive adapter on a virtual bus ------------------------------------

def test_native_client_names_types_and_handshakes():
    with motorbus.open_bus("virtual:arcus-canopen-client") as simbus:
        sim = ac.make_sim(NODE, bus=simbus)
        with motorbus.open_bus("virtual:arcus-canopen-client") as bus:
            host = ac.ArcusCanopen(bus, NODE, timeout=1.0, on_error=None, on_exit=None)
            assert host.snl_status is ac.SnlStatus.IDLE
            assert host.comm_type is ac.CommType.CAN and host.bit_rate is ac.BitRate.K125
            assert host.run_current == 1500 and host.snl_tolerance == 10 and host.counts_per_rev == 4000
            host.run_current = 1800
            assert host.run_current == 1800
            with pytest.raises(motorbus.InvalidArgument, match="outside 100..2500"):
                host.idle_current = 50
            with pytest.raises(motorbus.InvalidArgument, match="read-only"):
                host.write(0x6041, 0, 0)
            host.store()
            host.clear_errors()
            host.enable()
            host.set_mode(ac.OpMode.HOMING)
            host.home_arcus(ac.ArcusHomingMethod.CURRENT_POSITION, timeout=2)
            assert host.position == 0
            with pytest.raises(motorbus.InvalidArgument):
                host.home_arcus(21)
            host.close()
        sim.close()


def test_drive_move_while_moving_is_refused_typed_like_the_ascii_persona():
    with motorbus.open_bus("virtual:arcus-canopen-busy") as simbus:
        sim = ac.make_sim(NODE, bus=simbus)
        with motorbus.open_drive("arcus-canopen", bus="virtual:arcus-canopen-busy", address=NODE,
                                 timeout=0.2) as axis:
            axis.params["0x6081"] = 2000
            axis.enable()
            axis.move_to(100000, wait=False)
            with pytest.raises(motorbus.DriveFault, match="while the motor moves"):
                axis.move_to(10)
            with pytest.raises(motorbus.DriveFault, match="while the motor moves"):
                axis.jog(1000)
            axis.stop()
            axis.wait_idle(timeout=5)
            axis.jog(1000)
            with pytest.raises(motorbus.DriveFault, match="while the motor moves"):
                axis.move_by(10)
            axis.stop()
            axis.wait_idle(timeout=5)
            at = axis.position
            axis.move_by(10, timeout=5)
            assert axis.position == at + 10
        sim.close()


def test_plugin_and_drive_adapter_say_there_is_no_watchdog():
    plugin = motorbus.registry.drive_plugin("arcus-canopen")
    assert plugin.transport == "can" and plugin.check_address(" 5 ") == "5"
    with pytest.raises(motorbus.InvalidArgument):
        plugin.check_address("128")
    assert ac.ArcusCanopenDrive.has_watchdog is False
    assert motorbus.Capability.WATCHDOG not in ac.ArcusCanopenDrive.capabilities
    with pytest.raises(motorbus.InvalidArgument, match="unknown"):
        ac.make_sim(1, heartbeat_ms=100)
    with pytest.raises(motorbus.InvalidArgument, match="protocol"):
        ac.make_sim(1, protocol="modbus")


def test_latch_captures_positions_on_di2(clock):
    sim = ac.make_sim(NODE, clock)
    _enable(sim, 3)
    ok(write(sim, 0x60FF, 0, 2000, 4), 0x60FF)
    clock.advance(300 * MS)
    assert read(sim, 0x2008) == 0
    ok(write(sim, 0x2007, 0, 1, 1), 0x2007)
    assert read(sim, 0x2008) == 1                                     # armed, waiting
    at = sim.encoder_position
    sim.set_input(2, True)
    assert read(sim, 0x2008) == 2                                     # triggered
    assert read(sim, 0x2009, 2, signed=True) == at
    assert read(sim, 0x60FD) & (1 << 17)                              # DI2 in 60FDh bit 17
    clock.advance(100 * MS)
    assert read(sim, 0x2009, 2, signed=True) == at                    # the counters ran on, the latch did not


def test_sim_serve_store_dir_gives_each_node_its_flash_file(tmp_path):
    from motorbus.sim import SimBench
    with SimBench(["arcus-canopen:3"], bus="virtual:arcus-canopen-store", store_dir=str(tmp_path)) as bench:
        sim = bench.sims[("arcus-canopen", "3")]
        assert sim.store_path == str(tmp_path / "arcus-canopen-3.store")
        sdo_reply = sim.on_can_frame(_core.can.Frame(0x603, bytes([0x2F, 0x0E, 0x20, 0, 1, 0, 0, 0])))
        assert bytes(sdo_reply[0].data)[0] == 0x60
    assert (tmp_path / "arcus-canopen-3.store").read_text().count("CM=2") == 1


def test_the_shipped_eds_is_generated_from_the_table_and_canopen_reads_it():
    import pathlib

    import canopen
    path = pathlib.Path(__file__).parents[2] / "cpp/motorbus/drives/arcus/canopen.eds"
    assert path.read_text() == ac.eds_text()   # regenerate: python -c "...ac.eds_text()" > canopen.eds
    od = canopen.import_od(str(path))
    entries = {(o.index, o.subindex) for obj in od.values()
               for o in (obj.values() if isinstance(obj, (canopen.objectdictionary.ODRecord,
                                                           canopen.objectdictionary.ODArray)) else [obj])}
    assert entries == {(r[0], r[1]) for r in ac.OBJECTS}
    assert od[0x6402].default == 768 and od[0x1018][3].default == 112 and od[0x2004][2].default == 1500


def test_the_same_drive_api_script_through_both_personas_of_one_drive(tmp_path):
    """The Drive API on the ASCII persona (pty), then, after CM=2 + store + power cycle,
    on the CANopen persona (virtual bus) of the same simulated drive: same positions."""
    units = motorbus.Units("mm", 0.01)

    def script(drive, home_method, speed_params) -> list:
        for name, value in speed_params.items():
            drive.params[name] = value
        drive.enable()
        drive.move_to(10.0, timeout=10)
        out = [drive.position]
        drive.move_by(-3.0, timeout=10)
        out.append(drive.position)
        drive.home(home_method, timeout=20)
        out.append(drive.position)
        drive.move_to(2.5, timeout=10)
        out.append(drive.position)
        return out

    with motorbus.open_bus("virtual:arcus-both") as sim_bus:
        sim = ac.make_sim(NODE, protocol="ascii", store_path=str(tmp_path / "flash"), bus=sim_bus, eo_boot=True)
        pty = _core.serial.PtyLineServer([sim], 0, None)
        try:
            with motorbus.open_drive("arcus", line=pty.slave_path, address="01", units=units) as axis:
                by_ascii = script(axis, "HL+", {"HSPD": 20000, "LSPD": 2000, "ACC": 20, "DEC": 20})
                # Back to where the shaft started (home is 8000 steps = 100 mm out), so the
                # second persona starts from the same place: the power cycle zeroes the counters.
                axis.move_to(-100.0, timeout=10)
                assert sim.physical_position == 0
                axis.params["CM"] = 2
                axis.store()
            sim.power_cycle()
            with motorbus.open_drive("arcus-canopen", bus="virtual:arcus-both", address=NODE, units=units) as axis:
                by_canopen = script(axis, 19, {"0x6081": 20000, "0x6082": 2000, "0x6083": 20, "0x6084": 20,
                                               "0x6099:01": 20000, "0x6099:02": 2000, "0x609A": 20})
        finally:
            pty.close()
            sim.close()
    assert by_ascii == by_canopen == [10.0, 7.0, 0.0, 2.5]

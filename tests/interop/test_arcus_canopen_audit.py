"""Issue 23, DMX-CAN over CANopen (items 1-5) and the PMC007's baud index (item 11):
the simulators served as `motorbus sim serve` serves them (motorbus.sim.SimBench, a
socketcand server on 127.0.0.1), reached by python-can's socketcand interface with raw
CiA 301 frames -- no motorbus code on the client side.  The simulator objects are used
only for what a bench has and a bus does not: the shaft's physical position, a forced
limit switch, a jammed rotor, and moving a drive from one bus to another.
"""
import time

import can
import pytest

from motorbus.sim import SimBench

NODE = 1
KIND = "arcus-canopen"


def _bus(bench: SimBench) -> can.BusABC:
    srv = bench.can.servers[0]
    return can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")


def _drain(bus, quiet: float = 0.05) -> None:
    while bus.recv(quiet) is not None:
        pass


def _exchange(bus, node: int, request: bytes, timeout: float = 2.0):
    """One SDO request; the reply's 8 bytes, or None when the node stays silent."""
    bus.send(can.Message(arbitration_id=0x600 + node, data=request, is_extended_id=False))
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        m = bus.recv(max(0.0, deadline - time.monotonic()))
        if m is not None and m.arbitration_id == 0x580 + node:
            return bytes(m.data)
    return None


def _read(bus, index: int, sub: int = 0, node: int = NODE, signed: bool = False) -> int:
    r = _exchange(bus, node, bytes([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]))
    assert r is not None, f"no reply to an upload of {index:04X}h:{sub:02X}"
    assert r[0] & 0xE3 == 0x43, f"{index:04X}h:{sub:02X} aborted: {r.hex(' ')}"
    size = 4 - ((r[0] >> 2) & 3)
    return int.from_bytes(r[4:4 + size], "little", signed=signed)


def _write(bus, index: int, sub: int, value: int, size: int, node: int = NODE) -> bytes:
    cs = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
    data = (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little").ljust(4, b"\0")
    r = _exchange(bus, node, bytes([cs, index & 0xFF, index >> 8, sub]) + data)
    assert r is not None, f"no reply to a download of {index:04X}h:{sub:02X}"
    return r


def _ok(bus, index: int, sub: int, value: int, size: int, node: int = NODE) -> None:
    r = _write(bus, index, sub, value, size, node)
    assert r == bytes([0x60, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]), r.hex(" ")


def _handshake(bus, index: int, node: int = NODE, timeout: float = 3.0) -> list:
    """Fig. 8.1 / 8.2: write 1, poll until the drive resets the object to 0; the reads seen."""
    _ok(bus, index, 0, 1, 1, node)
    seen = []
    deadline = time.monotonic() + timeout
    while True:
        seen.append(_read(bus, index, node=node))
        if seen[-1] == 0:
            return seen
        assert time.monotonic() < deadline, f"{index:04X}h still reads 1"
        time.sleep(0.005)


def _boot_up(bus, node: int, timeout: float = 1.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        m = bus.recv(max(0.0, deadline - time.monotonic()))
        if m is not None and m.arbitration_id == 0x700 + node:
            return bytes(m.data)
    return None


def _nmt(bus, command: int, node: int) -> None:
    bus.send(can.Message(arbitration_id=0, data=bytes([command, node]), is_extended_id=False))


# ---- item 1: the store lives as long as the simulator ------------------------------------

def test_store_survives_nmt_reset_node_without_a_store_file():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        bus = _bus(bench)
        try:
            _ok(bus, 0x200C, 0, 5, 1)
            _ok(bus, 0x607C, 0, -1234, 4)
            _ok(bus, 0x2004, 2, 1800, 2)
            _handshake(bus, 0x200E)
            _drain(bus)
            _nmt(bus, 0x81, NODE)                                       # reset node = power cycle
            assert _boot_up(bus, 5) == b"\x00"                          # boots on 0x705, not 0x701
            assert _exchange(bus, NODE, bytes.fromhex("40 0C 20 00 00 00 00 00"), 0.3) is None
            assert _read(bus, 0x200C, node=5) == 5
            assert _read(bus, 0x607C, node=5, signed=True) == -1234
            assert _read(bus, 0x2004, 2, node=5) == 1800
            # What was not stored is gone at the next power cycle.
            _ok(bus, 0x607C, 0, 99, 4, node=5)
            _drain(bus)
            _nmt(bus, 0x81, 5)
            assert _boot_up(bus, 5) == b"\x00"
            assert _read(bus, 0x607C, node=5, signed=True) == -1234
        finally:
            bus.shutdown()


# ---- item 2: controlword bit 7 recovers from a latched fault ----------------------------

def _state(bus) -> int:
    return _read(bus, 0x6041)


def _enable(bus, mode: int) -> None:
    _ok(bus, 0x6060, 0, mode, 1)
    for cw in (0x06, 0x07, 0x0F):
        _ok(bus, 0x6040, 0, cw, 2)
    assert _state(bus) & 0x6F == 0x27


def _generic_recovery(bus) -> None:
    """What any CiA 402 master does: fault reset (rising bit 7), shutdown, switch on, enable."""
    _ok(bus, 0x6040, 0, 0x00, 2)
    _ok(bus, 0x6040, 0, 0x80, 2)
    assert _state(bus) & 0x4F == 0x40                                  # Switch on disabled
    assert _read(bus, 0x1001) == 0
    _ok(bus, 0x6040, 0, 0x06, 2)
    assert _state(bus) & 0x6F == 0x21
    _ok(bus, 0x6040, 0, 0x07, 2)
    _ok(bus, 0x6040, 0, 0x0F, 2)
    assert _state(bus) & 0x6F == 0x27                                  # Operation enabled again


def test_fault_reset_recovers_from_a_latched_limit_error():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        sim = bench.sims[(KIND, str(NODE))]
        bus = _bus(bench)
        try:
            _enable(bus, 3)
            sim.force_limit(1, True)
            _ok(bus, 0x60FF, 0, 2000, 4)
            sw = _state(bus)
            assert sw & 0x4F == 0x08 and sw & 0x0800, hex(sw)          # Fault, internal limit
            assert _read(bus, 0x2003) == 11 and _read(bus, 0x1001) == 1
            sim.force_limit(1, None)
            _generic_recovery(bus)
            assert _read(bus, 0x2003) == 0
        finally:
            bus.shutdown()


def test_fault_reset_recovers_from_a_stepnloop_stall():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        sim = bench.sims[(KIND, str(NODE))]
        bus = _bus(bench)
        try:
            for index, value in ((0x6081, 20000), (0x6083, 20), (0x6084, 20)):
                _ok(bus, index, 0, value, 4)
            _enable(bus, 1)
            sim.set_blocked(True)
            _ok(bus, 0x607A, 0, 20000, 4)
            _ok(bus, 0x6040, 0, 0x1F, 2)
            deadline = time.monotonic() + 5
            while _state(bus) & 0x4F != 0x08:
                assert time.monotonic() < deadline, "no stall fault"
                time.sleep(0.01)
            assert _read(bus, 0x2003) == 10                              # stall error
            sim.set_blocked(False)
            _generic_recovery(bus)
            assert _read(bus, 0x2003) == 0
        finally:
            bus.shutdown()


# ---- item 3: the home offset 607Ch ------------------------------------------------------

def _home(bus, node: int, method: int, offset: int, polarity: int = 0, speeds=(20000, 8000), timeout=10.0,
          sample=None) -> None:
    _ok(bus, 0x607E, 0, polarity, 1, node)
    _ok(bus, 0x607C, 0, offset, 4, node)
    _ok(bus, 0x6098, 0, method, 1, node)
    _ok(bus, 0x6099, 1, speeds[0], 4, node)
    _ok(bus, 0x6099, 2, speeds[1], 4, node)
    _ok(bus, 0x609A, 0, 20, 4, node)
    _ok(bus, 0x6060, 0, 6, 1, node)
    for cw in (0x06, 0x07, 0x0F, 0x1F):
        _ok(bus, 0x6040, 0, cw, 2, node)
    deadline = time.monotonic() + timeout
    while True:
        sw = _read(bus, 0x6041, node=node)
        if sw & 0x2000 or sw & 0x1400 == 0x1400:
            break
        if sample is not None:
            sample(_read(bus, 0x606C, node=node, signed=True))
        assert time.monotonic() < deadline, f"homing {method} did not end: {sw:#06x}"
        time.sleep(0.005)
    assert sw & 0x3400 == 0x1400, f"homing {method}: {sw:#06x}"      # attained, no error
    assert _read(bus, 0x6064, node=node, signed=True) == 0


# 500 counts = 400 motor steps (StepNLoop on: 4000 counts, 3200 steps a revolution).
# (method, 607Eh, 607Ch, start, end shift in steps against the same homing without offset)
OFFSET_CASES = [
    (7, 0, 500, 0.0, -400),       # positive search; "change direction and move by the home offset"
    (11, 0, 500, 12000.0, 400),   # negative search; change direction: +
    (33, 0, 500, 0.0, 400),       # "continue moving by the home offset amount"
    (34, 0, 500, 0.0, -400),
    (19, 0, 500, 0.0, -400),      # "move back by the Home Offset amount"
    (20, 0, 500, 12000.0, 400),
    (33, 0, -500, 0.0, -400),     # its sign is kept
    (33, 0x80, 500, 0.0, -400),   # 607Eh bit 7 reverses it like every position value
]


@pytest.mark.parametrize("method, polarity, offset, start, shift", OFFSET_CASES)
def test_home_offset_sets_the_end_point(method, polarity, offset, start, shift):
    # Node 1 homes without an offset, node 2 with: same world, same start.
    with SimBench([f"{KIND}:1,2"], sim_options={KIND: {"start_position": start}}) as bench:
        bus = _bus(bench)
        try:
            _home(bus, 1, method, 0, polarity)
            _home(bus, 2, method, offset, polarity)
            plain = bench.sims[(KIND, "1")].physical_position
            offs = bench.sims[(KIND, "2")].physical_position
            assert offs - plain == pytest.approx(shift, abs=1.5), (plain, offs)
        finally:
            bus.shutdown()


@pytest.mark.parametrize("method, side", [(17, 1), (18, -1)])
def test_limit_homing_backs_off_at_the_zero_position_speed(method, side):
    speeds = (20000, 5000)
    with SimBench([f"{KIND}:{NODE}"], sim_options={KIND: {"minus_limit": -3000.0, "plus_limit": 3000.0}}) as bench:
        bus = _bus(bench)
        away = []
        try:
            _home(bus, NODE, method, 4000, speeds=speeds,
                  sample=lambda v: away.append(-side * v) if v * side < 0 else None)
            # Away from the limit by 4000 counts = 3200 steps, end point zero.
            assert bench.sims[(KIND, str(NODE))].physical_position == pytest.approx(side * (3000 - 3200), abs=2)
        finally:
            bus.shutdown()
    assert away, "the back-off was never seen moving"
    assert max(away) <= speeds[1] * 1.01, max(away)                   # never at the home-switch speed


# ---- item 4 and 11: a stored bit rate takes effect -------------------------------------

def test_stored_bit_rate_takes_effect_after_store_and_power_cycle():
    with SimBench([f"{KIND}:{NODE}"], bitrate=125000) as old, \
            SimBench([], bitrate=500000, socketcand=["127.0.0.1:0"]) as new:
        sim = old.sims[(KIND, str(NODE))]
        bus, bus2 = _bus(old), _bus(new)
        try:
            assert _read(bus, 0x200B) == 5                              # factory: 125 kbit/s, the wire's
            _ok(bus, 0x200B, 0, 7, 1)                                   # 500 kbit/s
            assert _read(bus, 0x200B) == 7                              # read back at once
            _drain(bus)
            _nmt(bus, 0x81, NODE)                                       # not stored: discarded
            assert _boot_up(bus, NODE) == b"\x00"
            assert _read(bus, 0x200B) == 5
            _ok(bus, 0x200B, 0, 7, 1)
            _handshake(bus, 0x200E)
            assert _read(bus, 0x200B) == 7                              # still answering at 125k
            _drain(bus)
            _nmt(bus, 0x81, NODE)
            assert _boot_up(bus, NODE, 0.5) is None                     # its boot-up is not on this wire
            assert _exchange(bus, NODE, bytes.fromhex("40 0B 20 00 00 00 00 00"), 0.5) is None
            assert sim.can_bit_rate == 7
            # The same drive on a 500 kbit/s bus: reachable again.
            sim.close()
            sim.attach(new.can.endpoint())
            assert _boot_up(bus2, NODE) == b"\x00"
            assert _read(bus2, 0x200B) == 7
            assert _read(bus2, 0x1000) & 0xFFFF == 0x0192
        finally:
            sim.close()
            bus.shutdown()
            bus2.shutdown()


def test_pmc007_baud_index_takes_effect_at_reset_communication():
    node = 5
    with SimBench([f"pmc007:{node}"], bitrate=125000) as old, \
            SimBench([], bitrate=500000, socketcand=["127.0.0.1:0"]) as new:
        sim = old.sims[("pmc007", str(node))]
        bus, bus2 = _bus(old), _bus(new)
        try:
            assert _read(bus, 0x2003, node=node) == 4                   # index 4 = 125 kbit/s
            _ok(bus, 0x2003, 0, 6, 1, node)                             # 500 kbit/s (RAM)
            assert _read(bus, 0x2003, node=node) == 6
            _drain(bus)
            _nmt(bus, 0x82, node)                                       # reset communication: in effect
            assert _boot_up(bus, node, 0.5) is None
            assert _exchange(bus, node, bytes.fromhex("40 03 20 00 00 00 00 00"), 0.5) is None
            assert sim.active_baud_index == 6
            sim.close()
            sim.attach(new.can.endpoint())
            assert _boot_up(bus2, node) == b"\x00"
            assert _read(bus2, 0x2003, node=node) == 6
        finally:
            sim.close()
            bus.shutdown()
            bus2.shutdown()


def test_a_bus_without_a_bit_rate_carries_any_code():
    # No wire modelled (the default of `motorbus sim serve`): the node answers whatever 200Bh says.
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        bus = _bus(bench)
        try:
            _ok(bus, 0x200B, 0, 9, 1)
            _handshake(bus, 0x200E)
            _drain(bus)
            _nmt(bus, 0x81, NODE)
            assert _boot_up(bus, NODE) == b"\x00"
            assert _read(bus, 0x200B) == 9
        finally:
            bus.shutdown()


# ---- item 5: U32 StepNLoop parameters, handshakes that take time -------------------------

@pytest.mark.parametrize("sub", [2, 3, 4, 5])
def test_stepnloop_parameters_take_the_whole_u32_range(sub):
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        bus = _bus(bench)
        try:
            for value in (0x80000000, 0xFFFFFFFF):
                _ok(bus, 0x2001, sub, value, 4)
                assert _read(bus, 0x2001, sub) == value
        finally:
            bus.shutdown()


def test_served_store_handshake_reads_1_while_it_runs():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        bus = _bus(bench)
        try:
            seen = _handshake(bus, 0x200E)
            assert seen[0] == 1 and seen[-1] == 0, seen                 # the master's loop ran
        finally:
            bus.shutdown()


def test_clear_handshake_reads_1_for_the_configured_time():
    with SimBench([f"{KIND}:{NODE}"], sim_options={KIND: {"clear_time": 0.3, "store_time": 0.3}}) as bench:
        bus = _bus(bench)
        try:
            t0 = time.monotonic()
            seen = _handshake(bus, 0x200D)
            assert seen[0] == 1 and seen[-1] == 0 and len(seen) > 2, seen
            assert time.monotonic() - t0 >= 0.3
            seen = _handshake(bus, 0x200E)
            assert seen[0] == 1 and seen[-1] == 0, seen
        finally:
            bus.shutdown()


# ---- rows the audit saw exercised only on a SimClock: now through the transport ------------

def test_table_8_40_store_set_survives_a_power_cycle_and_the_rest_reverts():
    stored = [(0x2000, 0, 0, 1), (0x2001, 3, 25, 4), (0x2001, 2, 12, 4), (0x2001, 4, 7, 4), (0x2001, 5, 2000, 4),
              (0x2004, 2, 1200, 2), (0x2004, 3, 300, 2), (0x2004, 4, 800, 2), (0x2005, 0, 5, 1),
              (0x2006, 0, 1, 1), (0x200B, 0, 6, 1), (0x607C, 0, 77, 4), (0x607E, 0, 0x40, 1), (0x6086, 0, 1, 2)]
    volatile = [(0x6081, 0, 5000, 4, 1000), (0x6082, 0, 50, 4, 100), (0x6083, 0, 50, 4, 300),
                (0x6084, 0, 60, 4, 300), (0x6098, 0, 17, 1, 35), (0x6099, 1, 3000, 4, 1000),
                (0x6099, 2, 300, 4, 100), (0x609A, 0, 40, 4, 300), (0x607A, 0, 1234, 4, 0), (0x2007, 0, 1, 1, 0)]
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        bus = _bus(bench)
        try:
            for index, sub, value, size in stored:
                _ok(bus, index, sub, value, size)
            for index, sub, value, size, _default in volatile:
                _ok(bus, index, sub, value, size)
            _handshake(bus, 0x200E)
            _drain(bus)
            _nmt(bus, 0x81, NODE)
            assert _boot_up(bus, NODE) == b"\x00"
            for index, sub, value, _size in stored:
                assert _read(bus, index, sub) == value, f"{index:04X}h:{sub:02X}"
            for index, sub, _value, _size, default in volatile:
                assert _read(bus, index, sub) == default, f"{index:04X}h:{sub:02X}"
            # Boot states in effect: outputs per 2005h = 5 (2000h = 0: DO1/DO3 are plain outputs),
            # the motor powered per 2006h = 1: run/idle current flows (2004h:01 = idle 300 mA).
            assert _read(bus, 0x60FE) == 5 << 16
            assert _read(bus, 0x2004, 1) == 300
        finally:
            bus.shutdown()


def test_profile_velocity_polarity_inputs_latch_and_delta_through_the_transport():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        sim = bench.sims[(KIND, str(NODE))]
        bus = _bus(bench)
        try:
            _ok(bus, 0x2004, 2, 1300, 2)
            for index, value in ((0x6083, 10), (0x6084, 10)):
                _ok(bus, index, 0, value, 4)
            _enable(bus, 3)
            _ok(bus, 0x60FF, 0, 4000, 4)
            deadline = time.monotonic() + 3
            while _read(bus, 0x606C, signed=True) != 4000:
                assert time.monotonic() < deadline
                time.sleep(0.01)
            sw = _state(bus)
            assert sw & 0x0400 and not sw & 0x1000                      # reached, speed not zero
            assert _read(bus, 0x2004, 1) == 1300                        # run current while moving
            assert _read(bus, 0x2003) == 5                              # StepNLoop: jogging
            # Latch on DI2 (2007h arms, 2008h 1 -> 2, 2009h:02 the encoder there).
            _ok(bus, 0x2007, 0, 1, 1)
            assert _read(bus, 0x2008) == 1
            sim.set_input(2, True)
            at = sim.encoder_position
            assert _read(bus, 0x2008) == 2
            latched = _read(bus, 0x2009, 2, signed=True)
            assert 0 < latched <= at
            # 2009h:01 the pulse counter at the same instant (in counts too while StepNLoop is on).
            assert abs(_read(bus, 0x2009, 1, signed=True) - latched) <= 2
            assert _read(bus, 0x60FD) & (1 << 17)                       # DI2 = 60FDh bit 17
            sim.set_input(2, False)
            # A new 60FFh in the same direction changes the speed on the fly: no stop on the way.
            _ok(bus, 0x60FF, 0, 6000, 4)
            deadline = time.monotonic() + 3
            while (v := _read(bus, 0x606C, signed=True)) != 6000:
                assert v >= 4000 and time.monotonic() < deadline, v
                time.sleep(0.005)
            _ok(bus, 0x60FF, 0, 4000, 4)
            while (v := _read(bus, 0x606C, signed=True)) != 4000:
                assert v >= 4000 and time.monotonic() < deadline, v
                time.sleep(0.005)
            # Velocity polarity (607Eh bit 6): the same motion shown negative.
            _ok(bus, 0x607E, 0, 0x40, 1)
            assert _read(bus, 0x606C, signed=True) == -4000
            _ok(bus, 0x607E, 0, 0x00, 1)
            # Halt decelerates to a stop; the drive reports speed zero.
            _ok(bus, 0x6040, 0, 0x10F, 2)
            deadline = time.monotonic() + 3
            while _read(bus, 0x606C, signed=True) != 0:
                assert time.monotonic() < deadline
                time.sleep(0.01)
            assert _state(bus) & 0x1400 == 0x1400
            pos = _read(bus, 0x6064, signed=True)
            _ok(bus, 0x607E, 0, 0x80, 1)                                # position polarity
            assert _read(bus, 0x6064, signed=True) == -pos
            _ok(bus, 0x607E, 0, 0x00, 1)
            # Inputs: a forced + limit is 60FDh bit 1, a home switch bit 2.
            sim.force_limit(1, True)
            sim.force_home(True)
            assert _read(bus, 0x60FD) & 0b110 == 0b110
            sim.force_limit(1, None)
            sim.force_home(None)
            assert _read(bus, 0x60FD) & 0b111 == 0
            # A push on the shaft at rest beyond the error range (2001h:05 = 1000 counts): 2002h
            # shows pulses minus encoder, 2003h the range error, and the drive is in Fault.
            sim.disturb(1000)                                           # 1000 steps = 1250 counts
            assert _read(bus, 0x2002, signed=True) == -1250
            assert _read(bus, 0x2003) == 8
            assert _state(bus) & 0x4F == 0x08 and _read(bus, 0x1001) == 1
        finally:
            bus.shutdown()


def test_state_machine_motor_power_quick_stop_and_set_points_through_the_transport():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        sim = bench.sims[(KIND, str(NODE))]
        bus = _bus(bench)
        try:
            for index, value in ((0x6081, 20000), (0x6082, 100), (0x6083, 20), (0x6084, 20)):
                _ok(bus, index, 0, value, 4)
            _ok(bus, 0x6060, 0, 1, 1)
            assert _state(bus) & 0x4F == 0x40
            _ok(bus, 0x6040, 0, 0x06, 2)                                # Shutdown
            assert _state(bus) & 0x6F == 0x21 and _read(bus, 0x2004, 1) == 0   # motor unpowered
            _ok(bus, 0x6040, 0, 0x07, 2)                                # T1: motor powered
            assert _state(bus) & 0x6F == 0x23 and _read(bus, 0x2004, 1) > 0
            _ok(bus, 0x6040, 0, 0x06, 2)                                # T2
            assert _state(bus) & 0x6F == 0x21 and _read(bus, 0x2004, 1) == 0
            _ok(bus, 0x6040, 0, 0x07, 2)
            _ok(bus, 0x6040, 0, 0x0F, 2)                                # T3
            assert _state(bus) & 0x6F == 0x27 and _read(bus, 0x6061) == 1
            # A move, then a buffered one (bit 5) and a single one (refused: not acknowledged).
            _ok(bus, 0x607A, 0, 4000, 4)
            _ok(bus, 0x6040, 0, 0x1F, 2)
            assert _state(bus) & 0x1000                                 # set-point acknowledged
            _ok(bus, 0x6040, 0, 0x0F, 2)
            _ok(bus, 0x607A, 0, 1000, 4)
            _ok(bus, 0x6040, 0, 0x5F, 2)                                # relative, single: moving -> refused
            assert not _state(bus) & 0x1000
            _ok(bus, 0x6040, 0, 0x0F, 2)
            _ok(bus, 0x6040, 0, 0x7F, 2)                                # relative, set of set-points
            assert _state(bus) & 0x1000
            _ok(bus, 0x6040, 0, 0x0F, 2)
            deadline = time.monotonic() + 5
            while not (_state(bus) & 0x0400 and _read(bus, 0x6064, signed=True) == 5000):
                assert time.monotonic() < deadline, _read(bus, 0x6064, signed=True)
                time.sleep(0.01)
            # Quick stop while moving: immediate stop, Switch on disabled, motor unpowered.
            _ok(bus, 0x607A, 0, 60000, 4)
            _ok(bus, 0x6040, 0, 0x1F, 2)
            time.sleep(0.1)
            _ok(bus, 0x6040, 0, 0x02, 2)
            assert _state(bus) & 0x4F == 0x40
            assert _read(bus, 0x606C, signed=True) == 0 and not sim.busy
            assert _read(bus, 0x2004, 1) == 0
            # T4 / T5 / T6 from Operation enabled and Switched on.
            _enable(bus, 1)
            _ok(bus, 0x6040, 0, 0x07, 2)                                # T4
            assert _state(bus) & 0x6F == 0x23
            _ok(bus, 0x6040, 0, 0x0F, 2)
            _ok(bus, 0x6040, 0, 0x06, 2)                                # T5
            assert _state(bus) & 0x6F == 0x21
            _ok(bus, 0x6040, 0, 0x07, 2)
            _ok(bus, 0x6040, 0, 0x00, 2)                                # T6: disable voltage
            assert _state(bus) & 0x4F == 0x40 and _read(bus, 0x2004, 1) == 0
        finally:
            bus.shutdown()


def _ramp_slope(bus, low: float, high: float, timeout: float) -> float:
    """counts/s per s between the first samples of 606Ch above `low` and above `high`."""
    t_low = v_low = None
    deadline = time.monotonic() + timeout
    while True:
        t0 = time.monotonic()
        v = _read(bus, 0x606C, signed=True)
        t = (t0 + time.monotonic()) / 2
        if t_low is None and v > low:
            t_low, v_low = t, v
        elif t_low is not None and v > high:
            return (v - v_low) / (t - t_low)
        assert t < deadline, v
        time.sleep(0.01)


@pytest.mark.parametrize("acc_ms, speed, low_speed, window, slope", [
    (1000, 20000, 100, (3000, 15000), 19900.0),
    (30000, 20000, 100, (400, 1300), 1000.0),              # E-A12: 20 000 / 100 -> 19 900 ms
    (30000, 900000, 1000, (20000, 80000), 899000 / 23.05),  # E-A12: 900 000 / 1000 -> 23 050 ms
])
def test_acceleration_is_a_time_clamped_by_appendix_a(acc_ms, speed, low_speed, window, slope):
    # 6082h 100 -> 6081h/60FFh 20000 counts/s in 6083h ms: 1 s gives 19 900 counts/s per s; 30 000 ms
    # exceeds Table A.0's maximum for HSPD 20 000 (delta 1000 -> 19 900 ms): the write is kept and
    # the move ramps in 19 900 ms, 1000 counts/s per s (unclamped it would be 663).
    with SimBench([f"{KIND}:{NODE}"], sim_options={KIND: {"plus_limit": 4e6}}) as bench:
        bus = _bus(bench)
        try:
            _ok(bus, 0x6083, 0, acc_ms, 4)
            _ok(bus, 0x6082, 0, low_speed, 4)
            assert _read(bus, 0x6083) == acc_ms                         # the value is kept
            _enable(bus, 3)
            _ok(bus, 0x60FF, 0, speed, 4)
            assert _ramp_slope(bus, *window, 5) == pytest.approx(slope, rel=0.1)
            _ok(bus, 0x6040, 0, 0x02, 2)                                # quick stop
        finally:
            bus.shutdown()


def test_end_velocity_is_the_start_and_stop_speed_of_a_move():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        bus = _bus(bench)
        try:
            for index, value in ((0x6081, 6000), (0x6082, 3000), (0x6083, 300), (0x6084, 300)):
                _ok(bus, index, 0, value, 4)
            _enable(bus, 1)
            _ok(bus, 0x607A, 0, 3000, 4)
            _ok(bus, 0x6040, 0, 0x1F, 2)
            seen = []
            deadline = time.monotonic() + 5
            while not (_state(bus) & 0x0400 and _read(bus, 0x6064, signed=True) == 3000):
                seen.append(_read(bus, 0x606C, signed=True))
                assert time.monotonic() < deadline
            moving = [v for v in seen if v]
            assert moving and min(moving) >= 3000 and max(moving) <= 6000, (min(moving), max(moving))
        finally:
            bus.shutdown()


def test_a_mode_written_while_moving_takes_over_once_idle_and_homing_35():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        sim = bench.sims[(KIND, str(NODE))]
        bus = _bus(bench)
        try:
            for index, value in ((0x6081, 8000), (0x6083, 20), (0x6084, 20)):
                _ok(bus, index, 0, value, 4)
            _enable(bus, 1)
            _ok(bus, 0x607A, 0, 4000, 4)
            _ok(bus, 0x6040, 0, 0x1F, 2)
            _ok(bus, 0x6060, 0, 6, 1)                                   # homing, while moving
            assert _read(bus, 0x6061) == 1
            deadline = time.monotonic() + 5
            while _read(bus, 0x6061) != 6:
                assert time.monotonic() < deadline
                time.sleep(0.01)
            assert _read(bus, 0x6064, signed=True) == 4000
            # Method 35: this position is home, no motion.
            at = sim.physical_position
            _ok(bus, 0x6098, 0, 35, 1)
            _ok(bus, 0x6040, 0, 0x0F, 2)
            _ok(bus, 0x6040, 0, 0x1F, 2)
            assert _state(bus) & 0x3400 == 0x1400
            assert _read(bus, 0x6064, signed=True) == 0 and sim.physical_position == at
        finally:
            bus.shutdown()


def test_stepnloop_off_positions_are_pulses():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        sim = bench.sims[(KIND, str(NODE))]
        bus = _bus(bench)
        try:
            _ok(bus, 0x2001, 1, 0, 4)                                   # StepNLoop off
            assert _read(bus, 0x2003) == 12                             # N/A
            for index, value in ((0x6081, 8000), (0x6083, 20), (0x6084, 20)):
                _ok(bus, index, 0, value, 4)
            _enable(bus, 1)
            _ok(bus, 0x607A, 0, 3200, 4)                                # 3200 pulses = one revolution
            _ok(bus, 0x6040, 0, 0x1F, 2)
            deadline = time.monotonic() + 5
            while _read(bus, 0x6064, signed=True) != 3200:
                assert time.monotonic() < deadline
                time.sleep(0.01)
            assert sim.physical_position == pytest.approx(3200, abs=1)
        finally:
            bus.shutdown()


@pytest.mark.parametrize("profile_type", [0, 1])
def test_motion_profile_type_shapes_the_ramp(profile_type):
    # 100 -> 20000 counts/s in 1000 ms.  Trapezoid: 2000 is reached at 0.10 s, 10000 at 0.50 s (ratio
    # 0.19); S-curve (6086h = 1, SCV): the ramp starts gently, 2000 at ~0.22 s of ~0.50 s (ratio ~0.44).
    with SimBench([f"{KIND}:{NODE}"], sim_options={KIND: {"plus_limit": 4e6}}) as bench:
        bus = _bus(bench)
        try:
            _ok(bus, 0x6086, 0, profile_type, 2)
            _ok(bus, 0x6083, 0, 1000, 4)
            _enable(bus, 3)
            t0 = time.monotonic()
            _ok(bus, 0x60FF, 0, 20000, 4)
            t1 = t2 = None
            while t2 is None:
                v = _read(bus, 0x606C, signed=True)
                t = time.monotonic()
                if t1 is None and v > 2000:
                    t1 = t
                if v > 10000:
                    t2 = t
                assert t - t0 < 5, v
            ratio = (t1 - t0) / (t2 - t0)
            assert (ratio > 0.32) if profile_type else (ratio < 0.28), ratio
            _ok(bus, 0x6040, 0, 0x02, 2)
        finally:
            bus.shutdown()


def test_idle_current_after_the_idle_time():
    with SimBench([f"{KIND}:{NODE}"]) as bench:
        bus = _bus(bench)
        try:
            _ok(bus, 0x2004, 2, 1400, 2)                                # run
            _ok(bus, 0x2004, 3, 400, 2)                                 # idle
            _ok(bus, 0x2004, 4, 1500, 2)                                # idle time, ms
            for index, value in ((0x6081, 8000), (0x6083, 20), (0x6084, 20)):
                _ok(bus, index, 0, value, 4)
            _enable(bus, 1)
            _ok(bus, 0x607A, 0, 800, 4)
            _ok(bus, 0x6040, 0, 0x1F, 2)
            deadline = time.monotonic() + 5
            while not _state(bus) & 0x0400 or _read(bus, 0x606C, signed=True) != 0:
                assert time.monotonic() < deadline
            stopped = time.monotonic()
            assert _read(bus, 0x2004, 1) == 1400                        # still the run current
            while _read(bus, 0x2004, 1) != 400:
                assert time.monotonic() < deadline + 5
                time.sleep(0.02)
            assert time.monotonic() - stopped >= 1.4
        finally:
            bus.shutdown()

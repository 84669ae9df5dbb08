"""Issue 23 items 15 and 16 (UNITEK), with python-can as the independent client of a
socketcand-served simulator: the EEPROM store keeps every writable register (B-U13),
the +/- 9-bit current command and "the smaller of the motor and device limit applies"
(§6.1, B-U17), and the bit-timing table (§3.1, B-U21): a node whose BTR's bit rate
differs from the bus's hears and sends nothing."""
from __future__ import annotations

import time

import can
import pytest

import motorbus
from motorbus import _core
from motorbus.drives.unitek import Reg, Status, Unitek, make_sim
from motorbus.sim import SimBench

pytestmark = pytest.mark.threaded

RX, TX = 0x201, 0x181


def peer_of(b) -> can.BusABC:
    srv = b.can.servers[0]
    return can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")


def send(bus, data, arb_id=RX) -> None:
    bus.send(can.Message(arbitration_id=arb_id, data=bytes(data), is_extended_id=False))


def settle(sim, n, timeout=2.0) -> None:
    """Writes are never acknowledged: wait until the sim has taken n frames."""
    end = time.monotonic() + timeout
    while sim.counters.frames_in < n:
        assert time.monotonic() < end, f"the sim took {sim.counters.frames_in} of {n} frames"
        time.sleep(0.002)


def frames(bus, wait=0.25, arb_id=TX) -> list[bytes]:
    out, end = [], time.monotonic() + wait
    while time.monotonic() < end:
        m = bus.recv(0.02)
        if m is not None and m.arbitration_id == arb_id:
            out.append(bytes(m.data))
    return out


def read(bus, regid: int, signed: bool = False, timeout: float = 2.0) -> int:
    """`3D regid 00` -> the value of the reply `regid v0 v1 dummy` (or the 32-bit one)."""
    while bus.recv(0) is not None:  # drop anything older
        pass
    send(bus, [0x3D, regid, 0x00])
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        m = bus.recv(0.05)
        if m is None or m.arbitration_id != TX or m.data[0] != regid:
            continue
        assert m.dlc in (4, 6)
        return int.from_bytes(m.data[1:m.dlc - 1], "little", signed=signed)
    raise AssertionError(f"no reply for REGID 0x{regid:02X}")


def le16(v: int) -> list[int]:
    return list((v & 0xFFFF).to_bytes(2, "little"))


@pytest.fixture()
def bench():
    with SimBench(["unitek:0x201"]) as b:
        peer = peer_of(b)
        try:
            yield b.sims[("unitek", "0x201")], peer
        finally:
            peer.shutdown()


# ---- item 15: the EEPROM keeps every writable register -----------------------------------

WRITES = [  # (REGID, value, signed): the manual's writable registers with a readable value
    (0x35, 500, False),        # ACC ramp (ex 6)
    (0x52, 0x0012, False),     # event mask: the limit switches (ex 10-1)
    (0x31, 3277, True),        # SPEED_CMD 10 % (ex 3)
    (0x90, 16380, True),       # TORQUE_CMD 50 % (ex 5)
]


@pytest.mark.parametrize("level", [0, 1])
def test_eeprom_store_keeps_every_writable_register(bench, level):
    sim, peer = bench
    n = 0
    send(peer, [0x51, 0x14, 0x00])                 # MODE: disable + status events
    for regid, v, _ in WRITES:
        send(peer, [regid, *le16(v)])
    send(peer, [0x6E, *(3000000).to_bytes(4, "little")])   # POS_DEST, DLC 5 (ex 4)
    send(peer, [0x68, 0x10, 0x02])                 # CAN-ID-Rx 0x210 (ex 1), effective at once
    n += 3 + len(WRITES)
    settle(sim, n)
    send(peer, [0x84, level, 0x00], arb_id=0x210)  # write EEPROM (ex 7)
    n += 1
    settle(sim, n)
    assert sim.counters.refused == 0 and sim.counters.unknown == 0
    # RAM changes after the store must not survive the power cycle.
    for regid, v, _ in WRITES:
        send(peer, [regid, *le16(v + 1)], arb_id=0x210)
    send(peer, [0x51, 0x00, 0x00], arb_id=0x210)
    n += len(WRITES) + 1
    settle(sim, n)
    assert sim.status & Status.ENA

    sim.power_cycle()
    assert sim.rx_id == 0x210
    assert frames(peer, 0.1) == []                 # no event at power-up
    for regid, v, signed in WRITES:
        send(peer, [0x3D, regid, 0x00], arb_id=0x210)
        m = [f for f in frames(peer, 0.3) if f[0] == regid]
        assert m, f"no reply for 0x{regid:02X}"
        assert int.from_bytes(m[0][1:3], "little", signed=signed) == v, f"REGID 0x{regid:02X}"
    send(peer, [0x3D, 0x6E, 0x00], arb_id=0x210)
    pos = [f for f in frames(peer, 0.3) if f[0] == 0x6E]
    assert pos and pos[0] == bytes([0x6E, 0xC0, 0xC6, 0x2D, 0x00, 0x00])
    # MODE came back too: the drive is disabled (bit 2) ...
    send(peer, [0x3D, 0x40, 0x00], arb_id=0x210)
    st = [f for f in frames(peer, 0.3) if f[0] == 0x40]
    assert st and int.from_bytes(st[0][1:3], "little") & Status.ENA == 0
    # ... and KERN_STATUS events (bit 4) are on with the stored mask 0x0012 (limits):
    sim.force_limit(+1, True)
    ev = frames(peer, 0.3)
    assert len(ev) == 1 and len(ev[0]) == 6 and ev[0][0] == 0x40
    assert int.from_bytes(ev[0][1:5], "little") & Status.LIM_PLUS
    # Stored set-points read back but start nothing at power-up.
    assert sim.speed_num == 0


def test_eeprom_store_keeps_the_current_registers_too(bench):
    sim, peer = bench
    send(peer, [0x24, *le16(100)])                 # I_MAX (NDrive list)
    send(peer, [0x26, *le16(-77)])                 # I_CMD (NDrive list)
    send(peer, [0x84, 0x00, 0x00])
    send(peer, [0x24, *le16(50)])
    send(peer, [0x26, *le16(5)])
    settle(sim, 5)
    sim.power_cycle()
    assert read(peer, 0x24) == 100
    assert read(peer, 0x26, signed=True) == -77
    assert read(peer, 0x20, signed=True) == -77    # within both limits


def test_a_power_cycle_without_a_store_keeps_the_factory_values(bench):
    sim, peer = bench
    send(peer, [0x35, 0xF4, 0x01])
    send(peer, [0x24, 0x64, 0x00])
    settle(sim, 2)
    sim.power_cycle()
    assert read(peer, 0x35) == 1000     # the factory ACC ramp (sim option acc_ramp_ms)
    assert read(peer, 0x24) == 160      # I_MAX: the DS 205/405's peak current


# ---- item 16: the +/- 9-bit current command; the smaller limit applies --------------------

def test_current_command_range_and_the_smaller_of_motor_and_device_limit(bench):
    sim, peer = bench
    assert read(peer, 0xC4) == 160                 # DS 205/405: max 160 num = 10 A
    send(peer, [0x26, *le16(511)])                 # +9 bit: the largest command
    settle(sim, 1)
    assert read(peer, 0x26, signed=True) == 511
    assert read(peer, 0x20, signed=True) == 160    # the device limit (motor limit = device's)
    send(peer, [0x26, *le16(512)])                 # beyond 9 bit: ignored, never acknowledged
    send(peer, [0x26, *le16(-512)])
    settle(sim, 6)                                 # 3 reads + 3 writes so far
    assert sim.counters.refused == 2
    assert read(peer, 0x26, signed=True) == 511
    send(peer, [0x24, *le16(100)])                 # motor limit 100 num < device 160
    send(peer, [0x26, *le16(-300)])
    assert read(peer, 0x20, signed=True) == -100
    send(peer, [0x24, *le16(300)])                 # motor 300 > device 160: the device's applies
    assert read(peer, 0x20, signed=True) == -160
    send(peer, [0x26, *le16(44)])                  # within both: delivered as commanded
    assert read(peer, 0x20, signed=True) == 44
    send(peer, [0x51, 0x04, 0x00])                 # disabled: no current
    assert read(peer, 0x20, signed=True) == 0


@pytest.mark.parametrize("device, peak", [("DS 412", 230), ("DS 420", 200)])
def test_device_rows_of_the_current_table(device, peak):
    with SimBench(["unitek:0x201"], sim_options={"unitek": {"device": device}}) as b:
        sim, peer = b.sims[("unitek", "0x201")], peer_of(b)
        try:
            assert read(peer, 0xC4) == peak
            send(peer, [0x26, *le16(-511)])
            assert read(peer, 0x20, signed=True) == -peak
            send(peer, [0x24, *le16(peak - 1)])
            assert read(peer, 0x20, signed=True) == -(peak - 1)
        finally:
            peer.shutdown()
    assert _core.unitek.effective_current_limit_num(device, 999) == peak
    assert _core.unitek.effective_current_limit_num(device, 12) == 12
    with pytest.raises(_core.InvalidArgument, match="DS 420"):
        _core.unitek.effective_current_limit_num("DS 999", 1)


def test_client_refuses_a_current_command_beyond_9_bit_before_sending():
    with SimBench(["unitek:0x201"]) as b:
        srv = b.can.servers[0]
        sim = b.sims[("unitek", "0x201")]
        with motorbus.open_bus(f"socketcand:{srv.host}:{srv.port}/can0") as bus, Unitek(bus, RX) as d:
            with pytest.raises(_core.InvalidArgument, match="I_CMD"):
                d.write(Reg.I_CMD, 512)
            assert sim.counters.frames_in == 0                    # refused before sending
            d.write(Reg.I_CMD, -511)
            assert d.read(Reg.I_CMD) == -511
            assert d.read(Reg.I_ACT) == -160
            assert d.read_physical(Reg.I_ACT) == pytest.approx(-10.0)  # 160 num = 10 A (DS 205/405)


# ---- item 16: the analog command, 10 V = 29490 num ----------------------------------------

def test_analog_command_10_volts_is_29490_num_and_90_percent_of_n_max():
    opts = {"unitek": {"analog_command": 1, "acc_ramp_ms": 0}}
    with SimBench(["unitek:0x201"], sim_options=opts) as b:
        sim, peer = b.sims[("unitek", "0x201")], peer_of(b)
        try:
            for volts, num in ((10.0, 29490), (-10.0, -29490), (5.0, 14745), (0.0, 0)):
                sim.set_analog_input(1, volts)
                assert read(peer, 0xD5, signed=True) == num          # AIN1
                end = time.monotonic() + 2
                while read(peer, 0x30, signed=True) != num:          # SPEED_IST follows AIN1
                    assert time.monotonic() < end, (volts, num)
            sim.set_analog_input(2, 3.0)                             # AIN2 reads, commands nothing here
            assert read(peer, 0xD6, signed=True) == 8847
            assert read(peer, 0x30, signed=True) == 0
            with pytest.raises(_core.InvalidArgument, match="10 V"):
                sim.set_analog_input(1, 10.5)
        finally:
            peer.shutdown()
    assert _core.unitek.analog_command_num(10.0) == 29490
    # 29490 of 32767 is 90 % of N max: 2700 rpm on a 3000 rpm drive.
    assert _core.unitek.Scalings(n_max_rpm=3000).to_physical(_core.unitek.sim_default_table()[0xD5], 29490) \
        == pytest.approx(2700, abs=0.1)


# ---- item 16: the bit-timing table --------------------------------------------------------

def test_bit_timing_table():
    rows = [(r["kbit_s"], r["btr"], r["max_line_m"]) for r in _core.unitek.bit_timings()]
    assert rows == [(1000, 0x4002, 20), (500, 0x4025, 70), (625, 0x4014, 70), (250, 0x405C, 100),
                    (100, 0x4425, 500)]
    assert _core.unitek.btr_for_bit_rate(250000) == 0x405C
    assert _core.unitek.bit_rate_for_btr(0x4014) == 625000       # C-U08: 625, not "615"
    with pytest.raises(_core.InvalidArgument, match="0x4026.*0x4025"):
        _core.unitek.bit_rate_for_btr(0x4026)
    with pytest.raises(_core.InvalidArgument, match="btr|BTR"):
        make_sim("0x201", btr=0x1234)
    assert make_sim("0x201").bit_rate == 500000                  # the UNITEK standard (§4.1)


def test_a_node_at_another_bit_rate_is_silent_and_deaf():
    # The bus runs at 250 kbit/s; the drive's BTR is the factory 0x4025 (500 k).
    with SimBench(["unitek:0x201"], bitrate=250000) as b:
        sim, peer = b.sims[("unitek", "0x201")], peer_of(b)
        try:
            send(peer, [0x3D, 0x40, 0x00])
            send(peer, [0x35, 0xF4, 0x01])
            assert frames(peer, 0.4) == []
            assert sim.bus_bit_rate == 250000
            end = time.monotonic() + 2
            while sim.counters.bit_rate_mismatch < 2:
                assert time.monotonic() < end
                time.sleep(0.005)
            assert sim.counters.frames_in == 0 and sim.value(Reg.ACC_RAMP) == 1000
        finally:
            peer.shutdown()
    # The same bus with the drive set to 0x405C (250 k) in NDrive: it answers.
    with SimBench(["unitek:0x201"], bitrate=250000, sim_options={"unitek": {"btr": 0x405C}}) as b:
        sim, peer = b.sims[("unitek", "0x201")], peer_of(b)
        try:
            send(peer, [0x3D, 0x40, 0x00])
            assert frames(peer, 0.4) == [bytes([0x40, 0x81, 0x01, 0x00])]
            assert sim.counters.bit_rate_mismatch == 0
        finally:
            peer.shutdown()


def test_python_api_of_the_tables():
    from motorbus.drives import unitek

    assert unitek.BIT_TIMINGS[1] == (500, 0x4025, 70)
    assert unitek.btr_for_bit_rate(1_000_000) == 0x4002
    assert unitek.bit_rate_for_btr(0x4425) == 100_000
    assert unitek.current_limit_num("DS 412", 300) == 230
    assert unitek.CURRENT_COMMAND_MAX == 511
    with pytest.raises(_core.InvalidArgument, match="0x4002"):
        unitek.btr_for_bit_rate(615_000)

"""HOSTILE_INPUTS.md §2.10 (R1-R4) against the UNITEK simulator and client, with
python-can as the peer that sends the hostile frames over socketcand."""
from __future__ import annotations

import time

import can
import pytest

import motorbus
from motorbus.drives import unitek
from motorbus.drives.unitek import Reg, Status, Unitek
from motorbus.sim import SimBench

pytestmark = pytest.mark.threaded


@pytest.fixture()
def bench():
    with SimBench(["unitek:0x201"]) as b:
        srv = b.can.servers[0]
        peer = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        try:
            yield b.sims[("unitek", "0x201")], peer, f"socketcand:{srv.host}:{srv.port}/can0"
        finally:
            peer.shutdown()


def send(bus, arb_id, data) -> None:
    bus.send(can.Message(arbitration_id=arb_id, data=bytes(data), is_extended_id=False))


def frames_on(bus, arb_id, wait=0.25) -> list:
    out, end = [], time.monotonic() + wait
    while time.monotonic() < end:
        m = bus.recv(0.02)
        if m is not None and m.arbitration_id == arb_id:
            out.append(bytes(m.data))
    return out


def settle(sim, n, timeout=2.0) -> None:
    end = time.monotonic() + timeout
    while sim.counters.frames_in < n:
        assert time.monotonic() < end
        time.sleep(0.002)


def test_r1_dlc_to_the_drive(bench):
    sim, peer, _ = bench
    for n in range(3):                                   # DLC 0-2: ignored
        send(peer, 0x201, [0x3D, 0x40][:n])
    settle(sim, 3)
    assert sim.counters.malformed == 3
    assert frames_on(peer, 0x181) == []
    send(peer, 0x201, [0x3D, 0x40, 0x00, 0xEE])          # DLC 4: evaluated as 3
    assert frames_on(peer, 0x181) == [bytes([0x40, 0x81, 0x01, 0x00])]
    send(peer, 0x201, [0x35, 0xE8, 0x03, 0xAA])           # DLC 4 write: byte 3 ignored
    send(peer, 0x201, [0x6E, 0xC0, 0xC6, 0x2D, 0x00, 1, 2, 3])   # DLC 8: evaluated as 5
    settle(sim, 6)
    assert sim.value(Reg.ACC_RAMP) == 1000 and sim.value(Reg.POS_DEST) == 3_000_000
    send(peer, 0x201, [0x35, 0x10, 0x00, 0x77, 0x77])     # 16-bit register, DLC 5: low 16 bits
    settle(sim, 7)
    assert sim.value(Reg.ACC_RAMP) == 0x10


def test_r1_wrong_dlc_from_the_drive_rejected_and_counted(bench):
    sim, peer, where = bench
    with motorbus.open_bus(where) as bus:
        d = Unitek(bus, 0x201, timeout=0.3)
        for data in ([0x40, 0x81, 0x01], [0x40, 0x81, 0x01, 0, 0], [0x40] * 7, [0x40] * 8, []):
            send(peer, 0x181, data)
        end = time.monotonic() + 2
        while d.counters.rejected < 5:
            assert time.monotonic() < end
            time.sleep(0.002)
        assert d.read(Reg.KERN_STATUS) == 0x0181         # and the next real reply still works
        d.close()
    with pytest.raises(unitek.FrameError) as e:
        motorbus._core.unitek.decode_from_drive(bytes([0x40, 0x81, 0x01]))
    assert e.value.byte == 3


def test_r2_unknown_register(bench, tmp_path):
    sim, peer, where = bench
    send(peer, 0x201, [0x3D, 0x99, 0x00])                # read: no reply (no NACK exists)
    send(peer, 0x201, [0x99, 0x01, 0x00])                # write: ignored
    settle(sim, 2)
    assert frames_on(peer, 0x181) == [] and sim.counters.unknown == 2
    with motorbus.open_bus(where) as bus:
        d = Unitek(bus, 0x201, timeout=0.2)
        before = bus.counters.tx_frames
        with pytest.raises(unitek.UnknownRegister):
            d.write(0x99, 1)                              # refused before sending
        with pytest.raises(unitek.UnknownRegister):
            d.read(0x99)
        assert bus.counters.tx_frames == before
        f = tmp_path / "extra.toml"
        f.write_text('[[register]]\nregid = 0x99\nname = "EXTRA"\n')
        extended = Unitek(bus, 0x201, timeout=0.2, registers=f)
        extended.write(0x99, 1)                           # a user-extended table can
        with pytest.raises(motorbus.TimeoutError):
            extended.read("EXTRA")                        # and this sim does not know it: no reply
        extended.close()
        d.close()


def test_r3_range_and_read_only(bench):
    sim, peer, where = bench
    with motorbus.open_bus(where) as bus:
        d = Unitek(bus, 0x201)
        before = bus.counters.tx_frames
        for reg, value in ((Reg.SPEED_CMD, 32768), (Reg.CAN_ID_RX, 0x280), (Reg.EEPROM_WRITE, 2),
                           (Reg.SPEED_IST, 5), (Reg.KERN_STATUS, 0)):
            with pytest.raises(motorbus.InvalidArgument):
                d.write(reg, value)
        assert bus.counters.tx_frames == before
        d.close()
    send(peer, 0x201, [0x68, 0x00, 0x03])                # rx id 0x300: out of range
    send(peer, 0x201, [0x30, 0x01, 0x00])                # read-only
    send(peer, 0x201, [0x84, 0x02, 0x00])                # EEPROM level 2
    settle(sim, 3)
    assert sim.counters.refused == 3 and sim.rx_id == 0x201 and sim.eeprom()[0x35] == 1000
    assert frames_on(peer, 0x181) == []


def test_r4_unsolicited_and_foreign_replies_ignored(bench):
    sim, peer, where = bench
    with motorbus.open_bus(where) as bus:
        d = Unitek(bus, 0x201, timeout=0.3)
        send(peer, 0x181, [0x30, 0x10, 0x00, 0x00])       # nobody asked
        send(peer, 0x181, [0x40, 0x85, 0x31, 0, 0, 0])    # an event while events are off
        send(peer, 0x182, [0x40, 0x85, 0x31, 0x00])       # another node's transmit id
        end = time.monotonic() + 2
        while d.counters.unsolicited < 2:
            assert time.monotonic() < end
            time.sleep(0.002)
        assert d.last_event_status is None
        assert d.read(Reg.KERN_STATUS) == 0x0181          # nothing stale answered the read
        assert d.counters.unsolicited == 2
        s = d.subscribe(Reg.SPEED_IST, 50)                # a running cyclic read is used
        end = time.monotonic() + 2
        while s.count < 2:
            assert time.monotonic() < end
            time.sleep(0.005)
        d.set_events(True)
        send(peer, 0x181, [0x40, 0x85, 0x31, 0, 0, 0])    # with events on: taken
        end = time.monotonic() + 2
        while d.last_event_status is None:
            assert time.monotonic() < end
            time.sleep(0.002)
        assert d.last_event_status == Status(0x3185)
        d.close()                                          # stops its stream
    end = time.monotonic() + 2
    while sim.cyclic:
        assert time.monotonic() < end
        time.sleep(0.005)
    time.sleep(0.1)
    while peer.recv(0.02) is not None:                    # what the exchange above left queued
        pass
    send(peer, 0x202, [0x3D, 0x40, 0x00])                 # a request to another drive: not ours
    assert frames_on(peer, 0x181) == []

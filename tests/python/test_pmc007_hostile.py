"""The CANopen rows of HOSTILE_INPUTS.md that apply to the PMC007 simulator, sent as raw
frames on an in-process virtual bus.  After each hostile frame the node must still answer
and its state must be what it was (the "never disturbs the node's state" rule)."""
from __future__ import annotations

import itertools
import time

import pytest

import motorbus
from motorbus import _core
from motorbus.drives import pmc007

pytestmark = pytest.mark.threaded
_names = itertools.count()


class Raw:
    def __init__(self, bus):
        self.bus = bus

    def send(self, cob: int, data: bytes, rtr: bool = False, dlc=None) -> None:
        if rtr:
            self.bus.send(_core.can.Frame(cob, b"", rtr=True, dlc=dlc if dlc is not None else 0))
        else:
            self.bus.send(_core.can.Frame(cob, bytes(data)))

    def reply(self, cob: int = 0x585, timeout: float = 0.3):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            f = self.bus.recv(timeout=0.05)
            if f is not None and f.id == cob:
                return bytes(f.data)
        return None

    def sdo(self, data: bytes, timeout: float = 1.0):
        self.send(0x605, data)
        return self.reply(0x585, timeout)

    def drain(self) -> None:
        while self.bus.recv(timeout=0.02) is not None:
            pass


@pytest.fixture
def raw():
    name = f"virtual:pmc007-hostile-{next(_names)}"
    clock = _core.runtime.SimClock(1_000_000_000)
    with motorbus.open_bus(name) as sim_bus, motorbus.open_bus(name) as host_bus:
        sim = pmc007.make_sim(5, clock=clock, bus=sim_bus)
        r = Raw(host_bus)
        r.drain()
        yield sim, r
        sim.close()


def still_fine(r: Raw) -> None:
    assert r.sdo(bytes.fromhex("40 06 60 00 00 00 00 00")) == bytes.fromhex("4B 06 60 00 90 01 00 00")


@pytest.mark.parametrize("row, request_, reply", [
    ("S1 unknown CCS", "E0 06 60 00 00 00 00 00", "80 06 60 00 01 00 04 05"),
    ("S6 no object", "40 30 60 00 00 00 00 00", "80 30 60 00 00 00 02 06"),
    ("S7 sub of a VAR", "40 06 60 01 00 00 00 00", "80 06 60 01 11 00 09 06"),
    ("S8 write ro", "23 00 10 00 01 00 00 00", "80 00 10 00 02 00 01 06"),
    ("S9 too long", "23 06 60 00 01 00 00 00", "80 06 60 00 12 00 07 06"),
    ("S9 too short", "2F 06 60 00 01 00 00 00", "80 06 60 00 13 00 07 06"),
    ("S10 above 6003h", "23 03 60 00 01 7D 00 00", "80 03 60 00 31 00 09 06"),
    ("S10 2003h 9", "2F 03 20 00 09 00 00 00", "80 03 20 00 31 00 09 06"),
    ("S14 segment with no transfer", "60 00 00 00 00 00 00 00", "80 00 00 00 01 00 04 05"),
    ("B-P05 block upload refused", "A0 08 10 00 7F 00 00 00", "80 08 10 00 01 00 04 05"),
    ("B-P05 block download refused", "C2 06 60 00 02 00 00 00", "80 06 60 00 01 00 04 05"),
    ("B-P33 TPDO type 241", "2F 00 18 02 F1 00 00 00", "80 00 18 02 30 00 09 06"),
    ("P7 unmappable 6004h", "23 00 1A 01 20 00 04 60", "80 00 1A 01 41 00 04 06"),
    ("P7 sub0 > 8", "2F 00 1A 00 09 00 00 00", "80 00 1A 00 42 00 04 06"),  # 06040042 (B-P31)
    ("2007h 0", "2F 07 20 00 00 00 00 00", "80 07 20 00 30 00 09 06"),
    ("6017h bit 0", "2B 17 60 00 E7 64 00 00", "80 17 60 00 30 00 09 06"),
])
def test_sdo_rows_get_the_named_abort_and_change_nothing(raw, row, request_, reply):
    sim, r = raw
    assert r.sdo(bytes.fromhex(request_)) == bytes.fromhex(reply), row
    still_fine(r)


def test_s2_abort_while_idle_gets_no_reply(raw):
    sim, r = raw
    r.send(0x605, bytes.fromhex("80 06 60 00 00 00 04 05"))
    assert r.reply(timeout=0.2) is None
    still_fine(r)


@pytest.mark.parametrize("dlc", [0, 1, 3, 7])
def test_short_sdo_frames_are_ignored(raw, dlc):
    # S4/S5 with the policy of B-P06 [P]: an SDO request whose DLC is not 8 gets no answer
    # (counted), is not applied, and the node answers the next request.
    sim, r = raw
    r.send(0x605, bytes.fromhex("2B 06 60 00 58 02 00 00")[:dlc])
    assert r.reply(timeout=0.2) is None
    still_fine(r)


def test_s17_no_sdo_while_stopped_and_n1_n2_n4_ignored(raw):
    sim, r = raw
    for bad in (b"\x02", b"\x02\x05\x00", b"\x02\x85", b"\x03\x05", b"\xff\x00"):
        r.send(0x000, bad)               # N1 DLC != 2, N2 node-ID 133, N4 unknown CS
    still_fine(r)
    r.send(0x000, b"\x02\x00")           # N3 broadcast stop
    time.sleep(0.05)
    r.drain()
    assert r.sdo(bytes.fromhex("40 06 60 00 00 00 00 00"), timeout=0.3) is None
    r.send(0x000, b"\x80\x05")
    time.sleep(0.05)
    still_fine(r)


def test_p3_rpdo_ignored_before_operational_and_p6_rtr_ignored(raw):
    sim, r = raw
    # RPDO1 maps 600Ch (writable, mappable): position written by PDO only in OPERATIONAL.
    assert r.sdo(bytes.fromhex("2F 00 16 00 01 00 00 00"))[0] == 0x60
    assert r.sdo(bytes.fromhex("23 00 16 01 20 00 0C 60"))[0] == 0x60
    r.send(0x205, (1234).to_bytes(4, "little"))
    time.sleep(0.05)
    assert sim.position == 0                     # pre-operational: ignored
    r.send(0x205, b"", rtr=True, dlc=4)          # P6 RTR: ignored
    r.send(0x000, b"\x01\x05")
    time.sleep(0.05)
    r.send(0x205, (1234).to_bytes(4, "little"))
    deadline = time.monotonic() + 2
    while sim.position != 1234:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    r.send(0x205, b"\x01")                       # P1: shorter than the mapping, not applied
    time.sleep(0.05)
    assert sim.position == 1234


def test_step_rules_busy_ignored_refused_while_released(raw):
    sim, r = raw
    assert r.sdo(bytes.fromhex("23 03 60 00 E8 03 00 00"))[0] == 0x60
    assert r.sdo(bytes.fromhex("23 04 60 00 80 0C 00 00"))[0] == 0x60
    # B-P07: a second step command while busy is acknowledged and ignored.
    assert r.sdo(bytes.fromhex("23 04 60 00 10 27 00 00")) == bytes.fromhex("60 04 60 00 00 00 00 00")
    assert r.sdo(bytes.fromhex("40 04 60 00 00 00 00 00")) == bytes.fromhex("43 04 60 00 80 0C 00 00")
    # B-P20: released -> refused 08000022.
    assert r.sdo(bytes.fromhex("2F 0E 60 00 00 00 00 00"))[0] == 0x60
    assert not sim.busy
    assert r.sdo(bytes.fromhex("23 04 60 00 80 0C 00 00")) == bytes.fromhex("80 04 60 00 22 00 00 08")


def test_emcy_on_a_fault_bit(raw):
    sim, r = raw
    r.drain()
    sim.inject_error(0x10)                       # AOC
    got = r.reply(0x085, timeout=1)
    assert got is not None and got[:2] == (0x2300).to_bytes(2, "little") and got[3] == 0x10


def test_s11_s13_segmented_download_size_and_toggle(raw):
    sim, r = raw
    # S11: segmented initiate for 6006h (2 bytes) announcing 4 bytes -> 06070012 at initiate.
    assert r.sdo(bytes.fromhex("21 06 60 00 04 00 00 00")) == bytes.fromhex("80 06 60 00 12 00 07 06")
    still_fine(r)
    # S13: a segmented download to 1006h (4 bytes) whose first segment has toggle 1 -> 05030000.
    assert r.sdo(bytes.fromhex("21 06 10 00 04 00 00 00")) == bytes.fromhex("60 06 10 00 00 00 00 00")
    assert r.sdo(bytes.fromhex("17 01 02 03 04 00 00 00")) == bytes.fromhex("80 06 10 00 00 00 03 05")
    still_fine(r)
    # Nothing was committed.
    assert r.sdo(bytes.fromhex("40 06 10 00 00 00 00 00")) == bytes.fromhex("43 06 10 00 00 00 00 00")

"""The PMC007 defects of issue 23 (items 6-10, 12-14), each through a real transport: the
simulator is served by socketcand from a SimBench in this process, python-can's socketcand
interface is the client (SDO, NMT, SYNC, frames), and where python-can cannot say it (a
remote frame: its socketcand interface sends every frame as data) a plain TCP socket speaks
socketcand's ASCII protocol.  No motorbus code on the client side; the simulator object is
used only to do what a wire cannot (inject a power-stage error, pull an input, re-power)."""
from __future__ import annotations

import re
import socket
import time

import can
import pytest

from motorbus.sim import SimBench

NODE = 5
SDO_TX, SDO_RX, EMCY, HEARTBEAT = 0x600 + NODE, 0x580 + NODE, 0x080 + NODE, 0x700 + NODE


def frame(text: str) -> bytes:
    return bytes.fromhex(text.replace(" ", ""))


# Frames that arrived while a test waited for an SDO reply: kept for the next look (an
# EMCY sent from inside a write arrives before the write's reply).
_backlog: dict[int, list[can.Message]] = {}


def recv(bus: can.BusABC, timeout: float) -> can.Message | None:
    kept = _backlog.get(id(bus))
    if kept:
        return kept.pop(0)
    return bus.recv(timeout)


def drain(bus: can.BusABC, seconds: float = 0.1) -> list[can.Message]:
    out, deadline = [], time.monotonic() + seconds
    while time.monotonic() < deadline:
        m = recv(bus, 0.02)
        if m is not None:
            out.append(m)
    return out


def exchange(bus: can.BusABC, data: bytes, timeout: float = 2.0) -> bytes | None:
    bus.send(can.Message(arbitration_id=SDO_TX, data=data, is_extended_id=False))
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        m = bus.recv(0.05)
        if m is not None and m.arbitration_id == SDO_RX:
            return bytes(m.data)
        if m is not None:
            _backlog.setdefault(id(bus), []).append(m)
    return None


def download(bus, index: int, sub: int, value: int, size: int) -> bytes:
    cmd = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
    payload = (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little").ljust(4, b"\0")
    reply = exchange(bus, bytes([cmd]) + index.to_bytes(2, "little") + bytes([sub]) + payload)
    assert reply is not None, f"no SDO reply to the write of {index:04X}h:{sub:02X}"
    return reply


def write_ok(bus, index: int, sub: int, value: int, size: int) -> None:
    reply = download(bus, index, sub, value, size)
    assert reply == bytes([0x60]) + index.to_bytes(2, "little") + bytes([sub, 0, 0, 0, 0]), reply.hex(" ")


def write_abort(bus, index: int, sub: int, value: int, size: int) -> int:
    reply = download(bus, index, sub, value, size)
    assert reply[0] == 0x80 and reply[1:4] == index.to_bytes(2, "little") + bytes([sub]), reply.hex(" ")
    return int.from_bytes(reply[4:8], "little")


def read(bus, index: int, sub: int = 0) -> int:
    reply = exchange(bus, bytes([0x40]) + index.to_bytes(2, "little") + bytes([sub, 0, 0, 0, 0]))
    assert reply is not None and reply[0] in (0x4F, 0x4B, 0x43), reply
    size = {0x4F: 1, 0x4B: 2, 0x43: 4}[reply[0]]
    return int.from_bytes(reply[4:4 + size], "little")


def nmt(bus, cs: int, node: int = NODE) -> None:
    bus.send(can.Message(arbitration_id=0x000, data=[cs, node], is_extended_id=False))


def wait_for(bus, cob_id: int, timeout: float = 3.0) -> can.Message | None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        m = recv(bus, 0.05)
        if m is not None and m.arbitration_id == cob_id:
            return m
    return None


class RawSocketcand:
    """socketcand's ASCII protocol on a TCP socket (raw mode): what python-can cannot send."""

    def __init__(self, host: str, port: int) -> None:
        self.sock = socket.create_connection((host, port), timeout=5)
        self.buf = ""
        assert self.element() == "< hi >"
        self.sock.sendall(b"< open can0 >")
        assert self.element() == "< ok >"
        self.sock.sendall(b"< rawmode >")
        assert self.element() == "< ok >"
        time.sleep(0.2)  # the server holds frames briefly after rawmode

    def element(self, timeout: float = 5.0) -> str | None:
        deadline = time.monotonic() + timeout
        while ">" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self.sock.settimeout(left)
            try:
                chunk = self.sock.recv(4096)
            except socket.timeout:
                return None
            if not chunk:
                return None
            self.buf += chunk.decode("ascii")
        end = self.buf.index(">") + 1
        el, self.buf = self.buf[:end].strip(), self.buf[end:]
        return el

    def elements(self, seconds: float) -> list[str]:
        out, deadline = [], time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            el = self.element(left)
            if el is not None:
                out.append(el)
        return out

    def send_rtr(self, cob_id: int, dlc: int) -> None:
        self.sock.sendall(f"< sendrtr {cob_id:03X} {dlc} >".encode())

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def served():
    with SimBench([f"pmc007:{NODE}"], bus=f"virtual:pmc007-audit-{time.monotonic_ns()}") as bench:
        srv = bench.can.servers[0]
        bus = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        drain(bus, 0.3)  # the boot-up may still be on its way: no test should take it for a later one
        try:
            yield bench.sims[("pmc007", str(NODE))], bus, (srv.host, srv.port)
        finally:
            _backlog.pop(id(bus), None)
            bus.shutdown()


def map_tpdo1(bus, cob_id: int, ttype: int, event_ms: int = 0) -> None:
    """TPDO1 maps 6001h (controller status, 8 bits), in the manual's order."""
    write_ok(bus, 0x1800, 1, cob_id, 4)
    write_ok(bus, 0x1800, 2, ttype, 1)
    write_ok(bus, 0x1800, 5, event_ms, 2)
    write_ok(bus, 0x1A00, 0, 1, 1)
    write_ok(bus, 0x1A00, 1, 0x60010008, 4)


# ---- item 6: no answer to a remote frame on a TPDO's COB-ID (B-P35, 003 §4.2) ----------

def test_6_a_tpdo_does_not_answer_a_remote_frame(served):
    sim, bus, (host, port) = served
    map_tpdo1(bus, 0x187, 255)                   # the manual's own COB-ID: bit 30 = 0 ("RTR allowed")
    raw = RawSocketcand(host, port)
    try:
        nmt(bus, 0x01)
        assert wait_for(bus, 0x187) is not None  # the event TPDO on entering OPERATIONAL
        raw.elements(0.3)                        # what the listener saw so far
        raw.send_rtr(0x187, 1)
        seen = raw.elements(0.8)
        listener = RawSocketcand(host, port)
        try:
            listener.elements(0.1)
            raw.send_rtr(0x187, 1)               # a second request, watched by a peer that did not send it
            watched = listener.elements(0.8)
        finally:
            listener.close()
    finally:
        raw.close()
    assert any(re.match(r"< rtr 187 ", e) for e in watched), watched   # the request was on the bus
    assert not [e for e in seen + watched if re.match(r"< frame 187 ", e)], seen + watched
    assert read(bus, 0x6001) == 0               # the node is alive and answering


# ---- item 7: 2007h = 3 restores PDO and heartbeat parameters in their services ----------

def test_7_factory_reset_restores_pdo_and_heartbeat_in_their_services(served):
    sim, bus, _ = served
    map_tpdo1(bus, 0x185, 255, event_ms=100)
    write_ok(bus, 0x1017, 0, 100, 2)            # heartbeat every 100 ms
    write_ok(bus, 0x1016, 1, 0x00010064, 4)     # consume node 1, 100 ms
    nmt(bus, 0x01)
    assert wait_for(bus, 0x185) is not None and wait_for(bus, HEARTBEAT) is not None
    write_ok(bus, 0x2007, 0, 3, 1)
    drain(bus, 0.15)
    assert read(bus, 0x1800, 5) == 0 and read(bus, 0x1A00, 0) == 0 and read(bus, 0x1A00, 1) == 0
    assert read(bus, 0x1800, 1) == 0x185 and read(bus, 0x1800, 2) == 255
    assert read(bus, 0x1017) == 0 and read(bus, 0x1016, 1) == 0
    # The services took the factory values: no TPDO (nothing mapped), no heartbeat, and node 1's
    # heartbeat is no longer watched (one beat, then silence: no EMCY 8130h).
    bus.send(can.Message(arbitration_id=0x701, data=[0x05], is_extended_id=False))
    after = drain(bus, 0.8)
    assert not [m for m in after if m.arbitration_id in (0x185, HEARTBEAT)], after
    assert not [m for m in after if m.arbitration_id == EMCY and bytes(m.data[:2]) == frame("30 81")], after


# ---- item 8: the bootloader stays silent until a power cycle --------------------------

def test_8_bootloader_stays_silent_through_nmt_start_and_pre_operational(served):
    sim, bus, _ = served
    write_ok(bus, 0x2007, 0, 1, 1)
    drain(bus, 0.3)
    assert sim.in_bootloader
    assert exchange(bus, frame("40 01 60 00 00 00 00 00"), timeout=0.5) is None
    for cs, node in ((0x01, NODE), (0x80, NODE), (0x01, 0), (0x80, 0)):
        nmt(bus, cs, node)
        drain(bus, 0.1)
        assert exchange(bus, frame("40 01 60 00 00 00 00 00"), timeout=0.5) is None, (cs, node)
    sim.power_cycle()
    boot = wait_for(bus, HEARTBEAT)
    assert boot is not None and bytes(boot.data) == b"\x00"
    assert not sim.in_bootloader
    assert read(bus, 0x6001) == 0


# ---- item 9: 6021h is a set, in use from the next power-up --------------------------------

def test_9_encoder_cpr_is_a_set_and_takes_effect_after_re_power(served):
    sim, bus, _ = served
    assert write_abort(bus, 0x6021, 0, 700, 2) == 0x06090030
    assert read(bus, 0x6021) == 500
    for cpr in (400, 500, 600, 800, 1200, 1600, 1000):
        write_ok(bus, 0x6021, 0, cpr, 2)
    assert read(bus, 0x6021) == 1000 and sim.active_encoder_cpr == 500
    nmt(bus, 0x82)                              # reset communication is no re-power
    assert wait_for(bus, HEARTBEAT) is not None
    assert sim.active_encoder_cpr == 500
    write_ok(bus, 0x2007, 0, 2, 1)              # saved, then reset node (= power-on, B-P28)
    nmt(bus, 0x81)
    assert wait_for(bus, HEARTBEAT) is not None
    assert sim.active_encoder_cpr == 1000 and read(bus, 0x6021) == 1000
    write_ok(bus, 0x6021, 0, 1600, 2)           # not saved: the power cycle brings 1000 back
    sim.power_cycle()
    assert sim.active_encoder_cpr == 1000 and read(bus, 0x6021) == 1000


# ---- item 10: SYNC consumed on the COB-ID of 1005h ------------------------------------

def test_10_sync_is_consumed_on_the_configured_cob_id(served):
    sim, bus, _ = served
    map_tpdo1(bus, 0x185, 1)                    # every SYNC
    nmt(bus, 0x01)
    drain(bus, 0.2)
    bus.send(can.Message(arbitration_id=0x080, data=[], is_extended_id=False))
    assert wait_for(bus, 0x185, timeout=1.0) is not None
    assert write_abort(bus, 0x1005, 0, 0x40000081, 4) == 0x06090030   # the PMC007 produces no SYNC
    assert write_abort(bus, 0x1005, 0, 0x20000081, 4) == 0x06090030   # standard frames only
    write_ok(bus, 0x1005, 0, 0x81, 4)
    drain(bus, 0.1)
    bus.send(can.Message(arbitration_id=0x080, data=[], is_extended_id=False))
    assert [m for m in drain(bus, 0.5) if m.arbitration_id == 0x185] == []
    bus.send(can.Message(arbitration_id=0x081, data=[], is_extended_id=False))
    assert wait_for(bus, 0x185, timeout=1.0) is not None
    nmt(bus, 0x81)                              # not saved: reset node brings 0x80 back
    assert wait_for(bus, HEARTBEAT) is not None
    assert read(bus, 0x1005) == 0x80


# ---- item 12: abort codes as the manual and the spec's readings say ----------------------

def test_12_abort_codes_of_sets_and_mapping_length(served):
    sim, bus, _ = served
    assert write_abort(bus, 0x1A00, 0, 9, 1) == 0x06040042
    assert write_abort(bus, 0x1600, 0, 9, 1) == 0x06040042
    assert write_abort(bus, 0x1003, 0, 8, 1) == 0x06090030
    assert write_abort(bus, 0x600A, 0, 512, 2) == 0x06090030
    assert write_abort(bus, 0x6020, 0, 1, 1) == 0x06090030
    assert write_abort(bus, 0x6020, 0, 1, 4) == 0x06090030   # the U32 form of 6020h
    write_ok(bus, 0x6020, 0, 0, 1)


def test_12_any_cob_id_may_be_configured(served):
    sim, bus, _ = served
    map_tpdo1(bus, 0x120, 255)                  # in CiA 301's restricted 0x101-0x180
    assert read(bus, 0x1800, 1) == 0x120
    write_ok(bus, 0x1400, 1, 0x5F0, 4)          # RPDO1 in the SDO range 0x581-0x5FF
    assert read(bus, 0x1400, 1) == 0x5F0
    assert [m for m in drain(bus, 0.3) if m.arbitration_id == 0x120] == []   # B-P26: no PDO in PRE-OPERATIONAL
    nmt(bus, 0x01)
    m = wait_for(bus, 0x120)
    assert m is not None and bytes(m.data) == b"\x00"


# ---- item 13: 6019h:01 = 100; a refused 6003h; speed mode at the current 6003h -----------

def test_13_program_pointer_reaches_100(served):
    sim, bus, _ = served
    write_ok(bus, 0x6019, 1, 100, 1)
    assert read(bus, 0x6019, 1) == 100
    assert write_abort(bus, 0x6019, 1, 101, 1) in (0x06090030, 0x06090031)
    # [P] no 101st instruction: a word written at pointer 100 is refused.
    assert write_abort(bus, 0x6019, 2, 0x01000001, 4) == 0x08000022


def test_13_a_refused_speed_write_leaves_the_direction(served):
    sim, bus, _ = served
    write_ok(bus, 0x6005, 0, 1, 1)              # speed mode, 6003h = 0: at rest
    assert read(bus, 0x6002) == 0
    sim.inject_error(0x01)                      # UVLO latched: motion refused (B-P19)
    assert write_abort(bus, 0x6003, 0, 1000, 4) == 0x08000022
    assert read(bus, 0x6002) == 0 and read(bus, 0x6003) == 0


def test_13_switching_to_speed_mode_runs_at_the_current_speed(served):
    sim, bus, _ = served
    write_ok(bus, 0x6003, 0, -800, 4)           # position mode: speed and direction only
    assert read(bus, 0x6002) == 0 and read(bus, 0x6001) & 0x08 == 0
    write_ok(bus, 0x6005, 0, 1, 1)
    time.sleep(0.3)
    assert read(bus, 0x6001) & 0x08             # busy: running
    p1 = read(bus, 0x600C)
    time.sleep(0.3)
    p2 = read(bus, 0x600C)
    p1, p2 = (p - (1 << 32) if p & 0x80000000 else p for p in (p1, p2))
    assert p2 < p1 < 0                          # counting down: the sign of 6003h
    write_ok(bus, 0x6020, 0, 0, 1)
    sim.inject_error(0x01)                      # a refused switch: 08000022, no motion, mode kept
    write_ok(bus, 0x6005, 0, 0, 1)
    assert write_abort(bus, 0x6005, 0, 1, 1) == 0x08000022
    assert read(bus, 0x6005) == 0 and read(bus, 0x6001) & 0x08 == 0


# ---- item 14: EMCY byte 2 = 1001h, 0000h when clear, delayed by the inhibit time -----------

def emcys(bus, seconds: float) -> list[can.Message]:
    return [m for m in drain(bus, seconds) if m.arbitration_id == EMCY]


def test_14_emcy_error_register_is_1001h_and_0000_when_clear(served):
    sim, bus, _ = served
    drain(bus, 0.1)
    sim.inject_error(0x10)                      # AOC: EMCY 2300h
    (e,) = emcys(bus, 0.4)
    assert bytes(e.data[:2]) == frame("00 23") and e.data[2] == read(bus, 0x1001) == 0x03
    assert e.data[3] == 0x10
    write_ok(bus, 0x600F, 1, 0x01, 1)           # EXT1 enabled, falling edge, no debounce
    write_ok(bus, 0x601A, 0, 0, 2)
    sim.set_input(7, False)                     # EMCY FF01h: 1001h is unchanged (0x03)
    (e,) = emcys(bus, 0.4)
    assert bytes(e.data[:2]) == frame("01 FF") and e.data[2] == read(bus, 0x1001) == 0x03
    write_ok(bus, 0x6000, 0, 0x10, 1)           # the error cleared, the EXT1 latch still set: no 0000h
    assert emcys(bus, 0.3) == []
    write_ok(bus, 0x6001, 0, 0x01, 1)           # all clear
    (e,) = emcys(bus, 0.4)
    assert bytes(e.data) == bytes(8), e          # 0000h, 1001h = 0, 6000h = 0, 6001h = 0
    assert read(bus, 0x1001) == 0
    assert read(bus, 0x1003, 1) == 0xFF01      # 0000h is not logged as an error


def test_14_an_emcy_inside_the_inhibit_time_is_delayed_not_dropped(served):
    sim, bus, _ = served
    write_ok(bus, 0x1015, 0, 5000, 2)           # 500 ms
    drain(bus, 0.1)
    t0 = time.monotonic()
    sim.inject_error(0x01)                      # UVLO: 3200h at once
    sim.inject_error(0x20)                      # TSD: 4200h inside the inhibit time
    first = wait_for(bus, EMCY, timeout=1.0)
    assert first is not None and bytes(first.data[:2]) == frame("00 32")
    second = wait_for(bus, EMCY, timeout=3.0)
    t1 = time.monotonic()
    assert second is not None and bytes(second.data[:2]) == frame("00 42")
    assert second.data[2] == 0x0D               # 1001h at the time of the event: generic, voltage, temperature
    assert t1 - t0 >= 0.4                       # not before the inhibit time has passed


# ---- every dictionary row through canopen (PyPI) over socketcand --------------------------
#
# Each of the 210 index:sub entries is read (size and default), each read-only one refuses a
# write (06010002), each stored one takes a value that survives save + reset node (ROM) or
# returns to its default (RAM), and 2007h = 3 brings the ROM ones back to the factory value
# in the working copy only (C-P19).  Objects whose write is an action (motion, program, save,
# stop, node-ID, bit rate) have their own tests above and in test_pmc007_pythoncan.

import canopen  # noqa: E402

from motorbus import _core  # noqa: E402
from motorbus.drives.pmc007 import EDS_PATH  # noqa: E402

_SIZE = {"U8": 1, "U16": 2, "U32": 4, "I32": 4}
IDENTITY = {1: 0, 2: 7, 3: 0x00010000, 4: 1}  # the sim's 1018h (Pmc007SimOptions::identity)
# A value for each stored RW row ((index, sub) -> value); RAM rows return to the default at reset.
STORED = {
    (0x1005, 0): 0x81, (0x1006, 0): 1000, (0x1007, 0): 500, (0x1015, 0): 10,
    (0x1016, 1): 0x00010064, (0x1016, 2): 0x00020064, (0x1016, 3): 0x00030064, (0x1017, 0): 2000,
    (0x1200, 3): 7, (0x1280, 1): 0x80000611, (0x1280, 2): 0x80000591, (0x1280, 3): 9,
    (0x6003, 0): 1000, (0x6002, 0): 1, (0x6006, 0): 600, (0x6007, 0): 50, (0x6008, 0): 3, (0x6009, 0): 4,
    (0x600A, 0): 16, (0x600B, 0): 1500, (0x600C, 0): 1234, (0x600D, 0): 2, (0x600E, 0): 0,
    (0x600F, 1): 0x03, (0x600F, 2): 0x01, (0x6010, 0): 7, (0x6011, 1): 0x0003, (0x6011, 2): 0x1234,
    (0x6012, 0): 0x0001, (0x6013, 1): 5, (0x6013, 2): 6, (0x6017, 0): 0x6400, (0x6018, 1): 3,
    (0x6019, 1): 2, (0x6019, 2): 0x01000064, (0x6019, 4): 0x00FF, (0x601A, 0): 50, (0x601B, 0): 1,
    (0x6021, 0): 800, (0x6023, 0): 60, (0x6024, 0): 61, (0x6025, 0): 33, (0x6026, 0): 9, (0x6027, 0): 10,
    (0x6028, 0): 65, (0x6029, 0): 0, (0x602A, 0): 1,
}
for _k in range(4):
    STORED[(0x1400 + _k, 1)] = 0x80000000 | (0x200 + 0x100 * _k + NODE)   # invalid, then mapped
    STORED[(0x1800 + _k, 1)] = 0x80000000 | (0x180 + 0x100 * _k + NODE)
    for _base in (0x1400, 0x1800):
        STORED.update({(_base + _k, 2): 1, (_base + _k, 3): 20, (_base + _k, 4): 0, (_base + _k, 5): 300})
    for _s in range(1, 9):
        STORED[(0x1600 + _k, _s)] = 0x60010008    # 8 x 6001h = 64 bits (RPDO: writable, mappable)
        STORED[(0x1A00 + _k, _s)] = 0x10010008    # 8 x 1001h (TPDO: readable, mappable)
    STORED[(0x1600 + _k, 0)] = 8
    STORED[(0x1A00 + _k, 0)] = 8
# Written for their effect (tests above), read here only.
ACTIONS = {(0x2002, 0), (0x2003, 0), (0x2007, 0), (0x6000, 0), (0x6001, 0), (0x6004, 0), (0x6005, 0),
           (0x6018, 2), (0x6019, 3), (0x6019, 5), (0x601C, 0), (0x6020, 0), (0x1003, 0)}


_TYPE = {_core.canopen.DataType.UNSIGNED8: "U8", _core.canopen.DataType.UNSIGNED16: "U16", _core.canopen.DataType.UNSIGNED32: "U32",
         _core.canopen.DataType.INTEGER32: "I32", _core.canopen.DataType.VISIBLE_STRING: "VISIBLE_STRING"}


def _rows():
    """Every entry of the table (the typed dictionary the library hands up), as this audit reads them."""
    od = _core.pmc007.object_dictionary(NODE)
    out = []
    for index in od.indices():
        for sub in od.subindices(index):
            var = od[index, sub]
            default = var.default
            if index == 0x1018 and sub >= 1:
                default = IDENTITY[sub]
            elif (index, sub) == (0x1014, 0):
                default = 0x80 + NODE
            elif (index, sub) in ((0x1200, 1), (0x1200, 2)):
                default = (0x600 if sub == 1 else 0x580) + NODE
            elif sub == 1 and (0x1400 <= index <= 0x1403 or 0x1800 <= index <= 0x1803):
                default = (0x200 if index < 0x1800 else 0x180) + 0x100 * (index & 3) + NODE
            out.append(dict(index=index, sub=sub, name=var.name, type=_TYPE[var.data_type], access=var.access,
                            storage=_core.pmc007.storage(index, sub).name.lower(), default=default))
    return out


def _value(raw: bytes, dtype: str):
    if dtype == "VISIBLE_STRING":
        return raw.decode("ascii")
    return int.from_bytes(raw, "little", signed=dtype == "I32")


@pytest.fixture
def co_node():
    with SimBench([f"pmc007:{NODE}"], bus=f"virtual:pmc007-audit-od-{time.monotonic_ns()}") as bench:
        srv = bench.can.servers[0]
        bus = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        net = canopen.Network(bus)
        net.connect = lambda *a, **k: None  # the bus is already open
        net.notifier = can.Notifier(bus, net.listeners, 0.1)
        try:
            yield bench.sims[("pmc007", str(NODE))], net.add_node(NODE, EDS_PATH)
        finally:
            net.notifier.stop()
            bus.shutdown()


def _read(node, r):
    raw = node.sdo.upload(r["index"], r["sub"])
    if r["type"] in _SIZE:
        assert len(raw) == _SIZE[r["type"]], (hex(r["index"]), r["sub"], raw)
    return _value(raw, r["type"])


def _write(node, index: int, sub: int, value: int, dtype: str) -> None:
    node.sdo.download(index, sub, int(value).to_bytes(_SIZE[dtype], "little", signed=dtype == "I32"))


def _reset_node(node) -> None:
    node.nmt.send_command(0x81)
    deadline = time.monotonic() + 5
    while True:  # answers again once it has booted
        time.sleep(0.1)
        try:
            node.sdo.upload(0x1000, 0)
            return
        except (canopen.SdoCommunicationError, canopen.SdoAbortedError):
            if time.monotonic() > deadline:
                raise


def test_every_row_reads_refuses_stores_and_resets_as_the_table_says(co_node):
    sim, node = co_node
    node.sdo.RESPONSE_TIMEOUT = 1.0
    rows = _rows()
    assert len(rows) == 210
    for r in rows:                              # defaults, sizes (strings by segmented upload)
        assert _read(node, r) == r["default"], (hex(r["index"]), r["sub"], r["name"])
    for r in rows:                              # read-only and constant rows refuse writes
        if r["access"] in ("ro", "const"):
            with pytest.raises(canopen.SdoAbortedError) as e:
                node.sdo.download(r["index"], r["sub"], b"\x00" * _SIZE.get(r["type"], 1))
            assert e.value.code == 0x06010002, (hex(r["index"]), r["sub"])
    rw = [r for r in rows if r["access"] == "rw"]
    assert {(r["index"], r["sub"]) for r in rw} == set(STORED) | ACTIONS
    # Mapping sub0 goes last (the entries first), the rest in table order.
    order = sorted((r for r in rw if (r["index"], r["sub"]) in STORED),
                   key=lambda r: (0x1600 <= r["index"] <= 0x1A03 and r["sub"] == 0, 0))
    for r in order:
        _write(node, r["index"], r["sub"], STORED[(r["index"], r["sub"])], r["type"])
    for r in order:
        want = STORED[(r["index"], r["sub"])]
        assert _read(node, r) == want, (hex(r["index"]), r["sub"], r["name"])
    _write(node, 0x2007, 0, 2, "U8")            # save every ROM object (B-P37)
    _reset_node(node)                           # reset node = power-on (B-P28)
    for r in order:
        key = (r["index"], r["sub"])
        if key == (0x600C, 0):
            want = 1234                         # 602Ah = 1: the position saved at power-off (B-P17)
        elif r["storage"] == "rom":
            want = STORED[key]
        else:
            want = r["default"]
        assert _read(node, r) == want, (hex(r["index"]), r["sub"], r["name"], r["storage"])
    assert node.sdo.upload(0x6022, 0) == (1234).to_bytes(4, "little")
    _write(node, 0x2007, 0, 3, "U8")            # factory values into the working copy (B-P38)
    for r in order:
        if r["storage"] == "rom":
            assert _read(node, r) == r["default"], (hex(r["index"]), r["sub"], r["name"])
    _reset_node(node)                           # not saved: the flash still holds the stored values (C-P19)
    for r in order:
        if r["storage"] == "rom":
            assert _read(node, r) == STORED[(r["index"], r["sub"])], (hex(r["index"]), r["sub"])


# ---- behaviours through python-can (B-P04 ... B-P46 where the tests above do not) ----------

def signed32(v: int) -> int:
    return v - (1 << 32) if v & 0x80000000 else v


def wait_idle(bus, timeout: float = 5.0) -> None:
    deadline = time.monotonic() + timeout
    while read(bus, 0x6001) & 0x08:
        assert time.monotonic() < deadline, "still busy"
        time.sleep(0.05)


def test_sdo_abort_selection_block_refused_and_dlc_8_only(served):
    sim, bus, _ = served
    assert exchange(bus, frame("40 00 21 00 00 00 00 00")) == frame("80 00 21 00 00 00 02 06")  # 06020000
    assert exchange(bus, frame("40 00 60 01 00 00 00 00")) == frame("80 00 60 01 11 00 09 06")  # 06090011
    assert write_abort(bus, 0x6006, 0, 600, 4) == 0x06070012                                  # too long
    assert write_abort(bus, 0x6006, 0, 60, 1) == 0x06070013                                   # too short
    assert write_abort(bus, 0x6003, 0, 32001, 4) == 0x06090031
    assert write_abort(bus, 0x6003, 0, -32001, 4) == 0x06090032
    assert exchange(bus, frame("A0 08 10 00 7F 00 00 00")) == frame("80 08 10 00 01 00 04 05")  # B-P05
    bus.send(can.Message(arbitration_id=SDO_TX, data=frame("40 06 60 00"), is_extended_id=False))
    assert [m for m in drain(bus, 0.4) if m.arbitration_id == SDO_RX] == []                    # B-P06
    assert read(bus, 0x6006) == 400


def test_motion_rules_step_absolute_sign_stop_enable(served):
    sim, bus, _ = served
    write_ok(bus, 0x6003, 0, -4000, 4)          # B-P16 / E-P19: negative speed counts down
    write_ok(bus, 0x6004, 0, 100, 4)
    wait_idle(bus)
    assert signed32(read(bus, 0x600C)) == -100
    write_ok(bus, 0x6003, 0, 4000, 4)
    write_ok(bus, 0x601C, 0, 200, 4)            # B-P18: absolute target
    wait_idle(bus)
    assert read(bus, 0x600C) == 200 and read(bus, 0x601C) == 200
    write_ok(bus, 0x6003, 0, 1000, 4)
    write_ok(bus, 0x6004, 0, 100000, 4)
    assert read(bus, 0x6001) & 0x08             # B-P09
    write_ok(bus, 0x6004, 0, 5, 4)              # B-P07: ignored while busy, acknowledged
    assert read(bus, 0x6004) == 100000
    write_ok(bus, 0x6020, 0, 0, 1)              # B-P14: immediate stop
    assert read(bus, 0x6001) & 0x08 == 0
    write_ok(bus, 0x600C, 0, 1000, 4)           # B-P15: the counter is not rescaled by 600Ah
    write_ok(bus, 0x600A, 0, 16, 2)
    assert read(bus, 0x600C) == 1000
    write_ok(bus, 0x600E, 0, 0, 1)              # B-P20: released, step commands refused
    assert write_abort(bus, 0x6004, 0, 10, 4) == 0x08000022
    write_ok(bus, 0x600E, 0, 1, 1)
    sim.inject_error(0x02)                      # B-P19: errors cleared before motion
    assert write_abort(bus, 0x6004, 0, 10, 4) == 0x08000022
    write_ok(bus, 0x6000, 0, 0x02, 1)
    write_ok(bus, 0x6004, 0, 10, 4)
    wait_idle(bus)
    assert read(bus, 0x600C) == 1010


def test_stall_external_stop_debounce_and_gpio(served):
    sim, bus, _ = served
    write_ok(bus, 0x6017, 0, 0x64E6, 2)         # B-P21: threshold 0x64 arms detection (E-P17 row)
    write_ok(bus, 0x601B, 0, 1, 1)              # stop on stall
    write_ok(bus, 0x6003, 0, 1000, 4)
    write_ok(bus, 0x6004, 0, 100000, 4)
    drain(bus, 0.05)
    sim.set_jammed(True)
    time.sleep(0.2)
    assert read(bus, 0x6001) & 0x0C == 0x04     # stall latched, stopped
    assert any(bytes(m.data[:2]) == frame("00 FF") for m in drain(bus, 0.2) if m.arbitration_id == EMCY)
    sim.set_jammed(False)
    write_ok(bus, 0x6001, 0, 0x04, 1)
    # B-P22 / B-P23: EXT2 on the rising edge, 601Ah = 100 ms: a shorter glitch is ignored.
    write_ok(bus, 0x600F, 1, 0x02, 1)
    write_ok(bus, 0x600F, 2, 0x02, 1)
    sim.set_input(8, False)                     # low: not the selected edge
    time.sleep(0.2)
    sim.set_input(8, True)                      # rising: counts after 100 ms stable...
    sim.set_input(8, False)                     # ...back within it: a glitch
    time.sleep(0.3)
    assert read(bus, 0x6001) & 0x02 == 0
    sim.set_input(8, True)
    time.sleep(0.3)
    assert read(bus, 0x6001) & 0x02
    # B-P24: 6012h bit = 1 for a low level; outputs (6011h:01) driven by 6012h writes.
    assert read(bus, 0x6012) & 0x0100 == 0      # EXT2 is high
    sim.set_input(8, False)
    write_ok(bus, 0x6011, 1, 0x0003, 2)
    write_ok(bus, 0x6012, 0, 0x0002, 2)         # GPIO2 low, GPIO1 high
    assert read(bus, 0x6012) & 0x0103 == 0x0102
    assert sim.gpio_value & 0x3 == 0x2


def test_nmt_states_node_id_heartbeat_and_pdo_rules(served):
    sim, bus, _ = served
    drain(bus, 0.2)                             # the boot-up (00) if it is still on its way
    write_ok(bus, 0x1017, 0, 100, 2)            # B-P29: heartbeat 7F in PRE-OPERATIONAL
    hb = wait_for(bus, HEARTBEAT)
    assert hb is not None and bytes(hb.data) == b"\x7f"
    nmt(bus, 0x02)                              # B-P26: STOPPED: no SDO, heartbeat 04
    drain(bus, 0.15)
    hb = wait_for(bus, HEARTBEAT)
    assert hb is not None and bytes(hb.data) == b"\x04"
    assert exchange(bus, frame("40 00 10 00 00 00 00 00"), timeout=0.4) is None
    nmt(bus, 0x80)
    assert read(bus, 0x1000) == 0
    write_ok(bus, 0x1017, 0, 0, 2)
    # B-P29 consumer [P]: node 1 watched at 100 ms; its heartbeat stops: EMCY 8130h, no state change.
    write_ok(bus, 0x1016, 1, 0x000101F4, 4)     # node 1, 500 ms
    bus.send(can.Message(arbitration_id=0x701, data=[0x05], is_extended_id=False))
    lost = [m for m in drain(bus, 1.2) if m.arbitration_id == EMCY]
    assert [bytes(m.data[:3]) for m in lost] == [frame("30 81 11")], lost   # 1001h: communication error
    assert read(bus, 0x1001) == 0x11
    assert read(bus, 0x1000) == 0               # still PRE-OPERATIONAL: SDO answered
    bus.send(can.Message(arbitration_id=0x701, data=[0x05], is_extended_id=False))   # back: 0000h
    back = [m for m in drain(bus, 0.1) if m.arbitration_id == EMCY]
    write_ok(bus, 0x1016, 1, 0, 4)              # no longer watched (before it is lost again)
    assert bytes(back[0].data) == bytes(8), back
    assert read(bus, 0x1001) == 0
    assert write_abort(bus, 0x1A00, 1, 0x60040020, 4) == 0x06040041   # B-P31: 6004h not mappable
    assert write_abort(bus, 0x1800, 2, 241, 1) == 0x06090030          # B-P33
    assert write_abort(bus, 0x1800, 2, 252, 1) == 0x06090030          # RTR-only types: no RTR
    write_ok(bus, 0x1800, 2, 254, 1)
    # B-P27 / B-P36: a new node-ID is served from reset communication on; unsaved, reset node
    # brings the flash value back.
    write_ok(bus, 0x2002, 0, 6, 1)
    assert read(bus, 0x2002) == 6
    drain(bus, 0.05)
    nmt(bus, 0x82)
    boot = wait_for(bus, 0x706)
    assert boot is not None and bytes(boot.data) == b"\x00"
    bus.send(can.Message(arbitration_id=0x606, data=frame("40 14 10 00 00 00 00 00"), is_extended_id=False))
    reply = wait_for(bus, 0x586)
    assert reply is not None and bytes(reply.data) == frame("43 14 10 00 86 00 00 00")  # EMCY id moved
    nmt(bus, 0x81, node=6)
    boot = wait_for(bus, HEARTBEAT)
    assert boot is not None and bytes(boot.data) == b"\x00"
    assert read(bus, 0x2002) == 5


def _word(op: int, option: int = 0, data: int = 0) -> int:
    # The spec's reading of the word (§1.10 [P]): opcode 31-24, option 23-20, data 19-0.
    return op << 24 | option << 20 | data


ROT, MIC, DIR, EXTEN, FREE, CLR2, CLR1, VSET, ACC, TRIG, CNTI, CNTC, JMP, JNE, JEQ, WAIT, OUT, CMP, \
    RESET_EN, PAUSE_EN = range(1, 21)
PROGRAM = [
    _word(CLR1), _word(CLR2),                   # 0-1: the latched EXT1/EXT2 would refuse ROT
    _word(MIC, 0, 16), _word(ACC, 0, 5), _word(DIR, 0, 1), _word(VSET, 0, 4000),   # 2-5
    _word(CNTC),                                # 6
    _word(ROT, 0, 200), _word(WAIT, 1, 0), _word(CNTI), _word(CMP, 1, 3), _word(JNE, 0, 7),  # 7-11: 3 x 200
    _word(OUT, 3, 1),                           # 12: GPO3 low (GPI1/GPI2 are the RESET/PAUSE inputs)
    _word(EXTEN, 0, 1), _word(TRIG, 0, 2), _word(FREE, 0, 0),   # 13-15
    _word(JEQ, 0, 18), _word(DIR, 0, 0),        # 16-17: flag 1 (CMP): 17 skipped
    _word(JMP, 0, 20), _word(DIR, 0, 0),        # 18-19: 19 skipped
    _word(RESET_EN, 1, 0), _word(PAUSE_EN, 1, 0),   # 20-21: GPI1 low = restart at 0, GPI2 low = pause
]


def test_offline_program_every_instruction_over_sdo(served):
    sim, bus, _ = served
    write_ok(bus, 0x601A, 0, 0, 2)              # no debounce: input edges count at once
    write_ok(bus, 0x600F, 1, 0x03, 1)           # latch EXT1 and EXT2 (falling edges)...
    sim.set_input(7, False)
    sim.set_input(8, False)
    sim.set_input(7, True)
    sim.set_input(8, True)
    write_ok(bus, 0x600F, 1, 0x00, 1)           # ...and disable them: the latches stay
    assert read(bus, 0x6001) & 0x03 == 0x03
    # B-P42: the manual's SDO sequence; B-P41: 100 instructions at most.
    write_ok(bus, 0x6018, 2, 0, 1)
    for i, w in enumerate(PROGRAM):
        write_ok(bus, 0x6019, 1, i, 1)
        write_ok(bus, 0x6019, 2, w, 4)
    write_ok(bus, 0x6018, 1, len(PROGRAM), 1)
    assert write_abort(bus, 0x6018, 1, 101, 1) in (0x06090030, 0x06090031)
    for i, w in enumerate(PROGRAM):             # read back word by word
        write_ok(bus, 0x6019, 1, i, 1)
        assert read(bus, 0x6019, 2) == w
    write_ok(bus, 0x6019, 3, 1, 1)              # to flash
    write_ok(bus, 0x6018, 2, 1, 1)              # run now
    deadline = time.monotonic() + 5
    while sim.program_running and time.monotonic() < deadline:
        time.sleep(0.05)
    wait_idle(bus)
    assert read(bus, 0x600C) == 600             # ROT/WAIT/CNTI/CMP/JNE: three moves of 200 (B-P43, B-P44)
    assert read(bus, 0x600A) == 16 and read(bus, 0x6008) == 5           # MIC, ACC
    assert read(bus, 0x6002) == 1 and read(bus, 0x6003) == 4000         # DIR (17, 19 skipped), VSET
    assert read(bus, 0x600F, 1) == 0x03 and read(bus, 0x600F, 2) == 0x02  # EXTEN, TRIG
    assert read(bus, 0x6005) == 0 and read(bus, 0x6001) & 0x03 == 0     # FREE; CLR1, CLR2
    assert read(bus, 0x6012) & 0x07 == 0x04     # OUT 3,1: GPO3 low (B-P46)
    # B-P45: GPI1 low restarts at 0 (RESET_EN); GPI2 low pauses (PAUSE_EN) after the move in flight.
    sim.set_input(0, False)
    sim.set_input(1, False)
    time.sleep(0.6)
    wait_idle(bus)
    assert read(bus, 0x600C) == 800             # one move of 200, then paused
    sim.set_input(1, True)
    sim.set_input(1, False)                     # a second pulse resumes
    deadline = time.monotonic() + 5
    while sim.program_running and time.monotonic() < deadline:
        time.sleep(0.05)
    wait_idle(bus)
    assert read(bus, 0x600C) == 1200
    # B-P41: saved with 6018h:02 = 1 by 2007h = 2, the program runs at power-up.
    write_ok(bus, 0x2007, 0, 2, 1)
    sim.power_cycle()
    assert wait_for(bus, HEARTBEAT) is not None
    deadline = time.monotonic() + 5
    while sim.program_running and time.monotonic() < deadline:
        time.sleep(0.05)
    wait_idle(bus)
    assert read(bus, 0x600C) == 600


# ---- the position-mode profile over SDO, on a simulated clock (B-P11, B-P13, E-P15) ---------
# Gear g = the ramp's average acceleration (pps², 003 §4.5.12): from the start speed 6006h to
# 6003h in (6003h - 6006h) / gear seconds, covering the mean speed times that time.

GEARS = {1: 77440, 2: 48410, 3: 27170, 4: 21510, 5: 14080, 6: 10460, 7: 6915, 8: 5210}


@pytest.fixture
def clocked():
    from motorbus import _core as core
    clock = core.runtime.SimClock(1_000_000_000)
    with SimBench([f"pmc007:{NODE}"], bus=f"virtual:pmc007-audit-clk-{time.monotonic_ns()}",
                  clock=clock) as bench:
        srv = bench.can.servers[0]
        bus = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        drain(bus, 0.3)
        try:
            yield bench.sims[("pmc007", str(NODE))], bus, clock
        finally:
            _backlog.pop(id(bus), None)
            bus.shutdown()


def at(sim, clock, bus, t0: int, seconds: float) -> int:
    clock.set(t0 + int(seconds * 1e9))
    sim.poll()
    return signed32(read(bus, 0x600C))


@pytest.mark.parametrize("gear", sorted(GEARS))
def test_position_move_start_speed_gear_ramps_cruise_and_end(clocked, gear):
    sim, bus, clock = clocked
    a = GEARS[gear]
    write_ok(bus, 0x6006, 0, 400, 2)            # start speed (factory 400)
    write_ok(bus, 0x6007, 0, 0, 2)              # stop speed
    write_ok(bus, 0x6008, 0, gear, 1)
    write_ok(bus, 0x6009, 0, gear, 1)
    write_ok(bus, 0x6003, 0, 4000, 4)
    t_up, d_up = 3600 / a, (400 + 4000) / 2 * 3600 / a
    t_down, d_down = 4000 / a, 4000 / 2 * 4000 / a
    steps = 20000
    t_cruise = (steps - d_up - d_down) / 4000
    t0 = clock.now()                            # the clock stands still while the command is sent
    write_ok(bus, 0x6004, 0, steps, 4)
    assert abs(at(sim, clock, bus, t0, t_up) - d_up) <= 0.01 * d_up + 2          # the ramp: gear and 6006h
    p1 = at(sim, clock, bus, t0, t_up + 0.5)
    p2 = at(sim, clock, bus, t0, t_up + 1.0)
    assert abs((p2 - p1) - 2000) <= 2                                           # cruise at 6003h
    end = t_up + t_cruise + t_down
    at(sim, clock, bus, t0, end - 0.05)
    assert read(bus, 0x6001) & 0x08                                             # still decelerating
    assert at(sim, clock, bus, t0, end + 0.05) == steps
    assert read(bus, 0x6001) & 0x08 == 0


def test_speed_mode_ramps_up_and_decelerates_with_the_6009h_gear(clocked):
    sim, bus, clock = clocked
    write_ok(bus, 0x6008, 0, 8, 1)
    write_ok(bus, 0x6009, 0, 6, 1)
    write_ok(bus, 0x6003, 0, -4000, 4)          # B-P12: the sign is the direction
    t0 = clock.now()
    write_ok(bus, 0x6005, 0, 1, 1)              # runs at the 6003h in force
    t_up = 3600 / GEARS[8]
    p1 = at(sim, clock, bus, t0, t_up + 1.0)
    p2 = at(sim, clock, bus, t0, t_up + 2.0)
    assert p2 - p1 == -4000
    t1 = clock.now()
    write_ok(bus, 0x6005, 0, 0, 1)              # speed -> position: decelerates with 6009h
    t_down = 4000 / GEARS[6]
    at(sim, clock, bus, t1, t_down - 0.05)
    assert read(bus, 0x6001) & 0x08
    p3 = at(sim, clock, bus, t1, t_down + 0.05)
    assert read(bus, 0x6001) & 0x08 == 0
    assert abs((p2 - p3) - 4000 / 2 * t_down) <= 0.01 * 4000 / 2 * t_down + 2


# ---- B-P34: an event TPDO never more often than its inhibit time -----------------------------

def test_event_tpdo_respects_the_inhibit_time(served):
    sim, bus, _ = served
    write_ok(bus, 0x1800, 1, 0x185, 4)
    write_ok(bus, 0x1800, 2, 255, 1)
    write_ok(bus, 0x1800, 3, 5000, 2)           # 500 ms in 100 us units (C-P08)
    write_ok(bus, 0x1A00, 0, 1, 1)
    write_ok(bus, 0x1A00, 1, 0x600C0020, 4)     # 600Ch: changes on every step
    nmt(bus, 0x01)
    write_ok(bus, 0x6003, 0, 2000, 4)
    write_ok(bus, 0x6004, 0, 100000, 4)
    got = [m for m in drain(bus, 1.8) if m.arbitration_id == 0x185]
    write_ok(bus, 0x6020, 0, 0, 1)
    assert 2 <= len(got) <= 5, len(got)
    gaps = [b.timestamp - a.timestamp for a, b in zip(got, got[1:])]
    assert min(gaps) >= 0.3, gaps               # 500 ms apart at the sender (receive jitter allowed)
    values = [int.from_bytes(m.data, "little") for m in got]
    assert values == sorted(values) and len(set(values)) == len(values)


def test_rot_does_not_wait_for_the_end_of_its_move(served):
    # B-P43: ROT starts the rotation and the next instruction runs at once: a second ROT
    # finds the motor busy and is ignored (B-P07), unless a WAIT 1,0 separates them.
    sim, bus, _ = served
    write_ok(bus, 0x6003, 0, 4000, 4)
    for i, w in enumerate([_word(ROT, 0, 200), _word(ROT, 0, 200)]):
        write_ok(bus, 0x6019, 1, i, 1)
        write_ok(bus, 0x6019, 2, w, 4)
    write_ok(bus, 0x6018, 1, 2, 1)
    write_ok(bus, 0x6018, 2, 1, 1)
    time.sleep(0.3)
    wait_idle(bus)
    assert read(bus, 0x600C) == 200
    assert not sim.program_running


def test_run_one_instruction_and_clear_the_error_history(served):
    sim, bus, _ = served
    write_ok(bus, 0x6019, 1, 4, 1)              # 6019h:05 = 1 runs the word at the pointer (B-P42)
    write_ok(bus, 0x6019, 2, _word(MIC, 0, 32), 4)
    write_ok(bus, 0x6019, 5, 1, 2)
    assert read(bus, 0x600A) == 32 and read(bus, 0x6019, 5) == 0
    sim.inject_error(0x20)                      # 1003h logs 4200h; writing 0 to 1003h:00 clears it
    assert read(bus, 0x1003, 0) == 1 and read(bus, 0x1003, 1) == 0x4200
    write_ok(bus, 0x1003, 0, 0, 1)
    assert read(bus, 0x1003, 0) == 0 and read(bus, 0x1003, 1) == 0

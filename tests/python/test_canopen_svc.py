"""motorbus.canopen services from Python: NMT, heartbeat, EMCY, PDO, SYNC, CiA 402, scanner."""
from __future__ import annotations

import json
import pathlib
import threading

import pytest

from motorbus import _core
import motorbus
from motorbus.canopen import (Cia402, Cia402Device, EmcyConsumer, EmcyProducer,
                                       HeartbeatConsumer, NmtMaster, OpMode, PdoMap, PdoReceiver,
                                       SyncProducer, configure_pdo, decode_statusword,
                                       read_pdo_config, scan_network)
from motorbus.canopen import heartbeat as hb_mod
from motorbus.canopen import nmt as nmt_mod
from motorbus.canopen import pdo as pdo_mod
from polling import recv_id, wait_for

VECTORS = json.loads((pathlib.Path(__file__).parents[1] / "vectors" / "seed_examples.json").read_text())
_hub = iter(range(1_000_000))


def pair():
    name = f"svc-py-{next(_hub)}"
    return _core.can.open_virtual(name), _core.can.open_virtual(name)


# ---- PDO codec ---------------------------------------------------------------

def test_pdomap_bit_offsets_and_signed():
    m = PdoMap([(0x2000, 1, 1), (0x2000, 2, 3), (0x2000, 3, 12), (0x2000, 4, 7), (0x2000, 5, 1)])
    assert m.pack([1, 5, 0xABC, 0x55, 1]) == bytes([0xCB, 0xAB, 0xD5])
    assert m.unpack(bytes([0xCB, 0xAB, 0xD5])) == [1, 5, 0xABC, 0x55, 1]
    assert [m.offset(i) for i in range(5)] == [0, 1, 4, 16, 23]
    s = PdoMap([(0x6041, 0, 16), (0x6064, 0, 32, True)])
    assert s.pack([0x0637, -100]) == bytes.fromhex("37069cffffff")
    assert s.unpack(bytes.fromhex("37069cffffff")) == [0x0637, -100]
    assert s.unpack_dict(bytes.fromhex("37069cffffff"))[(0x6064, 0)] == -100
    assert s.mapping_words == [0x60410010, 0x60640020]
    with pytest.raises(motorbus.ProtocolError):
        s.unpack(b"\x37\x06")
    with pytest.raises(motorbus.InvalidArgument):
        PdoMap([(0x2000, 0, 64), (0x2001, 0, 1)])
    assert pdo_mod.pack([(0x6012, 0, 16)], [3]) == b"\x03\x00"


class RecordingSdo:
    """An SDO client stand-in: records downloads, answers uploads from a dict."""

    def __init__(self, values=None):
        self.writes = []
        self.values = values or {}

    def download(self, index, sub, data):
        self.writes.append((index, sub, bytes(data)))
        self.values[(index, sub)] = int.from_bytes(data, "little")

    def upload(self, index, sub):
        return self.values[(index, sub)].to_bytes(4, "little")


def expedited(index, sub, data):
    return bytes([0x23 | ((4 - len(data)) << 2), index & 0xFF, index >> 8, sub]) + data + bytes(4 - len(data))


def test_pmc007_pdo_configuration_byte_for_byte():
    seq = VECTORS["pmc007_canopen"]["pdo_config_sequence"]
    sdo = RecordingSdo()
    configure_pdo(sdo, 5, tpdo=1, cob_id=0x187, transmission_type=255, inhibit_100us=50,
                  event_timer_ms=1000, mapping=[(0x6012, 0, 16)], procedure="direct")
    frames = [expedited(i, s, d) for i, s, d in sdo.writes]
    assert frames == [bytes.fromhex(r["data"]) for r in seq["requests"]]
    # The resulting TPDO decodes with the same mapping to the manual's frame.
    m = PdoMap([(0x6012, 0, 16)])
    assert m.pack([3]) == bytes.fromhex(seq["resulting_pdo"]["data"])
    back = read_pdo_config(RecordingSdo({**sdo.values, (0x1800, 0): 5}), 5, tpdo=1)
    assert back.cob_id == 0x187 and back.enabled
    assert back.mapping == [(0x6012, 0, 16)]


def test_cia301_procedure_order():
    sdo = RecordingSdo()
    configure_pdo(sdo, 5, rpdo=1, cob_id=0x205, transmission_type=1, mapping=[(0x6040, 0, 16)])
    assert [(i, s) for i, s, _ in sdo.writes] == [(0x1400, 1), (0x1400, 2), (0x1600, 0), (0x1600, 1),
                                                 (0x1600, 0), (0x1400, 1)]
    assert sdo.writes[0][2] == (0x80000205).to_bytes(4, "little")
    assert sdo.writes[-1][2] == (0x205).to_bytes(4, "little")
    with pytest.raises(motorbus.InvalidArgument):
        configure_pdo(sdo, 5, mapping=[(0x6040, 0, 16)])


# ---- NMT / heartbeat / EMCY / SYNC ------------------------------------------------

def test_nmt_master_commands_and_states():
    host, dev = pair()
    m = NmtMaster(host)
    changes = []
    m.on_state_change = lambda n, a, b: changes.append((n, a, b))
    m.start(5)
    f = recv_id(dev, 0x000)
    assert f.data == b"\x01\x05"
    m.reset_node()
    assert recv_id(dev, 0x000).data == b"\x81\x00"
    dev.send(hb_mod.heartbeat_encode(5, "PRE-OPERATIONAL"))
    assert m.wait_for_state(5, "PRE-OPERATIONAL", timeout=1.0)
    dev.send(_core.can.Frame(0x705, b"\x42"))  # N7
    wait_for(lambda: m.raw_state(5) == 0x42, 1.0)
    assert m.state(5) == "UNKNOWN"
    assert changes[0] == (5, "UNKNOWN", "PRE-OPERATIONAL")
    assert nmt_mod.nmt_decode(_core.can.Frame(0, b"\x01")) is None  # N1


def test_heartbeat_consumer_lost_on_sim_clock():
    host, dev = pair()
    clock = _core.runtime.SimClock(0)
    hb = HeartbeatConsumer(host, clock)
    events = []
    got = threading.Event()

    def on_event(node, ev, state):
        events.append((node, ev, state))
        got.set()

    hb.on_event = on_event
    hb.monitor(7, timeout=0.1)
    dev.send(hb_mod.heartbeat_encode(7, "OPERATIONAL"))
    assert got.wait(1.0)
    clock.advance(100_000_000)
    hb.process()
    assert events == [(7, "started", "OPERATIONAL"), (7, "lost", "OPERATIONAL")]
    assert hb.health(7).lost and hb.health(7).timeouts == 1


def test_emcy_consumer_and_producer_inhibit():
    host, dev = pair()
    c = EmcyConsumer(host, history=4)
    clock = _core.runtime.SimClock(0)
    p = EmcyProducer(dev, 5, inhibit_100us=100, clock=clock)
    assert p.report(0x2310, 0x03, b"\x01\x02")
    e = c.wait(5, timeout=1.0)
    assert e is not None and e.code == 0x2310 and e.register == 0x03 and e.data == b"\x01\x02\x00\x00\x00"
    assert e.text == "current"
    assert not p.report(0x3210, 0x05)  # inhibited: queued
    assert p.pending == 1
    clock.advance(10_000_000)
    p.process()
    e2 = c.wait(5, timeout=1.0)
    assert e2.code == 0x3210
    dev.send(_core.can.Frame(0x85, b"\x10\x42"))  # E1: short
    e3 = c.wait(5, timeout=1.0)
    assert e3.short and e3.code == 0x4210 and e3.register == 0
    assert c.active(5) == [0x2310, 0x3210, 0x4210]
    dev.send(_core.canopen.emcy_encode(5, 0, 0))
    assert c.wait(5, timeout=1.0).is_reset
    assert c.active(5) == []


def test_sync_producer_jitter_stats():
    host, dev = pair()
    s = SyncProducer(host, 0.002, counter_overflow=5)
    s.start()
    wait_for(lambda: s.sent >= 10, 2.0, interval=0.005)
    s.stop()
    j = s.jitter()
    assert j.count == s.sent - 1
    assert j.min_ns <= j.mean_ns <= j.max_ns
    first = recv_id(dev, 0x80)
    assert first.data == b"\x01"


# ---- PDO on the bus ----------------------------------------------------------------

def test_pdo_receiver_values_and_short_frames():
    host, dev = pair()
    rx = PdoReceiver(host, 0x185, [(0x6041, 0, 16), (0x6064, 0, 32)])
    seen = threading.Event()
    rx.set_callback(lambda values, ts: seen.set())
    dev.send(_core.can.Frame(0x185, b"\x37\x06"))  # too short: counted
    dev.send(_core.can.Frame(0x185, b"\x37\x06\x10\x27\x00\x00"))
    assert seen.wait(1.0)
    assert rx.values == [0x0637, 10000]
    assert rx.value(0x6064) == 10000
    assert rx.short_frames == 1


# ---- CiA 402 ------------------------------------------------------------------------

class DeviceSdo:
    """SDO stand-in served by the C++ device-side state machine."""

    def __init__(self):
        self.dev = Cia402Device()
        self.objects = {}
        self.controlwords = []

    def download(self, index, sub, data):
        v = int.from_bytes(data, "little")
        if index == 0x6040:
            self.controlwords.append(v)
            self.dev.on_controlword(v)
            if v & 0x10 and self.dev.mode == 1:
                self.dev.set_status_bits(0x0400, 0x0400)
        elif index == 0x6060:
            code = self.dev.set_mode(int.from_bytes(data, "little", signed=True))
            if code:
                raise motorbus.ProtocolError(f"abort {code:#010x}")
        else:
            self.objects[index] = v

    def upload(self, index, sub):
        if index == 0x6041:
            return self.dev.statusword.to_bytes(2, "little")
        if index == 0x6061:
            return (self.dev.mode & 0xFF).to_bytes(1, "little")
        return self.objects.get(index, 0).to_bytes(4, "little")


def test_cia402_decode_every_state_and_unknown():
    assert decode_statusword(0x0040) == "SWITCH ON DISABLED"
    assert decode_statusword(0x0237) == "OPERATION ENABLED"
    assert decode_statusword(0x0007) == "QUICK STOP ACTIVE"
    assert decode_statusword(0x0008) == "FAULT"
    assert decode_statusword(0x0067) == "UNKNOWN"  # D3


def test_cia402_host_enable_move_and_faults():
    sdo = DeviceSdo()
    d = Cia402(sdo, 5, timeout=0.5, poll=0.001)
    d.set_mode(OpMode.PROFILE_POSITION)
    assert d.op_mode == OpMode.PROFILE_POSITION
    d.enable()
    assert sdo.controlwords == [0x06, 0x07, 0x0F]
    assert d.state == "OPERATION ENABLED"
    d.move_to(-1000)
    assert sdo.objects[0x607A] == (-1000) & 0xFFFFFFFF
    assert sdo.controlwords[-2:] == [0x3F, 0x2F]
    d.wait_target_reached(timeout=0.5)
    with pytest.raises(motorbus.ProtocolError):
        d.set_mode(OpMode.CYCLIC_SYNC_TORQUE)  # D4 surfaces as the SDO error
    sdo.dev.fault(0x7300)
    with pytest.raises(motorbus.DriveFault):
        d.wait_target_reached(timeout=0.5)
    sdo.dev.fault_reaction_done()
    d.enable()  # fault reset (rising edge) then 2, 3, 4
    assert 0x80 in sdo.controlwords
    assert d.state == "OPERATION ENABLED"


def test_cia402_device_loss_of_master_and_quick_stop():
    dev = Cia402Device()
    dev.set_abort_connection_option(3)
    dev.on_controlword(0x06)
    dev.on_controlword(0x0F)
    assert dev.loss_of_master() == 11  # D5: quick stop
    assert dev.state == "QUICK STOP ACTIVE"
    dev.motion_stopped()               # D6 with 605A = 2
    assert dev.state == "SWITCH ON DISABLED"
    assert dev.on_controlword(0x0F) == -1  # D1


# ---- scanner ------------------------------------------------------------------------------

def test_scan_network_finds_a_responder():
    host, dev = pair()
    objs = {(0x1000, 0): 0x00040192, (0x1018, 1): 0x12E, (0x1018, 2): 7, (0x1018, 3): 1, (0x1018, 4): 99}

    def answer(f):
        d = f.data
        if len(d) != 8 or d[0] != 0x40:
            return
        v = objs[(d[1] | d[2] << 8, d[3])]
        dev.send(_core.can.Frame(0x585, bytes([0x43]) + d[1:4] + v.to_bytes(4, "little")))

    dev.subscribe(answer, id=0x605)
    found = scan_network(host, sdo_timeout=0.1)
    assert [n.node for n in found] == [5]
    n = found[0]
    assert n.device_type == 0x00040192 and n.profile == 402
    assert (n.vendor_id, n.product_code, n.revision, n.serial_number) == (0x12E, 7, 1, 99)


# ---- end to end with our LocalNode and SdoClient ------------------------------------------

def test_pmc007_end_to_end_on_local_node():
    from motorbus.canopen import PdoService
    from motorbus.canopen import LocalNode, ObjectDictionary, SdoClient

    seq = VECTORS["pmc007_canopen"]["pdo_config_sequence"]
    name = f"svc-py-{next(_hub)}"
    dev, host, sniff = _core.can.open_virtual(name), _core.can.open_virtual(name), _core.can.open_virtual(name)
    od = ObjectDictionary()
    od.add_variable(0x6012, "GPIO value", "U16", access="rw", pdo_mappable=True, default=3)
    node = LocalNode(dev, 5, od)
    pdo = PdoService(node, strict=False)
    sdo = SdoClient(host, 5)
    configure_pdo(sdo, 5, tpdo=1, cob_id=0x187, transmission_type=255, inhibit_100us=50,
                  event_timer_ms=1000, mapping=[(0x6012, 0, 16)], procedure="direct")
    reqs = []
    while len(reqs) < 6:
        f = sniff.recv(1.0)
        assert f is not None
        if f.id == 0x605:
            reqs.append(f.data)
    assert reqs == [bytes.fromhex(r["data"]) for r in seq["requests"]]
    assert pdo.mapping(True, 1) == [(0x6012, 0, 16)]
    NmtMaster(host).start(5)
    f = recv_id(sniff, 0x187, timeout=2.0)
    assert f is not None and f.data == bytes.fromhex(seq["resulting_pdo"]["data"])
    assert pdo.counters.tpdo_sent >= 1
    node.close()


def test_tpdo_carries_what_the_read_hook_answers():
    """A TPDO reads its objects as an SDO upload does, through the read hook: a simulator
    that computes 6064h when asked (the CiA 402 sim) sends its live position, not the
    value the dictionary last stored (which stays 0 here)."""
    from motorbus.canopen import LocalNode, ObjectDictionary, PdoService, SdoClient

    dev, host = pair()
    od = ObjectDictionary()
    live = {"position": -1234}
    var = od.add_variable(0x6064, "Position actual value", "I32", access="ro", pdo_mappable=True, default=0)
    var.set_read_hook(lambda v, current: live["position"].to_bytes(4, "little", signed=True))
    node = LocalNode(dev, 5, od)
    PdoService(node)
    configure_pdo(SdoClient(host, 5), 5, tpdo=1, transmission_type=1, mapping=[(0x6064, 0, 32, True)])
    rx = PdoReceiver(host, 0x185, [(0x6064, 0, 32, True)])
    NmtMaster(host).start(5)
    seen = []
    for position in (-1234, 5678):
        live["position"] = position
        after = rx.received
        host.send(_core.can.Frame(0x080, b""))                   # SYNC: transmission type 1 sends TPDO 1
        assert rx.wait_newer(after, timeout=2.0) is not None
        seen.append(rx.value(0x6064))
    assert [v - (1 << 32) if v >= 1 << 31 else v for v in seen] == [-1234, 5678]
    assert od[0x6064, 0].raw == bytes(4)                    # nothing was stored: the hook answered
    node.close()


def test_heartbeat_service_on_local_node_applies_loss_of_master():
    from motorbus.canopen import HeartbeatService
    from motorbus.canopen import LocalNode, ObjectDictionary, SdoClient

    name = f"svc-py-{next(_hub)}"
    dev, host = _core.can.open_virtual(name), _core.can.open_virtual(name)
    node = LocalNode(dev, 5, ObjectDictionary())
    hb = HeartbeatService(node, consumer_entries=2)
    drive = Cia402Device()
    drive.set_abort_connection_option(2)
    drive.on_controlword(0x06)
    drive.on_controlword(0x0F)
    lost = threading.Event()
    hb.set_lost_callback(lambda n: (drive.loss_of_master(), lost.set()))
    sdo = SdoClient(host, 5)
    sdo.download(0x1016, 1, (0x00010028).to_bytes(4, "little"))   # node 1, 40 ms
    with pytest.raises(Exception) as exc:
        sdo.download(0x1016, 2, (0x00010050).to_bytes(4, "little"))  # N12 duplicate
    assert getattr(exc.value, "code", None) == 0x06040043
    host.send(hb_mod.heartbeat_encode(1, "OPERATIONAL"))
    assert lost.wait(2.0)
    assert drive.state == "SWITCH ON DISABLED"   # 0x6007 = 2 (D5)
    assert hb.health(1).lost
    node.close()


def test_heartbeat_producer_with_python_state_function():
    host, dev = pair()
    clock = _core.runtime.SimClock(0)
    states = iter(["PRE-OPERATIONAL", "OPERATIONAL"])
    p = hb_mod.HeartbeatProducer(dev, 9, 0.1, lambda: next(states), clock=clock)
    p.send_boot_up()
    p.process()
    clock.advance(100_000_000)
    p.process()
    got = [recv_id(host, 0x709).data for _ in range(3)]
    assert got == [b"\x00", b"\x7f", b"\x05"]
    assert p.sent == 3
    del p  # the state function is released without the GIL held by the destructor

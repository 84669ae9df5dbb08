"""The node-centric facade (motorbus.canopen.Network) over a virtual bus:
against a LocalNode serving a dictionary, and against a simulated CiA 402
drive (LocalNode + Cia402Device + PdoService + EmcyProducer)."""
import itertools
import threading

import pytest

import motorbus
from motorbus import _core
from motorbus.canopen import (Cia402Device, EmcyProducer, HeartbeatService, LocalNode, Network, NotFound,
                              ObjectDictionary, OpMode, PdoService, SdoAbortError)
from polling import wait_for

_hub = itertools.count()


def od_for_tests():
    od = ObjectDictionary()
    od.add_variable(0x1000, "Device type", "u32", "ro", default=0x00020192)
    od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "ro", default="motorbus drive")
    od.add_record(0x1018, "Identity object")
    od.add_member(0x1018, 1, "Vendor-ID", "u32", "ro", default=0x12E)
    od.add_member(0x1018, 2, "Product code", "u32", "ro", default=7)
    od.add_variable(0x2000, "Offset", "i16", "rw", default=-5)
    od.add_variable(0x2001, "Gain", "f32", "rw", default=1.5)
    od.add_variable(0x2002, "Enabled", "BOOLEAN", "rw", default=1)
    od.add_variable(0x2003, "Baud index", "u8", "rw", low=0, high=8, default=4)
    return od


class SimulatedDrive:
    """A CiA 402 drive in profile position mode, served by LocalNode: the
    statusword follows Cia402Device; a new set-point moves the position to the
    target at once and sets target reached (bit 10); TPDO1 carries statusword +
    position on change."""

    def __init__(self, bus, node_id=5):
        self.dev = Cia402Device()
        self.position = 0
        od = od_for_tests()
        od.add_variable(0x6040, "Controlword", "u16", "rw", pdo_mappable=True)
        od.add_variable(0x6041, "Statusword", "u16", "ro", pdo_mappable=True)
        od.add_variable(0x6060, "Modes of operation", "i8", "rw")
        od.add_variable(0x6061, "Modes of operation display", "i8", "ro")
        od.add_variable(0x6064, "Position actual value", "i32", "ro", pdo_mappable=True)
        od.add_variable(0x607A, "Target position", "i32", "rw", pdo_mappable=True)
        od[0x6040].set_write_hook(lambda var, data: self._controlword(int.from_bytes(data, "little")))
        od[0x6060].set_write_hook(lambda var, data: self._mode(int.from_bytes(data, "little", signed=True)))
        self.od = od
        self.node = LocalNode(bus, node_id, od)
        self.pdo = PdoService(self.node)
        self.heartbeat = HeartbeatService(self.node, producer_ms=20)
        self.emcy = EmcyProducer(bus, node_id)
        self._publish()

    def _publish(self):
        # Local writes: the PDO engine sees them as changes of mapped objects.
        self.od[0x6041].value = self.dev.statusword
        self.od[0x6061].value = self.dev.mode
        self.od[0x6064].value = self.position
        self.pdo.notify_change(0x6041)
        self.pdo.notify_change(0x6064)

    def _controlword(self, cw):
        if cw & 0x10 and self.dev.state == "OPERATION ENABLED" and self.dev.mode == 1:
            self.dev.set_status_bits(0x0400, 0)
            self.dev.on_controlword(cw)
            self.position = self.od[0x607A].value   # the move is instantaneous here
            self.dev.set_status_bits(0x0400, 0x0400)
        else:
            self.dev.on_controlword(cw)
        self._publish()

    def _mode(self, mode):
        code = self.dev.set_mode(mode)
        self._publish()
        return code or None

    def close(self):
        self.node.close()


@pytest.fixture()
def net():
    name = f"net-{next(_hub)}"
    dev_bus = _core.can.open_virtual(name)
    drive = SimulatedDrive(dev_bus)
    with Network(f"virtual:{name}", sdo_timeout=0.5) as network:
        yield network, drive
    drive.close()
    dev_bus.close()


def test_sdo_by_index_and_by_name_with_typed_values(net):
    network, drive = net
    node = network.add_node(5, drive.od)
    assert node.sdo[0x1000].raw == 0x00020192
    assert node.sdo["Identity object"]["Vendor-ID"].raw == 0x12E
    assert node.sdo[0x1018][2].raw == 7
    assert node.sdo["Identity object.Product code"].raw == 7
    assert node.sdo["Offset"].raw == -5                 # signed per INTEGER16
    assert node.sdo["Gain"].value == 1.5 and isinstance(node.sdo["Gain"].value, float)
    assert node.sdo["Gain"].raw == bytes.fromhex("0000c03f")     # not an integer type: the bytes
    assert node.sdo["Enabled"].value is True
    assert node.sdo["Manufacturer device name"].value == "motorbus drive"
    node.sdo["Offset"].raw = -300
    assert drive.od[0x2000].value == -300
    node.sdo["Gain"].value = 2.25
    assert drive.od[0x2001].value == 2.25
    node.sdo[0x2003].value = 8
    assert drive.od[0x2003].value == 8
    with pytest.raises(SdoAbortError) as e:
        node.sdo["Baud index"].raw = 9                  # above the high limit: the server refuses
    assert e.value.code == 0x06090031
    assert node.sdo.upload(0x1018, 1) == (0x12E).to_bytes(4, "little")
    node.sdo.download(0x2000, 0, (7).to_bytes(2, "little"))
    assert node.sdo[0x2000].value == 7


def test_sdo_without_a_dictionary_reads_bytes_and_needs_sizes(net):
    network, drive = net
    node = network.add_node(5)
    assert node.sdo[0x1018][1].raw == (0x12E).to_bytes(4, "little")
    node.sdo[0x2000][0].write(-2, size=2, signed=True)
    assert drive.od[0x2000].value == -2
    node.sdo[0x2003].raw = b"\x03"
    assert drive.od[0x2003].value == 3
    with pytest.raises(motorbus.InvalidArgument, match="size"):
        node.sdo[0x2003].raw = 3
    with pytest.raises(motorbus.InvalidArgument, match="data type"):
        node.sdo[0x2003].value


def test_unknown_names_and_indices_raise_typed_errors_naming_them(net):
    network, drive = net
    node = network.add_node(5, drive.od)
    with pytest.raises(NotFound, match="'Nope'"):
        node.sdo["Nope"]
    with pytest.raises(KeyError):                       # NotFound is also a KeyError
        node.sdo["Identity object"]["Colour"]
    with pytest.raises(motorbus.MotorbusError, match="0x3000"):
        node.sdo[0x3000]
    with pytest.raises(motorbus.InvalidArgument, match="RECORD"):
        node.sdo["Identity object"].raw
    with pytest.raises(NotFound, match="node 9"):
        network[9]
    with pytest.raises(motorbus.InvalidArgument, match="1-127"):
        network.add_node(128)
    with pytest.raises(motorbus.InvalidArgument, match="already"):
        network.add_node(5)
    assert network[5] is node and 5 in network and list(network) == [5]


def test_nmt_state_follows_the_heartbeat_and_commands_move_it(net):
    network, drive = net
    node = network.add_node(5, drive.od)
    assert node.nmt.wait_for_heartbeat(1.0) == "PRE-OPERATIONAL"
    node.nmt.state = "OPERATIONAL"
    assert wait_for(lambda: node.nmt.state == "OPERATIONAL", 1.0)
    assert drive.node.nmt_state == "OPERATIONAL"
    node.nmt.state = "STOPPED"
    assert node.nmt.wait_for_heartbeat(1.0) == "STOPPED"
    events = []
    node.heartbeat.add_callback(lambda event, state: events.append((event, state)))
    boot_ups = node.heartbeat.health.boot_ups
    node.nmt.state = "RESET COMMUNICATION"
    # Counted, not waited for with wait_for_bootup(): that waits for the *next* boot-up,
    # and the node's may already have arrived when the call starts (it did, under ASan).
    assert wait_for(lambda: node.heartbeat.health.boot_ups > boot_ups, 2.0)
    assert wait_for(lambda: node.nmt.state == "PRE-OPERATIONAL", 1.0)
    assert ("reset", "INITIALISING") in events
    assert node.heartbeat.health.boot_ups >= 1
    with pytest.raises(motorbus.InvalidArgument, match="SLEEPING"):
        node.nmt.state = "SLEEPING"


def test_wait_for_bootup_times_out_with_a_typed_error(net):
    network, _ = net
    node = network.add_node(6)
    with pytest.raises(motorbus.TimeoutError, match="node 6"):
        node.nmt.wait_for_bootup(0.05)
    with pytest.raises(motorbus.TimeoutError, match="heartbeat"):
        node.nmt.wait_for_heartbeat(0.05)


def test_emcy_reaches_the_node_log_callbacks_and_wait(net):
    network, drive = net
    node = network.add_node(5, drive.od)
    got = []
    node.emcy.add_callback(got.append)
    drive.emcy.report(0x2310, 0x03, b"\x01\x02")
    e = node.emcy.wait(1.0)
    assert (e.node, e.code, e.register, e.data) == (5, 0x2310, 0x03, b"\x01\x02\x00\x00\x00")
    assert e.text and not e.is_reset
    assert wait_for(lambda: len(got) == 1, 1.0) and got[0].code == 0x2310
    assert node.emcy.active == [0x2310]
    assert [m.code for m in node.emcy.log] == [0x2310]
    drive.emcy.report(0x0000)
    assert node.emcy.wait(1.0).is_reset
    assert node.emcy.active == []


def test_tpdo_configured_over_sdo_delivers_values_to_callbacks(net):
    network, drive = net
    node = network.add_node(5, drive.od)
    cfg = node.tpdo[1].configure(transmission_type=255, mapping=[(0x6041, 0, 16), (0x6064, 0, 32)])
    assert cfg.cob_id & 0x7FF == 0x185 and cfg.mapping == [(0x6041, 0, 16), (0x6064, 0, 32)]
    seen = []
    received = threading.Event()
    node.tpdo[1].add_callback(lambda values: (seen.append(values), received.set()))
    node.nmt.state = "OPERATIONAL"
    assert wait_for(lambda: drive.node.nmt_state == "OPERATIONAL", 1.0)
    drive.position = -1234                              # signed INTEGER32, sign-extended from the OD
    drive._publish()
    assert received.wait(1.0)
    assert wait_for(lambda: seen and seen[-1][(0x6064, 0)] == -1234, 1.0)
    assert node.tpdo[1].values[(0x6041, 0)] == drive.dev.statusword
    assert node.tpdo.read([1])[0].transmission_type == 255


def test_cia402_enable_and_move_through_the_node(net):
    network, drive = net
    node = network.add_node(5, drive.od)
    drive_obj = node.cia402
    assert node.cia402 is drive_obj                     # one per node, made on first use
    drive_obj.set_mode(OpMode.PROFILE_POSITION)
    drive_obj.enable()
    assert drive.dev.state == "OPERATION ENABLED"
    drive_obj.move_to(10_000)
    drive_obj.wait_target_reached(timeout=1.0)
    assert node.sdo["Position actual value"].raw == 10_000
    assert drive_obj.state == "OPERATION ENABLED"


def test_network_opens_and_closes_its_own_bus_but_not_a_given_one():
    name = f"net-own-{next(_hub)}"
    bus = _core.can.open_virtual(name)
    with Network(bus) as network:
        assert network.bus is bus
    bus.send(_core.can.Frame(0x123, b""))                   # still open: the network did not own it
    with Network(f"virtual:{name}") as network:
        own = network.bus
    with pytest.raises(motorbus.ClosedError):
        own.send(_core.can.Frame(0x123, b""))
    bus.close()
    with pytest.raises(motorbus.InvalidArgument, match="spec string"):
        Network(42)


def test_scan_finds_the_served_node(net):
    network, drive = net
    found = network.scan(sdo_timeout=0.1)
    assert [n.node for n in found] == [5]
    assert found[0].device_type == 0x00020192 and found[0].profile == 402 and found[0].vendor_id == 0x12E

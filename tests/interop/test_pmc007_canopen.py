"""canopen (PyPI) as an independent master of the simulated PMC007, with the EDS motorbus
ships (cpp/motorbus/drives/pmc007/pmc007.eds, installed beside _core: pmc007.EDS_PATH; generated from the
simulator's own table).

The simulator is served by socketcand from a SimBench in this process; canopen talks to it
through python-can's socketcand interface (no motorbus code on the client side)."""
from __future__ import annotations

import time

import can
import canopen
import pytest

from motorbus.drives.pmc007 import EDS_PATH
from motorbus.sim import SimBench


@pytest.fixture
def master():
    with SimBench(["pmc007:5"], bus=f"virtual:pmc007-canopen-{time.monotonic_ns()}") as bench:
        srv = bench.can.servers[0]
        bus = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        net = canopen.Network(bus)
        net.connect = lambda *a, **k: None  # the bus is already open
        net.notifier = can.Notifier(bus, net.listeners, 0.1)
        try:
            node = net.add_node(5, EDS_PATH)
            yield bench.sims[("pmc007", "5")], node
        finally:
            net.notifier.stop()
            bus.shutdown()


def test_sdo_read_write_by_eds_names(master):
    sim, node = master
    assert node.sdo["Start speed"].raw == 400
    assert node.sdo["Baud rate"].raw == 4
    assert node.sdo["Manufacturer device name"].raw == "PMC007 (motorbus sim)"  # segmented upload
    node.sdo["Start speed"].raw = 600
    assert node.sdo["Start speed"].raw == 600
    node.sdo["Maximum speed"].raw = -1200          # signed 6003h: direction follows the sign
    assert node.sdo["Rotation direction"].raw == 0
    assert node.sdo["External emergency stop"]["Enable"].raw == 0
    with pytest.raises(canopen.SdoAbortedError) as e:
        node.sdo["Microstepping"].raw = 3
    assert e.value.code == 0x06090030


def test_tpdo_with_the_manuals_sequence_then_start_and_receive(master):
    sim, node = master
    node.sdo["GPIO parameters"]["Direction"].raw = 0x0003
    # App.3 §11.2 in the manual's order: COB-ID, type, inhibit, event timer, count, entry.
    comm, mapping = node.sdo[0x1800], node.sdo[0x1A00]
    comm[1].raw = 0x187
    comm[2].raw = 255
    comm[3].raw = 50
    comm[5].raw = 1000
    mapping[0].raw = 1
    mapping[1].raw = 0x60120010
    node.tpdo.read()                               # canopen reads the configuration back
    assert node.tpdo[1].cob_id == 0x187 and node.tpdo[1].trans_type == 255
    assert node.tpdo[1].event_timer == 1000 and node.tpdo[1].inhibit_time == 50
    node.nmt.state = "OPERATIONAL"
    node.sdo["GPIO value"].raw = 0x0003            # GPIO1, GPIO2 driven low: bit = 1
    deadline = time.monotonic() + 3
    while node.tpdo[1]["GPIO value"].raw != 0x0003:
        assert time.monotonic() < deadline, "no TPDO carrying 03 00"
        node.tpdo[1].wait_for_reception(0.5)
    sim.set_input(2, False)                        # GPIO3 input pulled low: an event-driven PDO
    deadline = time.monotonic() + 3
    while node.tpdo[1]["GPIO value"].raw != 0x0007:
        assert time.monotonic() < deadline, "the change was not sent"
        node.tpdo[1].wait_for_reception(0.5)


def test_nmt_stop_silences_sdo(master):
    sim, node = master
    node.sdo.RESPONSE_TIMEOUT = 0.3
    node.nmt.state = "STOPPED"
    time.sleep(0.05)
    with pytest.raises(canopen.SdoCommunicationError):
        node.sdo["Start speed"].raw
    node.nmt.state = "PRE-OPERATIONAL"
    time.sleep(0.05)
    assert node.sdo["Start speed"].raw == 400


def test_save_and_reset_node_keep_rom_values(master):
    sim, node = master
    node.sdo["Start speed"].raw = 777              # ROM
    node.sdo["Operation mode"].raw = 1             # RAM
    node.sdo["System control"].raw = 2             # save to flash
    node.sdo["Stop speed"].raw = 55                # ROM, not saved
    node.nmt.state = "RESET"
    node.nmt.wait_for_bootup(2)
    assert node.sdo["Start speed"].raw == 777
    assert node.sdo["Stop speed"].raw == 0
    assert node.sdo["Operation mode"].raw == 0
    assert node.sdo["System control"].raw == 0

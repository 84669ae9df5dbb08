"""canopen's BaseNode402 (python-canopen's CiA 402 master, a real peer) drives the C++
generic cia402 simulator: NMT, PDO set-up by SDO, setup_402_state_machine, the power
state machine to OPERATION ENABLED, a profile-position move (target in an RPDO, the
set-point handshake by controlword) to target reached, and homing.

The simulator is served by socketcand from a SimBench in this process; canopen talks to
it through python-can's socketcand interface (no motorbus code on the client side).  The
client's object dictionary is the EDS the simulator's own dictionary exports."""
from __future__ import annotations

import time

import can
import canopen
import pytest

from motorbus.sim import SimBench

NODE = 5


@pytest.fixture
def drive(tmp_path):
    with SimBench([f"cia402:{NODE}"], bus=f"virtual:cia402-402-{time.monotonic_ns()}") as bench:
        sim = bench.sims[("cia402", str(NODE))]
        eds = tmp_path / "cia402.eds"
        eds.write_text(sim.od.to_eds(False))
        srv = bench.can.servers[0]
        bus = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        net = canopen.Network(bus)
        net.connect = lambda *a, **k: None  # the bus is already open
        net.notifier = can.Notifier(bus, net.listeners, 0.1)
        node = canopen.BaseNode402(NODE, str(eds))
        net.add_node(node)
        try:
            yield sim, node, net
        finally:
            net.sync.stop()
            net.notifier.stop()
            bus.shutdown()


def configure_pdos(node) -> None:
    """TPDO 1: statusword + mode display on every SYNC; TPDO 2: position on every SYNC;
    RPDO 1: target position (the controlword stays on SDO, so each write is confirmed)."""
    node.tpdo.read()
    node.rpdo.read()
    for pdo in (node.tpdo[1], node.tpdo[2], node.rpdo[1]):
        pdo.clear()
    node.tpdo[1].add_variable(0x6041)
    node.tpdo[1].add_variable(0x6061)
    node.tpdo[2].add_variable(0x6064)
    for tpdo in (node.tpdo[1], node.tpdo[2]):
        tpdo.trans_type = 1
        tpdo.enabled = True
    node.rpdo[1].add_variable(0x607A)
    node.rpdo[1].trans_type = 255
    node.rpdo[1].enabled = True
    for pdo in (node.tpdo[1], node.tpdo[2], node.rpdo[1]):
        pdo.save()


def test_basenode402_enables_moves_and_homes_the_simulator(drive):
    sim, node, net = drive
    # NMT: a heartbeat from the node, then PRE-OPERATIONAL for the PDO set-up.
    node.sdo[0x1017].raw = 50
    assert node.nmt.wait_for_heartbeat(2.0) == "PRE-OPERATIONAL"
    node.nmt.state = "PRE-OPERATIONAL"
    configure_pdos(node)
    node.setup_402_state_machine()           # reads the PDO set-up back, finds 6041h / 6061h in TPDO 1
    assert 0x6041 in node.tpdo_values and 0x607A in node.rpdo_pointers
    node.nmt.state = "OPERATIONAL"
    net.sync.start(0.01)                     # the TPDOs go out on every SYNC
    node.tpdo[1].wait_for_reception(2.0)
    assert node.nmt.wait_for_heartbeat(2.0) == "OPERATIONAL"

    node.sdo[0x6081].raw = 20000             # profile velocity, inc/s
    node.sdo[0x6083].raw = 200000
    node.sdo[0x6084].raw = 200000
    node.state = "SWITCH ON DISABLED"
    node.state = "OPERATION ENABLED"         # 2, 3, 4 as BaseNode402 walks the graph
    assert node.state == "OPERATION ENABLED"
    assert sim.state == "OPERATION ENABLED"
    node.op_mode = "PROFILED POSITION"
    assert node.op_mode == "PROFILED POSITION"

    # The target travels in RPDO 1; the set-point handshake by controlword (SDO).
    node.rpdo[1]["Target position"].raw = -3000
    node.rpdo[1].transmit()
    deadline = time.monotonic() + 2
    while node.sdo[0x607A].raw != -3000:
        assert time.monotonic() < deadline, "RPDO 1 did not set 607Ah"
        time.sleep(0.01)
    node.controlword = 0x1F                  # enable operation + new set-point
    node.check_statusword()
    assert node.statusword & 0x1000          # set-point acknowledge
    node.controlword = 0x0F
    node.check_statusword()
    assert not node.statusword & 0x1000      # dropped with bit 4
    deadline = time.monotonic() + 5
    while not node.check_statusword() & 0x0400 or not node.statusword & 0x0400:
        assert time.monotonic() < deadline, f"no target reached, statusword 0x{node.statusword:04X}"
    node.tpdo[2].wait_for_reception(1.0)
    assert node.tpdo[2]["Position actual value"].raw == -3000
    assert node.sdo[0x6064].raw == -3000
    assert round(sim.position) == -3000

    # Homing: method 19 searches the home switch (1000..1400 increments) in the positive
    # direction, from -3000; 607Ch = 250 is the position there.
    node.sdo[0x6098].raw = 19
    node.sdo[0x607C].raw = 250
    node.sdo[0x6099][1].raw = 20000
    node.sdo[0x6099][2].raw = 2000
    node.sdo[0x609A].raw = 200000
    assert node.homing(timeout=10) is True
    assert node.is_homed()
    assert node.sdo[0x6064].raw == 250
    assert node.op_mode == "HOMING"

    node.state = "SWITCH ON DISABLED"
    assert sim.state == "SWITCH ON DISABLED"


def test_basenode402_sees_a_fault_and_resets_it(drive):
    sim, node, net = drive
    node.nmt.state = "PRE-OPERATIONAL"
    configure_pdos(node)
    node.setup_402_state_machine()
    node.nmt.state = "OPERATIONAL"
    net.sync.start(0.01)
    node.tpdo[1].wait_for_reception(2.0)
    node.state = "SWITCH ON DISABLED"
    node.state = "OPERATION ENABLED"
    sim.inject_fault(0x5441)
    node.check_statusword()
    node.tpdo[1].wait_for_reception(1.0)
    assert node.is_faulted()
    assert node.sdo[0x603F].raw == 0x5441
    node.reset_from_fault()                  # bit 7 edge, then back to OPERATION ENABLED
    assert node.state == "OPERATION ENABLED"

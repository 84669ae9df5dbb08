"""The persona switch of one simulated DMX-CAN over real transports, with independent
peers only: pyserial on its pty (the ASCII front end) and python-can on a socketcand
server (the CANopen front end).  Store 200Ah = 2 over ASCII, power-cycle: it answers on
CAN and not on serial; store 200Ah = 0 over CAN, power-cycle: serial again, settings kept.
"""
import time

import can
import pytest
import serial

import motorbus
import motorbus._core as core
from motorbus.bus_server import BusServers
from motorbus.drives import arcus_canopen


def ascii_exchange(port: serial.Serial, cmd: str, timeout: float = 0.5) -> bytes:
    port.reset_input_buffer()
    port.write(f"@01{cmd}\r".encode())
    deadline = time.monotonic() + timeout
    out = b""
    while time.monotonic() < deadline:
        chunk = port.read(1)
        if chunk:
            out += chunk
            if chunk == b"\0":
                break
    return out


def sdo(bus: can.BusABC, data: bytes, timeout: float = 0.5) -> bytes:
    bus.send(can.Message(arbitration_id=0x601, data=data, is_extended_id=False))
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        m = bus.recv(0.05)
        if m is not None and m.arbitration_id == 0x581:
            return bytes(m.data)
    return b""


@pytest.fixture
def bench(tmp_path):
    with BusServers("virtual:arcus-persona", socketcand=["127.0.0.1:0"]) as servers, \
            motorbus.open_bus("virtual:arcus-persona") as sim_bus:
        sim = arcus_canopen.make_sim(1, protocol="ascii", store_path=str(tmp_path / "flash"), bus=sim_bus)
        pty = core.serial.PtyLineServer([sim], 0, None)
        port = serial.Serial(pty.slave_path, 9600, timeout=0.05)
        srv = servers.servers[0]
        pcan = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        try:
            yield sim, port, pcan
        finally:
            pcan.shutdown()
            port.close()
            pty.close()
            sim.close()


def test_the_persona_switch_both_ways_over_pty_and_socketcand(bench):
    sim, port, pcan = bench
    read_cm = bytes.fromhex("40 0A 20 00 00 00 00 00")
    # Factory fresh: RS-232 answers, CAN is silent.
    assert ascii_exchange(port, "CM") == b"0\0"
    assert sdo(pcan, read_cm) == b""
    assert ascii_exchange(port, "CURR=1234") == b"OK\0"
    assert ascii_exchange(port, "CM=2") == b"OK\0"
    assert ascii_exchange(port, "STORE") == b"OK\0"
    sim.power_cycle()
    # Now CAN: the boot-up was sent, SDO answers, the serial line is silent.
    assert sdo(pcan, read_cm) == bytes.fromhex("4F 0A 20 00 02 00 00 00")
    assert sdo(pcan, bytes.fromhex("40 04 20 02 00 00 00 00")) == bytes.fromhex("4B 04 20 02 D2 04 00 00")
    assert ascii_exchange(port, "CM") == b""
    # And back over CAN: 200Ah = 0, store, NMT reset node (= power cycle).
    assert sdo(pcan, bytes.fromhex("2B 04 20 02 39 05 00 00"))[0] == 0x60   # run current 1337 mA
    assert sdo(pcan, bytes.fromhex("2F 0A 20 00 00 00 00 00"))[0] == 0x60
    assert sdo(pcan, bytes.fromhex("2F 0E 20 00 01 00 00 00"))[0] == 0x60
    deadline = time.monotonic() + 2                                         # Fig. 8.2: poll until 0
    while sdo(pcan, bytes.fromhex("40 0E 20 00 00 00 00 00")) != bytes.fromhex("4F 0E 20 00 00 00 00 00"):
        assert time.monotonic() < deadline
        time.sleep(0.01)
    pcan.send(can.Message(arbitration_id=0, data=bytes([0x81, 1]), is_extended_id=False))
    deadline = time.monotonic() + 2
    while sim.active_protocol != 0:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert sdo(pcan, read_cm) == b""
    assert ascii_exchange(port, "CM") == b"0\0"
    assert ascii_exchange(port, "CURR") == b"1337\0"

"""`motorbus sim serve` serving CAN drives, with independent peers as clients.

A simulated CiA 402 node served by the command in its own process over socketcand
(127.0.0.1), reached by the `canopen` package through python-can's `socketcand`
interface (no motorbus code on the client side), and by motorbus's own Drive API.
"""
import signal
import subprocess
import sys
import time

import can
import canopen
import pytest

import motorbus


@pytest.fixture(scope="module")
def served():
    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", "--drive", "cia402:5,6",
                             "--bitrate", "1000000"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    word, hostport, channel = proc.stdout.readline().split()
    assert word == "socketcand" and channel == "can0"
    host, port = hostport.rsplit(":", 1)
    yield host, int(port)
    proc.send_signal(signal.SIGINT)
    assert proc.wait(10) == 0  # Ctrl-C ends the server cleanly


def test_canopen_over_python_can_socketcand_reads_and_drives_the_node(served):
    host, port = served
    bus = can.Bus(interface="socketcand", host=host, port=port, channel="can0")
    net = canopen.Network(bus)
    net.connect = lambda *a, **k: None  # the bus is already open
    net.notifier = can.Notifier(bus, net.listeners, 1)
    try:
        node = net.add_node(5, canopen.ObjectDictionary())
        sdo = node.sdo
        assert int.from_bytes(sdo.upload(0x1000, 0), "little") == 0x00420192
        assert sdo.upload(0x1008, 0) == b"motorbus CiA 402 sim"
        assert int.from_bytes(sdo.upload(0x6041, 0), "little") & 0x4F == 0x40   # SWITCH ON DISABLED
        sdo.download(0x6060, 0, b"\x01")                                         # profile position
        for cw in (0x06, 0x07, 0x0F):
            sdo.download(0x6040, 0, cw.to_bytes(2, "little"))
        assert int.from_bytes(sdo.upload(0x6041, 0), "little") & 0x6F == 0x27   # OPERATION ENABLED
        sdo.download(0x6081, 0, (50000).to_bytes(4, "little"))
        sdo.download(0x6083, 0, (1_000_000).to_bytes(4, "little"))
        sdo.download(0x6084, 0, (1_000_000).to_bytes(4, "little"))
        sdo.download(0x607A, 0, (2500).to_bytes(4, "little", signed=True))
        sdo.download(0x6040, 0, (0x3F).to_bytes(2, "little"))                  # new set-point, immediately
        sdo.download(0x6040, 0, (0x0F).to_bytes(2, "little"))
        deadline = time.monotonic() + 5
        while not int.from_bytes(sdo.upload(0x6041, 0), "little") & 0x400:     # target reached
            assert time.monotonic() < deadline
            time.sleep(0.01)
        assert int.from_bytes(sdo.upload(0x6064, 0), "little", signed=True) == 2500
        # An unsupported mode is refused with CiA 402's abort code.
        with pytest.raises(canopen.SdoAbortedError) as e:
            sdo.download(0x6060, 0, b"\x07")
        assert e.value.code == 0x06090030
    finally:
        net.notifier.stop()
        bus.shutdown()


def test_the_drive_api_on_the_other_node_through_the_same_server(served):
    host, port = served
    with motorbus.open_drive("cia402", bus=f"socketcand:{host}:{port}/can0", address=6,
                             units=motorbus.Units("mm", 0.01)) as axis:
        axis.params["Profile velocity"] = 50000
        axis.params["0x6083"] = 1_000_000
        axis.params["0x6084"] = 1_000_000
        axis.enable()
        axis.move_to(-12.5, timeout=10)
        assert axis.position == pytest.approx(-12.5, abs=0.01)
        assert axis.status.at_target and axis.status.enabled

"""Hardening (issue "Hardening"): the C++ core under faults and bad input, seen
from Python.  The checks live in C++; these tests show the typed errors reach
Python through the existing bindings."""
import itertools
import time

import pytest

import motorbus
from motorbus.canopen import LocalNode, ObjectDictionary, SdoAbortError, SdoClient, load_eds

_hub = itertools.count()


def _blob_node(block_transfer):
    name = f"hardening-core-{next(_hub)}"
    dev = motorbus.open_bus(f"virtual:{name}")
    host = motorbus.open_bus(f"virtual:{name}")
    od = ObjectDictionary()
    od.add_variable(0x2201, "Blob", "DOMAIN", "rw", max_size=1 << 16)
    node = LocalNode(dev, 5, od, block_transfer=block_transfer)
    return dev, host, node


# ---- defect 4: block means block -------------------------------------------------------------

def test_block_refused_is_an_abort_not_a_silent_segmented_transfer():
    dev, host, node = _blob_node(block_transfer=False)
    try:
        sdo = SdoClient(host, 5, timeout=0.5)
        sdo.download(0x2201, 0, b"x" * 100)  # segmented: fine
        with pytest.raises(SdoAbortError) as e:
            sdo.upload(0x2201, 0, block=True)
        assert e.value.code == 0x05040001
        with pytest.raises(SdoAbortError) as e:
            sdo.download(0x2201, 0, b"y" * 100, block=True)
        assert e.value.code == 0x05040001
        assert sdo.counters.fallbacks == 0
        # Opting in gives the old behaviour, counted.
        fb = SdoClient(host, 5, timeout=0.5, block_fallback=True)
        assert fb.upload(0x2201, 0, block=True) == b"x" * 100
        assert fb.counters.fallbacks == 1
    finally:
        node.close()
        host.close()
        dev.close()


# ---- defect 9: load_eds is bounded -----------------------------------------------------------

def test_load_eds_refuses_an_endless_file_fast():
    t0 = time.monotonic()
    with pytest.raises(motorbus.InvalidArgument, match=r"/dev/zero.*16 MiB"):
        load_eds("/dev/zero")
    assert time.monotonic() - t0 < 2.0


# ---- defects 1 and 11: invalid values are refused where they enter the core ---------------

@pytest.mark.parametrize("kwargs,name", [({"rx_queue_size": 0}, "rx_queue_size"),
                                         ({"tx_queue": 0, "bitrate": 500_000}, "tx_queue")])
def test_bus_size_options_zero_refused(kwargs, name):
    with pytest.raises(motorbus.InvalidArgument, match=name):
        motorbus.open_bus(f"virtual:hardening-core-{next(_hub)}", **kwargs)


@pytest.mark.parametrize("field", ["drop_probability", "corrupt_probability"])
@pytest.mark.parametrize("p", [-0.1, 1.5, float("nan")])
def test_fault_probability_outside_unit_interval_refused(field, p):
    with motorbus.open_bus(f"virtual:hardening-core-{next(_hub)}") as bus:
        with pytest.raises(motorbus.InvalidArgument, match=field):
            bus.set_faults(**{field: p})
        bus.set_faults(**{field: 1.0})


@pytest.mark.parametrize("size", [0, 128, 255])
def test_sdo_block_size_outside_1_127_refused(size):
    with motorbus.open_bus(f"virtual:hardening-core-{next(_hub)}") as bus:
        with pytest.raises(motorbus.InvalidArgument, match="block_size.*1-127"):
            SdoClient(bus, 5, block_size=size)


def test_duplicate_local_node_on_one_hub_refused():
    name = f"hardening-core-{next(_hub)}"
    with motorbus.open_bus(f"virtual:{name}") as a, motorbus.open_bus(f"virtual:{name}") as b:
        od = ObjectDictionary()
        od.add_variable(0x2000, "U8", "u8", "rw")
        first = LocalNode(a, 5, od)
        with pytest.raises(motorbus.InvalidArgument, match="node_id: 5"):
            LocalNode(a, 5, od)
        with pytest.raises(motorbus.InvalidArgument, match="node_id: 5"):
            LocalNode(b, 5, od)
        first.close()
        LocalNode(b, 5, od).close()


def test_heartbeat_period_below_1ms_refused():
    from motorbus.canopen import HeartbeatProducer
    with motorbus.open_bus(f"virtual:hardening-core-{next(_hub)}") as bus:
        with pytest.raises(motorbus.InvalidArgument, match="1 ms"):
            HeartbeatProducer(bus, 5, 1e-9)
        HeartbeatProducer(bus, 5, 0.001)


# ---- defect 6: a dead socketcand link wakes its waiters --------------------------------------

@pytest.mark.threaded
def test_socketcand_waiting_recv_gets_linkdown_when_the_server_goes():
    import threading
    from motorbus.socketcand import SocketcandServer, open_socketcand
    served = motorbus.open_bus(f"virtual:hardening-core-{next(_hub)}")
    server = SocketcandServer(served, host="127.0.0.1", port=0)
    bus = open_socketcand("127.0.0.1", server.port, "can0", keepalive=None)
    outcome = []

    def wait_forever():
        try:
            outcome.append(bus.recv(timeout=None))
        except BaseException as e:  # noqa: BLE001 - the type is what we check
            outcome.append(e)

    t = threading.Thread(target=wait_forever, daemon=True)
    t.start()
    time.sleep(0.05)
    t0 = time.monotonic()
    server.close()
    t.join(timeout=1.0)
    try:
        assert not t.is_alive(), "recv(timeout=None) still blocked 1 s after the server closed"
        assert isinstance(outcome[0], motorbus.LinkDown), outcome
        assert time.monotonic() - t0 < 1.0
        with pytest.raises(motorbus.LinkDown):
            bus.recv_many(timeout=None)
        with pytest.raises(motorbus.LinkDown):
            bus.send(motorbus.Frame(0x1, b""))
    finally:
        bus.close()
        served.close()


# ---- defect 3: one serial line, one opener ---------------------------------------------------

def test_pty_slave_opens_once_in_this_process_and_from_a_child():
    import os
    import subprocess
    import sys
    from motorbus.serial import PtyLineServer, PtyPair, open_port
    with PtyPair() as pty:
        first = open_port(pty.slave_path, 0)
        with pytest.raises(motorbus.LinkDown, match=rf"{pty.slave_path}.*busy.*pid {os.getpid()}"):
            open_port(pty.slave_path, 0)
        child = subprocess.run(
            [sys.executable, "-c",
             "import sys, motorbus\n"
             "from motorbus.serial import open_port\n"
             "try:\n"
             "    open_port(sys.argv[1], 0)\n"
             "except motorbus.LinkDown as e:\n"
             "    print(e); sys.exit(0)\n"
             "sys.exit(1)\n", pty.slave_path],
            capture_output=True, text=True, timeout=30)
        assert child.returncode == 0, "the child opened a port this process holds"
        assert f"pid {os.getpid()}" in child.stdout
        first.close()
        open_port(pty.slave_path, 0).close()  # free again once closed
    with PtyLineServer([]) as server:
        client = open_port(server.slave_path, 115200)
        with pytest.raises(motorbus.LinkDown, match="busy"):
            open_port(server.slave_path, 115200)
        client.close()

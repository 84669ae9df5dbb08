"""A CiA 402 drive object stops its motor: on an exception leaving ``with``, at
interpreter exit, and (through the drive's own heartbeat consumer, 0x1016 and
0x6007) when the host's link is lost.  Against a simulated CiA 402 node served
by LocalNode over a virtual bus, the way a real drive is reached."""
import itertools
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

import motorbus
from motorbus import _core
from motorbus.canopen import LocalNode, ObjectDictionary
from motorbus.canopen.cia402 import Cia402, Cia402Device
from motorbus.canopen.heartbeat import HeartbeatService
from polling import wait_for

_hub = itertools.count()
REPO = Path(__file__).resolve().parents[2]


class Cia402Node:
    """Cia402Device behind an object dictionary: 0x6040/0x6041/0x6060/0x6061/0x6007,
    with a heartbeat consumer (0x1016) whose loss applies 0x6007 (CiA 402 D5)."""

    def __init__(self, bus, node_id=5):
        self.dev = Cia402Device()
        self.lost = threading.Event()
        od = ObjectDictionary()
        cw = od.add_variable(0x6040, "Controlword", "U16")
        cw.set_write_hook(lambda var, data: self._controlword(int.from_bytes(data, "little")))
        sw = od.add_variable(0x6041, "Statusword", "U16", access="ro")
        sw.set_read_hook(lambda var, current: self.dev.statusword.to_bytes(2, "little"))
        mode = od.add_variable(0x6060, "Modes of operation", "I8")
        mode.set_write_hook(lambda var, data: self.dev.set_mode(int.from_bytes(data, "little", signed=True)) or None)
        od.add_variable(0x6061, "Modes of operation display", "I8", access="ro").set_read_hook(
            lambda var, current: (self.dev.mode & 0xFF).to_bytes(1, "little"))
        self.abort_option = od.add_variable(0x6007, "Abort connection option code", "I16", default=1)
        self.abort_option.set_write_hook(
            lambda var, data: self.dev.set_abort_connection_option(int.from_bytes(data, "little", signed=True)) or None)
        self.od = od
        self.node = LocalNode(bus, node_id, od)
        self.heartbeat = HeartbeatService(self.node, consumer_entries=2)
        self.heartbeat.set_lost_callback(lambda n: (self.dev.loss_of_master(), self.lost.set()))

    def _controlword(self, value):
        self.dev.on_controlword(value)
        return None

    def close(self):
        self.node.close()


@pytest.fixture()
def bench():
    name = f"cia402-safety-{next(_hub)}"
    dev_bus, host_bus = _core.can.open_virtual(name), _core.can.open_virtual(name)
    node = Cia402Node(dev_bus)
    yield node, host_bus
    node.close()
    host_bus.close()
    dev_bus.close()


def test_exception_leaving_with_quick_stops_the_drive(bench):
    node, host = bench
    with pytest.raises(RuntimeError, match="script failed"):
        with Cia402(host, 5, timeout=1.0, poll=0.001) as drive:
            drive.enable()
            assert node.dev.state == "OPERATION ENABLED"
            raise RuntimeError("script failed")
    assert node.dev.controlword == 0x0002
    assert node.dev.state == "QUICK STOP ACTIVE"


def test_disable_voltage_on_error_and_a_clean_exit_leaves_the_motor_alone(bench):
    node, host = bench
    with Cia402(host, 5, timeout=1.0, poll=0.001) as drive:
        drive.enable()
    assert node.dev.state == "OPERATION ENABLED"  # no exception: nothing to stop
    with pytest.raises(KeyError):
        with Cia402(host, 5, timeout=1.0, poll=0.001, on_error="disable"):
            raise KeyError("x")
    assert node.dev.controlword == 0x0000
    assert node.dev.state == "SWITCH ON DISABLED"


def test_watchdog_arms_the_drives_heartbeat_consumer_and_the_drive_stops_when_the_host_goes(bench):
    node, host = bench
    drive = Cia402(host, 5, timeout=1.0, poll=0.001)
    drive.enable()
    drive.start_watchdog(host_node=1, period=0.02)
    assert node.od[0x1016, 1].value == (1 << 16) | 60  # node 1, 3 periods
    assert node.abort_option.value == 3                # quick stop
    # The host's heartbeat arrives: the drive watches it and stays enabled.
    assert wait_for(lambda: node.heartbeat.health(1).state == "OPERATIONAL", 2.0)
    assert node.dev.state == "OPERATION ENABLED"
    host.close()  # the cable is pulled: no more heartbeats, no SDO either
    assert node.lost.wait(2.0)
    assert node.dev.state == "QUICK STOP ACTIVE"
    drive.close()  # the drive is unreachable now: close must not raise


def test_clean_close_disarms_the_watchdog_before_the_heartbeat_stops(bench):
    node, host = bench
    drive = Cia402(host, 5, timeout=1.0, poll=0.001)
    drive.enable()
    drive.start_watchdog(host_node=1, period=0.02, timeout=0.06, action="fault")
    assert node.abort_option.value == 1
    drive.close()
    assert node.od[0x1016, 1].value == 0
    time.sleep(0.3)  # five consumer times: a lost master would have been reported by now
    assert not node.lost.is_set()
    assert node.dev.state == "OPERATION ENABLED"


def test_watchdog_arguments_are_checked(bench):
    node, host = bench
    drive = Cia402(host, 5, timeout=1.0, poll=0.001)
    with pytest.raises(motorbus.InvalidArgument, match="action"):
        drive.start_watchdog(host_node=1, action="explode")
    with pytest.raises(motorbus.InvalidArgument, match="host_node"):
        drive.start_watchdog(host_node=5)
    with pytest.raises(motorbus.InvalidArgument, match="timeout"):
        drive.start_watchdog(host_node=1, period=0.1, timeout=0.05)
    with pytest.raises(motorbus.InvalidArgument, match="on_error"):
        Cia402(host, 5, on_error="brake")
    drive.close()


@pytest.mark.subprocess
def test_drives_still_open_at_interpreter_exit_are_quick_stopped():
    # The checker is registered before motorbus is imported, so it runs after
    # motorbus's own exit hook (atexit is last-in, first-out).
    script = textwrap.dedent(f"""
        import atexit, sys
        sys.path[:0] = [{str(REPO / "tests" / "python")!r}, {str(REPO / "tests")!r}]
        state = {{}}
        atexit.register(lambda: print("STATE", state["node"].dev.state, hex(state["node"].dev.controlword)))
        from motorbus import _core
        from motorbus.canopen.cia402 import Cia402
        from test_canopen_cia402_safety import Cia402Node
        dev, host = _core.can.open_virtual("exit"), _core.can.open_virtual("exit")
        state["node"] = Cia402Node(dev)
        drive = Cia402(host, 5, timeout=1.0, poll=0.001)
        drive.enable()
        print("ENABLED", state["node"].dev.state)
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert "ENABLED OPERATION ENABLED" in out.stdout
    assert "STATE QUICK STOP ACTIVE 0x2" in out.stdout, out.stdout + out.stderr

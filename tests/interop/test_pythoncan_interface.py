"""The motorbus python-can interface behaves like python-can's own buses.

Reference: python-can's ``can/interfaces/virtual.py`` and ``can/bus.py``: every error
is a ``can.CanError``, a receive that gets nothing returns None, operations after
``shutdown()`` raise ``CanOperationError``, and CAN FD is refused on a classic-CAN
interface with python-can's "not implemented" error.
"""
import threading
import time

import can
import pytest

import motorbus
from motorbus import Frame


def _mb(name, **kw):
    return can.Bus(interface="motorbus", channel=f"virtual:{name}", **kw)


def test_recv_in_flight_at_shutdown_returns_none():
    """A recv() blocked when another thread shuts the bus down returns None, promptly."""
    for timeout in (5.0, None):
        bus = _mb("sem-inflight")
        got = {}

        def reader():
            try:
                got["msg"] = bus.recv(timeout)
            except BaseException as e:  # noqa: BLE001 - the test reports it
                got["err"] = e

        t = threading.Thread(target=reader)
        t.start()
        time.sleep(0.1)
        t0 = time.monotonic()
        bus.shutdown()
        t.join(2.0)
        assert not t.is_alive()
        assert time.monotonic() - t0 < 1.0
        assert got == {"msg": None}, got


def test_operations_after_shutdown_raise_can_operation_error():
    bus = _mb("sem-after")
    bus.shutdown()
    with pytest.raises(can.CanOperationError):
        bus.recv(0)
    with pytest.raises(can.CanOperationError):
        bus.recv(0.05)
    with pytest.raises(can.CanOperationError):
        bus.send(can.Message(arbitration_id=0x1))
    with pytest.raises(can.CanOperationError):
        bus.set_filters([{"can_id": 0x1, "can_mask": 0x7FF}])
    bus.shutdown()  # twice is fine


def test_underlying_bus_closed_is_a_can_operation_error():
    bus = _mb("sem-under")
    try:
        bus.motorbus_bus.close()
        with pytest.raises(can.CanOperationError) as e:
            bus.recv(0.05)
        assert isinstance(e.value.__cause__, motorbus.ClosedError)
        with pytest.raises(can.CanOperationError):
            bus.send(can.Message(arbitration_id=0x1))
    finally:
        bus.shutdown()


def test_send_errors_are_can_operation_errors():
    bus = _mb("sem-send")
    try:
        bus.motorbus_bus.set_bus_off(True)
        with pytest.raises(can.CanOperationError) as e:
            bus.send(can.Message(arbitration_id=0x1))
        assert isinstance(e.value.__cause__, motorbus.LinkDown)
        bus.motorbus_bus.set_bus_off(False)
        with pytest.raises(can.CanOperationError):
            bus.send(can.Message(arbitration_id=0x1, data=b"\x00" * 9, check=False))
    finally:
        bus.shutdown()


def test_notifier_survives_shutdown():
    """python-can's Notifier thread ends cleanly when the bus shuts down under its
    in-flight recv(): Notifier.stop(timeout=0) then shutdown(), as canopen's tests do."""
    bus = _mb("sem-notifier")
    peer = motorbus.open_bus("virtual:sem-notifier")
    reader = can.BufferedReader()
    notifier = can.Notifier(bus, [reader], timeout=1.0)
    threads = [t for t in notifier._readers if isinstance(t, threading.Thread)]
    try:
        peer.send(Frame(0x123, b"\x01"))
        assert reader.get_message(1.0).arbitration_id == 0x123
        time.sleep(0.05)
        notifier.stop(timeout=0)
        bus.shutdown()      # the Notifier's recv(1.0) is in flight
        for t in threads:
            t.join(2.0)
            assert not t.is_alive()
        assert notifier.exception is None
    finally:
        notifier.stop()
        bus.shutdown()
        peer.close()


def test_notifier_errors_after_shutdown_are_can_errors():
    """A Notifier left running on a shut-down bus gets CanOperationError (a CanError,
    which its listeners' on_error handle), as on python-can's virtual bus."""
    bus = _mb("sem-notifier-2")
    errors = []
    listener = type("L", (can.Listener,), {
        "on_message_received": lambda self, m: None,
        "on_error": lambda self, exc: errors.append(exc)})()
    notifier = can.Notifier(bus, [listener], timeout=0.05)
    try:
        time.sleep(0.02)
        bus.shutdown()
        time.sleep(0.2)
    finally:
        notifier.stop()
    assert errors and all(type(e) is can.CanOperationError for e in errors)


def test_canopen_network_disconnect_reports_no_error():
    """canopen re-raises in disconnect() what killed its Notifier thread; with no
    shutdown timeout (as canopen's own tests do) the bus closes under a waiting recv."""
    import canopen

    net = canopen.Network()
    net.NOTIFIER_SHUTDOWN_TIMEOUT = 0.0
    net.connect(interface="motorbus", channel="virtual:sem-canopen")
    threads = [t for t in net.notifier._readers if isinstance(t, threading.Thread)]
    time.sleep(0.05)
    net.disconnect()
    for t in threads:
        t.join(2.0)
        assert not t.is_alive()
    net.check()


def test_can_fd_is_refused():
    with pytest.raises(can.CanInterfaceNotImplementedError, match="CAN FD is not supported"):
        _mb("sem-fd", fd=True)
    with pytest.raises(can.CanInterfaceNotImplementedError):
        _mb("sem-fd", timing=can.BitTimingFd.from_sample_point(
            f_clock=80_000_000, nom_bitrate=500_000, nom_sample_point=80.0,
            data_bitrate=2_000_000, data_sample_point=80.0))
    bus = _mb("sem-fd", fd=False)
    try:
        with pytest.raises(can.CanOperationError, match="CAN FD"):
            bus.send(can.Message(arbitration_id=0x1, is_fd=True, data=b"\x01"))
        assert bus.protocol == can.CanProtocol.CAN_20
    finally:
        bus.shutdown()


def test_open_errors_are_can_initialization_errors():
    with pytest.raises(can.CanInitializationError):
        can.Bus(interface="motorbus", channel="nosuchscheme:x")
    with pytest.raises(can.CanInitializationError):
        can.Bus(interface="motorbus", channel="virtual:sem-init", rx_spin=-1.0)


def test_state_maps_to_python_can():
    bus = _mb("sem-state")
    try:
        assert bus.state == can.BusState.ACTIVE
        bus.motorbus_bus.set_bus_off(True)
        assert bus.state == can.BusState.ERROR
    finally:
        bus.shutdown()


_EXIT_SCRIPT = r"""
import sys, threading, time
import can, canopen
bus = can.Bus(interface="motorbus", channel="virtual:exit")
def reader():
    while True:
        bus.recv(0.05)
for _ in range(3):
    threading.Thread(target=reader, daemon=True).start()
net = canopen.Network()               # left connected: its Notifier thread is a daemon
net.connect(interface="motorbus", channel="virtual:exit")
time.sleep(float(sys.argv[1]))
"""


@pytest.mark.subprocess
def test_interpreter_exit_with_buses_open_does_not_abort():
    """Daemon threads waiting in recv() when the interpreter exits (a Notifier left
    running): the process exits normally instead of aborting in std::terminate."""
    import subprocess
    import sys

    for i in range(6):
        r = subprocess.run([sys.executable, "-c", _EXIT_SCRIPT, str(0.02 + 0.03 * i)],
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == 0 and "terminate" not in r.stderr, (r.returncode, r.stderr[-2000:])

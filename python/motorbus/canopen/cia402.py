"""CiA 402 on the host (Cia402) and on a simulated device (Cia402Device).

    from motorbus.canopen import Cia402, OpMode
    drive = Cia402(bus, node=5)                  # or an SDO client object
    drive.use_statusword_pdo(rx)                # optional: wait on TPDOs, not SDO polls
    drive.set_mode(OpMode.PROFILE_POSITION)
    drive.go_to("OPERATION ENABLED")            # walks 2, 3, 4 (fault reset first if needed)
    drive.move_to(10_000)                       # new set-point / acknowledge handshake
    drive.wait_target_reached(timeout=5.0)

A statusword outside the CiA 402 table decodes as "UNKNOWN" and is never taken
for "OPERATION ENABLED".
"""
from __future__ import annotations

import enum
from typing import Optional

from .. import _core, _stop_at_exit
from ..stopping import check_stop_way

__all__ = ["ABORT_CONNECTION_ACTIONS", "Cia402", "Cia402Device", "OpMode", "STATES",
           "decode_statusword", "Controlword", "next_step"]

STATES = ("NOT READY TO SWITCH ON", "SWITCH ON DISABLED", "READY TO SWITCH ON", "SWITCHED ON",
          "OPERATION ENABLED", "QUICK STOP ACTIVE", "FAULT REACTION ACTIVE", "FAULT", "UNKNOWN")

from .._core.canopen import (  # noqa: E402,F401
    cia402_decode_statusword as decode_statusword, cia402_next_step as next_step,
)


class OpMode(enum.IntEnum):
    NONE = 0
    PROFILE_POSITION = 1
    VELOCITY = 2
    PROFILE_VELOCITY = 3
    PROFILE_TORQUE = 4
    HOMING = 6
    INTERPOLATED_POSITION = 7
    CYCLIC_SYNC_POSITION = 8
    CYCLIC_SYNC_VELOCITY = 9
    CYCLIC_SYNC_TORQUE = 10


class Controlword(enum.IntEnum):
    SHUTDOWN = 0x0006
    SWITCH_ON = 0x0007
    DISABLE_VOLTAGE = 0x0000
    QUICK_STOP = 0x0002
    DISABLE_OPERATION = 0x0007
    ENABLE_OPERATION = 0x000F
    FAULT_RESET = 0x0080


# 0x6007 abort connection option codes (CiA 402): what the drive does by itself
# when it loses its master (heartbeat missing, bus-off ...).
ABORT_CONNECTION_ACTIONS = {"fault": 1, "disable_voltage": 2, "quick_stop": 3}


class Cia402(_stop_at_exit.StopsMotor, _core.canopen.Cia402Host):
    """Host-side CiA 402 state machine of one drive.

    ``Cia402(bus_or_sdo, node, timeout=2.0, poll=0.005, on_error="quick_stop",
    on_exit="quick_stop", bus=None)`` -- ``bus``: where :meth:`start_watchdog`
    produces its heartbeat when the first argument is an SDO client
    (``node.cia402`` of a Network passes the network's bus).

    Safety, as for every motorbus drive object:

    * as a context manager it stops the motor when an exception leaves the block
      (``on_error``: "quick_stop" = controlword Quick Stop, the drive decelerates
      with its 605Ah option; "disable" = Disable Voltage, the power stage is
      switched off at once; None = leave it);
    * a drive still open when the interpreter exits is stopped with ``on_exit``;
    * :meth:`start_watchdog` arms the drive's own heartbeat consumer (0x1016) on
      a heartbeat this host produces, and sets what the drive does when it stops
      arriving (0x6007): a crashed host, a pulled cable or a dead adapter stop
      the motor without any help from the host.
    """

    def __init__(self, sdo, node: int, timeout: float = 2.0, poll: float = 0.005, *,
                 on_error: Optional[str] = "quick_stop", on_exit: Optional[str] = "quick_stop",
                 bus: Optional[_core.can.Bus] = None) -> None:
        check_stop_way(on_error, "Cia402 on_error", _HALTS)
        check_stop_way(on_exit, "Cia402 on_exit", _HALTS)
        if isinstance(sdo, _core.can.Bus):
            # One SDO client for the state machine and the watchdog set-up: two
            # clients on one COB-ID would take each other's responses.
            self._bus = sdo
            sdo = _core.canopen.SdoClient(sdo, node, timeout=timeout)
        else:
            self._bus = bus
        super().__init__(sdo, node, timeout, poll)
        self._sdo = sdo
        self._node = node
        self._on_error = on_error
        self._on_exit = on_exit
        self._heartbeat: Optional[_core.canopen.HeartbeatProducer] = None
        self._watchdog_sub: Optional[int] = None
        self._closed = False
        _stop_at_exit.track(self)

    @property
    def sdo(self):
        """The SDO client this drive object talks through (one per node: a second
        client on the same COB-IDs would take this one's responses)."""
        return self._sdo

    @property
    def node(self) -> int:
        """The drive's CANopen node-ID."""
        return self._node

    @property
    def bus(self) -> Optional[_core.can.Bus]:
        """The bus this drive object was opened on (None when given only an SDO client)."""
        return self._bus

    def set_mode(self, mode: int) -> None:  # accepts OpMode or int
        super().set_mode(int(mode))

    @property
    def op_mode(self) -> OpMode:
        return OpMode(self.mode)

    def enable(self) -> None:
        self.go_to("OPERATION ENABLED")

    def disable(self) -> None:
        self.go_to("SWITCH ON DISABLED")

    # ---- link-loss watchdog: the drive's own heartbeat consumer ----
    def start_watchdog(self, host_node: int, period: float = 0.1, timeout: Optional[float] = None,
                       action: str = "quick_stop", bus=None, entry: int = 1) -> None:
        """Produce a heartbeat as node ``host_node`` every ``period`` seconds and
        make the drive watch it: 0x1016:``entry`` = host_node / ``timeout``
        (default 3 periods, at least 10 ms more than the period), 0x6007 =
        ``action`` ("quick_stop", "disable_voltage" or "fault").  ``bus``: where
        to produce it (default: the bus this drive was opened on)."""
        if action not in ABORT_CONNECTION_ACTIONS:
            raise _core.InvalidArgument(
                f"start_watchdog action: one of {sorted(ABORT_CONNECTION_ACTIONS)}, not {action!r}")
        if not 1 <= int(host_node) <= 127 or int(host_node) == self._node:
            raise _core.InvalidArgument(f"start_watchdog host_node: 1-127 and not the drive's own id, not {host_node}")
        if not period > 0:
            raise _core.InvalidArgument(f"start_watchdog period: must be > 0 s, not {period}")
        timeout_ms = round((timeout if timeout is not None else max(3 * period, period + 0.01)) * 1000)
        if not period * 1000 < timeout_ms <= 0xFFFF:
            raise _core.InvalidArgument(
                f"start_watchdog timeout: {timeout_ms} ms must exceed the period ({period * 1000:g} ms) and fit 16 bits")
        bus = bus if bus is not None else self._bus
        if bus is None:
            raise _core.InvalidArgument("start_watchdog: pass bus= (this drive was opened on an SDO client)")
        self.stop_watchdog()
        # Produce first, then arm the consumer: the drive must never watch a silent producer.
        hb = _core.canopen.HeartbeatProducer(bus, int(host_node), period)
        hb.start()
        self._heartbeat = hb
        try:
            self._sdo.download(0x6007, 0, ABORT_CONNECTION_ACTIONS[action].to_bytes(2, "little", signed=True))
            self._sdo.download(0x1016, entry, ((int(host_node) << 16) | timeout_ms).to_bytes(4, "little"))
        except Exception:
            hb.stop()
            self._heartbeat = None
            raise
        self._watchdog_sub = entry

    def stop_watchdog(self) -> None:
        """Disarm the drive's consumer entry first, then stop producing (a clean
        stop must not look like a lost master)."""
        if self._watchdog_sub is not None:
            try:
                self._sdo.download(0x1016, self._watchdog_sub, (0).to_bytes(4, "little"))
            finally:
                self._watchdog_sub = None
        if self._heartbeat is not None:
            self._heartbeat.stop()
            self._heartbeat = None

    # ---- lifecycle ----
    def _stop_on_error(self) -> None:
        self._halt(self._on_error)

    def close(self) -> None:
        """Stop the watchdog cleanly and forget this drive for the exit-time stop.
        The motor is left as it is (use ``with`` or ``on_exit`` to stop it)."""
        if self._closed:
            return
        self._closed = True
        _stop_at_exit.untrack(self)
        try:
            self.stop_watchdog()
        except Exception:  # noqa: BLE001 - the drive may be unreachable; its watchdog then acts
            if self._heartbeat is not None:
                self._heartbeat.stop()
                self._heartbeat = None

    def _stop_at_exit(self) -> None:
        self._halt(self._on_exit)
        # Leave the heartbeat to stop with the process: the drive's watchdog
        # then applies 0x6007 too, should the stop above not have reached it.

    def _halt(self, how: Optional[str]) -> None:
        if self._closed:
            return

        def quick_stop() -> None:
            self.write_controlword(int(Controlword.QUICK_STOP))

        def disable() -> None:
            self.write_controlword(int(Controlword.DISABLE_VOLTAGE))
        # The words' ladder is _stop_at_exit.halt's ("stop" is not one of this host's words).
        _stop_at_exit.halt(how, quick_stop, quick_stop, disable)


#: The stop words this host has (stopping.py's minus "stop": the controlword's own
#: decelerated stop is a halt the Drive layer drives, not one the host applies on unwinding).
_HALTS = ("quick_stop", "disable", None)


#: The device-side state machine for simulators (C++ Cia402Device).
Cia402Device = _core.canopen.Cia402Device

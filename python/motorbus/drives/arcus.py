"""Arcus DMX-CAN drives over their ASCII line (RS-232 or RS-485 multi-drop).

    from motorbus.drives.arcus import ArcusClient
    with ArcusClient("/dev/ttyUSB0", address="01", baud=9600) as drive:
        drive.enable()
        drive.high_speed = 2000     # HSPD (a read/write property)
        drive.move(4000)            # X4000: counts with StepNLoop on, pulses without
        drive.wait_idle(timeout=10)
        print(drive.position, drive.status)

A simulator for tests and demos (``make_sim``) answers on a pty exactly like the
device; ``motorbus sim serve --pty --drive arcus:01`` uses it.
"""
from __future__ import annotations

import enum
import os
from typing import Any, Optional, Union

from .. import _core, _stop_at_exit
from .._core import ArcusClientBase, ArcusSim  # noqa: F401  (re-exported)

__all__ = [
    "ArcusClient",
    "ArcusSim",
    "MotorStatus",
    "SnlStatus",
    "LatchStatus",
    "SyncStatus",
    "SyncCondition",
    "LINE_SETTINGS",
    "REQUEST_TERMINATOR",
    "REPLY_TERMINATOR",
    "make_sim",
    "open_line",
    "STOP_WAYS",
    "build_request",
    "parse_reply",
]

REQUEST_TERMINATOR = b"\r"
REPLY_TERMINATOR = b"\0"
# What a PtyLineServer / LineLink needs to frame this protocol.
LINE_SETTINGS = {
    "request_terminator": REQUEST_TERMINATOR,
    "reply_terminators": [REPLY_TERMINATOR],
    "max_line": _core.ARCUS_MAX_REPLY,
}

build_request = _core.arcus_build_request
parse_reply = _core.arcus_parse_reply


class MotorStatus(enum.IntFlag):
    """MST bits (Table 7.3)."""

    CONSTANT_SPEED = 1 << 0
    ACCELERATING = 1 << 1
    DECELERATING = 1 << 2
    HOME = 1 << 3
    MINUS_LIMIT = 1 << 4
    PLUS_LIMIT = 1 << 5
    MINUS_LIMIT_ERROR = 1 << 6
    PLUS_LIMIT_ERROR = 1 << 7
    LATCH_INPUT = 1 << 8
    Z_INDEX = 1 << 9

    @property
    def moving(self) -> bool:
        return bool(self & (MotorStatus.CONSTANT_SPEED | MotorStatus.ACCELERATING | MotorStatus.DECELERATING))

    @property
    def limit_error(self) -> bool:
        return bool(self & (MotorStatus.MINUS_LIMIT_ERROR | MotorStatus.PLUS_LIMIT_ERROR))


class SnlStatus(enum.IntEnum):
    """SLS values (Table 7.6; 12 and 13 from Table 8.14)."""

    IDLE = 0
    MOVING = 1
    CORRECTING = 2
    STOPPING = 3
    ABORTING = 4
    JOGGING = 5
    HOMING = 6
    Z_HOMING = 7
    CORRECTION_RANGE_ERROR = 8
    CORRECTION_ATTEMPT_ERROR = 9
    STALL_ERROR = 10
    LIMIT_ERROR = 11
    DISABLED = 12
    LIMIT_HOMING = 13

    @property
    def is_error(self) -> bool:
        return 8 <= self.value <= 11


class LatchStatus(enum.IntEnum):
    """LTS (Table 7.4)."""

    OFF = 0
    WAITING = 1
    TRIGGERED = 2


class SyncStatus(enum.IntEnum):
    """SYNS."""

    OFF = 0
    WAITING = 1
    OCCURRED = 2


class SyncCondition(enum.IntEnum):
    """SYNC: DO2 turns on when the encoder is equal to / less than / greater than SYNP."""

    EQUAL = 1
    LESS = 2
    GREATER = 3


def open_line(port: Union[str, "os.PathLike[str]", "_core.Port"], *, baud: int = 9600, timeout: float = 0.2,
              turnaround: float = 0.0) -> "_core.LineLink":
    """A LineLink framed for DMX-CAN (CR after requests, NUL after replies).

    ``port``: a device path (opened at ``baud``) or an open ``motorbus.serial.Port``.
    ``timeout``: seconds to wait for a reply; ``turnaround``: seconds of quiet
    before each request (slow RS-485 transceivers).  Share the link between
    several ArcusClient objects to talk to up to 99 devices on one RS-485 line."""
    if isinstance(port, (str, os.PathLike)):
        port = _core.open_port(os.fspath(port), baud)
    elif not isinstance(port, _core.Port):
        raise _core.InvalidArgument(f"arcus open_line: a path or a motorbus Port, not {type(port).__name__}")
    return _core.LineLink(port, request_terminator=REQUEST_TERMINATOR, reply_terminators=[REPLY_TERMINATOR],
                          max_line=_core.ARCUS_MAX_REPLY, reply_timeout=timeout, turnaround=turnaround)


#: on_error / on_exit words, the same as motorbus.Drive's.
STOP_WAYS = ("stop", "quick_stop", "disable", None)


class ArcusClient(_stop_at_exit.StopsMotor, ArcusClientBase):
    """Typed client for one DMX-CAN.

    ``line``: a device path (opened with :func:`open_line` at ``baud`` and
    closed by :meth:`close`), an open ``motorbus.serial.Port``, or a
    ``LineLink`` from :func:`open_line` shared with other clients on the same
    RS-485 line (neither is closed by :meth:`close`).  ``address``: ``"01"``..
    ``"99"``, ``"DMC05"`` or an int.  ``timeout``: reply timeout in s (None: the
    link's, 0.2 s for a line opened here).

    Readings are properties (``position``, ``encoder``, ``speed``, ``status``
    -> :class:`MotorStatus`, ``snl_status`` -> :class:`SnlStatus`, ...);
    settings are read/write properties (``client.high_speed = 10000``);
    commands are methods.

    As a context manager it stops the motor when an exception leaves the block
    (``on_error``) and, for clients still open when the interpreter exits, with
    ``on_exit``: "stop" (STOP, decelerated), "quick_stop" (ABORT, at once),
    "disable" (EO=0, power off) or None.  A failed stop falls back to the next
    harder one.
    """

    def __init__(self, line: Any, address: Union[int, str] = "01", *, baud: int = 9600,
                 timeout: Optional[float] = None, on_error: Optional[str] = "stop",
                 on_exit: Optional[str] = "stop", query_retries: int = 1):
        for name, v in (("on_error", on_error), ("on_exit", on_exit)):
            if v not in STOP_WAYS:
                raise _core.InvalidArgument(f"{name}: one of 'stop', 'quick_stop', 'disable' or None, not {v!r}")
        number = _address(address)
        self._owned_port = None
        if isinstance(line, _core.LineLink):
            link = line
        elif isinstance(line, _core.Port):
            link = open_line(line, timeout=0.2 if timeout is None else timeout)
        else:
            link = open_line(line, baud=baud, timeout=0.2 if timeout is None else timeout)
            self._owned_port = link.port
        super().__init__(link, number, timeout, query_retries)
        self.link = link
        self.on_error = on_error
        self.on_exit = on_exit
        self._closed = False
        _stop_at_exit.track(self)

    # ---- lifecycle ----
    def _stop_on_error(self) -> None:
        self._halt(self.on_error)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        _stop_at_exit.untrack(self)
        if self._owned_port is not None:
            try:
                self._owned_port.close()
            except Exception:  # noqa: BLE001 - closing must not mask the real error
                pass

    @property
    def closed(self) -> bool:
        return self._closed

    def _stop_at_exit(self) -> None:
        self._halt(self.on_exit)

    def _halt(self, how: Optional[str]) -> None:
        """Best effort while unwinding: a failed stop falls back to the next harder one."""
        if how is None or self._closed:
            return
        ladder = {"stop": (self.stop, self.abort, self.disable),
                  "quick_stop": (self.abort, self.disable),
                  "disable": (self.disable,)}[how]
        for step in ladder:
            try:
                step()
                return
            except Exception:  # noqa: BLE001 - the link may be gone; try the next way
                continue

    # ---- typed views of the status registers ----
    @property
    def status(self) -> MotorStatus:
        """MST as :class:`MotorStatus` flags."""
        return MotorStatus(self._status_raw)

    @property
    def snl_status(self) -> SnlStatus:
        """SLS as :class:`SnlStatus`."""
        return SnlStatus(self._snl_status_raw)

    @property
    def latch_status(self) -> LatchStatus:
        return LatchStatus(self._latch_status_raw)

    @property
    def sync_status(self) -> SyncStatus:
        return SyncStatus(self._sync_status_raw)

    @property
    def sync_condition(self) -> SyncCondition:
        return SyncCondition(self._sync_condition_raw)

    @sync_condition.setter
    def sync_condition(self, condition: Union[SyncCondition, int]) -> None:
        self._sync_condition_raw = int(condition)

    def broadcast_command(self, command: str) -> None:
        """``@00<command>``: every device on this line acts; none replies."""
        ArcusClientBase.broadcast(self.link, command)

    def __repr__(self) -> str:
        return f"ArcusClient(address={self.address:02d})"


def _address(address: Union[str, int]) -> int:
    text = str(address).strip()
    if text.upper().startswith(("DMC", "DMK")):
        text = text[3:]
    if not text.isdigit():
        raise _core.InvalidArgument(f"arcus address: two digits 01..99, not {address!r}")
    value = int(text)
    if not 1 <= value <= 99:
        raise _core.InvalidArgument(f"arcus address: 01..99 (00 is broadcast), not {address!r}")
    return value


def make_sim(address: Union[str, int] = "01", clock: Optional["_core.Clock"] = None,
             store_path: Optional[str] = None, **options: Any) -> ArcusSim:
    """A simulated DMX-CAN answering at ``address`` ("01".."99", "DMC05" accepted).

    ``clock``: a motorbus.SimClock to drive time from a test (default: real time).
    ``store_path``: where STORE persists the flash items (read back at boot).
    ``options``: response_type (0/1), eo_boot (Table 7.11 ships 0: motor off
    until EO=1), snl (StepNLoop, default on), home=(lo, hi), minus_limit,
    plus_limit, z_position, start_position (physical steps), tick (s).
    Serve it with ``motorbus.PtyLineServer([sim])``; the line settings are
    LINE_SETTINGS (requests end with CR, replies with NUL).
    """
    known = {"response_type", "eo_boot", "snl", "home", "minus_limit", "plus_limit", "z_position",
             "start_position", "tick"}
    unknown = set(options) - known
    if unknown:
        raise _core.InvalidArgument(f"arcus sim options: unknown {sorted(unknown)}; known {sorted(known)}")
    return ArcusSim(clock, address=_address(address), store_path=store_path or "", **options)

"""Arcus DMX-CAN drives over their ASCII line (RS-232 or RS-485 multi-drop).

    from motorbus.drives.arcus import ArcusClient
    with ArcusClient("/dev/ttyUSB0", address=1, baud=9600) as drive:
        drive.enable()
        drive.move(4000)            # X4000: counts with StepNLoop on, pulses without
        drive.wait_idle(timeout=10)
        print(drive.position(), drive.status())

A simulator for tests and demos (``make_sim``) answers on a pty exactly like the
device; ``motorbus sim serve --pty --drive arcus:01`` uses it.
"""
from __future__ import annotations

import enum
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


def open_line(port: Union[str, "_core.Port"], baud: int = 9600, timeout: float = 0.2,
              turnaround: float = 0.0) -> "_core.LineLink":
    """A LineLink framed for DMX-CAN (CR after requests, NUL after replies).

    Share it between several ArcusClient objects to talk to up to 99 devices on
    one RS-485 line."""
    if isinstance(port, str):
        port = _core.open_port(port, baud)
    return _core.LineLink(port, request_terminator=REQUEST_TERMINATOR, reply_terminators=[REPLY_TERMINATOR],
                          max_line=_core.ARCUS_MAX_REPLY, reply_timeout=timeout, turnaround=turnaround)




class ArcusClient(_stop_at_exit.StopsMotor, ArcusClientBase):
    """Typed client for one DMX-CAN.

    ``port`` is a device path (opened at ``baud``), a ``motorbus.Port``, or a
    ``motorbus.LineLink`` from :func:`open_line` shared with other clients on
    the same RS-485 line.

    As a context manager it stops the motor when an exception leaves the block
    (``on_error``: "abort" = ABORT, immediate; "stop" = STOP, decelerated; None)
    and, for clients still open when the interpreter exits, with ``on_exit``
    (default "stop").
    """

    def __init__(self, port: Any, address: Union[int, str] = 1, *, baud: int = 9600, timeout: float = 0.2,
                 query_retries: int = 1, on_error: Optional[str] = "abort", on_exit: Optional[str] = "stop"):
        for name, v in (("on_error", on_error), ("on_exit", on_exit)):
            if v not in (None, "stop", "abort"):
                raise _core.InvalidArgument(f"{name}: 'stop', 'abort' or None, not {v!r}")
        if isinstance(port, _core.LineLink):
            link, self._owns_port = port, False
        else:
            link, self._owns_port = open_line(port, baud=baud, timeout=timeout), True
        super().__init__(link, int(address), None, query_retries)
        self.link = link
        self._on_error = on_error
        self._on_exit = on_exit
        self._closed = False
        _stop_at_exit.track(self)

    # ---- lifecycle ----
    def _stop_on_error(self) -> None:
        self._safe_halt(self._on_error)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        _stop_at_exit.untrack(self)
        if self._owns_port:
            try:
                self.link.port.close()
            except Exception:  # noqa: BLE001 - closing must not mask the real error
                pass

    def _stop_at_exit(self) -> None:
        self._safe_halt(self._on_exit)

    def _safe_halt(self, how: Optional[str]) -> None:
        if how is None or self._closed:
            return
        try:
            self.abort() if how == "abort" else self.stop()
        except Exception:  # noqa: BLE001 - best effort while unwinding
            if how == "stop":
                try:
                    self.abort()
                except Exception:  # noqa: BLE001
                    pass

    # ---- typed views of the status registers ----
    def status(self) -> MotorStatus:
        return MotorStatus(self.status_raw())

    def snl_status(self) -> SnlStatus:
        return SnlStatus(self.snl_status_raw())

    def latch_status(self) -> LatchStatus:
        return LatchStatus(self.latch_status_raw())

    def sync_status(self) -> SyncStatus:
        return SyncStatus(self.sync_status_raw())

    def sync_condition(self) -> SyncCondition:
        return SyncCondition(self.sync_condition_raw())

    def set_sync_condition(self, condition: Union[SyncCondition, int]) -> None:
        self.set_sync_condition_raw(int(condition))

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

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

from .. import _core, _stop_at_exit, faces
from ..stopping import STOP_WAYS, check_stop_way  # noqa: F401  (STOP_WAYS re-exported: motorbus's, said once)
from .._core.arcus import (  # noqa: F401  (re-exported)
    ClientBase as ArcusClientBase, ClientCounters as ArcusClientCounters, CommandInfo as ArcusCommandInfo,
    Phase as ArcusPhase, Sim as ArcusSim,
)
# The DMX-CAN's profile model (manual 000, Appendix A) and homing engine, with the motion
# library's generic pieces in motorbus.motion: re-exported here, the vendor's own module.
from .._core.arcus import (  # noqa: F401
    MAX_MOVE_DISTANCE as ARCUS_MAX_MOVE_DISTANCE, Homing as ArcusHoming, HomingOptions as ArcusHomingOptions,
    Motion as ArcusMotion, ProfileParams as ArcusProfileParams, SpeedWindow as ArcusSpeedWindow,
    check_strict as arcus_check_strict, effective as arcus_effective, max_acc_ms as arcus_max_acc_ms,
    speed_windows as arcus_speed_windows, window_for_hspd as arcus_window_for_hspd,
    window_for_sspdm as arcus_window_for_sspdm,
)

__all__ = [
    "ARCUS_MAX_MOVE_DISTANCE", "ArcusHoming", "ArcusHomingOptions", "ArcusMotion", "ArcusProfileParams",
    "ArcusSpeedWindow", "arcus_check_strict", "arcus_effective", "arcus_max_acc_ms", "arcus_speed_windows",
    "arcus_window_for_hspd", "arcus_window_for_sspdm",
    "ArcusClient",
    "ArcusClientCounters",
    "ArcusCommandInfo",
    "ArcusPhase",
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
    "ArcusDrive",
    "ArcusParams",
    "ArcusHomingError",
    "ArcusHomingLimit",
    "ArcusHomingStalled",
    "ArcusMotorDisabled",
    "HOME_METHODS",
    "DEFAULT_HOME_METHOD",
    "check_address",
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
    "max_line": _core.arcus.MAX_REPLY,
}

from .._core.arcus import build_request, parse_reply  # noqa: E402,F401


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


def open_line(port: Union[str, "os.PathLike[str]", "_core.serial.Port"], *, baud: int = 9600, timeout: float = 0.2,
              turnaround: float = 0.0) -> "_core.serial.LineLink":
    """A LineLink framed for DMX-CAN (CR after requests, NUL after replies).

    ``port``: a device path (opened at ``baud``) or an open ``motorbus.serial.Port``.
    ``timeout``: seconds to wait for a reply; ``turnaround``: seconds of quiet
    before each request (slow RS-485 transceivers).  Share the link between
    several ArcusClient objects to talk to up to 99 devices on one RS-485 line."""
    if isinstance(port, (str, os.PathLike)):
        port = _core.serial.open_port(os.fspath(port), baud)
    elif not isinstance(port, _core.serial.Port):
        raise _core.InvalidArgument(f"arcus open_line: a path or a motorbus Port, not {type(port).__name__}")
    return _core.serial.LineLink(port, request_terminator=REQUEST_TERMINATOR, reply_terminators=[REPLY_TERMINATOR],
                                 max_line=_core.arcus.MAX_REPLY, reply_timeout=timeout, turnaround=turnaround)


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
        check_stop_way(on_error, "on_error")
        check_stop_way(on_exit, "on_exit")
        number = _address(address)
        self._owned_port = None
        if isinstance(line, _core.serial.LineLink):
            link = line
        elif isinstance(line, _core.serial.Port):
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
        if not self._closed:
            _stop_at_exit.halt(how, self.stop, self.abort, self.disable)

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


def check_address(text: str) -> str:
    """'1', '01', 'DMC01' -> '01'; InvalidArgument naming the problem."""
    return f"{_address(text):02d}"


def make_sim(address: Union[str, int] = "01", clock: Optional["_core.runtime.Clock"] = None,
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
             "start_position", "tick"}  # = ArcusDrive.sim_options but store_path
    unknown = set(options) - known
    if unknown:
        raise _core.InvalidArgument(f"arcus sim options: unknown {sorted(unknown)}; known {sorted(known)}")
    return ArcusSim(clock, address=_address(address), store_path=store_path or "", **options)


# ---- the motorbus.Drive adapter ------------------------------------------------------------------

from .. import drive as _drive  # noqa: E402  (after the client: the adapter is built on it)

#: home() methods: the manual's homing commands (Figures 7.2-7.6).
HOME_METHODS = ("H+", "H-", "HL+", "HL-", "L+", "L-", "Z+", "Z-", "ZH+", "ZH-")
#: home(None): H+ (home input only, Figure 7.2): the shortest routine; the
#: counter is zeroed at the switch edge and the motor stops past it by its
#: deceleration distance.  HL+/ZH+ end exactly at zero but search at LSPD.
DEFAULT_HOME_METHOD = "H+"


class ArcusHomingError(_drive.MoveFailed):
    """home() ended in a limit error or a StepNLoop error instead of at the switch.

    A :class:`motorbus.MoveFailed`: the error raised is one of its subclasses,
    which is also the outcome class of the reason (:class:`ArcusHomingLimit` is a
    ``LimitReached``, :class:`ArcusHomingStalled` a ``MoveStalled``)."""

    __module__ = "motorbus.drives.arcus"


class ArcusHomingLimit(ArcusHomingError, _drive.LimitReached):
    """The homing ran into a limit switch (MST bit 6/7): ``side`` says which."""

    __module__ = "motorbus.drives.arcus"


class ArcusHomingStalled(ArcusHomingError, _drive.MoveStalled):
    """A StepNLoop error (SLS 8..10) ended the homing."""

    __module__ = "motorbus.drives.arcus"


class ArcusMotorDisabled(_core.DriveFault):
    """A motion was asked of a disabled motor (EO=0): the DMX-CAN would answer OK and not move (§6)."""

    __module__ = "motorbus.drives.arcus"


_I, _F, _B, _S = "int", "float", "bool", "str"
_INT32 = 2**31 - 1
# name: (type, min, max, unit, factory default, stored by STORE, writable, description)
_PARAMS: dict[str, tuple] = {
    "HSPD": (_I, 1, 6_000_000, "pulses/s (counts/s with SL=1)", 1000, False, True, "high speed"),
    "LSPD": (_I, 1, 6_000_000, "pulses/s (counts/s with SL=1)", 100, False, True, "low (start) speed"),
    "ACC": (_I, 1, _INT32, "ms", 300, False, True, "acceleration time (adjusted into Appendix A's window)"),
    "DEC": (_I, 1, _INT32, "ms", 300, False, True, "deceleration time, used when EDEC=1"),
    "EDEC": (_B, 0, 1, "", False, False, True, "use DEC for deceleration (else ACC)"),
    "SCV": (_B, 0, 1, "", False, False, True, "S-curve acceleration"),
    "SSPDM": (_I, 0, 9, "", 0, False, True, "on-the-fly speed window (Appendix A)"),
    "HCA": (_I, 0, _INT32, "pulses", 100, False, True, "home correction amount (HL homing)"),
    "RZ": (_B, 0, 1, "", False, False, True, "return to zero after H/HL homing"),
    "LCA": (_I, 0, _INT32, "pulses", 1000, True, True, "limit correction amount (L homing)"),
    "CURR": (_I, 100, 2500, "mA", 1600, True, True, "run current"),
    "CURI": (_I, 0, 2500, "mA", 1000, True, True, "idle current (0, or 100..2500; 0 = unpowered when idle)"),
    "CURT": (_I, 0, _INT32, "ms", 500, True, True, "idle time before idle current"),
    "CUR": (_I, 0, 2500, "mA", None, False, False, "actual current"),
    "EOBOOT": (_B, 0, 1, "", False, True, True, "motor power at boot"),
    "DOBOOT": (_I, 0, 7, "", 7, True, True, "digital outputs at boot"),
    "EDO": (_B, 0, 1, "", True, True, True, "DO1 in-position / DO3 alarm outputs under StepNLoop"),
    "POL": (_I, 0, 511, "bits", 0, True, True, "polarity: 1 dir, 4 limit, 5 home, 6 latch, 7 in-pos, 8 alarm"),
    "SL": (_B, 0, 1, "", True, True, True, "StepNLoop closed loop (positions and speeds in encoder counts)"),
    "SLT": (_I, 0, _INT32, "counts", 20, True, True, "StepNLoop tolerance (in position)"),
    "SLE": (_I, 0, _INT32, "counts", 1000, True, True, "StepNLoop error range"),
    "SLA": (_I, 0, _INT32, "", 10, True, True, "StepNLoop maximum correction attempts"),
    "SLM": (_I, 0, _INT32, "counts", 5, True, True, "StepNLoop idle tolerance"),
    "SLR": (_F, 0.001, 999.999, "pulses/count", 0.8, True, True, "StepNLoop ratio"),
    "DN": (_I, 1, 99, "", 1, True, True, "device name DMCnn (after STORE and a power cycle)"),
    "RT": (_I, 0, 1, "", 0, True, True, "response type (after STORE and a power cycle)"),
    "DB": (_I, 1, 5, "", 1, True, True, "serial baud code 1=9600 .. 5=115200"),
    "CM": (_I, 0, 2, "", 0, True, True, "communication mode 0 RS-232, 1 RS-485, 2 CANopen"),
    "BR": (_I, 1, 9, "", 5, True, True, "CANopen bit rate code"),
    "NID": (_I, 1, 127, "", 1, True, True, "CANopen node id"),
    "SYNP": (_I, -(2**27), 2**27 - 1, "counts", 0, False, True, "sync output position"),
    "SYNC": (_I, 1, 3, "", 1, False, True, "sync condition 1 =, 2 <, 3 >"),
    "ID": (_S, None, None, "", "DriveMax-CAN", False, False, "product id"),
    "VER": (_S, None, None, "", None, False, False, "firmware version"),
}


class ArcusParams(_drive.Params):
    """``drive.params``: the DMX-CAN's own command names (Tables 7.10, 7.11 and the profile)."""

    def _names(self) -> list[str]:
        return list(_PARAMS)

    def _key(self, name: str) -> str:
        return super()._key(name).strip().upper()

    def _info(self, name: str) -> Optional[_drive.ParamInfo]:
        row = _PARAMS.get(name)
        if row is None:
            return None
        typ, lo, hi, unit, default, persists, writable, desc = row
        return _drive.ParamInfo(name, typ, lo, hi, unit, default, persists, writable, desc)

    async def _read(self, info: _drive.ParamInfo) -> Any:
        io = self._drive.io
        if info.name == "SLR":
            return await io.attr("snl_ratio")
        if info.name == "DN":
            return int((await io.attr("device_name"))[-2:])
        if info.type == "str":
            return await io.command(info.name, True)
        value = await io.query(info.name)
        return bool(value) if info.type == "bool" else value

    async def _write(self, info: _drive.ParamInfo, value: Any) -> None:
        io = self._drive.io
        if info.type == "int" and isinstance(value, float) and not value.is_integer():
            raise _core.InvalidArgument(f"arcus: {info.name} takes an integer, not {value!r}")
        if info.type == "bool" and value not in (0, 1):
            raise _core.InvalidArgument(f"arcus: {info.name} takes True/False (1/0), not {value!r}")
        if info.name == "SLR":
            await io.set_attr("snl_ratio", float(value))
        elif info.name == "DN":
            await io.set_device_name(int(value))
        else:
            await io.set(info.name, int(value))
        if info.name in ("SL", "SLT"):
            await self._drive._read_loop_settings()


#: SLS error values and the manual's words for them (Table 7.6, Table 7.7, §8 object 2003h).
_SNL_ERRORS = {
    SnlStatus.CORRECTION_RANGE_ERROR: "StepNLoop correction range error: the delta exceeded the error range "
                                      "(SLE) while the motor was idle (SLS 8)",
    SnlStatus.CORRECTION_ATTEMPT_ERROR: "StepNLoop correction attempt error: the position was not reached in the "
                                        "maximum number of correction attempts (SLA) (SLS 9)",
    SnlStatus.STALL_ERROR: "StepNLoop stall error: the delta (DX) exceeded the error range (SLE) while the "
                           "motor was moving (SLS 10)",
}
#: SLS values of a motor still busy (moving, correcting, stopping, homing): not at rest yet.
_SNL_BUSY = frozenset({SnlStatus.MOVING, SnlStatus.CORRECTING, SnlStatus.STOPPING, SnlStatus.ABORTING,
                       SnlStatus.JOGGING, SnlStatus.HOMING, SnlStatus.Z_HOMING, SnlStatus.LIMIT_HOMING})


class ArcusDrive(_drive.Drive):
    """A DMX-CAN behind :class:`motorbus.Drive`.

    Native units are the drive's own: with StepNLoop on (SL=1, the factory
    setting) positions, targets and velocities are encoder counts and
    counts/s (4000 per rev) and ``position`` is EX; with SL=0 they are pulses
    and pulses/s (3200 per rev) and ``position`` is PX.  ``velocity=`` of a
    move (and a jog's velocity) sets HSPD for that move only: the old HSPD is
    written back once it has ended, however it ended.  A move has arrived when
    it is at rest within the StepNLoop tolerance SLT of its target (SL=1), or
    exactly on it (SL=0: the pulse counter); otherwise it raises the
    ``motorbus.MoveFailed`` that says why (docs/drives/arcus.md, "How a move
    ends").  No watchdog: on link loss the motor keeps doing what it was last
    told and the next call raises LinkDown.
    """

    kind = "arcus"
    capabilities = frozenset({_drive.Capability.POSITION, _drive.Capability.VELOCITY, _drive.Capability.HOMING,
                              _drive.Capability.ENCODER, _drive.Capability.STORE})
    has_watchdog = False

    # the plugin (motorbus.registry): what the kind is
    description = "Arcus DMX-CAN integrated stepper, ASCII over RS-232/RS-485 (StepNLoop closed loop)"
    transport = "serial"
    default_address = "01"
    line_settings = LINE_SETTINGS
    default_baud = 9600
    sim_options = ("response_type", "eo_boot", "snl", "home", "minus_limit", "plus_limit", "z_position",
                   "start_position", "tick", "store_path")
    store_file = "arcus-{address}.store"
    probe_addresses = tuple(f"{a:02d}" for a in range(1, 100))   # DN 01-99
    probe_bauds = (9600, 19200, 38400, 57600, 115200)              # the DB settings

    def __init__(self, native: ArcusClient, **kw: Any) -> None:
        super().__init__(native, **kw)
        self._homed = False
        self._homing = False
        self._target: Optional[float] = None
        self._direction = 1
        # What this Drive last told the drive, so a move costs one request like the
        # native client's (EO and ABS/INC are read once here and after enable/disable;
        # a script that changes them through drive.native should reopen the Drive).
        # Read here, blocking: a Drive is built by open() (blocking in both faces:
        # aio.open_drive runs it off the loop).
        self._enabled = self.native.enabled
        self._incremental: Optional[bool] = None
        faces.run(self._read_loop_settings())

    async def _read_loop_settings(self) -> None:
        # SL and SLT decide what position() reads and a move's window: read at open
        # and again when params writes them (not on every move).
        self._snl = bool(await self.io.attr("snl_enabled"))
        self._tolerance = await self.io.attr("snl_tolerance") if self._snl else 0

    def _require_enabled(self) -> None:
        if not self._enabled:
            raise ArcusMotorDisabled(f"arcus {self.native.address:02d}: the motor is disabled (EO=0); "
                                     "call enable() first")

    async def _speed_for_this_move(self, velocity: Optional[float]) -> None:
        # HSPD for this move only (Drive writes the old value back when it ends);
        # nothing is written when the move runs at the drive's own speed.
        if velocity is None:
            return
        speed = max(1, int(round(abs(velocity))))
        old = await self.io.attr("high_speed")
        if old != speed:
            await self._for_this_move(lambda: old, lambda value: self.io.set_attr("high_speed", value), speed)

    # ---- motion ----
    # Coroutines over self.io (motorbus.faces): the same code serves drive.move_to(...)
    # and `await aio.Drive(drive).move_to(...)`; the exchanges of the drives of one line
    # share the line's worker (_io_link: the default, native.link, the LineLink).
    async def _enable(self) -> None:
        await self.io.enable(True)
        self._enabled = True

    async def _disable(self) -> None:
        self._enabled = False
        await self.io.enable(False)

    async def _use_mode(self, incremental: bool) -> None:
        if self._incremental is not incremental:
            await (self.io.incremental_mode() if incremental else self.io.absolute_mode())
            self._incremental = incremental

    async def _move_to(self, target: float, velocity: Optional[float]) -> None:
        self._require_enabled()
        goal = int(round(target))
        await self._speed_for_this_move(velocity)
        await self._use_mode(False)
        self._target, self._direction = goal, 0   # direction: worked out when velocity is read
        try:
            await self.io.move(goal)
        except _core.ArcusUnknownCommand:
            # "?X..." also answers a move longer than the drive's largest (Table 11.0):
            # say which, in the Drive's words (read only on this path: a move stays one request).
            here = await self._position()
            if abs(goal - here) > _core.arcus.MAX_MOVE_DISTANCE:
                raise _core.InvalidArgument(
                    f"arcus {self.native.address:02d}: a move from {here:g} to {goal} is "
                    f"{abs(goal - here):g} {'counts' if self._snl else 'pulses'}; the DMX-CAN moves at most "
                    f"{_core.arcus.MAX_MOVE_DISTANCE} in one X (Table 11.0): split it") from None
            raise

    async def _move_by(self, distance: float, velocity: Optional[float]) -> None:
        # An absolute X to the target Drive judges the move by (where the axis was read
        # plus the distance).  An X in INC mode would count from PX, the commanded
        # position, which StepNLoop leaves up to SLT away from EX: the move would end
        # within SLT of a target that is itself up to SLT off the one judged.
        move = self._move
        if move is not None and move.target is not None:
            target = move.target
        else:
            target = await self._position() + distance
        await self._move_to(target, velocity)

    async def _jog(self, velocity: float) -> None:
        self._require_enabled()
        await self._speed_for_this_move(velocity)
        self._direction = 1 if velocity > 0 else -1
        self._target = None
        await self.io.jog(self._direction)

    # Stops overtake the exchanges queued on the line's worker (the awaitable face).
    async def _stop(self) -> None:
        await self.io.urgent.stop()

    async def _quick_stop(self) -> None:
        await self.io.urgent.abort()

    # Speed and ramps as a motion controller sets them (the EPICS record's VELO/ACCL):
    # HSPD is the position speed in pulses/s, ACC/DEC the ramp times in ms.
    homing_directions = ("H+", "H-")

    async def _move_speed(self) -> tuple[Optional[float], Optional[float]]:
        return await self._speed_param("HSPD")

    async def _set_accel_time(self, seconds: float, speed: float, top: Optional[float]) -> bool:
        ms = max(1.0, seconds * 1000.0)
        await self._set_params_clamped({"ACC": ms, "DEC": ms})
        return True

    async def _home(self, method: Any) -> None:
        method = DEFAULT_HOME_METHOD if method is None else method
        if not isinstance(method, str) or method.strip().upper() not in HOME_METHODS:
            raise _core.InvalidArgument(f"arcus home method: one of {', '.join(HOME_METHODS)} (None = "
                                        f"{DEFAULT_HOME_METHOD}), not {method!r}")
        method = method.strip().upper()
        self._require_enabled()
        self._homed = False
        self._homing = True
        self._target = None
        self._direction = 1 if method.endswith("+") else -1
        await self.io.action(method)

    async def _homing_done(self) -> bool:
        if not await self._is_idle():
            return False
        self._homing = False
        status = await self._status()
        reason = self._stop_reason(status)
        if reason is not None and reason.error in (_drive.LimitReached, _drive.MoveStalled):
            error = ArcusHomingLimit if reason.error is _drive.LimitReached else ArcusHomingStalled
            move = self._move
            if move is not None:
                raise await self._failure(move, _drive.StopReason(error, f"{reason.text}: homing failed",
                                                                  reason.code, reason.side), status=status)
            raise error(f"arcus {self.native.address:02d}: homing failed: {reason.text}")
        # Nothing the drive shows tells a homing that found its switch from one a STOP
        # of another client on the line ended (docs/drives/arcus.md): it counts as homed.
        move = self._move
        self._homed = reason is None and (move is None or move.stopped_by is None)
        return True

    async def _clear_faults(self) -> None:
        await self.io.clear()  # CLR: limit errors and the StepNLoop error status

    async def _store(self) -> None:
        await self.io.store()

    # ---- readings ----
    async def _position(self) -> float:
        return float(await self.io.attr("encoder" if self._snl else "position"))

    async def _velocity(self) -> float:
        if not await self.io.attr("moving"):
            return 0.0
        if self._direction == 0 and self._target is not None:
            self._direction = 1 if self._target >= await self._position() else -1
        return float(await self.io.attr("speed") * (self._direction or 1))

    async def _is_idle(self) -> bool:
        # At rest: no pulses (MST bits 0..2) and, under StepNLoop, no correction on
        # its way either (SLS 1..7, 13).  An error state (SLS 8..11) is at rest.
        if (await self.io.attr("status")).moving:
            return False
        return not self._snl or await self.io.attr("snl_status") not in _SNL_BUSY

    def _in_position_window(self) -> float:
        # StepNLoop calls a move "in position" within SLT encoder counts (Table 7.5);
        # without it the drive counts pulses and stops on the target exactly.  No
        # exchange (SLT is read at open and when params writes it): a plain function.
        return float(self._tolerance)

    def _stop_reason(self, status: _drive.DriveStatus) -> Optional[_drive.StopReason]:
        mst, snl = status.raw
        # MST bits 6/7 latch when a limit switch stops a motion in its direction
        # (Table 7.3); the DMX-CAN has hard limit inputs only, no soft limits.
        if mst & MotorStatus.PLUS_LIMIT_ERROR:
            return _drive.StopReason(_drive.LimitReached, "the +limit switch (MST bit 7, plus limit error)",
                                     side=1)
        if mst & MotorStatus.MINUS_LIMIT_ERROR:
            return _drive.StopReason(_drive.LimitReached, "the -limit switch (MST bit 6, minus limit error)",
                                     side=-1)
        if snl in _SNL_ERRORS:
            return _drive.StopReason(_drive.MoveStalled, _SNL_ERRORS[snl], code=int(snl))
        if snl is SnlStatus.LIMIT_ERROR:     # MST's latch cleared by hand, SLS's not
            return _drive.StopReason(_drive.LimitReached, "a limit switch (StepNLoop limit error, SLS 11)")
        if not status.enabled:
            return _drive.StopReason(_drive.MoveInterrupted, "the motor power switched off (EO=0)")
        # A STOP or an ABORT leaves no trace in MST or SLS once the motor is at rest.  A
        # line is one process's: a move this program did not stop was stopped by
        # another client on the same line (the DMX-CAN has no stop input).
        move = self._move
        if move is not None and move.what == "move" and move.stopped_by is None:
            return _drive.StopReason(_drive.MoveInterrupted, "a command from another client on the line (STOP, "
                                     "ABORT or a new target: the DMX-CAN keeps no trace of it at rest)")
        return None

    async def _status(self) -> _drive.DriveStatus:
        st = await self.io.attr("status")
        snl = await self.io.attr("snl_status")
        enabled = await self.io.attr("enabled")
        moving = st.moving
        fault = st.limit_error or snl.is_error
        pos = await self._position()
        at_target = not moving and not fault and (self._target is not None and abs(pos - self._target)
                                                  <= self._tolerance)
        flags = "|".join(f.name for f in MotorStatus if f in st) or "idle"
        text = (f"arcus {self.native.address:02d}: {'enabled' if enabled else 'disabled'}, MST {flags}, "
                f"SLS {snl.name}, {'EX' if self._snl else 'PX'}={int(pos)}")
        return _drive.DriveStatus(enabled=enabled, moving=moving, homed=self._homed, fault=fault,
                                  at_target=at_target, limit_positive=bool(st & MotorStatus.PLUS_LIMIT),
                                  limit_negative=bool(st & MotorStatus.MINUS_LIMIT), raw=(st, snl), text=text)

    def _make_params(self) -> _drive.Params:
        return ArcusParams(self)

    async def _console(self, line: str) -> str:
        # The ASCII command as typed (HSPD, HSPD=5000, X1000, MST...), framed and
        # addressed by the client; the reply body, or the drive's refusal as an error.
        return await self.io.command(line)

    def _close(self) -> None:
        self.native.close()

    # ---- the plugin's hooks (motorbus.registry) ------------------------------------------
    @classmethod
    def open(cls, *, line: Any = None, bus: Any = None, address: str = "01", units: Optional[_drive.Units] = None,
             baud: int = 9600, timeout: Optional[float] = None, on_error: Optional[str] = "stop",
             on_exit: Optional[str] = "stop", query_retries: int = 1) -> "ArcusDrive":
        """``line`` is a path (the client opens it, closed with the drive) or a shared LineLink."""
        # The Drive applies on_error/on_exit; the client itself stays quiet.
        return cls._open_on(line, bus, lambda link: ArcusClient(link, address, baud=baud, timeout=timeout,
                                                                on_error=None, on_exit=None,
                                                                query_retries=query_retries),
                            units=units, on_error=on_error, on_exit=on_exit)

    make_sim = staticmethod(make_sim)
    check_address = staticmethod(check_address)

    @classmethod
    def probe(cls, line: "_core.serial.LineLink", address: str) -> Optional[dict]:
        """Discovery: the product id and firmware of the drive at `address`, or None.
        Reads only (ID, VER): never moves the motor nor writes a parameter."""
        client = ArcusClient(line, address, on_error=None, on_exit=None, query_retries=0)
        try:
            return {"model": client.id, "firmware": client.version}
        finally:
            client.close()   # a shared LineLink stays open

    @classmethod
    def sim_faults(cls) -> dict:
        return dict(SIM_FAULTS)

    def poll_fields(self, fields: Any) -> "PollSpec":
        """motorbus.Poller: EX (PX with StepNLoop off), PS and MST queried by a client of
        the poll thread's own on the drive's line.  PS is a speed (>= 0): the polled
        velocity has no sign, unlike Drive.velocity (which adds the move's direction)."""
        from ..registry import PollSpec

        queries = {"position": "EX" if self._snl else "PX", "velocity": "PS", "status": "MST"}
        names = []
        for f in fields:
            if f not in queries:
                raise _core.InvalidArgument(f"arcus poll field {f!r}: this kind gives {', '.join(queries)}")
            names.append(queries[f])
        link = self.native.link
        source = _core.arcus.poll_source(link, self.native.address, names)
        return PollSpec(source=source, scales=(1.0,) * len(names), transport=link)

    def plan_move(self, start: float, target: float) -> Any:
        """The move as the DMX-CAN makes it (its profile model, ``ArcusMotion``: jump to
        LSPD, ramp in ACC ms, cruise at HSPD, DEC with EDEC, S-curve with SCV), in the
        drive's position unit (encoder counts with StepNLoop on, pulses off)."""
        p = self.params
        hspd, lspd = float(p["HSPD"]), float(p["LSPD"])
        params = ArcusProfileParams(hspd=hspd, lspd=min(lspd, hspd), acc_ms=float(p["ACC"]),
                                    dec_ms=float(p["DEC"]), edec=bool(p["EDEC"]), scv=bool(p["SCV"]),
                                    snl_ratio=float(p["SLR"]) if self._snl else 1.0)
        model = ArcusMotion(params)
        error = model.move(float(start), float(target))
        if error:
            raise _core.InvalidArgument(f"arcus plan_move {start} -> {target}: the drive would answer {error}")
        return model.profile


def _limit_fault(sim: ArcusSim, direction: Any = 1) -> None:
    if isinstance(direction, bool) or str(direction).strip() not in ("1", "+1", "-1"):
        raise _core.InvalidArgument(f"arcus sim fault 'limit': direction +1 or -1, not {direction!r}")
    sim.force_limit(int(str(direction).strip()), True)


# Faults the simulator can be given (the pytest plugin's sim_faults fixture), under
# the standard names of docs/drives/arcus.md ("How a move ends").  The DMX-CAN has
# no drive fault register and no stop input in ASCII mode: no "fault", no "stop_input".
SIM_FAULTS = {
    # a limit switch closes (direction +1 or -1, forced until the sim is replaced): a
    # motion that way stops at once and latches the limit error (MST bit 6/7, SLS 11)
    "limit": _limit_fault,
    # the rotor jams: pulses go out, the shaft stays; StepNLoop stops the motor when
    # the delta passes SLE (SLS 10, stall error; with SL=0 nothing notices)
    "stall": lambda sim: sim.set_blocked(True),
    # the names of earlier releases
    "trip_limit": lambda sim, direction=-1: _limit_fault(sim, direction),
}

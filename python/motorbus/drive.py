"""One API over every drive: :class:`Drive`, what python-can's ``BusABC`` is to buses.

    import motorbus
    with motorbus.open_drive("<kind>", line="/dev/ttyUSB0", address="01",
                             units=motorbus.Units("mm", 0.0025)) as x:
        x.enable()
        x.move_to(25.0)                 # mm, waits until the move is done
        print(x.position, x.status.text)
        x.params["HSPD"] = 10000        # the vendor's own parameter names
        x.native                        # the vendor's full client

A vendor adapts its native client to this class by implementing the ``_``
methods below in *native* units (steps, counts, increments); :class:`Drive`
does the units, the waiting, the safety rules and the argument checks once for
every vendor.  The vocabulary:

* positions in user units, velocities in user units per second,
  accelerations per second squared; ``units.scale`` = user units per native unit;
* ``on_error`` / ``on_exit``: ``"stop"`` (decelerate), ``"quick_stop"`` (the
  fastest stop the drive has), ``"disable"`` (power stage off) or ``None``;
* a ``with`` block stops the motor when an exception leaves it; the exit hook
  stops every drive still open when the interpreter exits; a lost link stops the
  motor through the drive's own watchdog where it has one (``has_watchdog``),
  otherwise the next call raises ``LinkDown`` (the drive keeps doing what it was
  last told: see each vendor's page in docs/drives/).
"""
from __future__ import annotations

import abc
import enum
import math
import time
from collections.abc import Iterator, MutableMapping
from dataclasses import dataclass
from typing import Any, Callable, Optional, Union

from . import _core, _stop_at_exit, registry

__all__ = ["open_drive", "Capability", "Drive", "DriveStatus", "ParamInfo", "Params", "StopHow", "Units", "STOP_WAYS"]

#: The one safety vocabulary (on_error, on_exit).
STOP_WAYS = ("stop", "quick_stop", "disable", None)
StopHow = Optional[str]


class Capability(enum.Enum):
    """What a drive can do through :class:`Drive` (``drive.capabilities``)."""

    POSITION = "position"            # move_to / move_by
    VELOCITY = "velocity"            # jog
    HOMING = "homing"                # home()
    INTERPOLATION = "interpolation"  # multi-axis streamed set-points (see drive.native)
    TORQUE = "torque"                # torque / current control (see drive.native)
    ENCODER = "encoder"              # position read back from an encoder, not counted steps
    STORE = "store"                  # store(): parameters survive a power cycle
    WATCHDOG = "watchdog"            # the drive stops by itself when the link is lost


@dataclass(frozen=True)
class Units:
    """User units: ``scale`` user units per native unit (step, count, increment).

    ``Units("mm", 0.0025)``: 400 native steps per mm.  Default: native units."""

    name: str = "native"
    scale: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.scale, (int, float)) or not math.isfinite(self.scale) or self.scale == 0:
            raise _core.InvalidArgument(f"Units.scale: a finite non-zero number, not {self.scale!r}")

    def to_native(self, value: float) -> float:
        return value / self.scale

    def to_user(self, value: float) -> float:
        return value * self.scale


@dataclass(frozen=True)
class DriveStatus:
    """What every drive can say about itself; ``raw`` is the vendor's own status."""

    enabled: bool
    moving: bool
    homed: bool
    fault: bool
    at_target: bool
    limit_positive: bool
    limit_negative: bool
    raw: Any = None
    text: str = ""


@dataclass(frozen=True)
class ParamInfo:
    """One parameter of ``drive.params``: its vendor name and what it holds."""

    name: str
    type: str                       # "int", "float", "bool", "str"
    minimum: Optional[float] = None
    maximum: Optional[float] = None
    unit: str = ""
    default: Any = None
    persists: bool = False          # kept by store() / survives a power cycle
    writable: bool = True
    description: str = ""

    @property
    def range(self) -> tuple[Optional[float], Optional[float]]:
        return (self.minimum, self.maximum)


class Params(MutableMapping):
    """``drive.params``: the vendor's parameters by their own names, read and
    written through the native protocol on every access (no cache: the drive is
    the truth).  A vendor implements ``_names``, ``_info``, ``_read``, ``_write``."""

    def __init__(self, drive: "Drive") -> None:
        self._drive = drive

    # -- for vendors -----------------------------------------------------------
    def _names(self) -> list[str]:
        raise NotImplementedError

    def _info(self, name: str) -> Optional[ParamInfo]:
        raise NotImplementedError

    def _read(self, info: ParamInfo) -> Any:
        raise NotImplementedError

    def _write(self, info: ParamInfo, value: Any) -> None:
        raise NotImplementedError

    # -- the mapping -----------------------------------------------------------
    def describe(self, name: str) -> ParamInfo:
        """Type, range, unit, default and whether it persists; KeyError (InvalidArgument) if unknown."""
        info = self._info(self._key(name))
        if info is None:
            raise UnknownParameter(f"{self._drive.kind}: no parameter {name!r}")
        return info

    def __getitem__(self, name: str) -> Any:
        self._drive._check_open()
        return self._read(self.describe(name))

    def __setitem__(self, name: str, value: Any) -> None:
        self._drive._check_open()
        info = self.describe(name)
        if not info.writable:
            raise _core.InvalidArgument(f"{self._drive.kind}: parameter {info.name} is read-only")
        if info.type in ("int", "float") and not isinstance(value, bool):
            if not isinstance(value, (int, float)) or (isinstance(value, float) and not math.isfinite(value)):
                raise _core.InvalidArgument(f"{self._drive.kind}: {info.name} takes a number, not {value!r}")
            if info.minimum is not None and value < info.minimum or info.maximum is not None and value > info.maximum:
                raise _core.InvalidArgument(
                    f"{self._drive.kind}: {info.name}={value!r} is outside [{info.minimum}, {info.maximum}]")
        self._write(info, value)

    def __delitem__(self, name: str) -> None:
        raise _core.InvalidArgument(f"{self._drive.kind}: parameters cannot be deleted")

    def __iter__(self) -> Iterator[str]:
        return iter(self._names())

    def __len__(self) -> int:
        return len(self._names())

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and self._info(self._key(name)) is not None

    def _key(self, name: str) -> str:
        if not isinstance(name, str):
            raise _core.InvalidArgument(f"{self._drive.kind}: parameter names are strings, not {name!r}")
        return name

    def __repr__(self) -> str:
        return f"<{self._drive.kind} params: {len(self)} names>"


class UnknownParameter(_core.InvalidArgument, KeyError):
    """A parameter name the drive does not have (also a KeyError, as a mapping raises)."""

    __module__ = "motorbus"

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class Drive(abc.ABC):
    """One motor axis, whatever its vendor.  See the module doc.

    Subclasses set ``kind``, ``capabilities`` and implement the ``_`` methods in
    native units; ``native`` is the vendor client they wrap."""

    kind: str = "?"
    capabilities: frozenset = frozenset()
    #: The drive stops by itself when the link to this host is lost.
    has_watchdog: bool = False
    #: Seconds a waiting call allows when given timeout=None.
    default_timeout: float = 60.0
    #: Poll period of the generic wait_idle.
    poll_interval: float = 0.005

    def __init__(self, native: Any, *, units: Optional[Units] = None, on_error: StopHow = "stop",
                 on_exit: StopHow = "stop", close_native: Optional[Callable[[], None]] = None) -> None:
        for name, how in (("on_error", on_error), ("on_exit", on_exit)):
            if how not in STOP_WAYS:
                raise _core.InvalidArgument(f"{name}: one of 'stop', 'quick_stop', 'disable' or None, not {how!r}")
        if units is None:
            units = Units()
        elif not isinstance(units, Units):
            raise _core.InvalidArgument(f"units: a motorbus.Units, not {type(units).__name__}")
        self.native = native
        self._units = units
        self.on_error = on_error
        self.on_exit = on_exit
        self._close_native = close_native
        self._closed = False
        self._params: Optional[Params] = None
        _stop_at_exit.track(self)

    # ---- vendor side (native units) -------------------------------------------------
    @abc.abstractmethod
    def _enable(self) -> None: ...

    @abc.abstractmethod
    def _disable(self) -> None: ...

    @abc.abstractmethod
    def _move_to(self, target: float, velocity: Optional[float]) -> None: ...

    def _move_by(self, distance: float, velocity: Optional[float]) -> None:
        self._move_to(self._position() + distance, velocity)

    @abc.abstractmethod
    def _jog(self, velocity: float) -> None: ...

    @abc.abstractmethod
    def _stop(self) -> None: ...

    @abc.abstractmethod
    def _quick_stop(self) -> None: ...

    def _home(self, method: Any) -> None:
        raise _core.InvalidArgument(f"{self.kind}: this drive has no homing")

    def _homing_done(self) -> bool:
        """True when a homing started by _home has finished (raise on a homing error)."""
        return not self._status().moving

    @abc.abstractmethod
    def _clear_faults(self) -> None: ...

    def _store(self) -> None:
        raise _core.InvalidArgument(f"{self.kind}: this drive cannot store its parameters")

    @abc.abstractmethod
    def _position(self) -> float: ...

    @abc.abstractmethod
    def _velocity(self) -> float: ...

    @abc.abstractmethod
    def _status(self) -> DriveStatus: ...

    def _is_idle(self) -> bool:
        return not self._status().moving

    def _travel_limits(self) -> tuple[Optional[float], Optional[float]]:
        """The soft travel limits the drive itself enforces now, native units (None: no limit that side)."""
        return (None, None)

    def _make_params(self) -> Params:
        return Params(self)

    def _close(self) -> None:
        """Release what the vendor opened (the native client); the link is closed by Drive."""

    def _console(self, line: str) -> str:
        """One request in the drive's own protocol -> its answer as text (`console`)."""
        raise _core.InvalidArgument(f"{self.kind}: this drive has no protocol console")

    # ---- commands ------------------------------------------------------------------
    def enable(self) -> None:
        """Power the motor (the drive holds position)."""
        self._check_open()
        self._enable()

    def disable(self) -> None:
        """Power stage off: the motor no longer holds position."""
        self._check_open()
        self._disable()

    def move_to(self, position: float, *, velocity: Optional[float] = None, wait: bool = True,
                timeout: Optional[float] = None) -> None:
        """Absolute move in user units; ``velocity`` (user units/s) for this move, else the drive's own."""
        self._check_open()
        target = self._units.to_native(self._number("position", position))
        self._move_to(target, self._speed_arg(velocity))
        if wait:
            self.wait_idle(timeout)

    def move_by(self, distance: float, *, velocity: Optional[float] = None, wait: bool = True,
                timeout: Optional[float] = None) -> None:
        """Relative move in user units."""
        self._check_open()
        self._move_by(self._units.to_native(self._number("distance", distance)), self._speed_arg(velocity))
        if wait:
            self.wait_idle(timeout)

    def jog(self, velocity: float) -> None:
        """Run at ``velocity`` (user units/s, the sign is the direction) until stop()."""
        self._check_open()
        v = self._units.to_native(self._number("velocity", velocity))
        if v == 0:
            self._stop()
            return
        self._jog(v)

    def stop(self) -> None:
        """Decelerate to a stop with the drive's deceleration."""
        self._check_open()
        self._stop()

    def quick_stop(self) -> None:
        """The fastest stop the drive has (an abort or the quick-stop ramp)."""
        self._check_open()
        self._quick_stop()

    def home(self, method: Any = None, *, wait: bool = True, timeout: Optional[float] = None) -> None:
        """Run the drive's homing (``method``: the vendor's own, None = its default)."""
        self._check_open()
        self._home(method)
        if wait:
            self._wait(self._homing_done, timeout, "homing")

    def wait_idle(self, timeout: Optional[float] = None) -> None:
        """Return when the motor is at rest (TimeoutError after ``timeout`` s, None = default_timeout)."""
        self._check_open()
        self._wait(self._is_idle, timeout, "motion")

    def clear_faults(self) -> None:
        """Clear latched faults (limit errors, drive faults) so it accepts motion again."""
        self._check_open()
        self._clear_faults()

    def console(self, line: str) -> str:
        """Sends one request in the drive's own protocol and returns the answer as text:
        what ``motorbus terminal`` types (ASCII commands for serial drives, SDO reads and
        writes for CANopen drives...; the vendor's docs give the syntax).  Bypasses the
        Drive's bookkeeping: a move started here is not known to ``wait_idle``."""
        self._check_open()
        if not isinstance(line, str):
            raise _core.InvalidArgument(f"{self.kind} console: a line of text, not {type(line).__name__}")
        return self._console(line.strip())

    def store(self) -> None:
        """Persist the parameters in the drive's non-volatile memory."""
        self._check_open()
        self._store()

    def close(self) -> None:
        """Forget the drive (no stop); closes the line or bus if open_drive opened it."""
        if self._closed:
            return
        self._closed = True
        _stop_at_exit.untrack(self)
        try:
            self._close()
        finally:
            if self._close_native is not None:
                self._close_native()

    # ---- readings ------------------------------------------------------------------
    @property
    def position(self) -> float:
        """Position in user units (the encoder where the drive reads one)."""
        self._check_open()
        return self._units.to_user(self._position())

    @property
    def velocity(self) -> float:
        """Velocity in user units per second."""
        self._check_open()
        return self._units.to_user(self._velocity())

    @property
    def status(self) -> DriveStatus:
        self._check_open()
        return self._status()

    @property
    def units(self) -> Units:
        return self._units

    @property
    def travel_limits(self) -> tuple[float, float]:
        """``(low, high)`` in user units: the soft limits the drive enforces now, read from it;
        ``-inf`` / ``inf`` on a side where it has none (most kinds have none at all)."""
        self._check_open()
        lo, hi = self._travel_limits()
        sign = 1.0 if self._units.scale > 0 else -1.0   # a negative scale swaps the ends
        a = -math.inf * sign if lo is None else self._units.to_user(lo)
        b = math.inf * sign if hi is None else self._units.to_user(hi)
        return (min(a, b), max(a, b))

    @property
    def params(self) -> Params:
        if self._params is None:
            self._params = self._make_params()
        return self._params

    @property
    def closed(self) -> bool:
        return self._closed

    # ---- safety ----------------------------------------------------------------------
    def __enter__(self) -> "Drive":
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        try:
            if exc_type is not None:
                self._halt(self.on_error)
        finally:
            self.close()

    def _stop_at_exit(self) -> None:
        self._halt(self.on_exit)

    def _halt(self, how: StopHow) -> None:
        if not self._closed:
            _stop_at_exit.halt(how, self._stop, self._quick_stop, self._disable)

    # ---- helpers -------------------------------------------------------------------------
    def _check_open(self) -> None:
        if self._closed:
            raise _core.ClosedError(f"{self.kind} drive: closed")

    def _number(self, name: str, value: Any) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise _core.InvalidArgument(f"{self.kind}: {name} must be a finite number, not {value!r}")
        return float(value)

    def _speed_arg(self, velocity: Optional[float]) -> Optional[float]:
        if velocity is None:
            return None
        v = abs(self._units.to_native(self._number("velocity", velocity)))
        if v == 0:
            raise _core.InvalidArgument(f"{self.kind}: velocity must be non-zero")
        return v

    def _wait(self, done: Callable[[], bool], timeout: Optional[float], what: str) -> None:
        limit = self.default_timeout if timeout is None else self._number("timeout", timeout)
        deadline = time.monotonic() + limit
        while not done():
            if time.monotonic() >= deadline:
                raise _core.TimeoutError(f"{self.kind}: {what} not finished after {limit:g} s")
            time.sleep(self.poll_interval)

    def __repr__(self) -> str:
        state = "closed" if self._closed else "open"
        return f"<{type(self).__name__} {self.kind} {state}, units={self._units.name}>"


def open_drive(kind: str, *, line: Any = None, bus: Any = None, address: Union[str, int],
               units: Optional[Units] = None, **options: Any) -> Drive:
    """Opens a drive of a registered ``kind`` (``motorbus.drive_kinds()`` lists them).

    * serial kinds: ``line`` = a port path (opened with the vendor's framing) or
      an open ``LineLink`` shared with other drives on one RS-485 line;
    * CAN kinds: ``bus`` = an ``open_bus`` spec (opened, and closed with the
      drive) or an open Bus;
    * ``address``: the vendor's own (two digits on an ASCII line, the node-ID
      for CANopen: see docs/drives/<vendor>.md);
    * ``options``: the vendor's (``on_error``, ``on_exit``, timeouts...).
    """
    plugin = registry.drive_plugin(kind)
    canonical = plugin.check_address(str(address).strip())
    if plugin.transport == "serial":
        if line is None or bus is not None:
            raise _core.InvalidArgument(f"open_drive({kind!r}): a serial drive takes line=, not bus=")
    elif bus is None or line is not None:
        raise _core.InvalidArgument(f"open_drive({kind!r}): a CAN drive takes bus=, not line=")
    return plugin.open(line=line, bus=bus, address=canonical, units=units, **options)

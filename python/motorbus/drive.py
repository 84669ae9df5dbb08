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
import asyncio
import dataclasses
import enum
import inspect
import logging
import math
import os
import time
from collections.abc import Iterator, Mapping, MutableMapping
from dataclasses import dataclass
from typing import Any, Callable, Optional, Union

from . import _core, _stop_at_exit, faces, registry

#: A DEBUG line per command (``motorbus -vv``); the protocol itself: ``motorbus.trace``.
log = logging.getLogger(__name__)

__all__ = ["open_drive", "Capability", "Drive", "DriveStatus", "ParamInfo", "Params", "StopHow", "Units", "STOP_WAYS",
           "MoveFailed", "MoveInterrupted", "LimitReached", "MoveFaulted", "MoveStalled", "MoveTimedOut",
           "MoveOutcome", "StopReason"]

# The one safety vocabulary (on_error, on_exit) lives in stopping.py, said once for
# the Drive, the native clients, bench files and the CLI; re-exported here.
from .stopping import STOP_WAYS, StopHow, check_stop_way  # noqa: E402


async def _value(result: Any) -> Any:
    """The result of a function that may be plain or a coroutine function (``_stop_reason``,
    ``_in_position_window``, Params' ``_read``/``_write``, ``_for_this_move``'s read/write)."""
    if inspect.isawaitable(result):
        return await result
    return result


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


class MoveFailed(_core.DriveFault):
    """A move, jog or homing that did not end at rest where it was sent.

    The one outcome error of every kind (a ``DriveFault``, so ``except DriveFault``
    still catches it); the subclass says why.  Attributes: ``axis`` (the kind, or the
    bench's axis name), ``target`` and ``position`` in user units (``target`` None for
    a jog or a homing), ``reason`` (one line, the drive's own words where it has
    them), ``code`` (the drive's fault or error code, or None), ``status`` (the
    drive's native status, ``DriveStatus.raw``) and ``units`` (their name)."""

    __module__ = "motorbus"
    #: A word for the kind of failure: exit codes and JSON carry it.
    outcome = "failed"

    def __init__(self, message: str, *, axis: str = "", target: Optional[float] = None,
                 position: Optional[float] = None, reason: str = "", code: Optional[int] = None,
                 status: Any = None, units: str = "") -> None:
        super().__init__(message)
        self.axis, self.target, self.position = axis, target, position
        self.reason, self.code, self.status, self.units = reason, code, status, units


class MoveInterrupted(MoveFailed):
    """Stopped before the target: a stop or quick stop from this program, another
    program, or a stop input of the drive."""

    __module__ = "motorbus"

    outcome = "interrupted"


class LimitReached(MoveFailed):
    """Stopped by a hard limit switch or a soft travel limit (``side``: +1 or -1, 0 if
    the drive does not say which)."""

    __module__ = "motorbus"

    outcome = "limit"

    def __init__(self, message: str, *, side: int = 0, **kw: Any) -> None:
        super().__init__(message, **kw)
        self.side = side


class MoveFaulted(MoveFailed):
    """The drive faulted during the move (``code`` and ``reason`` are the drive's)."""

    __module__ = "motorbus"

    outcome = "fault"


class MoveStalled(MoveFailed):
    """The rotor stalled or the following error grew too large (a drive's stall
    detection, a closed-loop stepper giving up its correction)."""

    __module__ = "motorbus"

    outcome = "stall"


class MoveTimedOut(MoveFailed, _core.TimeoutError):
    """Not at rest within the timeout (also a ``motorbus.TimeoutError``); the motor may
    still be moving: ``position`` is where it was then."""

    __module__ = "motorbus"

    outcome = "timeout"


@dataclass(frozen=True)
class StopReason:
    """What a kind can see of why its drive stopped (``Drive._stop_reason``)."""

    error: type                 # a MoveFailed subclass
    text: str                   # the drive's own words: "+limit switch", "0x7500 overcurrent"...
    code: Optional[int] = None
    side: int = 0               # LimitReached: +1 / -1


@dataclass(frozen=True)
class MoveOutcome:
    """The last move's outcome (``DriveStatus.last_move``): what was asked, where it ended."""

    what: str                   # "move", "jog" or "home"
    target: Optional[float]     # user units (None: jog, home)
    position: Optional[float]   # user units, where it came to rest (None while running)
    state: str                  # "running", "done" or the failure's outcome word
    reason: str = ""
    error: Optional[MoveFailed] = None

    @property
    def ok(self) -> bool:
        return self.state == "done"


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
    #: The last move, jog or homing of this Drive and how it ended (None: none yet).
    last_move: Optional[MoveOutcome] = None


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
    the truth).  A vendor implements ``_names``, ``_info`` (plain functions: the
    kind's tables) and ``_read``, ``_write`` (coroutines over ``drive.io``)."""

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
        return faces.run(self._co_get(name))

    async def _co_get(self, name: str) -> Any:
        self._drive._check_open()
        return await _value(self._read(self.describe(name)))

    def __setitem__(self, name: str, value: Any) -> None:
        faces.run(self._co_set(name, value))

    async def _co_set(self, name: str, value: Any) -> None:
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
        await _value(self._write(info, value))

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


def stopped_by_text(by: str) -> str:
    """The outcome's words for who stopped a move: a bare call ("stop()", "quick_stop()") is
    this program's; anything else names its origin itself ("stop() of the program with pid
    42 through motorbus serve", "STOP of the EPICS record lab:x", "the cancellation of the
    awaiting task")."""
    return f"{by} of this program" if by.endswith("()") else by


class _Move:
    """The move, jog or homing in progress: what was asked, in native units, and what
    must be put back when it ends (settings a ``velocity=`` changed for this move)."""

    __slots__ = ("what", "target", "stopped_by", "restore", "judged", "commanded")

    def __init__(self, what: str, target: Optional[float]) -> None:
        self.what = what
        self.target = target
        self.stopped_by: Optional[str] = None      # "stop()" / "quick_stop()" of this program
        self.restore: list[Callable[[], Any]] = []
        self.judged = False
        # False while the command is being sent: a drive at rest then has not started
        # this move yet, and a reading awaited meanwhile (another task) must not judge it.
        self.commanded = False


class Drive(abc.ABC):
    """One motor axis, whatever its vendor.  See the module doc.

    Subclasses set ``kind``, ``capabilities`` and implement the ``_`` methods in
    native units; ``native`` is the vendor client they wrap.

    A kind's subclass is also its plugin: the ``motorbus.drive`` entry point names
    it (as python-can's ``can.interface`` names a bus class), its class attributes
    below say what the kind is, and the registry's consumers (``open_drive``, the
    simulators, discovery, benches, the Poller, plots) call its hooks: classmethods
    for what comes before a drive is open (``open``, ``make_sim``, ``check_address``,
    ``probe``, ``canopen_match``, ``store_options``, ``synchronised_start``,
    ``sim_faults``), methods for what acts on an open one (``poll_fields``,
    ``capture_fields``, ``plan_move``).  An optional capability is a hook the kind
    overrides (``provides(hook)`` says which); the defaults say the kind lacks it."""

    kind: str = "?"
    #: One line for ``motorbus kinds`` and ``drive_kinds()``.
    description: str = ""
    #: ``"serial"`` (a line, shared by drives of one kind: RS-485 multi-drop) or
    #: ``"can"`` (a node on a CAN bus); the registry refuses anything else.
    transport: str = ""
    #: The address a bench file or a test uses when it names none.
    default_address: str = ""
    #: Serial only: the framing (request/reply terminators, max line) a line server
    #: and a LineLink need, as keyword arguments of both.
    line_settings: Optional[dict] = None
    #: Serial only: the line's baud rate unless a bench file says otherwise.
    default_baud: int = 0
    #: The keyword options ``make_sim`` takes (``sim serve`` and bench files pass them through).
    sim_options: tuple = ()
    #: What a discovery sweep tries (``probe``): addresses, and bauds on a serial line.
    probe_addresses: tuple = ()
    probe_bauds: tuple = ()
    capabilities: frozenset = frozenset()
    #: The drive stops by itself when the link to this host is lost.
    has_watchdog: bool = False
    #: Seconds a waiting call allows when given timeout=None.
    default_timeout: float = 60.0
    #: Poll period of the generic wait_idle.
    poll_interval: float = 0.005
    #: How far from its target (native units) a move may come to rest and still count as
    #: arrived, when the kind does not read it from the drive (``_in_position_window``).
    in_position_window: float = 0.0
    #: ``move_to(velocity=)`` sets the speed of that move (False: the kind's position speed
    #: is a drive setting only its own tools change, and ``velocity=`` is refused).
    per_move_velocity: bool = True
    #: The homing methods for "home forward" and "home reverse" (the motor record's HOMF
    #: and HOMR); None: the kind's default method.
    homing_directions: tuple = (None, None)
    #: The file, in ``sim serve --store-dir``'s folder, that keeps a served drive's stored
    #: parameters (``"mykind-{address}.flash"``: formatted with the canonical address and
    #: handed to ``make_sim`` as ``store_path`` by ``store_options``); "" = the kind keeps none.
    store_file: str = ""

    # ---- the plugin: hooks of the kind (classmethods) and of an open drive -------------
    @classmethod
    def open(cls, *, line: Any = None, bus: Any = None, address: str, units: Optional[Units] = None,
             **options: Any) -> "Drive":
        """The kind's Drive on an open LineLink/port (``line``, serial kinds) or Bus/spec
        (``bus``, CAN kinds) at a canonical ``address`` (``open_drive`` checks both first)."""
        raise _core.InvalidArgument(f"drive kind {cls.kind!r} cannot be opened (its class has no open())")

    @classmethod
    def _open_on(cls, line: Any, bus: Any, native: Callable[[Any], Any], **drive_options: Any) -> "Drive":
        """What every kind's ``open`` does around its own construction, so that it states only
        that: takes the link of the kind's transport (``line=`` serial, ``bus=`` CAN; the
        other is refused), opens a bus given as an ``open_bus`` spec (closed with the drive),
        builds the vendor client on the link with ``native(link)`` and the Drive on it with
        ``cls(client, **drive_options)``.  If either fails, the client and a bus opened here
        are closed before the error goes on: a failed open leaves nothing open behind it.
        (A serial client given a port path opens and owns its port itself.)"""
        opened = None
        if cls.transport == "serial":
            if bus is not None or line is None:
                raise _core.InvalidArgument(f"{cls.kind}: a serial drive takes line=, not bus=")
            link = line
        else:
            if line is not None or bus is None:
                raise _core.InvalidArgument(f"{cls.kind}: a CAN drive takes bus=, not line=")
            if isinstance(bus, str):
                from .bus import open_bus

                bus = opened = open_bus(bus)
            link = bus
        client = None
        try:
            client = native(link)
            return cls(client, close_native=None if opened is None else opened.close, **drive_options)
        except BaseException:
            try:
                if client is not None:
                    client.close()
            finally:
                if opened is not None:
                    opened.close()
            raise

    @classmethod
    def make_sim(cls, address: Any, clock: Any = None, **options: Any) -> Any:
        """A simulated drive.  Serial: a LineDevice for a PtyLineServer.  CAN: an object
        with ``attach(bus)`` and ``close()`` (``make_sim(..., bus=bus)`` attaches at once)."""
        raise _core.InvalidArgument(f"drive kind {cls.kind!r} has no simulator")

    @classmethod
    def check_address(cls, text: Any) -> str:
        """The canonical form of an address, or InvalidArgument naming the problem.  The
        default takes any non-empty text without spaces; kinds check their own notation."""
        if not isinstance(text, (str, int)) or isinstance(text, bool) or not str(text).strip() \
                or any(c.isspace() for c in str(text).strip()):
            raise _core.InvalidArgument(f"{cls.kind} address: non-empty text without spaces, not {text!r}")
        return str(text).strip()

    @classmethod
    def store_options(cls, store_dir: str, address: str) -> dict:
        """The ``make_sim`` options that keep a served drive's stored parameters in
        ``store_dir`` (``sim serve --store-dir``): ``store_path`` = ``store_file`` there,
        none when the kind has no ``store_file``."""
        if not cls.store_file:
            return {}
        return {"store_path": os.path.join(store_dir, cls.store_file.format(address=address))}

    @classmethod
    def wire_line(cls, sims: list) -> None:
        """``sim serve``: wires the simulated drives of one served line together (a
        synchronisation chain on their I/Os), before the line is served; nothing by default."""

    @classmethod
    def probe(cls, link: Any, address: str) -> Optional[dict]:
        """Discovery (it never moves a motor nor writes a parameter): asks one address for
        its identity (``{"model", "firmware", "serial"}``, what the protocol gives) over a
        LineLink framed with ``line_settings`` (serial) or a Bus (CAN kinds that are not
        CANopen); None when nothing answers.  Default: the kind cannot be probed."""
        return None

    @classmethod
    def canopen_match(cls, node: Any) -> int:
        """CANopen kinds: a score for a node the CANopen scan found (``NodeInfo``: device
        type, vendor id, product code...), 0 = not this kind; the highest score names the
        node's kind."""
        return 0

    @classmethod
    def synchronised_start(cls, link: Any, drives: Any) -> Any:
        """A drive-level synchronised start for drives of this kind sharing ``link``: a
        context manager (its value: one word saying how); moves commanded inside it start
        together when it exits (``Bench.move_together``)."""
        raise _core.InvalidArgument(f"drive kind {cls.kind!r} has no drive-level synchronised start")

    @classmethod
    def sim_faults(cls) -> dict:
        """Faults the kind's simulator can be given for robustness tests (the pytest
        plugin's ``sim_faults`` fixture, ``sim serve``'s ``fault``): ``{name: fault(sim,
        **options)}``, each provoking what its name says on one simulated drive (a limit
        switch trips, the rotor stalls, the supply drops...).  Names are the kind's own."""
        return {}

    def poll_fields(self, fields: tuple) -> "registry.PollSpec":
        """What ``motorbus.Poller`` reads from this drive on its C++ poll thread, for
        field names among "position", "velocity", "status" (InvalidArgument for a field
        the kind cannot give)."""
        raise _core.InvalidArgument(f"{self.kind}: this drive kind cannot be polled")

    def capture_fields(self, fields: tuple, period: float) -> "registry.PollSpec":
        """For kinds whose drive can push its data (CANopen TPDOs, cyclic registers): sets
        the drive to transmit ``fields`` about every ``period`` s and returns a capture
        source (``stamped=True``) that takes what arrives instead of asking."""
        raise _core.InvalidArgument(f"{self.kind}: this drive kind cannot push its data")

    def plan_move(self, start: float, target: float) -> Any:
        """The kind's own profile model of a position move: a ``motion.Profile`` in native
        units, t = 0 at the command, from the drive's current speed/ramp parameters
        (``motorbus.plot.planned``, ``motorbus demo``)."""
        raise _core.InvalidArgument(f"drive kind {self.kind!r} has no profile model (plan_move)")

    @classmethod
    def provides(cls, hook: str) -> bool:
        """True when the kind overrides ``hook`` (one of ``HOOKS``): an optional
        capability its consumers offer only where it exists."""
        if hook not in HOOKS:
            raise _core.InvalidArgument(f"Drive.provides: a hook among {', '.join(HOOKS)}, not {hook!r}")
        def function(attr: Any) -> Any:     # a classmethod's function (a kind may restore the default)
            return getattr(attr, "__func__", attr)

        return function(inspect.getattr_static(cls, hook)) is not function(Drive.__dict__[hook])

    def __init__(self, native: Any, *, units: Optional[Units] = None, on_error: StopHow = "stop",
                 on_exit: StopHow = "stop", close_native: Optional[Callable[[], None]] = None) -> None:
        check_stop_way(on_error, "on_error")
        check_stop_way(on_exit, "on_exit")
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
        self._move: Optional[_Move] = None
        self._last_move: Optional[MoveOutcome] = None
        #: The name errors give this axis (a bench sets its axis name).
        self.name = self.kind
        #: The native client's calls as awaitables, for the kind's hooks (motorbus.faces):
        #: done at once in the blocking face, on the link's worker in the awaitable one.
        self.io = faces.NativeIo(native, self._io_link())
        _stop_at_exit.track(self)

    def _io_link(self) -> Any:
        """What this drive's native calls share a worker with in the awaitable face: the
        line or bus they go over (``native.link`` where the client has one), so that
        the drives of one RS-485 line queue on one worker as they queue on the wire."""
        return getattr(self.native, "link", None)

    # ---- vendor side (native units) -------------------------------------------------
    # The hooks are ``async def`` coroutines that talk to the drive through ``self.io``
    # (motorbus.faces): written once, they serve the blocking verbs and motorbus.aio alike.
    @abc.abstractmethod
    async def _enable(self) -> None: ...

    @abc.abstractmethod
    async def _disable(self) -> None: ...

    @abc.abstractmethod
    async def _move_to(self, target: float, velocity: Optional[float]) -> None: ...

    async def _move_by(self, distance: float, velocity: Optional[float]) -> None:
        await self._move_to(await self._position() + distance, velocity)

    @abc.abstractmethod
    async def _jog(self, velocity: float) -> None: ...

    @abc.abstractmethod
    async def _stop(self) -> None: ...

    @abc.abstractmethod
    async def _quick_stop(self) -> None: ...

    async def _home(self, method: Any) -> None:
        raise _core.InvalidArgument(f"{self.kind}: this drive has no homing")

    async def _homing_done(self) -> bool:
        """True when a homing started by _home has finished (raise on a homing error)."""
        return not (await self._status()).moving

    @abc.abstractmethod
    async def _clear_faults(self) -> None: ...

    async def _store(self) -> None:
        raise _core.InvalidArgument(f"{self.kind}: this drive cannot store its parameters")

    @abc.abstractmethod
    async def _position(self) -> float: ...

    @abc.abstractmethod
    async def _velocity(self) -> float: ...

    @abc.abstractmethod
    async def _status(self) -> DriveStatus: ...

    async def _is_idle(self) -> bool:
        """True once the motor is at rest, whatever the reason (target, limit, fault,
        stop): the outcome is judged afterwards from ``_stop_reason`` and the position."""
        return not (await self._status()).moving

    def _stop_reason(self, status: DriveStatus) -> Optional[StopReason]:
        """Why the drive stopped, as far as it says (a fault, a limit, a stall, a stop
        input), or None when it shows no reason.  Called once the motor is at rest after
        a move that did not reach its target (and for a jog or a homing), and after a
        move that did, where a fault or stall still fails it.  Kinds override this
        to map their own status words and error registers; the default reads the
        common fields of ``status``."""
        if status.fault:
            return StopReason(MoveFaulted, status.text)
        if status.limit_positive or status.limit_negative:
            side = 1 if status.limit_positive else -1
            return StopReason(LimitReached, f"the {'+' if side > 0 else '-'}limit switch", side=side)
        return None

    def _in_position_window(self) -> float:
        """How far from its target (native units) a move may end and count as arrived."""
        return self.in_position_window

    async def _for_this_move(self, read: Callable[[], Any], write: Callable[[Any], Any], value: Any) -> None:
        """For a vendor's ``_move_to`` (``await self._for_this_move(...)``): sets a drive
        setting (a speed) for the move being started and puts the old value back once it
        has ended, however it ended.  ``read``/``write`` may return awaitables (``self.io...``)
        or values (a speed the kind already knows)."""
        old = await _value(read())
        await _value(write(value))
        if self._move is not None:
            self._move.restore.append(lambda: write(old))

    async def _travel_limits(self) -> tuple[Optional[float], Optional[float]]:
        """The soft travel limits the drive itself enforces now, native units (None: no limit that side)."""
        return (None, None)

    # ---- speed and ramps, for callers that set them as a motion controller does ----------------
    # (the EPICS motor record's VELO/VMAX/ACCL, docs/epics.md).  A kind says where its
    # position-move speed lives and how its ramps are written; the defaults say "not known".

    async def _move_speed(self) -> tuple[Optional[float], Optional[float]]:
        """(the speed a position move runs at now, its declared maximum), native units per
        second; None where the kind does not say."""
        return (None, None)

    async def _set_accel_time(self, seconds: float, speed: float, top: Optional[float]) -> bool:
        """Writes the kind's ramp settings so that a move reaches ``speed`` (native units/s)
        from rest in ``seconds`` (``top``: the maximum of ``_move_speed``, for drives whose
        ramps are times to their maximum).  The drive keeps them.  False: the kind has no
        ramp it can set this way."""
        return False

    async def _speed_param(self, name: str, per_unit: float = 1.0) -> tuple[Optional[float], Optional[float]]:
        """For ``_move_speed``: a speed parameter's value and declared maximum, each times
        ``per_unit`` (native units/s per the parameter's unit)."""
        if name not in self.params:
            return (None, None)
        now = abs(float(await self.params._co_get(name))) * per_unit
        top = self.params.describe(name).maximum
        return (now or None, None if top is None else abs(float(top)) * per_unit)

    async def _set_params_clamped(self, values: Mapping[str, float]) -> None:
        """For ``_set_accel_time``: writes each parameter the drive has, clamped into its
        declared range (rounded for an integer one)."""
        for name, value in values.items():
            if name not in self.params:
                continue
            info = self.params.describe(name)
            if info.minimum is not None:
                value = max(value, info.minimum)
            if info.maximum is not None:
                value = min(value, info.maximum)
            await self.params._co_set(name, int(round(value)) if info.type == "int" else value)

    def _make_params(self) -> Params:
        return Params(self)

    def _close(self) -> None:
        """Release what the vendor opened (the native client); the link is closed by Drive."""

    async def _console(self, line: str) -> str:
        """One request in the drive's own protocol -> its answer as text (`console`)."""
        raise _core.InvalidArgument(f"{self.kind}: this drive has no protocol console")

    # ---- commands ------------------------------------------------------------------
    # Each verb is one coroutine, ``_co_<verb>``: the logic, written once.  The blocking
    # verb below runs it to its end on the calling thread (``faces.run``); motorbus.aio
    # awaits the same coroutine.  A kind's hooks are coroutines too (``self.io``).
    def enable(self) -> None:
        """Power the motor (the drive holds position)."""
        faces.run(self._co_enable())

    async def _co_enable(self) -> None:
        self._check_open()
        log.debug("%s: enable", self.name)
        await self._enable()

    def disable(self) -> None:
        """Power stage off: the motor no longer holds position."""
        faces.run(self._co_disable())

    async def _co_disable(self) -> None:
        self._check_open()
        log.debug("%s: disable", self.name)
        await self._disable()

    def move_to(self, position: float, *, velocity: Optional[float] = None, wait: bool = True,
                timeout: Optional[float] = None) -> None:
        """Absolute move in user units; ``velocity`` (user units/s) for this move, else the drive's own."""
        faces.run(self._co_move_to(position, velocity=velocity, wait=wait, timeout=timeout))

    async def _co_move_to(self, position: float, *, velocity: Optional[float] = None, wait: bool = True,
                          timeout: Optional[float] = None) -> None:
        self._check_open()
        log.debug("%s: move_to %r %s (velocity %r, wait %s)", self.name, position, self._units.name, velocity, wait)
        target = self._units.to_native(self._number("position", position))
        speed = self._speed_arg(velocity)
        await self._start("move", target, lambda: self._move_to(target, speed))
        if wait:
            await self._co_wait_idle(timeout)

    def move_by(self, distance: float, *, velocity: Optional[float] = None, wait: bool = True,
                timeout: Optional[float] = None) -> None:
        """Relative move in user units."""
        faces.run(self._co_move_by(distance, velocity=velocity, wait=wait, timeout=timeout))

    async def _co_move_by(self, distance: float, *, velocity: Optional[float] = None, wait: bool = True,
                          timeout: Optional[float] = None) -> None:
        self._check_open()
        log.debug("%s: move_by %r %s (velocity %r, wait %s)", self.name, distance, self._units.name, velocity, wait)
        distance = self._units.to_native(self._number("distance", distance))
        speed = self._speed_arg(velocity)
        await self._settle()
        target = await self._position() + distance
        await self._start("move", target, lambda: self._move_by(distance, speed))
        if wait:
            await self._co_wait_idle(timeout)

    def jog(self, velocity: float) -> None:
        """Run at ``velocity`` (user units/s, the sign is the direction) until stop()."""
        faces.run(self._co_jog(velocity))

    async def _co_jog(self, velocity: float) -> None:
        self._check_open()
        log.debug("%s: jog %r %s/s", self.name, velocity, self._units.name)
        v = self._units.to_native(self._number("velocity", velocity))
        if v == 0:
            await self._co_stop()
            return
        await self._start("jog", None, lambda: self._jog(v))

    def stop(self) -> None:
        """Decelerate to a stop with the drive's deceleration.  A move this stops ends in
        ``MoveInterrupted`` (from its ``wait_idle``); a jog ends normally."""
        faces.run(self._co_stop())

    async def _co_stop(self, by: str = "stop()") -> None:
        self._check_open()
        log.debug("%s: stop", self.name)
        if self._move is not None and self._move.stopped_by is None:
            self._move.stopped_by = by
        await self._stop()

    def quick_stop(self) -> None:
        """The fastest stop the drive has (an abort or the quick-stop ramp)."""
        faces.run(self._co_quick_stop())

    async def _co_quick_stop(self, by: str = "quick_stop()") -> None:
        self._check_open()
        log.debug("%s: quick_stop", self.name)
        if self._move is not None and self._move.stopped_by is None:
            self._move.stopped_by = by
        await self._quick_stop()

    def home(self, method: Any = None, *, wait: bool = True, timeout: Optional[float] = None) -> None:
        """Run the drive's homing (``method``: the vendor's own, None = its default);
        returns once it has finished, else raises a :class:`MoveFailed`."""
        faces.run(self._co_home(method, wait=wait, timeout=timeout))

    async def _co_home(self, method: Any = None, *, wait: bool = True, timeout: Optional[float] = None) -> None:
        self._check_open()
        log.debug("%s: home (method %r, wait %s)", self.name, method, wait)
        await self._start("home", None, lambda: self._home(method))
        if wait:
            await self._co_wait_idle(timeout)

    def wait_idle(self, timeout: Optional[float] = None) -> None:
        """Return when the motor is at rest.  After a move, jog or homing of this Drive,
        return only if it ended where it was sent (a jog: by this program's ``stop()``);
        otherwise raise the :class:`MoveFailed` subclass that says why, once
        (``status.last_move`` keeps it).  ``MoveTimedOut`` (a ``TimeoutError``) after
        ``timeout`` s (None = ``default_timeout``)."""
        faces.run(self._co_wait_idle(timeout))

    async def _co_wait_idle(self, timeout: Optional[float] = None) -> None:
        self._check_open()
        move = self._move
        if move is None or move.judged:
            await self._wait(self._is_idle, timeout, "motion")
            return
        done = self._homing_done if move.what == "home" else self._is_idle
        limit = self.default_timeout if timeout is None else self._number("timeout", timeout)
        try:
            await self._wait(done, limit, "homing" if move.what == "home" else move.what)
        except MoveFailed as e:
            self._finish(move, e)
            raise
        except _core.TimeoutError:
            raise await self._failure(move, StopReason(MoveTimedOut, f"the timeout ({limit:g} s)"),
                                      at_rest=False) from None
        except _core.DriveFault as e:       # a kind's own error while waiting: a fault
            raise await self._failure(move, StopReason(MoveFaulted, str(e))) from e
        await self._judge(move, raise_error=True)

    # ---- the outcome of a move ----------------------------------------------------
    async def _start(self, what: str, target: Optional[float], command: Callable[[], Any]) -> None:
        """Begins a move, jog or homing: the previous one's settings are put back first."""
        await self._settle()
        move = _Move(what, target)
        self._move = move
        self._last_move = MoveOutcome(what, None if target is None else self._units.to_user(target), None, "running")
        try:
            await command()
        except asyncio.CancelledError:
            # Cancelled while the command was on its way: the drive may have taken it, so
            # the move stays on record for the cancellation's stop to judge (motorbus.aio).
            move.commanded = True
            raise
        except BaseException:
            await self._restore(move)
            self._move, self._last_move = None, None
            raise
        move.commanded = True

    async def _settle(self) -> None:
        """Judges an earlier move nobody waited for, if it has ended (its outcome goes to
        ``status.last_move``, not raised), and puts its settings back."""
        move = self._move
        if move is not None and not move.judged and move.commanded:
            try:
                if move.what == "home" or not await self._is_idle():
                    await self._restore(move)     # superseded; a homing is not judged by rest alone
                    move.judged = True
                    return
                await self._judge(move, raise_error=False)
            except MoveFailed:
                pass

    async def _judge(self, move: _Move, *, raise_error: bool) -> None:
        """The motor is at rest after ``move``: done, or the MoveFailed that says why."""
        status = await self._status()
        reason = await _value(self._stop_reason(status))
        position = await self._position()
        # A target in user units is a float in native units (8.88 mm at 0.01 mm = 887.9999999999999
        # steps, which the kind sends as step 888): that rounding is not a distance from the target.
        arrived = move.target is None or abs(position - move.target) <= (
            await _value(self._in_position_window()) + 1e-9 * max(1.0, abs(move.target)))
        if move.what == "home":
            failed = (reason is not None and reason.error is not LimitReached) or move.stopped_by is not None \
                or not status.homed
        elif move.what == "jog":
            failed = reason is not None or move.stopped_by is None
        else:
            failed = not arrived or (reason is not None and reason.error in (MoveFaulted, MoveStalled))
        if not failed:
            await self._finish_restored(move, None, position)
            return
        if reason is None:
            if move.stopped_by is not None:
                reason = StopReason(MoveInterrupted, stopped_by_text(move.stopped_by))
            elif move.what == "home":
                reason = StopReason(MoveInterrupted, "an end of the homing before the drive was homed (a stop "
                                                     "from another program or a stop input?)")
            else:
                reason = StopReason(MoveInterrupted, "a stop from another program or a stop input (the drive "
                                                     "shows no fault or limit)")
        error = await self._failure(move, reason, status=status, position=position)
        if raise_error:
            raise error

    async def _failure(self, move: _Move, reason: StopReason, *, status: Optional[DriveStatus] = None,
                       position: Optional[float] = None, at_rest: bool = True) -> MoveFailed:
        """Builds the error for ``move`` (and records it as the last outcome)."""
        if position is None:
            try:
                position = await self._position()
            except Exception:  # noqa: BLE001 - the error must still be raised
                position = math.nan
        if status is None:
            try:
                status = await self._status()
            except Exception:  # noqa: BLE001
                status = None
        u = self._units
        where, goal = u.to_user(position), None if move.target is None else u.to_user(move.target)
        place = "still moving at" if not at_rest else "stopped at"
        what = {"move": f"target {goal:g} {u.name}" if goal is not None else "move",
                "jog": "a jog", "home": "homing"}[move.what]
        kw = dict(axis=self.name, target=goal, position=where, reason=reason.text, code=reason.code,
                  status=None if status is None else status.raw, units=u.name)
        message = f"{self.name}: {place} {where:g} {u.name} by {reason.text}, {what}"
        error = (reason.error(message, side=reason.side, **kw) if issubclass(reason.error, LimitReached)
                 else reason.error(message, **kw))
        await self._finish_restored(move, error, position)
        return error

    async def _finish_restored(self, move: _Move, error: Optional[MoveFailed], position: Optional[float] = None) -> None:
        await self._restore(move)
        self._finish(move, error, position)

    def _finish(self, move: _Move, error: Optional[MoveFailed], position: Optional[float] = None) -> None:
        """Records how ``move`` ended (its settings are put back by the caller)."""
        log.debug("%s: %s ended: %s", self.name, move.what, "done" if error is None else error)
        move.judged = True
        u = self._units
        if position is None and error is not None:
            where = error.position
        else:
            where = None if position is None else u.to_user(position)
        self._last_move = MoveOutcome(move.what, None if move.target is None else u.to_user(move.target), where,
                                      "done" if error is None else error.outcome,
                                      "" if error is None else error.reason, error)

    async def _restore(self, move: _Move) -> None:
        steps, move.restore = move.restore, []
        for put_back in steps:
            try:
                await _value(put_back())
            except Exception:  # noqa: BLE001 - a lost link must not hide the move's outcome
                pass

    def clear_faults(self) -> None:
        """Clear latched faults (limit errors, drive faults) so it accepts motion again."""
        faces.run(self._co_clear_faults())

    async def _co_clear_faults(self) -> None:
        self._check_open()
        log.debug("%s: clear_faults", self.name)
        await self._clear_faults()

    def console(self, line: str) -> str:
        """Sends one request in the drive's own protocol and returns the answer as text:
        what ``motorbus terminal`` types (ASCII commands for serial drives, SDO reads and
        writes for CANopen drives...; the vendor's docs give the syntax).  Bypasses the
        Drive's bookkeeping: a move started here is not known to ``wait_idle``."""
        return faces.run(self._co_console(line))

    async def _co_console(self, line: str) -> str:
        self._check_open()
        if not isinstance(line, str):
            raise _core.InvalidArgument(f"{self.kind} console: a line of text, not {type(line).__name__}")
        return await self._console(line.strip())

    def store(self) -> None:
        """Persist the parameters in the drive's non-volatile memory."""
        faces.run(self._co_store())

    async def _co_store(self) -> None:
        self._check_open()
        log.debug("%s: store", self.name)
        await self._store()

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
        return faces.run(self._co_position())

    async def _co_position(self) -> float:
        self._check_open()
        return self._units.to_user(await self._position())

    @property
    def velocity(self) -> float:
        """Velocity in user units per second."""
        return faces.run(self._co_velocity())

    async def _co_velocity(self) -> float:
        self._check_open()
        return self._units.to_user(await self._velocity())

    @property
    def status(self) -> DriveStatus:
        """The drive's status now, with ``last_move``: how the last move, jog or homing
        ended (judged here if it ended while nobody waited)."""
        return faces.run(self._co_status())

    async def _co_status(self) -> DriveStatus:
        self._check_open()
        await self._settle_if_at_rest()
        st = await self._status()
        last = self._last_move
        if last is not None and last.what == "move" and last.state != "done" and st.at_target:
            st = dataclasses.replace(st, at_target=False)     # halted short: not "at target"
        return dataclasses.replace(st, last_move=last)

    async def _settle_if_at_rest(self) -> None:
        move = self._move
        if move is not None and not move.judged and move.commanded and move.what != "home":
            try:
                if await self._is_idle():
                    await self._judge(move, raise_error=False)
            except _core.DriveFault:    # judged and recorded in last_move
                pass

    @property
    def units(self) -> Units:
        return self._units

    @property
    def travel_limits(self) -> tuple[float, float]:
        """``(low, high)`` in user units: the soft limits the drive enforces now, read from it;
        ``-inf`` / ``inf`` on a side where it has none (most kinds have none at all)."""
        return faces.run(self._co_travel_limits())

    async def _co_travel_limits(self) -> tuple[float, float]:
        self._check_open()
        lo, hi = await self._travel_limits()
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
            _stop_at_exit.halt(how, lambda: faces.run(self._stop()), lambda: faces.run(self._quick_stop()),
                               lambda: faces.run(self._disable()))

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

    async def _wait(self, done: Callable[[], Any], timeout: Optional[float], what: str) -> None:
        """Polls ``done`` every ``poll_interval`` until true: the thread sleeps between polls
        in the blocking face, the task in the awaitable one."""
        limit = self.default_timeout if timeout is None else self._number("timeout", timeout)
        if limit < 0:
            raise _core.InvalidArgument(f"{self.name}: timeout must be >= 0, not {limit!r}")
        deadline = time.monotonic() + limit
        while not await done():
            if time.monotonic() >= deadline:
                raise _core.TimeoutError(f"{self.name}: {what} not finished after {limit:g} s")
            await faces.sleep(self.poll_interval)

    def __repr__(self) -> str:
        state = "closed" if self._closed else "open"
        return f"<{type(self).__name__} {self.kind} {state}, units={self._units.name}>"


registry.set_drive_base(Drive)

#: The hooks that talk to the drive: coroutine functions in every kind (the registry
#: refuses a kind that has one as a plain function).  ``_stop_reason`` and
#: ``_in_position_window``, which judge what was read, may be either.
Drive.COROUTINE_HOOKS = ("_enable", "_disable", "_move_to", "_move_by", "_jog", "_stop", "_quick_stop", "_home",
                         "_homing_done", "_is_idle", "_clear_faults", "_store", "_position", "_velocity", "_status",
                         "_travel_limits", "_console", "_move_speed", "_set_accel_time")

#: The plugin hooks a kind may override (``Drive.provides``).
HOOKS = ("open", "make_sim", "check_address", "store_options", "wire_line", "probe", "canopen_match", "synchronised_start",
         "sim_faults", "poll_fields", "capture_fields", "plan_move")


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
    cls = registry.drive_plugin(kind)
    # An integer means that integer for every kind (a CAN id 0x201 is 513, not "513" read
    # as hex text by a kind that writes its ids in hex); text is the vendor's own notation.
    is_int = isinstance(address, int) and not isinstance(address, bool)
    canonical = cls.check_address(address if is_int else str(address).strip())
    if cls.transport == "serial":
        if line is None or bus is not None:
            raise _core.InvalidArgument(f"open_drive({kind!r}): a serial drive takes line=, not bus=")
    elif bus is None or line is not None:
        raise _core.InvalidArgument(f"open_drive({kind!r}): a CAN drive takes bus=, not line=")
    # The stop words before any line or bus is opened (the Drive checks them again, for
    # kinds opened another way): a typo must not leave a link half-opened behind it.
    for key in ("on_error", "on_exit"):
        if key in options:
            check_stop_way(options[key], key)
    return cls.open(line=line, bus=bus, address=canonical, units=units, **options)

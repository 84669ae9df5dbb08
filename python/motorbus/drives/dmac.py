"""Midi Ingénierie DMAC17/23/34 over its ASCII protocol: client, simulator, Drive adapter.

Example — a simulated module on a pty, driven through the typed client::

    from motorbus._core.runtime import SimClock
    from motorbus.serial import PtyLineServer
    from motorbus.drives.dmac import DmacClient, DmacStatus, make_sim

    clock = SimClock()
    with PtyLineServer([make_sim("00", clock=clock)]) as server:
        with DmacClient(server.slave_path, "00") as axis:   # STOP on error and at exit
            axis.brake(False)                       # DMAC34: factory BRAKE ON
            axis.move_to(200000)                    # 20 turns, 1/10000 rev units
            clock.advance(5_000_000_000)            # 5 s of device time
            assert axis.position == 200000
            assert DmacStatus.POWER_ON in axis.status

Units are the module's: positions in 1/10000 rev, speeds in 0.01 rpm, times in ms.
Requests end with CR, replies with CR LF (``LINE_SETTINGS``; the manual does not
say, see docs/drives/dmac.md).
"""
from __future__ import annotations

import enum
import math
import contextlib
from typing import Any, AsyncIterator, Iterable, Iterator, Optional, Sequence

from .. import _core, _stop_at_exit, faces
from ..stopping import check_stop_way
# The DMAC's profile model (#ACCEL_TIME/#DECEL_TIME, the closed-loop approach at #LOW_SPEED):
# the vendor's own module re-exports it (motorbus.motion keeps the generic planners).
from .._core.dmac import (  # noqa: F401
    Motion as DmacMotion, ProfileParams as DmacProfileParams, position_profile as dmac_position_profile,
    ramp_time as dmac_ramp_time, speed_profile as dmac_speed_profile,
)
from ..drive import (Capability, Drive, DriveStatus, LimitReached, MoveFailed, MoveFaulted, MoveInterrupted,
                     MoveTimedOut, ParamInfo, Params, StopReason, stopped_by_text)

from .._core.dmac import (  # noqa: E402,F401
    Sim as DmacSim, SimState as DmacSimState, Radix as DmacRadix, ReadReply as DmacReadReply,
    VariableInfo as DmacVariableInfo, VersionInfo as DmacVersionInfo, ClientCounters as DmacClientCounters,
    StreamStats as DmacStreamStats,
)
UnknownCommand = _core.DmacUnknownCommand
CommandRejected = _core.DmacCommandRejected
from .._core.dmac import (  # noqa: E402,F401
    format_value, parse_read_reply, status_names, error_names, variable as variable_info,
)

#: Line settings of a DMAC bus (what ``motorbus sim serve --drive dmac:NN`` uses).
LINE_SETTINGS = {"request_terminator": b"\r", "reply_terminators": [b"\r\n"], "max_line": 256}
#: The single byte a full interpolation FIFO answers to MOVE_INTERPOL.
XON_ERROR = b"\x17"
#: Baud rates SET_BAUDRATE accepts; 38400 is the factory default.
BAUDRATES = (9600, 19200, 38400, 115200)
DEFAULT_BAUD = 38400
DEFAULT_ADDRESS = "00"


def _bit(n: int) -> int:
    """The manual numbers bits 1..32, bit 1 the LSB: bit n is 1 << (n - 1)."""
    return 1 << (n - 1)


class DmacStatus(enum.IntFlag):
    """#STATUS (manual 5.25), bits named as the manual's table names them.

    The manual numbers bits 1..32 with bit 1 the LSB: ``BUSY`` (bit 29) is
    ``1 << 28``.  Where the manual's text contradicts its table (5.7 and 5.19
    call the polarity bits 13 and 12) the table wins: 12 S-curve, 13 inputs, 14
    outputs."""

    OPTIMIZED_CURRENT = _bit(4)
    HARD_POSITIVE_END_ENABLED = _bit(5)
    HARD_NEGATIVE_END_ENABLED = _bit(6)
    SOFT_ENDS_ENABLED = _bit(7)
    HARD_ENDS_INVERTED = _bit(8)
    S_CURVE = _bit(12)
    INPUTS_INVERTED = _bit(13)
    OUTPUTS_INVERTED = _bit(14)
    SEQUENCER_RUN = _bit(15)
    SEQUENCER_EDIT = _bit(16)
    HARD_POSITIVE_END = _bit(17)
    HARD_NEGATIVE_END = _bit(18)
    SOFT_POSITIVE_END = _bit(19)
    SOFT_NEGATIVE_END = _bit(20)
    BRAKE = _bit(21)
    SYNCHRO = _bit(23)
    POWER_ON = _bit(25)
    MOVEMENT = _bit(26)
    POSITION_CONTROL = _bit(27)
    BUSY = _bit(29)
    REFERENCE = _bit(30)
    ERROR = _bit(31)
    ABNORMAL_STOP = _bit(32)

    def bit(self, n: int) -> bool:
        """Bit ``n`` as the manual numbers it (1..32)."""
        if not 1 <= n <= 32:
            raise _core.InvalidArgument(f"#STATUS bit: {n} is outside 1..32")
        return bool(int(self) & _bit(n))

    @property
    def names(self) -> list:
        return status_names(int(self))


class DmacErrorWord(enum.IntFlag):
    """#ERROR (manual 5.5), bits named as the manual names them (bit n = 1 << (n - 1)).

    Bits 2..5 are hardware faults that stop the motor (``FAULTS``); 7, 8 and 12
    are a refused command.  ``#ERROR:=0`` (``clear_error()``) acknowledges."""

    THERMAL = _bit(2)
    SHORT_CIRCUIT = _bit(3)
    UNDERVOLTAGE = _bit(4)
    OVERVOLTAGE = _bit(5)
    LIMIT = _bit(7)
    COMPUTATION = _bit(8)
    SYNTAX = _bit(12)

    def bit(self, n: int) -> bool:
        if not 1 <= n <= 32:
            raise _core.InvalidArgument(f"#ERROR bit: {n} is outside 1..32")
        return bool(int(self) & _bit(n))

    @property
    def names(self) -> list:
        return error_names(int(self))


#: The #ERROR bits that are hardware faults (the FAULT output, OUT2).
FAULTS = DmacErrorWord.THERMAL | DmacErrorWord.SHORT_CIRCUIT | DmacErrorWord.UNDERVOLTAGE | DmacErrorWord.OVERVOLTAGE


class HomingFailed(MoveFailed):
    """A DMAC reference run that did not end homed: a :class:`motorbus.MoveFailed`.  The
    error raised is one of its subclasses, also the outcome class of the reason: an
    end-stop (:class:`HomingLimitReached`, a ``LimitReached``), a fault
    (:class:`HomingFaulted`), a stop (:class:`HomingInterrupted`) or no IN5 reference
    edge within the timeout (:class:`HomingTimedOut`, a ``MoveTimedOut``)."""


class HomingLimitReached(HomingFailed, LimitReached):
    """An end-stop stopped the reference run before IN5 rose."""


class HomingFaulted(HomingFailed, MoveFaulted):
    """A hardware fault (#ERROR bits 2..5) stopped the reference run."""


class HomingInterrupted(HomingFailed, MoveInterrupted):
    """A STOP, HALT, POWER OFF or BRAKE ON (this program, another client on the line) ended the run."""


class HomingTimedOut(HomingFailed, MoveTimedOut):
    """No IN5 reference edge within the timeout (the search is stopped)."""


#: Where make_sim's IN5 reference switch turns on (1/10000 rev, stays on beyond it): the
#: default homing finds it from anywhere (it backs off first when IN5 is already on).
DEFAULT_REFERENCE_SWITCH = 3000.0

#: The manual's words for the #ERROR fault bits (2.1, 3.5.4, 5.5).
_FAULT_TEXT = {
    2: "thermal disjunction (#ERROR bit 2): the motor or the electronics above 85 degC, or the CPU above "
       "120 degC; the motor power is cut",
    3: "short-circuit (#ERROR bit 3): a motor overcurrent disjunction; the motor power is cut",
    4: "undervoltage (#ERROR bit 4): the supply dropped below {under} V; motion is stopped and the module is "
       "in undervoltage lockout",
    5: "overvoltage (#ERROR bit 5): the supply rose above {over} V; the motor power is disabled",
}


__all__ = [
    "BAUDRATES",
    "CommandRejected",
    "DEFAULT_ADDRESS",
    "DEFAULT_BAUD",
    "DEFAULT_REFERENCE_SWITCH",
    "DmacClient",
    "DmacClientCounters",
    "DmacDrive",
    "DmacErrorWord",
    "DmacRadix",
    "DmacReadReply",
    "DmacSim",
    "DmacSimState",
    "DmacStatus",
    "DmacStreamStats",
    "DmacVariableInfo",
    "DmacVersionInfo",
    "FAULTS",
    "HomingFailed",
    "HomingFaulted",
    "HomingInterrupted",
    "HomingLimitReached",
    "HomingTimedOut",
    "LINE_SETTINGS",
    "UnknownCommand",
    "XON_ERROR",
    "chain_ultrasync",
    "check_address",
    "error_names",
    "format_value",
    "make_sim",
    "open_line",
    "parse_read_reply",
    "status_names",
    "stream_interpolation",
    "dmac_interpolation",
    "DmacMotion",
    "DmacProfileParams",
    "dmac_position_profile",
    "dmac_ramp_time",
    "dmac_speed_profile",
    "synchro",
    "variable_info",
]


def open_line(port: Any, *, baud: int = DEFAULT_BAUD, timeout: float = 0.5, turnaround: float = 0.0) -> Any:
    """A ``LineLink`` framed for the DMAC (CR / CR LF) on a path or an open ``Port``.

    ``timeout``: seconds a reply may take (the client adds the module's
    #LINE_DELAY and the wire time); ``turnaround``: pause before each request."""
    from ..serial import LineLink, open_port

    if baud not in BAUDRATES:
        raise _core.InvalidArgument(f"DMAC baud: {baud!r} is not one of {BAUDRATES}")
    if isinstance(port, str):
        port = open_port(port, baud)
    return LineLink(port, request_terminator=LINE_SETTINGS["request_terminator"],
                    reply_terminators=LINE_SETTINGS["reply_terminators"],
                    max_line=LINE_SETTINGS["max_line"], reply_timeout=timeout, turnaround=turnaround)


class DmacClient(_stop_at_exit.StopsMotor, _core.dmac.Client):
    """Typed DMAC commands for the module at ``address`` on a line.

    ``DmacClient(line, address=0, *, baud=38400, timeout=None, verify=True,
    sleep=None, on_error="stop", on_exit="stop")``

    * ``line``: a port path (opened with :func:`open_line`, closed by
      ``close()``), an open ``Port``, or a ``LineLink`` shared with the other
      modules of an RS-485 line (left open by ``close()``).
    * ``address``: "00".."63" or an int.
    * ``verify``: each command frame ends with ``READ #ERROR`` so a rejected
      command raises at once (``UnknownCommand`` for bit 12, ``CommandRejected``
      for bits 7/8, and for a move while a fault is latched).
    * ``timeout``: seconds per reply (None = the link's); ``sleep``: how the
      client waits when polling (``lambda s: clock.advance(int(s * 1e9))`` on a SimClock).
    * ``on_error`` / ``on_exit``: ``"stop"`` (STOP: decelerate with
      #DECEL_TIME), ``"quick_stop"`` (HALT: no ramp, maximum braking torque —
      the fastest stop a DMAC has), ``"disable"`` (POWER OFF) or None; applied
      when an exception leaves ``with`` and at interpreter exit.
    """

    def __init__(self, line: Any, address: Any = 0, *, baud: int = DEFAULT_BAUD, timeout: Optional[float] = None,
                 verify: bool = True, sleep: Any = None, on_error: Optional[str] = "stop",
                 on_exit: Optional[str] = "stop") -> None:
        check_stop_way(on_error, "on_error")
        check_stop_way(on_exit, "on_exit")
        self._port = None
        if isinstance(line, str):
            from ..serial import open_port
            self._port = open_port(line, baud)
            line = open_line(self._port, baud=baud, timeout=0.5 if timeout is None else timeout)
        elif isinstance(line, _core.serial.Port):
            line = open_line(line, baud=baud, timeout=0.5 if timeout is None else timeout)
        elif not isinstance(line, _core.serial.LineLink):
            raise _core.InvalidArgument(f"DmacClient line: a path, a Port or a LineLink, not {type(line).__name__}")
        super().__init__(line, address=_parse_address(address), baud=baud, verify=verify, timeout=timeout,
                         sleep=sleep)
        self.link = line          # what a poll source shares (motorbus.Poller)
        self.baud = baud
        self.timeout = timeout    # reply timeout (s), which a poll source reuses
        self.on_error = on_error
        self.on_exit = on_exit
        self._open = True
        _stop_at_exit.track(self)

    def _stop_on_error(self) -> None:
        self._apply(self.on_error)

    def close(self) -> None:
        """Forget this client for the exit hook; closes the port if it opened it."""
        self._open = False
        _stop_at_exit.untrack(self)
        if self._port is not None:
            port, self._port = self._port, None
            port.close()

    def _stop_at_exit(self) -> None:
        self._apply(self.on_exit)

    def _apply(self, how: Optional[str]) -> None:
        if not getattr(self, "_open", False):
            return

        def send(cmd: str) -> Any:
            # The command plus a READ, so we know the module took it; no error
            # checking that could itself raise while unwinding.
            return lambda: self.raw(f"{self.address:02d}{cmd}, READ #STATUS", expect_reply=True)
        # The words' ladder is _stop_at_exit.halt's (a failed STOP falls back to HALT, then POWER OFF).
        _stop_at_exit.halt(how, send("STOP"), send("HALT"), send("POWER OFF"))

    def __repr__(self) -> str:
        return f"DmacClient(address={self.address:02d})"


def _parse_address(address: Any) -> int:
    if isinstance(address, bool):
        raise _core.InvalidArgument(f"DMAC address: {address!r} is not a number 00..63")
    try:
        a = int(address)
    except (TypeError, ValueError):
        raise _core.InvalidArgument(f"DMAC address: {address!r} is not a number 00..63") from None
    if not 0 <= a <= 63:
        raise _core.InvalidArgument(f"DMAC address: {a} is outside 00..63")
    return a


def make_sim(address: Any = "00", clock: Any = None, **options: Any) -> DmacSim:
    """Factory for ``motorbus sim serve --pty --drive dmac:00``.

    ``address`` is "00".."63" (or an int).  Options: ``model`` ("DMAC17",
    "DMAC23-1", "DMAC23-2", "DMAC34-1", "DMAC34-2"), ``supply_voltage`` (mV),
    ``baudrate``, ``request_terminator`` / ``reply_terminator`` (bytes),
    ``positive_end_switch`` / ``negative_end_switch`` (position in 1/10000 rev
    where a mechanical end-stop switch on IN1/IN2 or IN9/IN10 closes) and
    ``end_switch_active_low``, ``reference_switch`` (position where a switch
    on IN5 turns on and stays on beyond: REFERENCE homing and #CAPTURE;
    default ``DEFAULT_REFERENCE_SWITCH``, 3000 = 0.3 rev, so the Drive's default
    homing works on a served twin; None or False = no switch).
    ``clock`` is a motorbus Clock (SimClock for tests); None = real time.
    """
    allowed = {"model", "supply_voltage", "baudrate", "request_terminator", "reply_terminator",
               "positive_end_switch", "negative_end_switch", "end_switch_active_low", "reference_switch"}
    unknown = set(options) - allowed
    if unknown:
        raise _core.InvalidArgument(f"make_sim: unknown option(s) {sorted(unknown)}; allowed: {sorted(allowed)}")
    for k in ("request_terminator", "reply_terminator"):
        if isinstance(options.get(k), str):
            options[k] = options[k].encode()
    if "supply_voltage" in options:
        options["supply_voltage"] = int(options["supply_voltage"])
    if "baudrate" in options:
        options["baudrate"] = int(options["baudrate"])
    options.setdefault("reference_switch", DEFAULT_REFERENCE_SWITCH)
    if options["reference_switch"] is False:     # a bench file's way to say "no switch" (TOML has no None)
        options["reference_switch"] = None
    if clock is None:
        clock = _real_clock()    # one time line for every module, so a line's modules can be chained
    return DmacSim(clock, address=_parse_address(address), **options)


_REAL_CLOCK: Any = None


def _real_clock() -> Any:
    global _REAL_CLOCK
    if _REAL_CLOCK is None:
        _REAL_CLOCK = _core.runtime.RealClock()
    return _REAL_CLOCK


def chain_ultrasync(sims: Sequence[DmacSim]) -> None:
    """Wire IN6/OUT1 of these simulated modules into one UltraSYNC chain (manual 5.11),
    before they are served.  With ``#INTERPOL_MODE:=-1`` each interpolation segment then
    ends when it is finished on every chained module that interpolates in UltraSYNC: a
    module that is done waits at rest on the segment's end (``sim.set_speed_limit`` makes
    one axis slow, as friction or a brake does).  In SimpleSYNC (0) each times its own."""
    DmacSim.chain_ultrasync(list(sims))


def wire_line(sims: Sequence[DmacSim]) -> None:
    """``motorbus sim serve``: the modules of one served line have IN6/OUT1 chained, the
    UltraSYNC wiring (it changes nothing unless ``#INTERPOL_MODE:=-1``)."""
    if len(sims) > 1:
        chain_ultrasync(sims)


def synchro(link: Any, what: str) -> None:
    """Global ``SYNCHRO ON|OFF|TOP|INTERPOL`` (no module answers it)."""
    _core.dmac.synchro(link, what)


@contextlib.contextmanager
def synchronised_start(link: Any, drives: Sequence[Any]) -> Iterator[str]:
    """Moves commanded inside the block are held by every module of the line
    (``SYNCHRO ON``) and start on one broadcast ``SYNCHRO TOP`` when it exits: the
    modules start on the same bytes of the wire.  Yields the method's name."""
    synchro(link, "ON")
    try:
        yield "DMAC SYNCHRO TOP"
    except BaseException:
        synchro(link, "OFF")
        for d in drives:       # held moves must not start later by surprise
            d.stop()
        raise
    synchro(link, "TOP")
    synchro(link, "OFF")


def stream_interpolation(axes: Sequence[DmacClient], segments: Iterable[Sequence[int]],
                         interpol_time_ms: int = 100, fifo_size: int = 64, sleep: Any = None,
                         backoff: Optional[float] = None) -> "_core.dmac.StreamStats":
    """Stream ``segments[k][axis]`` (MOVE_INTERPOL offsets) to every axis.

    Pre-fills each FIFO, starts all axes with the global SYNCHRO INTERPOL, then
    keeps every FIFO fed, backing off on XON_ERROR.  Returns a read-only
    ``DmacStreamStats`` (``.segments``, ``.xon_errors``, ``.underruns``,
    ``.min_level_after_start``...).
    """
    return _core.dmac.stream_interpolation(list(axes), [list(map(int, s)) for s in segments],
                                           interpol_time_ms, fifo_size, sleep, backoff)


def dmac_interpolation(start: Sequence[float], target: Sequence[float], limits: Sequence["_core.motion.Limits"],
                       period_ms: int = 100, straight_line: bool = True) -> Any:
    """Plan a synchronised multi-axis move and split it into MOVE_INTERPOL offsets.

    Returns an int64 numpy array ``[segment, axis]`` whose column sums reach
    ``target - start``: the ``segments`` :func:`stream_interpolation` sends, one
    row per ``period_ms`` (``#INTERPOL_TIME``).  The planning is the motion
    library's (``motorbus.motion.plan_straight_line`` / ``plan_synchronized``).
    """
    import numpy as np

    from .. import motion

    # The module's own range for #INTERPOL_TIME (the splitter takes any period from 1 ms).
    rng = _core.dmac.variable("#INTERPOL_TIME")
    if not rng.min <= period_ms <= rng.max:
        bound = rng.min if period_ms < rng.min else rng.max
        e = _core.LimitExceeded(f"#INTERPOL_TIME: requested {period_ms} is outside {rng.min}..{rng.max} (ms per segment)")
        e.limit, e.requested, e.allowed, e.excess = "#INTERPOL_TIME", float(period_ms), float(bound), float(period_ms - bound)
        raise e
    planner = motion.plan_straight_line if straight_line else motion.plan_synchronized
    axes = planner(list(map(float, start)), list(map(float, target)), list(limits))
    return np.asarray(motion.split_interpolation(axes, int(period_ms)), dtype=np.int64).reshape(-1, len(start))


SIM_OPTIONS = ("model", "supply_voltage", "baudrate", "request_terminator", "reply_terminator",
               "positive_end_switch", "negative_end_switch", "end_switch_active_low", "reference_switch")


def check_address(text: str) -> str:
    """The canonical two-digit address ("00".."63"), or InvalidArgument naming the problem."""
    if isinstance(text, int) and not isinstance(text, bool):
        text = str(text)             # an integer means that integer
    if not isinstance(text, str) or not text.strip().isdigit():
        raise _core.InvalidArgument(f"DMAC address: {text!r} is not a number 00..63")
    return f"{_parse_address(text.strip()):02d}"


# ---- the Drive adapter ------------------------------------------------------------------------
#: 0.01 rpm per increment/s (1 rev = 10000 increments): the unit of #HIGH_SPEED and MOVE_SPEED.
_SPEED_PER_INC_S = 6000.0 / 10000.0

_UNITS = {"#ACCEL_TIME": "ms", "#DECEL_TIME": "ms", "#HIGH_SPEED": "0.01 rpm", "#LOW_SPEED": "0.01 rpm",
          "#LINE_DELAY": "us", "#TORQUE_RATIO": "%", "#POSITION": "1/10000 rev", "#NEGATIVE_END": "1/10000 rev",
          "#POSITIVE_END": "1/10000 rev", "#SPEED": "0.01 rpm", "#PROFILE_SPEED": "0.01 rpm",
          "#SUPPLY_VOLTAGE": "mV", "#CPU_TEMPERATURE": "0.1 degC", "#DRIVER_TEMPERATURE": "0.1 degC",
          "#MOTOR_TEMPERATURE": "0.1 degC", "#INTERPOL_TIME": "ms", "#INPUT_ANALOG": "mV", "#INPUT_A1": "mV",
          "#INPUT_A2": "mV", "#OUTPUT_A1": "mV", "#OUTPUT_A2": "mV", "#CAPTURE": "1/10000 rev"}
_DESCRIPTIONS = {
    "#ACCEL_TIME": "time from standstill to #HIGH_SPEED", "#DECEL_TIME": "time from #HIGH_SPEED to standstill",
    "#HIGH_SPEED": "cruise speed of a position move, limit of MOVE_SPEED", "#LOW_SPEED": "approach speed of the closed position loop",
    "#LINE_DELAY": "RS-485 turnaround before each reply", "#TORQUE_RATIO": "share of the torque available",
    "#POSITION": "position (assigning re-homes)", "#NEGATIVE_END": "soft negative end-stop",
    "#POSITIVE_END": "soft positive end-stop", "#OUTPUT_CONFIG": "OUT1=BUSY (bit 1), OUT2=FAULT (bit 2)",
    "#ON_RESET": "sequencer line run at reset (0 = none)", "#ERROR": "error register (write 0 to acknowledge)",
    "#STATUS": "status word", "#INTERPOL_TIME": "duration of one interpolation segment",
    "#INTERPOL_FIFOSIZE": "interpolation FIFO size (segments)", "#INTERPOL_MODE": "0 SimpleSYNC, -1 UltraSYNC",
}
# The variables drive.params lists (the #V/#M/#TIMER families are reachable by name too).
_PARAM_NAMES = ("#ACCEL_TIME", "#DECEL_TIME", "#HIGH_SPEED", "#LOW_SPEED", "#TORQUE_RATIO", "#LINE_DELAY",
                "#POSITIVE_END", "#NEGATIVE_END", "#OUTPUT_CONFIG", "#ON_RESET", "#INTERPOL_TIME",
                "#INTERPOL_FIFOSIZE", "#INTERPOL_MODE", "#POSITION", "#OUTPUT", "#ERROR", "#STATUS", "#SPEED",
                "#PROFILE_SPEED", "#INPUT", "#SUPPLY_VOLTAGE", "#CPU_TEMPERATURE", "#CAPTURE", "#LINE",
                "#INTERPOL_COUNT")


class DmacParams(Params):
    """``drive.params`` over the DMAC variables: ``params["#HIGH_SPEED"]`` or
    ``params["HIGH_SPEED"]`` (the ``#`` is optional; mnemonics such as ``HSP`` too)."""

    def _key(self, name: str) -> str:
        name = super()._key(name).strip().upper()
        return name if name.startswith("#") else "#" + name

    def _names(self) -> list:
        return list(_PARAM_NAMES)

    def _info(self, name: str) -> Optional[ParamInfo]:
        try:
            v = variable_info(name)
        except _core.InvalidArgument:
            return None
        canonical = v.name
        writable = not v.read_only and canonical not in ("#STATUS",)
        return ParamInfo(name=canonical, type="int", minimum=v.min, maximum=v.max,
                         unit=_UNITS.get(canonical, ""), default=v.factory, persists=v.stored,
                         writable=writable, description=_DESCRIPTIONS.get(canonical, ""))

    async def _read(self, info: ParamInfo) -> Any:
        return await self._drive.io.read(info.name)

    async def _write(self, info: ParamInfo, value: Any) -> None:
        if isinstance(value, bool) or int(value) != value:
            raise _core.InvalidArgument(f"dmac: {info.name} takes an integer, not {value!r}")
        await self._drive.io.write(info.name, int(value))


class DmacDrive(Drive):
    """A DMAC module as a :class:`motorbus.Drive` (native unit: the increment, 1/10000 rev).

    * ``enable()``: BRAKE OFF (DMAC34) and POWER ON; ``disable()``: POWER OFF.
    * ``stop()``: STOP (#DECEL_TIME ramp); ``quick_stop()``: HALT (no ramp).
    * ``move_to(..., velocity=v)``: #HIGH_SPEED for that move only; the old value is
      written back when the move ends, however it ends (both writes go to the
      module's non-volatile memory: set ``params["#HIGH_SPEED"]`` once for many moves).
    * A move has arrived when it is at rest within 1 increment of its target (the
      position loop's precision, manual 1.2.1: the DMAC has no window setting);
      otherwise it raises the ``motorbus.MoveFailed`` that says why, from #STATUS
      and #ERROR (docs/drives/dmac.md, "How a move ends").
    * ``home(method)``: ``"reference"`` (default): off the IN5 switch first if it is
      already on, then REFERENCE ON and MOVE_SPEED at #LOW_SPEED clockwise until IN5
      rises (the module re-homes there), then back to 0; ``"here"``: #POSITION:=0
      where the axis stands.  A run that fails raises a :class:`HomingFailed`.
    * ``clear_faults()``: #ERROR:=0; raises if the fault latches again at once (its
      cause, a supply or a temperature out of range, is still present).
      ``store()``: nothing to send — the DMAC writes its stored variables to
      non-volatile memory as they are written.
    * No watchdog: on link loss the module keeps doing what it was last told.
    """

    kind = "dmac"
    capabilities = frozenset({Capability.POSITION, Capability.VELOCITY, Capability.HOMING,
                              Capability.INTERPOLATION, Capability.ENCODER, Capability.STORE})
    has_watchdog = False
    HOME_METHODS = ("reference", "here")
    #: The position loop reaches its target "with a precision of 1/10000 rev" (manual
    #: 1.2.1): one increment, the module having no in-position window to read.
    in_position_window = 1.0

    # the plugin (motorbus.registry): what the kind is
    description = "Midi Ingénierie DMAC17/23/34 brushless modules, ASCII protocol over RS-232/RS-485"
    transport = "serial"
    default_address = DEFAULT_ADDRESS
    line_settings = LINE_SETTINGS
    default_baud = DEFAULT_BAUD
    sim_options = SIM_OPTIONS
    probe_addresses = tuple(f"{a:02d}" for a in range(64))   # 00-63
    probe_bauds = BAUDRATES

    def __init__(self, native: DmacClient, **kwargs: Any) -> None:
        super().__init__(native, **kwargs)
        self._homed = False
        self._homing: Optional[str] = None      # "backoff", "search", "return" or None
        self._model_is_dmac34: Optional[bool] = None

    def _io_link(self) -> Any:
        # The LineLink of the RS-485 line: the modules of one line take turns on its wire,
        # so their exchanges queue on one worker in the awaitable face.
        return self.native.link

    def _make_params(self) -> Params:
        return DmacParams(self)

    async def _console(self, line: str) -> str:
        # READ/REQUEST_* answer; every other DMAC command is silent, so it is sent
        # with the client's #ERROR check and "OK" stands for "accepted".
        if line.upper().startswith(("READ", "REQUEST")):
            reply = await self.io.raw(f"{self.native.address:02d}{line}", True)
            return reply.decode("ascii", "replace").strip()
        await self.io.command(line)
        return "OK"

    # ---- faces of the module ----
    async def _is_dmac34(self) -> bool:
        # REQUEST_VERSION once (the client caches it too): kept here so that later
        # questions cost no trip to the link's worker.
        if self._model_is_dmac34 is None:
            self._model_is_dmac34 = bool(await self.io.attr("is_dmac34"))
        return self._model_is_dmac34

    # ---- faults in the Drive's words ----
    async def _fault_cause(self, err: DmacErrorWord) -> str:
        """Whether the cause of the latched faults in ``err`` is still there, read from the module."""
        dmac34 = await self._is_dmac34()
        under, over = (20, 170) if dmac34 else (12, 49)
        present = []
        if err & (DmacErrorWord.UNDERVOLTAGE | DmacErrorWord.OVERVOLTAGE):
            mv = await self.io.attr("supply_voltage")
            if mv < under * 1000 or mv > over * 1000:
                present.append(f"#SUPPLY_VOLTAGE {mv / 1000:g} V, outside {under}..{over} V")
        if err & DmacErrorWord.THERMAL:
            sensors = [("#CPU_TEMPERATURE", "cpu_temperature", 1200)]
            if dmac34:
                sensors += [("#DRIVER_TEMPERATURE", "driver_temperature", 850),
                            ("#MOTOR_TEMPERATURE", "motor_temperature", 850)]
            for name, attr, limit in sensors:
                t = await self.io.attr(attr)
                if t > limit:
                    present.append(f"{name} {t / 10:g} degC, above {limit / 10:g}")
        return "; ".join(present)

    async def _fault_text(self, err: DmacErrorWord) -> str:
        under, over = (20, 170) if await self._is_dmac34() else (12, 49)
        words = [_FAULT_TEXT[b].format(under=under, over=over) for b in (2, 3, 4, 5) if err.bit(b)]
        return "; ".join(words) or f"#ERROR {', '.join(err.names)}"

    @contextlib.asynccontextmanager
    async def _refused_in_drive_words(self, what: str) -> AsyncIterator[None]:
        """A command the client refuses because a fault is latched: say so in the Drive's
        words (clear_faults(), and whether the cause is still there)."""
        try:
            yield
        except CommandRejected as e:
            err = DmacErrorWord(int(getattr(e, "error", 0) or 0)) & FAULTS
            if not err:
                raise
            cause = await self._fault_cause(err)
            then = (f"its cause is still present ({cause}): remove it, then call clear_faults()" if cause else
                    "clear_faults() acknowledges it")
            error = CommandRejected(f"dmac {self.native.address:02d}: {what} refused: a fault is latched "
                                    f"({await self._fault_text(err)}); {then}")
            error.error = int(err)
            raise error from None

    # ---- motion ----
    async def _enable(self) -> None:
        if await self._is_dmac34():
            await self.io.brake(False)
        async with self._refused_in_drive_words("enable()"):
            await self.io.power("ON")

    async def _disable(self) -> None:
        await self.io.power("OFF")

    async def _speed_for_this_move(self, velocity: Optional[float]) -> None:
        if velocity is None:
            return
        speed = int(round(velocity * _SPEED_PER_INC_S))
        if not 1 <= speed <= 400000:
            raise _core.InvalidArgument(f"dmac: velocity {velocity:g} increments/s is outside "
                                        f"1..400000 (0.01 rpm, #HIGH_SPEED)")
        old = await self.io.attr("high_speed")
        if old != speed:       # a stored variable: no flash write when it would not change
            await self._for_this_move(lambda: old, lambda v: self.io.set_attr("high_speed", v), speed)

    async def _abandon_homing(self) -> None:
        # A reference run nobody waited to the end of: REFERENCE ON would otherwise stay
        # armed and silently re-home the axis at the next IN5 edge turning clockwise.
        if self._homing is not None:
            self._homing = None
            await self.io.reference(False)

    async def _move_to(self, target: float, velocity: Optional[float]) -> None:
        goal = self._increments(target)
        await self._abandon_homing()
        await self._speed_for_this_move(velocity)
        async with self._refused_in_drive_words(f"move_to (MOVE_TO {goal})"):
            await self.io.move_to(goal)

    async def _move_by(self, distance: float, velocity: Optional[float]) -> None:
        # MOVE_ON counts from where the axis is at rest (the sim and the manual: from the
        # target of a move in progress), which is where Drive read the start it judges by.
        step = self._increments(distance)
        await self._abandon_homing()
        await self._speed_for_this_move(velocity)
        async with self._refused_in_drive_words(f"move_by (MOVE_ON {step})"):
            await self.io.move_on(step)

    async def _jog(self, velocity: float) -> None:
        speed = int(round(velocity * _SPEED_PER_INC_S))
        if abs(speed) > 400000:
            raise _core.InvalidArgument(f"dmac: jog velocity {velocity:g} increments/s exceeds 400000 (0.01 rpm)")
        if speed == 0:
            await self.io.urgent.stop()
            return
        await self._abandon_homing()
        async with self._refused_in_drive_words(f"jog (MOVE_SPEED {speed})"):
            await self.io.move_speed(speed)  # the module limits |speed| to #HIGH_SPEED

    async def _stop(self) -> None:
        await self.io.urgent.stop()

    async def _quick_stop(self) -> None:
        await self.io.urgent.halt()

    # ---- homing ----
    async def _in5(self) -> bool:
        return bool(await self.io.attr("inputs") & (1 << 4))

    # Speed and ramps (the EPICS record's VELO/ACCL): #HIGH_SPEED is in 0.01 rpm, 0.6 of it
    # per increment/s at 10 000 increments per turn; #ACCEL_TIME/#DECEL_TIME in ms.
    async def _move_speed(self) -> tuple[Optional[float], Optional[float]]:
        return await self._speed_param("#HIGH_SPEED", 10000.0 / 6000.0)

    async def _set_accel_time(self, seconds: float, speed: float, top: Optional[float]) -> bool:
        ms = max(1.0, seconds * 1000.0)
        await self._set_params_clamped({"#ACCEL_TIME": ms, "#DECEL_TIME": ms})
        return True

    async def _home(self, method: Any) -> None:
        method = "reference" if method is None else method
        if method not in self.HOME_METHODS:
            raise _core.InvalidArgument(f"dmac: home method {method!r} is not one of {self.HOME_METHODS}")
        self._homed = False
        await self._abandon_homing()
        if method == "here":
            await self.io.set_attr("position", 0)
            self._homed = True
            return
        async with self._refused_in_drive_words("home()"):
            if await self._in5():
                # REFERENCE needs a rising edge: leave the switch (counter-clockwise) first.
                await self.io.move_speed(-max(1, await self.io.attr("high_speed")))
                self._homing = "backoff"
            else:
                await self._start_search()

    async def _start_search(self) -> None:
        await self.io.reference(True)
        await self.io.move_speed(max(1, await self.io.attr("low_speed")))
        self._homing = "search"

    async def _homing_failed(self, st: DmacStatus, waiting_for: str) -> None:
        """The run stopped early: raise the HomingFailed subclass of the reason the module shows."""
        self._homing = None
        try:
            await self.io.reference(False)
        except _core.MotorbusError:
            pass
        status = await self._status()
        reason = await self._stop_reason(status)
        move = self._move
        if reason is None:
            by = move.stopped_by if move is not None else None
            reason = StopReason(MoveInterrupted, stopped_by_text(by) if by else
                                "a STOP or HALT from another client on the line")
        error = {LimitReached: HomingLimitReached, MoveFaulted: HomingFaulted}.get(reason.error, HomingInterrupted)
        text = f"{reason.text}, while waiting for {waiting_for}"
        if move is not None:
            raise await self._failure(move, StopReason(error, text, reason.code, reason.side), status=status)
        raise error(f"dmac {self.native.address:02d}: homing failed: {text}")

    async def _homing_done(self) -> bool:
        phase = self._homing
        if phase is None:          # "here": done when it was asked
            return True
        st = await self.io.attr("status")
        moving = DmacStatus.MOVEMENT in st
        if phase == "backoff":
            if not await self._in5():
                await self.io.stop()
                self._homing = "backoff_stop"
            elif not moving or DmacStatus.ABNORMAL_STOP in st:
                await self._homing_failed(st, "IN5 to turn off (backing off the reference switch, counter-clockwise)")
            return False
        if phase == "backoff_stop":
            if not moving:
                await self._start_search()
            return False
        if phase == "search":
            if DmacStatus.REFERENCE not in st:         # IN5 rose: the module re-homed
                await self.io.move_to(0)              # back onto the reference point
                self._homing = "return"
                return False
            if not moving or DmacStatus.ABNORMAL_STOP in st:
                await self._homing_failed(st, "the IN5 reference edge (REFERENCE ON, clockwise at #LOW_SPEED)")
            return False
        if moving:
            return False
        self._homing = None
        self._homed = abs(await self.io.attr("position")) <= self.in_position_window
        return True

    async def _co_wait_idle(self, timeout: Optional[float] = None) -> None:
        move = self._move
        phase = self._homing
        try:
            await super()._co_wait_idle(timeout)
        except MoveTimedOut as e:
            phase = self._homing or phase
            if move is None or move.what != "home" or phase is None:
                raise
            # A reference search turns until IN5 rises: stop it, and say what it waited for.
            self._homing = None
            try:
                await self.io.urgent.stop()
                await self.io.reference(False)
            except _core.MotorbusError:
                pass
            waited = {"backoff": "IN5 to turn off (backing off the reference switch, counter-clockwise)",
                      "backoff_stop": "the axis to stop after backing off the reference switch",
                      "search": "the IN5 reference edge (REFERENCE ON, clockwise at #LOW_SPEED); "
                                "is a reference switch wired on IN5? the search was stopped",
                      "return": "the return to 0 after the IN5 edge"}[phase]
            raise await self._failure(move, StopReason(HomingTimedOut, f"{e.reason} waiting for {waited}"),
                                      status=None, position=None, at_rest=False) from None

    async def _clear_faults(self) -> None:
        await self.io.clear_error()
        err = DmacErrorWord(int(await self.io.attr("error"))) & FAULTS
        if err:
            cause = await self._fault_cause(err)
            raise _core.DriveFault(
                f"dmac {self.native.address:02d}: clear_faults(): the fault latched again at once "
                f"({await self._fault_text(err)}): its cause is still present" + (f" ({cause})" if cause else ""))

    async def _store(self) -> None:
        # Stored variables go to non-volatile memory when written (manual 5.x,
        # "This parameter is stored in non-volatile memory"); HARD_ENDS and
        # OPTIMIZED_CURRENT at shut-down.  There is no save command to send.
        pass

    # ---- readings ----
    async def _position(self) -> float:
        return float(await self.io.attr("position"))

    async def _velocity(self) -> float:
        return await self.io.attr("speed") / _SPEED_PER_INC_S

    async def _is_idle(self) -> bool:
        # At rest, not merely at the target speed (BUSY ends there in velocity mode).
        return DmacStatus.MOVEMENT not in await self.io.attr("status")

    async def _stop_reason(self, status: DriveStatus) -> Optional[StopReason]:
        st, err = status.raw
        faults = err & FAULTS
        if faults:
            return StopReason(MoveFaulted, await self._fault_text(faults), code=int(faults))
        # An end-stop stops the motion with "movement stopped abnormally" (#STATUS bit 32);
        # the end-stop bits alone only say the axis sits on one (a move away may follow).
        if DmacStatus.ABNORMAL_STOP in st:
            for bit, side, text in ((DmacStatus.HARD_POSITIVE_END, 1, "the hard positive end-stop (#STATUS bit 17)"),
                                    (DmacStatus.HARD_NEGATIVE_END, -1, "the hard negative end-stop (#STATUS bit 18)"),
                                    (DmacStatus.SOFT_POSITIVE_END, 1,
                                     "the soft positive end-stop #POSITIVE_END (#STATUS bit 19)"),
                                    (DmacStatus.SOFT_NEGATIVE_END, -1,
                                     "the soft negative end-stop #NEGATIVE_END (#STATUS bit 20)")):
                if bit in st:
                    return StopReason(LimitReached, text, side=side)
            return StopReason(MoveInterrupted, "an abnormal stop with no end-stop or fault shown (#STATUS bit 32)")
        if DmacStatus.POWER_ON not in st:
            return StopReason(MoveInterrupted, "POWER OFF (#STATUS bit 25 clear)")
        if DmacStatus.BRAKE in st:
            return StopReason(MoveInterrupted, "BRAKE ON (#STATUS bit 21)")
        # STOP and HALT leave no trace in #STATUS once the axis is at rest.  A line is one
        # process's: a move this program did not stop was stopped by another client on
        # the same line (the DMAC has no stop input).
        move = self._move
        if move is not None and move.what == "move" and move.stopped_by is None:
            return StopReason(MoveInterrupted, "a command from another client on the line (STOP, HALT or a new "
                                               "target: the DMAC keeps no trace of it at rest)")
        return None

    async def _travel_limits(self) -> tuple[Optional[float], Optional[float]]:
        # The soft end-stops bind only while SOFT_ENDS ON is in force (#STATUS bit 7).
        if DmacStatus.SOFT_ENDS_ENABLED not in await self.io.attr("status"):
            return (None, None)
        return (float(await self.io.read("#NEGATIVE_END")), float(await self.io.read("#POSITIVE_END")))

    async def _status(self) -> DriveStatus:
        st = await self.io.attr("status")
        err = DmacErrorWord(int(await self.io.attr("error"))) if DmacStatus.ERROR in st else DmacErrorWord(0)
        fault = bool(err & FAULTS)
        moving = DmacStatus.MOVEMENT in st
        words = [n for n in ("power on" if DmacStatus.POWER_ON in st else "power off",
                             "moving" if moving else "at rest",
                             "busy" if DmacStatus.BUSY in st else "",
                             "brake" if DmacStatus.BRAKE in st else "",
                             "fault: " + ", ".join(err.names) if err else "") if n]
        return DriveStatus(enabled=DmacStatus.POWER_ON in st, moving=moving, homed=self._homed, fault=fault,
                           at_target=DmacStatus.BUSY not in st and not moving,
                           limit_positive=bool(st & (DmacStatus.HARD_POSITIVE_END | DmacStatus.SOFT_POSITIVE_END)),
                           limit_negative=bool(st & (DmacStatus.HARD_NEGATIVE_END | DmacStatus.SOFT_NEGATIVE_END)),
                           raw=(st, err), text=f"DMAC {self.native.address:02d}: " + ", ".join(words))

    @staticmethod
    def _increments(x: float) -> int:
        n = int(round(x))
        if not -2**31 <= n < 2**31:
            raise _core.InvalidArgument(f"dmac: position {x:g} increments is outside int32")
        return n

    def _close(self) -> None:
        self.native.close()     # and the port, if the client opened it from a path

    # ---- the plugin's hooks (motorbus.registry) ------------------------------------------
    @classmethod
    def open(cls, *, line: Any = None, bus: Any = None, address: str = DEFAULT_ADDRESS, units: Any = None,
             baud: int = DEFAULT_BAUD, timeout: Optional[float] = None, on_error: Optional[str] = "stop",
             on_exit: Optional[str] = "stop", sleep: Any = None) -> "DmacDrive":
        # The adapter owns the safety words: the client does nothing at exit itself.
        return cls._open_on(line, bus, lambda link: DmacClient(link, check_address(str(address)), baud=baud,
                                                               timeout=timeout, sleep=sleep, on_error=None,
                                                               on_exit=None),
                            units=units, on_error=on_error, on_exit=on_exit)

    make_sim = staticmethod(make_sim)
    check_address = staticmethod(check_address)
    wire_line = staticmethod(wire_line)
    synchronised_start = staticmethod(synchronised_start)

    @classmethod
    def probe(cls, line: "_core.serial.LineLink", address: str) -> Optional[dict]:
        """Discovery: REQUEST_VERSION of the module at `address`, or None.  Reads only."""
        client = DmacClient(line, address=int(address), verify=False, on_error=None, on_exit=None)
        try:
            # Presence first, on the link's short reply timeout (the sweep's cost per
            # empty address); the long REQUEST_VERSION banner only where a module is.
            client.raw(f"{int(address):02d}READ #STATUS", True)
            v = client.request_version()
            return {"model": v.model, "firmware": f"v{v.version}.{v.release}", "serial": v.serial}
        finally:
            client.close()

    @classmethod
    def sim_faults(cls) -> dict:
        return dict(SIM_FAULTS)

    def poll_fields(self, fields: Any) -> "PollSpec":
        """motorbus.Poller: #POSITION, #SPEED and #STATUS (hex) read by a client of the poll
        thread's own on the drive's line.  Each READ waits the module's #LINE_DELAY (3 ms
        from the factory): a DMAC line polls at tens of Hz."""
        from ..registry import PollSpec

        reads = {"position": ("POSITION", 1.0), "velocity": ("SPEED", 1.0 / _SPEED_PER_INC_S),
                 "status": ("STATUS", 1.0)}
        for f in fields:
            if f not in reads:
                raise _core.InvalidArgument(f"dmac poll field {f!r}: this kind gives {', '.join(reads)}")
        n = self.native
        source = _core.dmac.poll_source(n.link, n.address, [reads[f][0] for f in fields], baud=n.baud,
                                        timeout=n.timeout)
        return PollSpec(source=source, scales=tuple(reads[f][1] for f in fields), transport=n.link)

    def plan_move(self, start: float, target: float) -> Any:
        """A DMAC position move (its profile model: #ACCEL_TIME/#DECEL_TIME to and from
        #HIGH_SPEED, the closed-loop approach at #LOW_SPEED, S_CURVE), in increments."""
        from .. import motion

        p = self.params
        params = DmacProfileParams(high_speed=int(p["#HIGH_SPEED"]), low_speed=int(p["#LOW_SPEED"]),
                                   accel_time_ms=int(p["#ACCEL_TIME"]), decel_time_ms=int(p["#DECEL_TIME"]))
        return dmac_position_profile(motion.MotionState(float(start), 0.0, 0.0, 0.0), float(target), params)


def _sim_model_is_dmac34(sim: DmacSim) -> bool:
    # REQUEST_VERSION names the model; it reads only.
    return b"DMAC34" in sim.on_line(f"{sim.address:02d}REQUEST_VERSION".encode())


def _limit_fault(sim: DmacSim, direction: Any = 1) -> None:
    """The end-stop switch of one side closes, that side's hard end-stop enabled (as on a
    bench whose switches are wired and HARD_ENDS set): a motion that way stops."""
    if isinstance(direction, bool) or str(direction).strip() not in ("1", "+1", "-1"):
        raise _core.InvalidArgument(f"dmac sim fault 'limit': direction +1 or -1, not {direction!r}")
    side = int(str(direction).strip())
    status = DmacStatus(sim.read("#STATUS"))
    positive = DmacStatus.HARD_POSITIVE_END_ENABLED in status or side > 0
    negative = DmacStatus.HARD_NEGATIVE_END_ENABLED in status or side < 0
    word = "ALL" if positive and negative else "POS" if positive else "NEG"
    sim.on_line(f"{sim.address:02d}HARD_ENDS {word}".encode())
    dmac34 = _sim_model_is_dmac34(sim)
    sim.set_input((9 if side > 0 else 10) if dmac34 else (1 if side > 0 else 2), True)


def _fault(sim: DmacSim, bit: Any = 4) -> None:
    """A hardware fault (#ERROR bit 2 thermal, 3 short-circuit, 4 undervoltage, 5 overvoltage)."""
    if isinstance(bit, bool) or str(bit).strip() not in ("2", "3", "4", "5"):
        raise _core.InvalidArgument(f"dmac sim fault 'fault': bit 2, 3, 4 or 5 (#ERROR), not {bit!r}")
    sim.inject_error(int(str(bit).strip()))


# Faults the simulator can be given (the pytest plugin's sim_faults fixture), under the
# standard names of docs/drives/dmac.md ("How a move ends").  A DMAC has no stall (its
# self-switched motor "guarantees the motor position") and no stop input: no "stall",
# no "stop_input".
SIM_FAULTS = {
    # an end-stop switch closes (direction +1 or -1): the module stops, ABNORMAL_STOP
    "limit": _limit_fault,
    # a hardware fault latches (bit=, default 4 undervoltage): the module stops
    "fault": _fault,
    # the supply falls (mV): below the model's range the drive latches undervoltage and stops
    "supply_drop": lambda sim, mv=11000: sim.set_supply_voltage(int(mv)),
    # a sensor ("cpu", "driver" or "motor") heats (0.1 degC): past its threshold a thermal fault latches
    "overheat": lambda sim, sensor="motor", tenths_c=900: sim.set_temperature(str(sensor), int(tenths_c)),
}

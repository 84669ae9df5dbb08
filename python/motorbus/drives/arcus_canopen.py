"""The Arcus DMX-CAN-23 over CANopen (CiA DSP-402, SDO only): client, simulator, Drive adapter.

    import motorbus
    with motorbus.open_drive("arcus-canopen", bus="socketcand:127.0.0.1:29536/can0", address=1) as axis:
        axis.enable()
        axis.move_to(4000)                  # profile position (encoder counts with StepNLoop)
        axis.home(19)                       # manual 000's method 19: home input, positive
        axis.params["Run current"] = 1200   # 2004h:02, by name or "0x2004:02"

It is the same drive as the ASCII kind ``arcus``: one simulator (``_core.arcus.Sim``)
with two front ends.  Which one answers is the communication type stored in
200Ah (ASCII ``CM``) at the last power-up: a factory-fresh unit talks RS-232;
``make_sim(1, protocol="canopen")`` gives a unit set up for CAN.

The native client :class:`ArcusCanopen` is the generic CiA 402 host
(``motorbus.canopen.Cia402``) plus the Arcus objects 2000h-200Eh, typed and
named, the manual's homing methods and the clear-error (200Dh) and store (200Eh)
handshakes.  The manual documents no heartbeat, PDO or EMCY: the drive has no
communication watchdog.  On a cut cable the motor finishes (or keeps running)
what it was last told; the adapter stops it when the ``with`` block fails or
the program exits, and the next call raises ``LinkDown``/``TimeoutError``.
"""
from __future__ import annotations

import enum
import time
from typing import Any, Optional, Union

from .. import _core
from .._core.arcus import Motion as ArcusMotion, ProfileParams as ArcusProfileParams  # the DMX-CAN's profile model
from ..canopen.cia402 import Cia402, OpMode
from ..canopen.node import check_node_id
from ..drive import (Capability, Drive, DriveStatus, LimitReached, MoveFaulted, MoveStalled, ParamInfo, Params,
                     StopReason, Units)
from . import arcus as _arcus
from .cia402 import Cia402Drive

__all__ = ["ArcusCanopen", "ArcusCanopenDrive", "ArcusCanopenSim", "ArcusHomingMethod", "BitRate",
           "CommType", "SnlStatus", "OBJECTS", "make_sim"]

# (index, sub, name, type, access, default, low, high, unit, persists): the OD the
# simulator serves (Table 10.1), from the C++ table.
OBJECTS = [tuple(row) for row in _core.arcus.canopen_objects()]
_BY_KEY = {(r[0], r[1]): r for r in OBJECTS}

_SW_INTERNAL_LIMIT = 1 << 11


class ArcusHomingMethod(enum.IntEnum):
    """6098h as manual 000 §8 defines it (its directions, not CiA 402's: C-A06)."""
    HOME_Z_POSITIVE = 7
    HOME_Z_NEGATIVE = 11
    LIMIT_POSITIVE = 17
    LIMIT_NEGATIVE = 18
    HOME_POSITIVE = 19
    HOME_NEGATIVE = 20
    Z_POSITIVE = 33
    Z_NEGATIVE = 34
    CURRENT_POSITION = 35


class CommType(enum.IntEnum):
    """200Ah (in effect after a store and a power cycle)."""
    RS232 = 0
    RS485 = 1
    CAN = 2


class BitRate(enum.IntEnum):
    """200Bh codes (Table 8.36; no 25 kbit/s)."""
    K10 = 1
    K20 = 2
    K50 = 3
    K100 = 4
    K125 = 5
    K250 = 6
    K500 = 7
    K800 = 8
    M1 = 9


# StepNLoop status: the same values on both personas (Tables 7.6 and 8.14), one enum.
SnlStatus = _arcus.SnlStatus


def _check_node(address: Union[str, int]) -> str:
    """The node-ID 1..127 (200Ch) as text (the CANopen layer's check)."""
    return str(check_node_id(address, "arcus-canopen"))


def _entry(index: int, sub: int) -> "_core.canopen.Variable":
    """The typed dictionary entry of one object of Table 10.1 (its C++ codec encodes and decodes)."""
    od = _dictionary()
    if (index, sub) not in od:
        raise _core.InvalidArgument(f"arcus-canopen: 0x{index:04X}:{sub:02X} is not in the object dictionary")
    return od[index, sub]


def _encode(var: "_core.canopen.Variable", value: int) -> bytes:
    """The manual's range checked before anything is sent (the drive's answer to a value
    outside it is a bare abort), then the entry's codec."""
    where = f"arcus-canopen {var.name} (0x{var.index:04X}:{var.subindex:02X})"
    if not isinstance(value, int) or isinstance(value, bool):
        raise _core.InvalidArgument(f"{where}: an integer, not {value!r}")
    low, high = var.value_range
    if not low <= value <= high:
        raise _core.InvalidArgument(f"{where}: {value} is outside {low}..{high}")
    return var.encode(value)


class ArcusCanopen(Cia402):
    """The DMX-CAN's CANopen persona from the host: the CiA 402 state machine of
    :class:`motorbus.canopen.Cia402` plus the Arcus objects, typed and named.

    ``ArcusCanopen(bus, node=1, timeout=1.0)``; every access is one expedited SDO
    (the drive knows no other transfer)."""

    def read(self, index: int, sub: int = 0) -> Any:
        """One object of Table 10.1, decoded by its dictionary entry."""
        return _entry(index, sub).decode(bytes(self.sdo.upload(index, sub)))

    def write(self, index: int, sub: int, value: int) -> None:
        """One writable object, range-checked against the manual before it is sent."""
        var = _entry(index, sub)
        if var.access not in ("rw", "wo"):
            raise _core.InvalidArgument(f"arcus-canopen {var.name} (0x{index:04X}:{sub:02X}) is read-only")
        self.sdo.download(index, sub, _encode(var, value))

    # ---- Arcus objects (2000h-200Eh) ----
    def _prop(index: int, sub: int = 0, wrap: Any = None, doc: str = ""):  # noqa: N805 - class-body helper
        def get(self: "ArcusCanopen") -> Any:
            v = self.read(index, sub)
            return wrap(v) if wrap is not None else v

        def put(self: "ArcusCanopen", value: Any) -> None:
            self.write(index, sub, int(value))
        row = _BY_KEY[(index, sub)]
        writable = row[4] in ("rw", "wo")
        return property(get, put if writable else None, doc=doc or f"{row[2]} (0x{index:04X}:{sub:02X})")

    alarm_in_position_enable = _prop(0x2000, 0, bool)
    snl_enable = _prop(0x2001, 1, bool, "StepNLoop on: positions and speeds are encoder counts (4000/rev)")
    snl_max_attempts = _prop(0x2001, 2)
    snl_tolerance = _prop(0x2001, 3)
    snl_idle_tolerance = _prop(0x2001, 4)
    snl_error_range = _prop(0x2001, 5)
    snl_delta = _prop(0x2002)
    snl_status = _prop(0x2003, 0, SnlStatus)
    current = _prop(0x2004, 1, doc="Real-time current, mA (run current while moving, idle current after idle time)")
    run_current = _prop(0x2004, 2)
    idle_current = _prop(0x2004, 3)
    idle_time = _prop(0x2004, 4)
    output_boot_state = _prop(0x2005)
    enable_boot_state = _prop(0x2006, 0, bool)
    latch_enable = _prop(0x2007, 0, bool)
    latch_status = _prop(0x2008)
    latched_pulse_position = _prop(0x2009, 1)
    latched_encoder_position = _prop(0x2009, 2)
    comm_type = _prop(0x200A, 0, CommType, "200Ah: in effect after store() and a power cycle")
    bit_rate = _prop(0x200B, 0, BitRate, "200Bh: in effect after store() and a power cycle")
    node_id = _prop(0x200C, 0, doc="200Ch: in effect after store() and a power cycle")
    home_offset = _prop(0x607C)
    polarity = _prop(0x607E, 0, doc="607Eh: bit 7 negates positions, bit 6 velocities")
    motion_profile_type = _prop(0x6086, 0, doc="0 trapezoidal, 1 S-curve")
    profile_velocity = _prop(0x6081)
    end_velocity = _prop(0x6082)
    profile_acceleration = _prop(0x6083, 0, doc="ms to reach 6081h (clamped to Appendix A at the move)")
    profile_deceleration = _prop(0x6084, 0, doc="ms from 6081h to 6082h")
    home_switch_speed = _prop(0x6099, 1)
    home_zero_speed = _prop(0x6099, 2)
    homing_acceleration = _prop(0x609A)
    position = _prop(0x6064, 0, doc="6064h: pulses (StepNLoop off) or encoder counts (on)")
    velocity = _prop(0x606C)
    digital_inputs = _prop(0x60FD)
    digital_outputs = _prop(0x60FE)
    del _prop

    @property
    def counts_per_rev(self) -> int:
        """Position units per motor revolution: 4000 encoder counts with StepNLoop on,
        3200 pulses (16 microsteps of a 1.8 deg motor) with it off (manual 000 §7)."""
        return 4000 if self.read(0x2001, 1) else 3200

    # ---- handshakes ----
    def _handshake(self, index: int, what: str, timeout: float) -> None:
        self.write(index, 0, 1)
        deadline = time.monotonic() + timeout
        while self.read(index, 0) != 0:
            if time.monotonic() > deadline:
                raise _core.TimeoutError(f"arcus-canopen: {what} (0x{index:04X}) still reads 1 after {timeout} s")
            time.sleep(0.002)

    def clear_errors(self, timeout: float = 1.0) -> None:
        """200Dh: the drive clears limit, StepNLoop and motor errors and resets the
        object to 0 (Fig. 8.1); waits for that, then resets the CiA 402 fault."""
        self._handshake(0x200D, "clear error", timeout)
        if self.state == "FAULT":
            self.fault_reset()

    def store(self, timeout: float = 2.0) -> None:
        """200Eh: saves Table 8.40's objects to flash (Fig. 8.2); 200Ah/200Bh/200Ch
        take effect at the next power cycle."""
        self._handshake(0x200E, "store", timeout)

    def home_arcus(self, method: Union[int, ArcusHomingMethod, None] = None, timeout: float = 30.0) -> None:
        """Homing with manual 000's methods (7, 11, 17-20, 33-35), waited for."""
        if method is not None:
            method = ArcusHomingMethod(int(method)) if int(method) in set(ArcusHomingMethod) else method
            if not isinstance(method, ArcusHomingMethod):
                raise _core.InvalidArgument(f"arcus-canopen home: method 7, 11, 17-20 or 33-35, not {method!r}")
        self.set_mode(OpMode.HOMING)
        self.home(None if method is None else int(method), timeout)


#: One simulated DMX-CAN: ``_core.arcus.Sim`` itself, the whole drive in one object.  It is a
#: ``SimulatedDevice`` (``attach(bus)`` serves its CAN front end, boot-up 0x700+n sent when CAN is in
#: effect, and keeps the bus; ``close()``) and a ``LineDevice`` (``on_line``, for the pty server):
#: it answers SDO while its stored communication type is CAN, ASCII lines while it is RS-232/485.
ArcusCanopenSim = _core.arcus.Sim


_SIM_OPTIONS = ("protocol", "store_path", "eo_boot", "snl", "home", "minus_limit", "plus_limit", "z_position",
                "start_position", "tick", "store_time", "clear_time", "ascii_address", "bit_rate")

#: How long 200Eh / 200Dh read 1 after a request on a served sim (real clock): a
#: flash sector write and an error clear take that long on a small controller,
#: and a master's polling loop (Fig. 8.1/8.2) must be exercised.  On a test's
#: SimClock they finish at once unless ``store_time``/``clear_time`` are given.
SERVED_STORE_TIME = 0.1
SERVED_CLEAR_TIME = 0.02


def make_sim(address: Union[str, int] = "1", clock: Optional[_core.runtime.Clock] = None, *,
             bus: Optional[_core.can.Bus] = None, protocol: str = "canopen", ascii_address: int = 1,
             **options: Any) -> ArcusCanopenSim:
    """A simulated DMX-CAN at node-ID ``address``.  ``protocol="canopen"``: a unit set
    up for CAN (200Ah = 2, the CANopen tables' defaults); ``"ascii"``: factory-fresh
    (RS-232).  A ``store_path`` file written by either persona overrides both; without
    one, what is stored lasts as long as the sim (power cycles and NMT resets keep it).
    ``bit_rate``: the factory 200Bh code (5 = 125 kbit/s); on a bus that models a bit
    rate the node answers only when its code in effect gives that rate.
    ``store_time``/``clear_time`` (s): how long 200Eh/200Dh read 1 (default
    SERVED_STORE_TIME/SERVED_CLEAR_TIME on the real clock, 0 on a given clock).
    Other options: those of ``_core.arcus.Sim`` (home, limits, snl, eo_boot, tick...)."""
    unknown = set(options) - set(_SIM_OPTIONS)
    if unknown:
        raise _core.InvalidArgument(f"arcus-canopen sim options: unknown {sorted(unknown)}; known {sorted(_SIM_OPTIONS)}")
    if protocol not in ("canopen", "ascii"):
        raise _core.InvalidArgument(f"arcus-canopen sim protocol: 'canopen' or 'ascii', not {protocol!r}")
    node = int(_check_node(address))
    if clock is None:
        options.setdefault("store_time", SERVED_STORE_TIME)
        options.setdefault("clear_time", SERVED_CLEAR_TIME)
    core = _core.arcus.Sim(clock, address=int(ascii_address), node_id=node,
                           comm_type=2 if protocol == "canopen" else 0, **options)
    if bus is not None:
        core.attach(bus)
    return core


# ---- the Drive adapter ----------------------------------------------------------------

def _key(index: int, sub: int) -> str:
    return f"0x{index:04X}" + (f":{sub:02X}" if sub else "")


class ArcusCanopenParams(Params):
    """Objects by index (``"0x6081"``, ``"0x2001:03"``, ``"2001h:03"``) or by name
    (``"Run current"``), read and written by SDO.

    Write-only objects (6060h, Modes of operation: the drive aborts a read with
    06010001) are described as such, written like any other, left out of the
    iteration (what ``config read --all`` reads) and refused by name when read."""

    def _names(self) -> list[str]:
        return [_key(r[0], r[1]) for r in OBJECTS if r[4] != "wo"]

    def _key(self, name: str) -> str:
        name = super()._key(name).strip()
        for r in OBJECTS:
            if name.lower() == r[2].lower():
                return _key(r[0], r[1])
        text = name[:-1] if name.lower().endswith("h") and ":" not in name else name
        idx, _, sub = text.partition(":")
        idx = idx[:-1] if idx.lower().endswith("h") else idx
        try:
            return _key(int(idx, 16), int(sub, 16) if sub else 0)
        except ValueError:
            return name

    def _row(self, name: str) -> Optional[tuple]:
        for r in OBJECTS:
            if _key(r[0], r[1]) == name:
                return r
        return None

    def _info(self, name: str) -> Optional[ParamInfo]:
        r = self._row(name)
        if r is None:
            return None
        index, sub, n, _type, access, _default, _low, _high, unit, persists = r
        var = _entry(index, sub)            # type, range, default: the typed entry's
        writable = var.access in ("rw", "wo")
        low, high = var.value_range if writable else (None, None)
        return ParamInfo(name=name, type="str" if var.data_type == _core.canopen.DataType.VISIBLE_STRING else "int",
                         minimum=low, maximum=high, unit=unit, default=var.default, persists=bool(persists),
                         writable=writable,
                         description=f"{n} (write-only: the drive cannot read it back)" if access == "wo" else n)

    async def _read(self, info: ParamInfo) -> Any:
        r = self._row(info.name)
        if r[4] == "wo":
            raise _core.InvalidArgument(
                f"{self._drive.name}: parameter {info.name} ({r[2]}) is write-only: the DMX-CAN aborts a read of it "
                f"(06010001); the mode in effect is 0x6061")
        return await self._drive._read(r[0], r[1])        # Table 10.1's entry decodes it

    async def _write(self, info: ParamInfo, value: Any) -> None:
        # Params has checked the access and the entry's range (the client's write checks)
        r = self._row(info.name)
        await self._drive._download(r[0], int(value), r[1])


class ArcusCanopenDrive(Cia402Drive):
    """A DMX-CAN on CANopen behind :class:`motorbus.Drive` (the generic CiA 402
    adapter with the Arcus differences: no watchdog, no 603Fh, the manual's
    homing methods, clear-error and store handshakes).

    A move ends at its target within the StepNLoop tolerance 2001h:03 (exactly, with
    StepNLoop off) or raises the :class:`motorbus.MoveFailed` that says why: a limit
    error (LimitReached), a StepNLoop stall, range or attempt error (2003h 10/8/9:
    MoveStalled), a halt or quick stop from elsewhere (MoveInterrupted);
    docs/drives/arcus.md "How a move ends".  ``velocity=`` sets 6081h for that move
    only (put back when it ends).

    Native units: encoder counts and counts/s with StepNLoop on (2001h:01 = 1, the
    default), pulses and pulses/s with it off.  No watchdog (the manual documents
    no heartbeat): on link loss the motor keeps doing what it was last told and
    the next call raises; the adapter stops it when a ``with`` block fails or the
    program exits (``on_error``/``on_exit``)."""

    kind = "arcus-canopen"
    capabilities = frozenset({Capability.POSITION, Capability.VELOCITY, Capability.HOMING, Capability.ENCODER,
                              Capability.STORE})
    has_watchdog = False

    # ---- the plugin (motorbus.registry): what the kind is, and its hooks -------------------
    # (poll_fields is Cia402Drive's: 6064h, 606Ch and 6041h by SDO, as for any CiA 402 drive.)
    description = "Arcus DMX-CAN integrated stepper, CANopen CiA DSP-402 by SDO (the CAN persona of 'arcus')"
    transport = "can"
    default_address = "1"
    sim_options = _SIM_OPTIONS
    store_file = "arcus-canopen-{address}.store"
    # Not offered by this persona (Cia402Drive's would be inherited): the SYNC start
    # and the TPDO capture were never validated against the DMX-CAN's manual.
    synchronised_start = classmethod(Drive.synchronised_start.__func__)
    capture_fields = Drive.capture_fields

    @classmethod
    def open(cls, *, line: Any = None, bus: Any = None, address: str = "1", units: Optional[Units] = None,
             timeout: float = 1.0, on_error: Optional[str] = "quick_stop",
             on_exit: Optional[str] = "quick_stop") -> "ArcusCanopenDrive":
        """``open_drive("arcus-canopen", bus=..., address=1)`` (the ASCII persona is ``arcus``, on a line)."""
        return cls._open_on(line, bus, lambda b: ArcusCanopen(b, int(_check_node(address)), timeout=timeout,
                                                              on_error=None, on_exit=None),
                            units=units, on_error=on_error, on_exit=on_exit)

    make_sim = staticmethod(make_sim)
    check_address = staticmethod(_check_node)

    @classmethod
    def canopen_match(cls, node: Any) -> int:
        # Discovery: profile 402 with the identity Table 10.1 gives (vendor 0, revision 112)
        # beats the generic cia402 match; any other 402 node stays cia402.
        return 5 if node.profile == 402 and not node.vendor_id and node.revision == 112 else 0

    @classmethod
    def sim_faults(cls) -> dict:
        return dict(SIM_FAULTS)

    def plan_move(self, start: float, target: float) -> Any:
        """The move as this persona makes it: the DMX-CAN's own profile model
        (``ArcusMotion``) loaded from the CiA 402 objects as the drive loads its ASCII
        registers: 6081h = HSPD, 6082h = LSPD (at most 6081h), 6083h/6084h = ACC/DEC (ms),
        6086h = 1 S-curve.  The StepNLoop ratio has no CANopen object: the factory
        3200 pulses per 4000 counts (0.8) with 2001h:01 on."""
        native = self.native
        hspd = max(float(native.read(0x6081)), 1.0)
        lspd = min(max(float(native.read(0x6082)), 1.0), hspd)
        snl = bool(native.read(0x2001, 1))
        params = ArcusProfileParams(hspd=hspd, lspd=lspd, acc_ms=max(float(native.read(0x6083)), 1.0),
                                    dec_ms=max(float(native.read(0x6084)), 1.0), edec=False,
                                    scv=native.read(0x6086) == 1, snl_ratio=0.8 if snl else 1.0)
        model = ArcusMotion(params)
        error = model.move(float(start), float(target))
        if error:
            raise _core.InvalidArgument(f"arcus-canopen plan_move {start} -> {target}: the model refuses: {error}")
        return model.profile

    async def _snl_text(self) -> str:
        try:
            return SnlStatus(await self._read(0x2003)).name
        except ValueError:
            return "?"

    # Speed and ramps (the EPICS record's VELO/ACCL): 6081h in pulses/s as on CiA 402, but
    # this drive's 6083h/6084h are ramp times in ms (its StepNLoop firmware), not pulses/s².
    async def _set_accel_time(self, seconds: float, speed: float, top: Optional[float]) -> bool:
        ms = max(1.0, seconds * 1000.0)
        await self._set_params_clamped({"0x6083": ms, "0x6084": ms})
        return True

    async def _home(self, method: Any) -> None:
        await self._operation_enabled()
        await self._use_mode(OpMode.HOMING)
        if method is not None:
            if isinstance(method, bool) or not isinstance(method, int) or int(method) not in set(ArcusHomingMethod):
                raise _core.InvalidArgument(f"arcus-canopen home: method 7, 11, 17-20 or 33-35, not {method!r}")
            await self.io.write(0x6098, 0, int(method))
        await self._new_set_point_edge()

    async def _set_point(self, target: float, relative: bool, velocity: Optional[float]) -> None:
        # A single set-point (controlword bit 5 = 0), as the ASCII persona's X: manual 000
        # makes bit 5 = 1 a buffered "set of set-points" (native.move_to(..., immediate=True)).
        try:
            await self._use_mode(OpMode.PROFILE_POSITION)
            await self._speed_for_this_move(velocity)
            await self.io.move_to(int(round(target)), relative, False)      # (target, relative, immediate)
        except _core.TimeoutError:
            # Not acknowledged: say why (checked only on failure: it costs SDO reads).
            await self._refused("move")
            if await self._velocity() != 0:
                raise _core.DriveFault("arcus-canopen: move refused while the motor moves (the drive takes "
                                       "a single set-point once the move is done; stop() first)") from None
            distance = abs(target if relative else target - await self._position())
            if distance > _core.arcus.MAX_MOVE_DISTANCE:
                raise _core.InvalidArgument(
                    f"{self.name}: move of {distance:g} refused by the drive: at most "
                    f"{_core.arcus.MAX_MOVE_DISTANCE} per move (the firmware's limit; split it)") from None
            raise

    async def _jog(self, velocity: float) -> None:
        # Refused before anything is sent when the drive cannot run; a jog that the
        # drive takes and then ends in a limit error is a fault seen in status.
        await self._refused("jog")
        try:
            await self._use_mode(OpMode.PROFILE_VELOCITY)
        except _core.TimeoutError:
            # 6061h follows a new mode only once the motor is idle (B-A10).
            if await self._velocity() != 0:
                raise _core.DriveFault("arcus-canopen: jog refused while the motor moves a set-point "
                                       "(stop() first)") from None
            raise
        await self.io.set_velocity(int(round(velocity)))

    @staticmethod
    def object_dictionary() -> "_core.canopen.ObjectDictionary":
        """Table 10.1, typed: the CiA 402 adapter's reads and writes use its entries."""
        return _dictionary()

    # _is_idle and _homing_done: the CiA 402 ones (at rest for any reason; a homing error
    # or a fault raises what _stop_reason below finds).

    async def _in_position_window(self) -> float:
        """StepNLoop on (2001h:01): its tolerance 2001h:03 (SLT, encoder counts: the drive
        corrects a larger error at the end of a move); off: 0 (an open-loop pulse counter
        ends exactly on its target).  Read at each judged move (two SDO reads): the manual
        has no 6067h."""
        if not await self._read(0x2001, 1):
            return 0.0
        return float(await self._read(0x2001, 3))

    async def _travel_limits(self) -> tuple[Optional[float], Optional[float]]:
        return (None, None)          # Table 10.1 has no 607Dh: no software limits

    async def _limit_side(self, status: DriveStatus) -> tuple[int, str]:
        # 60FDh shows a switch still pressed; else the direction the move was going
        # (the ASCII persona's MST bits 6/7 say which, CANopen has no object for them).
        if status.limit_positive:
            return 1, "the +limit switch (60FDh bit 1)"
        if status.limit_negative:
            return -1, "the -limit switch (60FDh bit 0)"
        move = self._move
        if move is not None and move.target is not None:
            side = 1 if move.target > await self._position() else -1
            return side, f"the {'+' if side > 0 else '-'}limit (the switch no longer reads active; side from the move)"
        return 0, "a limit (the drive does not say which)"

    async def _stop_reason(self, status: DriveStatus) -> Optional[StopReason]:
        """A latched error is the FAULT state (B-A18, B-A22); which one, from StepNLoop
        status 2003h (10 stall, 8 correction range, 9 attempts, 11 limit) and the limit
        bits (statusword 11, 60FDh).  The DMX-CAN has no 603Fh: a fault has no code beyond
        the StepNLoop status.  Out of FAULT: as any CiA 402 drive (quick stop, halt...)."""
        sw = int(status.raw)
        state = _core.canopen.cia402_decode_statusword(sw)
        if state not in ("FAULT", "FAULT REACTION ACTIVE"):
            return await super()._stop_reason(status)
        sls = int(await self._read(0x2003))
        if sls in (SnlStatus.STALL_ERROR, SnlStatus.CORRECTION_RANGE_ERROR, SnlStatus.CORRECTION_ATTEMPT_ERROR):
            words = {10: "stall", 8: "correction range", 9: "max attempts"}[sls]
            return StopReason(MoveStalled, f"StepNLoop error: {words} (2003h = {sls})", code=sls)
        if sls == SnlStatus.LIMIT_ERROR or sw & _SW_INTERNAL_LIMIT or status.limit_positive or status.limit_negative:
            side, text = await self._limit_side(status)
            return StopReason(LimitReached, f"{text}: a limit error (statusword bit 11"
                                            f"{', StepNLoop status 11' if sls == SnlStatus.LIMIT_ERROR else ''})",
                              code=sls if sls == SnlStatus.LIMIT_ERROR else None, side=side)
        return StopReason(MoveFaulted, f"a fault (statusword 0x{sw:04X}, StepNLoop status {sls}; the DMX-CAN "
                                       "has no error code object)", code=sls)

    async def _clear_faults(self) -> None:
        # The 200Dh handshake (write 1, poll until 0) is the client's, one job on the
        # node's worker: its polling sleeps that thread, never the event loop.
        await self.io.clear_errors()

    async def _store(self) -> None:
        await self.io.store()         # the 200Eh handshake, as clear_errors

    async def _status_text(self, state: str, mode: Optional[int], sw: int, fault: bool) -> str:
        return (f"{state}, mode {OpMode(mode).name if mode is not None else '?'}, statusword 0x{sw:04X}, "
                f"StepNLoop {await self._snl_text()}")

    def _make_params(self) -> Params:
        return ArcusCanopenParams(self)

    def start_watchdog(self, *args: Any, **kwargs: Any) -> None:
        raise _core.InvalidArgument("arcus-canopen: the DMX-CAN documents no heartbeat; it has no watchdog")


# The same drive as 'arcus' behind its CAN front end: the same faults.
# Standard names ("limit", "stall") and the older alias; the DMX-CAN has no other fault
# (no 603Fh: its errors are the limit and StepNLoop ones) and no stop input.
SIM_FAULTS = {
    # a limit switch closes (+1 / -1): a motion toward it stops and latches a limit error
    "limit": lambda sim, direction=1: sim.force_limit(int(direction), True),
    # the rotor jams: StepNLoop sees the error grow past 2001h:05, stall error (2003h = 10)
    "stall": lambda sim: sim.set_blocked(True),
    "trip_limit": lambda sim, direction=-1: sim.force_limit(int(direction), True),
}


def object_dictionary() -> "_core.canopen.ObjectDictionary":
    """Table 10.1 as a typed motorbus ObjectDictionary (types, access, defaults, ranges and the
    C++ codec of each entry), built in C++ from the table the simulator serves
    (``cpp/motorbus/drives/arcus/canopen_od.cpp``); the EDS (:func:`eds_text`) is generated
    from it.  A fresh dictionary per call (tools may change its values)."""
    return _core.arcus.canopen_object_dictionary()


_OD: Optional["_core.canopen.ObjectDictionary"] = None


def _dictionary() -> "_core.canopen.ObjectDictionary":
    """object_dictionary(), made once: the client's and the adapter's codecs (read only)."""
    global _OD
    if _OD is None:
        _OD = object_dictionary()
    return _OD


def eds_text() -> str:
    """The DMX-CAN's EDS as generated from Table 10.1 (``cpp/motorbus/drives/arcus/canopen.eds``)."""
    return object_dictionary().to_eds()

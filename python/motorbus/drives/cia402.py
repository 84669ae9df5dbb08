"""Any CiA 402 drive on CANopen: a simulated one and the ``Drive`` adapter.

    import motorbus
    with motorbus.open_drive("cia402", bus="socketcand:127.0.0.1:29536/can0", address=5) as axis:
        axis.enable()
        axis.move_to(4000)                  # profile position mode, set-point handshake
        axis.jog(-1000)                     # profile velocity mode
        axis.stop()
        axis.params["0x6081"] = 2000        # profile velocity, by index (or "0x6099:01", or a name)

The adapter runs on the host-side CiA 402 state machine (``motorbus.canopen``'s
``Cia402``) and uses the drive's own heartbeat consumer (0x1016 + 0x6007) as the
link-loss watchdog: the host produces a heartbeat, the drive quick-stops when it
stops arriving (``watchdog=`` option of :func:`open`).

The simulator (``make_sim``: the C++ ``Cia402Sim``, cpp/motorbus/drives/cia402/) is a
CiA 402 node as the profile describes it, built from the core's pieces: a LocalNode
(SDO server, NMT slave, boot-up), a HeartbeatService (producer 0x1017, consumer
0x1016), a PdoService (RPDO/TPDO 1-4, SYNC; the motion objects are mappable) and the
CiA 402 axis (canopen::Cia402Axis: state machine, profile position / profile velocity
/ homing on a motor model with home and limit switches).  ``motorbus sim serve --drive
cia402:5`` serves it over socketcand or SLCAN.

Several CiA 402 axes on one bus start together on one SYNC (:func:`synchronised_start`,
used by ``Bench.move_together``): each drive's set-point travels in a synchronous RPDO
and every drive applies it on the same SYNC frame.
"""
from __future__ import annotations

import contextlib
import time
from typing import Any, Iterator, Optional, Sequence, Union

from .. import _core, faces
from ..canopen.node import check_node_id
from ..canopen.pdo import PdoMap, configure_pdo, read_pdo_config
from ..canopen.sdo import download_async, upload_async
from ..canopen.cia402 import Cia402, Cia402Device, Controlword, OpMode
from ..drive import (Capability, Drive, DriveStatus, LimitReached, MoveFaulted, MoveInterrupted, MoveStalled,
                     ParamInfo, Params, StopReason, Units)

__all__ = ["Cia402Drive", "Cia402Sim", "ERROR_CODES", "SYNC_START_RPDO", "make_sim", "OBJECTS",
           "error_text", "synchronised_start"]

# Statusword bits beyond the state that the adapter reads.
_SW_TARGET_REACHED = 1 << 10
_SW_INTERNAL_LIMIT = 1 << 11
_SW_BIT12 = 1 << 12   # PV: speed zero; HM: homing attained (bit 12 of PP is the set-point ack)
_SW_BIT13 = 1 << 13   # HM: homing error; PP: following error
_I32_MIN, _I32_MAX = -(1 << 31), (1 << 31) - 1

_CW_NEW_SETPOINT = 1 << 4
_CW_IMMEDIATE = 1 << 5
_CW_RELATIVE = 1 << 6
_CW_HALT = 1 << 8

# (index, sub, name, type, access, default, low, high, unit, persists, description): the objects
# the simulator serves and the adapter's params describe -- one table, in C++
# (cpp/motorbus/drives/cia402/sim.cpp ``objects()``); typed, it is object_dictionary().
OBJECTS = [tuple(row) for row in _core.cia402.objects()]
_SAVE = 0x65766173  # CiA 301 1010h signature "save" (ASCII, little-endian)
_OD: Optional["_core.canopen.ObjectDictionary"] = None


def object_dictionary() -> "_core.canopen.ObjectDictionary":
    """The objects the generic simulator serves, as the typed dictionary built in C++ from
    its table (``_core.cia402.object_dictionary``: the rows plus 1010h:01): the adapter
    reads and writes each object with its entry's codec (``Variable.encode/decode``);
    nothing is packed in Python.  Made once, read only."""
    global _OD
    if _OD is None:
        _OD = _core.cia402.object_dictionary()
    return _OD


def _check_node(address: Union[str, int]) -> str:
    """The node-ID 1..127 as text (the CANopen layer's check)."""
    return str(check_node_id(address, "cia402"))


# The simulator is C++ (cpp/motorbus/drives/cia402/sim.hpp): a LocalNode with a
# HeartbeatService, a PdoService and a canopen::Cia402Axis on a motor model.
Cia402Sim = _core.cia402.Sim
_SIM_OPTIONS = ("steps_per_rev", "home", "minus_limit", "plus_limit", "heartbeat_ms", "start_position")


def make_sim(address: Union[str, int] = "1", clock: Optional[_core.runtime.Clock] = None, *,
             bus: Optional[_core.can.Bus] = None, **options: Any) -> Any:
    """A simulated CiA 402 drive at node ``address`` (the C++ ``Cia402Sim``); attached to
    ``bus`` when given.  Options: ``steps_per_rev`` (motor model, default 3200), ``home=(lo, hi)``
    (home switch window in increments, default (1000, 1400)), ``minus_limit`` / ``plus_limit``
    (switch positions, default -100000 / 100000, None = none), ``heartbeat_ms`` (1017h at boot,
    default 0 = off), ``start_position``.  Test hooks: ``inject_fault``, ``force_limit``,
    ``jam``, ``set_stop_input`` (docs/drives/cia402.md)."""
    unknown = set(options) - set(_SIM_OPTIONS)
    if unknown:
        raise _core.InvalidArgument(f"cia402 sim options: unknown {sorted(unknown)}; known {sorted(_SIM_OPTIONS)}")
    # A value of the wrong type is pybind's TypeError, as for every simulator's constructor:
    # a bench file's loader then names the option (Bench._make_sim).
    sim = _core.cia402.Sim(int(_check_node(address)), clock, **options)
    if bus is not None:
        sim.attach(bus)
    return sim


# ---- the Drive adapter --------------------------------------------------------------------

#: 603Fh error codes as CiA 402 (IEC 61800-7-201) names them: the ones a drive
#: commonly shows; any other code is named by its group (:func:`error_text`).
ERROR_CODES = {
    0x0000: "no error",
    0x1000: "generic error",
    0x2220: "continuous over-current (device internal)",
    0x2310: "continuous over-current",
    0x2320: "short circuit / earth leakage",
    0x2330: "earth leakage",
    0x2340: "short circuit",
    0x3110: "mains over-voltage",
    0x3120: "mains under-voltage",
    0x3130: "phase failure",
    0x3210: "DC link over-voltage",
    0x3220: "DC link under-voltage",
    0x4110: "ambient temperature too high",
    0x4210: "excess temperature device",
    0x4310: "excess temperature drive",
    0x5114: "supply voltage too low (electronics)",
    0x5441: "contacts error 1 (an interlock input)",
    0x5530: "EEPROM error",
    0x6010: "reset by watchdog",
    0x6320: "parameter error",
    0x7121: "motor blocked",
    0x7122: "commutation error",
    0x7305: "incremental sensor 1 fault",
    0x7310: "speed error",
    0x7320: "position error",
    0x7500: "communication error",
    0x8110: "CAN overrun",
    0x8120: "CAN error passive",
    0x8130: "life guard or heartbeat error",
    0x8140: "recovered from bus-off",
    0x8311: "torque too high",
    0x8611: "following error",
    0x8612: "reference limit",
}
_ERROR_GROUPS = {0x1: "generic error", 0x2: "current", 0x3: "voltage", 0x4: "temperature",
                 0x5: "device hardware", 0x6: "device software", 0x7: "additional modules",
                 0x8: "monitoring", 0x9: "external error", 0xF: "additional functions"}
#: Codes that mean the rotor did not follow (MoveStalled rather than MoveFaulted).
STALL_CODES = {0x7121, 0x8611}


def error_text(code: int) -> str:
    """``"fault 0x8611 following error"``: a 603Fh code in CiA 402's words."""
    if code in ERROR_CODES:
        name = ERROR_CODES[code]
    elif code >= 0xFF00:
        name = "manufacturer-specific error (the drive's manual)"
    else:
        name = f"{_ERROR_GROUPS.get(code >> 12, 'unknown')} error (group 0x{code >> 8:02X}xx)"
    return f"fault 0x{code:04X} {name}"


class Cia402Params(Params):
    """Objects by index (``"0x6081"``, ``"0x6099:01"``, ``"6081h"``) or by the names of the
    objects table (``"Profile velocity"``); read and written by SDO."""

    def _names(self) -> list[str]:
        return [f"0x{i:04X}" + (f":{s:02X}" if s else "") for (i, s, *_r) in OBJECTS]

    def _key(self, name: str) -> str:
        name = super()._key(name).strip()
        for (i, s, n, *_r) in OBJECTS:
            if name.lower() == n.lower():
                return f"0x{i:04X}" + (f":{s:02X}" if s else "")
        text = name[:-1] if name.lower().endswith("h") else name
        idx, _, sub = text.partition(":")
        try:
            index = int(idx, 16)
            subindex = int(sub, 16) if sub else 0
        except ValueError:
            return name
        return f"0x{index:04X}" + (f":{subindex:02X}" if subindex else "")

    def _info(self, name: str) -> Optional[ParamInfo]:
        for (i, s, n, _dtype, access, default, _low, _high, unit, persists, *desc) in OBJECTS:
            if name == f"0x{i:04X}" + (f":{s:02X}" if s else ""):
                var = object_dictionary()[i, s]     # type and range: the typed entry's
                low, high = var.value_range or (None, None)
                return ParamInfo(name=name, type="str" if var.data_type == _core.canopen.DataType.VISIBLE_STRING else "int",
                                 minimum=low, maximum=high, unit=unit, default=default, persists=persists,
                                 writable=access != "ro", description=f"{n}: {desc[0]}" if desc else n)
        return None

    def _where(self, info: ParamInfo) -> "_core.canopen.Variable":
        idx, _, sub = info.name.partition(":")
        return object_dictionary()[int(idx, 16), int(sub, 16) if sub else 0]

    async def _read(self, info: ParamInfo) -> Any:
        var = self._where(info)
        return var.decode(await self._drive._sdo_upload(var.index, var.subindex))

    async def _write(self, info: ParamInfo, value: Any) -> None:
        var = self._where(info)
        await self._drive._sdo_download(var.index, var.subindex, var.encode(int(value)))
        if var.index == 0x6067:
            self._drive._window = None      # the cached position window is read again


class Cia402Drive(Drive):
    """The Drive API over any CiA 402 node (profile position, profile velocity, homing).

    A move ends at its target within 6067h (position window, read once) or raises the
    :class:`motorbus.MoveFailed` that says why, from the statusword and what it points to
    (603Fh, 60FDh, 607Dh, 6040h): docs/drives/cia402.md "How a move ends".
    ``velocity=`` sets 6081h (profile velocity) for that move only: it is put back when
    the move ends, however it ends."""

    kind = "cia402"
    capabilities = frozenset({Capability.POSITION, Capability.VELOCITY, Capability.HOMING, Capability.STORE,
                              Capability.WATCHDOG})
    has_watchdog = True

    # ---- the plugin (motorbus.registry): what the kind is, and its hooks -------------------
    description = "any CiA 402 drive on CANopen (profile position, profile velocity, homing); simulated generically"
    transport = "can"
    default_address = "1"
    sim_options = ("steps_per_rev", "home", "minus_limit", "plus_limit", "heartbeat_ms", "start_position")

    @classmethod
    def open(cls, *, line: Any = None, bus: Any = None, address: str, units: Optional[Units] = None,
             timeout: float = 1.0, on_error: Optional[str] = "quick_stop", on_exit: Optional[str] = "quick_stop",
             watchdog: Optional[dict] = None) -> "Cia402Drive":
        """``open_drive("cia402", bus=..., address=5)``.  ``watchdog={"host_node": 127, "period": 0.1}``
        arms the drive's heartbeat consumer at once (see Cia402.start_watchdog)."""
        drive = cls._open_on(line, bus, lambda b: Cia402(b, int(address), timeout=timeout, on_error=None,
                                                         on_exit=None),
                             units=units, on_error=on_error, on_exit=on_exit)
        if watchdog:
            try:
                drive.start_watchdog(**watchdog)
            except BaseException:
                drive.close()       # and the bus, if opened from a spec
                raise
        return drive

    make_sim = staticmethod(make_sim)
    check_address = staticmethod(_check_node)

    @classmethod
    def canopen_match(cls, node: Any) -> int:
        # Any node whose device type (0x1000) names profile 402; vendor kinds score higher.
        return 1 if node.profile == 402 else 0

    @classmethod
    def synchronised_start(cls, bus: _core.can.Bus, drives: Sequence["Cia402Drive"]) -> Any:
        return synchronised_start(bus, drives)

    @classmethod
    def sim_faults(cls) -> dict:
        return dict(SIM_FAULTS)

    def poll_fields(self, fields: Sequence[str]) -> Any:
        """motorbus.Poller: 6064h/606Ch/6041h by SDO through the drive's own client."""
        from ..canopen.poll import CIA402_POLL_OBJECTS, sdo_poll_spec

        return sdo_poll_spec(self.kind, self._sdo, self.native.bus, fields, CIA402_POLL_OBJECTS)

    def capture_fields(self, fields: Sequence[str], period: float) -> Any:
        """motorbus.Poller, capturing: 6064h/606Ch/6041h mapped into TPDO 1 (and 2 when
        they pass 64 bits), sent on the event timer every period (whole ms, >= 1)."""
        from ..canopen.poll import CIA402_POLL_OBJECTS, tpdo_capture_spec

        if self.native.bus is None:
            raise _core.InvalidArgument(f"{self.kind} capture: the drive's SDO client has no bus to listen on")
        return tpdo_capture_spec(self.kind, self._sdo, self.native.bus, self.native.node, fields,
                                 CIA402_POLL_OBJECTS, period)

    def plan_move(self, start: float, target: float) -> Any:
        """Profile position mode as CiA 402 defines it: 6081h velocity, 6083h/6084h
        accelerations, 6086h ramp shape (0 linear, 1 sin²), 607Fh cap; increments."""
        from .. import motion

        p = self.params
        params = motion.Cia402ProfileParams(
            profile_velocity=float(p["0x6081"]), profile_acceleration=float(p["0x6083"]),
            profile_deceleration=float(p["0x6084"]), motion_profile_type=int(p["0x6086"]),
            max_profile_velocity=float(p["0x607F"]) if "0x607F" in p else 0.0)
        return motion.cia402_position_profile(motion.MotionState(float(start), 0.0, 0.0, 0.0), float(target), params)

    def __init__(self, host: Cia402, *, units: Optional[Units] = None, on_error: Optional[str] = "quick_stop",
                 on_exit: Optional[str] = "quick_stop", close_native=None) -> None:
        super().__init__(host, units=units, on_error=on_error, on_exit=on_exit, close_native=close_native)
        self._sdo = host.sdo
        self._mode: Optional[int] = None
        # A synchronised start in progress: the bus its SYNC comes on, and the controlword
        # (without the set-point bit) of the move held in the RPDO until then.
        self._sync_bus: Optional[_core.can.Bus] = None
        self._held_cw: Optional[int] = None
        self._sync_rpdo: Optional[tuple] = None   # (COB-ID, PdoMap) of the synchronised-start RPDO
        self._homed = False                      # the last homing attained (sticky until the next)
        self._window: Optional[float] = None     # 6067h, read at the first judged move
        self._at_limit_since: Optional[float] = None
        self._homing_since = 0.0
        self._homing_ran = False

    # ---- helpers ----
    # Every exchange with the drive is an await on self.io (motorbus.faces): the same
    # coroutines serve the blocking verbs and motorbus.aio.  In the awaitable face they run
    # on the worker of this node's SDO client (_io_link), so nodes on one bus talk at once.
    #: The typed dictionary the adapter reads and writes by (a vendor kind gives its own).
    object_dictionary = staticmethod(object_dictionary)

    def _io_link(self) -> Any:
        """One worker per node: its SDO client (the same object for the drive's life).  The
        node's transfers are one conversation anyway (one SDO channel); other nodes on the
        bus have their own workers and their transfers overlap on the wire."""
        return self.native.sdo

    # The adapter's own reads and writes are the CANopen layer's awaitable transfers: in the
    # awaitable face they run in C++ on the bus's receive thread and complete through the
    # loop's queue (no worker thread, however many axes wait); under faces.run, the
    # blocking calls.  The state machine's calls (Cia402Host: enable, the set-point
    # handshake, controlwords) go through self.io, on the node's worker.
    def _sdo_upload(self, index: int, sub: int) -> Any:
        """One SDO upload, awaitable (the one place an SDO read is sent)."""
        return upload_async(self._sdo, index, sub)

    def _sdo_download(self, index: int, sub: int, data: bytes) -> Any:
        """One SDO download, awaitable (the one place an SDO write is sent)."""
        return download_async(self._sdo, index, sub, data)

    async def _read(self, index: int, sub: int = 0) -> Any:
        """One object, decoded by its dictionary entry (C++ codec), through the read that
        survives a second SDO client (_upload)."""
        return self.object_dictionary()[index, sub].decode(await self._upload(index, sub))

    async def _download(self, index: int, value: Any, sub: int = 0) -> None:
        """One object, encoded by its dictionary entry (C++ codec)."""
        await self._sdo_download(index, sub, self.object_dictionary()[index, sub].encode(value))

    #: Attempts of one read when another SDO client on the node takes the reply.
    sdo_read_attempts = 5

    async def _upload(self, index: int, sub: int = 0) -> bytes:
        """One SDO read that survives another program's SDO client on this node (its
        requests and ours share the COB-IDs): a reply naming another object is not our
        answer (ask again), and one dropped request is a collision (ask once more); a
        second timeout in a row is a link that is gone."""
        timeouts = 0
        for attempt in range(self.sdo_read_attempts):
            try:
                return bytes(await self._sdo_upload(index, sub))
            except _core.SdoProtocolError:
                if attempt + 1 == self.sdo_read_attempts:
                    raise
            except _core.SdoTimeout:
                timeouts += 1
                if timeouts > 1 or attempt + 1 == self.sdo_read_attempts:
                    raise
        raise AssertionError("unreachable")

    async def _statusword(self) -> int:
        return int(await self._read(0x6041))

    async def _use_mode(self, mode: OpMode) -> None:
        if self._mode != mode:
            await self.io.set_mode(mode)
            self._mode = mode

    async def _operation_enabled(self) -> None:
        if await self.io.attr("state") != "OPERATION ENABLED":
            await self.io.go_to("OPERATION ENABLED")

    async def _new_set_point_edge(self) -> None:
        """Controlword bit 4 low then high in Operation Enabled (a homing start): one job on
        the link, so that a stop sent meanwhile lands after both writes instead of between
        them, where the second (halt bit clear) would undo it."""
        await self.io.do(_set_point_edge, self.native)

    # ---- Drive ----
    async def _enable(self) -> None:
        await self.io.enable()

    async def _disable(self) -> None:
        await self.io.disable()

    async def _speed_for_this_move(self, velocity: Optional[float]) -> None:
        """velocity= is for this move only: 6081h is put back when the move ends."""
        if velocity is not None:
            await self._for_this_move(lambda: self._read(0x6081), lambda v: self._download(0x6081, int(round(v))),
                                      int(round(velocity)))

    async def _set_point(self, target: float, relative: bool, velocity: Optional[float]) -> None:
        await self._use_mode(OpMode.PROFILE_POSITION)
        await self._speed_for_this_move(velocity)
        if self._sync_bus is not None:
            await self._hold_set_point(int(round(target)), relative)
            return
        try:
            # The set-point handshake (new set-point, acknowledge, release) is one native
            # call: one job on the link's worker.
            await self.io.move_to(int(round(target)), relative)
        except _core.TimeoutError:
            # A drive that is not in Operation Enabled never acknowledges a set-point:
            # say that rather than "timeout" (checked only on failure: it costs an SDO read).
            await self._refused("move")
            raise

    # ---- SYNC-triggered start (see synchronised_start) ----
    async def _arm_sync_start(self, bus: _core.can.Bus) -> None:
        """Maps RPDO SYNC_START_RPDO (once): synchronous (type 1), target position then
        controlword — in that order, because the drive applies the entries in mapping order
        and the set-point edge must find the new target already written.  Starts the node
        (NMT): PDOs flow only in OPERATIONAL."""
        node = self.native.node
        if self._sync_rpdo is None:
            # The PDO layer writes the mapping and packs the frames (sizes and signs from the entries).
            entries = []
            for index in (0x607A, 0x6040):
                var = self.object_dictionary()[index, 0]
                entries.append((index, 0, 8 * var.size, var.value_range[0] < 0))

            def configure() -> Any:
                configure_pdo(self._sdo, node, rpdo=SYNC_START_RPDO, transmission_type=1, mapping=entries)
                return read_pdo_config(self._sdo, node, rpdo=SYNC_START_RPDO).cob_id
            self._sync_rpdo = (await self.io.do(configure), PdoMap(entries))
        # PDOs flow only in OPERATIONAL
        await self.io.do(bus.send, _core.canopen.nmt_encode(_core.canopen.NmtCommand.START, node))
        self._sync_bus = bus

    async def _hold_set_point(self, target: int, relative: bool) -> None:
        base = int(Controlword.ENABLE_OPERATION) | _CW_IMMEDIATE | (_CW_RELATIVE if relative else 0)
        # As in an SDO move: the previous acknowledge must have dropped for the edge to count.
        await self.io.wait_statusword(_SW_BIT12, 0)
        cob, layout = self._sync_rpdo
        await self.io.do(self._sync_bus.send, _core.can.Frame(cob, layout.pack([target, base | _CW_NEW_SETPOINT])))
        self._held_cw = base

    async def _release_sync_start(self, started: bool) -> None:
        """After the SYNC (``started``): completes the set-point handshake.  Without it (the
        block failed): overwrites the held RPDO with one that carries no set-point edge, so a
        later SYNC from anyone starts nothing."""
        bus, base = self._sync_bus, self._held_cw
        self._sync_bus = self._held_cw = None
        if base is None:
            return
        if not started:
            cob, layout = self._sync_rpdo
            await self.io.do(bus.send, _core.can.Frame(cob, layout.pack([int(await self._read(0x607A)), base])))
            return
        try:
            await self.io.wait_statusword(_SW_BIT12, _SW_BIT12)
        except _core.TimeoutError:
            await self._refused("move")
            raise
        await self.io.write_controlword(base)

    async def _refused(self, what: str) -> None:
        state = await self.io.attr("state")
        if state != "OPERATION ENABLED":
            raise _core.DriveFault(f"{self.kind}: {what} refused in state {state} (enable() first"
                                   f"{', clear_faults()' if state == 'FAULT' else ''})")

    async def _move_to(self, target: float, velocity: Optional[float]) -> None:
        await self._set_point(target, False, velocity)

    async def _move_by(self, distance: float, velocity: Optional[float]) -> None:
        await self._set_point(distance, True, velocity)

    async def _jog(self, velocity: float) -> None:
        await self._use_mode(OpMode.PROFILE_VELOCITY)
        await self.io.set_velocity(int(round(velocity)))
        await self._refused("jog")  # PV has no handshake: look whether the drive can run

    async def _stop(self) -> None:
        # Halt (controlword bit 8): decelerate with 6084h and stay in Operation Enabled.
        await self.io.urgent.write_controlword(int(Controlword.ENABLE_OPERATION) | _CW_HALT)

    async def _quick_stop(self) -> None:
        await self.io.urgent.write_controlword(int(Controlword.QUICK_STOP))

    # Speed and ramps (the EPICS record's VELO/ACCL): profile velocity 6081h, and the
    # profile acceleration/deceleration 6083h/6084h in position units per s².
    async def _move_speed(self) -> tuple[Optional[float], Optional[float]]:
        return await self._speed_param("0x6081")

    async def _set_accel_time(self, seconds: float, speed: float, top: Optional[float]) -> bool:
        rate = max(1.0, speed / seconds)
        await self._set_params_clamped({"0x6083": rate, "0x6084": rate})
        return True

    async def _home(self, method: Any) -> None:
        await self._operation_enabled()
        await self._use_mode(OpMode.HOMING)
        if method is not None:
            if not isinstance(method, int) or not _core.motion.Cia402Homing.supported(method):
                raise _core.InvalidArgument(f"cia402 home: method 7, 11, 17-20 or 33-35, not {method!r}")
            await self._download(0x6098, int(method))
        await self._start_homing()

    async def _start_homing(self) -> None:
        self._homed = False          # this homing decides; an earlier one no longer counts
        self._homing_since = time.monotonic()
        self._homing_ran = False
        await self._new_set_point_edge()

    #: Seconds after the homing start in which "target reached without homing attained"
    #: still means "not started yet" rather than "interrupted" (CiA 402 shows both alike).
    homing_start_grace = 0.2

    async def _homing_done(self) -> bool:
        """CiA 402 homing bits 13/12/10: error / attained / reached.  Ends on attained,
        raises the MoveFailed that says why on an error or a fault, and returns True on an
        interrupted homing (reached without attained, or the drive left Operation Enabled)
        so that the outcome is judged (a halt or quick stop: MoveInterrupted)."""
        sw = await self._statusword()
        state = _core.canopen.cia402_decode_statusword(sw)
        if state in ("FAULT", "FAULT REACTION ACTIVE") or sw & _SW_BIT13:
            if sw & _SW_BIT13 and state == "OPERATION ENABLED":
                await self.io.write_controlword(int(Controlword.ENABLE_OPERATION))
            if state == "FAULT REACTION ACTIVE":
                return False
            status = await self._status()
            reason = await self._stop_reason(status)
            if reason is None or reason.error is MoveInterrupted:
                reason = StopReason(MoveFaulted, "a homing error (statusword bit 13)")
            elif not state.startswith("FAULT"):
                reason = StopReason(reason.error, f"a homing error (statusword bit 13) at {reason.text}",
                                    reason.code, reason.side)
            raise await self._failure(self._move, reason, status=status)
        if state != "OPERATION ENABLED":
            return True             # quick stopped or disabled: judged (MoveInterrupted)
        reached = bool(sw & _SW_TARGET_REACHED)
        if (sw & (_SW_BIT12 | _SW_TARGET_REACHED)) == (_SW_BIT12 | _SW_TARGET_REACHED):
            await self.io.write_controlword(int(Controlword.ENABLE_OPERATION))
            return True
        if not reached:
            self._homing_ran = True
            return False
        # Reached, not attained, no error: interrupted (a halt) -- or not started yet.
        if self._homing_ran or time.monotonic() - self._homing_since > self.homing_start_grace:
            return await self._velocity() == 0
        return False

    async def _controlword_now(self) -> int:
        """6040h as the drive holds it (another program may have written it)."""
        return int(await self._read(0x6040))

    #: Seconds a drive must stand still at an internal limit (bit 11) without showing
    #: target reached before it counts as at rest (a move leaving a limit starts at v = 0).
    limit_rest_time = 0.1

    async def _is_idle(self) -> bool:
        """At rest, whatever the reason: Operation Enabled with target reached (PP: the
        target, or a halt: CiA 402 sets bit 10 once a halted axis stands), a following
        error (bit 13), a standstill at an internal limit (bit 11); or out of Operation
        Enabled (fault, quick stop done, disabled) -- with the velocity 0."""
        sw = await self._statusword()
        state = _core.canopen.cia402_decode_statusword(sw)
        if state == "FAULT REACTION ACTIVE":
            return False
        if state == "OPERATION ENABLED":
            settled = bool(sw & _SW_TARGET_REACHED)
            if not settled and self._mode == OpMode.PROFILE_POSITION and sw & _SW_BIT13:
                settled = True
            if not settled and sw & _SW_INTERNAL_LIMIT:
                since = self._at_limit_since
                now = time.monotonic()
                if since is None:
                    self._at_limit_since = now
                elif now - since >= self.limit_rest_time:
                    settled = True
            else:
                self._at_limit_since = None
            if not settled:
                return False
        self._at_limit_since = None
        return await self._velocity() == 0

    async def _in_position_window(self) -> float:
        """6067h (position window), read once and kept: it is a setting, not a reading.
        FFFFFFFFh switches the drive's window off (CiA 402): then, as without 6067h, exactly."""
        if self._window is None:
            try:
                window = int(await self._read(0x6067))
            except _core.SdoAbortError:
                window = 0xFFFFFFFF
            self._window = self.in_position_window if window == 0xFFFFFFFF else float(window)
        return self._window

    async def _limit_side(self, status: DriveStatus) -> tuple[int, str]:
        """Which limit the drive stands at, in its own terms (60FDh, then 607Dh)."""
        bit11 = "; statusword bit 11 internal limit active" if int(status.raw) & _SW_INTERNAL_LIMIT else ""
        if status.limit_positive:
            return 1, f"the +limit switch (60FDh bit 1{bit11})"
        if status.limit_negative:
            return -1, f"the -limit switch (60FDh bit 0{bit11})"
        lo, hi = await self._travel_limits()
        position = await self._position()
        if hi is not None and position >= hi:
            return 1, f"the software position limit 607Dh:02 = {hi:g}{bit11.replace(';', ' (') + ')' if bit11 else ''}"
        if lo is not None and position <= lo:
            return -1, f"the software position limit 607Dh:01 = {lo:g}{bit11.replace(';', ' (') + ')' if bit11 else ''}"
        return 0, "an internal limit (statusword bit 11; the drive does not say which)"

    async def _stop_reason(self, status: DriveStatus) -> Optional[StopReason]:
        """The statusword and what it points to: a fault (603Fh code and CiA 402 text; a
        following error 0x8611 or motor blocked 0x7121 is a stall), a following error (PP
        bit 13), a limit (60FDh switches, 607Dh soft limits, bit 11), a quick stop, the
        drive out of Operation Enabled, or a halt (6040h bit 8) that this program did not
        send."""
        sw = int(status.raw)
        state = _core.canopen.cia402_decode_statusword(sw)
        ours = self._move is not None and self._move.stopped_by is not None
        if state in ("FAULT", "FAULT REACTION ACTIVE"):
            code = int(await self._read(0x603F))
            error = MoveStalled if code in STALL_CODES else MoveFaulted
            return StopReason(error, error_text(code), code=code)
        if self._mode == OpMode.PROFILE_POSITION and sw & _SW_BIT13:
            return StopReason(MoveStalled, "a following error (statusword bit 13)")
        if sw & _SW_INTERNAL_LIMIT or status.limit_positive or status.limit_negative:
            side, text = await self._limit_side(status)
            return StopReason(LimitReached, text, side=side)
        if ours:
            return None             # this program's stop()/quick_stop(): Drive says so
        if state == "QUICK STOP ACTIVE":
            return StopReason(MoveInterrupted, "a quick stop (state QUICK STOP ACTIVE) from another program or a "
                                               "stop input (CiA 402 does not say which)")
        if state != "OPERATION ENABLED":
            return StopReason(MoveInterrupted, f"the drive leaving OPERATION ENABLED (now {state}): a quick stop, "
                                               "disable or shutdown from another program, a stop input or a lost "
                                               "heartbeat")
        if await self._controlword_now() & _CW_HALT:
            return StopReason(MoveInterrupted, "a halt (controlword bit 8) from another program")
        return None

    async def _travel_limits(self) -> tuple[Optional[float], Optional[float]]:
        """607Dh:01/02 (software position limits); the I32 extremes mean none."""
        try:
            lo, hi = int(await self._read(0x607D, 1)), int(await self._read(0x607D, 2))
        except _core.SdoAbortError:
            return (None, None)      # the drive has no 607Dh
        if lo >= hi:
            return (None, None)      # CiA 402: min >= max switches the limits off on many drives
        return (None if lo <= _I32_MIN else float(lo), None if hi >= _I32_MAX else float(hi))

    async def _clear_faults(self) -> None:
        await self.io.fault_reset()

    async def _store(self) -> None:
        await self._download(0x1010, _SAVE, sub=1)

    async def _position(self) -> float:
        return float(await self._read(0x6064))

    async def _velocity(self) -> float:
        return float(await self._read(0x606C))

    async def _digital_inputs(self) -> int:
        """60FDh (bit 0 negative limit, bit 1 positive limit)."""
        return int(await self._read(0x60FD))

    async def _status_text(self, state: str, mode: Optional[int], sw: int, fault: bool) -> str:
        """The status line; a vendor kind adds what its drive says beyond CiA 402."""
        text = f"{state}, mode {OpMode(mode).name if mode is not None else '?'}, statusword 0x{sw:04X}"
        if fault:
            text += f", {error_text(int(await self._read(0x603F)))}"
        return text

    async def _status(self) -> DriveStatus:
        sw = await self._statusword()
        state = _core.canopen.cia402_decode_statusword(sw)
        inputs = await self._digital_inputs()
        velocity = await self._velocity()
        mode = self._mode
        fault = state in ("FAULT", "FAULT REACTION ACTIVE")
        if mode is None:        # not set by this Drive yet: the mode in effect (6061h), for the text
            try:
                mode = int(await self._read(0x6061))
                OpMode(mode)
            except (_core.SdoAbortError, ValueError):
                mode = None
        # With halt (6040h bit 8) set, bit 10 means "stands still", not "at target" (CiA 402),
        # whoever set it.
        at_target = bool(sw & _SW_TARGET_REACHED) and state == "OPERATION ENABLED" and not (
            await self._controlword_now() & _CW_HALT)
        homed = self._mode == OpMode.HOMING and bool(sw & _SW_BIT12)
        self._homed = self._homed or homed
        text = await self._status_text(state, mode, sw, fault)
        return DriveStatus(enabled=state == "OPERATION ENABLED",
                           moving=velocity != 0 or not (sw & _SW_TARGET_REACHED or state != "OPERATION ENABLED"),
                           homed=self._homed, fault=fault, at_target=at_target,
                           limit_positive=bool(inputs & 2), limit_negative=bool(inputs & 1), raw=sw, text=text)

    async def _console(self, line: str) -> str:
        # SDO reads and writes by index (motorbus.canopen.console has the syntax).
        from ..canopen.console import sdo_console
        return await self.io.do(sdo_console, self._sdo, line)

    def _make_params(self) -> Params:
        return Cia402Params(self)

    def _close(self) -> None:
        self.native.close()

    def start_watchdog(self, host_node: int, period: float = 0.1, **kwargs: Any) -> None:
        """Arm the drive's own heartbeat consumer on a heartbeat this host produces."""
        self.native.start_watchdog(host_node, period, **kwargs)


def _set_point_edge(host: Cia402) -> None:
    """Controlword 0x0F then 0x1F: the new-set-point edge that starts a homing."""
    host.write_controlword(int(Controlword.ENABLE_OPERATION))
    host.write_controlword(int(Controlword.ENABLE_OPERATION) | _CW_NEW_SETPOINT)


#: The RPDO a synchronised start maps on each drive (its previous mapping is replaced).
SYNC_START_RPDO = 4


@contextlib.contextmanager
def synchronised_start(bus: _core.can.Bus, drives: Sequence[Cia402Drive]) -> Iterator[str]:
    """Moves commanded inside the block start together on one CANopen SYNC.

    Each drive gets its set-point (target position and the controlword with the
    new-set-point bit) in a synchronous RPDO (type 1, RPDO ``SYNC_START_RPDO``), which a
    CiA 301 device holds until the next SYNC; when the block exits one SYNC frame on
    ``bus`` makes every drive apply it, so all start on the same frame.  The handshake is
    then completed over SDO as for any move.  If the block fails, the held RPDOs are
    overwritten with ones that start nothing.  Yields the method's name.

    A plain (blocking) context manager, as every kind's: under motorbus.aio its entry
    and exit (the RPDO mapping once, the NMT start, then the handshakes' ends) run on
    the loop's thread, a few SDO transfers per drive (``faces.run``)."""
    for d in drives:
        faces.run(d._arm_sync_start(bus))
    try:
        yield "CANopen SYNC"
    except BaseException:
        for d in drives:
            faces.run(d._release_sync_start(started=False))
        raise
    bus.send(_core.can.Frame(0x080, b""))       # SYNC (COB-ID 0x080): every held RPDO applies now
    for d in drives:
        faces.run(d._release_sync_start(started=True))


# Faults the simulator can be given (the pytest plugin's sim_faults fixture).
# The standard names ("limit", "fault", "stall", "stop_input") and the older alias.
SIM_FAULTS = {
    # a limit switch closes (+1 / -1): a motion toward it stops at once (bit 11, 60FDh)
    "limit": lambda sim, direction=1: sim.force_limit(int(direction), True),
    # the drive detects a fault (603Fh code, default 0x5441 interlock): motor stops, state FAULT
    "fault": lambda sim, code=0x5441: sim.inject_fault(int(code)),
    # the rotor jams: the following error passes 6065h, fault 0x8611 (statusword bit 13)
    "stall": lambda sim: sim.jam(True),
    # the simulator's quick-stop input (60FDh bit 16) fires: a quick stop, as by controlword
    "stop_input": lambda sim: sim.set_stop_input(True),
    "drive_fault": lambda sim, code=0x5441: sim.inject_fault(int(code)),
}

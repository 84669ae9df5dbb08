"""CQPUSI PMC007 integrated stepper on CANopen (CiA 301): client, simulator, Drive adapter.

    import motorbus
    with motorbus.open_drive("pmc007", bus="socketcand:127.0.0.1:29536/can0", address=5) as axis:
        axis.enable()
        axis.move_to(3200)                  # 6004h step command (relative), 601Ch absolute
        axis.jog(-1000)                     # speed mode (6005h = 1, 6003h signed)
        axis.stop()
        axis.params["start_speed"] = 600    # any object by name, "0x6006" or "6006h"
        axis.native.controller_status       # ControllerStatus.BUSY | ...

The native client :class:`Pmc007` is a profile of the CANopen node facade, as
canopen's ``BaseNode402`` is a ``RemoteNode``: a :class:`motorbus.canopen.RemoteNode`
whose object dictionary is the C++ one of the device (``cpp/motorbus/drives/pmc007/od_table.cpp``,
handed up typed by ``_core.pmc007.object_dictionary``; the EDS shipped next to this module
is generated from the same table).  An object by name is an entry of that dictionary
read and written through the node's SDO client with the entry's C++ codec; PDOs are
the node's ``tpdo``/``rpdo`` channels (the C++ PDO engine packs and unpacks them).  The simulator (:class:`~motorbus._core.pmc007.Sim`, ``make_sim``)
is C++: a LocalNode with that dictionary, heartbeat, PDOs, EMCY, motion on the
motor model.

Link loss: the PMC007 produces a heartbeat (1017h) and has consumer entries
(1016h), but the manual documents no reaction to a lost consumer heartbeat and
no communication watchdog.  A cut cable therefore cannot stop the motor: a
running move finishes and speed mode keeps running.  The adapter stops the motor
at exit and on an exception inside ``with`` (``on_error``/``on_exit``), and the
next call after a link loss raises (SdoTimeout).  ``has_watchdog`` is False.
"""
from __future__ import annotations

import enum
import math
import re
import threading
import time
from typing import Any, Callable, Iterable, Optional, Union

from .. import _core, _stop_at_exit, faces
from . import data_file
from ..stopping import check_stop_way
from ..canopen.node import RemoteNode, check_node_id
from ..canopen.pdo import PdoChannel
from ..canopen.sdo import SdoVariable
# The PMC007's profile model (start/stop speeds, gear table, microstepping): the vendor's own module
# re-exports it (motorbus.motion keeps the generic planners).
from .._core.pmc007 import (  # noqa: F401
    ProfileParams as Pmc007ProfileParams, convert_position as pmc007_convert_position,
    gear_acceleration as pmc007_gear_acceleration, microsteps as pmc007_microsteps,
    position_profile as pmc007_position_profile, speed_profile as pmc007_speed_profile,
)
from ..drive import (Capability, Drive, DriveStatus, LimitReached, MoveFaulted, MoveInterrupted, MoveStalled,
                     ParamInfo, Params, StopReason, Units, stopped_by_text)

__all__ = ["ControllerStatus", "ErrorStatus", "Pmc007", "Pmc007Drive", "make_sim", "OBJECTS",
           "EDS_PATH", "assemble", "disassemble", "BAUD_RATES", "GEAR_ACCELERATION", "STALL_EXAMPLES",
           "ABORT_DEVICE_STATE", "Pmc007ProfileParams", "pmc007_convert_position",
           "pmc007_gear_acceleration", "pmc007_microsteps", "pmc007_position_profile", "pmc007_speed_profile"]

#: The EDS shipped with the package (generated from the table the simulator uses; its home is
#: cpp/motorbus/drives/pmc007/pmc007.eds, installed beside _core: see motorbus.drives.data_file).
EDS_PATH = str(data_file("pmc007", "pmc007.eds"))

#: 2003h baud index -> kbit/s (003 §4.3.2).
BAUD_RATES = {0: 20, 1: 25, 2: 50, 3: 100, 4: 125, 5: 250, 6: 500, 7: 800, 8: 1000}
#: 6008h/6009h gear -> pps² (003 §4.5.12; 0 = no ramp).
GEAR_ACCELERATION = {g: _core.pmc007.gear_acceleration(g) for g in range(1, 9)}
#: 003 §4.5.19: the manual's stall-detection reference rows (6017h values).
STALL_EXAMPLES = {
    "28mm 5.7mH 900mA 24V 8 microsteps": 0x64E6,
    "42mm 2.8mH 1600mA": 0x64B4,
    "57mm 1.1mH 3000mA": 0xC8B2,
}
ABORT_DEVICE_STATE = 0x08000022


class ErrorStatus(enum.IntFlag):
    """6000h "driving state" error bits; write 1 to a bit to clear it."""

    UVLO = 1 << 0   # low voltage
    BERR = 1 << 1   # coil B error
    AERR = 1 << 2   # coil A error
    BOC = 1 << 3    # coil B over-current
    AOC = 1 << 4    # coil A over-current
    TSD = 1 << 5    # over-temperature shutdown


#: 6000h bits in the manual's words (003 §4.5.1).
ERROR_TEXT = {ErrorStatus.UVLO: "UVLO low voltage", ErrorStatus.BERR: "BERR coil B error",
              ErrorStatus.AERR: "AERR coil A error", ErrorStatus.BOC: "BOC coil B over-current",
              ErrorStatus.AOC: "AOC coil A over-current", ErrorStatus.TSD: "TSD over-temperature shutdown"}


class ControllerStatus(enum.IntFlag):
    """6001h controller bits; 1 clears EXT1/EXT2/STALL (and the EXT3 latch); BUSY cannot be cleared."""

    EXT1 = 1 << 0
    EXT2 = 1 << 1
    STALL = 1 << 2
    BUSY = 1 << 3
    EXT3 = 1 << 4   # the spec's reading: EXT3 (ENC1) latch


def _snake(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")


def _build_objects(od: "_core.canopen.ObjectDictionary") -> dict:
    """Python name -> the dictionary's typed entry (``motorbus.canopen.Variable``); names
    are snake_case of the manual's object names ("start_speed"), "<record>.<member>" for
    sub-indexed ones ("external_emergency_stop.enable")."""
    out = {}
    for index in od.indices():
        record = _snake(od.object_name(index)) if od.object_code(index) != "VAR" else None
        for sub in od.subindices(index):
            var = od[index, sub]
            key = f"{record}.{_snake(var.name)}" if record else _snake(var.name)
            if key in out:  # repeated member names (1003h:01..07, 1016h:01..03)
                key = f"{key}_{sub}"
            out[key] = var
    return out


#: Every object of the dictionary by its Python name (see _build_objects): the typed
#: entries of the C++ table (data type, access, limits, default, encode/decode).
OBJECTS = _build_objects(_core.pmc007.object_dictionary())
_BY_INDEX = {(v.index, v.subindex): k for k, v in OBJECTS.items()}


def assemble(text: str) -> list[int]:
    """Offline-program text ("ROT 0,3200" per line) -> 6019h:02 words.  The word encoding
    is not in the manual: opcode << 24 | option << 20 | data (the spec's reading)."""
    return list(_core.pmc007.assemble(text))


def disassemble(words: Iterable[int]) -> str:
    return _core.pmc007.disassemble([int(w) for w in words])


def _check_node(address: Union[str, int]) -> str:
    """The node-ID 1..127 as text (the CANopen layer's check)."""
    return str(check_node_id(address, "pmc007"))


def _object_property(name: str, doc: str) -> property:
    """A read/write property over one integer object of the table (read and written by SDO)."""
    return property(lambda self: int(self.read(name)), lambda self, value: self.write(name, value), doc=doc)


class Pmc007(_stop_at_exit.StopsMotor, RemoteNode):
    """The native client: a PMC007 profile of a CANopen node (``motorbus.canopen.RemoteNode``).

    ``Pmc007(bus, node=5)`` (a ``_core.can.Bus`` or ``motorbus.open_bus`` text).  Objects by
    name: ``drive["start_speed"]``, ``drive.read("0x6006")``, ``drive.write("6006h", 600)``;
    properties for the common ones.  Underneath is the node: ``object_dictionary`` (the
    device's C++ table, typed), ``sdo`` (its SDO client), ``tpdo``/``rpdo``, ``nmt``.
    Safety words ``on_error``/``on_exit`` ("stop" and "quick_stop" = 6020h immediate stop,
    "disable" = 600Eh = 0, None): ``on_error`` when an exception leaves ``with``,
    ``on_exit`` at interpreter exit, as every native client (``_stop_at_exit.StopsMotor``)."""

    def __init__(self, bus: Any, node: int = 5, timeout: float = 1.0, *, on_error: Optional[str] = "stop",
                 on_exit: Optional[str] = "stop") -> None:
        check_stop_way(on_error, "on_error")
        check_stop_way(on_exit, "on_exit")
        node_id = check_node_id(node, "pmc007")
        self._owns = isinstance(bus, str)
        if self._owns:
            from ..bus import open_bus
            bus = open_bus(bus)
        super().__init__(bus, node_id, _core.pmc007.object_dictionary(node_id), timeout)
        self.node = node_id
        self.on_error, self.on_exit = on_error, on_exit
        self._vars: dict = {}       # Python name -> the node's SdoVariable (made on first use)
        self._pdos: dict = {}       # COB-ID -> the PdoChannel this client configured on it
        self._closed = False
        _stop_at_exit.track(self)

    # ---- objects by name ----
    @staticmethod
    def resolve(name: Union[str, int, tuple]) -> str:
        """The table name for "start_speed", "Start speed", "0x6006", "6006h", "0x600F:01", (0x600F, 1)."""
        if isinstance(name, tuple):
            key = _BY_INDEX.get((int(name[0]), int(name[1]) if len(name) > 1 else 0))
            if key is None:
                raise _core.InvalidArgument(f"pmc007: no object {name!r}")
            return key
        if isinstance(name, int):
            return Pmc007.resolve((name, 0))
        if not isinstance(name, str):
            raise _core.InvalidArgument(f"pmc007: object names are strings, not {name!r}")
        text = name.strip()
        if text in OBJECTS:
            return text
        snake = _snake(text)
        if snake in OBJECTS:
            return snake
        m = re.fullmatch(r"(?:0x)?([0-9a-fA-F]{4})h?(?:(?::|sub)(?:0x)?([0-9a-fA-F]{1,2})h?)?", text)
        if m and (text.lower().startswith("0x") or text.lower().endswith("h") or ":" in text):
            key = _BY_INDEX.get((int(m.group(1), 16), int(m.group(2), 16) if m.group(2) else 0))
            if key is not None:
                return key
        raise _core.InvalidArgument(f"pmc007: no object {name!r}")

    def variable(self, name: Union[str, int, tuple]) -> SdoVariable:
        """The node's SDO object for a name (any form :meth:`resolve` takes): ``.value``
        reads and writes it with its dictionary entry's C++ codec."""
        key = self.resolve(name)
        var = self._vars.get(key)
        if var is None:
            index, sub = OBJECTS[key].index, OBJECTS[key].subindex
            var = self._vars[key] = SdoVariable(self.sdo.client, index, sub, self.object_dictionary[index, sub])
        return var

    def read(self, name: Union[str, int, tuple]) -> Union[int, str]:
        return self.variable(name).value

    def write(self, name: Union[str, int, tuple], value: int) -> None:
        var = self.variable(name)
        if var.od.access == "const":
            raise _core.InvalidArgument(f"pmc007: {var.od.name} is not writable")
        # The entry's codec refuses a value its type cannot carry; the limits are the device's.
        var.value = int(value)

    def __getitem__(self, name: Union[str, int, tuple]) -> Union[int, str]:
        return self.read(name)

    def __setitem__(self, name: Union[str, int, tuple], value: int) -> None:
        self.write(name, value)

    # ---- status ----
    @property
    def error_status(self) -> ErrorStatus:
        return ErrorStatus(self.read("error_status"))

    def clear_errors(self, bits: int = 0x3F) -> None:
        """Write 1 to the 6000h bits to clear them."""
        self.write("error_status", int(bits) & 0x3F)

    @property
    def controller_status(self) -> ControllerStatus:
        return ControllerStatus(self.read("controller_status"))

    def clear_status(self, bits: int = 0x17) -> None:
        """Write 1 to 6001h bits (EXT1, EXT2, STALL, EXT3); BUSY cannot be cleared."""
        self.write("controller_status", int(bits) & 0x17)

    @property
    def busy(self) -> bool:
        return bool(self.controller_status & ControllerStatus.BUSY)

    # ---- motion ----
    position = _object_property("motor_position", "600Ch: motor position, steps (writable: sets the counter)")
    speed = _object_property("maximum_speed", "6003h: signed run speed, pps (+ sets direction 1, - direction 0)")
    direction = _object_property("rotation_direction", "6002h: rotation direction, 0 or 1")
    microstepping = _object_property("microstepping", "600Ah: microsteps per full step")

    @property
    def enabled(self) -> bool:
        return self.read("motor_enable") == 1

    def enable(self, on: bool = True) -> None:
        self.write("motor_enable", 1 if on else 0)

    def release(self) -> None:
        """600Eh = 0: phase current off, the current step command ends."""
        self.enable(False)

    def set_mode(self, speed_mode: bool) -> None:
        self.write("operation_mode", 1 if speed_mode else 0)

    def step(self, steps: int, speed: Optional[int] = None) -> None:
        """Relative move (6004h) of |steps| in the sign's direction; speed in pps (6003h)."""
        steps = int(steps)
        pps = abs(int(speed)) if speed is not None else abs(self.speed)
        if pps:
            # 6003h's sign is the direction: write the speed with the move's sign ("speed first").
            self.speed = pps if steps >= 0 else -pps
        else:
            self.direction = 1 if steps >= 0 else 0
        self.write("step_command", abs(steps))

    def move_absolute(self, target: int, speed: Optional[int] = None) -> None:
        if speed is not None:
            self.speed = abs(int(speed))
        self.write("absolute_displacement_command", int(target))

    def run(self, pps: int) -> None:
        """Speed mode at a signed speed.  6003h first: switching to speed mode runs at once at
        the 6003h in force (B-P12), so the mode goes second or the motor would start at the old
        speed (and direction).  In speed mode already, the 6003h write changes the run."""
        self.speed = int(pps)
        self.set_mode(True)

    def stop(self) -> None:
        """6020h: immediate stop in any mode."""
        self.write("stop_stepping_command", 0)

    # ---- persistence / system ----
    def save(self) -> None:
        """2007h = 2: every ROM object to flash."""
        self.write("system_control", 2)

    def factory_reset(self) -> None:
        """2007h = 3: factory values into the working copy (save() to keep them)."""
        self.write("system_control", 3)

    def bootloader(self) -> None:
        self.write("system_control", 1)

    # ---- offline program ----
    def upload_program(self, program: Union[str, Iterable[int]], *, to_flash: bool = True,
                       auto_run: Optional[bool] = None) -> list[int]:
        """The manual's sequence: 6018h:02 = 0, each word at 6019h:01 = i / 6019h:02, 6018h:01 = count,
        6019h:03 = 1 (flash); ``auto_run`` sets 6018h:02 afterwards."""
        words = assemble(program) if isinstance(program, str) else [int(w) for w in program]
        if len(words) > 100:
            raise _core.InvalidArgument(f"pmc007 program: {len(words)} instructions, at most 100")
        self.write("offline_programming_parameter_1.offline_automatic_operation", 0)
        for i, w in enumerate(words):
            self.write("offline_programming_parameter_2.program_pointer", i)
            self.write("offline_programming_parameter_2.offline_command", w & 0xFFFFFFFF)
        self.write("offline_programming_parameter_1.number_of_offline_commands", len(words))
        if to_flash:
            self.write("offline_programming_parameter_2.save_offline_commands", 1)
        if auto_run is not None:
            self.write("offline_programming_parameter_1.offline_automatic_operation", 1 if auto_run else 0)
        return words

    def read_program(self) -> list[int]:
        n = int(self.read("offline_programming_parameter_1.number_of_offline_commands"))
        out = []
        for i in range(n):
            self.write("offline_programming_parameter_2.program_pointer", i)
            out.append(int(self.read("offline_programming_parameter_2.offline_command")))
        return out

    def verify_program(self, program: Union[str, Iterable[int]]) -> bool:
        words = assemble(program) if isinstance(program, str) else [int(w) for w in program]
        return self.read_program() == words

    def run_instruction(self, index: int) -> None:
        """PUSICAN "try run current command": 6019h:01 = index, 6019h:05 = 1."""
        self.write("offline_programming_parameter_2.program_pointer", index)
        self.write("offline_programming_parameter_2.run_command", 1)

    def start_program(self, on: bool = True) -> None:
        self.write("offline_programming_parameter_1.offline_automatic_operation", 1 if on else 0)

    # ---- PDO: the node's tpdo/rpdo channels (C++ PDO engine), in the manual's order ----
    def _mapping(self, items: Iterable[Union[str, tuple]]) -> list:
        """(index, sub, bits) of each object, the size from its dictionary entry."""
        out = []
        for item in items:
            v = OBJECTS[self.resolve(item)]
            out.append((v.index, v.subindex, 8 * v.size))
        return out

    def configure_tpdo(self, n: int, mapping: Iterable[Union[str, tuple]], *, cob_id: Optional[int] = None,
                       transmission_type: int = 255, inhibit_100us: int = 0, event_timer_ms: int = 0) -> int:
        """TPDO ``n`` (1..4) with the manual's sequence (App.3 §11.2): COB-ID, type, inhibit,
        event timer, sub0 = count, then the entries (``procedure="direct"`` of the PDO layer).
        Returns the COB-ID."""
        if not 1 <= int(n) <= 4:
            raise _core.InvalidArgument(f"pmc007: TPDO number 1..4, not {n!r}")
        cob = int(cob_id) if cob_id is not None else 0x180 + 0x100 * (n - 1) + self.node
        channel = self.tpdo[int(n)]
        channel.configure(cob_id=cob, transmission_type=int(transmission_type), inhibit_100us=int(inhibit_100us),
                          event_timer_ms=int(event_timer_ms), mapping=self._mapping(mapping), procedure="direct")
        self._pdos[cob] = channel
        return cob

    def configure_rpdo(self, n: int, mapping: Iterable[Union[str, tuple]], *, cob_id: Optional[int] = None,
                       transmission_type: int = 255) -> int:
        """RPDO ``n`` (1..4) in the same order: COB-ID, type, sub0 = count, entries.  Only the
        writable mappable objects (6000h, 6001h, 600Ch, 6012h) can be mapped.  Returns the COB-ID."""
        if not 1 <= int(n) <= 4:
            raise _core.InvalidArgument(f"pmc007: RPDO number 1..4, not {n!r}")
        cob = int(cob_id) if cob_id is not None else 0x200 + 0x100 * (n - 1) + self.node
        channel = self.rpdo[int(n)]
        channel.configure(cob_id=cob, transmission_type=int(transmission_type), mapping=self._mapping(mapping),
                          procedure="direct")
        self._pdos[cob] = channel
        return cob

    def _channel(self, cob_id: int, tpdo: bool) -> PdoChannel:
        channel = self._pdos.get(int(cob_id))
        if channel is None or channel.tpdo != tpdo:
            raise _core.InvalidArgument(f"pmc007: {'TPDO' if tpdo else 'RPDO'} 0x{int(cob_id):X} was not "
                                        "configured by this client")
        return channel

    def send_rpdo(self, cob_id: int, values: dict) -> None:
        """One RPDO frame on ``cob_id`` (configured by configure_rpdo) with {object name: value}."""
        channel = self._channel(cob_id, tpdo=False)
        names = [_BY_INDEX[(index, sub)] for (index, sub, _bits) in channel.mapping]
        missing = [k for k in names if k not in values]
        if missing:
            raise _core.InvalidArgument(f"pmc007: RPDO 0x{int(cob_id):X} needs a value for {missing[0]!r}")
        channel.transmit([int(values[k]) for k in names])

    def tpdo_stream(self, cob_id: int, capacity: int = 100_000) -> "TpdoStream":
        """The TPDO's values as numpy arrays: a ring of ``capacity`` frames, one field per mapped
        object plus ``t`` (the frame's receive time, s).  ``stream.values()`` is a copy, oldest first."""
        return TpdoStream(self._channel(cob_id, tpdo=True), int(capacity))

    def on_tpdo(self, cob_id: int, callback: Callable[[dict], None]) -> Callable[[dict], None]:
        """Typed callback {object name: value} for every TPDO frame on ``cob_id`` (as
        configured by configure_tpdo).  Returns what was added to the channel
        (``self.tpdo[n].remove_callback(it)`` stops it)."""
        channel = self._channel(cob_id, tpdo=True)
        names = {(index, sub): _BY_INDEX[(index, sub)] for (index, sub, _bits) in channel.mapping}

        def by_name(values: dict) -> None:
            callback({names[k]: v for k, v in values.items()})
        channel.add_callback(by_name)
        return by_name

    # ---- life ----
    def _stop_on_error(self) -> None:
        self._halt(self.on_error)

    def _stop_at_exit(self) -> None:
        self._halt(self.on_exit)

    def _halt(self, how: Optional[str]) -> None:
        if not self._closed:
            # 6020h is already the immediate stop: "stop" and "quick_stop" are the same here.
            _stop_at_exit.halt(how, self.stop, self.stop, self.release)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        _stop_at_exit.untrack(self)
        super().close()             # the node's PDO receivers
        if self._owns:
            self.bus.close()


class TpdoStream:
    """numpy ring buffer of one TPDO's values (see Pmc007.tpdo_stream), fed by the node's
    TPDO channel (decoded by the C++ PDO engine); ``close()`` stops it."""

    def __init__(self, channel: PdoChannel, capacity: int) -> None:
        import numpy as np

        if capacity < 1:
            raise _core.InvalidArgument("pmc007: tpdo_stream capacity must be >= 1")
        self._keys = [(index, sub) for (index, sub, _bits) in channel.mapping]
        od = channel._node.object_dictionary
        fields = [("t", "f8")]
        for index, sub in self._keys:
            var = od[index, sub]
            # numpy's integer of the entry's size and sign (the entry says both).
            fields.append((_BY_INDEX[(index, sub)], f"{'i' if var.value_range[0] < 0 else 'u'}{var.size}"))
        self.dtype = np.dtype(fields)
        self._buf = np.zeros(capacity, dtype=self.dtype)
        self._n = 0
        self._lock = threading.Lock()
        self._channel = channel
        channel.add_callback(self._on_values)

    def _on_values(self, values: dict) -> None:
        row = (self._channel.timestamp, *(values[k] for k in self._keys))
        with self._lock:
            self._buf[self._n % len(self._buf)] = row
            self._n += 1

    def __len__(self) -> int:
        return min(self._n, len(self._buf))

    @property
    def received(self) -> int:
        return self._n

    def values(self) -> Any:
        import numpy as np

        with self._lock:
            n, cap = self._n, len(self._buf)
            if n <= cap:
                return self._buf[:n].copy()
            i = n % cap
            return np.concatenate([self._buf[i:], self._buf[:i]])

    def close(self) -> None:
        self._channel.remove_callback(self._on_values)


# ---- simulator -------------------------------------------------------------------------

def make_sim(address: Union[str, int] = "5", clock: Optional[_core.runtime.Clock] = None, *,
             bus: Optional[_core.can.Bus] = None, **options: Any) -> Any:
    """A simulated PMC007 at node ``address`` (``_core.pmc007.Sim``); attached to ``bus`` when given.
    Options: ``steps_per_rev`` (200), ``pull_out_speed`` (0 = never stalls by speed),
    ``ext1_switch=(lo, hi)``: a switch wired to EXT1, low while the position is inside
    (default (-1e9, -1000): a home switch on the negative side, for homing into EXT1),
    ``store_path``: the file holding the sim's flash between runs (2007h=2, 6019h:03, 602Ah),
    ``vendor_id``/``product_code``/``revision``/``serial``: what 1018h reads (the manual gives
    no identity; default vendor 0 = none claimed, product 7, revision 0x00010000, serial 1)."""
    known = {"steps_per_rev", "pull_out_speed", "ext1_switch", "store_path", "vendor_id", "product_code", "revision",
             "serial"}
    options.setdefault("ext1_switch", (-1e9, -1000.0))
    unknown = set(options) - known
    if unknown:
        raise _core.InvalidArgument(f"pmc007 sim options: unknown {sorted(unknown)}; known {sorted(known)}")
    sim = _core.pmc007.Sim(int(_check_node(address)), clock, **options)
    if bus is not None:
        sim.attach(bus)
    return sim


# ---- the Drive adapter ----------------------------------------------------------------

class Pmc007Params(Params):
    """Every object of the dictionary by its table name ("start_speed",
    "external_emergency_stop.enable") or by index ("0x6006", "6006h", "0x600F:01")."""

    def _names(self) -> list[str]:
        return list(OBJECTS)

    def _key(self, name: str) -> str:
        name = super()._key(name)
        try:
            return Pmc007.resolve(name)
        except _core.InvalidArgument:
            return name

    def _info(self, name: str) -> Optional[ParamInfo]:
        if name not in OBJECTS:
            return None
        # The node's own entry (defaults for its node-ID): a table lookup, no exchange.
        var = self._drive._od[OBJECTS[name].index, OBJECTS[name].subindex]
        low, high = var.value_range or (None, None)
        return ParamInfo(name=name, type="str" if var.data_type == _core.canopen.DataType.VISIBLE_STRING else "int",
                         minimum=low, maximum=high, default=var.default,
                         persists=_core.pmc007.storage(var.index, var.subindex) == _core.pmc007.Storage.ROM,
                         writable=var.access in ("rw", "wo"),
                         description=f"{var.index:04X}h:{var.subindex:02X} {var.name}")

    async def _read(self, info: ParamInfo) -> Any:
        return await self._drive.io.read(info.name)

    async def _write(self, info: ParamInfo, value: Any) -> None:
        await self._drive.io.write(info.name, int(value))


#: External stop inputs: 6001h latch bit -> (name, 600Fh enable bit).
_EXT_INPUTS = {ControllerStatus.EXT1: ("EXT1", 0x01), ControllerStatus.EXT2: ("EXT2", 0x02),
               ControllerStatus.EXT3: ("EXT3", 0x10)}


def _flags(value: Any) -> str:
    """A status byte for a person: ``0x09 (EXT1|BUSY)``, ``0x00 (none)``."""
    names = "|".join(f.name for f in type(value) if f in value) or "none"
    return f"0x{int(value):02X} ({names})"


def _read_state(native: Pmc007) -> tuple:
    """(6000h error bits, 6001h controller bits, enabled): the three uploads a status takes,
    run together (one job on the drive's worker in the awaitable face, not three)."""
    return native.error_status, native.controller_status, native.enabled


class Pmc007Drive(Drive):
    """The Drive API over a PMC007: position mode (6004h relative, 601Ch absolute), speed mode,
    stop (6020h), enable/release (600Eh), homing into an external stop input.

    ``velocity=`` (pps) sets 6003h for that move only: the drive's own value is put back
    when the move ends, however it ends.  How a move ends (``_stop_reason``): 6000h error
    bits → MoveFaulted (code = 6000h), 6001h STALL → MoveStalled, an external stop input
    (EXT1/EXT2/EXT3 latch) → MoveInterrupted naming the input, or LimitReached when
    ``ext_limits`` declares that input a limit switch (``{"ext2": +1}``: EXT2 is wired to
    the + limit), the motor released (600Eh = 0) → MoveInterrupted.  The in-position
    window is 0: 600Ch is the drive's own step counter (open loop), it ends exactly on
    the target unless stopped."""

    kind = "pmc007"
    capabilities = frozenset({Capability.POSITION, Capability.VELOCITY, Capability.HOMING, Capability.STORE})
    has_watchdog = False
    in_position_window = 0.0

    # ---- the plugin (motorbus.registry): what the kind is, and its hooks -------------------
    description = "CQPUSI PMC007 integrated stepper on CANopen (CiA 301)"
    transport = "can"
    default_address = "5"
    sim_options = ("steps_per_rev", "pull_out_speed", "ext1_switch", "store_path", "vendor_id", "product_code",
                   "revision", "serial")
    store_file = "pmc007-{address}.flash"

    @classmethod
    def open(cls, *, line: Any = None, bus: Any = None, address: str, units: Optional[Units] = None,
             timeout: float = 1.0, on_error: Optional[str] = "stop", on_exit: Optional[str] = "stop",
             home_speed: int = 2000, ext_limits: Optional[dict] = None) -> "Pmc007Drive":
        """``open_drive("pmc007", bus=..., address=5)``; ``ext_limits={"ext2": +1}``: external stop
        inputs wired as limit switches (their stop is then LimitReached, not MoveInterrupted)."""
        return cls._open_on(line, bus, lambda b: Pmc007(b, int(_check_node(address)), timeout=timeout,
                                                        on_error=None, on_exit=None),
                            units=units, on_error=on_error, on_exit=on_exit, home_speed=home_speed,
                            ext_limits=ext_limits)

    make_sim = staticmethod(make_sim)
    check_address = staticmethod(_check_node)

    @classmethod
    def canopen_match(cls, node: Any) -> int:
        # Discovery: the manual gives the PMC007 no device type and no identity (1000h 0,
        # no vendor), so a node reporting device type 0 and no vendor is taken for one (the
        # simulator's product code 7 makes it surer); weak, but the only mark the manual
        # leaves.  A CiA 402 drive reports its profile instead.
        if node.device_type != 0 or node.vendor_id:
            return 0
        return 3 if node.product_code == 7 else 2 if not node.product_code else 0

    @classmethod
    def sim_faults(cls) -> dict:
        return dict(SIM_FAULTS)

    def poll_fields(self, fields: Any) -> Any:
        """motorbus.Poller: 600Ch (position) and the controller status by SDO.  The
        PMC007 has no actual-speed object (the Drive measures it over a window), so
        "velocity" is refused: differentiate the polled position instead."""
        from ..canopen.poll import sdo_poll_spec

        native = self.native
        return sdo_poll_spec(self.kind, native.sdo.client, native.bus, fields, _poll_objects())

    def capture_fields(self, fields: Any, period: float) -> Any:
        """motorbus.Poller, capturing: 600Ch and the controller status (6001h), both
        PDO-mappable, in TPDO 1 on the event timer, written with the manual's sequence
        (App.3 §11.2: the PDO changed in place)."""
        from ..canopen.poll import tpdo_capture_spec

        native = self.native
        if native.bus is None:
            raise _core.InvalidArgument("pmc007 capture: the drive's SDO client has no bus to listen on")
        return tpdo_capture_spec(self.kind, native.sdo.client, native.bus, native.node, fields, _poll_objects(), period,
                                 procedure="direct")

    def plan_move(self, start: float, target: float) -> Any:
        """A PMC007 position move (its profile model): run speed |6003h| (the start
        speed 6006h when 0), start/stop speeds 6006h/6007h, gears 6008h/6009h,
        microstepping 600Ah; steps."""
        from .. import motion

        p = self.params
        speed = abs(float(p["0x6003"])) or float(p["0x6006"])
        params = Pmc007ProfileParams(speed=speed, start_speed=float(p["0x6006"]), stop_speed=float(p["0x6007"]),
                                     accel_gear=int(p["0x6008"]), decel_gear=int(p["0x6009"]),
                                     microstepping=int(p["0x600A"]))
        return pmc007_position_profile(motion.MotionState(float(start), 0.0, 0.0, 0.0), float(target), params)

    def __init__(self, native: Pmc007, *, units: Optional[Units] = None, on_error: Optional[str] = "stop",
                 on_exit: Optional[str] = "stop", close_native=None, home_speed: int = 2000,
                 ext_limits: Optional[dict] = None) -> None:
        super().__init__(native, units=units, on_error=on_error, on_exit=on_exit, close_native=close_native)
        self._home_speed = int(home_speed)
        self._homing: Optional[ControllerStatus] = None
        self._homed = False
        self._speed_mode = False
        self._sdo_misses = 0
        self._ext_limits = _check_ext_limits(ext_limits)
        #: The node's object dictionary (its C++ table for this node-ID), kept so that
        #: describing a parameter reads a table, never the client, on the event loop.
        self._od = getattr(native, "object_dictionary", None)

    # ---- Drive hooks, native units (steps) -------------------------------------------------
    # Coroutines over self.io (motorbus.faces): the same code serves drive.move_to(...) and
    # `await aio.Drive(drive).move_to(...)`.  Each exchange is one SDO transfer of the native
    # client (Pmc007, blocking); the awaitable face runs them on the bus's worker.
    def _io_link(self) -> Any:
        # The drive's SDO transfers share a worker with every drive on the same CAN bus (one
        # conversation at a time on the wire, one thread for a bench of axes); a node built
        # without a bus object falls back to a worker of its own.
        return getattr(self.native, "bus", None)

    async def _refusing(self, what: str, call: Any) -> None:
        """Awaits ``call`` (an exchange of self.io); the device-state abort 08000022 (a
        command the drive refuses in its present state) becomes a DriveFault saying why."""
        try:
            await call
        except _core.SdoAbortError as e:
            if e.code != ABORT_DEVICE_STATE:
                raise
            text = await self._fault_text()
            raise _core.DriveFault(f"pmc007: {what} refused (08000022): {text}") from None

    async def _state(self) -> tuple:
        """(6000h, 6001h, enabled) read as one snapshot (three SDO uploads in a row on the worker)."""
        return await self.io.do(_read_state, self.native)

    async def _fault_text(self) -> str:
        err, st, enabled = await self._state()
        return f"6000h {_flags(err)}, 6001h {_flags(st)}, enabled={enabled}"

    async def _leave_speed_mode(self, urgent: bool = False) -> None:
        if self._speed_mode:
            # speed -> position mode decelerates with the 6009h gear: a stop when urgent
            await (self.io.urgent if urgent else self.io).set_mode(False)
            self._speed_mode = False

    async def _speed_for_this_move(self, velocity: Optional[float], sign: int = 1) -> Optional[int]:
        """6003h for this move only (Drive puts the old value back when it ends)."""
        if velocity is None:
            return None
        pps = abs(int(round(velocity)))
        if not 1 <= pps <= 32000:
            raise _core.InvalidArgument(f"pmc007: velocity {velocity:g} pps is outside 1..32000 (6003h)")
        await self._for_this_move(lambda: self.io.attr("speed"), lambda v: self.io.set_attr("speed", v),
                                  pps if sign >= 0 else -pps)
        return pps

    async def _enable(self) -> None:
        await self.io.enable(True)

    async def _disable(self) -> None:
        await self.io.release()

    async def _wait_stopped(self) -> None:
        # A step command while busy is ignored (B-P07): the previous move must be over.
        for _ in range(2000):
            if not await self.io.attr("busy"):
                return
            await faces.sleep(0.005)

    async def _move_to(self, target: float, velocity: Optional[float]) -> None:
        await self._leave_speed_mode()
        await self._wait_stopped()
        await self._speed_for_this_move(velocity)
        await self._refusing("move", self.io.move_absolute(int(round(target))))

    async def _move_by(self, distance: float, velocity: Optional[float]) -> None:
        await self._leave_speed_mode()
        await self._wait_stopped()
        steps = int(round(distance))
        await self._speed_for_this_move(velocity, 1 if steps >= 0 else -1)
        await self._refusing("move", self.io.step(steps))

    async def _jog(self, velocity: float) -> None:
        pps = int(round(velocity))
        self._speed_mode = True
        await self._refusing("jog", self.io.run(pps))

    async def _stop(self) -> None:
        if self._speed_mode:
            await self._leave_speed_mode(urgent=True)  # speed -> position mode decelerates with the 6009h gear
        else:
            await self.io.urgent.stop()

    async def _quick_stop(self) -> None:
        await self.io.urgent.stop()
        await self._leave_speed_mode(urgent=True)

    # Speed and ramps (the EPICS record's VELO/ACCL): maximum_speed in steps/s; the drive
    # accelerates by gears (1 fastest .. 8, 6008h/6009h): the gear nearest speed/seconds.
    async def _move_speed(self) -> tuple[Optional[float], Optional[float]]:
        return await self._speed_param("maximum_speed")

    async def _set_accel_time(self, seconds: float, speed: float, top: Optional[float]) -> bool:
        want = speed / seconds if seconds > 0 else math.inf
        gear = min(GEAR_ACCELERATION, key=lambda g: abs(math.log(GEAR_ACCELERATION[g] / max(want, 1e-9))))
        await self._set_params_clamped({"0x6008": gear, "0x6009": gear})
        return True

    async def _home(self, method: Any) -> None:
        inputs = {None: ControllerStatus.EXT1, "ext1": ControllerStatus.EXT1, "ext2": ControllerStatus.EXT2,
                  "ext3": ControllerStatus.EXT3}
        if method not in inputs:
            raise _core.InvalidArgument(f"pmc007 home: 'ext1', 'ext2', 'ext3' or None, not {method!r}")
        bit = inputs[method]
        enable_bit = _EXT_INPUTS[bit][1]
        io = self.io
        await io.stop()
        await io.clear_status(int(bit))
        await io.write("external_emergency_stop.enable",
                       int(await io.read("external_emergency_stop.enable")) | enable_bit)
        await io.write("external_emergency_stop.trigger_mode",
                       int(await io.read("external_emergency_stop.trigger_mode")) & ~enable_bit)  # falling edge
        old_speed = await io.attr("speed")
        if self._move is not None:
            # The homing runs in speed mode at -home_speed: 6003h is put back once it has
            # ended, but never while speed mode still runs (the write would set its speed).
            self._move.restore.append(lambda: None if self._speed_mode else io.set_attr("speed", old_speed))
        self._homing = bit
        self._homed = False
        self._speed_mode = True
        await self._refusing("home", io.run(-abs(self._home_speed)))

    async def _homing_done(self) -> bool:
        err, st, enabled = await self._state()
        if self._homing is None:
            return not st & ControllerStatus.BUSY
        failure = None
        if err or st & ControllerStatus.STALL or not enabled:
            failure = self._stop_reason_of(err, st, enabled)
        elif st & self._homing and not st & ControllerStatus.BUSY:
            await self.io.clear_status(int(self._homing))
            await self._leave_speed_mode()
            await self.io.set_attr("position", 0)
            self._homing = None
            self._homed = True
            return True
        elif st & ~self._homing & (ControllerStatus.EXT1 | ControllerStatus.EXT2 | ControllerStatus.EXT3):
            failure = self._stop_reason_of(err, ControllerStatus(st & ~self._homing), True)
        elif not st & ControllerStatus.BUSY:
            by = self._move.stopped_by if self._move is not None else None
            failure = StopReason(MoveInterrupted, stopped_by_text(by) if by else
                                 f"a stop before the {_EXT_INPUTS[self._homing][0]} input fired (another "
                                 "program's stop?)")
        if failure is None:
            return False
        self._homing = None
        await self._leave_speed_mode()
        where = await self._position()
        kw = {"side": failure.side} if issubclass(failure.error, LimitReached) else {}
        raise failure.error(f"{self.name}: homing stopped at {self._units.to_user(where):g} {self._units.name} "
                            f"by {failure.text}", axis=self.name, position=self._units.to_user(where),
                            reason=failure.text, code=failure.code, status=(int(err), int(st)),
                            units=self._units.name, **kw)

    async def _is_idle(self) -> bool:
        # Another program's SDO requests to this node (a second client on the same COB-IDs)
        # can take our reply (SdoProtocolError: it names another object) or take the node's
        # single request slot so ours is dropped (SdoTimeout): neither is an answer, so
        # the poll asks again; a second timeout in a row is a link that is gone.
        try:
            busy = await self.io.attr("busy")
        except _core.SdoProtocolError:
            return False
        except _core.SdoTimeout:
            self._sdo_misses += 1
            if self._sdo_misses > 1:
                raise
            return False
        self._sdo_misses = 0
        return not busy

    def _stop_reason(self, status: DriveStatus) -> Optional[StopReason]:
        err, st = status.raw
        return self._stop_reason_of(ErrorStatus(err), ControllerStatus(st), status.enabled)

    def _stop_reason_of(self, err: ErrorStatus, st: ControllerStatus, enabled: bool) -> Optional[StopReason]:
        if err:
            words = ", ".join(text for bit, text in ERROR_TEXT.items() if err & bit)
            return StopReason(MoveFaulted, f"the error status 6000h = 0x{int(err):02X} ({words})", code=int(err))
        if st & ControllerStatus.STALL:
            return StopReason(MoveStalled, "the stall detection (6001h bit 2 STALL)", code=int(st))
        for bit, (name, _) in _EXT_INPUTS.items():
            if st & bit:
                where = {ControllerStatus.EXT1: "bit 0", ControllerStatus.EXT2: "bit 1",
                         ControllerStatus.EXT3: "bit 4"}[bit]
                side = self._ext_limits.get(name.lower())
                if side:
                    return StopReason(LimitReached, f"the {'+' if side > 0 else '-'}limit switch on the {name} "
                                                    f"input (6001h {where})", code=int(st), side=side)
                return StopReason(MoveInterrupted, f"the {name} external stop input (6001h {where})", code=int(st))
        if not enabled:
            return StopReason(MoveInterrupted, "the release of the motor (600Eh = 0)")
        return None

    async def _clear_faults(self) -> None:
        await self.io.clear_errors()
        await self.io.clear_status()

    async def _store(self) -> None:
        await self.io.save()

    async def _position(self) -> float:
        return float(await self.io.attr("position"))

    #: Seconds between the two position samples a velocity reading takes.
    velocity_window: float = 0.01

    async def _velocity(self) -> float:
        # The PMC007 has no actual-speed object: the speed is measured from the position
        # counter (600Ch) over velocity_window seconds while the motor is busy, else 0.
        if not await self.io.attr("busy"):
            return 0.0
        t0, p0 = time.monotonic(), await self.io.attr("position")
        await faces.sleep(self.velocity_window)
        t1, p1 = time.monotonic(), await self.io.attr("position")
        return (p1 - p0) / (t1 - t0) if t1 > t0 else 0.0

    async def _status(self) -> DriveStatus:
        err, st, enabled = await self._state()
        fault = bool(err) or bool(st & ControllerStatus.STALL)
        busy = bool(st & ControllerStatus.BUSY)
        lim = {side: any(st & bit for bit, (name, _) in _EXT_INPUTS.items() if self._ext_limits.get(name.lower()) == side)
               for side in (1, -1)}
        text = f"6000h {_flags(err)}, 6001h {_flags(st)}, {'enabled' if enabled else 'released'}"
        return DriveStatus(enabled=enabled, moving=busy, homed=self._homed, fault=fault, at_target=not busy,
                           limit_positive=lim[1], limit_negative=lim[-1], raw=(int(err), int(st)), text=text)

    async def _console(self, line: str) -> str:
        # SDO reads and writes by index (motorbus.canopen.console has the syntax).
        from ..canopen.console import sdo_console
        return await self.io.do(sdo_console, self.native.sdo, line)

    def _make_params(self) -> Params:
        return Pmc007Params(self)

    def _close(self) -> None:
        self.native.close()


def _check_ext_limits(ext_limits: Optional[dict]) -> dict:
    """``{"ext1": -1, "ext2": +1}``: which external stop inputs are wired as limit switches."""
    if ext_limits is None:
        return {}
    if not isinstance(ext_limits, dict):
        raise _core.InvalidArgument(f"pmc007 ext_limits: a table {{input: +1 or -1}}, not {ext_limits!r}")
    out = {}
    for k, v in ext_limits.items():
        name = str(k).lower()
        if name not in ("ext1", "ext2", "ext3") or isinstance(v, bool) or v not in (1, -1):
            raise _core.InvalidArgument(f"pmc007 ext_limits: {k!r} = {v!r}; inputs ext1/ext2/ext3, sides +1 or -1")
        out[name] = int(v)
    return out


def _sim_stall(sim: Any) -> None:
    """The rotor jams and the drive detects it: an open-loop PMC007 sees a stall only with
    stall detection set up (6017h threshold != 0), so a sim without it gets the manual's
    first reference row (0x64E6) and stop-on-stall (601Bh = 1) first."""
    od = sim.od
    if int(od[(0x6017, 0)].value) >> 8 == 0:
        od[(0x6017, 0)].value = STALL_EXAMPLES["28mm 5.7mH 900mA 24V 8 microsteps"]
        od[(0x601B, 0)].value = 1
    sim.set_jammed(True)


def _sim_stop_input(sim: Any, input: str = "ext2") -> None:  # noqa: A002 - the input's name
    """An external stop input fires (B-P22): enabled in 600Fh:01 on its falling edge if it is
    not, then driven low; it counts after the 601Ah debounce (100 ms by default).  EXT2 by
    default: EXT1 carries the sim's home switch."""
    bit, port = {"ext1": (0x01, 7), "ext2": (0x02, 8), "ext3": (0x10, 9)}[str(input).lower()]
    od = sim.od
    od[(0x600F, 1)].value = int(od[(0x600F, 1)].value) | bit
    od[(0x600F, 2)].value = int(od[(0x600F, 2)].value) & ~bit
    sim.set_input(port, False)


# Faults the simulator can be given (the pytest plugin's sim_faults fixture): the standard
# names ("fault", "stall", "stop_input") and this kind's own.  No "limit": the PMC007 has
# no limit switch input; an external stop input wired as one is "stop_input" with
# ext_limits= on the Drive.
SIM_FAULTS = {
    # a drive fault: 6000h error bits (default UVLO low voltage); the motor stops
    "fault": lambda sim, bits=1: sim.inject_error(int(bits)),
    # the rotor jams and the drive's stall detection sees it (6001h bit 2)
    "stall": _sim_stall,
    # an external stop input fires (EXT2 unless input="ext1"/"ext3")
    "stop_input": _sim_stop_input,
    # the supply falls below the drive's threshold: the UVLO error bit (ErrorStatus bit 0)
    "supply_drop": lambda sim: sim.inject_error(1),
    # any error-status bits (ErrorStatus), e.g. 0x20 = over-temperature shutdown
    "error": lambda sim, bits=1: sim.inject_error(int(bits)),
}
def _poll_objects() -> dict:
    """The poll layer's (index, sub, "i32"/"u8", scale) of each field, said by the entry."""
    objects = {}
    for field, name in (("position", "motor_position"), ("status", "controller_status")):
        var = OBJECTS[name]
        sign = "i" if var.value_range[0] < 0 else "u"
        objects[field] = (var.index, var.subindex, f"{sign}{8 * var.size}", 1.0)
    return objects

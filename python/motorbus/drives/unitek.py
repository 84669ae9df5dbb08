"""UNITEK BAMOCAR / BAMOBIL / DS servo controllers on their CAN register protocol.

    import motorbus
    from motorbus.drives.unitek import Unitek, Reg, Status

    bus = motorbus.open_bus("socketcand:127.0.0.1:29536/can0")
    with Unitek(bus, rx_id=0x201) as drive:          # stops the motor when the block fails
        drive.write(Reg.ACC_RAMP, 1000)               # ms; writes are never acknowledged...
        assert drive.read(Reg.ACC_RAMP) == 1000       # ...so read back what matters
        drive.speed_rpm = 300                         # SPEED_CMD from rpm via N max
        stream = drive.subscribe(Reg.SPEED_IST, 1)    # every 1 ms into a numpy ring
        t_ns, num = stream.read()                     # filled by the C++ receive thread
        drive.unsubscribe(Reg.SPEED_IST)

The protocol is not CANopen (002 §4.1): one REGID byte and a little-endian
value, to the drive on its receive id (0x201..0x27F), from the drive on its
transmit id (0x181..0x1FF; here ``rx_id - 0x80`` unless given, the pairing of
the manual's defaults and of its example 9, 0x210/0x190).  ``open_drive("unitek",
bus=..., address="0x201")`` gives the shared Drive API; ``make_sim("0x201")`` a
simulated servo; ``motorbus sim serve --drive unitek:0x201`` serves one.

Registers are data: :func:`builtin_registers` (the 12 documented REGIDs),
extended with :func:`load_registers` from a TOML file (the manual says the full
map lives in NDrive).  Format::

    [[register]]
    regid = 0x6D            # required
    name = "POS_IST"        # required
    bits = 32               # 16 (default) or 32
    signed = true
    access = "ro"           # rw (default) | ro | wo
    quantity = "position"   # raw (default) | speed | position | current | torque | time
    unit = "rev"
    scale = 1.0             # raw/time: physical = num * scale
    min = -100              # optional range (both or neither)
    max = 100
    description = "..."

Link loss: the drive's only time-out monitor is "T-Out" in NDrive's CAN-Setup
(002 Fig. 6-1), not reachable over CAN and not described further.  The
adapter therefore does not claim a watchdog (``has_watchdog = False``): when
the link is lost the drive keeps the last set-point (a jog keeps turning)
unless T-Out was set in NDrive, and the next call raises ``LinkDown`` or
``TimeoutError``.  The simulator models T-Out only when asked (``t_out_ms``).
"""
from __future__ import annotations

import enum
import threading
import time
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, Union

from .. import _core, _stop_at_exit, faces
from . import data_file
from ..stopping import check_stop_way
# The drive's speed ramps (ACC 0x35 / DEC 0xED): the vendor's own module re-exports the model.
from .._core.unitek import RampParams as UnitekRampParams, speed_profile as unitek_speed_profile  # noqa: F401
from ..drive import (Capability, Drive, DriveStatus, LimitReached, MoveFaulted, MoveInterrupted, ParamInfo, Params,
                     StopReason, Units, stopped_by_text)
from ..registry import PollSpec

__all__ = ["FrameError", "UnknownRegister", "CyclicLimit", "Reg", "Status", "ModeBit", "Unitek", "UnitekDrive", "UnitekSim", "Stream", "make_sim",
           "builtin_registers", "load_registers", "ndrive_registers", "REVOLUTIONS", "BIT_TIMINGS",
           "btr_for_bit_rate", "bit_rate_for_btr", "current_limit_num", "CURRENT_COMMAND_MAX", "UnitekRampParams",
           "unitek_speed_profile"]

#: Typed errors (also motorbus._core.Unitek*: the errors are at _core top level).
FrameError = _core.UnitekFrameError          # a frame breaking the protocol; .byte, .data
UnknownRegister = _core.UnitekUnknownRegister  # REGID not in the table; .regid
CyclicLimit = _core.UnitekCyclicLimit        # a 9th cyclic register

COUNTS_PER_REV = 65536
FULL_SCALE = 32767
#: User units of revolutions for open_drive(..., units=REVOLUTIONS).
REVOLUTIONS = Units("rev", 1.0 / COUNTS_PER_REV)

#: §3.1: (bit rate in kbit/s, NDrive's BTR setting value, longest line in m).  The bit rate is
#: set in NDrive's CAN-Setup, not over CAN: open the bus at the drive's rate.
BIT_TIMINGS = tuple((r["kbit_s"], r["btr"], r["max_line_m"]) for r in _core.unitek.bit_timings())
#: §6.1: the current command range, "+/- 9 bit".
CURRENT_COMMAND_MAX = 511


def btr_for_bit_rate(bit_rate: float) -> int:
    """The BTR setting of a bit rate (bit/s); InvalidArgument naming the table's five."""
    return _core.unitek.btr_for_bit_rate(bit_rate)


def bit_rate_for_btr(btr: int) -> float:
    """The bit rate (bit/s) of a BTR setting value; InvalidArgument naming the table's five."""
    return _core.unitek.bit_rate_for_btr(btr)


def current_limit_num(device: str, motor_limit_num: int) -> int:
    """§6.1 "the smaller value is effective": the peak current (num) a ``device`` ("DS 205/405",
    "DS 412", "DS 420") delivers with a motor limit of ``motor_limit_num``."""
    return _core.unitek.effective_current_limit_num(device, motor_limit_num)


class Reg(enum.IntEnum):
    """The REGIDs of the 002 manual (and POS_IST from the NDrive list)."""

    SPEED_IST = 0x30
    SPEED_CMD = 0x31
    ACC_RAMP = 0x35
    READ = 0x3D
    KERN_STATUS = 0x40
    MODE = 0x51
    EVENT_MASK = 0x52
    CAN_ID_RX = 0x68
    POS_IST = 0x6D
    POS_DEST = 0x6E
    EEPROM_WRITE = 0x84
    TORQUE_CMD = 0x90
    REG_A8 = 0xA8
    ERR_WARN = 0x8F     # NDrive list, not in 002 (ndrive.toml)
    I_ACT = 0x20        # NDrive list: actual current (num)
    I_MAX = 0x24        # NDrive list: the motor's peak current limit (num)
    I_CMD = 0x26        # NDrive list: current command, +/- 9 bit (§6.1)
    DEVICE_I_MAX = 0xC4  # NDrive list: the device's peak current (num, §6.1 table)
    AIN1 = 0xD5         # NDrive list: analog command input 1 (10 V = 29490 num, §6.1)
    AIN2 = 0xD6         # NDrive list: analog command input 2


class Status(enum.IntFlag):
    """KERN_STATUS (0x40).  ICNS has no documented bit: bit 5 is this project's reading."""

    ENA = 1 << 0
    LIM_PLUS = 1 << 2
    LIM_MINUS = 1 << 3
    ICNS = 1 << 5
    POSITION_CONTROL = 1 << 7
    SPEED_CONTROL = 1 << 8
    CAL = 1 << 12
    TOL = 1 << 13


#: NDrive's error bits of ERR_WARN (0x8F, bits 0-15; the NDrive register list and the
#: BAMOCAR manuals' "error signals" table, not manual 002): each switches the power
#: stage off.  bit -> (NDrive name, what it means).  Bits 12 and 13 are not used.
ERRORS = {
    0: ("BADPARAS", "parameters damaged"),
    1: ("POWERFAULT", "hardware error of the power stage"),
    2: ("RFE", "safety circuit (RFE input) faulty"),
    3: ("BUS_TIMEOUT", "CAN time-out (the T-Out time was exceeded)"),
    4: ("FEEDBACK", "bad or wrong encoder / resolver signal"),
    5: ("POWERVOLTAGE", "power voltage missing"),
    6: ("MOTORTEMP", "motor temperature too high"),
    7: ("DEVICETEMP", "device temperature too high"),
    8: ("OVERVOLTAGE", "overvoltage (above 1.8 x UN)"),
    9: ("I_PEAK", "overcurrent or strongly oscillating current"),
    10: ("RACEAWAY", "race-away (speed without a set-point, or the wrong direction)"),
    11: ("USER", "user-selected error"),
    14: ("HW_ERR", "current measurement error"),
    15: ("BALLAST", "ballast circuit overloaded"),
}


def error_text(err_warn: int) -> str:
    """The error bits of an ERR_WARN value in NDrive's words (``"error 8 OVERVOLTAGE:
    overvoltage (above 1.8 x UN)"``; several joined by ``; ``), "" when none is set."""
    parts = []
    for bit in range(16):
        if err_warn >> bit & 1:
            name, meaning = ERRORS.get(bit, (f"ERR{bit}", "not used by NDrive"))
            parts.append(f"error {bit} {name}: {meaning}")
    return "; ".join(parts)


class ModeBit(enum.IntFlag):
    """MODE (0x51)."""

    DISABLE = 1 << 2
    EVENTS = 1 << 4


_QUANTITIES = {"raw": _core.unitek.Quantity.RAW, "speed": _core.unitek.Quantity.SPEED,
               "position": _core.unitek.Quantity.POSITION, "current": _core.unitek.Quantity.CURRENT,
               "torque": _core.unitek.Quantity.TORQUE, "time": _core.unitek.Quantity.TIME}
_ACCESS = {"rw": _core.unitek.Access.RW, "ro": _core.unitek.Access.RO, "wo": _core.unitek.Access.WO}
_ROW_KEYS = {"regid", "name", "bits", "signed", "access", "quantity", "unit", "scale", "min", "max", "description"}


def builtin_registers() -> Any:
    """The documented REGIDs as a register table (a copy you may extend)."""
    return _core.unitek.RegisterTable()


def _rows_from_toml(data: dict, where: str) -> list:
    rows = data.get("register", [])
    if not isinstance(rows, list):
        raise _core.InvalidArgument(f"{where}: [[register]] must be an array of tables")
    out = []
    for i, row in enumerate(rows):
        label = f"{where}: register #{i + 1}"
        if not isinstance(row, dict):
            raise _core.InvalidArgument(f"{label}: not a table")
        unknown = set(row) - _ROW_KEYS
        if unknown:
            raise _core.InvalidArgument(f"{label}: unknown keys {sorted(unknown)} (known: {sorted(_ROW_KEYS)})")
        for key in ("regid", "name"):
            if key not in row:
                raise _core.InvalidArgument(f"{label}: '{key}' is required")
        regid, name = row["regid"], row["name"]
        if isinstance(regid, bool) or not isinstance(regid, int):
            raise _core.InvalidArgument(f"{label}: regid must be an integer, not {regid!r}")
        if not isinstance(name, str):
            raise _core.InvalidArgument(f"{label}: name must be a string")
        quantity = str(row.get("quantity", "raw")).lower()
        access = str(row.get("access", "rw")).lower()
        if quantity not in _QUANTITIES:
            raise _core.InvalidArgument(f"{label} ({name}): quantity {quantity!r} not one of {sorted(_QUANTITIES)}")
        if access not in _ACCESS:
            raise _core.InvalidArgument(f"{label} ({name}): access {access!r} not one of {sorted(_ACCESS)}")
        try:
            out.append(_core.unitek.Register(
                regid, name, bits=int(row.get("bits", 16)), signed=bool(row.get("signed", False)),
                access=_ACCESS[access], quantity=_QUANTITIES[quantity], unit=str(row.get("unit", "")),
                scale=float(row.get("scale", 1.0)), min=row.get("min"), max=row.get("max"),
                description=str(row.get("description", ""))))
        except _core.InvalidArgument as e:
            raise _core.InvalidArgument(f"{label} ({name}): {e}") from None
        except (TypeError, ValueError) as e:
            raise _core.InvalidArgument(f"{label} ({name}): {e}") from None
    return out


def load_registers(path: Union[str, Path], table: Any = None) -> Any:
    """Adds the rows of a TOML register list to ``table`` (default: a copy of the
    built-in table) and returns it.  Bad rows raise InvalidArgument naming the row."""
    import tomllib

    p = Path(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as e:
        raise _core.InvalidArgument(f"unitek registers {p}: {e.strerror or e}") from None
    except tomllib.TOMLDecodeError as e:
        raise _core.InvalidArgument(f"unitek registers {p}: not TOML ({e})") from None
    t = table if table is not None else builtin_registers()
    for row in _rows_from_toml(data, str(p)):
        t.add(row)
    return t


def ndrive_registers() -> Any:
    """The built-in table plus the NDrive rows motorbus ships (POS_IST)."""
    # cpp/motorbus/drives/unitek/ndrive.toml, installed beside _core (motorbus.drives.data_file)
    return load_registers(data_file("unitek", "ndrive.toml"))


def _regid(reg: Union[int, str, Reg], table: Any) -> int:
    if isinstance(reg, str):
        return int(table[reg].regid)
    if isinstance(reg, bool) or not isinstance(reg, int):
        raise _core.InvalidArgument(f"unitek register: a REGID or a name, not {reg!r}")
    return int(reg)


def check_address(address: Union[str, int]) -> str:
    """The drive's receive id, 0x201..0x27F: an int, or hex text as the manual writes
    ids ("201", "0x201"); canonical form ``0x201``."""
    if isinstance(address, bool):
        raise _core.InvalidArgument(f"unitek address: a receive id 0x201..0x27F, not {address!r}")
    if isinstance(address, int):
        value = address
    else:
        text = str(address).strip().lower()
        digits = text[2:] if text.startswith("0x") else text
        try:
            value = int(digits, 16)
        except ValueError:
            raise _core.InvalidArgument(f"unitek address: a receive id 0x201..0x27F, not {address!r}") from None
    if not 0x201 <= value <= 0x27F:
        raise _core.InvalidArgument(f"unitek address: receive id 0x{value:X} is outside 0x201..0x27F")
    return f"0x{value:03X}"


def _tx_for(rx_id: int) -> int:
    return rx_id - 0x80


# ---- streams ----------------------------------------------------------------------------

class Stream:
    """A cyclic register: ``read()`` -> (timestamps ns, values num) as numpy int64 arrays;
    ``physical()`` the same values converted by the register's scaling."""

    def __init__(self, core: Any, register: Any, scalings: Any) -> None:
        self._core = core
        self.register = register
        self._scalings = scalings

    regid = property(lambda self: self._core.regid)
    interval_ms = property(lambda self: self._core.interval_ms)
    active = property(lambda self: self._core.active)
    count = property(lambda self: self._core.count)
    lost = property(lambda self: self._core.lost)
    capacity = property(lambda self: self._core.capacity)

    def read(self, max: int = -1) -> tuple:  # noqa: A002 - mirrors the core
        return self._core.read(max)

    def physical(self, values: Any) -> Any:
        """num -> the register's unit (rpm, rev, %, A, ms), vectorised."""
        import numpy as np

        one = self._scalings.to_physical(self.register, 1)
        return np.asarray(values, dtype=float) * one

    def __repr__(self) -> str:
        return f"<unitek Stream 0x{self.regid:02X} every {self.interval_ms} ms, {self.count} samples>"


# ---- the native client ------------------------------------------------------------------

class Unitek(_stop_at_exit.StopsMotor, _core.unitek.Client):
    """The register protocol of one drive (see the module doc): the C++
    ``unitek::Client`` with registers by name or :class:`Reg`, values in physical
    units, :class:`Status`/:class:`ModeBit` types and numpy streams.

    ``on_error`` / ``on_exit``: "stop" and "quick_stop" (speed command 0: the drive
    decelerates on its ramp; the protocol has no faster stop of its own), "disable"
    (MODE bit 2) or None; applied when an exception leaves ``with`` and at
    interpreter exit, as every native client does."""

    def __init__(self, bus: Any, rx_id: int = 0x201, tx_id: Optional[int] = None, *, timeout: float = 0.2,
                 registers: Any = None, n_max_rpm: float = 3000.0, device: str = "DS 205/405",
                 clock: Any = None, on_error: Optional[str] = "stop", on_exit: Optional[str] = "stop") -> None:
        check_stop_way(on_error, "on_error")
        check_stop_way(on_exit, "on_exit")
        currents = {d["device"]: d for d in _core.unitek.device_currents()}
        if device not in currents:
            raise _core.InvalidArgument(f"unitek device: one of {sorted(currents)}, not {device!r}")
        d = currents[device]
        self.scalings = _core.unitek.Scalings(n_max_rpm=n_max_rpm, i_max_num=d["i_max_num"], i_max_a=d["i_max_a"])
        if registers is None:
            table = ndrive_registers()
        elif isinstance(registers, (str, Path)):
            table = load_registers(registers, ndrive_registers())
        else:
            table = registers
        rx = int(check_address(rx_id), 16)
        super().__init__(bus, rx_id=rx, tx_id=_tx_for(rx) if tx_id is None else tx_id,
                         timeout=timeout, table=table, clock=clock)
        #: the CAN bus the drive is on (the Poller groups axes by it)
        self.bus = bus
        self.on_error = on_error
        self.on_exit = on_exit
        self._streams: dict[int, Stream] = {}
        self._lock = threading.Lock()
        self._open = True
        _stop_at_exit.track(self)

    # ---- registers (table, add_register, write_raw: the C++ client's) ----
    def register(self, reg: Union[int, str]) -> Any:
        return self.table[_regid(reg, self.table)]

    def write(self, reg: Union[int, str], value: int) -> None:
        """Writes ``value`` (num).  Never acknowledged by the drive (read back where it matters)."""
        super().write(_regid(reg, self.table), value)

    def read(self, reg: Union[int, str], timeout: Optional[float] = None) -> int:
        """Reads once (``3D REGID 00``); TimeoutError when the drive does not answer."""
        return super().read(_regid(reg, self.table), timeout)

    def write_physical(self, reg: Union[int, str], value: float) -> None:
        """Writes ``value`` in the register's unit (rpm, rev, %, A, ms)."""
        r = self.register(reg)
        self.write(r.regid, self.scalings.to_num(r, value))

    def read_physical(self, reg: Union[int, str], timeout: Optional[float] = None) -> float:
        r = self.register(reg)
        return self.scalings.to_physical(r, self.read(r.regid, timeout))

    # ---- cyclic (cyclic: the C++ client's) ----
    def subscribe(self, reg: Union[int, str], interval_ms: int, capacity: int = 65536,
                  callback: Optional[Callable[[int, int, int], None]] = None) -> Stream:
        """Every ``interval_ms`` (1..254) into a numpy ring; ``callback(regid, t_ns, value)`` too if given
        (it runs on the bus thread and takes the GIL: keep it short, or use the ring alone).
        The 9th register raises UnitekCyclicLimit."""
        regid = _regid(reg, self.table)
        core = super().subscribe(regid, interval_ms, capacity, callback)
        with self._lock:
            s = self._streams.get(regid)
            if s is None:
                s = self._streams[regid] = Stream(core, self.table[regid], self.scalings)
            return s

    def unsubscribe(self, reg: Union[int, str]) -> None:
        regid = _regid(reg, self.table)
        super().unsubscribe(regid)
        with self._lock:
            self._streams.pop(regid, None)

    # ---- MODE / events (enable, disable, set_events: the C++ client's) ----
    def on_status(self, callback: Optional[Callable[[Status, int], None]]) -> None:
        if callback is None:
            super().on_status(None)
        else:
            super().on_status(lambda st, t: callback(Status(st), t))

    @property
    def last_event_status(self) -> Optional[Status]:
        st = _core.unitek.Client.last_event_status.fget(self)
        return None if st is None else Status(st)

    @property
    def mode(self) -> ModeBit:
        return ModeBit(_core.unitek.Client.mode.fget(self))

    def set_receive_id(self, rx_id: int) -> None:
        """0x68: the drive listens on ``rx_id`` at once (persistent after store_eeprom)."""
        super().set_receive_id(int(check_address(rx_id), 16))

    # ---- typed shortcuts ----
    @property
    def status(self) -> Status:
        return Status(self.read(Reg.KERN_STATUS))

    @property
    def speed_rpm(self) -> float:
        return self.read_physical(Reg.SPEED_IST)

    @speed_rpm.setter
    def speed_rpm(self, rpm: float) -> None:
        self.write_physical(Reg.SPEED_CMD, rpm)

    @property
    def position_rev(self) -> float:
        return self.read_physical(Reg.POS_IST)

    def move_to_rev(self, rev: float) -> None:
        self.write_physical(Reg.POS_DEST, rev)

    def torque_percent(self, percent: float) -> None:
        self.write_physical(Reg.TORQUE_CMD, percent)

    def stop(self) -> None:
        """Speed command 0: the drive decelerates on its ramp."""
        self.write(Reg.SPEED_CMD, 0)

    def close(self) -> None:
        """Stops every cyclic transmission this client started and lets go of the bus."""
        self._open = False
        _stop_at_exit.untrack(self)
        super().close()

    def _stop_on_error(self) -> None:
        self._halt(self.on_error)

    def _stop_at_exit(self) -> None:
        self._halt(self.on_exit)

    def _halt(self, how: Optional[str]) -> None:
        if getattr(self, "_open", False):
            _stop_at_exit.halt(how, self.stop, self.stop, self.disable)


# ---- the simulator ------------------------------------------------------------------------

_SIM_OPTIONS = ("n_max_rpm", "acc_ramp_ms", "dec_ramp_ms", "position_control", "speed_control", "calibrated",
                "tol_num", "minus_limit_num", "plus_limit_num", "torque_continuous_num", "dummy", "tx_id",
                "registers", "t_out_ms", "store_path", "device", "motor_i_max_num", "btr",
                "analog_command")


class UnitekSim:
    """A simulated UNITEK servo (C++ ``UnitekSim``; see cpp/motorbus/drives/unitek/sim.hpp).

    Inputs for tests: ``set_hardware_enable``, ``force_limit(±1, True/False/None)``,
    ``set_calibrated``, ``force_icns``, ``power_cycle``.  ``store_path``: a JSON file the
    EEPROM store (0x84) writes and the next sim reads at start (``sim serve --store-dir``).
    On a SimClock call
    ``service()`` after advancing the clock.  ``t_out_ms`` models NDrive's T-Out:
    with no frame on the receive id for that long while enabled, the drive
    disables itself (0 = off, the default: 002 does not say what T-Out does).

    ``device`` (§6.1 row: "DS 205/405", "DS 412", "DS 420") and ``motor_i_max_num``
    (the motor's peak current limit in num, default the device's; I_MAX 0x24 over CAN):
    I_ACT (0x20) is I_CMD (0x26, +/- 511) limited to the smaller of the two.  ``btr``
    (§3.1 table, default 0x4025 = 500 kbit/s): on a bus modelling another bit rate
    the node hears and sends nothing (``counters.bit_rate_mismatch``).  ``set_analog_input(1|2,
    volts)``: AIN1/AIN2 read 2949 num/V (0xD5/0xD6); with ``analog_command`` = 1 or 2 (the
    speed command's source in NDrive; 0 = the bus) that input is the speed command, 10 V =
    29490 num = 90 % of N max (§6.1)."""

    def __init__(self, rx_id: int = 0x201, clock: Any = None, *, registers: Any = None, t_out_ms: float = 0,
                 store_path: Optional[str] = None, **options: Any) -> None:
        self.clock = clock if clock is not None else _core.runtime.RealClock()
        table = _core.unitek.sim_default_table()
        if registers is not None:
            table = load_registers(registers, table)
        options.setdefault("tx_id", _tx_for(rx_id))
        self._core = _core.unitek.Sim(self.clock, rx_id=rx_id, table=table, **options)
        self.rx = rx_id
        self._t_out = float(t_out_ms)
        if self._t_out < 0:
            raise _core.InvalidArgument("unitek sim t_out_ms: >= 0")
        self._watch: Optional[threading.Thread] = None
        self._closing = threading.Event()
        self.store_path = store_path
        if store_path:
            self._load_store(Path(store_path))
            self._core.on_eeprom_store(self._save_store)

    def _load_store(self, path: Path) -> None:
        """The EEPROM of the last run (a JSON of REGID -> value), as a power cycle reads it."""
        import json

        if not path.exists():
            return
        try:
            values = {int(k, 0): int(v) for k, v in json.loads(path.read_text()).items()}
        except (ValueError, AttributeError, TypeError) as e:
            raise _core.InvalidArgument(f"unitek sim store {path}: not an EEPROM file ({e})") from None
        self._core.load_eeprom(values)

    def _save_store(self, values: dict) -> None:
        import json
        import os

        path = Path(self.store_path)
        tmp = path.with_suffix(path.suffix + ".tmp")
        tmp.write_text(json.dumps({f"0x{k:02X}": v for k, v in sorted(values.items())}, indent=1))
        os.replace(tmp, path)

    def attach(self, bus: Any) -> "UnitekSim":
        self._core.attach(bus)
        if self._t_out > 0:
            self._watch = threading.Thread(target=self._t_out_loop, name="unitek-sim-t-out", daemon=True)
            self._watch.start()
        return self

    def _t_out_loop(self) -> None:
        last = self._core.counters.frames_in
        last_t = self.clock.now()
        while not self._closing.wait(0.005):
            n = self._core.counters.frames_in
            now = self.clock.now()
            if n != last:
                last, last_t = n, now
            elif now - last_t > self._t_out * 1e6 and self._core.status & Status.ENA:
                self._core.set_hardware_enable(False)  # the monitor trips: power stage off
                self.t_out_tripped = True

    t_out_tripped = False

    def close(self) -> None:
        self._closing.set()
        self._core.close()
        if self._watch is not None:
            self._watch.join(timeout=1)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._core, name)

    @property
    def status_flags(self) -> Status:
        return Status(self._core.status)


def make_sim(address: Union[str, int] = "0x201", clock: Any = None, *, bus: Any = None, **options: Any) -> UnitekSim:
    """A simulated UNITEK servo on receive id ``address`` (transmit id = address - 0x80 unless
    ``tx_id``); attached to ``bus`` when given.  Options: see :class:`UnitekSim`."""
    unknown = set(options) - set(_SIM_OPTIONS)
    if unknown:
        raise _core.InvalidArgument(f"unitek sim options: unknown {sorted(unknown)}; known {sorted(_SIM_OPTIONS)}")
    sim = UnitekSim(int(check_address(address), 16), clock, **options)
    if bus is not None:
        sim.attach(bus)
    return sim


# ---- the Drive adapter ---------------------------------------------------------------------

class UnitekParams(Params):
    """The register table by name (num values).  Iteration lists the readable registers
    (so ``dict(drive.params)`` works); write-only ones (MODE, CAN_ID_RX, EEPROM_WRITE) can
    still be written by name."""

    def _names(self) -> list[str]:
        return [r.name for r in self._drive.native.table.rows() if r.readable]

    def _info(self, name: str) -> Optional[ParamInfo]:
        table = self._drive.native.table
        if name not in table:
            return None
        r = table[name]
        return ParamInfo(name=r.name, type="int", minimum=r.min, maximum=r.max, unit="num", persists=False,
                         writable=r.writable, description=f"0x{r.regid:02X} {r.description}")

    async def _read(self, info: ParamInfo) -> Any:
        return await self._drive.io.read(info.name)

    async def _write(self, info: ParamInfo, value: Any) -> None:
        await self._drive.io.write(info.name, int(value))


class UnitekDrive(Drive):
    """The Drive API over a UNITEK servo.  Native units: position num (65536 per
    revolution), velocity num/s of position (a speed command is num of N max).

    * move_to / move_by: POS_DEST (position control), read back until the drive shows
      the new target (writes are never acknowledged: a move is judged only once the
      drive has taken it).  The positioning speed is an NDrive parameter (no REGID in
      002): ``velocity=`` is refused.
    * at rest (``wait_idle``): SPEED_IST 0 and either Tol with POS_IST within the
      in-position window of the target, or a stop the drive shows (the limit switch
      on the side of travel, Ena gone), or the position still over a poll.
    * how a move ended (``_stop_reason``): ERR_WARN (0x8F, NDrive) error bits →
      MoveFaulted (code = the error bits), Ena lost although enabled → MoveFaulted,
      Lim+/Lim− on the side of travel → LimitReached; otherwise a move short of its
      target was stopped by a speed command 0 (this program's stop() or another
      program's): MoveInterrupted.
    * in-position window: ``tol_num`` (default 64 num), the drive's Tol window; NDrive
      sets it on the drive, 002 has no REGID for it: give the drive's value.
    * jog: SPEED_CMD from num/s via N max; stop / quick_stop: SPEED_CMD 0 (the
      drive's ramp; the protocol has no faster stop but disable).
    * torque: ``drive.torque(percent)`` (TORQUE_CMD).
    * home: no homing REGID in 002: ``home()`` requires the calibrated bit (Cal,
      the drive knows its absolute position) and positions to 0.
    * fault: an error bit in ERR_WARN, or the adapter asked for enable but KERN_STATUS
      has no Ena (hardware enable missing); ``clear_faults`` writes MODE again.
    """

    kind = "unitek"
    capabilities = frozenset({Capability.POSITION, Capability.VELOCITY, Capability.HOMING, Capability.TORQUE,
                              Capability.STORE, Capability.ENCODER})
    has_watchdog = False

    # the plugin (motorbus.registry): what the kind is
    description = "UNITEK BAMOCAR/BAMOBIL/DS servo on its CAN register protocol (REGID, not CANopen)"
    transport = "can"
    default_address = "0x201"
    sim_options = _SIM_OPTIONS
    store_file = "unitek-{address}.eeprom.json"
    probe_addresses = tuple(f"0x{i:03X}" for i in range(0x201, 0x280))   # the receive-id range
    #: Seconds a move may show no motion before a still motor counts as at rest (a
    #: stop that came before the motor got going); a drive showing why it stopped, or
    #: Tol at the target, is at rest at once.
    start_grace: float = 0.1

    def __init__(self, native: Unitek, *, units: Optional[Units] = None, on_error: Optional[str] = "stop",
                 on_exit: Optional[str] = "stop", close_native: Any = None, tol_num: float = 64) -> None:
        super().__init__(native, units=units, on_error=on_error, on_exit=on_exit, close_native=close_native)
        if isinstance(tol_num, bool) or not isinstance(tol_num, (int, float)) or not 0 <= tol_num < 2 ** 31:
            raise _core.InvalidArgument(f"unitek tol_num: the drive's Tol window in num (>= 0), not {tol_num!r}")
        self._tol_num = float(tol_num)
        self._want_enabled = False
        self._no_err_warn = False
        self._activity: Optional[str] = None
        self._target: Optional[int] = None     # POS_DEST of the move in progress
        self._direction = 0                    # +1 / -1: the side a limit switch stops it on
        self._seen_motion = False
        self._started = 0.0
        n_max = native.scalings.n_max_rpm
        self._counts_per_s_per_num = n_max / 60.0 * COUNTS_PER_REV / FULL_SCALE

    # ---- helpers ----
    # The hooks below are coroutines over self.io (motorbus.faces): written once, they
    # serve the blocking verbs (drive.move_to) and motorbus.aio (await axis.move_to) alike.
    def _io_link(self) -> Any:
        # One worker per node: the client itself.  Its reads are matched to their replies
        # by REGID on the node's own transmit id (the C++ client waits under its own lock),
        # so the nodes of one bus need not queue behind each other as one serial line's
        # drives must; a node's exchanges stay in order on its worker.
        return self.native

    async def _st(self) -> Status:
        return await self.io.attr("status")      # KERN_STATUS as a Status

    async def _require_enabled(self, what: str) -> None:
        st = await self._st()
        if not st & Status.ENA:
            why = "fault: Ena is 0 although enabled" if self._want_enabled else "disabled"
            errors = error_text(await self._errors() or 0)
            raise _core.DriveFault(f"unitek: {what} refused, drive {why} (KERN_STATUS 0x{int(st):04X}"
                                   f"{'; ' + errors if errors else ''}; "
                                   f"{'clear_faults()/hardware enable' if self._want_enabled else 'enable() first'})")

    async def _errors(self) -> Optional[int]:
        """ERR_WARN (0x8F), None when the drive does not answer it (a firmware without it:
        asked once, then no more, so a move's judgement does not wait a timeout each time)."""
        if self._no_err_warn:
            return None
        try:
            return int(await self.io.read(Reg.ERR_WARN))
        except (_core.TimeoutError, UnknownRegister):   # no reply, or a table without 0x8F
            self._no_err_warn = True
            return None

    def _begin(self, activity: str, target: Optional[int], direction: int) -> None:
        self._activity, self._target, self._direction = activity, target, direction
        self._seen_motion = False
        self._started = time.monotonic()

    # ---- Drive ----
    async def _enable(self) -> None:
        await self.io.enable()
        self._want_enabled = True

    async def _disable(self) -> None:
        await self.io.disable()
        self._want_enabled = False
        self._activity = None

    async def _move_to(self, target: float, velocity: Optional[float]) -> None:
        if velocity is not None:
            raise _core.InvalidArgument("unitek: velocity= is not supported: the positioning speed is an NDrive "
                                        "parameter (002 has no REGID for it)")
        await self._require_enabled("move")
        num = int(round(target))
        if not -2147483647 <= num <= 2147483647:
            raise _core.InvalidArgument(f"unitek: position {num} is outside ±2147483647 num (POS_DEST)")
        start = await self._position()
        await self._put_pos_dest(num)
        self._begin("position", num, (num > start) - (num < start))

    async def _put_pos_dest(self, num: int) -> None:
        # Writes are never acknowledged, and a reply can be a cyclic frame the drive
        # sent before it took the write: POS_DEST is read back until it shows the new
        # target, so nothing read afterwards judges the move by the drive's state
        # before it (issue 28: 5 of 2 860 moves returned at the previous target).
        for _ in range(2):
            await self.io.write(Reg.POS_DEST, num)
            for _ in range(4):
                if await self.io.read(Reg.POS_DEST) == num:
                    return
        raise _core.DriveFault(f"unitek move: POS_DEST does not read back {num} after two writes")

    async def _jog(self, velocity: float) -> None:
        await self._require_enabled("jog")
        num = int(round(velocity / self._counts_per_s_per_num))
        if abs(num) > FULL_SCALE:
            raise _core.InvalidArgument(f"unitek: jog velocity {velocity:g} num/s is above N max "
                                        f"({FULL_SCALE * self._counts_per_s_per_num:g} num/s)")
        await self.io.write(Reg.SPEED_CMD, num)
        self._begin("speed", None, (num > 0) - (num < 0))

    def torque(self, percent: float) -> None:
        """Torque command in % of the drive's maximum (TORQUE_CMD, ±32767 = ±100 %)."""
        faces.run(self._co_torque(percent))

    async def _co_torque(self, percent: float) -> None:
        """``torque`` as a coroutine (``await axis.sync._co_torque(p)`` from asyncio)."""
        self._check_open()
        await self._require_enabled("torque")
        await self.io.torque_percent(self._number("torque", percent))
        self._begin("torque", None, (percent > 0) - (percent < 0))

    async def _stop(self) -> None:
        # Writes are never acknowledged: a stop is read back, so it has reached the drive
        # before the call returns (a stop sent just before the link closes could
        # otherwise be lost with it — seen when a bench closed under ASan).  Urgent: in
        # the awaitable face it overtakes the node's queued exchanges (a task's polls).
        io = self.io.urgent
        for _ in range(2):
            await io.write(Reg.SPEED_CMD, 0)
            if await io.read(Reg.SPEED_CMD) == 0:
                break
        else:
            raise _core.DriveFault("unitek stop: SPEED_CMD does not read back 0 after two writes")
        self._activity = "speed"

    async def _quick_stop(self) -> None:
        await self._stop()      # the protocol has no faster stop than speed command 0 (but disable)

    # Speed and ramps (the EPICS record's VELO/ACCL): the positioning speed is an NDrive
    # setting (velocity= is refused); ACC_RAMP is the ramp in ms to the drive's maximum speed,
    # so the time to reach ``speed`` scales by top/speed where both are known.
    per_move_velocity = False

    async def _set_accel_time(self, seconds: float, speed: float, top: Optional[float]) -> bool:
        ms = seconds * 1000.0 * (top / speed if top and speed else 1.0)
        await self._set_params_clamped({"ACC_RAMP": max(1.0, ms)})
        return True

    async def _home(self, method: Any) -> None:
        if method not in (None, "calibrated"):
            raise _core.InvalidArgument(f"unitek home: method None or 'calibrated', not {method!r}")
        st = await self._st()
        if not st & Status.CAL:
            raise _core.DriveFault("unitek home: the drive is not calibrated (KERN_STATUS bit 12 Cal = 0); "
                                   "calibrate it with NDrive")
        await self._move_to(0, None)

    async def _homing_done(self) -> bool:
        if not await self._is_idle():
            return False
        # Homing is a move to 0: short of it, it failed the way a move does.
        position = await self._position()
        if self._target is not None and abs(position - self._target) > self._in_position_window():
            reason = await self._stop_reason(await self._status())
            if reason is None:
                by = self._move.stopped_by if self._move is not None else None
                reason = StopReason(MoveInterrupted, stopped_by_text(by) if by else
                                    "a stop before the position 0 (a speed command 0 from another program)")
            raise reason.error(f"{self.name}: homing (a move to 0) stopped at {position:g} num by {reason.text}",
                               axis=self.name, position=self._units.to_user(position), reason=reason.text,
                               code=reason.code, units=self._units.name,
                               **({"side": reason.side} if issubclass(reason.error, LimitReached) else {}))
        return True

    async def _clear_faults(self) -> None:
        if self._want_enabled:
            await self.io.enable()

    async def _store(self) -> None:
        await self.io.store_eeprom(0)

    async def _position(self) -> float:
        return float(await self.io.read(Reg.POS_IST))

    async def _velocity(self) -> float:
        return await self.io.read(Reg.SPEED_IST) * self._counts_per_s_per_num

    def _shows_stop(self, st: Status) -> bool:
        """The drive shows why it would be at rest: Ena gone while enabled, or the limit
        switch on the side of travel (a switch behind the motion stops nothing)."""
        if self._want_enabled and not st & Status.ENA:
            return True
        return bool((self._direction > 0 and st & Status.LIM_PLUS) or (self._direction < 0 and st & Status.LIM_MINUS))

    async def _is_idle(self) -> bool:
        # At rest whatever the reason (target, limit, fault, stop); never raises for a
        # fault: the outcome is judged afterwards (_stop_reason).
        st = await self._st()
        if await self.io.read(Reg.SPEED_IST) != 0:
            self._seen_motion = True
            return False
        position = await self._position()
        if (self._activity == "position" and st & Status.TOL and self._target is not None
                and abs(position - self._target) <= self._in_position_window()):
            return True
        if self._shows_stop(st):
            return True
        if not self._seen_motion and time.monotonic() - self._started < self.start_grace:
            return False        # not started yet, or a reply older than the command
        await faces.sleep(self.poll_interval)     # the thread in the blocking face, the task in motorbus.aio
        if await self.io.read(Reg.SPEED_IST) != 0:
            self._seen_motion = True
            return False
        return abs(await self._position() - position) <= max(self._tol_num, 1.0)

    async def _stop_reason(self, status: DriveStatus) -> Optional[StopReason]:
        st = Status(status.raw)
        errors = await self._errors()
        if errors and errors & 0xFFFF:
            return StopReason(MoveFaulted, f"{error_text(errors)} (ERR_WARN 0x8F = 0x{errors:08X})",
                              code=errors & 0xFFFF)
        if self._want_enabled and not st & Status.ENA:
            return StopReason(MoveFaulted, "the loss of Ena (KERN_STATUS bit 0) although enabled: the hardware "
                                           "enable (RUN) input is off or the drive switched itself off")
        limits = [(1, Status.LIM_PLUS, "the +limit switch (KERN_STATUS bit 2 Lim+)"),
                  (-1, Status.LIM_MINUS, "the -limit switch (KERN_STATUS bit 3 Lim-)")]
        for side, bit, text in limits:
            if st & bit and self._direction in (0, side):
                return StopReason(LimitReached, text, side=side)
        return None

    def _in_position_window(self) -> float:
        return self._tol_num        # the drive's Tol window as given to open(): no exchange

    async def _status(self) -> DriveStatus:
        st = await self._st()
        speed = await self.io.read(Reg.SPEED_IST)
        at_target = bool(st & Status.TOL)
        fault = self._want_enabled and not st & Status.ENA
        moving = speed != 0
        names = [f.name for f in Status if f & st] or ["none"]
        text = f"KERN_STATUS 0x{int(st):04X} ({' '.join(names)})"
        if fault:
            text += ", fault: no Ena although enabled (hardware enable or a drive error)"
        return DriveStatus(enabled=bool(st & Status.ENA), moving=moving, homed=bool(st & Status.CAL), fault=fault,
                           at_target=at_target, limit_positive=bool(st & Status.LIM_PLUS),
                           limit_negative=bool(st & Status.LIM_MINUS), raw=int(st), text=text)

    def _make_params(self) -> Params:
        return UnitekParams(self)

    def _close(self) -> None:
        self.native.close()

    # ---- the plugin's hooks (motorbus.registry) ------------------------------------------
    @classmethod
    def open(cls, *, line: Any = None, bus: Any = None, address: Union[str, int] = "0x201",
             units: Optional[Units] = None, timeout: float = 0.2, on_error: Optional[str] = "stop",
             on_exit: Optional[str] = "stop", tx_id: Optional[int] = None, registers: Any = None,
             n_max_rpm: float = 3000.0, device: str = "DS 205/405", tol_num: float = 64) -> "UnitekDrive":
        """``open_drive("unitek", bus=..., address="0x201")``; ``tol_num``: the drive's Tol window
        (num), the in-position window a move is judged by."""
        return cls._open_on(line, bus, lambda b: Unitek(b, int(check_address(address), 16), tx_id, timeout=timeout,
                                                        registers=registers, n_max_rpm=n_max_rpm, device=device,
                                                        on_error=None, on_exit=None),
                            units=units, on_error=on_error, on_exit=on_exit, tol_num=tol_num)

    make_sim = staticmethod(make_sim)
    check_address = staticmethod(check_address)

    @classmethod
    def probe(cls, bus: Any, address: str) -> Optional[dict]:
        """Discovery: reads KERN_STATUS once from the drive on receive id `address` (the
        documented registers name no model or firmware).  Reads only; starts no stream."""
        client = Unitek(bus, int(check_address(address), 16), timeout=0.05, on_error=None, on_exit=None)
        try:
            return {"kern_status": f"0x{client.read(Reg.KERN_STATUS):04X}"}
        finally:
            client.close()

    @classmethod
    def sim_faults(cls) -> dict:
        return dict(SIM_FAULTS)

    def poll_fields(self, fields: Sequence[str]) -> PollSpec:
        """motorbus.Poller, asking: POS_IST/SPEED_IST/KERN_STATUS read (3D REGID 00) each sample."""
        regids, scales = _poll_rows(self, fields)
        source = _core.unitek.poll_source(self.native, regids)
        return PollSpec(source=source, scales=scales, transport=self.native.bus, bus=self.native.bus)

    def capture_fields(self, fields: Sequence[str], period: float) -> PollSpec:
        """motorbus.Poller, capturing: the drive transmits each register cyclically
        (``3D REGID t``, t = the poll period in whole ms, 1..254) and each sample takes
        the latest value.  A register the user already streams keeps its interval; the
        transmissions started here stop when the Poller stops.  At most 8 registers
        transmit cyclically per drive (CyclicLimit beyond)."""
        regids, scales = _poll_rows(self, fields)
        interval_ms = min(254, max(1, int(round(period * 1000))))
        source = _core.unitek.capture_source(self.native, regids, interval_ms)
        return PollSpec(source=source, scales=scales, transport=self.native.bus, bus=self.native.bus,
                        stamped=True, close=source.close)


# ---- motorbus.Poller ---------------------------------------------------------------
#: The registers of the Drive's readings: (REGID, factor from the register's number to
#: the Drive's native units — velocity: SPEED_IST's number to counts/s, set per drive).
_POLL_REGISTERS = {"position": Reg.POS_IST, "velocity": Reg.SPEED_IST, "status": Reg.KERN_STATUS}


def _poll_rows(drive: UnitekDrive, fields: Sequence[str]) -> tuple[list[int], tuple]:
    regids, scales = [], []
    for f in fields:
        if f not in _POLL_REGISTERS:
            raise _core.InvalidArgument(f"unitek poll field {f!r}: this kind gives {', '.join(_POLL_REGISTERS)}")
        regids.append(int(_POLL_REGISTERS[f]))
        scales.append(drive._counts_per_s_per_num if f == "velocity" else 1.0)
    return regids, tuple(scales)


# Faults the simulator can be given (the pytest plugin's sim_faults fixture): the standard
# names ("limit", "fault") and this kind's own.  No "stall" (a servo: no stall detection on
# this protocol) and no "stop_input" (002 documents no stop input; the RUN input is
# "enable_off", a fault).
SIM_FAULTS = {
    # a limit switch closes (direction +1 / -1): a motion towards it stops
    "limit": lambda sim, direction=1: sim.force_limit(int(direction), True),
    # a drive error: ERR_WARN bits (default bit 8 OVERVOLTAGE) switch the power stage off
    "fault": lambda sim, bits=0x0100: sim.force_error(int(bits)),
    # a limit switch input goes active (direction -1 or +1)
    "trip_limit": lambda sim, direction=-1: sim.force_limit(int(direction), True),
    # the hardware enable (RUN) input drops: the power stage switches off
    "enable_off": lambda sim: sim.set_hardware_enable(False),
}

"""What each drive kind does with the motor record's VELO, ACCL and HOMF/HOMR
(``motorbus serve``'s CA face; the table in docs/epics.md says the same).

* ``speed``: the parameter holding the kind's position-move speed, and the factor from
  its number to native units per second: VELO's starting value (until a client sets
  VELO) and VMAX (its declared maximum), both in user units per second;
* ``velocity``: whether ``move_to(velocity=)`` is honoured (UNITEK: the positioning
  speed is an NDrive parameter, not settable per move);
* ``accel``: how ACCL (seconds from rest to VELO) is written into the kind's own
  ramp parameters before a move, when ACCL or VELO changed since the last move; the
  drive keeps the value afterwards (it is not put back);
* ``home``: the homing method of HOMF and of HOMR (None: the kind's default).

A kind not in the table (an out-of-tree plugin) moves at the drive's own speed until a
client sets VELO, ignores ACCL and homes with its default method for both buttons.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Optional

from ..drive import _value


async def _set_params(drive: Any, values: dict) -> None:
    """Writes what the drive has, each clamped into its declared range."""
    for name, value in values.items():
        if name not in drive.params:
            continue
        info = drive.params.describe(name)
        if info.minimum is not None:
            value = max(value, info.minimum)
        if info.maximum is not None:
            value = min(value, info.maximum)
        if info.type == "int":
            value = int(round(value))
        await drive.params.set(name, value)


def _ms(*names: str) -> Callable[[Any, float, float, float], dict]:
    """Ramp parameters in milliseconds to the move's speed."""
    return lambda drive, accl, velo_native, vmax_native: {n: max(1.0, accl * 1000.0) for n in names}


def _per_s2(*names: str) -> Callable[[Any, float, float, float], dict]:
    """Accelerations in native units per second squared: VELO / ACCL."""
    return lambda drive, accl, velo_native, vmax_native: {n: max(1.0, velo_native / accl) for n in names}


def _ms_to_max(*names: str) -> Callable[[Any, float, float, float], dict]:
    """Ramps in milliseconds to the drive's maximum speed: scaled so that VELO is reached
    in ACCL seconds (unknown maximum: ACCL itself)."""
    def values(drive: Any, accl: float, velo_native: float, vmax_native: float) -> dict:
        ms = accl * 1000.0 * (vmax_native / velo_native if vmax_native and velo_native else 1.0)
        return {n: max(1.0, ms) for n in names}
    return values


def _pmc007_gear(drive: Any, accl: float, velo_native: float, vmax_native: float) -> dict:
    """The PMC007 accelerates by gears (1 fastest .. 8): the gear nearest VELO / ACCL."""
    from ..drives.pmc007 import GEAR_ACCELERATION

    want = velo_native / accl if accl > 0 else math.inf
    gear = min(GEAR_ACCELERATION, key=lambda g: abs(math.log(GEAR_ACCELERATION[g] / max(want, 1e-9))))
    return {"0x6008": gear, "0x6009": gear}


@dataclass(frozen=True)
class KindMap:
    kind: str
    speed: Optional[tuple] = None           # (parameter, native units/s per its number)
    velocity: bool = True
    accel: Optional[Callable[[Any, float, float, float], dict]] = None
    home: tuple = (None, None)              # (HOMF method, HOMR method)

    async def speeds(self, drive: Any) -> tuple[Optional[float], Optional[float]]:
        """(the current move speed, its declared maximum), user units/s, where the kind says."""
        if self.speed is None:
            return (None, None)
        name, factor = self.speed
        scale = abs(drive.units.scale)
        try:
            if name not in drive.params:
                return (None, None)
            now = abs(float(await drive.params.get(name))) * factor * scale
            info = drive.params.describe(name)
            top = None if info.maximum is None else abs(float(info.maximum)) * factor * scale
            return (now or None, top)
        except Exception:  # noqa: BLE001 - unknown speeds: the record starts from defaults
            return (None, None)

    async def deadband(self, drive: Any) -> float:
        """RDBD: the kind's in-position window, user units."""
        try:
            window = await _value(drive.sync._in_position_window())
            return abs(drive.units.to_user(float(window)))
        except Exception:  # noqa: BLE001
            return 0.0

    @staticmethod
    def address(drive: Any) -> str:
        native = drive.native
        for attr in ("address", "node_id", "node"):
            value = getattr(native, attr, None)
            if isinstance(value, (int, str)) and not isinstance(value, bool):
                return str(value)
        return "?"

    def home_method(self, drive: Any, *, forward: bool) -> Any:
        return self.home[0 if forward else 1]

    async def apply_accel(self, drive: Any, accl: float, velo: float) -> None:
        if self.accel is None or accl <= 0:
            return
        scale = abs(drive.units.scale)
        velo_native = velo / scale if velo else 0.0
        _, vmax = await self.speeds(drive)
        vmax_native = vmax / scale if vmax else 0.0
        await _set_params(drive, self.accel(drive, accl, velo_native, vmax_native))


_DMAC_SPEED_PER_INC_S = 6000.0 / 10000.0     # drives/dmac.py: #HIGH_SPEED (0.01 rpm) per increment/s

KINDS = {
    "arcus": KindMap("arcus", speed=("HSPD", 1.0), accel=_ms("ACC", "DEC"), home=("H+", "H-")),
    "arcus-canopen": KindMap("arcus-canopen", speed=("0x6081", 1.0), accel=_ms("0x6083", "0x6084")),
    "cia402": KindMap("cia402", speed=("0x6081", 1.0), accel=_per_s2("0x6083", "0x6084")),
    "dmac": KindMap("dmac", speed=("#HIGH_SPEED", 1.0 / _DMAC_SPEED_PER_INC_S),
                    accel=_ms("#ACCEL_TIME", "#DECEL_TIME")),
    "pmc007": KindMap("pmc007", speed=("maximum_speed", 1.0), accel=_pmc007_gear),
    "unitek": KindMap("unitek", velocity=False, accel=_ms_to_max("ACC_RAMP")),
}


def kind_map(kind: str) -> KindMap:
    return KINDS.get(kind, KindMap(kind))

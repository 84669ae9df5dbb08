"""What the motor record's VELO, VMAX, ACCL, RDBD and HOMF/HOMR do on a drive: through
the Drive's own hooks, so every kind -- an out-of-tree plugin too -- says it in its own
module (docs/epics.md, "Per kind"):

* ``Drive._move_speed()``: the position-move speed and its declared maximum (VELO's
  starting value until a client sets it, and VMAX), native units/s;
* ``Drive.per_move_velocity``: whether ``move_to(velocity=)`` takes VELO per move;
* ``Drive._set_accel_time(seconds, speed, top)``: ACCL written into the kind's own ramp
  settings before a move, when ACCL or VELO changed since the last move (the drive keeps
  the value);
* ``Drive.homing_directions``: the homing methods of HOMF and HOMR;
* ``Drive._in_position_window()``: RDBD.

A kind that says nothing moves at the drive's own speed until a client sets VELO,
ignores ACCL and homes with its default method for both buttons.
"""
from __future__ import annotations

from typing import Any, Optional

from ..drive import _value


class DriveSettings:
    """One axis' drive seen through those hooks, in the record's user units."""

    def __init__(self, drive: Any) -> None:
        self.drive = drive                   # the aio.Drive
        self.sync = drive.sync               # its Drive, whose hooks these are

    @property
    def velocity(self) -> bool:
        return bool(self.sync.per_move_velocity)

    async def speeds(self) -> tuple[Optional[float], Optional[float]]:
        """(the current move speed, its declared maximum), user units/s, where the kind says."""
        scale = abs(self.drive.units.scale)
        try:
            now, top = await self.sync._move_speed()
        except Exception:  # noqa: BLE001 - unknown speeds: the record starts from defaults
            return (None, None)
        return (None if now is None else now * scale, None if top is None else top * scale)

    async def deadband(self) -> float:
        """RDBD: the kind's in-position window, user units."""
        try:
            window = await _value(self.sync._in_position_window())
            return abs(self.drive.units.to_user(float(window)))
        except Exception:  # noqa: BLE001
            return 0.0

    def address(self) -> str:
        native = self.drive.native
        for attr in ("address", "node_id", "node"):
            value = getattr(native, attr, None)
            if isinstance(value, (int, str)) and not isinstance(value, bool):
                return str(value)
        return "?"

    def home_method(self, *, forward: bool) -> Any:
        return tuple(self.sync.homing_directions)[0 if forward else 1]

    async def apply_accel(self, accl: float, velo: float) -> bool:
        """ACCL seconds to VELO (user units/s) on the kind's ramps; False: it has none."""
        if accl <= 0:
            return False
        scale = abs(self.drive.units.scale)
        _, top = await self.speeds()
        return bool(await self.sync._set_accel_time(accl, velo / scale if velo else 0.0,
                                                     top / scale if top else None))

"""Every motorbus axis as an ophyd-async device a bluesky RunEngine can scan.

    from bluesky import RunEngine
    from bluesky.plans import scan
    from ophyd_async.plan_stubs import ensure_connected
    from motorbus import Bench
    from motorbus.ophyd import devices_from_bench

    RE = RunEngine()
    with Bench.load("bench.toml") as bench:
        motors = devices_from_bench(bench)            # {axis name: MotorbusMotor}
        RE(ensure_connected(*motors.values()))
        RE(scan([motors["y"]], motors["x"], 0.0, 10.0, 11))

Needs the ``bluesky`` extra (``pip install 'motorbus[bluesky]'``): motorbus itself
never imports this module.  The device follows ophyd-async's own motor
(``ophyd_async.epics.motor.Motor``): ``user_readback`` (hinted, named as the
device), ``user_setpoint``, ``velocity``, ``low_limit_travel`` /
``high_limit_travel``, ``motor_egu``; ``set(x)`` moves and waits for the drive to
be at rest, ``stop()`` stops the axis.  Every signal reads the drive when read,
except ``user_readback`` while the device is staged (ophyd-async then reads its
monitor, refreshed every ``POLL_PERIOD`` and at the end of each move); each drive
call runs on a worker thread so the RunEngine's event loop never waits on a serial
line or a CAN bus.
"""
from __future__ import annotations

import asyncio
import math
from functools import cached_property
from typing import Any, Mapping, Optional

try:
    from ophyd_async.core import (
        AsyncStatus,
        MovableLogic,
        StandardMovable,
        StandardReadable,
        StandardReadableFormat,
        TimeoutCalculator,
        soft_signal_r_and_setter,
        soft_signal_rw,
    )
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError("motorbus.ophyd needs ophyd-async and bluesky: pip install 'motorbus[bluesky]'") from e

from . import _core
from .drive import Drive

__all__ = ["MotorbusMotor", "MoveLimitError", "devices_from_bench"]

#: Seconds between readings of the position while a move is watched (bluesky's
#: progress bars and ``observe_value`` subscribe to ``user_readback``).
POLL_PERIOD = 0.05


class MoveLimitError(_core.InvalidArgument):
    """A target outside the travel limits the drive reports (nothing was sent)."""

    __module__ = "motorbus.ophyd"


async def _call(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """A blocking drive call on a worker thread: the event loop goes on meanwhile."""
    return await asyncio.to_thread(fn, *args, **kwargs)


def _precision(scale: float) -> int:
    """Decimal places that show one native step in user units (0.0025 mm -> 4)."""
    return max(0, math.ceil(-math.log10(abs(scale)) - 1e-9))


class _DriveMoveLogic(MovableLogic[float]):
    """How a MotorbusMotor moves: the drive's own move, its own wait and its own errors."""

    def __init__(self, motor: "MotorbusMotor") -> None:
        super().__init__(setpoint=motor.user_setpoint, readback=motor.user_readback)
        self._motor = motor

    async def check_move(self, new_position: float) -> None:
        if isinstance(new_position, bool) or not isinstance(new_position, (int, float)) \
                or not math.isfinite(new_position):
            raise _core.InvalidArgument(f"{self._motor.name}: target must be a finite number, not {new_position!r}")
        low, high = await _call(lambda: self._motor.drive.travel_limits)
        if not low <= new_position <= high:
            units = self._motor.drive.units.name
            raise MoveLimitError(f"{self._motor.name}: target {new_position:g} {units} is outside the drive's "
                                 f"travel limits [{low:g}, {high:g}] {units}")

    async def move(self, new_position: float, timeout: TimeoutCalculator) -> None:
        drive = self._motor.drive
        speed = await self._motor.velocity.get_value()
        await self.setpoint.set(new_position)
        # Start, then wait on the drive: a refusal (disabled, fault, limit) raises the
        # drive's own typed error here, and a move that ends short raises the Drive API's
        # MoveFailed (limit, fault, stall, interrupted, timeout); either fails the status.
        await _call(drive.move_to, float(new_position), velocity=speed or None, wait=False)
        try:
            await _call(drive.wait_idle, timeout())
        finally:
            # A staged signal reads its monitor's cache (ophyd-async), refreshed every
            # POLL_PERIOD: hand it the position at rest so the reading after the move is it.
            try:
                self._motor._publish_position(await _call(lambda: drive.position))
            except _core.MotorbusError:
                pass

    async def stop(self) -> None:
        await _call(self._motor.drive.stop)

    async def get_units_precision(self) -> tuple[Optional[str], Optional[int]]:
        units = self._motor.drive.units
        return units.name, _precision(units.scale)


class MotorbusMotor(StandardReadable, StandardMovable[float]):
    """One :class:`motorbus.Drive` as an ophyd-async motor (movable, readable, stoppable).

    Signals (user units from ``drive.units``):

    * ``user_readback`` — ``drive.position``, read from the drive on every read
      (hinted: a scan's events carry it under the device's name);
    * ``user_setpoint`` — the last target asked for;
    * ``velocity`` — the speed of moves in user units/s, 0 = the drive's own
      configured speed (configuration);
    * ``low_limit_travel`` / ``high_limit_travel`` — ``drive.travel_limits``, the
      soft limits the drive enforces, ``-inf`` / ``inf`` where it has none
      (configuration; a target outside them fails before anything is sent);
    * ``motor_egu`` — the user units' name (configuration);
    * ``actual_velocity`` — ``drive.velocity`` (not in ``read()``: read it when wanted).

    ``set(x)`` returns a status that completes when the drive is at rest after
    the move and fails with the drive's own error if it refuses or faults;
    ``stop(success=False)`` stops the axis (``drive.stop()``: its deceleration).
    The motor is not enabled here: enable the drive (or not) as the bench needs.
    """

    def __init__(self, drive: Drive, name: str = "", *, velocity: float = 0.0) -> None:
        if not isinstance(drive, Drive):
            raise _core.InvalidArgument(f"MotorbusMotor: a motorbus.Drive, not {type(drive).__name__}")
        if isinstance(velocity, bool) or not isinstance(velocity, (int, float)) \
                or not math.isfinite(velocity) or velocity < 0:
            raise _core.InvalidArgument(f"MotorbusMotor: velocity must be a finite number >= 0, not {velocity!r}")
        self.drive = drive
        units, precision = drive.units.name, _precision(drive.units.scale)

        async def position() -> float:
            return await _call(lambda: drive.position)

        async def speed() -> float:
            return await _call(lambda: drive.velocity)

        async def low() -> float:
            return (await _call(lambda: drive.travel_limits))[0]

        async def high() -> float:
            return (await _call(lambda: drive.travel_limits))[1]

        with self.add_children_as_readables(StandardReadableFormat.HINTED_SIGNAL):
            self.user_readback, self._publish_position = soft_signal_r_and_setter(
                float, drive.position, units=units, precision=precision, getter=position, poll_period=POLL_PERIOD)
        with self.add_children_as_readables(StandardReadableFormat.CONFIG_SIGNAL):
            self.velocity = soft_signal_rw(float, float(velocity), units=f"{units}/s")
            self.low_limit_travel, _ = soft_signal_r_and_setter(float, units=units, getter=low)
            self.high_limit_travel, _ = soft_signal_r_and_setter(float, units=units, getter=high)
            self.motor_egu, _ = soft_signal_r_and_setter(str, units)
        # The setpoint starts where the axis stands, as a motor record's VAL does.
        self.user_setpoint = soft_signal_rw(float, drive.position, units=units, precision=precision)
        self.actual_velocity, _ = soft_signal_r_and_setter(float, units=f"{units}/s", getter=speed)
        super().__init__(name=name)

    @AsyncStatus.wrap
    async def stage(self) -> None:
        await super().stage()
        # Staged, user_readback reads its monitor's cache, which starts from the last
        # value seen: give it the position now, not the one of the last read.
        self._publish_position(await _call(lambda: self.drive.position))

    @cached_property
    def movable_logic(self) -> _DriveMoveLogic:
        return _DriveMoveLogic(self)

    def __repr__(self) -> str:
        return f"<MotorbusMotor {self.name!r} on {self.drive!r}>"


def devices_from_bench(bench: Any, names: Optional[list[str]] = None) -> dict[str, MotorbusMotor]:
    """``{axis name: MotorbusMotor}`` for every axis of a :class:`motorbus.Bench`
    (or only ``names``), each device named as its axis."""
    axes: Mapping[str, Drive] = bench.select(names)
    return {name: MotorbusMotor(drive, name=name) for name, drive in axes.items()}

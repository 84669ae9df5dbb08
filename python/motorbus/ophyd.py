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
be at rest, ``stop()`` stops the axis.

Every drive call is awaited on the axis's :class:`motorbus.aio.Drive` twin, on the
RunEngine's own event loop: no ``to_thread``, no executor.  A move is one awaited
``twin.move_to``; when ophyd-async cancels its task (``stop()``, a pause, a failed
plan) the twin stops the motor and waits, bounded, for rest before the status
ends.  Every signal reads the drive when read, except ``user_readback`` while the
device is staged (ophyd-async then reads its monitor, refreshed every
``POLL_PERIOD`` and at the end of each move).
"""
from __future__ import annotations

import math
from functools import cached_property
from typing import Any, Mapping, Optional, Union

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

from . import _core, aio
from .bench import Bench
from .drive import Drive

__all__ = ["MotorbusMotor", "MoveLimitError", "devices_from_bench"]

#: Seconds between readings of the position while a move is watched (bluesky's
#: progress bars and ``observe_value`` subscribe to ``user_readback``).
POLL_PERIOD = 0.05


class MoveLimitError(_core.InvalidArgument):
    """A target outside the travel limits the drive reports (nothing was sent)."""

    __module__ = "motorbus.ophyd"


def _precision(scale: float) -> int:
    """Decimal places that show one native step in user units (0.0025 mm -> 4)."""
    return max(0, math.ceil(-math.log10(abs(scale)) - 1e-9))


class _DriveMoveLogic(MovableLogic[float]):
    """How a MotorbusMotor moves: the twin's own move, its own wait and its own errors."""

    def __init__(self, motor: "MotorbusMotor") -> None:
        super().__init__(setpoint=motor.user_setpoint, readback=motor.user_readback)
        self._motor = motor

    async def check_move(self, new_position: float) -> None:
        if isinstance(new_position, bool) or not isinstance(new_position, (int, float)) \
                or not math.isfinite(new_position):
            raise _core.InvalidArgument(f"{self._motor.name}: target must be a finite number, not {new_position!r}")
        low, high = await self._motor.twin.travel_limits()
        if not low <= new_position <= high:
            units = self._motor.twin.units.name
            raise MoveLimitError(f"{self._motor.name}: target {new_position:g} {units} is outside the drive's "
                                 f"travel limits [{low:g}, {high:g}] {units}")

    async def move(self, new_position: float, timeout: TimeoutCalculator) -> None:
        twin = self._motor.twin
        speed = await self._motor.velocity.get_value()
        await self.setpoint.set(new_position)
        # One awaited move: a refusal (disabled, fault, limit) raises the drive's own typed
        # error, a move that ends short the Drive API's MoveFailed (limit, fault, stall,
        # interrupted, timeout); either fails the status.  Cancelled (ophyd-async's stop(),
        # a pause, a failed plan), the twin stops the motor and waits for rest first.
        try:
            await twin.move_to(float(new_position), velocity=speed or None, timeout=timeout())
        finally:
            # A staged signal reads its monitor's cache (ophyd-async), refreshed every
            # POLL_PERIOD: hand it the position at rest so the reading after the move is it.
            try:
                self._motor._publish_position(await twin.position())
            except _core.MotorbusError:
                pass

    async def stop(self) -> None:
        # StandardMovable.stop() calls this before it cancels the move's task: the kind's
        # stop goes out at once (ahead of any exchange queued on the link), not after the
        # cancellation has reached the move.
        await self._motor.twin.stop()

    async def get_units_precision(self) -> tuple[Optional[str], Optional[int]]:
        units = self._motor.twin.units
        return units.name, _precision(units.scale)


class MotorbusMotor(StandardReadable, StandardMovable[float]):
    """One :class:`motorbus.Drive` (or its :class:`motorbus.aio.Drive` twin) as an
    ophyd-async motor (movable, readable, stoppable).

    Signals (user units from ``drive.units``):

    * ``user_readback`` — the position, read from the drive on every read
      (hinted: a scan's events carry it under the device's name);
    * ``user_setpoint`` — the last target asked for (the position at connection
      until then);
    * ``velocity`` — the speed of moves in user units/s, 0 = the drive's own
      configured speed (configuration);
    * ``low_limit_travel`` / ``high_limit_travel`` — the drive's travel limits,
      the soft limits it enforces, ``-inf`` / ``inf`` where it has none
      (configuration; a target outside them fails before anything is sent);
    * ``motor_egu`` — the user units' name (configuration);
    * ``actual_velocity`` — the drive's velocity (not in ``read()``: read it when wanted).

    ``set(x)`` returns a status that completes when the drive is at rest after
    the move and fails with the drive's own error if it refuses or faults;
    ``stop(success=False)`` stops the axis (the kind's stop: its deceleration).
    ``drive`` is the blocking :class:`motorbus.Drive`, ``twin`` the awaitable one
    every call of the device goes through.  Building the device talks to nothing
    (no loop is taken); connecting it reads the position once.  The motor is not
    enabled here: enable the drive (or not) as the bench needs.
    """

    def __init__(self, drive: Union[Drive, aio.Drive], name: str = "", *, velocity: float = 0.0) -> None:
        if isinstance(drive, aio.Drive):
            twin = drive
        elif isinstance(drive, Drive):
            twin = aio.Drive(drive)
        else:
            raise _core.InvalidArgument(f"MotorbusMotor: a motorbus.Drive or motorbus.aio.Drive, "
                                        f"not {type(drive).__name__}")
        if isinstance(velocity, bool) or not isinstance(velocity, (int, float)) \
                or not math.isfinite(velocity) or velocity < 0:
            raise _core.InvalidArgument(f"MotorbusMotor: velocity must be a finite number >= 0, not {velocity!r}")
        self.twin = twin
        self.drive = twin.sync
        self._placed = False
        units, precision = twin.units.name, _precision(twin.units.scale)

        async def low() -> float:
            return (await twin.travel_limits())[0]

        async def high() -> float:
            return (await twin.travel_limits())[1]

        with self.add_children_as_readables(StandardReadableFormat.HINTED_SIGNAL):
            self.user_readback, self._publish_position = soft_signal_r_and_setter(
                float, units=units, precision=precision, getter=twin.position, poll_period=POLL_PERIOD)
        with self.add_children_as_readables(StandardReadableFormat.CONFIG_SIGNAL):
            self.velocity = soft_signal_rw(float, float(velocity), units=f"{units}/s")
            self.low_limit_travel, _ = soft_signal_r_and_setter(float, units=units, getter=low)
            self.high_limit_travel, _ = soft_signal_r_and_setter(float, units=units, getter=high)
            self.motor_egu, _ = soft_signal_r_and_setter(str, units)
        self.user_setpoint = soft_signal_rw(float, units=units, precision=precision)
        self.actual_velocity, _ = soft_signal_r_and_setter(float, units=f"{units}/s", getter=twin.velocity)
        super().__init__(name=name)

    async def connect(self, mock: Any = False, timeout: float = 10.0, force_reconnect: bool = False) -> None:
        await super().connect(mock=mock, timeout=timeout, force_reconnect=force_reconnect)
        if not mock and (force_reconnect or not self._placed):
            # The setpoint starts where the axis stands, as a motor record's VAL does:
            # read here (awaited, on the connecting loop), not when the device was built.
            position = await self.twin.position()
            await self.user_setpoint.set(position)
            self._publish_position(position)
            self._placed = True

    async def stop(self, success: bool = False) -> None:
        try:
            await super().stop(success=success)
        except BaseException:
            # ophyd-async sends the stop, then cancels the move: a stop that failed (a
            # lost link...) must not leave the move running with its status pending. The
            # cancelled move tries the twin's own ladder (stop, then quick stop).
            if self._move_status is not None:
                self._move_status.task.cancel()
            raise

    @AsyncStatus.wrap
    async def stage(self) -> None:
        await super().stage()
        # Staged, user_readback reads its monitor's cache, which starts from the last
        # value seen: give it the position now, not the one of the last read.
        self._publish_position(await self.twin.position())

    @cached_property
    def movable_logic(self) -> _DriveMoveLogic:
        return _DriveMoveLogic(self)

    def __repr__(self) -> str:
        return f"<MotorbusMotor {self.name!r} on {self.drive!r}>"


def devices_from_bench(bench: Union[Bench, aio.Bench], names: Optional[list[str]] = None) -> dict[str, MotorbusMotor]:
    """``{axis name: MotorbusMotor}`` for every axis of a :class:`motorbus.Bench` or a
    :class:`motorbus.aio.Bench` (or only ``names``), each device named as its axis
    (on an ``aio.Bench``, the device uses the bench's own twin of the axis)."""
    if isinstance(bench, aio.Bench):
        chosen: Mapping[str, Drive] = bench.sync.select(names)
        return {name: MotorbusMotor(bench[name], name=name) for name in chosen}
    if not isinstance(bench, Bench):
        raise _core.InvalidArgument(f"devices_from_bench: a motorbus.Bench or motorbus.aio.Bench, "
                                    f"not {type(bench).__name__}")
    return {name: MotorbusMotor(drive, name=name) for name, drive in bench.select(names).items()}

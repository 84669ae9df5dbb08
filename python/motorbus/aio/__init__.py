"""Awaitable motorbus: the same verbs as the blocking API, from asyncio.

    import asyncio, motorbus
    from motorbus import aio

    async def main():
        async with await aio.open_drive(KIND, line="/dev/ttyUSB0", address="01") as x:
            await x.enable()
            await x.move_to(25.0)                 # ends at the target or raises MoveFailed
            print(await x.position(), (await x.status()).text)

        async with await aio.Bench.load("bench.toml", sim=True) as bench:
            await bench.move_together({"x": 10, "y": 20})
            await bench.stop_all()

    asyncio.run(main())

An :class:`aio.Drive` is the awaitable twin of a :class:`motorbus.Drive` (``.sync``
is the blocking one, on the same drive): both run the same logic, written once as
coroutines (motorbus.faces).  Readings that talk to the drive are awaitable
methods (``await x.position()``, ``status()``, ``velocity()``,
``travel_limits()``; ``await x.params.get(name)`` / ``set(name, value)``), since a
property cannot be awaited.  Outcomes are the blocking API's: a move ends at its
target or raises the :class:`motorbus.MoveFailed` subclass that says why.

**Cancelling an awaited move stops the motor**: the task's ``CancelledError``
sends the kind's stop (ahead of any queued exchange), waits up to ``stop_timeout``
seconds for rest, records the move as interrupted by the cancellation and only then
re-raises ``CancelledError``.  ``stop_on_cancel=False`` (per call) leaves the motor
going, for deliberate fire-and-forget.

The loop is the running one when a call is awaited (nothing binds an object to a
loop), so several loops in several threads can each drive their own axes.
"""
from __future__ import annotations

import asyncio
from collections.abc import Mapping
from typing import Any, Optional, Union

from .. import _core, _stop_at_exit, faces
from ..bench import Bench as _SyncBench, StartReport
from ..drive import (Drive as _SyncDrive, DriveStatus, MoveInterrupted, MoveTimedOut, ParamInfo, StopReason, Units,
                     stopped_by_text)
from ..drive import open_drive as _open_drive
from ..stopping import STOP_WAYS, StopHow, check_stop_way
# The awaitable twins that live beside their blocking originals (docs/aio.md):
from ..bus import AioBus as Bus, FrameStream, aio_open_bus as open_bus  # noqa: E402,F401
from .discovery import discover  # noqa: E402,F401

__all__ = ["Drive", "Params", "Bench", "open_drive", "transact", "Bus", "open_bus", "FrameStream", "discover",
           "STOP_TIMEOUT"]

#: Seconds an awaited move's cancellation waits for the motor to come to rest after
#: its stop, unless the call gives ``stop_timeout``.
STOP_TIMEOUT = 10.0


async def _blocking_once(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """A one-off blocking step (opening ports and buses, starting simulators) off the
    loop, on the shared worker for such steps (a thread that ends when idle)."""
    return await faces.NativeIo(None, link=_blocking_once).do(lambda: fn(*args, **kwargs))


class Params:
    """``await axis.params.get(name)`` / ``await axis.params.set(name, value)``: the
    blocking ``drive.params`` mapping's reads and writes, awaited; names, ``in``,
    ``describe`` and iteration need no exchange and are plain."""

    def __init__(self, params: Any) -> None:
        self.sync = params

    async def get(self, name: str) -> Any:
        return await self.sync._co_get(name)

    async def set(self, name: str, value: Any) -> None:
        await self.sync._co_set(name, value)

    def describe(self, name: str) -> ParamInfo:
        return self.sync.describe(name)

    def __iter__(self) -> Any:
        return iter(self.sync)

    def __len__(self) -> int:
        return len(self.sync)

    def __contains__(self, name: object) -> bool:
        return name in self.sync

    def __repr__(self) -> str:
        return f"<awaitable {self.sync!r}>"


class Drive:
    """The awaitable twin of a :class:`motorbus.Drive` (see the module doc)."""

    def __init__(self, drive: _SyncDrive, *, stop_timeout: float = STOP_TIMEOUT) -> None:
        if not isinstance(drive, _SyncDrive):
            raise _core.InvalidArgument(f"aio.Drive: a motorbus.Drive, not {type(drive).__name__}")
        self.sync = drive
        self.stop_timeout = stop_timeout
        self._params: Optional[Params] = None

    # ---- what needs no exchange ---------------------------------------------------------------
    @property
    def kind(self) -> str:
        return self.sync.kind

    @property
    def name(self) -> str:
        return self.sync.name

    @property
    def units(self) -> Units:
        return self.sync.units

    @property
    def capabilities(self) -> frozenset:
        return self.sync.capabilities

    @property
    def native(self) -> Any:
        return self.sync.native

    @property
    def closed(self) -> bool:
        return self.sync.closed

    @property
    def params(self) -> Params:
        if self._params is None:
            self._params = Params(self.sync.params)
        return self._params

    def __repr__(self) -> str:
        return f"<awaitable {self.sync!r}>"

    # ---- commands --------------------------------------------------------------------------------
    async def enable(self) -> None:
        await self.sync._co_enable()

    async def disable(self) -> None:
        await self.sync._co_disable()

    async def move_to(self, position: float, *, velocity: Optional[float] = None, wait: bool = True,
                      timeout: Optional[float] = None, stop_on_cancel: bool = True) -> None:
        """Absolute move in user units; see ``motorbus.Drive.move_to``.  Cancelled: stops the motor."""
        await self._moving(self.sync._co_move_to(position, velocity=velocity, wait=wait, timeout=timeout),
                           stop_on_cancel)

    async def move_by(self, distance: float, *, velocity: Optional[float] = None, wait: bool = True,
                      timeout: Optional[float] = None, stop_on_cancel: bool = True) -> None:
        await self._moving(self.sync._co_move_by(distance, velocity=velocity, wait=wait, timeout=timeout),
                           stop_on_cancel)

    async def jog(self, velocity: float) -> None:
        """Starts a jog (returns at once, as the blocking ``jog``); ``stop()`` ends it."""
        await self.sync._co_jog(velocity)

    async def home(self, method: Any = None, *, wait: bool = True, timeout: Optional[float] = None,
                   stop_on_cancel: bool = True) -> None:
        await self._moving(self.sync._co_home(method, wait=wait, timeout=timeout), stop_on_cancel)

    async def wait_idle(self, timeout: Optional[float] = None, *, stop_on_cancel: bool = True) -> None:
        """At rest, judged as the blocking ``wait_idle`` judges it.  Cancelled while the
        motor still moves: stops it (``stop_on_cancel``)."""
        await self._moving(self.sync._co_wait_idle(timeout), stop_on_cancel)

    async def stop(self) -> None:
        await self.sync._co_stop()

    async def quick_stop(self) -> None:
        await self.sync._co_quick_stop()

    async def clear_faults(self) -> None:
        await self.sync._co_clear_faults()

    async def store(self) -> None:
        await self.sync._co_store()

    async def console(self, line: str) -> str:
        return await self.sync._co_console(line)

    # ---- readings --------------------------------------------------------------------------------
    async def position(self) -> float:
        return await self.sync._co_position()

    async def velocity(self) -> float:
        return await self.sync._co_velocity()

    async def status(self) -> DriveStatus:
        return await self.sync._co_status()

    async def travel_limits(self) -> tuple[float, float]:
        return await self.sync._co_travel_limits()

    # ---- cancellation stops the motor -----------------------------------------------------------
    async def _moving(self, logic: Any, stop_on_cancel: bool) -> None:
        try:
            await logic
        except asyncio.CancelledError:
            if stop_on_cancel and not self.sync.closed:
                await self._stop_after_cancel()
            raise

    async def _stop_after_cancel(self) -> None:
        """The cancelled move's stop: sent at once (ahead of anything queued on the link),
        then a bounded wait for rest; the move's outcome is recorded.  Shielded: a second
        cancellation ends this wait, not the stop (already sent) nor the recording."""
        d = self.sync
        by = "the cancellation of the awaiting task"
        try:
            await asyncio.shield(d._co_stop(by=by))
        except Exception:  # noqa: BLE001 - a failed stop falls back as the exit hook's ladder does
            try:
                await asyncio.shield(d._co_quick_stop(by=by))
            except Exception:  # noqa: BLE001 - nothing more to do from here; the CancelledError goes on
                return
        try:
            await asyncio.shield(self._settle_cancelled())
        except Exception:  # noqa: BLE001 - recorded in last_move where it could be; the cancellation goes on
            pass

    async def _settle_cancelled(self) -> None:
        """Waits up to ``stop_timeout`` for rest after the cancellation's stop and records
        the move's outcome: judged as any other once at rest (a homing cut short is
        interrupted, whatever it had found); not at rest in time, a MoveTimedOut saying
        the motor was still moving -- never a judgement of a shaft still turning."""
        d = self.sync
        move = d._move
        try:
            await d._wait(d._is_idle, self.stop_timeout, "the stop after a cancellation")
        except _core.TimeoutError:
            if move is not None and not move.judged:
                await d._failure(move, StopReason(MoveTimedOut, f"no rest within {self.stop_timeout:g} s of the "
                                                                 "stop sent for the cancellation"), at_rest=False)
            raise
        if move is None or move.judged:
            return
        if move.what == "home":
            await d._failure(move, StopReason(MoveInterrupted, stopped_by_text(move.stopped_by)))
        else:
            await d._judge(move, raise_error=False)

    # ---- safety --------------------------------------------------------------------------------
    async def __aenter__(self) -> "Drive":
        return self

    async def __aexit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        try:
            if exc_type is not None and not self.sync.closed:
                await self._halt(self.sync.on_error)
        finally:
            await self.aclose()

    async def _halt(self, how: StopHow) -> None:
        """The ``on_error`` ladder of the blocking face, awaited: the asked stop, then the
        stronger ones if it fails."""
        d = self.sync
        for step in _stop_at_exit.ladder(how, d._co_stop, d._co_quick_stop, d._co_disable):
            try:
                await asyncio.shield(step())
                return
            except Exception:  # noqa: BLE001 - the next, stronger way
                continue

    async def aclose(self) -> None:
        """Forgets the drive (no stop), closing what ``open_drive`` opened (off the loop:
        closing a client may say goodbye to its drive)."""
        await _blocking_once(self.sync.close)


async def open_drive(kind: str, *, line: Any = None, bus: Any = None, address: Union[str, int],
                     units: Optional[Units] = None, stop_timeout: float = STOP_TIMEOUT, **options: Any) -> Drive:
    """``motorbus.open_drive``, awaited (opening the port or bus runs off the loop); the
    awaitable twin of the drive it opens."""
    drive = await _blocking_once(_open_drive, kind, line=line, bus=bus, address=address, units=units, **options)
    return Drive(drive, stop_timeout=stop_timeout)


async def transact(link: "_core.serial.LineLink", request: Union[str, bytes], *,
                   timeout: Optional[float] = None) -> bytes:
    """``link.transact(request)`` awaited: one request/reply on a serial line, the reply
    without its terminator.  Completion-based: the transaction runs on the link's own C++
    worker (one per link, in order with every other transaction on it) and its reply
    wakes the loop through the loop's completion queue; the same errors as the blocking
    call (``TimeoutError``, ``ReplyTooLong``, ``LinkDown``...).  A cancelled await drops
    the reply (the transaction itself, a few ms, still completes on the line)."""
    bridge = faces.bridge_for()
    token, future = bridge.expect()
    link.transact_async(request, bridge.completions, token, timeout)
    try:
        return await future
    except asyncio.CancelledError:
        bridge.forget(token)
        raise


class Bench:
    """The awaitable twin of a :class:`motorbus.Bench`: ``axes`` are :class:`aio.Drive`."""

    def __init__(self, bench: _SyncBench, *, stop_timeout: float = STOP_TIMEOUT) -> None:
        self.sync = bench
        self._axes = {name: Drive(d, stop_timeout=stop_timeout) for name, d in bench.axes.items()}

    @classmethod
    async def load(cls, path: Any, *, sim: bool = False, clock: Any = None,
                   stop_timeout: float = STOP_TIMEOUT) -> "Bench":
        """``motorbus.Bench.load`` (with ``sim=True``: its simulated twin), awaited."""
        return cls(await _blocking_once(_SyncBench.load, path, sim=sim, clock=clock), stop_timeout=stop_timeout)

    @classmethod
    async def from_dict(cls, data: Mapping[str, Any], *, sim: bool = False, clock: Any = None,
                        stop_timeout: float = STOP_TIMEOUT) -> "Bench":
        return cls(await _blocking_once(_SyncBench.from_dict, data, sim=sim, clock=clock), stop_timeout=stop_timeout)

    @classmethod
    async def connect(cls, address: Any, *, timeout: float = 5.0) -> Any:
        """``motorbus.Bench.connect``, awaited: the bench a running ``motorbus serve`` owns, its
        axes awaitable twins of Drives that talk to the service (serve.client.AioRemoteBench)."""
        from ..serve.client import aio_connect

        return await aio_connect(address, timeout=timeout)

    @property
    def axes(self) -> dict[str, Drive]:
        return dict(self._axes)

    def __getitem__(self, name: str) -> Drive:
        self.sync[name]                 # the blocking bench's check and message
        return self._axes[name]

    def __iter__(self) -> Any:
        return iter(self._axes)

    def __len__(self) -> int:
        return len(self._axes)

    async def move_together(self, targets: Mapping[str, float], *, relative: bool = False,
                            velocity: Optional[float] = None, wait: bool = True, timeout: Optional[float] = None,
                            stop_on_cancel: bool = True) -> StartReport:
        """``Bench.move_together``, awaited; cancelled: every axis it started is stopped."""
        try:
            return await self.sync._co_move_together(targets, relative=relative, velocity=velocity, wait=wait,
                                                     timeout=timeout)
        except asyncio.CancelledError:
            if stop_on_cancel:
                await asyncio.gather(*(self._axes[n]._stop_after_cancel() for n in targets if n in self._axes),
                                     return_exceptions=True)
            raise

    async def stop_all(self, how: str = "stop") -> list[tuple[str, BaseException]]:
        check_stop_way(how, "Bench.stop_all how", tuple(w for w in STOP_WAYS if w is not None))
        return await self.sync._co_stop_all(how)

    async def status(self) -> dict[str, DriveStatus]:
        return {name: await d.status() for name, d in self._axes.items()}

    async def aclose(self) -> None:
        await _blocking_once(self.sync.close)

    async def __aenter__(self) -> "Bench":
        return self

    async def __aexit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        try:
            if exc_type is not None:
                await asyncio.gather(*(d._halt(d.sync.on_error) for d in self._axes.values() if not d.closed),
                                     return_exceptions=True)
        finally:
            await self.aclose()

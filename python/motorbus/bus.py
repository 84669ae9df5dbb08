"""Opening buses: ``open_bus(spec, **options)`` and the python-can bridge.

Specs are URL-like strings, one scheme per registered backend (entry-point group
``motorbus.bus``, see docs/plugins.md); the ones motorbus brings::

    virtual:NAME                    in-process hub (bitrate=, tx_queue=, receive_own=, rx_spin=)
    slcan:PATH[@BITRATE]            Lawicel adapter on a serial line (CANable, USBtin, a pty)
    socketcand:HOST:PORT/CHANNEL    socketcand server over TCP
    socketcan:IFACE                 Linux AF_CAN raw socket (can0, vcan0)

or a python-can ``can.BusABC`` instance, which is wrapped so every motorbus
client (SDO, drives, recorder) runs on it.

Every bus also has an awaitable face (issue 25, docs/aio.md "Buses and
streams"), methods of the same Bus objects, named after their blocking twins:

    frame = await bus.arecv(timeout=1.0)        # recv(): the same queue and filters
    frames = await bus.arecv_many(256)          # recv_many()
    await bus.asend(frame)                      # send(), waiting on a full medium without blocking the loop
    async for frame in bus: ...                 # bus.frames(): a stream of its own
    async with bus.frames(filters=[{"can_id": 0x180, "can_mask": 0x780}], queue=64) as tpdos:
        async for frame in tpdos: ...

No thread waits for a frame: the bus's receive thread hands each burst to the
loop's completion queue (an eventfd the loop watches) without the GIL.
"""
from __future__ import annotations

import asyncio
import collections
import math
import threading
import time
import weakref
from typing import Any, Callable, Coroutine, Optional

from . import _core, faces, registry

__all__ = ["open_bus", "parse_spec", "frame_to_message", "message_to_frame", "wall_time", "FrameStream", "AioBus",
           "aio_open_bus"]

# Offset from the monotonic clock of frame timestamps to the epoch, fixed once
# so converted timestamps keep their spacing.
_EPOCH_OFFSET = time.time() - time.monotonic_ns() / 1e9


def wall_time(timestamp_ns: int) -> float:
    """Epoch seconds for a Frame.timestamp_ns (python-can's timestamp convention)."""
    return timestamp_ns / 1e9 + _EPOCH_OFFSET


def parse_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """Split a bus spec into (scheme, arguments) through the registered scheme.

    InvalidArgument names the problem (an unknown scheme lists the registered ones)."""
    scheme, sep, rest = spec.partition(":")
    if not sep or not rest:
        raise _core.InvalidArgument(f"bus spec {spec!r}: expected SCHEME:ARGS, e.g. virtual:bench")
    try:
        return scheme, registry.bus_scheme(scheme).parse(rest)
    except _core.InvalidArgument as e:
        raise _core.InvalidArgument(f"bus spec {spec!r}: {e}") from None


def open_bus(spec: Any, **options: Any) -> _core.can.Bus:
    """Open a bus from a spec string or wrap a python-can bus. See the module doc."""
    if not isinstance(spec, str):
        return _bridge(spec, **options)
    scheme, args = parse_spec(spec)
    return registry.bus_scheme(scheme).open(**args, **options)


def _parse_virtual(rest: str) -> dict[str, Any]:
    return {"name": rest}


#: ``virtual:NAME``: every bus opened with one NAME in this process is one CAN bus.
VIRTUAL = registry.BusScheme("virtual", "in-process hub: wire time at a bit rate, arbitration, fault injection",
                             parse=_parse_virtual, open=_core.can.open_virtual, example="virtual:bench")


# ---------------------------------------------------------------------------
# python-can -> motorbus

def message_to_frame(msg: Any) -> _core.can.Frame:
    """python-can Message -> Frame (validated)."""
    if msg.is_remote_frame:
        return _core.can.Frame(msg.arbitration_id, b"", extended=msg.is_extended_id, rtr=True, dlc=msg.dlc)
    return _core.can.Frame(msg.arbitration_id, bytes(msg.data), extended=msg.is_extended_id)


def frame_to_message(frame: _core.can.Frame, channel: Any = None) -> Any:
    """Frame -> python-can Message (timestamp in epoch seconds, as python-can uses)."""
    import can

    return can.Message(
        timestamp=wall_time(frame.timestamp_ns) if frame.timestamp_ns else time.time(),
        arbitration_id=frame.id,
        is_extended_id=frame.extended,
        is_remote_frame=frame.rtr,
        is_error_frame=frame.is_error,
        dlc=frame.dlc,
        data=None if frame.rtr else frame.data,
        channel=channel,
        is_rx=not frame.is_loopback,
    )


class _Bridge:
    """Owns the reader thread that moves frames from a python-can bus into an ExternalBus."""

    def __init__(self, pcbus: Any, poll: float, receive_own: bool) -> None:
        self._pc = pcbus
        self._poll = poll
        self._stop = threading.Event()
        self.bus = _core.can.ExternalBus(
            channel=f"python-can:{getattr(pcbus, 'channel_info', type(pcbus).__name__)}",
            send=self._send,
            close=self._close,
            receive_own=receive_own,
        )
        self._thread = threading.Thread(target=self._reader, name="motorbus-python-can-bridge", daemon=True)
        self._thread.start()

    def _send(self, frame: _core.can.Frame, timeout: float) -> None:
        import can

        try:
            self._pc.send(frame_to_message(frame), timeout=timeout)
        except can.CanOperationError as e:
            raise _core.TimeoutError(f"python-can bus did not accept the frame: {e}") from e

    def _reader(self) -> None:
        while not self._stop.is_set():
            try:
                msg = self._pc.recv(self._poll)
            except Exception:  # a foreign bus that fails to parse must not end the bridge
                self.bus.feed_parse_error()
                continue
            if msg is None or msg.is_error_frame:
                continue
            try:
                frame = message_to_frame(msg)
            except _core.InvalidArgument:
                self.bus.feed_parse_error()
                continue
            frame.timestamp_ns = _core.runtime.monotonic_ns()
            self.bus.feed(frame)

    def _close(self) -> None:
        self._stop.set()
        if threading.current_thread() is not self._thread:
            self._thread.join()


def _bridge(pcbus: Any, poll: float = 0.01, receive_own: bool = False) -> _core.can.Bus:
    import can

    if not isinstance(pcbus, can.BusABC):
        raise _core.InvalidArgument(
            f"open_bus: expected a spec string or a can.BusABC, got {type(pcbus).__name__}")
    return _Bridge(pcbus, poll, receive_own).bus


# ---------------------------------------------------------------------------
# The awaitable face: methods of every _core.can.Bus (see the module doc)

def _check_timeout(what: str, timeout: Any) -> Optional[float]:
    if timeout is None:
        return None
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or math.isnan(timeout) or timeout < 0:
        raise _core.InvalidArgument(f"{what} timeout: seconds >= 0 or None (wait forever), not {timeout!r}")
    return None if math.isinf(timeout) else float(timeout)


def _check_count(what: str, n: Any) -> int:
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise _core.InvalidArgument(f"{what}: a number of frames >= 1, not {n!r}")
    return n


async def _completed(bridge: faces.LoopBridge, token: int, future: asyncio.Future, timeout: Optional[float],
                     withdraw: Callable[[], bool], keep: Callable[[list], None]) -> Optional[list]:
    """Waits for the completion ``token`` of a frame waiter; None after ``timeout``.

    The future is shielded: a cancelled (or timed-out) wait first withdraws its
    waiter; if the waiter had already been served, its frames are on their way
    and go to ``keep`` (the next read takes them first) instead of being lost."""
    try:
        if timeout is None:
            return await asyncio.shield(future)
        done, _ = await asyncio.wait((future,), timeout=timeout)
        if done:
            return future.result()
    except asyncio.CancelledError:
        if withdraw():
            bridge.forget(token)
        else:
            future.add_done_callback(lambda f: keep(f.result()) if not f.cancelled() and f.exception() is None
                                     else None)
        raise
    if withdraw():
        bridge.forget(token)
        return None
    return await future          # served as the timeout struck: already on its way, take it


# Frames a cancelled arecv() had already been given, per bus: the next arecv() starts with them.
_leftovers: "weakref.WeakKeyDictionary[Any, collections.deque]" = weakref.WeakKeyDictionary()


def _keep_for(bus: Any) -> Callable[[list], None]:
    def keep(frames: list) -> None:
        _leftovers.setdefault(bus, collections.deque()).extendleft(reversed(frames))
    return keep


async def _frames_or_wait(take: Callable[[Any, int], list], withdraw: Callable[[Any, int], bool],
                          keep: Callable[[list], None], timeout: Optional[float]) -> list:
    """What ``take(completions, token)`` has now, or else the batch it completes
    later (``[]`` after ``timeout``): the one wait of ``arecv`` and of a stream."""
    bridge = faces.bridge_for()
    token, future = bridge.expect()
    try:
        frames = take(bridge.completions, token)
    except BaseException:
        bridge.forget(token)
        raise
    if frames:
        bridge.forget(token)
        return frames
    got = await _completed(bridge, token, future, timeout, lambda: withdraw(bridge.completions, token), keep)
    return [] if got is None else got


async def _recv_batch(bus: Any, max_frames: int, timeout: Optional[float]) -> list:
    kept = _leftovers.get(bus)
    if kept:
        return [kept.popleft() for _ in range(min(max_frames, len(kept)))]
    return await _frames_or_wait(lambda done, token: bus._recv_or_wait(max_frames, done, token), bus._cancel_wait,
                                 _keep_for(bus), timeout)


def _arecv(self: Any, timeout: Optional[float] = None
           ) -> "typing.Coroutine[typing.Any, typing.Any, typing.Optional[motorbus._core.can.Frame]]":
    """``await bus.arecv(timeout=None)``: the awaitable twin of ``recv()`` -- the
    next frame of the same queue, through the same filters (``set_filters``),
    or None after ``timeout`` seconds (None: wait forever).  ClosedError /
    LinkDown as ``recv()``.  No thread waits: the bus's receive thread
    completes the wait on the loop's completion queue."""
    return _first(_recv_batch(self, 1, _check_timeout("Bus.arecv", timeout)))


async def _first(batch: Coroutine) -> Optional[_core.can.Frame]:
    frames = await batch
    return frames[0] if frames else None


def _arecv_many(self: Any, max: int = 1024, timeout: Optional[float] = None  # noqa: A002
                ) -> "typing.Coroutine[typing.Any, typing.Any, list[motorbus._core.can.Frame]]":
    """``await bus.arecv_many(max=1024, timeout=None)``: the awaitable twin of
    ``recv_many()`` -- up to ``max`` frames, oldest first, as soon as there is
    one; [] after ``timeout``."""
    return _recv_batch(self, _check_count("Bus.arecv_many max", max), _check_timeout("Bus.arecv_many", timeout))


def _asend(self: Any, frame: "motorbus._core.can.Frame", timeout: float = 1.0
           ) -> "typing.Coroutine[typing.Any, typing.Any, None]":
    """``await bus.asend(frame, timeout=1.0)``: the awaitable twin of ``send()``.

    ``send()`` blocks while the medium is full (a virtual bus's transmit queue,
    a socketcand server that stops reading); here the frame is offered without
    waiting and, while the medium stays full, offered again after a short
    sleep of the task (0.5 ms, doubling to 10 ms) until ``timeout``: then
    TimeoutError, as ``send()``.  A medium with room costs no sleep."""
    return _send_co(self, frame, timeout, _check_timeout("Bus.asend", timeout))


async def _send_co(self: Any, frame: _core.can.Frame, timeout: float, limit: Optional[float]) -> None:
    deadline = None if limit is None else time.monotonic() + limit
    pause = 0.0005
    while True:
        try:
            self.send(frame, 0.0)
            return
        except _core.TimeoutError:
            if deadline is not None and time.monotonic() >= deadline:
                raise _core.TimeoutError(f"bus {self.channel}: the medium stayed full for {timeout:g} s; "
                                         f"frame {frame} not sent") from None
        await asyncio.sleep(pause if deadline is None else max(0.0, min(pause, deadline - time.monotonic())))
        pause = min(pause * 2, 0.01)


class FrameStream:
    """A bus's frames as an async iterator (``bus.frames(...)``, ``async for frame in bus``).

    A subscription of its own (C++ ``can::AsyncReceiver``): it takes nothing
    from ``recv()``'s queue, and every stream sees every frame its ``filters``
    pass (python-can style dicts: ``{"can_id": 0x181, "can_mask": 0x7FF,
    "extended": False}``; None = all).  The bus's receive thread appends to a
    bounded queue of ``queue`` frames; when the loop is slower, the newest
    frames are dropped and counted in ``overflows`` -- the bus thread never
    waits.  The stream ends (StopAsyncIteration) after its queued frames when
    the bus closes or ``close()`` is called; a link lost for good raises
    LinkDown.  Cancelling the task that iterates leaves the bus usable; a
    frame already handed to the cancelled wait is kept for the next one."""

    def __init__(self, bus: Any, filters: Any = None, queue: int = 1024, batch: int = 256) -> None:
        _check_count("Bus.frames queue", queue)
        self._batch_max = _check_count("Bus.frames batch", batch)
        self.bus = bus
        self._rx = _core.can.AsyncReceiver(bus, filters, queue)
        self._ready: collections.deque = collections.deque()

    # ---- counters ----
    @property
    def overflows(self) -> int:
        """Frames dropped because the queue was full (the newest of a burst)."""
        return self._rx.counters.overflows

    @property
    def received(self) -> int:
        """Frames that passed the filters since the stream began (delivered, queued or dropped)."""
        return self._rx.counters.received

    @property
    def wakeups(self) -> int:
        """Times the bus thread woke the loop (one per burst the loop was waiting for)."""
        return self._rx.counters.wakeups

    @property
    def queued(self) -> int:
        return self._rx.queued + len(self._ready)

    # ---- reading ----
    def __aiter__(self) -> "FrameStream":
        return self

    async def __anext__(self) -> _core.can.Frame:
        if not self._ready:
            try:
                self._ready.extend(await self.batch())
            except _core.ClosedError:
                raise StopAsyncIteration from None
        return self._ready.popleft()

    async def batch(self, max: Optional[int] = None, timeout: Optional[float] = None) -> list:  # noqa: A002
        """The queued frames (up to ``max``, default the stream's batch size) as soon as
        there is one, oldest first; [] after ``timeout``.  ClosedError once ended."""
        max_frames = self._batch_max if max is None else _check_count("FrameStream.batch max", max)
        timeout = _check_timeout("FrameStream.batch", timeout)
        if self._ready:
            return [self._ready.popleft() for _ in range(min(max_frames, len(self._ready)))]
        return await _frames_or_wait(lambda done, token: self._rx.take_or_arm(max_frames, done, token),
                                     lambda done, token: self._rx.disarm(),
                                     lambda frames: self._ready.extendleft(reversed(frames)), timeout)

    # ---- ending ----
    def close(self) -> None:
        """Unsubscribes; the iteration ends after the frames already queued.  Idempotent."""
        self._rx.close()

    async def __aenter__(self) -> "FrameStream":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self) -> None:
        rx = getattr(self, "_rx", None)
        if rx is not None:
            rx.close()          # unsubscribe now (without the GIL), not whenever the C++ object goes

    def __repr__(self) -> str:
        return (f"<FrameStream on {self.bus.channel}: {self.received} received, {self.overflows} overflows, "
                f"{self.queued} queued>")


def _frames(self: Any, filters: Any = None, queue: int = 1024, batch: int = 256) -> "motorbus.bus.FrameStream":
    """``bus.frames(filters=None, queue=1024, batch=256)``: a :class:`FrameStream`
    of this bus (an async iterator of Frames with its own filters and bounded queue)."""
    return FrameStream(self, filters, queue, batch)


def _aiter(self: Any) -> "motorbus.bus.FrameStream":
    """``async for frame in bus``: ``bus.frames()`` with its defaults."""
    return FrameStream(self)


class AioBus:
    """The awaitable twin of a bus (``motorbus.aio.Bus``): the blocking verbs' own names,
    awaited -- ``await twin.recv()``, ``recv_many()``, ``send()``, ``async for frame in
    twin``, ``twin.frames(...)`` -- on the same bus (``twin.sync``; ``bus.arecv()`` etc. are
    the same calls).  Everything else (``set_filters``, ``counters``, ``state``,
    ``channel``, ``subscribe``...) is the bus's own.  ``async with twin:`` closes the bus."""

    __slots__ = ("sync",)

    def __init__(self, bus: Any) -> None:
        if not isinstance(bus, _core.can.Bus):
            raise _core.InvalidArgument(f"aio.Bus: a motorbus bus (open_bus), not {type(bus).__name__}")
        self.sync = bus

    def recv(self, timeout: Optional[float] = None) -> Coroutine:
        return self.sync.arecv(timeout)

    def recv_many(self, max: int = 1024, timeout: Optional[float] = None) -> Coroutine:  # noqa: A002
        return self.sync.arecv_many(max, timeout)

    def send(self, frame: _core.can.Frame, timeout: float = 1.0) -> Coroutine:
        return self.sync.asend(frame, timeout)

    def frames(self, filters: Any = None, queue: int = 1024, batch: int = 256) -> FrameStream:
        return FrameStream(self.sync, filters, queue, batch)

    def __aiter__(self) -> FrameStream:
        return FrameStream(self.sync)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.sync, name)

    async def __aenter__(self) -> "AioBus":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        await _opening(self.sync.close)      # close() joins the backend's threads

    def __repr__(self) -> str:
        return f"<aio.Bus {self.sync.channel} ({self.sync.state})>"


async def aio_open_bus(spec: Any, **options: Any) -> AioBus:
    """``await aio.open_bus(spec, **options)``: :func:`open_bus` off the loop (a
    socketcand connect and handshake, an SLCAN adapter's setup may take seconds),
    on one shared worker for such one-off steps; the bus's awaitable twin."""
    return AioBus(await _opening(open_bus, spec, **options))


_OPENING = object()      # the key of the worker that opens and closes buses


def _opening(fn: Callable, *args: Any, **kwargs: Any) -> Any:
    return faces.NativeIo(None, link=_OPENING).do(lambda: fn(*args, **kwargs))


# Methods of every bus, whatever its backend: the Bus objects users already hold get their awaitable twins.
_core.can.Bus.arecv = _arecv
_core.can.Bus.arecv_many = _arecv_many
_core.can.Bus.asend = _asend
_core.can.Bus.frames = _frames
_core.can.Bus.__aiter__ = _aiter

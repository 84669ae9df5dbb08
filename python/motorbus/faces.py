"""One implementation, two faces: how a kind's logic is written once and run
either blocking (``drive.move_to(5)``) or awaited (``await axis.move_to(5)``).

A kind writes its ``Drive`` hooks (``_enable``, ``_move_to``, ``_status``...) as
``async def`` coroutines, and every exchange with its drive as an ``await`` on
``self.io`` (the kind's native client seen through :class:`NativeIo`)::

    async def _enable(self):
        if await self.io.has_brake():
            await self.io.brake(False)
        await self.io.power("ON")

    async def _position(self):
        return float(await self.io.attr("position"))     # a property of the client

The two faces run the *same* coroutine:

* the blocking face, :func:`run`, drives it to completion on the calling thread
  with no event loop: each ``await self.io...`` performs the native call at once
  and hands back its result without suspending, so the coroutine never yields
  (the way zaber-motion's synchronous API sits on its asynchronous core);
* the awaitable face (``motorbus.aio``) awaits it in a task: each exchange is
  handed to the link's worker and the task sleeps until the result comes back
  through the loop's completion queue (:class:`LoopBridge`: an eventfd the loop
  watches with ``add_reader``, drained in batches).

Which face a coroutine runs under is a context variable set by :func:`run`;
``faces.sleep`` sleeps the thread in one face and the task in the other.  The
loop is the one running when a call is awaited, never the one of the moment an
object was built, so several loops (one per thread) work side by side.

Workers: the native clients' calls block in C++ (with the GIL released) for one
transaction of a few milliseconds; the awaitable face runs them on one worker
thread per link (a serial line or a drive's node: one conversation at a time
anyway), started on first use and ended after an idle second -- never a thread
per wait: a move's wait is the task's, polling between ``asyncio.sleep``.  A
stop (``urgent=True``) goes to the front of its worker's queue.
"""
from __future__ import annotations

import asyncio
import collections
import contextvars
import itertools
import threading
import time
import weakref
from typing import Any, Callable, Coroutine, Optional

from . import _core

__all__ = ["run", "blocking", "sleep", "NativeIo", "LoopBridge", "bridge_for"]

_BLOCKING: contextvars.ContextVar[bool] = contextvars.ContextVar("motorbus_blocking_face", default=False)


def run(coro: Coroutine) -> Any:
    """The blocking face: runs a coroutine of motorbus logic to its end on this thread
    and returns its value (or raises its error).  The coroutine must only await
    motorbus calls (``self.io``, ``faces.sleep``, other such coroutines)."""
    token = _BLOCKING.set(True)
    try:
        try:
            step = coro.send(None)
        except StopIteration as done:
            return done.value
        coro.close()
        raise RuntimeError(f"motorbus: {getattr(coro, '__qualname__', coro)} awaited {step!r}, which is not a "
                           "motorbus call: the blocking face cannot run it")
    finally:
        _BLOCKING.reset(token)


def blocking() -> bool:
    """True inside :func:`run` (the blocking face)."""
    return _BLOCKING.get()


class _Sleep:
    __slots__ = ("seconds", "sleeper")

    def __init__(self, seconds: float, sleeper: Optional[Callable[[float], Any]]) -> None:
        self.seconds, self.sleeper = seconds, sleeper

    def __await__(self) -> Any:
        if self.sleeper is not None:            # a simulated clock: advancing it takes no time
            self.sleeper(self.seconds)
            return None
        if _BLOCKING.get():
            time.sleep(self.seconds)
            return None
        return (yield from asyncio.sleep(self.seconds).__await__())


def sleep(seconds: float, sleeper: Optional[Callable[[float], Any]] = None) -> _Sleep:
    """``await faces.sleep(s)``: the thread sleeps (blocking face) or the task does
    (awaitable face); ``sleeper``: a kind's own (a simulated clock's advance)."""
    return _Sleep(seconds, sleeper)


# ---- the loop side: one completion queue per event loop ---------------------------------
class LoopBridge:
    """Where finished operations meet one event loop: a C++ ``Completions`` queue
    whose eventfd the loop watches, and the futures waiting on it by token.

    C++ completion-based entry points (SDO transfers...) push a C++ value with a
    token from their own thread, without the GIL; the link workers (Python
    threads) append to ``_from_threads`` and poke the same eventfd.  The loop
    drains both in one callback: one wake-up per burst, however many finished."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self.completions = _core.runtime.Completions()
        self._futures: dict[int, asyncio.Future] = {}
        self._tokens = itertools.count(1)
        self._from_threads: collections.deque = collections.deque()
        try:
            loop.add_reader(self.completions.fileno(), self._drain)
        except NotImplementedError:
            # A loop that cannot watch a descriptor (Windows' proactor): the pushing
            # thread schedules the drain, once per burst.
            self.completions.set_wakeup(lambda: loop.call_soon_threadsafe(self._drain))

    def expect(self) -> tuple[int, asyncio.Future]:
        """A token for a C++ entry point and the future its completion resolves."""
        token = next(self._tokens)
        future = self.loop.create_future()
        self._futures[token] = future
        return token, future

    def forget(self, token: int) -> None:
        """A waiter that gave up (cancelled): its completion, if it comes, is dropped."""
        self._futures.pop(token, None)

    def deliver(self, future: asyncio.Future, value: Any = None, error: Optional[BaseException] = None) -> None:
        """From any thread: resolve ``future`` on the loop thread."""
        self._from_threads.append((future, value, error))
        self.completions.notify()

    def _drain(self) -> None:
        for token, value, failure in self.completions.drain():
            future = self._futures.pop(token, None)
            if future is None or future.done():
                continue
            if failure is None:
                future.set_result(value)
            else:
                try:
                    failure.rethrow()
                except BaseException as e:  # noqa: BLE001 - it is the operation's error, handed on
                    future.set_exception(e)
        while self._from_threads:
            future, value, error = self._from_threads.popleft()
            if future.done():                  # cancelled meanwhile
                continue
            if error is None:
                future.set_result(value)
            else:
                future.set_exception(error)


_bridges: "weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, LoopBridge]" = weakref.WeakKeyDictionary()
_bridges_lock = threading.Lock()


def bridge_for(loop: Optional[asyncio.AbstractEventLoop] = None) -> LoopBridge:
    """The bridge of ``loop`` (the running one by default), made on first use."""
    loop = loop or asyncio.get_running_loop()
    with _bridges_lock:
        bridge = _bridges.get(loop)
        if bridge is None:
            bridge = _bridges[loop] = LoopBridge(loop)
    return bridge


# ---- the link side: one worker per link ------------------------------------------------------
class _LinkWorker:
    """Runs one link's native calls in order on one thread, which ends after an idle
    second (and starts again when needed)."""

    IDLE = 1.0

    def __init__(self, key: int, workers: dict) -> None:
        self._key, self._workers = key, workers
        self._jobs: collections.deque = collections.deque()
        self._wake = threading.Condition(_workers_lock)
        self._thread = threading.Thread(target=self._serve, name=f"motorbus-link-{key:x}", daemon=True)
        self._thread.start()

    def submit(self, job: tuple, urgent: bool) -> None:       # called with _workers_lock held
        (self._jobs.appendleft if urgent else self._jobs.append)(job)
        self._wake.notify()

    def _serve(self) -> None:
        while True:
            with _workers_lock:
                if not self._jobs:
                    self._wake.wait(self.IDLE)
                if not self._jobs:
                    del self._workers[self._key]    # idle: the next call starts a new worker
                    return
                fn, args, bridge, future = self._jobs.popleft()
            if future.done():                       # its waiter was cancelled before it ran
                continue
            try:
                value = fn(*args)
            except BaseException as e:  # noqa: BLE001 - handed to the waiter
                bridge.deliver(future, error=e)
            else:
                bridge.deliver(future, value)


_workers: dict = {}
_workers_lock = threading.Lock()


def _submit(key: Any, fn: Callable, args: tuple, bridge: LoopBridge, future: asyncio.Future, urgent: bool) -> None:
    with _workers_lock:
        worker = _workers.get(id(key))
        if worker is None:
            worker = _workers[id(key)] = _LinkWorker(id(key), _workers)
        worker.submit((fn, args, bridge, future), urgent)


def worker_threads() -> int:
    """Link workers alive now (tests, benchmarks)."""
    with _workers_lock:
        return len(_workers)


class _Call:
    __slots__ = ("key", "fn", "args", "urgent")

    def __init__(self, key: Any, fn: Callable, args: tuple, urgent: bool = False) -> None:
        self.key, self.fn, self.args, self.urgent = key, fn, args, urgent

    def __await__(self) -> Any:
        if _BLOCKING.get():
            return self.fn(*self.args)
        bridge = bridge_for()
        future = bridge.loop.create_future()
        _submit(self.key, self.fn, self.args, bridge, future, self.urgent)
        return (yield from future)


class NativeIo:
    """A native client's calls as awaitables: ``await io.read(v)`` is
    ``native.read(v)``; ``await io.attr("position")`` reads a property,
    ``await io.set_attr("high_speed", 5)`` writes one, ``await io.do(f, *args)``
    runs any function (of the client, or a few of its calls in a row); ``io.urgent``
    is the same for calls that must overtake queued ones (stops).  ``link``: what
    the calls' worker is shared with (a serial line's drives share one).  (The
    helpers' names are ones no native client uses: ``get``/``set``/``read`` are the
    clients' own.)"""

    __slots__ = ("_native", "_link", "_urgent")

    def __init__(self, native: Any, link: Any = None, urgent: bool = False) -> None:
        self._native = native
        self._link = native if link is None else link
        self._urgent = urgent

    @property
    def urgent(self) -> "NativeIo":
        return NativeIo(self._native, self._link, True)

    def __getattr__(self, name: str) -> Callable[..., _Call]:
        method = getattr(self._native, name)
        link, urgent = self._link, self._urgent
        return lambda *args: _Call(link, method, args, urgent)

    def attr(self, name: str) -> _Call:
        return _Call(self._link, getattr, (self._native, name), self._urgent)

    def set_attr(self, name: str, value: Any) -> _Call:
        return _Call(self._link, setattr, (self._native, name, value), self._urgent)

    def do(self, fn: Callable, *args: Any) -> _Call:
        return _Call(self._link, fn, args, self._urgent)

"""A served bench from another program: ``motorbus.Bench.connect(BENCH)`` (blocking) and
``await motorbus.aio.Bench.connect(BENCH)`` (awaitable).

    with motorbus.Bench.connect("bench.toml") as bench:    # the bench file of a running `motorbus serve`
        bench["x"].move_to(10)                             # a MoveFailed subclass if it stops short
        print(bench["x"].position, bench.status())
        with bench.poll(rate_hz=1000) as poller:           # rows of the service's one shared Poller
            frame = poller.frame()

``bench["x"]`` is a :class:`RemoteDrive`, a :class:`motorbus.Drive` subclass whose verbs and readings
are calls to the service (docs/serve-protocol.md), so ``isinstance`` checks, ``motorbus.aio.Drive(...)``,
``motorbus.ophyd`` and the CLI take it unchanged.  One connection carries every call of the program:
a reader thread matches replies by id, so several threads (and tasks) call at once and a stop overtakes
a move another thread is waiting for.

Safety, as for a local bench, for what *this* program commands: an exception leaving ``with`` (and the
interpreter's exit) stops the axes this program moved; if the program dies, the service stops the
moves it was awaiting.  Axes it only read are left as they are.
"""
from __future__ import annotations

import asyncio
import collections
import itertools
import json
import math
import os
import socket
import stat
import threading
from struct import error as struct_error
from typing import Any, Iterable, Mapping, Optional, Sequence

import numpy as np

from .. import _core, faces
from ..bench import Bench
from ..drive import Capability, Drive, DriveStatus, Params, ParamInfo, Units
from ..stopping import STOP_WAYS, check_stop_way
from . import rpc

__all__ = ["connect", "aio_connect", "RemoteBench", "RemoteDrive", "RemoteParams", "RemotePoller",
           "AioRemoteBench", "resolve"]


def _from_here(by: str) -> str:
    """A stop sent to the service names this program, so the outcome the service records
    (which every program waiting on the move reads) says whose stop it was."""
    return f"{by} of the program with pid {os.getpid()} through motorbus serve" if by.endswith("()") else by


def resolve(address: Any) -> tuple[str, Optional[Any]]:
    """The socket path of ``address`` ("unix:/path.sock", a socket path, or a bench file whose
    service runs) and the service's ServiceInfo when it was found through its bench file."""
    if isinstance(address, bytes):
        address = os.fsdecode(address)
    try:
        a = os.fspath(address)
    except TypeError:
        raise _core.InvalidArgument(f"connect: a bench file, a socket path or 'unix:/path.sock', "
                                    f"not {address!r}") from None
    if a.startswith("unix:"):
        return a[len("unix:"):], None
    try:
        if stat.S_ISSOCK(os.stat(a).st_mode):
            return a, None
    except OSError:
        pass
    from .lockfile import find_service

    info = find_service(a)
    if info is not None:
        return info.socket, info
    if not os.path.exists(a):
        raise _core.InvalidArgument(f"connect: {a}: no such bench file or socket")
    raise _core.LinkDown(f"{a}: no motorbus serve runs for this bench (start one: motorbus serve {a})")


# ---- the connection ------------------------------------------------------------------------------
class _SyncWaiter:
    __slots__ = ("event", "value", "error")

    def __init__(self) -> None:
        self.event = threading.Event()
        self.value: Any = None
        self.error: Optional[BaseException] = None

    def resolve(self, value: Any, error: Optional[BaseException]) -> None:
        self.value, self.error = value, error
        self.event.set()


class _AsyncWaiter:
    __slots__ = ("loop", "future")

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self.future = loop.create_future()

    def resolve(self, value: Any, error: Optional[BaseException]) -> None:
        def settle() -> None:
            if self.future.done():
                return
            if error is None:
                self.future.set_result(value)
            else:
                self.future.set_exception(error)
        try:
            self.loop.call_soon_threadsafe(settle)
        except RuntimeError:      # the loop is closed: nobody waits any more
            pass


class Connection:
    """One Unix-socket connection to a service, shared by every caller of a program: calls
    carry ids, a reader thread hands each reply to its caller (a thread or a task)."""

    def __init__(self, path: str, *, timeout: float = 5.0) -> None:
        self.path = path
        self._ids = itertools.count(1)
        self._pending: dict[int, Any] = {}
        self._lock = threading.Lock()
        self._send_lock = threading.Lock()
        self._subs: dict[int, "RemotePoller"] = {}
        self._early: dict[int, collections.deque] = {}   # rows of a subscription not registered yet
        self._ended_subs: set[int] = set()
        self.closed = False
        self.lost: Optional[str] = None
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            sock.settimeout(timeout)
            sock.connect(path)
        except socket.timeout:
            sock.close()
            raise _core.TimeoutError(f"motorbus serve at {path}: no connection within {timeout:g} s") from None
        except OSError as e:
            sock.close()
            raise _core.LinkDown(f"motorbus serve at {path}: {e.strerror or e} (is the service running?)") from None
        sock.settimeout(None)
        self._sock = sock
        self._reader = threading.Thread(target=self._read_loop, name=f"motorbus-serve-client-{path}", daemon=True)
        self._reader.start()

    # -- sending --
    def _send(self, msg: dict) -> None:
        data = rpc.frame(rpc.FRAME_JSON, rpc.dumps(msg))
        with self._send_lock:
            if self.closed:
                raise _core.ClosedError(f"motorbus serve at {self.path}: connection closed")
            try:
                self._sock.sendall(data)
            except OSError as e:
                raise _core.LinkDown(f"motorbus serve at {self.path}: {e.strerror or e}") from None

    def _message(self, cid: int, call: str, axis: Optional[str], args: Sequence, kwargs: Mapping) -> dict:
        msg: dict = {"id": cid, "call": call, "args": [rpc.encode(a) for a in args],
                     "kwargs": {k: rpc.encode(v) for k, v in kwargs.items()}}
        if axis is not None:
            msg["axis"] = axis
        return msg

    def _register(self, waiter: Any) -> int:
        with self._lock:
            if self.lost is not None:
                raise _core.LinkDown(self.lost)
            if self.closed:
                raise _core.ClosedError(f"motorbus serve at {self.path}: connection closed")
            cid = next(self._ids)
            self._pending[cid] = waiter
        return cid

    def call(self, call: str, axis: Optional[str] = None, *args: Any, **kwargs: Any) -> Any:
        """A call, waited for on this thread (the blocking face)."""
        waiter = _SyncWaiter()
        cid = self._register(waiter)
        try:
            self._send(self._message(cid, call, axis, args, kwargs))
            waiter.event.wait()
        except BaseException:
            # Ctrl-C while waiting: the service's call runs on (a move is not stopped by the
            # wait being given up -- the program's with-block, exit hook or its own stop is).
            with self._lock:
                self._pending.pop(cid, None)
            raise
        if waiter.error is not None:
            raise waiter.error
        return waiter.value

    async def acall(self, call: str, axis: Optional[str] = None, *args: Any, **kwargs: Any) -> Any:
        """A call, awaited (the awaitable face): the task sleeps until its reply comes."""
        waiter = _AsyncWaiter(asyncio.get_running_loop())
        cid = self._register(waiter)
        try:
            self._send(self._message(cid, call, axis, args, kwargs))
            return await waiter.future
        finally:
            with self._lock:
                self._pending.pop(cid, None)

    # -- receiving --
    def _recv_exact(self, n: int) -> bytes:
        buf = bytearray()
        while len(buf) < n:
            chunk = self._sock.recv(n - len(buf))
            if not chunk:
                raise ConnectionError("closed by the service")
            buf += chunk
        return bytes(buf)

    def _read_loop(self) -> None:
        why = "closed by the service"
        try:
            while True:
                size, kind = rpc.HEADER.unpack(self._recv_exact(rpc.HEADER.size))
                if size > rpc.MAX_FRAME:
                    why = f"a frame of {size} bytes: not the motorbus serve protocol"
                    break
                payload = self._recv_exact(size)
                if kind == rpc.FRAME_JSON:
                    self._on_reply(json.loads(payload))
                elif kind == rpc.FRAME_ROWS:
                    sid, n, cols, dropped = rpc.ROWS_HEADER.unpack_from(payload)
                    rows = np.frombuffer(payload, dtype="<f8", offset=rpc.ROWS_HEADER.size).reshape(n, cols)
                    with self._lock:
                        sub = self._subs.get(sid)
                        if sub is None and sid not in self._ended_subs:
                            # Rows can overtake the subscriber's registration (the reply that
                            # names it and the first rows may come in one burst): kept for it.
                            early = self._early.setdefault(sid, collections.deque(maxlen=64))
                            early.append((rows, dropped))
                            while len(self._early) > 16:
                                self._early.pop(next(iter(self._early)))
                    if sub is not None:
                        sub._feed(rows, dropped)
        except (OSError, ConnectionError, ValueError, struct_error) as e:
            if not self.closed:
                why = f"{e}" if not isinstance(e, OSError) else (e.strerror or str(e))
        finally:
            self._lost(why)

    def _on_reply(self, msg: dict) -> None:
        if "event" in msg:                 # answers no call: a shared poll that ended by itself
            if msg["event"] == "poll_ended":
                sub = self._subs.get(msg.get("sub"))
                if sub is not None:
                    try:
                        sub.end_error = rpc.decode(msg.get("error"))
                        sub.end_stats = rpc.decode(msg.get("stats"))
                    except Exception:  # noqa: BLE001 - the end still counts
                        pass
                    sub._end()
            return
        with self._lock:
            waiter = self._pending.pop(msg.get("id"), None)
        if waiter is None:
            return              # a call its caller gave up on (Ctrl-C, a cancelled task)
        if "error" in msg:
            try:
                error = rpc.decode_error(msg["error"])
            except Exception as e:  # noqa: BLE001 - a reply that cannot be read is still an error
                error = _core.ProtocolError(f"motorbus serve: unreadable error reply: {e}")
            waiter.resolve(None, error)
        else:
            try:
                waiter.resolve(rpc.decode(msg.get("ok")), None)
            except Exception as e:  # noqa: BLE001
                waiter.resolve(None, _core.ProtocolError(f"motorbus serve: unreadable reply: {e}"))

    def _lost(self, why: str) -> None:
        with self._lock:
            closed_here = self.closed
            self.lost = f"motorbus serve at {self.path}: connection lost ({why})" if not closed_here else \
                f"motorbus serve at {self.path}: connection closed"
            pending, self._pending = self._pending, {}
        error: BaseException = (_core.ClosedError(self.lost) if closed_here else _core.LinkDown(self.lost))
        for waiter in pending.values():
            waiter.resolve(None, error)
        for sub in list(self._subs.values()):
            sub._end()

    def close(self) -> None:
        with self._lock:
            if self.closed:
                return
            self.closed = True
        try:
            self._sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._sock.close()
        if threading.current_thread() is not self._reader:
            self._reader.join(2.0)


class _RemoteCall:
    """``await``-able in both faces: in the blocking face (faces.run) the call is made at once
    on the thread; in the awaitable face the task awaits the reply."""

    __slots__ = ("conn", "call", "axis", "args", "kwargs")

    def __init__(self, conn: Connection, call: str, axis: Optional[str], args: tuple, kwargs: dict) -> None:
        self.conn, self.call, self.axis, self.args, self.kwargs = conn, call, axis, args, kwargs

    def __await__(self) -> Any:
        if faces.blocking():
            return self.conn.call(self.call, self.axis, *self.args, **self.kwargs)
        return (yield from self.conn.acall(self.call, self.axis, *self.args, **self.kwargs).__await__())


# ---- drives --------------------------------------------------------------------------------------
class RemoteParams(Params):
    """``drive.params`` of a served axis: names and descriptions fetched once, values read and
    written through the service on every access (the drive is the truth)."""

    def __init__(self, drive: "RemoteDrive") -> None:
        super().__init__(drive)
        self._table: Optional[dict[str, ParamInfo]] = None

    def _tab(self) -> dict[str, ParamInfo]:
        if self._table is None:
            d = self._drive
            infos = d._conn.call("params_list", d._axis)
            self._table = {i.name: i for i in infos}
        return self._table

    def _names(self) -> list[str]:
        return list(self._tab())

    def _info(self, name: str) -> Optional[ParamInfo]:
        table = self._tab()
        info = table.get(name)
        if info is None:      # the kind's own spelling rules (case, 0x6081 vs 6081h): the service's
            for key, i in table.items():
                if key.lower() == name.lower():
                    return i
            return None
        return info

    def describe(self, name: str) -> ParamInfo:
        info = self._info(self._key(name))
        if info is None:
            # The service says it, in the kind's own words (an alias the table does not spell).
            return self._drive._conn.call("params_describe", self._drive._axis, name)
        return info

    def __contains__(self, name: object) -> bool:
        if not isinstance(name, str):
            return False
        if self._info(name) is not None:
            return True
        try:
            self.describe(name)
            return True
        except _core.InvalidArgument:
            return False

    async def _co_get(self, name: str) -> Any:
        self._drive._check_open()
        return await self._drive._rc("params_get", name)

    async def _co_set(self, name: str, value: Any) -> None:
        self._drive._check_open()
        await self._drive._rc("params_set", name, value)


class RemoteDrive(Drive):
    """An axis of a served bench: a :class:`motorbus.Drive` whose verbs and readings are calls
    to the service (user units, outcomes and errors exactly the service's Drive's).  ``native``
    is None: the vendor client lives in the service."""

    def __init__(self, bench: "RemoteBench", name: str, desc: Mapping[str, Any]) -> None:
        self.kind = desc["kind"]
        caps = set()
        for c in desc.get("capabilities", ()):
            try:
                caps.add(Capability(c))
            except ValueError:
                pass
        self.capabilities = frozenset(caps)
        self.transport = desc.get("transport", "")
        self.has_watchdog = bool(desc.get("has_watchdog", False))
        self._bench = bench
        self._conn = bench._conn
        self._axis = name
        self._has_console = bool(desc.get("has_console", False))
        #: True once this program commanded motion here: what its with-block and exit stop.
        self.commanded = False
        units = desc.get("units")
        super().__init__(None, units=units if isinstance(units, Units) else None)
        self.name = name

    def _io_link(self) -> Any:
        return None

    def _rc(self, call: str, *args: Any, **kwargs: Any) -> _RemoteCall:
        return _RemoteCall(self._conn, call, self._axis, args, kwargs)

    # ---- the verbs: the service's Drive does the logic --------------------------------------
    async def _co_enable(self) -> None:
        self._check_open()
        await self._rc("enable")

    async def _co_disable(self) -> None:
        self._check_open()
        await self._rc("disable")

    async def _co_move_to(self, position: float, *, velocity: Optional[float] = None, wait: bool = True,
                          timeout: Optional[float] = None) -> None:
        self._check_open()
        self.commanded = True
        await self._rc("move_to", position, velocity=velocity, wait=wait, timeout=timeout)

    async def _co_move_by(self, distance: float, *, velocity: Optional[float] = None, wait: bool = True,
                          timeout: Optional[float] = None) -> None:
        self._check_open()
        self.commanded = True
        await self._rc("move_by", distance, velocity=velocity, wait=wait, timeout=timeout)

    async def _co_jog(self, velocity: float) -> None:
        self._check_open()
        self.commanded = True
        await self._rc("jog", velocity)

    async def _co_stop(self, by: str = "stop()") -> None:
        self._check_open()
        await self._rc("stop", by=_from_here(by))

    async def _co_quick_stop(self, by: str = "quick_stop()") -> None:
        self._check_open()
        await self._rc("quick_stop", by=_from_here(by))

    async def _co_home(self, method: Any = None, *, wait: bool = True, timeout: Optional[float] = None) -> None:
        self._check_open()
        self.commanded = True
        await self._rc("home", method, wait=wait, timeout=timeout)

    async def _co_wait_idle(self, timeout: Optional[float] = None) -> None:
        self._check_open()
        await self._rc("wait_idle", timeout)

    async def _co_clear_faults(self) -> None:
        self._check_open()
        await self._rc("clear_faults")

    async def _co_store(self) -> None:
        self._check_open()
        await self._rc("store")

    async def _co_console(self, line: str) -> str:
        self._check_open()
        return await self._rc("console", line)

    async def _co_position(self) -> float:
        self._check_open()
        return await self._rc("position")

    async def _co_velocity(self) -> float:
        self._check_open()
        return await self._rc("velocity")

    async def _co_status(self) -> DriveStatus:
        self._check_open()
        return await self._rc("status")

    async def _co_travel_limits(self) -> tuple[float, float]:
        self._check_open()
        lo, hi = await self._rc("travel_limits")
        return (lo, hi)

    # ---- the kind hooks (native units), for the Drive's generic parts: the safety ladder,
    # ---- aio's stop after a cancellation (its wait for rest) -------------------------------------
    async def _enable(self) -> None:
        await self._rc("enable")

    async def _disable(self) -> None:
        await self._rc("disable")

    async def _move_to(self, target: float, velocity: Optional[float]) -> None:
        v = None if velocity is None else abs(self._units.to_user(velocity))
        await self._rc("move_to", self._units.to_user(target), velocity=v, wait=False)

    async def _jog(self, velocity: float) -> None:
        await self._rc("jog", self._units.to_user(velocity))

    async def _stop(self) -> None:
        await self._rc("stop")

    async def _quick_stop(self) -> None:
        await self._rc("quick_stop")

    async def _home(self, method: Any) -> None:
        await self._rc("home", method, wait=False)

    async def _clear_faults(self) -> None:
        await self._rc("clear_faults")

    async def _store(self) -> None:
        await self._rc("store")

    async def _position(self) -> float:
        return self._units.to_native(await self._rc("position"))

    async def _velocity(self) -> float:
        return self._units.to_native(await self._rc("velocity"))

    async def _status(self) -> DriveStatus:
        return await self._rc("status")

    async def _is_idle(self) -> bool:
        return not (await self._rc("status")).moving

    async def _travel_limits(self) -> tuple[Optional[float], Optional[float]]:
        lo, hi = await self._rc("travel_limits")
        a = None if math.isinf(lo) else self._units.to_native(lo)
        b = None if math.isinf(hi) else self._units.to_native(hi)
        return (a, b) if self._units.scale > 0 else (b, a)

    async def _console(self, line: str) -> str:
        return await self._rc("console", line)

    def _make_params(self) -> Params:
        return RemoteParams(self)

    def poll_fields(self, fields: tuple) -> Any:
        """A served axis is polled by its service, not by this process: ``motorbus.Poller`` on a
        RemoteDrive says where to ask instead."""
        raise _core.InvalidArgument(f"Poller: axis {self.name!r} is served by motorbus serve: poll it through "
                                    f"the service, bench.poll([{self.name!r}], ...) (one shared Poller there)")

    # ---- safety: what this program commanded -----------------------------------------------
    def _halt(self, how: Any) -> None:
        """The with-block's and the exit hook's stop: only an axis this program moved (another
        program's move on a shared bench is not this one's to stop)."""
        if self.commanded and not self._conn.closed and self._conn.lost is None:
            super()._halt(how)

    def __repr__(self) -> str:
        state = "closed" if self._closed else "open"
        return f"<RemoteDrive {self.name} ({self.kind}) {state}, units={self._units.name}, via {self._conn.path}>"


# ---- polls ---------------------------------------------------------------------------------------
class RemotePoller:
    """A subscription to the service's shared poll: ``read()``, ``frame()``, ``chunks()``,
    ``save()`` and ``stats`` as :class:`motorbus.Poller` has them (one row per deadline: ``t``,
    and per axis ``<axis>.t`` and ``<axis>.<field>``, user units).  Rows arrive on the
    connection's reader thread into a bounded buffer (``capacity`` rows: a reader that falls
    further behind loses the oldest, counted in ``overflowed`` with what the service dropped)."""

    def __init__(self, bench: "RemoteBench", reply: Mapping[str, Any], *, capacity: Optional[int] = None,
                 keep: Optional[float] = 600.0) -> None:
        self._bench, self._conn = bench, bench._conn
        self.sub = int(reply["sub"])
        self.columns: list[str] = list(reply["columns"])
        self.rate_hz = float(reply["rate_hz"])
        self.fields = tuple(reply["fields"])
        self.axes = {n: bench[n] for n in reply["axes"]}
        self.modes = dict(reply.get("modes", {}))
        self.period_ns = int(round(float(reply["period"]) * 1e9))
        self._capacity = capacity if capacity is not None else max(4096, int(10 * self.rate_hz))
        self.keep_rows: Optional[int] = None if keep is None else int(math.ceil(keep * self.rate_hz))
        self.discarded = 0
        self._lock = threading.Lock()
        self._pending: collections.deque = collections.deque()
        self._pending_rows = 0
        self._lost_here = 0           # rows this buffer dropped (the program read too slowly)
        self._dropped_there = 0       # rows the service dropped for this subscriber (a slow connection)
        self._retained: list[np.ndarray] = []
        self._retained_rows = 0
        self._waiter: Optional[tuple] = None
        self._ended = False
        #: Why the service's poll ended by itself (a link failed), if it did; None otherwise.
        self.end_error: Optional[BaseException] = None
        #: The service's Poller's stats when it ended by itself (each group's error_type, error).
        self.end_stats: Optional[dict] = None

    # -- fed by the reader thread --
    def _feed(self, rows: np.ndarray, dropped: int) -> None:
        with self._lock:
            self._dropped_there = dropped
            self._pending.append(rows)
            self._pending_rows += len(rows)
            while self._pending_rows > self._capacity and len(self._pending) > 1:
                old = self._pending.popleft()
                self._pending_rows -= len(old)
                self._lost_here += len(old)
            self._wake_locked()

    def _end(self) -> None:
        with self._lock:
            self._ended = True
            self._wake_locked(force=True)

    def _wake_locked(self, force: bool = False) -> None:
        if self._waiter is None:
            return
        loop, future, rows = self._waiter
        if force or self._pending_rows >= rows:
            self._waiter = None
            try:
                loop.call_soon_threadsafe(lambda: future.done() or future.set_result(None))
            except RuntimeError:
                pass

    # -- like motorbus.Poller --
    def read(self) -> dict[str, np.ndarray]:
        """The rows since the last read(), as a frame."""
        with self._lock:
            parts, self._pending, self._pending_rows = list(self._pending), collections.deque(), 0
        block = np.concatenate(parts) if parts else np.empty((0, len(self.columns)))
        if len(block) and self.keep_rows != 0:
            self._retained.append(block)
            self._retained_rows += len(block)
            self._trim()
        elif len(block):
            self.discarded += len(block)
        return {c: block[:, i].copy() for i, c in enumerate(self.columns)}

    def _trim(self) -> None:
        if self.keep_rows is None:
            return
        excess = self._retained_rows - self.keep_rows
        while excess > 0 and self._retained:
            first = self._retained[0]
            if len(first) <= excess:
                self._retained.pop(0)
                cut = len(first)
            else:
                self._retained[0] = first[excess:].copy()
                cut = excess
            self._retained_rows -= cut
            self.discarded += cut
            excess -= cut

    def frame(self) -> dict[str, np.ndarray]:
        """The retained rows (the last ``keep`` seconds; reads what is new first)."""
        self.read()
        if len(self._retained) > 1:
            self._retained = [np.concatenate(self._retained)]
        block = self._retained[0] if self._retained else np.empty((0, len(self.columns)))
        return {c: block[:, i].copy() for i, c in enumerate(self.columns)}

    async def chunks(self, rows: Optional[int] = None) -> Any:
        """``async for chunk in poller.chunks(rows)``: frames of at least ``rows`` new rows
        (default a tenth of a second of them) as they arrive; ends when the poll ends."""
        if rows is None:
            rows = min(self._capacity, max(1, int(round(self.rate_hz / 10))))
        if isinstance(rows, bool) or not isinstance(rows, int) or not 1 <= rows <= self._capacity:
            raise _core.InvalidArgument(f"RemotePoller.chunks rows: a number of rows in 1..{self._capacity}, "
                                        f"not {rows!r}")
        loop = asyncio.get_running_loop()
        while True:
            with self._lock:
                ready = self._pending_rows >= rows or self._ended
                if not ready:
                    future = loop.create_future()
                    self._waiter = (loop, future, rows)
            if not ready:
                try:
                    await future
                finally:
                    with self._lock:
                        if self._waiter is not None and self._waiter[1] is future:
                            self._waiter = None
            ended = self._ended
            chunk = self.read()
            if len(chunk["t"]):
                yield chunk
            if ended:
                return

    @property
    def running(self) -> bool:
        return not self._ended

    @property
    def overflowed(self) -> int:
        """Rows lost: by the service for this subscriber (its connection read too slowly) and
        by this buffer (the program read too slowly)."""
        return self._dropped_there + self._lost_here

    @property
    def stats(self) -> dict[str, Any]:
        """The service's shared Poller's stats (per group) with this subscription's own
        counts under ``"subscription"``."""
        s = self._conn.call("poll_stats", None, self.sub)
        out = dict(s["stats"])
        out["subscription"] = {"sub": self.sub, "sent": s["sent"], "dropped_by_service": s["dropped"],
                               "dropped_here": self._lost_here, "subscribers": s["subscribers"],
                               "poller_overflowed": s["overflowed"]}
        return out

    def save(self, path: Any) -> None:
        from ..poller import Poller

        Poller.save(self, path)   # it needs only frame()

    def _detach(self) -> bool:
        """Ends the subscription here; True when the service is still to be told."""
        if self._ended and self.sub not in self._conn._subs:
            return False
        with self._conn._lock:
            self._conn._subs.pop(self.sub, None)
            self._conn._ended_subs.add(self.sub)
            self._conn._early.pop(self.sub, None)
        self._end()
        return not self._conn.closed and self._conn.lost is None

    def stop(self) -> None:
        """Ends this subscription (the service stops its Poller when no subscriber is left)."""
        if self._detach():
            try:
                self._conn.call("unpoll", None, self.sub)
            except (_core.LinkDown, _core.ClosedError):
                pass

    close = stop

    async def astop(self) -> None:
        """``stop()``, awaited (the awaitable face: the loop does not wait on the service)."""
        if self._detach():
            try:
                await self._conn.acall("unpoll", None, self.sub)
            except (_core.LinkDown, _core.ClosedError):
                pass

    async def __aenter__(self) -> "RemotePoller":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        await self.astop()

    def __enter__(self) -> "RemotePoller":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()

    def __repr__(self) -> str:
        return f"<RemotePoller {self.rate_hz:g} Hz, {', '.join(self.fields)}, axes: {', '.join(self.axes)}>"


# ---- the bench -----------------------------------------------------------------------------------
class RemoteBench(Bench):
    """A served bench, as :class:`motorbus.Bench` has it for everything that does not need the
    transports: ``axes`` (RemoteDrives), ``bench[name]``, ``select``, ``move_together``,
    ``stop_all``, ``status``, ``read_params``, ``diff``, ``apply``, ``store``, ``config``,
    ``source``, ``simulated``, ``lines``/``buses`` (names only: the service holds them),
    ``poll()`` (a :class:`RemotePoller`), ``info`` (the service's), ``close()`` and ``with``.

    A ``motorbus.Bench`` subclass, so code that checks for a Bench (``motorbus.ophyd``'s
    ``devices_from_bench``) takes it; it opens nothing itself (the service holds the bench),
    and every method of Bench is one of its own here."""

    def __init__(self, conn: Connection, hello: Mapping[str, Any], service: Any = None) -> None:  # noqa: D107
        # Bench.__init__ is not called: it would read a file and open transports.
        self._conn = conn
        self.address = conn.path
        #: What the service says of itself (pid, bench, socket, CA prefix and environment...).
        self.info: dict = dict(hello.get("info") or {})
        self.service = service
        self.source: str = hello.get("source", "<served>")
        self.simulated: bool = bool(hello.get("simulated", False))
        self.lines: dict[str, None] = dict.fromkeys(hello.get("lines", ()))
        self.buses: dict[str, None] = dict.fromkeys(hello.get("buses", ()))
        self.sims: dict = {}
        self.served_lines: dict = {}
        self.served_buses: dict = {}
        self.config: dict = {}
        self._axes: dict[str, RemoteDrive] = {}
        self._pollers: list[RemotePoller] = []
        self._closed = False
        for name, desc in hello["axes"].items():
            self.config[name] = desc.get("config")
            self._axes[name] = RemoteDrive(self, name, desc)

    @classmethod
    def load(cls, path: Any, **kw: Any) -> "Bench":
        raise _core.InvalidArgument("RemoteBench.load: a served bench is reached with motorbus.Bench.connect(ADDRESS); "
                                    "motorbus.Bench.load opens a bench file's transports itself")

    @classmethod
    def from_dict(cls, data: Any, **kw: Any) -> "Bench":
        raise _core.InvalidArgument("RemoteBench.from_dict: a served bench is reached with "
                                    "motorbus.Bench.connect(ADDRESS)")

    def _fail(self, message: str, *path: str) -> Any:
        return _core.InvalidArgument(f"{self.source}: {'.'.join(path)}: {message}")

    # ---- axes ------------------------------------------------------------------------------
    @property
    def axes(self) -> dict[str, RemoteDrive]:
        return dict(self._axes)

    def __getitem__(self, name: str) -> RemoteDrive:
        try:
            return self._axes[name]
        except (KeyError, TypeError):
            raise _core.InvalidArgument(f"bench {self.source}: no axis {name!r} "
                                        f"(axes: {', '.join(self._axes)})") from None

    def __iter__(self) -> Any:
        return iter(self._axes)

    def __len__(self) -> int:
        return len(self._axes)

    def select(self, names: Optional[Sequence[str]] = None) -> dict[str, RemoteDrive]:
        return {n: self[n] for n in names} if names else self.axes

    # ---- bench-wide ------------------------------------------------------------------------
    def move_together(self, targets: Mapping[str, float], *, relative: bool = False,
                      velocity: Optional[float] = None, wait: bool = True,
                      timeout: Optional[float] = None) -> Any:
        """``Bench.move_together`` in the service (its synchronised starts; the StartReport)."""
        return faces.run(self._co_move_together(targets, relative=relative, velocity=velocity, wait=wait,
                                                timeout=timeout))

    async def _co_move_together(self, targets: Mapping[str, float], *, relative: bool = False,
                                velocity: Optional[float] = None, wait: bool = True,
                                timeout: Optional[float] = None) -> Any:
        self._check_open()
        if not isinstance(targets, Mapping):
            raise _core.InvalidArgument(f"move_together: a mapping axis -> target, not {type(targets).__name__}")
        for n in targets:
            self[n].commanded = True
        return await _RemoteCall(self._conn, "move_together", None, (dict(targets),),
                                 dict(relative=relative, velocity=velocity, wait=wait, timeout=timeout))

    def stop_all(self, how: str = "stop") -> list[tuple[str, BaseException]]:
        check_stop_way(how, "Bench.stop_all how", tuple(w for w in STOP_WAYS if w is not None))
        return faces.run(self._co_stop_all(how))

    async def _co_stop_all(self, how: str) -> list[tuple[str, BaseException]]:
        self._check_open()
        out = await _RemoteCall(self._conn, "stop_all", None, (how,), {})
        return [(name, e) for name, e in out]

    def status(self) -> dict[str, DriveStatus]:
        self._check_open()
        return self._conn.call("status")

    def read_params(self, names: Optional[Sequence[str]] = None, *, all_params: bool = False) -> dict[str, dict]:
        self._check_open()
        return self._conn.call("read_params", None, list(names) if names else None, all_params=all_params)

    def diff(self, names: Optional[Sequence[str]] = None) -> list:
        self._check_open()
        return self._conn.call("diff", None, list(names) if names else None)

    def apply(self, names: Optional[Sequence[str]] = None) -> list:
        self._check_open()
        return self._conn.call("apply", None, list(names) if names else None)

    def store(self, names: Optional[Sequence[str]] = None) -> None:
        self._check_open()
        self._conn.call("store", None, list(names) if names else None)

    def counters(self) -> dict[str, int]:
        """The service's RPC counters (calls, failed_calls, clients, poll_subscribers, rows_sent...)."""
        self._check_open()
        return self._conn.call("counters")

    def poll(self, axes: Optional[Iterable[str]] = None, fields: Iterable[str] = ("position", "velocity", "status"),
             rate_hz: float = 100.0, *, mode: str = "auto", capacity: Optional[int] = None,
             keep: Optional[float] = 600.0) -> RemotePoller:
        """A subscription to the service's poll of ``axes`` (all by default) for ``fields`` at
        ``rate_hz``: programs asking the same axes, fields, rate and mode share one Poller in
        the service (N monitors cost one poll)."""
        self._check_open()
        names = list(axes) if axes is not None else None
        if isinstance(fields, str):
            fields = (fields,)
        reply = self._conn.call("poll", None, names, list(fields), rate_hz, mode=mode)
        return self._subscribed(reply, capacity, keep)

    def _subscribed(self, reply: Mapping[str, Any], capacity: Optional[int], keep: Optional[float]) -> RemotePoller:
        p = RemotePoller(self, reply, capacity=capacity, keep=keep)
        conn = self._conn
        with conn._lock:       # the early rows first, then the reader's (it needs this lock to find p)
            for rows, dropped in conn._early.pop(p.sub, ()):
                p._feed(rows, dropped)
            conn._subs[p.sub] = p
        self._pollers.append(p)
        return p

    # ---- lifetime --------------------------------------------------------------------------
    def _check_open(self) -> None:
        if self._closed:
            raise _core.ClosedError(f"bench {self.source} (served at {self.address}): closed")

    def close(self) -> None:
        """Ends this program's connection: its polls end, its drives close; nothing is stopped
        here (the with-block's and the exit hook's safety stop what this program moved)."""
        if self._closed:
            return
        self._closed = True
        for p in self._pollers:
            try:
                p.stop()
            except Exception:  # noqa: BLE001 - close the rest
                pass
        for d in self._axes.values():
            d.close()
        self._conn.close()

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> "RemoteBench":
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        # As a local bench's with-block, for what this program moved: its axes stop on the way
        # out (quick stop after an exception); axes it only read are another program's business.
        try:
            how = "quick_stop" if exc_type is not None else "stop"
            for d in self._axes.values():
                if d.commanded and not d.closed:
                    d._halt(how)
        finally:
            self.close()

    def __repr__(self) -> str:
        sim = " simulated" if self.simulated else ""
        return f"<RemoteBench {self.source}{sim} via {self.address}: {', '.join(self._axes)}>"


def _open(address: Any, timeout: float) -> RemoteBench:
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not math.isfinite(timeout) \
            or timeout <= 0:
        raise _core.InvalidArgument(f"connect timeout: seconds > 0, not {timeout!r}")
    path, service = resolve(address)
    conn = Connection(path, timeout=timeout)
    try:
        waiter = _SyncWaiter()
        cid = conn._register(waiter)
        conn._send(conn._message(cid, "hello", None, (), {}))
        if not waiter.event.wait(timeout):
            raise _core.TimeoutError(f"motorbus serve at {path}: no answer to hello within {timeout:g} s")
        if waiter.error is not None:
            raise waiter.error
        hello = waiter.value
        if not isinstance(hello, dict) or hello.get("protocol") != rpc.PROTOCOL:
            raise _core.ProtocolError(f"motorbus serve at {path}: protocol {hello.get('protocol')!r} "
                                      f"(this motorbus speaks {rpc.PROTOCOL})")
        return RemoteBench(conn, hello, service)
    except BaseException:
        conn.close()
        raise


def connect(address: Any, *, timeout: float = 5.0) -> RemoteBench:
    """The served bench at ``address``: a bench file whose ``motorbus serve`` runs (found through
    its lock file), a socket path, or ``"unix:/path.sock"``.  ``timeout``: seconds for the
    connection and its greeting."""
    return _open(address, timeout)


# ---- the awaitable face --------------------------------------------------------------------------
def _aio_bench_class() -> type:
    from .. import aio

    class AioRemoteBench(aio.Bench):
        """The awaitable face of a :class:`RemoteBench` (``await aio.Bench.connect(...)``): an
        ``aio.Bench`` whose axes are ``aio.Drive`` twins of RemoteDrives (cancelling an awaited
        move stops the motor, as for a local axis), plus the served bench's calls awaited."""

        def __init__(self, remote: RemoteBench, *, stop_timeout: float = aio.STOP_TIMEOUT) -> None:
            super().__init__(remote, stop_timeout=stop_timeout)      # type: ignore[arg-type]

        @property
        def source(self) -> str:
            return self.sync.source

        @property
        def simulated(self) -> bool:
            return self.sync.simulated

        @property
        def config(self) -> dict:
            return self.sync.config

        @property
        def info(self) -> dict:
            return self.sync.info

        def select(self, names: Optional[Sequence[str]] = None) -> dict:
            return {n: self[n] for n in names} if names else self.axes

        async def status(self) -> dict[str, DriveStatus]:
            self.sync._check_open()
            return await self.sync._conn.acall("status")

        async def read_params(self, names: Optional[Sequence[str]] = None, *, all_params: bool = False) -> dict:
            self.sync._check_open()
            return await self.sync._conn.acall("read_params", None, list(names) if names else None,
                                               all_params=all_params)

        async def diff(self, names: Optional[Sequence[str]] = None) -> list:
            self.sync._check_open()
            return await self.sync._conn.acall("diff", None, list(names) if names else None)

        async def apply(self, names: Optional[Sequence[str]] = None) -> list:
            self.sync._check_open()
            return await self.sync._conn.acall("apply", None, list(names) if names else None)

        async def store(self, names: Optional[Sequence[str]] = None) -> None:
            self.sync._check_open()
            await self.sync._conn.acall("store", None, list(names) if names else None)

        async def counters(self) -> dict:
            self.sync._check_open()
            return await self.sync._conn.acall("counters")

        async def poll(self, axes: Optional[Iterable[str]] = None,
                       fields: Iterable[str] = ("position", "velocity", "status"), rate_hz: float = 100.0, *,
                       mode: str = "auto", capacity: Optional[int] = None,
                       keep: Optional[float] = 600.0) -> RemotePoller:
            self.sync._check_open()
            if isinstance(fields, str):
                fields = (fields,)
            reply = await self.sync._conn.acall("poll", None, list(axes) if axes is not None else None,
                                                list(fields), rate_hz, mode=mode)
            return self.sync._subscribed(reply, capacity, keep)

        async def aclose(self) -> None:
            await asyncio.to_thread(self.sync.close)

        async def __aexit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
            try:
                how = "quick_stop" if exc_type is not None else "stop"
                halts = [d._halt(how) for d in self._axes.values() if d.sync.commanded and not d.closed]
                await asyncio.gather(*halts, return_exceptions=True)
            finally:
                await self.aclose()

        def __repr__(self) -> str:
            return f"<awaitable {self.sync!r}>"

    return AioRemoteBench


_AIO_CLASS: Optional[type] = None


def __getattr__(name: str) -> Any:
    if name == "AioRemoteBench":
        return _aio_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _aio_class() -> type:
    global _AIO_CLASS
    if _AIO_CLASS is None:
        _AIO_CLASS = _aio_bench_class()
    return _AIO_CLASS


async def aio_connect(address: Any, *, timeout: float = 5.0) -> Any:
    """``connect``, awaited (the connection is made off the loop): an ``AioRemoteBench``."""
    remote = await asyncio.to_thread(_open, address, timeout)
    return _aio_class()(remote)

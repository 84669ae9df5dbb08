"""The native face of ``motorbus serve``: the Drive API of a served bench over a local Unix socket.

motorbus's own programs (the CLI, scripts, notebooks, the pytest plugin, ``motorbus.ophyd``) reach a
served bench through :mod:`motorbus.serve.client`, which speaks this protocol (docs/serve-protocol.md):

* a **frame** is a 5-byte header, ``!IB`` (payload length, frame type), and its payload;
* type ``J`` (0x4A): a JSON object -- a call ``{"id", "call", "axis"?, "args", "kwargs"}``, its reply
  ``{"id", "ok": value}`` or ``{"id", "error": {...}}``.  Calls carry ids and each runs in its own task,
  so calls multiplex on one connection: a ``stop`` overtakes the ``move_to`` the same client awaits;
* type ``P`` (0x50): poll rows, binary -- ``<IIIQ`` (subscription, rows, columns, rows dropped so far)
  then ``rows x columns`` little-endian float64, row-major.

Every drive call goes through ``motorbus.aio`` on the service's loop (no blocking call there).  Errors
go back as their exact type with their fields (every ``MoveFailed`` subclass with axis, target,
position, side, reason...), and the client raises the same class.  When a connection closes, the
awaited moves it still has in flight are cancelled -- which stops those motors (motorbus.aio's
cancellation) -- because the program that awaited them is gone; a move it started with ``wait=False``
goes on.  Polls are shared: subscribers asking for the same axes, fields, rate and mode are served
from one :class:`motorbus.Poller`, its rows fanned out to each subscriber through a bounded queue
that drops its oldest rows (counted) when that subscriber reads too slowly.
"""
from __future__ import annotations

import asyncio
import collections
import contextlib
import dataclasses
import enum
import inspect
import itertools
import json
import logging
import math
import os
import socket
import stat
import struct
from typing import Any, Mapping, Optional

import numpy as np

from .. import _core
from ..drive import MoveFailed

log = logging.getLogger(__name__)

__all__ = ["start_rpc", "RpcFace", "PROTOCOL", "HEADER", "FRAME_JSON", "FRAME_ROWS", "ROWS_HEADER",
           "MAX_FRAME", "encode", "decode", "encode_error", "decode_error", "served_elsewhere"]

#: Protocol version said in the ``hello`` reply.
PROTOCOL = 1
HEADER = struct.Struct("!IB")          # payload length, frame type
FRAME_JSON = 0x4A                      # "J"
FRAME_ROWS = 0x50                      # "P"
ROWS_HEADER = struct.Struct("<IIIQ")   # subscription id, rows, columns, rows dropped so far (this subscriber)
#: The largest frame either side accepts: beyond it the peer is not speaking this protocol.
MAX_FRAME = 64 * 1024 * 1024
#: Chunks of rows a subscriber may have waiting; more and the oldest is dropped (counted).
SUB_QUEUE_CHUNKS = 64
#: Calls whose task is cancelled (stopping the motor) when the connection that awaits them closes.
_AWAITED_MOTION = {"move_to", "move_by", "home"}
#: Calls that start a motion whose outcome a later wait_idle of the same client reports.
_STARTS = {"move_to", "move_by", "home", "jog"}


# ---- values on the wire ----------------------------------------------------------------------
def _dataclass_types() -> dict[str, type]:
    from ..bench import AxisConfig, ParamDiff, StartReport
    from ..drive import DriveStatus, MoveOutcome, ParamInfo, Units

    return {c.__name__: c for c in (DriveStatus, MoveOutcome, ParamInfo, ParamDiff, StartReport, Units, AxisConfig)}


_DATACLASSES: dict[str, type] = {}


def _types() -> dict[str, type]:
    if not _DATACLASSES:
        _DATACLASSES.update(_dataclass_types())
    return _DATACLASSES


def encode(v: Any) -> Any:
    """A value of the Drive API as JSON-able data: motorbus' dataclasses, exceptions, tuples,
    sets, enums and bytes tagged with ``"$"`` (decode() gives them back); floats as they are
    (NaN and inf too: Python's json writes them, and both ends are Python)."""
    if v is None or isinstance(v, (bool, int, str)):
        return v
    if isinstance(v, float):
        return v
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, BaseException):
        return encode_error(v)
    if isinstance(v, enum.Enum):
        return {"$": "enum", "type": type(v).__name__, "value": encode(v.value)}
    if dataclasses.is_dataclass(v) and not isinstance(v, type) and type(v).__name__ in _types():
        out = {"$": type(v).__name__}
        for f in dataclasses.fields(v):
            out[f.name] = encode(getattr(v, f.name))
        return out
    if isinstance(v, tuple):
        return {"$": "tuple", "items": [encode(x) for x in v]}
    if isinstance(v, (set, frozenset)):
        return {"$": "set", "items": [encode(x) for x in v]}
    if isinstance(v, list):
        return [encode(x) for x in v]
    if isinstance(v, Mapping):
        if all(isinstance(k, str) for k in v) and "$" not in v:
            return {k: encode(x) for k, x in v.items()}
        return {"$": "dict", "items": [[encode(k), encode(x)] for k, x in v.items()]}
    if isinstance(v, (bytes, bytearray)):
        return {"$": "bytes", "hex": bytes(v).hex()}
    if isinstance(v, np.ndarray):
        return [encode(x) for x in v.tolist()]
    return {"$": "repr", "text": repr(v)}


def decode(v: Any) -> Any:
    if isinstance(v, list):
        return [decode(x) for x in v]
    if not isinstance(v, dict):
        return v
    tag = v.get("$")
    if tag is None:
        return {k: decode(x) for k, x in v.items()}
    if tag == "tuple":
        return tuple(decode(x) for x in v["items"])
    if tag == "set":
        return frozenset(decode(x) for x in v["items"])
    if tag == "dict":
        return {decode(k): decode(x) for k, x in v["items"]}
    if tag == "bytes":
        return bytes.fromhex(v["hex"])
    if tag == "repr":
        return v["text"]
    if tag == "error":
        return decode_error(v)
    if tag == "enum":
        if v["type"] == "Capability":
            from ..drive import Capability

            try:
                return Capability(decode(v["value"]))
            except ValueError:
                pass
        return decode(v["value"])
    cls = _types().get(tag)
    if cls is None:
        return {k: decode(x) for k, x in v.items() if k != "$"}
    fields = {f.name for f in dataclasses.fields(cls)}
    return cls(**{k: decode(x) for k, x in v.items() if k in fields})


def _qualname(cls: type) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"


_ERRORS: dict[str, type] = {}


def _error_classes() -> dict[str, type]:
    """Every exception class a served call can raise, by module-qualified name: motorbus'
    typed errors (the C++ ones, MoveFailed and its subclasses, BenchFileError...) and the
    builtins."""
    import builtins
    import importlib

    if _ERRORS:
        return _ERRORS
    modules = [builtins]
    for name in ("motorbus._core", "motorbus", "motorbus.drive", "motorbus.bench", "motorbus.canopen",
                 "motorbus._stop_at_exit", "motorbus.serve.lockfile"):
        try:
            modules.append(importlib.import_module(name))
        except Exception:  # noqa: BLE001 - a module that is not there (yet) adds no class
            continue
    for m in modules:
        for attr in dir(m):
            obj = getattr(m, attr, None)
            if isinstance(obj, type) and issubclass(obj, BaseException):
                _ERRORS.setdefault(_qualname(obj), obj)
    return _ERRORS


def encode_error(e: BaseException) -> dict:
    """An exception as data: its class (and its bases, so a client that lacks the class
    raises the nearest one it has), message, fields and notes."""
    cls = type(e)
    fields = {}
    for k, x in getattr(e, "__dict__", {}).items():
        if k.startswith("_"):
            continue
        try:
            fields[k] = encode(x)
        except Exception:  # noqa: BLE001 - a field that cannot be said is left out, not the error
            continue
    out = {"$": "error", "type": _qualname(cls), "bases": [_qualname(b) for b in cls.__mro__[1:]
                                                             if issubclass(b, BaseException)],
           "message": str(e), "fields": fields, "notes": [str(n) for n in getattr(e, "__notes__", ())]}
    if all(x is None or isinstance(x, (str, int, float)) for x in e.args):
        out["args"] = list(e.args)     # str() of some classes (KeyError) is not their argument
    return out


def decode_error(d: Mapping[str, Any]) -> BaseException:
    """The exception an ``encode_error`` describes, of the same class where this process
    has it (else the nearest base it has), with the same message and fields."""
    classes = _error_classes()
    cls = None
    for name in [d["type"], *d.get("bases", ())]:
        cls = classes.get(name)
        if cls is not None:
            break
    message = d.get("message", "")
    args = tuple(d["args"]) if isinstance(d.get("args"), list) else (message,)
    if cls is None or cls in (BaseException, Exception):
        cls, message = _core.MotorbusError, f"{d['type'].rsplit('.', 1)[-1]}: {message}"
        args = (message,)
    e: Optional[BaseException] = None
    for make in (lambda: cls(message), lambda: cls.__new__(cls)):
        # Its own constructor with the message (most take one), else made bare (ServedElsewhere
        # takes other arguments); the message is set as it was either way.
        try:
            e = make()
            e.args = args
            break
        except Exception:  # noqa: BLE001 - the next way
            e = None
    if e is None:
        e = _core.MotorbusError(f"{d['type'].rsplit('.', 1)[-1]}: {message}")
    for k, x in d.get("fields", {}).items():
        try:
            setattr(e, k, decode(x))
        except Exception:  # noqa: BLE001
            continue
    notes = [str(n) for n in d.get("notes", ())]
    if notes:
        e.__notes__ = notes          # what add_note keeps (3.11+), set the same way on any version
    return e


def served_elsewhere(info: Mapping[str, Any], what: str) -> BaseException:
    """The refusal of something that needs the transports while the service holds them
    (serve.lockfile's ``ServedElsewhere``: "<bench> is served by motorbus serve (pid N):
    <what> needs the transports; stop the service first")."""
    from .lockfile import ServedElsewhere

    pid = info.get("pid")
    return ServedElsewhere(str(info.get("bench") or "the bench"), int(pid) if isinstance(pid, int) else os.getpid(),
                           what)


def dumps(obj: Any) -> bytes:
    return json.dumps(obj, separators=(",", ":")).encode()


def frame(kind: int, payload: bytes) -> bytes:
    if len(payload) > MAX_FRAME:
        raise _core.InvalidArgument(f"motorbus serve: a frame of {len(payload)} bytes (at most {MAX_FRAME})")
    return HEADER.pack(len(payload), kind) + payload


def rows_frame(sub: int, rows: np.ndarray, dropped: int) -> bytes:
    rows = np.ascontiguousarray(rows, dtype="<f8")
    n, cols = rows.shape
    return frame(FRAME_ROWS, ROWS_HEADER.pack(sub, n, cols, dropped) + rows.tobytes())


# ---- the server --------------------------------------------------------------------------------
class _Sub:
    """One subscriber of a shared poll: its columns and its bounded queue."""

    def __init__(self, sid: int, conn: "_Conn", shared: "_SharedPoll", columns: list[str]) -> None:
        self.id, self.conn, self.shared, self.columns = sid, conn, shared, columns
        self.queue: collections.deque = collections.deque()
        self.dropped = 0
        self.sent = 0

    def push(self, rows: np.ndarray) -> None:
        if len(self.queue) >= SUB_QUEUE_CHUNKS:
            old = self.queue.popleft()
            n = 0 if isinstance(old, dict) else len(old)
            self.dropped += n
            self.conn.face.counters["rows_dropped"] += n
        self.queue.append(rows)
        self.conn.wake.set()


class _SharedPoll:
    """One motorbus.Poller over the service's drives, fanned out to its subscribers."""

    def __init__(self, face: "RpcFace", key: tuple, poller: Any) -> None:
        self.face, self.key, self.poller = face, key, poller
        self.subs: dict[int, _Sub] = {}
        self.task: Optional[asyncio.Task] = None

    async def run(self, rows: int) -> None:
        error: Optional[BaseException] = None
        try:
            async for chunk in self.poller.chunks(rows):
                for sub in list(self.subs.values()):
                    sub.push(np.column_stack([chunk[c] for c in sub.columns]))
        except asyncio.CancelledError:
            raise
        except Exception as e:  # noqa: BLE001 - a poll that ends on its own ends its subscribers' streams
            log.exception("motorbus serve: shared poll %s ended", self.key)
            error = e
        # The poll ended by itself (every group stopped: a link failed): each subscriber is told,
        # after the rows it still has queued, so its poller's stream ends instead of waiting.
        if self.face._polls.get(self.key) is self:      # a new subscriber gets a new Poller
            del self.face._polls[self.key]
            self.face.counters["pollers"] -= 1
        try:
            await asyncio.to_thread(self.poller.stop)
        except Exception:  # noqa: BLE001 - what it could not close is in its stats
            pass
        groups = self.poller.stats
        for sub in list(self.subs.values()):
            sub.conn.event({"event": "poll_ended", "sub": sub.id, "stats": encode(groups),
                            "error": None if error is None else encode_error(error)})


class _Conn:
    def __init__(self, face: "RpcFace", reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.face, self.reader, self.writer = face, reader, writer
        self.replies: collections.deque = collections.deque()
        self.wake = asyncio.Event()
        self.calls: dict[Any, tuple[asyncio.Task, bool]] = {}   # id -> (task, cancelled when the client goes)
        self.subs: dict[int, _Sub] = {}
        #: axis -> the motion this client started without waiting for it (drive._move), whose
        #: outcome its next wait_idle on that axis reports.
        self.started: dict[str, Any] = {}
        self.closed = False

    def reply(self, payload: dict) -> None:
        if self.closed:
            return
        self.replies.append(frame(FRAME_JSON, dumps(payload)))
        self.wake.set()

    def event(self, payload: dict) -> None:
        """A message that answers no call (a poll that ended), sent after the rows queued
        before it: it goes through the subscription's queue, in order."""
        sub = self.subs.get(payload.get("sub"))
        if sub is None or self.closed:
            return
        sub.queue.append(payload)
        self.wake.set()

    async def write_loop(self) -> None:
        """Replies first, then a chunk per subscription, round after round: a slow reader
        delays only its own stream (its queue drops its oldest rows meanwhile)."""
        while True:
            await self.wake.wait()
            self.wake.clear()
            while self.replies or any(s.queue for s in self.subs.values()):
                parts = []
                while self.replies:
                    parts.append(self.replies.popleft())
                for s in list(self.subs.values()):
                    if s.queue:
                        rows = s.queue.popleft()
                        if isinstance(rows, dict):          # an event, after the rows before it
                            parts.append(frame(FRAME_JSON, dumps(rows)))
                            continue
                        parts.append(rows_frame(s.id, rows, s.dropped))
                        s.sent += len(rows)
                        self.face.counters["rows_sent"] += len(rows)
                self.writer.write(b"".join(parts))
                await self.writer.drain()


class RpcFace:
    """The running native face: ``path`` (the Unix socket), ``counters`` (calls,
    failed_calls, clients, connections, poll_subscribers, pollers, rows_sent, rows_dropped)."""

    def __init__(self, bench: Any, path: str, info: Mapping[str, Any]) -> None:
        self.bench, self.path, self.info = bench, path, dict(info)
        self.counters: dict[str, int] = dict.fromkeys(
            ("calls", "failed_calls", "clients", "connections", "poll_subscribers", "pollers", "rows_sent",
             "rows_dropped"), 0)
        self._server: Optional[asyncio.AbstractServer] = None
        self._conns: set[_Conn] = set()
        self._handlers: set[asyncio.Task] = set()
        self._orphans: set[asyncio.Task] = set()        # calls of closed connections, finishing
        self._polls: dict[tuple, _SharedPoll] = {}
        self._sub_ids = itertools.count(1)
        self._poll_lock = asyncio.Lock()
        self._closed = False

    # ---- lifetime --------------------------------------------------------------------------
    async def _start(self) -> None:
        _free_socket_path(self.path)
        self._server = await asyncio.start_unix_server(self._serve, path=self.path, limit=MAX_FRAME)
        with contextlib.suppress(OSError):
            os.chmod(self.path, 0o600)     # the bench's user only: the socket moves motors

    async def close(self) -> None:
        """Stops accepting, closes every connection (their awaited moves are stopped, as
        when a client goes), stops the shared polls and removes the socket."""
        if self._closed:
            return
        self._closed = True
        if self._server is not None:
            self._server.close()
        for t in list(self._handlers):
            t.cancel()
        if self._handlers:
            await asyncio.gather(*self._handlers, return_exceptions=True)
        if self._orphans:
            await asyncio.gather(*self._orphans, return_exceptions=True)
        for shared in list(self._polls.values()):
            await self._end_poll(shared)
        with contextlib.suppress(OSError):
            if stat.S_ISSOCK(os.stat(self.path).st_mode):
                os.unlink(self.path)

    # ---- a connection ----------------------------------------------------------------------
    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        self._handlers.add(task)
        conn = _Conn(self, reader, writer)
        self._conns.add(conn)
        self.counters["clients"] += 1
        self.counters["connections"] += 1
        writing = asyncio.ensure_future(conn.write_loop())
        try:
            while True:
                head = await reader.readexactly(HEADER.size)
                size, kind = HEADER.unpack(head)
                if size > MAX_FRAME or kind != FRAME_JSON:
                    log.warning("motorbus serve: a client sent a frame of type %#x, %d bytes: closing it", kind, size)
                    break
                msg = json.loads(await reader.readexactly(size))
                self._dispatch(conn, msg)
        except (asyncio.IncompleteReadError, ConnectionError, json.JSONDecodeError, UnicodeDecodeError):
            pass
        except Exception:  # noqa: BLE001 - a bug must end this connection, not the service
            log.exception("motorbus serve: a connection ended on an error")
        except asyncio.CancelledError:
            pass
        finally:
            await self._drop(conn)
            writing.cancel()
            with contextlib.suppress(BaseException):
                await writing
            with contextlib.suppress(Exception):
                writer.close()
            self._conns.discard(conn)
            self._handlers.discard(task)

    async def _drop(self, conn: _Conn) -> None:
        """The client is gone: its awaited moves are cancelled (aio stops those motors), its
        other calls run to their end unheard, its subscriptions end."""
        conn.closed = True
        self.counters["clients"] -= 1
        for task, awaited in list(conn.calls.values()):
            if not task.done():
                if awaited:
                    task.cancel()
                self._orphans.add(task)
                task.add_done_callback(self._orphans.discard)
        for sid in list(conn.subs):
            await self._unsubscribe(conn, sid)

    def _dispatch(self, conn: _Conn, msg: Any) -> None:
        cid = msg.get("id") if isinstance(msg, dict) else None
        why = None
        if not isinstance(msg, dict) or not isinstance(msg.get("call"), str):
            why = 'a call is {"id", "call", "axis"?, "args", "kwargs"}'
        elif isinstance(cid, bool) or not isinstance(cid, (int, str)):
            why = f"a call's id is an integer or a text, not {cid!r}"
        elif cid in conn.calls:
            why = f"call id {cid!r} is already in flight on this connection"
        elif not isinstance(msg.get("args", []), list) or not isinstance(msg.get("kwargs", {}), dict):
            why = "a call's args are a list and its kwargs an object"
        if why is not None:
            self.counters["calls"] += 1
            self.counters["failed_calls"] += 1
            conn.reply({"id": cid if isinstance(cid, (int, str)) else None,
                        "error": encode_error(_core.InvalidArgument(f"motorbus serve: {why}"))})
            return
        call = msg["call"]
        self.counters["calls"] += 1
        kwargs = msg.get("kwargs") or {}
        awaited = (call in _AWAITED_MOTION and kwargs.get("wait", True)) \
            or (call == "move_together" and kwargs.get("wait", True)) \
            or (call == "wait_idle" and self._started_here(conn, msg.get("axis")))
        task = asyncio.ensure_future(self._run_call(conn, cid, call, msg))
        conn.calls[cid] = (task, awaited)
        task.add_done_callback(lambda _t: conn.calls.pop(cid, None))

    async def _run_call(self, conn: _Conn, cid: Any, call: str, msg: dict) -> None:
        try:
            args = [decode(a) for a in msg.get("args") or ()]
            kwargs = {k: decode(v) for k, v in (msg.get("kwargs") or {}).items()}
            value = await self._call(conn, call, msg.get("axis"), args, kwargs)
            reply = {"id": cid, "ok": encode(value)}
        except asyncio.CancelledError:
            self.counters["failed_calls"] += 1
            conn.reply({"id": cid, "error": encode_error(_core.MotorbusError(
                f"motorbus serve: {call} cancelled (its client went away or the service is closing)"))})
            raise
        except Exception as e:  # noqa: BLE001 - every error goes back to the caller, typed
            self.counters["failed_calls"] += 1
            reply = {"id": cid, "error": encode_error(e)}
        conn.reply(reply)

    # ---- the calls -------------------------------------------------------------------------
    async def _call(self, conn: _Conn, call: str, axis: Optional[str], args: list, kwargs: dict) -> Any:
        bench = self.bench
        if axis is not None:
            if not isinstance(axis, str):
                raise _core.InvalidArgument(f"motorbus serve: axis is a name, not {axis!r}")
            d = bench[axis]
            verb = _AXIS_CALLS.get(call)
            if verb is None:
                raise _core.InvalidArgument(f"motorbus serve: no axis call {call!r} (calls: "
                                            f"{', '.join(sorted(_AXIS_CALLS))})")
            _check_arguments(call, verb, (self, d), args, kwargs)
            if call == "wait_idle":
                return await self._wait_idle(conn, axis, d, *args, **kwargs)
            value = await verb(self, d, *args, **kwargs)
            if call in _STARTS:
                if call == "jog" or not kwargs.get("wait", True):
                    conn.started[axis] = d.sync._move      # its outcome is this client's wait_idle's
                else:
                    conn.started.pop(axis, None)           # reported by the call itself
            return value
        verb = _BENCH_CALLS.get(call)
        if verb is None:
            raise _core.InvalidArgument(f"motorbus serve: no call {call!r} (bench calls: "
                                        f"{', '.join(sorted(_BENCH_CALLS))}; axis calls take \"axis\")")
        _check_arguments(call, verb, (self, conn), args, kwargs)
        value = await verb(self, conn, *args, **kwargs)
        if call == "move_together" and isinstance(args[0], Mapping):
            for name in args[0]:
                if kwargs.get("wait", True):
                    conn.started.pop(name, None)
                else:
                    conn.started[name] = self.bench[name].sync._move
        return value

    def _started_here(self, conn: _Conn, axis: Any) -> bool:
        """A wait_idle stops the motor when its client goes only if that client started the
        motion it waits for (a program waiting on another's move does not own it)."""
        mine = conn.started.get(axis) if isinstance(axis, str) else None
        if mine is None:
            return False
        d = self.bench.axes.get(axis)
        return d is not None and d.sync._move is mine

    async def _wait_idle(self, conn: _Conn, axis: str, d: Any, timeout: Optional[float] = None) -> None:
        """``wait_idle`` as this client's own: after a move it started without waiting, it
        raises that move's MoveFailed even if another client's reading (a monitor's status)
        judged the move first -- on a local Drive nobody else reads it in between."""
        mine = conn.started.get(axis)
        try:
            await d.wait_idle(timeout)
        except MoveFailed:
            conn.started.pop(axis, None)
            raise
        if mine is None:
            return
        conn.started.pop(axis, None)
        drive = d.sync
        last = drive._last_move
        if drive._move is mine and mine.judged and last is not None and last.error is not None:
            raise last.error

    def describe(self) -> dict:
        """What a client needs to build its RemoteBench without asking again."""
        sync = self.bench.sync
        axes = {}
        for name, d in self.bench.axes.items():
            drive = d.sync
            axes[name] = {"kind": drive.kind, "units": drive.units, "capabilities": sorted(c.value for c in
                                                                                         drive.capabilities),
                          "transport": type(drive).transport, "has_watchdog": bool(type(drive).has_watchdog),
                          "config": sync.config.get(name), "has_console": _has_console(drive),
                          "pollable": type(drive).provides("poll_fields") or type(drive).provides("capture_fields")}
        return {"protocol": PROTOCOL, "info": self.info, "source": sync.source, "simulated": bool(sync.simulated),
                "lines": list(sync.lines), "buses": list(sync.buses), "axes": axes}

    # -- polls --
    async def subscribe(self, conn: _Conn, axes: Optional[list] = None, fields: Any = None, rate_hz: float = 100.0,
                        mode: str = "auto") -> dict:
        from ..poller import FIELDS, _check_fields

        names = list(axes) if axes else list(self.bench.axes)
        for n in names:
            self.bench[n]                     # the bench's check and message
        if len(set(names)) != len(names):
            raise _core.InvalidArgument(f"poll axes {names!r}: each at most once")
        fields = _check_fields(FIELDS if fields is None else fields)
        if isinstance(rate_hz, bool) or not isinstance(rate_hz, (int, float)) or not math.isfinite(rate_hz) \
                or not 0 < rate_hz <= 10_000:
            raise _core.InvalidArgument(f"poll rate_hz: a number in (0, 10000] through the service, not {rate_hz!r}")
        key = (tuple(names), fields, float(rate_hz), mode)
        async with self._poll_lock:
            shared = self._polls.get(key)
            if shared is None:
                shared = await self._start_poll(key)
            columns = ["t"] + [f"{a}.{c}" for a in names for c in ("t",) + fields]
            sub = _Sub(next(self._sub_ids), conn, shared, columns)
            shared.subs[sub.id] = sub
            conn.subs[sub.id] = sub
            self.counters["poll_subscribers"] += 1
        p = shared.poller
        return {"sub": sub.id, "columns": columns, "rate_hz": p.rate_hz, "fields": list(fields), "axes": names,
                "modes": dict(p.modes), "period": p.period_ns / 1e9}

    async def _start_poll(self, key: tuple) -> _SharedPoll:
        from ..poller import Poller

        names, fields, rate, mode = key
        drives = {n: self.bench[n].sync for n in names}
        # Starting a poll sets drives up (a capture maps TPDOs by SDO): off the loop.
        poller = await asyncio.to_thread(Poller, drives, fields, rate, mode=mode, keep=0)
        shared = _SharedPoll(self, key, poller)
        self._polls[key] = shared
        self.counters["pollers"] += 1
        rows = max(1, int(round(rate / 50)))          # ~50 chunks a second: a monitor's row lags <= 20 ms
        shared.task = asyncio.ensure_future(shared.run(rows))
        return shared

    async def _unsubscribe(self, conn: _Conn, sid: int) -> bool:
        sub = conn.subs.pop(sid, None)
        if sub is None:
            return False
        shared = sub.shared
        shared.subs.pop(sid, None)
        self.counters["poll_subscribers"] -= 1
        if not shared.subs:
            async with self._poll_lock:
                if not shared.subs and self._polls.get(shared.key) is shared:
                    await self._end_poll(shared)
        return True

    async def _end_poll(self, shared: _SharedPoll) -> None:
        self._polls.pop(shared.key, None)
        self.counters["pollers"] -= 1
        if shared.task is not None:
            shared.task.cancel()
            with contextlib.suppress(BaseException):
                await shared.task
        await asyncio.to_thread(shared.poller.stop)


def _check_arguments(call: str, verb: Any, head: tuple, args: list, kwargs: dict) -> None:
    """Arguments the call does not take are the caller's mistake, said as one (not a TypeError
    from deep inside the service)."""
    try:
        inspect.signature(verb).bind(*head, *args, **kwargs)
    except TypeError as e:
        raise _core.InvalidArgument(f"motorbus serve: {call}: {e}") from None


def _has_console(drive: Any) -> bool:
    from ..drive import Drive

    return type(drive)._console is not Drive._console


def _free_socket_path(path: str) -> None:
    """A socket file left by a dead service is removed; one a live service answers on, or a
    file that is not a socket, is refused."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return
    if not stat.S_ISSOCK(st.st_mode):
        raise _core.InvalidArgument(f"motorbus serve: {path} exists and is not a socket")
    probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        probe.settimeout(1.0)
        probe.connect(path)
    except OSError:
        os.unlink(path)               # nobody answers: a dead service's socket
        return
    finally:
        probe.close()
    raise _core.InvalidArgument(f"motorbus serve: another service answers on {path}")


# ---- the call tables: (face, aio.Drive, *args) / (face, conn, *args) -> value -------------------
async def _move_to(face: RpcFace, d: Any, position: float, *, velocity: Optional[float] = None, wait: bool = True,
                   timeout: Optional[float] = None) -> None:
    await d.move_to(position, velocity=velocity, wait=wait, timeout=timeout)


async def _move_by(face: RpcFace, d: Any, distance: float, *, velocity: Optional[float] = None, wait: bool = True,
                   timeout: Optional[float] = None) -> None:
    await d.move_by(distance, velocity=velocity, wait=wait, timeout=timeout)


async def _home(face: RpcFace, d: Any, method: Any = None, *, wait: bool = True,
                timeout: Optional[float] = None) -> None:
    await d.home(method, wait=wait, timeout=timeout)


async def _console(face: RpcFace, d: Any, line: Any = "") -> str:
    raise served_elsewhere(face.info, f"a protocol console (axis {d.name!r})")


async def _params_describe(face: RpcFace, d: Any, name: str) -> Any:
    return d.params.describe(name)


async def _params_list(face: RpcFace, d: Any) -> list:
    return [d.params.describe(n) for n in d.params]


_AXIS_CALLS = {
    "enable": lambda f, d: d.enable(),
    "disable": lambda f, d: d.disable(),
    "move_to": _move_to,
    "move_by": _move_by,
    "jog": lambda f, d, velocity: d.jog(velocity),
    # ``by``: who stopped it, for the move's outcome ("the cancellation of the awaiting task"
    # when a client's aio face stops a move whose task was cancelled).
    "stop": lambda f, d, by="stop()": d.sync._co_stop(by=str(by)),
    "quick_stop": lambda f, d, by="quick_stop()": d.sync._co_quick_stop(by=str(by)),
    "home": _home,
    "wait_idle": lambda f, d, timeout=None: d.wait_idle(timeout),
    "clear_faults": lambda f, d: d.clear_faults(),
    "store": lambda f, d: d.store(),
    "console": _console,
    "position": lambda f, d: d.position(),
    "velocity": lambda f, d: d.velocity(),
    "status": lambda f, d: d.status(),
    "travel_limits": lambda f, d: d.travel_limits(),
    "params_get": lambda f, d, name: d.params.get(name),
    "params_set": lambda f, d, name, value: d.params.set(name, value),
    "params_describe": _params_describe,
    "params_list": _params_list,
}


def _plain(fn: Any) -> Any:
    async def call(face: RpcFace, d: Any) -> Any:
        return fn(d)
    return call


_AXIS_CALLS.update({
    "units": _plain(lambda d: d.units),
    "kind": _plain(lambda d: d.kind),
    "capabilities": _plain(lambda d: d.capabilities),
    "last_move": _plain(lambda d: d.sync._last_move),
})


async def _b_hello(face: RpcFace, conn: _Conn) -> dict:
    return face.describe()


async def _b_info(face: RpcFace, conn: _Conn) -> dict:
    return dict(face.info)


async def _b_counters(face: RpcFace, conn: _Conn) -> dict:
    return dict(face.counters)


async def _b_move_together(face: RpcFace, conn: _Conn, targets: Mapping[str, float], *, relative: bool = False,
                           velocity: Optional[float] = None, wait: bool = True,
                           timeout: Optional[float] = None) -> Any:
    return await face.bench.move_together(targets, relative=relative, velocity=velocity, wait=wait, timeout=timeout)


async def _b_stop_all(face: RpcFace, conn: _Conn, how: str = "stop") -> list:
    return [[name, e] for name, e in await face.bench.stop_all(how)]


async def _b_status(face: RpcFace, conn: _Conn) -> dict:
    return await face.bench.status()


# The bench's configuration verbs are the Bench's own coroutines (Bench._co_diff...), awaited
# on the service's loop: each parameter read and write goes through the axis' link worker.
async def _b_read_params(face: RpcFace, conn: _Conn, names: Optional[list] = None, *,
                         all_params: bool = False) -> dict:
    return await face.bench.sync._co_read_params(names, all_params=all_params)


async def _b_diff(face: RpcFace, conn: _Conn, names: Optional[list] = None) -> list:
    return await face.bench.sync._co_diff(names)


async def _b_apply(face: RpcFace, conn: _Conn, names: Optional[list] = None) -> list:
    return await face.bench.sync._co_apply(names)


async def _b_store(face: RpcFace, conn: _Conn, names: Optional[list] = None) -> None:
    await face.bench.sync._co_store(names)


async def _b_poll(face: RpcFace, conn: _Conn, axes: Optional[list] = None, fields: Any = None,
                  rate_hz: float = 100.0, mode: str = "auto") -> dict:
    return await face.subscribe(conn, axes, fields, rate_hz, mode)


async def _b_unpoll(face: RpcFace, conn: _Conn, sub: int) -> bool:
    return await face._unsubscribe(conn, sub)


async def _b_poll_stats(face: RpcFace, conn: _Conn, sub: int) -> dict:
    s = conn.subs.get(sub)
    if s is None:
        raise _core.InvalidArgument(f"motorbus serve: no poll subscription {sub} on this connection")
    return {"stats": s.shared.poller.stats, "dropped": s.dropped, "sent": s.sent,
            "subscribers": len(s.shared.subs), "running": s.shared.poller.running,
            "overflowed": s.shared.poller.overflowed}


async def _b_console(face: RpcFace, conn: _Conn, *args: Any, **kwargs: Any) -> None:
    raise served_elsewhere(face.info, "a protocol console")


_BENCH_CALLS = {
    "hello": _b_hello, "info": _b_info, "counters": _b_counters, "move_together": _b_move_together,
    "stop_all": _b_stop_all, "status": _b_status, "read_params": _b_read_params, "diff": _b_diff,
    "apply": _b_apply, "store": _b_store, "poll": _b_poll, "unpoll": _b_unpoll, "poll_stats": _b_poll_stats,
    "console": _b_console,
}


async def start_rpc(bench: Any, path: str, *, info: Mapping[str, Any]) -> RpcFace:
    """Serves ``bench`` (a ``motorbus.aio.Bench``) on the Unix socket ``path`` from the running
    loop; ``info``: the service's (pid, bench, socket, CA prefix...), the ``info`` call's answer."""
    from .. import aio

    if not isinstance(bench, aio.Bench):
        raise _core.InvalidArgument(f"start_rpc: a motorbus.aio.Bench, not {type(bench).__name__}")
    path = os.fspath(path)
    if len(path.encode()) > 107:
        raise _core.InvalidArgument(f"start_rpc: the socket path {path!r} is longer than a Unix socket "
                                    "address holds (107 bytes)")
    face = RpcFace(bench, path, info)
    await face._start()
    return face

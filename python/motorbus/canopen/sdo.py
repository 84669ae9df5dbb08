"""SDO client, the SDO errors (C++ core; see docs/canopen.md), and ``node.sdo``:
objects of a remote node addressed as the `canopen` package does.

    node.sdo[0x1018][1].raw                 # by index and sub-index
    node.sdo["Identity object"]["Vendor-ID"].raw     # by name (the node has an OD / EDS)
    node.sdo["Device name"].value           # typed: int, float, bool, str or bytes per the data type
    node.sdo[0x2000][0].write(1234, size=4) # no OD: the size of an integer must be given

The awaitable face, on the same objects (any loop; no thread per transfer):

    await node.sdo["Device name"].get()     # as .value
    await node.sdo["Controlword"].set(0x0F) # as .value = 0x0F
    await node.sdo[0x1018][1].get_raw()     # as .raw;  set_raw(v, size=) as write()
    await node.sdo.upload_async(0x1F50, 1, block=True)   # any size, as upload()
    await node.sdo.download_async(0x1F50, 1, data)       # as download()

Each is the blocking call's logic run awaited (``.raw`` is ``faces.run(get_raw())``):
one implementation of the typing, two faces.  The transfer itself runs in C++ on
the bus's receive thread and completes through the loop's completion queue
(``faces.LoopBridge``); the loop arms the response deadline (``call_later`` ->
``SdoClient.check_deadline()``).  Cancelling the await withdraws the transfer (a
running one is aborted on the wire, 0x08000000) and leaves the channel usable.
"""
from __future__ import annotations

import asyncio
import os
import time
from typing import Any, Callable, Iterator, Optional, Union

from .. import _core, faces
from .._core import SdoAbortError, SdoProtocolError, SdoTimeout  # noqa: F401
from .._core.canopen import ABORT_CODES, SdoClient, SdoClientCounters, abort_text  # noqa: F401
from .od import NotFound, ObjectDictionary, Variable

__all__ = ["SdoClient", "SdoClientCounters", "SdoAbortError", "SdoTimeout", "SdoProtocolError", "abort_text",
           "ABORT_CODES", "SdoVariables", "SdoObject", "SdoVariable", "upload_async", "download_async"]

# CiA 301 types whose value is an integer (BOOLEAN, INTEGERn, UNSIGNEDn):
# `.raw` gives and takes an int for them, bytes for every other type.
_INTEGER_TYPES = frozenset({0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x10}) | frozenset(range(0x12, 0x1C))

Key = Union[int, str]

_NS = 1e-9
# The longest the loop sleeps before asking the client again when it reports no
# deadline (the transfer is queued behind a blocking one) or an infinite timeout.
_RECHECK_S = 1.0
#: How long an awaited transfer that is the loop's only one polls for its answer
#: before the loop thread sleeps (0 = never): at most this long, other tasks wait.
_SPIN_NS = 20_000
_yield = getattr(os, "sched_yield", lambda: None)
#: Answers a task may take by polling before it yields to the loop once (~100 us).
_BUDGET = 16


class _Yield:
    """``await _YIELD``: lets the loop run one round (as ``asyncio.sleep(0)``, without its call)."""

    __slots__ = ()

    def __await__(self):
        yield


_YIELD = _Yield()


class _Deadlines:
    """The response deadlines of one loop's awaited transfers: one loop timer, armed
    at the earliest deadline, that calls ``check_deadline()`` of every client with a
    transfer awaited (which times the running one out, sending the abort) and
    re-arms at the nearest deadline they report.  No thread, and no timer per
    transfer: a read costs a dict update, not a timer heap push and cancel."""

    __slots__ = ("loop", "pending", "handle", "when", "budget")

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self.budget = _BUDGET              # answers taken without yielding, before a yield
        self.pending: dict = {}            # client -> awaited transfers not completed
        self.handle: Optional[asyncio.TimerHandle] = None
        self.when = float("inf")           # loop time the timer fires

    def add(self, client: SdoClient) -> None:
        n = self.pending.get(client, 0)
        self.pending[client] = n + 1
        if n == 0:                          # this client's deadline may come before the armed one
            at = self.loop.time() + min(client.timeout, _RECHECK_S)
            if at < self.when:
                self._arm(at)

    def done(self, client: SdoClient) -> None:
        n = self.pending[client] - 1
        if n:
            self.pending[client] = n
        else:
            del self.pending[client]       # the timer may fire for nobody: cheaper than cancelling it

    def _arm(self, at: float) -> None:
        if self.handle is not None:
            self.handle.cancel()
        self.when = at
        self.handle = self.loop.call_at(at, self._fire)

    def _fire(self) -> None:
        self.handle, self.when = None, float("inf")
        if not self.pending:
            return
        nearest = _RECHECK_S
        now = _core.runtime.monotonic_ns()
        for client in list(self.pending):
            nxt = client.check_deadline()
            if nxt is not None:
                nearest = min(nearest, max(0.0, (nxt - now) * _NS))
        self._arm(self.loop.time() + nearest)


# The running loop's bridge and deadlines, looked up once per loop rather than per
# transfer (a loop that is running is never closed, so its bridge is current).
_last: tuple = (None, None, None)


def _loop_state() -> tuple:
    global _last
    loop = asyncio.get_running_loop()
    last = _last
    if last[0] is loop:
        return last
    bridge = faces.bridge_for(loop)
    deadlines = getattr(bridge, "_sdo_deadlines", None)
    if deadlines is None:
        deadlines = bridge._sdo_deadlines = _Deadlines(loop)
    _last = (loop, bridge, deadlines)
    return _last


async def _awaited(client: SdoClient, start: Callable[[Any, int], None]) -> Any:
    """Starts a completion-based transfer (``start(completions, token)``) and awaits its completion."""
    loop, bridge, deadlines = _loop_state()
    token, future = bridge.expect()
    completions = bridge.completions
    try:
        start(completions, token)
    except BaseException:
        bridge.forget(token)
        raise
    # loop._ready: asyncio's own loops (the callbacks ready to run); other loops never poll.
    if _SPIN_NS and not deadlines.pending and not getattr(loop, "_ready", True):
        # The only SDO transfer this loop awaits, and no other callback is ready to
        # run: its answer usually comes within a few microseconds, sooner than the
        # loop thread can sleep and be woken for it (the blocking call spins 50 us
        # for the same reason).  Poll the completion queue for at most _SPIN_NS
        # before sleeping.  With other transfers in flight or other work ready the
        # loop never spins.  A task whose answers keep coming this way still yields
        # to the loop every _BUDGET of them (as tokio's cooperative budget), so a
        # loop of awaited reads cannot starve the loop's timers and I/O.
        end = time.perf_counter_ns() + _SPIN_NS
        while not completions.pending:
            if time.perf_counter_ns() >= end:
                break
            _yield()         # the receive threads need the core more than this thread
        else:
            bridge._drain()
            if future.done():
                deadlines.budget -= 1
                if deadlines.budget <= 0:
                    deadlines.budget = _BUDGET
                    await _YIELD
                return future.result()
    deadlines.add(client)
    try:
        return await future
    except asyncio.CancelledError:
        # Withdrawn: a queued transfer is dropped, a running one aborted on the
        # wire, so the next transfer on this channel starts at once.
        bridge.forget(token)
        client.cancel_async(completions, token)
        raise
    finally:
        deadlines.done(client)


async def upload_async(client: SdoClient, index: int, subindex: int = 0, block: bool = False) -> bytes:
    """``await upload_async(client, ...)``: ``client.upload`` awaited, for code that
    holds a bare SdoClient (no node).  Under ``faces.run`` it is the blocking call."""
    if faces.blocking():
        return client.upload(index, subindex, block)
    return await _awaited(client, lambda done, token: client.upload_async(index, subindex, done, token, block))


async def download_async(client: SdoClient, index: int, subindex: int, data: bytes, block: bool = False,
                         segmented: bool = False) -> None:
    """``client.download`` awaited (see :func:`upload_async`)."""
    data = bytes(data)
    if faces.blocking():
        return client.download(index, subindex, data, block, segmented)
    await _awaited(client, lambda done, token: client.download_async(index, subindex, data, done, token, block,
                                                                      segmented))


_upload, _download = upload_async, download_async


class SdoVariable:
    """One sub-object of a remote node, read and written over SDO on access."""

    def __init__(self, client: SdoClient, index: int, subindex: int, od_var: Optional[Variable] = None) -> None:
        self._client = client
        self.index = index
        self.subindex = subindex
        self.od = od_var  # the dictionary entry (data type, name), None without an OD

    @property
    def name(self) -> str:
        return self.od.name if self.od is not None else f"0x{self.index:04X}:{self.subindex:02X}"

    def __repr__(self) -> str:
        return f"<SdoVariable 0x{self.index:04X}:{self.subindex:02X} {self.name!r}>"

    def _is_integer(self) -> bool:
        return self.od is not None and int(self.od.data_type) in _INTEGER_TYPES

    def read(self) -> bytes:
        """The object's bytes as uploaded."""
        return self._client.upload(self.index, self.subindex)

    def _encode_raw(self, value: Union[int, bytes, bytearray], size: Optional[int], signed: bool) -> bytes:
        if isinstance(value, (bytes, bytearray, memoryview)):
            return bytes(value)
        if size is not None:
            try:
                return int(value).to_bytes(size, "little", signed=signed)
            except OverflowError:
                raise _core.InvalidArgument(f"{self.name}: {value} does not fit {size} bytes") from None
        if self._is_integer():
            return self.od.encode(int(value))
        raise _core.InvalidArgument(
            f"{self.name}: no integer data type known for {value!r}: pass bytes or write(value, size=)")

    def write(self, value: Union[int, bytes, bytearray], size: Optional[int] = None, signed: bool = False) -> None:
        """Download bytes, or an int as ``size`` little-endian bytes (``size`` is
        needed when the data type is not known from a dictionary)."""
        faces.run(self.set_raw(value, size, signed))

    # ---- the logic, once, as coroutines: awaited directly, or run by faces.run ----
    async def get_raw(self) -> Union[int, bytes]:
        """Awaitable ``.raw``: the int for integer types, else the bytes."""
        data = await _upload(self._client, self.index, self.subindex)
        if self._is_integer():
            return int(self.od.decode(data))
        return data

    async def set_raw(self, value: Union[int, bytes, bytearray], size: Optional[int] = None,
                      signed: bool = False) -> None:
        """Awaitable ``write(value, size, signed)`` (``.raw = value``)."""
        await _download(self._client, self.index, self.subindex, self._encode_raw(value, size, signed))

    async def get(self):
        """Awaitable ``.value``: typed by the OD data type."""
        od = self._typed("read")
        return od.decode(await _upload(self._client, self.index, self.subindex))

    async def set(self, v) -> None:
        """Awaitable ``.value = v``."""
        await _download(self._client, self.index, self.subindex, self._typed("write").encode(v))

    @property
    def raw(self) -> Union[int, bytes]:
        """The int for integer types (signed per the type), else the bytes; bytes without an OD."""
        return faces.run(self.get_raw())

    @raw.setter
    def raw(self, value: Union[int, bytes]) -> None:
        faces.run(self.set_raw(value))

    @property
    def value(self):
        """Typed by the OD data type: int (signed or not), float, bool, str or bytes."""
        return faces.run(self.get())

    @value.setter
    def value(self, v) -> None:
        faces.run(self.set(v))

    def _typed(self, what: str) -> Variable:
        """The dictionary entry whose C++ codec gives and takes the value."""
        if self.od is None:
            raise _core.InvalidArgument(
                f"{self.name}: .value needs the data type: give add_node() an EDS or ObjectDictionary "
                f"(or use .raw to {what} bytes)")
        return self.od


class SdoObject:
    """An object (index) of a remote node: ``[sub]`` / ``["SubName"]`` gives its
    sub-objects; a VAR object (or any object when there is no OD) also reads
    and writes as a variable itself (``.raw``, ``.value``) through sub-index 0."""

    def __init__(self, sdo: "SdoVariables", index: int) -> None:
        self._sdo = sdo
        self.index = index
        od = sdo.od
        self.object_code = od.object_code(index) if od is not None else None
        self.name = (od.object_name(index) if od is not None else None) or f"0x{index:04X}"

    def __repr__(self) -> str:
        return f"<SdoObject 0x{self.index:04X} {self.name!r}>"

    def __getitem__(self, key: Key) -> SdoVariable:
        od = self._sdo.od
        if isinstance(key, str):
            if od is None:
                raise NotFound(f"{self.name}: sub-object {key!r} by name needs an EDS or ObjectDictionary")
            for s in od.subindices(self.index):
                if od[self.index, s].name == key:
                    return SdoVariable(self._sdo.client, self.index, s, od[self.index, s])
            raise NotFound(f"{self.name} (0x{self.index:04X}) has no sub-object named {key!r}")
        sub = int(key)
        if not 0 <= sub <= 0xFF:
            raise _core.InvalidArgument(f"{self.name}: sub-index {sub} is outside 0-255")
        if od is None:
            return SdoVariable(self._sdo.client, self.index, sub)
        if (self.index, sub) not in od:
            raise NotFound(f"{self.name} (0x{self.index:04X}) has no sub-index {sub} in the dictionary")
        return SdoVariable(self._sdo.client, self.index, sub, od[self.index, sub])

    def __iter__(self) -> Iterator[int]:
        od = self._sdo.od
        return iter(od.subindices(self.index) if od is not None else ())

    def _var(self) -> SdoVariable:
        var = self.__dict__.get("_var0")
        if var is None:
            if self.object_code not in (None, "VAR"):
                raise _core.InvalidArgument(f"{self.name} (0x{self.index:04X}) is a {self.object_code}: "
                                            f"pick a sub-object, e.g. [1]")
            var = self._var0 = self[0]
        return var

    @property
    def raw(self):
        return self._var().raw

    @raw.setter
    def raw(self, value) -> None:
        self._var().raw = value

    @property
    def value(self):
        return self._var().value

    @value.setter
    def value(self, v) -> None:
        self._var().value = v

    def read(self) -> bytes:
        return self._var().read()

    def write(self, value, size: Optional[int] = None, signed: bool = False) -> None:
        self._var().write(value, size, signed)

    # Awaitable twins (see SdoVariable): sub-index 0 of a VAR object.
    async def get(self):
        return await self._var().get()

    async def set(self, v) -> None:
        await self._var().set(v)

    async def get_raw(self):
        return await self._var().get_raw()

    async def set_raw(self, value, size: Optional[int] = None, signed: bool = False) -> None:
        await self._var().set_raw(value, size, signed)


class SdoVariables:
    """``node.sdo``: the objects of a remote node over one SdoClient (one client
    per node: two on one COB-ID would take each other's responses).

    ``[index]`` or ``["Object name"]`` gives an :class:`SdoObject`;
    ``["Record.Member"]`` a :class:`SdoVariable`; ``upload``/``download`` pass through."""

    def __init__(self, client: SdoClient, od: Optional[ObjectDictionary] = None) -> None:
        self.client = client
        self.od = od
        self._names = {od.object_name(i): i for i in od.indices()} if od is not None else {}

    def __getitem__(self, key: Key) -> Union[SdoObject, SdoVariable]:
        if isinstance(key, str):
            if key in self._names:
                return SdoObject(self, self._names[key])
            if self.od is not None and key in self.od:  # "Record.Member" or "0x1018:1"
                v = self.od[key]
                return SdoVariable(self.client, v.index, v.subindex, v)
            if self.od is None:
                raise NotFound(f"object {key!r}: access by name needs an EDS or ObjectDictionary (add_node(id, eds))")
            raise NotFound(f"node {self.client.node_id} has no object named {key!r} in its dictionary")
        index = int(key)
        if not 0 <= index <= 0xFFFF:
            raise _core.InvalidArgument(f"object index {index:#x} is outside 0x0000-0xFFFF")
        if self.od is not None and index not in self.od:
            raise NotFound(f"node {self.client.node_id} has no object 0x{index:04X} in its dictionary")
        return SdoObject(self, index)

    def __contains__(self, key: Key) -> bool:
        if self.od is None:
            return False
        return key in self._names or key in self.od

    def upload(self, index: int, subindex: int = 0, block: bool = False) -> bytes:
        return self.client.upload(index, subindex, block)

    def download(self, index: int, subindex: int, data: bytes, block: bool = False, segmented: bool = False) -> None:
        self.client.download(index, subindex, data, block, segmented)

    async def upload_async(self, index: int, subindex: int = 0, block: bool = False) -> bytes:
        """Awaitable ``upload``: any size (expedited, segmented, or block with ``block=True``)."""
        return await _upload(self.client, index, subindex, block)

    async def download_async(self, index: int, subindex: int, data: bytes, block: bool = False,
                             segmented: bool = False) -> None:
        """Awaitable ``download``."""
        await _download(self.client, index, subindex, data, block, segmented)

    @property
    def timeout(self) -> float:
        return self.client.timeout

    @timeout.setter
    def timeout(self, t: float) -> None:
        self.client.timeout = t


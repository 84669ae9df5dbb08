"""Pollers: read drives' position, velocity and status at a fixed rate on C++ threads, into numpy.

    with motorbus.Bench.load("bench.toml", sim=True) as bench, \\
            motorbus.Poller(bench.axes, rate_hz=1000) as poller:
        bench["x"].move_to(10)
        bench["x"].wait_idle()
        frame = poller.frame()          # {"t": ..., "x.position": ..., "x.t": ..., ...}
        print(poller.stats)             # missed, late, period error p50/p99/max per group

Axes are grouped by transport (a serial line, a CAN bus): one C++ thread per
group reads every axis of the group each period, on an absolute schedule
(deadline k at t0 + k / rate_hz, shared by all groups), timestamps the sample
and writes it into a preallocated ring, without the GIL.  Each drive kind says
what to read through its Drive class's ``poll_fields`` (registry.PollSpec); this
module converts the native readings to the axis's user units (``drive.units``)
with numpy, never per sample in Python.

Where a drive pushes its data (CANopen TPDOs, a register protocol's cyclic
transmissions: the kinds whose Drive class has ``capture_fields``, listed in
docs/poller.md), the poller captures instead of asking
(``mode="auto"``, the default): the drive kind sets the drive to transmit the
fields about every period, the bus receive thread keeps the latest values, and
each sample takes them — nothing is sent per sample.  ``mode="ask"`` always
asks (SDO reads, register reads, ASCII queries); ``mode="capture"`` refuses an
axis whose kind cannot push.  ``poller.modes`` says what each axis does.

A frame has one row per deadline index: ``t`` (s, the deadline, on the
monotonic clock of ``motorbus.monotonic_ns``), and per axis ``<axis>.t`` (s:
when that axis's group started the sample; for a captured axis when the oldest
of its values arrived, so the data's age shows) and ``<axis>.<field>``.  A
captured value that never arrived is NaN; a push that stopped arriving keeps
its old ``<axis>.t`` and each such sample counts in ``stats[...]["stale"]``.  A deadline
a group missed (its previous sample ran past a whole period) is a row of NaN
for its axes, and is counted in ``stats``: never hidden.  A group whose link
fails stops (its error is in ``stats``); the others go on.

The awaitable face (docs/aio.md "Buses and streams"): ``async for chunk in
poller.chunks(rows)`` yields the same frames as ``read()``, each of at least
``rows`` new rows (fewer at the end).  No thread waits and the poll threads
never take the GIL per sample: each group's thread pushes one completion to
the loop's queue once its ring holds ``rows`` unread rows (or it stopped), and
the loop takes the rows in one batch.  The ring is the bounded queue: a
consumer more than ``capacity`` rows behind loses the oldest, counted in
``stats[...]["overflowed"]`` (and :attr:`Poller.overflowed`).  Captured axes
(``mode="capture"``: TPDOs, cyclic registers) stream the same way.
"""
from __future__ import annotations

import csv
import math
import os
from collections.abc import AsyncIterator, Mapping
from typing import Any, Iterable, Optional, Union

import numpy as np

from . import _core, faces

__all__ = ["Poller", "FIELDS", "load_frame"]

#: What every pollable kind can be asked for (a kind may refuse one it has no object for).
FIELDS = ("position", "velocity", "status")
_SCALED = ("position", "velocity")   # converted to user units; status stays the raw word
_START_DELAY_NS = 20_000_000         # deadline 0: after every thread is up
#: Default seconds of rows frame() retains.  Unbounded, a 1 kHz poll of 2 axes grew ~1 GB/h
#: even for a caller that consumed read(); 10 minutes of it is ~43 MB.
KEEP_S = 600.0
MODES = ("auto", "capture", "ask")


class _Group:
    """One transport: its axes, their columns in the ring, and the C++ PollGroup."""

    def __init__(self, label: str, transport: Any, bus: Any) -> None:
        self.label = label
        self.transport = transport
        self.bus = bus
        self.axes: list[tuple[str, list[str], bool]] = []   # (axis name, fields, stamped) in column order
        self.sources: list[Any] = []
        self.scales: list[float] = []
        self.closers: list[Any] = []   # PollSpec.close of capture sources
        self.core: Optional[Any] = None
        self.recorder: Optional[Any] = None
        self.last_k = -1
        empty = (np.empty(0, np.int64), np.empty(0, np.int64), np.empty((0, 0)))
        self.pending = empty


class Poller:
    """Poll ``axes`` (a Drive, a list of Drives, or a mapping name -> Drive such
    as ``bench.axes``) for ``fields`` at ``rate_hz`` on one C++ thread per
    transport.

    * ``capacity``: ring rows per group (default: 10 s of samples, at least
      4096); a reader that falls further behind loses the oldest rows, counted
      in ``stats[...]["overflowed"]``;
    * ``spin_us``: busy-wait this long before each deadline (tighter timing at
      normal priority, at the cost of that much CPU per period);
    * ``realtime``: try SCHED_FIFO (``stats[...]["realtime"]`` says whether it
      was granted);
    * ``candump``: a path; the CAN traffic of CAN groups is recorded there as a
      candump log while polling (``name.log`` -> ``name-2.log`` for a second bus);
    * ``mode``: ``"auto"`` (default: capture what the drive pushes where its
      kind can push, i.e. its Drive class has ``capture_fields`` — TPDOs on the
      event timer, cyclic registers — and ask the others), ``"capture"`` (every axis captured; an
      axis whose kind cannot push is an InvalidArgument) or ``"ask"`` (always
      ask, one request per field per sample).  ``modes`` says per axis;
    * ``keep``: seconds of rows ``frame()`` and ``save()`` retain (default
      :data:`KEEP_S`, 10 minutes: bounded memory however long the poller runs;
      ``None``: every row since start; ``0``: none — for a caller that consumes
      ``read()``).  Rows that age out are counted in ``discarded``; ``read()``
      is not affected.
    """

    def __init__(self, axes: Any, fields: Iterable[str] = FIELDS, rate_hz: float = 1000.0, *,
                 capacity: Optional[int] = None, spin_us: float = 0.0, realtime: bool = False,
                 candump: Optional[Union[str, "os.PathLike[str]"]] = None, mode: str = "auto",
                 keep: Optional[float] = KEEP_S, start: bool = True) -> None:
        named = _named_axes(axes)
        fields = _check_fields(fields)
        if isinstance(rate_hz, bool) or not isinstance(rate_hz, (int, float)) or not math.isfinite(rate_hz) \
                or not 0 < rate_hz <= 100_000:
            raise _core.InvalidArgument(f"Poller rate_hz: a number in (0, 100000], not {rate_hz!r}")
        self.period_ns = int(round(1e9 / rate_hz))
        if self.period_ns <= 0:
            raise _core.InvalidArgument(f"Poller rate_hz {rate_hz!r}: too high")
        if capacity is None:
            capacity = max(4096, int(10 * rate_hz))
        if isinstance(capacity, bool) or not isinstance(capacity, int) or capacity < 1:
            raise _core.InvalidArgument(f"Poller capacity: a number of samples >= 1, not {capacity!r}")
        if not isinstance(spin_us, (int, float)) or not 0 <= spin_us <= self.period_ns / 1000:
            raise _core.InvalidArgument(f"Poller spin_us: between 0 and the period ({self.period_ns / 1000:g} µs), "
                                        f"not {spin_us!r}")
        if mode not in MODES:
            raise _core.InvalidArgument(f"Poller mode: one of {', '.join(repr(m) for m in MODES)}, not {mode!r}")
        if keep is not None and (isinstance(keep, bool) or not isinstance(keep, (int, float))
                                 or not math.isfinite(keep) or keep < 0):
            raise _core.InvalidArgument(f"Poller keep: seconds >= 0 of rows frame() retains, or None for all, "
                                        f"not {keep!r}")
        #: Rows frame() retains (None: all).
        self.keep_rows: Optional[int] = None if keep is None else int(math.ceil(keep * rate_hz))
        #: Rows that aged out of what frame() retains (read() returned each of them once).
        self.discarded = 0
        self.fields = fields
        self.rate_hz = float(rate_hz)
        self.mode = mode
        self.axes = dict(named)
        #: per axis: "capture" (takes what the drive pushes) or "ask"
        self.modes: dict[str, str] = {}
        self._groups: list[_Group] = []
        by_transport: dict[int, _Group] = {}
        try:
            for name, drive in named:
                spec = self._spec(name, drive, fields, mode)
                group = by_transport.get(id(spec.transport))
                if group is None:
                    group = _Group(f"group{len(self._groups)}", spec.transport, spec.bus)
                    by_transport[id(spec.transport)] = group
                    self._groups.append(group)
                if spec.close is not None:
                    group.closers.append(spec.close)
                group.axes.append((name, list(fields), bool(spec.stamped)))
                group.sources.append(spec.source)
                unit_scale = float(drive.units.scale)
                if spec.stamped:
                    group.scales.append(1.0)   # the arrival time (ns), handled in _merge
                group.scales.extend(s * (unit_scale if f in _SCALED else 1.0) for f, s in zip(fields, spec.scales))
        except BaseException:
            self._close_sources()
            raise
        for g in self._groups:   # a readable label: the axes it holds
            g.label = "+".join(a for a, _, _ in g.axes)
        self._capacity = capacity
        self._spin_ns = int(spin_us * 1000)
        self._realtime = bool(realtime)
        self._candump = os.fspath(candump) if candump is not None else None
        self._chunks: list[dict[str, np.ndarray]] = []
        self._retained = 0
        self._t0_ns = 0
        self._started = False
        self._stopped = False
        if start:
            self.start()

    def _spec(self, name: str, drive: Any, fields: tuple, mode: str) -> Any:
        can_capture = type(drive).provides("capture_fields")
        if mode == "capture" and not can_capture:
            raise _core.InvalidArgument(f"Poller mode 'capture': axis {name!r} ({drive.kind}) cannot push its data; "
                                        f"use mode='auto' to ask it instead")
        if mode != "ask" and can_capture:
            self.modes[name] = "capture"
            return drive.capture_fields(fields, self.period_ns / 1e9)
        if not type(drive).provides("poll_fields"):
            raise _core.InvalidArgument(f"Poller: axis {name!r} ({drive.kind}): this drive kind cannot be polled")
        self.modes[name] = "ask"
        return drive.poll_fields(fields)

    def _close_sources(self) -> None:
        for g in self._groups:
            closers, g.closers = g.closers, []
            for close in closers:
                try:
                    close()
                except _core.MotorbusError:
                    pass   # best effort: the link may be gone (the drive then stops transmitting with it)

    # ---- lifecycle ----
    def start(self) -> "Poller":
        """Starts every group's thread (once; the constructor does it unless start=False)."""
        if self._started:
            raise _core.InvalidArgument("Poller: already started (make a new Poller to poll again)")
        self._started = True
        self._t0_ns = _core.runtime.monotonic_ns() + max(_START_DELAY_NS, self.period_ns)
        can_groups = [g for g in self._groups if g.bus is not None]
        try:
            for g in self._groups:
                if self._candump and g.bus is not None:
                    g.recorder = _core.can.Recorder(g.bus, _numbered(self._candump, can_groups.index(g)))
                g.core = _core.poll.PollGroup(g.sources, self.period_ns / 1e9, capacity=self._capacity,
                                              spin=self._spin_ns / 1e9, realtime=self._realtime, start_ns=self._t0_ns)
                g.core.start()
        except BaseException:
            self.stop()
            raise
        return self

    def stop(self) -> None:
        """Stops every thread (each waits at most for the read in progress); idempotent."""
        self._stopped = True
        for g in self._groups:
            if g.core is not None:
                g.core.stop()
            if g.recorder is not None:
                g.recorder.stop()
        self._close_sources()

    def __enter__(self) -> "Poller":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        """True while any group's thread polls."""
        return any(g.core is not None and g.core.running for g in self._groups)

    @property
    def columns(self) -> list[str]:
        """The frame's keys, in order."""
        out = ["t"]
        for g in self._groups:
            for axis, fields, _ in g.axes:
                out.append(f"{axis}.t")
                out.extend(f"{axis}.{f}" for f in fields)
        return out

    # ---- data ----
    def read(self) -> dict[str, np.ndarray]:
        """The samples since the last read(), as a frame (see the module doc).

        Rows of a deadline some running group has not reached yet are held back
        to the next read, so every deadline is one row across reads."""
        running = [g.core is not None and g.core.running and not self._stopped for g in self._groups]
        for g in self._groups:
            if g.core is None:
                continue
            k, t, v, m = g.core.take()
            k, t, v = k[:m], t[:m], v[:m]
            if m:
                g.last_k = int(k[-1])
            pk, pt, pv = g.pending
            g.pending = (np.concatenate([pk, k]), np.concatenate([pt, t]),
                         np.concatenate([pv.reshape(-1, v.shape[1]), v]))
        horizons = [g.last_k for g, r in zip(self._groups, running) if r]
        horizon = min(horizons) if horizons else np.iinfo(np.int64).max
        parts = []
        for g in self._groups:
            k, t, v = g.pending
            n = int(np.searchsorted(k, horizon, side="right"))
            parts.append((g, k[:n], t[:n], v[:n]))
            g.pending = (k[n:], t[n:], v[n:])
        chunk = self._merge(parts)
        if len(chunk["t"]) and self.keep_rows != 0:
            self._chunks.append(chunk)
            self._retained += len(chunk["t"])
            self._trim()
        elif len(chunk["t"]):
            self.discarded += len(chunk["t"])
        return chunk

    def _trim(self) -> None:
        """Drops the oldest retained rows beyond keep_rows (whole chunks, then a slice)."""
        if self.keep_rows is None:
            return
        excess = self._retained - self.keep_rows
        while excess > 0 and self._chunks:
            first = self._chunks[0]
            n = len(first["t"])
            if n <= excess:
                self._chunks.pop(0)
                cut = n
            else:   # a copy: a view would keep the whole chunk alive
                self._chunks[0] = {k: v[excess:].copy() for k, v in first.items()}
                cut = excess
            self._retained -= cut
            self.discarded += cut
            excess -= cut

    def frame(self) -> dict[str, np.ndarray]:
        """The retained samples (reads what is new first): every row since start with
        ``keep=None``, else the last ``keep`` seconds of rows (``discarded`` counts the rest)."""
        self.read()
        if not self._chunks:
            return self._merge([(g, np.empty(0, np.int64), np.empty(0, np.int64),
                                 np.empty((0, len(g.scales)))) for g in self._groups])
        if len(self._chunks) > 1:   # keep one chunk: the next frame() concatenates only what is new
            self._chunks = [{key: np.concatenate([c[key] for c in self._chunks]) for key in self._chunks[0]}]
        return dict(self._chunks[0])

    def _merge(self, parts: list) -> dict[str, np.ndarray]:
        ks = [k for _, k, _, _ in parts]
        index = np.unique(np.concatenate(ks)) if ks else np.empty(0, np.int64)
        out: dict[str, np.ndarray] = {"t": (self._t0_ns + index * self.period_ns) / 1e9}
        n = len(index)
        for g, k, t, v in parts:
            rows = np.searchsorted(index, k)
            values = v * np.asarray(g.scales, dtype=float)  # native -> user units, every column at once
            missed = np.isnan(v).all(axis=1) if v.shape[1] else np.zeros(len(k), bool)
            when = np.where(missed, np.nan, t / 1e9)
            col = 0
            for axis, fields, stamped in g.axes:
                tcol = np.full(n, np.nan)
                if stamped:   # the source's arrival time column (ns; NaN before anything arrived)
                    tcol[rows] = v[:, col] / 1e9
                    col += 1
                else:
                    tcol[rows] = when
                out[f"{axis}.t"] = tcol
                for f in fields:
                    c = np.full(n, np.nan)
                    c[rows] = values[:, col]
                    out[f"{axis}.{f}"] = c
                    col += 1
        return out

    # ---- the awaitable face ----
    async def chunks(self, rows: Optional[int] = None) -> AsyncIterator[dict[str, np.ndarray]]:
        """``async for chunk in poller.chunks(rows)``: the samples as they come, each
        chunk a frame as ``read()`` returns (numpy arrays per column) of at least
        ``rows`` new rows (default: a tenth of a second of them, at most the ring's ``capacity``), fewer for the
        last one; ends when every group has stopped (``stop()``, or a link failed:
        see ``stats``).  The ring is the bounded queue (``capacity`` rows; what a
        slow consumer loses is counted in ``overflowed``).  Leaving the loop or
        cancelling its task withdraws the wait; the poller goes on."""
        if rows is None:   # a tenth of a second, as far as the ring holds it
            rows = min(self._capacity, max(1, int(round(self.rate_hz / 10))))
        if isinstance(rows, bool) or not isinstance(rows, int) or not 1 <= rows <= self._capacity:
            raise _core.InvalidArgument(f"Poller.chunks rows: a number of rows in 1..{self._capacity} (the ring's "
                                        f"capacity), not {rows!r}")
        if not self._started:
            raise _core.InvalidArgument("Poller.chunks: the poller was not started (start() first)")
        while True:
            await self._rows_ready(rows)
            ended = not self.running          # read before the last take: nothing can follow it
            chunk = self.read()
            if len(chunk["t"]):
                yield chunk
            if ended:
                return

    async def _rows_ready(self, rows: int) -> None:
        """Until every running group's ring holds ``rows`` unread rows (or it stopped)."""
        bridge = faces.bridge_for()
        waits = []
        try:
            for g in self._groups:
                if g.core is None:
                    continue
                token, future = bridge.expect()
                if g.core.notify_when(rows, bridge.completions, token):
                    bridge.forget(token)      # already so (or the group stopped)
                else:
                    waits.append((g, token, future))
            for _, _, future in waits:
                await future
        except BaseException:                 # cancelled (or the generator closed): withdraw what waits
            for g, token, future in waits:
                if not future.done():
                    g.core.cancel_notify()
                    bridge.forget(token)
            raise

    @property
    def overflowed(self) -> int:
        """Rows the groups' rings lost because the reader (read(), chunks()) fell a ring behind."""
        return sum(g.core.stats.overflowed for g in self._groups if g.core is not None)

    # ---- figures ----
    @property
    def stats(self) -> dict[str, dict[str, Any]]:
        """Per group (keyed by its axes, "x+y"): transport, captured (its axes
        that capture), samples, missed, late, overflowed, stale (samples whose
        captured data was older than the push period allows, or had not
        arrived yet: summed over the group's captured axes), period error / wake latency / read time p50, p99, max (s),
        realtime, running, error_type and error ("" unless the group stopped on
        its own, e.g. "LinkDown")."""
        out = {}
        for g in self._groups:
            entry: dict[str, Any] = {"axes": [a for a, _, _ in g.axes], "transport": "can" if g.bus is not None
                                     else "serial", "period": self.period_ns / 1e9,
                                     "captured": [a for a, _, stamped in g.axes if stamped]}
            if g.core is not None:
                s = g.core.stats
                entry.update(samples=s.samples, missed=s.missed, late=s.late, overflowed=s.overflowed, stale=s.stale,
                             realtime=s.realtime, running=s.running, error_type=s.error_type, error=s.error)
                for what in ("period_error", "wake_latency", "read_time"):
                    for q in ("p50", "p99", "max"):
                        entry[f"{what}_{q}"] = getattr(s, f"{what}_{q}_ns") / 1e9
            out[g.label] = entry
        return out

    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """The retained samples (``frame()``) to ``.npz`` (numpy arrays by column) or ``.csv`` (a header row of column names)."""
        path = os.fspath(path)
        frame = self.frame()
        if path.endswith(".npz"):
            np.savez(path, **frame)
        elif path.endswith(".csv"):
            keys = list(frame)
            with open(path, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(keys)
                w.writerows(np.column_stack([frame[k] for k in keys]).tolist() if keys else [])
        else:
            raise _core.InvalidArgument(f"Poller.save {path!r}: a .npz or .csv path")

    def __repr__(self) -> str:
        groups = "; ".join(g.label for g in self._groups)
        return f"<Poller {self.rate_hz:g} Hz, {', '.join(self.fields)}, groups: {groups}>"


def load_frame(path: Union[str, "os.PathLike[str]"]) -> dict[str, np.ndarray]:
    """A frame written by :meth:`Poller.save` (.npz or .csv), as a dict of float arrays."""
    path = os.fspath(path)
    if path.endswith(".npz"):
        with np.load(path) as z:
            return {k: z[k] for k in z.files}
    if path.endswith(".csv"):
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        keys, data = rows[0], np.array(rows[1:], dtype=float).reshape(-1, len(rows[0]))
        return {k: data[:, i] for i, k in enumerate(keys)}
    raise _core.InvalidArgument(f"load_frame {path!r}: a .npz or .csv path")


def _named_axes(axes: Any) -> list[tuple[str, Any]]:
    from .drive import Drive

    if isinstance(axes, Drive):
        pairs = [(getattr(axes, "name", None) or "axis0", axes)]
    elif isinstance(axes, Mapping):
        pairs = [(str(k), v) for k, v in axes.items()]
    elif isinstance(axes, Iterable) and not isinstance(axes, (str, bytes)):
        pairs = [(f"axis{i}", d) for i, d in enumerate(axes)]
    else:
        raise _core.InvalidArgument(f"Poller axes: a Drive, a list of Drives or a mapping name -> Drive, "
                                    f"not {type(axes).__name__}")
    if not pairs:
        raise _core.InvalidArgument("Poller axes: at least one axis")
    seen = set()
    for name, d in pairs:
        if not isinstance(d, Drive):
            raise _core.InvalidArgument(f"Poller axis {name!r}: a motorbus.Drive, not {type(d).__name__}")
        if id(d) in seen:
            raise _core.InvalidArgument(f"Poller axis {name!r}: the same drive is listed twice")
        seen.add(id(d))
    return pairs


def _check_fields(fields: Iterable[str]) -> tuple[str, ...]:
    if isinstance(fields, str):
        fields = (fields,)
    fields = tuple(fields)
    if not fields:
        raise _core.InvalidArgument("Poller fields: at least one of " + ", ".join(FIELDS))
    for f in fields:
        if f not in FIELDS:
            raise _core.InvalidArgument(f"Poller field {f!r}: one of {', '.join(FIELDS)}")
    if len(set(fields)) != len(fields):
        raise _core.InvalidArgument(f"Poller fields {fields!r}: each at most once")
    return fields


def _numbered(path: str, i: int) -> str:
    if i == 0:
        return path
    stem, ext = os.path.splitext(path)
    return f"{stem}-{i + 1}{ext}"

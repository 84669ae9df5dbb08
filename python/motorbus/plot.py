"""Plots of what a bench did: measured against planned motion, and CAN bus load.

    from motorbus import Poller, plot
    t_cmd = motorbus.monotonic_ns() / 1e9          # the move command's time: planned t = 0
    bench["x"].move_to(10)
    ...
    planned = plot.planned(bench["x"], start=0, target=10)   # the kind's own profile model
    ax = plot.profile(poller.frame(), "x", planned, t0=t_cmd)
    fig, load = plot.bus_load("traffic.log", bitrate=500_000)

matplotlib is an optional extra (``pip install 'motorbus[plot]'``), imported
only when a figure is drawn; the numbers (:func:`compare`, the load returned
by :func:`bus_load`) need only numpy.  Without a display (no ``DISPLAY`` and
no ``MPLBACKEND``) the Agg backend is chosen, so figures can be saved from a
shell, a test or CI.

Time axes: a frame's times are seconds on ``motorbus.monotonic_ns()``; a
planned profile's t = 0 is the moment the move was commanded.  ``t0`` (the
move command's time on that same clock) lines them up: plots show seconds
since ``t0`` (since the first row of the frame when ``t0`` is not given).
"""
from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any, Optional, Sequence, Union

import numpy as np

from . import _core

__all__ = ["profile", "bus_load", "planned", "compare", "frame_bits", "load_numbers"]


class MatplotlibMissing(ModuleNotFoundError):
    """matplotlib is not installed (it is the optional extra ``motorbus[plot]``)."""


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError as e:
        raise MatplotlibMissing("motorbus.plot draws with matplotlib, which is not installed: "
                                "pip install 'motorbus[plot]' (or pip install matplotlib)") from e
    import sys
    if "matplotlib.pyplot" not in sys.modules and not os.environ.get("MPLBACKEND") \
            and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        matplotlib.use("Agg")   # no display: draw to files (a notebook sets MPLBACKEND itself)
    import matplotlib.pyplot as plt
    return plt


# ---- planned motion ----

def planned(drive: Any, start: float, target: float, n: int = 1000) -> dict[str, np.ndarray]:
    """The move ``start`` -> ``target`` (user units) as the drive's kind plans it,
    sampled: ``{"t", "p", "v"}`` in seconds and user units, t = 0 at the command.

    The profile model is the kind's own (``Drive.plan_move``, fed with
    the drive's current speed and ramp parameters); InvalidArgument for a kind
    that has none."""
    if not type(drive).provides("plan_move"):
        raise _core.InvalidArgument(f"plot.planned: drive kind {drive.kind!r} has no profile model (plan_move)")
    scale = float(drive.units.scale)
    prof = drive.plan_move(start / scale, target / scale)
    s = prof.sample(max(2, int(n)))
    return {"t": s[:, 0], "p": s[:, 1] * scale, "v": s[:, 2] * scale}


def _planned_arrays(plan: Any) -> tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]:
    """(t, p, v or None) from a Profile, a mapping with t/p[/v], or a (t, p) pair."""
    if hasattr(plan, "sample") and hasattr(plan, "duration"):
        s = plan.sample(1000)
        return s[:, 0], s[:, 1], s[:, 2]
    if isinstance(plan, Mapping):
        if "t" not in plan or "p" not in plan:
            raise _core.InvalidArgument(f"planned: a mapping with 't' and 'p' arrays, not keys {sorted(plan)}")
        v = plan.get("v")
        return (np.asarray(plan["t"], float), np.asarray(plan["p"], float),
                None if v is None else np.asarray(v, float))
    if isinstance(plan, (tuple, list)) and len(plan) == 2:
        return np.asarray(plan[0], float), np.asarray(plan[1], float), None
    raise _core.InvalidArgument(f"planned: a motion Profile, a mapping with t/p arrays or a (t, p) pair, "
                                f"not {type(plan).__name__}")


def _measured(frame: Mapping[str, np.ndarray], axis: str, field: str) -> tuple[np.ndarray, np.ndarray]:
    tkey, vkey = f"{axis}.t", f"{axis}.{field}"
    if vkey not in frame:
        axes = sorted({k.split(".", 1)[0] for k in frame if "." in k})
        raise _core.InvalidArgument(f"plot: the frame has no column {vkey!r} (axes: {', '.join(axes)}; "
                                    f"columns: {', '.join(k for k in frame if k.startswith(axis + '.'))})")
    t = np.asarray(frame[tkey] if tkey in frame else frame["t"], float)
    v = np.asarray(frame[vkey], float)
    ok = ~np.isnan(t) & ~np.isnan(v)   # missed deadlines are NaN rows: not data
    return t[ok], v[ok]


def compare(frame: Mapping[str, np.ndarray], axis: str, plan: Any, t0: float,
            field: str = "position") -> dict[str, np.ndarray]:
    """Measured samples of ``axis`` against the plan at the same instants.

    Returns ``t`` (s since ``t0``, the move command's time on the frame's
    clock), ``measured``, ``planned`` (the plan at t, held at its end value after
    its end and at its start value before 0) and ``error`` = measured - planned.
    ``field`` "velocity" compares with the planned velocity (a kind that reports
    an unsigned speed is compared by magnitude)."""
    t, m = _measured(frame, axis, field)
    t = t - float(t0)
    pt, pp, pv = _planned_arrays(plan)
    if field == "velocity":
        if pv is None:
            pv = np.gradient(pp, pt) if len(pt) > 1 else np.zeros_like(pp)
        ref = np.interp(t, pt, pv, left=0.0, right=0.0)
        if len(m) and np.all(m >= 0) and np.any(ref < 0):
            ref = np.abs(ref)
    else:
        ref = np.interp(t, pt, pp)
    return {"t": t, "measured": m, "planned": ref, "error": m - ref}


def profile(frame: Mapping[str, np.ndarray], axis: str, planned: Any = None, ax: Any = None,
            field: str = "position", *, t0: Optional[float] = None, velocity: bool = False,
            units: str = "") -> Any:
    """Plot what the poller measured for ``axis`` (``frame`` from ``Poller.frame()``
    or ``load_frame``) against ``planned`` (a motion Profile, ``{"t", "p"[, "v"]}``
    such as :func:`planned` returns, or a (t, p) pair; in the frame's units).

    The time axis is seconds since ``t0``, the move command's time on the
    frame's clock (``motorbus.monotonic_ns() / 1e9`` taken just before the
    command): the plan's t = 0 sits there.  Without ``t0``, seconds since the
    frame's first row, and the plan starts at that row.

    ``velocity=True`` adds the velocity under the position (measured velocity
    column when polled, else differentiated; planned v).  ``ax``: an Axes (or
    two with velocity) to draw into, else a new figure.  Returns the Axes (a
    tuple (position Axes, velocity Axes) with velocity)."""
    plt = _pyplot()
    origin = float(t0) if t0 is not None else float(np.asarray(frame["t"], float)[0])
    if ax is None:
        if velocity:
            _, ax = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
        else:
            _, ax = plt.subplots(figsize=(8, 4))
    axes = list(ax) if isinstance(ax, (list, tuple, np.ndarray)) else [ax]
    if velocity and len(axes) < 2:
        raise _core.InvalidArgument("plot.profile(velocity=True): pass two Axes (position, velocity) or none")
    unit = f" ({units})" if units else ""
    t, m = _measured(frame, axis, field)
    axes[0].plot(t - origin, m, ".", ms=2, label=f"{axis} measured")
    if planned is not None:
        pt, pp, pv = _planned_arrays(planned)
        axes[0].plot(pt, pp, "-", lw=1.2, label=f"{axis} planned")
    axes[0].set_ylabel(f"{field}{unit}")
    axes[0].legend(loc="best", fontsize="small")
    axes[0].grid(True, alpha=0.3)
    if velocity:
        vkey = f"{axis}.velocity"
        if vkey in frame:
            tv, vv = _measured(frame, axis, "velocity")
        else:
            tv, vv = t, (np.gradient(m, t) if len(t) > 1 else np.zeros_like(m))
        axes[1].plot(tv - origin, vv, ".", ms=2, label=f"{axis} measured")
        if planned is not None:
            if pv is None:
                pv = np.gradient(pp, pt) if len(pt) > 1 else np.zeros_like(pp)
            axes[1].plot(pt, pv, "-", lw=1.2, label=f"{axis} planned")
        axes[1].set_ylabel(f"velocity{(' (' + units + '/s)') if units else ''}")
        axes[1].legend(loc="best", fontsize="small")
        axes[1].grid(True, alpha=0.3)
    axes[-1].set_xlabel("time since the move command (s)" if t0 is not None else "time since the first sample (s)")
    return (axes[0], axes[1]) if velocity else axes[0]


# ---- bus load ----

def _crc15(bits: Sequence[int]) -> int:
    crc = 0
    for b in bits:
        nxt = b ^ ((crc >> 14) & 1)
        crc = (crc << 1) & 0x7FFF
        if nxt:
            crc ^= 0x4599
    return crc


def frame_bits(frame: Any, stuffing: str = "worst") -> int:
    """Bits a classic CAN frame takes on the wire, with the 3-bit intermission.

    ``stuffing="worst"``: the worst case for its length (``_core.can.wire_bits_worst_case``,
    what the virtual bus's timing uses): 47 + 8n bits + (34 + 8n - 1) // 4 stuff bits
    for a standard id, 67 + 8n + (54 + 8n - 1) // 4 extended.  ``"exact"``: the stuff
    bits this frame's own bit stream needs (its id, data and CRC-15); ``"none"``:
    no stuff bits."""
    if stuffing == "worst":
        return int(_core.can.wire_bits_worst_case(frame))
    if stuffing not in ("exact", "none"):
        raise _core.InvalidArgument(f"frame_bits stuffing: 'worst', 'exact' or 'none', not {stuffing!r}")
    data = b"" if frame.rtr else bytes(frame.data)
    dlc = frame.dlc if frame.rtr else len(data)
    rtr = 1 if frame.rtr else 0

    def field(value: int, n: int) -> list[int]:
        return [(value >> (n - 1 - i)) & 1 for i in range(n)]

    if frame.extended:   # SOF, base id, SRR, IDE, id extension, RTR, r1, r0
        head = [0] + field(frame.id >> 18, 11) + [1, 1] + field(frame.id & 0x3FFFF, 18) + [rtr, 0, 0]
    else:                # SOF, id, RTR, IDE, r0
        head = [0] + field(frame.id, 11) + [rtr, 0, 0]
    bits = head + field(dlc, 4) + [b for byte in data for b in field(byte, 8)]
    bits += field(_crc15(bits), 15)
    if stuffing == "none":
        return len(bits) + 13
    stuffed, run, last = 0, 0, None
    for b in bits:
        if b == last:
            run += 1
        else:
            run, last = 1, b
        if run == 5:                 # a complementary stuff bit starts a new run
            stuffed += 1
            run, last = 1, 1 - b
    return len(bits) + stuffed + 13   # + CRC delimiter, ACK slot and delimiter, EOF 7, intermission 3


def _timed_frames(source: Any) -> list[tuple[float, Any]]:
    if isinstance(source, (str, os.PathLike)):
        entries, _bad = _core.can.read_log(os.fspath(source))
        return [(float(e.time), e.frame) for e in entries]
    out = []
    for item in source:
        if hasattr(item, "frame") and hasattr(item, "time"):      # a LogEntry
            out.append((float(item.time), item.frame))
        elif isinstance(item, tuple) and len(item) == 2:          # (time s, Frame)
            out.append((float(item[0]), item[1]))
        elif hasattr(item, "timestamp_ns"):                       # a received Frame
            out.append((item.timestamp_ns / 1e9, item))
        else:
            raise _core.InvalidArgument(f"bus_load: frames as LogEntry, (time, Frame) or timestamped Frame, "
                                        f"not {type(item).__name__}")
    return out


def load_numbers(source: Any, bitrate: float, window: float = 0.1, stuffing: str = "worst") -> dict[str, Any]:
    """Bus load per time window, without drawing (what :func:`bus_load` plots).

    ``source``: a candump log path, or LogEntry / (time s, Frame) items.  Each
    frame's bits (:func:`frame_bits`) count in the window holding its timestamp.
    Returns ``t`` (window starts, s since the first frame), ``bits``, ``frames``
    and ``load`` (% of ``bitrate`` x ``window``) per window, ``mean`` (% over the
    whole recording), ``peak`` (% of the busiest window), ``total_bits``,
    ``count``, and the ``bitrate``, ``window``, ``stuffing`` used."""
    if isinstance(bitrate, bool) or not isinstance(bitrate, (int, float)) or not bitrate > 0:
        raise _core.InvalidArgument(f"bus_load bitrate: bits/s > 0, not {bitrate!r}")
    if isinstance(window, bool) or not isinstance(window, (int, float)) or not window > 0:
        raise _core.InvalidArgument(f"bus_load window: seconds > 0, not {window!r}")
    frames = _timed_frames(source)
    times = np.array([t for t, _ in frames], float)
    bits = np.array([frame_bits(f, stuffing) for _, f in frames], float)
    if len(frames) == 0:
        return {"t": np.empty(0), "bits": np.empty(0), "frames": np.empty(0, np.int64), "load": np.empty(0),
                "mean": 0.0, "peak": 0.0, "total_bits": 0, "count": 0, "bitrate": float(bitrate),
                "window": float(window), "stuffing": stuffing}
    rel = times - times.min()
    idx = np.floor(rel / window).astype(np.int64)
    nwin = int(idx.max()) + 1
    per_bits = np.bincount(idx, weights=bits, minlength=nwin)
    per_frames = np.bincount(idx, minlength=nwin)
    load = per_bits / (bitrate * window) * 100.0
    return {"t": np.arange(nwin) * window, "bits": per_bits, "frames": per_frames, "load": load,
            "mean": float(bits.sum() / (bitrate * nwin * window) * 100.0), "peak": float(load.max()),
            "total_bits": int(bits.sum()), "count": len(frames), "bitrate": float(bitrate),
            "window": float(window), "stuffing": stuffing}


def bus_load(candump_path_or_frames: Any, bitrate: float, window: float = 0.1, ax: Any = None,
             stuffing: str = "worst") -> tuple[Any, dict[str, Any]]:
    """Plot the bus load (%) over time of a recording (a candump log path such as
    ``Poller(candump=...)`` writes, or frames: see :func:`load_numbers`).

    Frame lengths count the worst-case stuff bits by default (an upper bound, the
    virtual bus's own timing model); ``stuffing="exact"`` counts each frame's own.
    Returns (the Figure, the numbers of :func:`load_numbers`)."""
    numbers = load_numbers(candump_path_or_frames, bitrate, window, stuffing)
    plt = _pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 3))
    else:
        fig = ax.figure
    ax.step(numbers["t"], numbers["load"], where="post",
            label=f"{numbers['count']} frames, mean {numbers['mean']:.1f} %, peak {numbers['peak']:.1f} %")
    ax.set_xlabel("time since the first frame (s)")
    ax.set_ylabel(f"bus load (%) per {window * 1000:g} ms")
    ax.set_title(f"CAN bus load at {bitrate / 1000:g} kbit/s ({stuffing}-case stuffing)", fontsize="medium")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig, numbers

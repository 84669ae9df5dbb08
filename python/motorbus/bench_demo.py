"""``motorbus demo``: a simulated bench of every drive family over real transports.

The bench is a TOML file in the package (``demo_bench.toml``; ``--bench FILE``
for another).  ``Bench.load(path, sim=True)`` serves it as its simulated twin:
each serial line a pty, each CAN bus a virtual bus served over socketcand on
127.0.0.1, each axis's simulator behind it.  Then, as on a real bench:

1. discovery over those transports (the CANopen scan and CAN probes over a
   second socketcand connection, each serial axis's identity probe on its line),
   compared with the file;
2. every axis enabled, its file parameters applied, and homed;
3. one coordinated move (``Bench.move_together``) polled at 1 kHz by a
   ``Poller`` (positions) that records a candump log of the CAN traffic;
4. a summary table (target, position reached, whether it reached the target and
   why not, max following error against the kind's own profile model, samples,
   missed poll deadlines; values in each axis's units, a legend below) and a PNG
   (planned vs measured per axis, CAN bus load; without matplotlib it says so and
   writes none), with the arrays it plotted in ``demo_plot.npz``.

Any bench file that ``motorbus status FILE --sim`` accepts runs: an axis that
cannot be homed is left out of the move, one that stops short (a limit, a fault,
a stall...) is marked in the table, and the demo then exits 1.
"""
from __future__ import annotations

import contextlib
import os
import sys
import time
from typing import Any, Optional

import numpy as np

from . import _core, plot, registry
from .bench import Bench
from .poller import Poller

DEFAULT_BENCH = os.path.join(os.path.dirname(__file__), "demo_bench.toml")
#: Targets of the coordinated move, in each axis's user units (quick: shorter moves).
TARGETS = {"x": 25.0, "y": -10.0, "rot": 720.0, "z": 100.0, "tilt": 20.0, "feed": 60.0, "spindle": 90.0}
RATE_HZ = 1000.0
#: The bit rate the bus load is computed for.  The twin's virtual buses carry frames
#: without wire time, so this is the load the recorded traffic would put on a real
#: 500 kbit/s bus (a common rate for these drives), not a property of the simulation.
BUS_BITRATE = 500_000


def _say(text: str = "") -> None:
    print(text, flush=True)


def _served_spec(bench: Bench, bus: str) -> str:
    """The open_bus spec of a simulated bus: its socketcand server on 127.0.0.1."""
    srv = bench.served_buses[bus].servers[0]
    return f"socketcand:{srv.host}:{srv.port}/can0"


def _discover(bench: Bench) -> tuple[list[tuple[str, str, str, str]], list[str]]:
    """(axis, kind in the file, address, what answered) for every axis, and what
    answered on a bus that the file does not list."""
    from .discovery import discover

    from concurrent.futures import ThreadPoolExecutor

    specs = [_served_spec(bench, name) for name in bench.served_buses]
    # One discovery per bus, side by side: each waits mostly on reply timeouts.
    with ThreadPoolExecutor(max_workers=max(1, len(specs))) as pool:
        found = [f for d in pool.map(lambda spec: discover(buses=[spec], timeout=20.0), specs) for f in d.found]
    on_can = {(f.bus, f.address): f for f in found}
    rows = []
    for name, cfg in bench.config.items():
        plugin = registry.drive_plugin(cfg.kind)
        if cfg.bus:
            f = on_can.get((_served_spec(bench, cfg.bus), cfg.address))
            got = f"{f.kind} {f.identity.get('model', '')}".strip() if f else "nothing"
        else:   # the line is the bench's own: ask this axis's address with the kind's identity probe
            try:
                ident = plugin.probe(bench.lines[cfg.line], cfg.address) if plugin.provides("probe") else None
            except _core.MotorbusError as e:   # the demo goes on: the table says what the probe met
                ident, got = None, f"nothing ({type(e).__name__})"
            else:
                got = f"{cfg.kind} {ident.get('model', '')}".strip() if ident else "nothing"
        rows.append((name, cfg.kind, cfg.address, got))
    listed = {(_served_spec(bench, c.bus), c.address) for c in bench.config.values() if c.bus}
    extra = [f"{f.kind} {f.address} on {f.bus}" for f in found if (f.bus, f.address) not in listed]
    return rows, extra


def _table(title: str, header: list[str], rows: list[list[str]]) -> None:
    try:
        from rich.console import Console
        from rich.table import Table
    except ImportError:   # rich is a dependency; plain text if it is somehow missing
        _say(title)
        for r in [header, *rows]:
            _say("  " + "  ".join(f"{c:>12}" for c in r))
        return
    t = Table(title=title, title_justify="left")
    for h in header:
        t.add_column(h, justify="left" if h in ("axis", "kind", "file", "discovered", "result") else "right")
    for r in rows:
        t.add_row(*r)
    Console(width=max(100, len(header) * 14), force_terminal=sys.stdout.isatty()).print(t)


def main(quick: bool = False, out: Optional[str] = None, bench_file: Optional[str] = None) -> int:
    """Runs the demo on ``bench_file`` (default: the shipped demo bench); 0 when every
    axis reached its target, 1 when one did not (its row says why)."""
    t_start = time.monotonic()
    out = out or "motorbus-demo"
    os.makedirs(out, exist_ok=True)
    path = bench_file or DEFAULT_BENCH
    _say(f"motorbus demo: the bench {os.path.basename(path)} as its simulated twin "
         f"(serial lines on ptys, CAN buses over socketcand on 127.0.0.1)")
    written: list[str] = []
    with Bench.load(path, sim=True) as bench:
        for name, srv in bench.served_lines.items():
            _say(f"  line {name}: {srv.slave_path}")
        for name in bench.served_buses:
            _say(f"  bus {name}: {_served_spec(bench, name)}")

        _say("\n== discovery over those transports")
        t0 = time.monotonic()
        rows, extra = _discover(bench)
        _table("discovered vs the bench file", ["axis", "file", "address", "discovered"],
               [[a, k, addr, got] for a, k, addr, got in rows])
        matched = sum(1 for _, k, _, got in rows if got.split(" ")[0] == k)
        _say(f"  {matched}/{len(rows)} axes found as the file describes them ({time.monotonic() - t0:.1f} s: "
             f"a CANopen scan of nodes 1-127 and the CAN probes per bus, an identity query per serial axis)")
        _say("  not in the file: " + (", ".join(extra) if extra else "nothing"))

        _say("\n== enable, apply the file's parameters, home")
        # An axis that fails here is left out of the move and its row says why: the
        # others still run, and the demo exits non-zero.
        failed: dict[str, tuple[str, str]] = {}    # axis -> (a word for the table, the whole reason)
        t0 = time.monotonic()
        for name, d in bench.axes.items():
            step = "parameters refused"
            try:
                bench.apply([name])
                step = "not enabled"
                d.enable()
                step = "not homed"
                d.home(timeout=30)
                bench.apply([name])   # homing routines may leave their own search speeds behind
            except _core.MotorbusError as e:
                failed[name] = (step, f"{step}, not moved: {_why(e)}")
                _say(f"  {name}: {failed[name][1]}")
        homed = [n for n in bench.axes if n not in failed]
        _say(f"  {len(homed)} of {len(bench)} axes homed in {time.monotonic() - t0:.2f} s: "
             + ", ".join(f"{n}={bench[n].position:g}" for n in homed))

        scale = 0.4 if quick else 1.0
        movers = {n: bench[n] for n in homed}
        targets = {n: TARGETS.get(n, 10.0) * scale for n in movers}
        starts = {n: d.position for n, d in movers.items()}
        plans = {}
        for n, d in movers.items():
            if type(d).provides("plan_move"):
                try:
                    plans[n] = plot.planned(d, starts[n], targets[n])
                except _core.MotorbusError as e:   # the kind's model refuses these settings: no plan line
                    _say(f"  {n}: no planned profile ({e})")
        pollable = {n: d for n, d in movers.items() if type(d).provides("poll_fields")}

        _say(f"\n== coordinated move, polled at {RATE_HZ:g} Hz, CAN traffic recorded")
        candump = os.path.join(out, "demo_can.log")
        for old in _candumps(candump, len(bench.buses)):
            os.remove(old)   # a log left by an earlier run must not be listed as this run's
        report = None
        t_cmd = _core.runtime.monotonic_ns() / 1e9
        with (Poller(pollable, fields=("position",), rate_hz=RATE_HZ, candump=candump) if pollable
              else contextlib.nullcontext()) as poller:
            time.sleep(0.05)
            t_cmd = _core.runtime.monotonic_ns() / 1e9
            if movers:
                try:
                    report = bench.move_together(targets, wait=False)
                except _core.MotorbusError as e:    # not even started: every mover's row says so
                    failed.update({n: ("not started", _why(e)) for n in movers})
                for n, d in movers.items():
                    if n in failed:
                        continue
                    try:
                        d.wait_idle(30)
                    except _core.MotorbusError as e:   # MoveFailed (limit, fault, stall, stop...), a timeout
                        failed[n] = (getattr(e, "outcome", "error"), _why(e))
                    else:
                        last = d.status.last_move
                        if last is not None and not last.ok:
                            failed[n] = (last.state, f"{last.state}: {last.reason}")
            if poller is not None:
                _polled_past(poller, _core.runtime.monotonic_ns() / 1e9)
        frame = poller.frame() if poller is not None else {"t": np.zeros(0)}
        stats = poller.stats if poller is not None else {}
        frame_path = os.path.join(out, "demo_frame.npz")
        np.savez(frame_path, **frame)
        written.append(frame_path)
        offsets = report.offsets if report is not None else {}
        if report is not None:
            _say(f"  started by {report.method}; skew {report.skew * 1000:.2f} ms; "
                 f"{len(frame['t'])} deadlines")

        missed = {a: s.get("missed", 0) for s in stats.values() for a in s["axes"]}
        data: dict[str, np.ndarray] = {}
        table = []
        for n, d in bench.axes.items():
            unit = f" {d.units.name}" if d.units.name else ""
            reached = d.position
            err = "—"
            samples = "not polled"
            if n in pollable:
                samples = str(int(np.count_nonzero(~np.isnan(frame[f"{n}.position"]))))
            if n in plans and n in pollable:
                c = plot.compare(frame, n, plans[n], t_cmd + offsets.get(n, 0.0))
                # A poll group that stopped early (its error is printed below the table) may
                # have no sample of the move: say so rather than take the max of nothing.
                err = f"{np.max(np.abs(c['error'])):.3g}{unit}" if len(c["error"]) else "no samples"
                for k, v in c.items():
                    data[f"{n}.{k}"] = v
                data[f"{n}.plan_t"], data[f"{n}.plan_p"] = plans[n]["t"], plans[n]["p"]
                data[f"{n}.target"] = np.array(targets[n])
            target = f"{targets[n]:g}{unit}" if n in targets else "—"
            result = f"✗ {failed[n][0]}" if n in failed else "reached"
            table.append([n, d.kind, target, f"{reached:g}{unit}", result, err, samples,
                          str(missed.get(n, "—"))])
        _table("the coordinated move", ["axis", "kind", "target", "position", "result", "max |error| vs plan",
                                        "samples", "missed"], table)
        for n, (_, why) in failed.items():
            _say(f"  ✗ {n}: {why}")
        _say("  position: where the axis came to rest, in its units; result: reached (at rest within the "
             "kind's in-position window of the target) or ✗ why not (limit, fault, stall, interrupted, timeout, "
             "not homed...)")
        _say("  max |error| vs plan: the largest |measured - planned| position during the move, against the "
             "kind's own profile model (— : no model or not polled)")
        _say(f"  samples: positions polled at {RATE_HZ:g} Hz; missed: poll deadlines the poll thread passed "
             f"before its read answered (a slow line, a loaded host)")
        for group, s in stats.items():
            if s.get("error"):
                _say(f"  poll group {group} stopped early: {s.get('error_type')}: {s['error']}")

        logs = _candumps(candump, len(bench.buses))
        png = os.path.join(out, "demo.png")
        drawn, load = _draw(png, frame, plans, pollable, t_cmd, offsets, logs, bench, data)
        if load:
            _say(f"  CAN bus load of {os.path.basename(logs[0])} at {BUS_BITRATE / 1000:g} kbit/s (worst-case "
                 f"stuffing): {load['count']} frames, mean {load['mean']:.1f} %, peak {load['peak']:.1f} % per "
                 f"{load['window'] * 1000:g} ms")
        plot_npz = os.path.join(out, "demo_plot.npz")
        np.savez(plot_npz, **data)
    _say(f"\n  recording: {', '.join(written + logs)}")
    _say(f"  plot: {png} (its arrays: {plot_npz})" if drawn else f"  plot arrays: {plot_npz} (no PNG written)")
    if failed:
        _say(f"demo finished in {time.monotonic() - t_start:.1f} s: {len(failed)} of {len(bench.config)} axes did "
             f"not reach their target ({', '.join(failed)})")
        return 1
    _say(f"demo finished in {time.monotonic() - t_start:.1f} s")
    return 0


def _why(e: BaseException) -> str:
    """One line: the error's class and message (a MoveFailed names axis, place and reason)."""
    return " ".join(f"{type(e).__name__}: {e}".split())


def _polled_past(poller: Poller, t: float, timeout: float = 2.0) -> None:
    """Until every poll group has a row taken after ``t`` (every axis at rest by then): on a
    loaded machine the poll thread can lag the end of the moves by more than a few
    milliseconds, and the plot's last sample must be where each axis came to rest."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        frame = poller.frame()
        times = [v for k, v in frame.items() if k == "t" or k.endswith(".t")]
        if times and all(len(v) and v[-1] >= t for v in times):
            return
        time.sleep(0.02)


def _candumps(path: str, buses: int) -> list[str]:
    """The candump logs the Poller writes for ``path`` (``name.log``, ``name-2.log``
    for a second bus...) that exist."""
    stem, ext = os.path.splitext(path)
    names = [path] + [f"{stem}-{i + 1}{ext}" for i in range(1, max(1, buses))]
    return [p for p in names if os.path.exists(p)]


def _draw(png: str, frame: dict, plans: dict, pollable: dict, t_cmd: float, offsets: dict, logs: list[str],
          bench: Bench, data: dict) -> tuple[bool, Optional[dict]]:
    """Draws the PNG: (whether it was written, the bus-load numbers of the first CAN
    recording or None)."""
    try:
        plt = plot._pyplot()
    except plot.MatplotlibMissing as e:
        _say(f"  no plot: {e}")
        return False, None
    axes = list(pollable)
    candump = logs[0] if logs and os.path.getsize(logs[0]) else None
    if not axes and candump is None:
        _say("  no plot: nothing was polled nor recorded")
        return False, None
    rows = len(axes) + (1 if candump else 0)
    fig, grid = plt.subplots(rows, 1, figsize=(9, 2.2 * rows), squeeze=False)
    grid = grid[:, 0]
    for ax, n in zip(grid, axes):
        plot.profile(frame, n, plans.get(n), ax=ax, t0=t_cmd + offsets.get(n, 0.0), units=bench[n].units.name)
    numbers = None
    if candump is not None:   # the first CAN group's traffic
        _, numbers = plot.bus_load(candump, BUS_BITRATE, window=0.05, ax=grid[-1])
        for k in ("t", "load"):
            data[f"bus_load.{k}"] = numbers[k]
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)
    return True, numbers

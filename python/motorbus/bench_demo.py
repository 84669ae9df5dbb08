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
4. a summary table (target, reached, max following error against the kind's own
   profile model, samples, missed deadlines) and a PNG (planned vs measured per
   axis, CAN bus load), with the arrays it plotted in ``demo_plot.npz``.
"""
from __future__ import annotations

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
            ident = plugin.probe(bench.lines[cfg.line], cfg.address) if plugin.probe else None
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
        t.add_column(h, justify="left" if h in ("axis", "kind", "file", "discovered") else "right")
    for r in rows:
        t.add_row(*r)
    Console(width=max(100, len(header) * 14), force_terminal=sys.stdout.isatty()).print(t)


def main(quick: bool = False, out: Optional[str] = None, bench_file: Optional[str] = None) -> int:
    t_start = time.monotonic()
    out = out or "motorbus-demo"
    os.makedirs(out, exist_ok=True)
    path = bench_file or DEFAULT_BENCH
    _say(f"motorbus demo: the bench {os.path.basename(path)} as its simulated twin "
         f"(serial lines on ptys, CAN buses over socketcand on 127.0.0.1)")
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
        bench.apply()
        for name, d in bench.axes.items():
            d.enable()
        t0 = time.monotonic()
        for name, d in bench.axes.items():
            d.home(timeout=30)
        bench.apply()   # homing routines may leave their own search speeds behind
        _say(f"  {len(bench)} axes homed in {time.monotonic() - t0:.2f} s: "
             + ", ".join(f"{n}={d.position:g}" for n, d in bench.axes.items()))

        scale = 0.4 if quick else 1.0
        targets = {n: TARGETS.get(n, 10.0) * scale for n in bench.axes}
        starts = {n: d.position for n, d in bench.axes.items()}
        plans = {}
        for n, d in bench.axes.items():
            if registry.drive_plugin(d.kind).plan_move is not None:
                plans[n] = plot.planned(d, starts[n], targets[n])
        pollable = {n: d for n, d in bench.axes.items() if registry.drive_plugin(d.kind).poll_fields is not None}

        _say(f"\n== coordinated move, polled at {RATE_HZ:g} Hz, CAN traffic recorded")
        candump = os.path.join(out, "demo_can.log")
        with Poller(pollable, fields=("position",), rate_hz=RATE_HZ, candump=candump) as poller:
            time.sleep(0.05)
            t_cmd = _core.monotonic_ns() / 1e9
            report = bench.move_together(targets, timeout=30)
            time.sleep(0.05)
        frame = poller.frame()
        stats = poller.stats
        frame_path = os.path.join(out, "demo_frame.npz")
        np.savez(frame_path, **frame)
        _say(f"  started by {report.method}; skew {report.skew * 1000:.2f} ms; "
             f"{len(frame['t'])} deadlines")

        missed = {a: s.get("missed", 0) for s in stats.values() for a in s["axes"]}
        data: dict[str, np.ndarray] = {}
        table = []
        for n, d in bench.axes.items():
            unit = d.units.name or ""
            reached = d.position
            err = "—"
            samples = "not polled"
            if n in pollable:
                samples = str(int(np.count_nonzero(~np.isnan(frame[f"{n}.position"]))))
            if n in plans and n in pollable:
                c = plot.compare(frame, n, plans[n], t_cmd + report.offsets.get(n, 0.0))
                # A poll group that stopped early (its error is printed below the table) may
                # have no sample of the move: say so rather than take the max of nothing.
                err = f"{np.max(np.abs(c['error'])):.3g}" if len(c["error"]) else "no samples"
                for k, v in c.items():
                    data[f"{n}.{k}"] = v
                data[f"{n}.plan_t"], data[f"{n}.plan_p"] = plans[n]["t"], plans[n]["p"]
                data[f"{n}.target"] = np.array(targets[n])
            table.append([n, d.kind, f"{targets[n]:g} {unit}", f"{reached:g}", err, samples,
                          str(missed.get(n, "—"))])
        _table("the coordinated move", ["axis", "kind", "target", "reached", "max |error| vs plan",
                                        "samples", "missed"], table)
        for group, s in stats.items():
            if s.get("error"):
                _say(f"  poll group {group} stopped early: {s.get('error_type')}: {s['error']}")

        png = os.path.join(out, "demo.png")
        load = _draw(png, frame, plans, pollable, t_cmd, report.offsets, candump, bench, data)
        if load:
            _say(f"  CAN bus load of the recording at {BUS_BITRATE / 1000:g} kbit/s (worst-case stuffing): "
                 f"{load['count']} frames, mean {load['mean']:.1f} %, peak {load['peak']:.1f} % per "
                 f"{load['window'] * 1000:g} ms")
        np.savez(os.path.join(out, "demo_plot.npz"), **data)
    _say(f"\n  recording: {frame_path}, {candump}")
    _say(f"  plot: {png} (its arrays: {os.path.join(out, 'demo_plot.npz')})")
    _say(f"demo finished in {time.monotonic() - t_start:.1f} s")
    return 0


def _draw(png: str, frame: dict, plans: dict, pollable: dict, t_cmd: float, offsets: dict, candump: str,
          bench: Bench, data: dict) -> Optional[dict]:
    """Draws the PNG; returns the bus-load numbers of the first CAN recording (None without one)."""
    try:
        plt = plot._pyplot()
    except plot.MatplotlibMissing as e:
        _say(f"  no plot: {e}")
        return None
    axes = [n for n in pollable]
    fig, grid = plt.subplots(len(axes) + 1, 1, figsize=(9, 2.2 * (len(axes) + 1)))
    for ax, n in zip(grid, axes):
        plot.profile(frame, n, plans.get(n), ax=ax, t0=t_cmd + offsets.get(n, 0.0), units=bench[n].units.name)
    numbers = None
    if os.path.exists(candump) and os.path.getsize(candump):   # the first CAN group's traffic
        _, numbers = plot.bus_load(candump, BUS_BITRATE, window=0.05, ax=grid[-1])
        for k in ("t", "load"):
            data[f"bus_load.{k}"] = numbers[k]
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)
    return numbers

"""``motorbus monitor BENCH [--rate HZ] [--axis NAME]... [--sim]`` — watch a bench live.

A table (one row per axis: position, velocity, state, what the drive says) redrawn
``--rate`` times a second (default 10) with rich.  The monitor only reads, through
the Drive API: it never commands motion and stops nothing, neither while it runs
nor when it leaves (its drives are closed, not stopped), so it can watch a bench
another program is moving (a bench file pointing at the same CAN bus; a serial
line has room for one program).  ``q`` or Ctrl-C quits with exit code 0.

An axis that does not answer keeps its row, with the error in place of its readings.
"""
from __future__ import annotations

import argparse
import os
import select
import sys
import time
from contextlib import contextmanager
from typing import Any, Iterator, Optional

from . import _core
from .bench import Bench, BenchFileError

EXIT_OK, EXIT_USAGE = 0, 2


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def _flags(st: Any) -> str:
    on = [w for w, f in (("enabled", st.enabled), ("moving", st.moving), ("homed", st.homed),
                         ("at target", st.at_target), ("+limit", st.limit_positive),
                         ("-limit", st.limit_negative)) if f]
    return " ".join(on) or "-"


def read_rows(bench: Bench, names: list[str]) -> list[tuple]:
    """``(axis, kind, position, velocity, units, state, fault, drive says)`` per axis,
    read now; an axis that fails to answer says why instead."""
    rows = []
    for name in names:
        d = bench[name]
        try:
            st = d.status
            rows.append((name, d.kind, _fmt(d.position), _fmt(d.velocity), d.units.name, _flags(st),
                         "FAULT" if st.fault else "-", st.text or "-"))
        except _core.MotorbusError as e:
            rows.append((name, d.kind, "?", "?", d.units.name, "-", "no answer", f"{type(e).__name__}: {e}"))
    return rows


def render(bench: Bench, names: list[str], rate: float, frame: int) -> Any:
    from rich.table import Table

    sim = " (simulated twin)" if bench.simulated else ""
    table = Table(title=f"{bench.source}{sim}", caption=f"{rate:g} Hz, frame {frame} — q or Ctrl-C quits",
                  title_justify="left", caption_justify="left")
    for col, justify in (("axis", "left"), ("kind", "left"), ("position", "right"), ("velocity", "right"),
                         ("units", "left"), ("state", "left"), ("fault", "left"), ("drive says", "left")):
        table.add_column(col, justify=justify, no_wrap=col != "drive says")
    for row in read_rows(bench, names):
        style = "bold red" if row[6] != "-" else None
        table.add_row(*row, style=style)
    return table


class _Keys:
    """Single key presses from stdin without echo (a terminal in cbreak mode: Ctrl-C
    still interrupts); from a pipe, its bytes; nothing once it is at its end."""

    def __init__(self, stream: Any) -> None:
        self.fd: Optional[int] = None
        try:
            self.fd = stream.fileno()
        except (AttributeError, OSError, ValueError):
            self.fd = None

    def wait(self, timeout: float) -> str:
        """A key pressed within ``timeout`` s, else ""."""
        if self.fd is None:
            time.sleep(timeout)
            return ""
        ready, _, _ = select.select([self.fd], [], [], timeout)
        if not ready:
            return ""
        data = os.read(self.fd, 32)
        if not data:          # end of input: keep running, stop watching it
            self.fd = None
            return ""
        return data.decode("utf-8", "replace")


@contextmanager
def _cbreak(stream: Any) -> Iterator[None]:
    try:
        fd = stream.fileno()
        interactive = os.isatty(fd)
    except (AttributeError, OSError, ValueError):
        interactive = False
    if not interactive:
        yield
        return
    import termios
    import tty

    saved = termios.tcgetattr(fd)
    try:
        tty.setcbreak(fd)
        yield
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


def cmd_monitor(args: argparse.Namespace) -> int:
    from rich.console import Console
    from rich.live import Live

    if not args.rate > 0:
        print(f"motorbus monitor: --rate: a rate above 0 Hz, not {args.rate:g}", file=sys.stderr)
        return EXIT_USAGE
    try:
        bench = Bench.load(args.bench, sim=args.sim)
    except BenchFileError as e:
        print(f"motorbus: {e}", file=sys.stderr)
        return EXIT_USAGE
    try:
        for d in bench.axes.values():
            # Watching must not change what it watches: no stop when the monitor leaves.
            d.on_error = None
            d.on_exit = None
        try:
            names = list(bench.select(args.axis))
        except _core.InvalidArgument as e:
            print(f"motorbus: {e}", file=sys.stderr)
            return EXIT_USAGE
        period = 1.0 / args.rate
        keys = _Keys(sys.stdin)
        console = Console()
        frame = 0
        try:
            with _cbreak(sys.stdin), Live(render(bench, names, args.rate, frame), console=console,
                                          auto_refresh=False, transient=False) as live:
                next_t = time.monotonic()
                while True:
                    next_t += period
                    key = keys.wait(max(0.0, next_t - time.monotonic()))
                    if "q" in key.lower():
                        break
                    if time.monotonic() > next_t + period:   # slow drives: do not try to catch up
                        next_t = time.monotonic()
                    frame += 1
                    live.update(render(bench, names, args.rate, frame), refresh=True)
        except KeyboardInterrupt:
            pass
        return EXIT_OK
    finally:
        bench.close()     # closes the links; stops nothing


def add_commands(sub: Any) -> None:
    p = sub.add_parser("monitor", help="a live table of every axis (reads only; q or Ctrl-C quits)")
    p.add_argument("bench", metavar="BENCH", help="the bench file (TOML)")
    p.add_argument("--rate", type=float, default=10.0, metavar="HZ", help="redraws per second (default 10)")
    p.add_argument("--axis", action="append", help="only this axis (repeatable; default every axis)")
    p.add_argument("--sim", action="store_true", help="watch the bench's simulated twin")
    p.set_defaults(func=cmd_monitor)

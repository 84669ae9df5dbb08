"""``motorbus status|move|home|stop|config`` — work a bench described in a TOML file.

    motorbus status BENCH [--sim]
    motorbus move BENCH AXIS POSITION [--by] [--velocity V] [--timeout S] [--sim]
    motorbus home BENCH AXIS [--method M] [--timeout S] [--sim]
    motorbus stop BENCH [AXIS...] [--quick] [--sim]
    motorbus config read|diff|apply|store BENCH [--axis NAME]... [--all] [--sim]
    motorbus scan [--serial PORT]... [--can SPEC]... [--kind KIND]... [--write BENCH] [--timeout S]
    motorbus terminal BENCH AXIS [--sim]     (the drive's own protocol, line by line, with history)

Exit codes: 0 done; 1 a drive refused or failed (the message says which axis
and why); 2 the command line or the bench file is wrong (``file:line: key:
...``); 3 ``config diff`` found differences; 130 interrupted (Ctrl-C during a
move or homing stops that axis first).  ``--sim`` runs the command against the
bench's simulated twin (every axis replaced by its simulator).
"""
from __future__ import annotations

import argparse
import os
import sys
from typing import Any, Callable, Optional, Sequence

from . import _core
from .bench import Bench, BenchFileError

EXIT_OK, EXIT_DRIVE, EXIT_USAGE, EXIT_DIFFERENT, EXIT_INTERRUPTED = 0, 1, 2, 3, 130


def table(rows: Sequence[Sequence[Any]], header: Sequence[str]) -> str:
    """Plain aligned columns: readable on a terminal and in a log file."""
    cells = [[str(c) for c in header]] + [[str(c) for c in r] for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _say(text: str) -> None:
    print(text, flush=True)


def _with_bench(args: argparse.Namespace, work: Callable[[Bench], int]) -> int:
    """Opens the bench, runs `work`, maps errors to exit codes; every axis is
    stopped on the way out (the Bench's `with`)."""
    try:
        bench = Bench.load(args.bench, sim=args.sim)
    except BenchFileError as e:
        print(f"motorbus: {e}", file=sys.stderr)
        return EXIT_USAGE
    with bench:
        try:
            return work(bench)
        except BenchFileError as e:
            print(f"motorbus: {e}", file=sys.stderr)
            return EXIT_USAGE
        except _core.InvalidArgument as e:
            print(f"motorbus: {e}", file=sys.stderr)
            return EXIT_USAGE
        except _core.MotorbusError as e:
            print(f"motorbus: {type(e).__name__}: {e}", file=sys.stderr)
            return EXIT_DRIVE


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def cmd_status(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        rows = []
        for name, d in bench.axes.items():
            st = d.status
            flags = [w for w, on in (("enabled", st.enabled), ("moving", st.moving), ("homed", st.homed),
                                     ("FAULT", st.fault), ("+limit", st.limit_positive),
                                     ("-limit", st.limit_negative)) if on]
            rows.append((name, d.kind, _fmt(d.position), d.units.name, " ".join(flags) or "-", st.text))
        _say(table(rows, ("axis", "kind", "position", "units", "state", "drive says")))
        return EXIT_OK
    return _with_bench(args, work)


def _interruptible(drive: Any, action: Callable[[], None]) -> int:
    """Runs a move/homing; Ctrl-C stops the axis (decelerating) and exits 130."""
    try:
        action()
    except KeyboardInterrupt:
        drive.stop()
        print("motorbus: interrupted: axis stopped", file=sys.stderr)
        return EXIT_INTERRUPTED
    return EXIT_OK


def cmd_move(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        d = bench[args.axis]
        if not d.status.enabled:
            d.enable()
        move = d.move_by if args.by else d.move_to
        # On stderr, so stdout stays the one result line scripts read.
        print(f"{args.axis}: moving {'by' if args.by else 'to'} {_fmt(args.position)} {d.units.name} "
              "(Ctrl-C stops the axis)", file=sys.stderr, flush=True)
        rc = _interruptible(d, lambda: move(args.position, velocity=args.velocity, timeout=args.timeout))
        _say(f"{args.axis}: {_fmt(d.position)} {d.units.name}")
        return rc
    return _with_bench(args, work)


def cmd_home(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        d = bench[args.axis]
        if not d.status.enabled:
            d.enable()
        method: Any = args.method
        if method is not None and method.lstrip("-").isdigit():
            method = int(method)  # CiA 402 methods are numbers
        rc = _interruptible(d, lambda: d.home(method, timeout=args.timeout))
        _say(f"{args.axis}: homed at {_fmt(d.position)} {d.units.name}")
        return rc
    return _with_bench(args, work)


def cmd_stop(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        how = "quick_stop" if args.quick else "stop"
        failed = []
        for name, d in bench.select(args.axes).items():
            try:
                getattr(d, how)()
                _say(f"{name}: stopped")
            except _core.MotorbusError as e:
                failed.append(name)
                print(f"motorbus: {name}: {type(e).__name__}: {e}", file=sys.stderr)
        return EXIT_DRIVE if failed else EXIT_OK
    return _with_bench(args, work)


def cmd_config(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        axes = args.axis or None
        if args.action == "read":
            rows = [(axis, p, v) for axis, params in bench.read_params(axes, all_params=args.all).items()
                    for p, v in params.items()]
            _say(table(rows, ("axis", "parameter", "drive value")))
            return EXIT_OK
        if args.action == "diff":
            diffs = bench.diff(axes)
            if diffs:
                _say(table([(c.axis, c.name, c.file_value, c.drive_value) for c in diffs],
                           ("axis", "parameter", "file", "drive")))
            else:
                _say("no differences")
            return EXIT_DIFFERENT if diffs else EXIT_OK
        if args.action == "apply":
            changed = bench.apply(axes)
            for c in changed:
                _say(f"{c.axis}.{c.name}: {c.drive_value} -> {c.file_value}")
            _say(f"{len(changed)} parameter(s) written")
            return EXIT_OK
        bench.store(axes)
        _say(f"stored on {', '.join(bench.select(axes))}")
        return EXIT_OK
    return _with_bench(args, work)


def cmd_scan(args: argparse.Namespace) -> int:
    from .discovery import discover

    if not args.serial and not args.can:
        print("motorbus scan: give --serial PORT and/or --can SPEC", file=sys.stderr)
        return EXIT_USAGE
    try:
        result = discover(args.serial or (), args.can or (), kinds=args.kind, timeout=args.timeout,
                          reply_timeout=args.reply_timeout, progress=not args.quiet)
    except _core.InvalidArgument as e:
        print(f"motorbus: {e}", file=sys.stderr)
        return EXIT_USAGE
    rows = [(f.kind, f.address, f.line or f.bus, f.baud or "", ", ".join(f"{k}={v}" for k, v in f.identity.items()))
            for f in result.found]
    _say(table(rows, ("kind", "address", "where", "baud", "identity")) if rows else "no drive answered")
    for s in result.skipped:
        print(f"motorbus: not probed (time budget or port): {s}", file=sys.stderr)
    if args.write:
        result.write(args.write)
        _say(f"wrote {args.write}")
    return EXIT_OK


def cmd_terminal(args: argparse.Namespace) -> int:
    """Reads lines (a prompt with history on a terminal, plain lines from a pipe), sends
    each in the axis's own protocol and prints the answer; errors are printed and the
    console goes on.  `quit`, `exit` or end of input leave (the axis is stopped)."""
    interactive = sys.stdin.isatty()
    history = os.path.expanduser("~/.motorbus_history")
    if interactive:
        try:
            import readline
            try:
                readline.read_history_file(history)
            except OSError:
                pass
        except ImportError:  # pragma: no cover - readline is in every CPython on Linux
            readline = None  # type: ignore[assignment]

    def work(bench: Bench) -> int:
        d = bench[args.axis]
        if interactive:
            _say(f"{args.axis}: {d.kind} — its own protocol; 'quit' leaves")
        while True:
            try:
                line = input(f"{args.axis}> " if interactive else "")
            except EOFError:
                break
            except KeyboardInterrupt:
                print()
                continue
            if line.strip() in ("quit", "exit"):
                break
            if not line.strip():
                continue
            try:
                _say(d.console(line))
            except _core.MotorbusError as e:
                _say(f"! {type(e).__name__}: {e}")
        if interactive and readline is not None:
            try:
                readline.write_history_file(history)
            except OSError:
                pass
        return EXIT_OK
    return _with_bench(args, work)


def add_commands(sub: Any) -> None:
    """Adds the bench commands to the top-level parser's subparsers."""
    def bench_parser(name: str, help: str) -> argparse.ArgumentParser:
        p = sub.add_parser(name, help=help)
        p.add_argument("bench", metavar="BENCH", help="the bench file (TOML)")
        p.add_argument("--sim", action="store_true", help="run against the bench's simulated twin")
        return p

    p = bench_parser("status", "a table of every axis: position, state, what the drive says")
    p.set_defaults(func=cmd_status)
    p = bench_parser("move", "move an axis (in the bench's units); Ctrl-C stops it")
    p.add_argument("axis")
    p.add_argument("position", type=float)
    p.add_argument("--by", action="store_true", help="relative move")
    p.add_argument("--velocity", type=float, default=None, help="speed for this move (user units/s)")
    p.add_argument("--timeout", type=float, default=None, help="seconds to wait for the end of the move")
    p.set_defaults(func=cmd_move)
    p = bench_parser("home", "home an axis; Ctrl-C stops it")
    p.add_argument("axis")
    p.add_argument("--method", default=None, help="the drive's own homing method (default: the kind's)")
    p.add_argument("--timeout", type=float, default=None)
    p.set_defaults(func=cmd_home)
    p = bench_parser("stop", "stop axes (all when none is named)")
    p.add_argument("axes", nargs="*", metavar="AXIS")
    p.add_argument("--quick", action="store_true", help="the fastest stop the drive has")
    p.set_defaults(func=cmd_stop)
    p = sub.add_parser("scan", help="find the drives on serial lines and CAN buses (reads only)")
    p.add_argument("--serial", action="append", metavar="PORT", help="a serial port to sweep; repeatable")
    p.add_argument("--can", action="append", metavar="SPEC", help="an open_bus spec to scan; repeatable")
    p.add_argument("--kind", action="append", help="only these kinds (default: every registered kind)")
    p.add_argument("--write", metavar="BENCH", help="write a bench file for what was found")
    p.add_argument("--timeout", type=float, default=300.0, help="time budget for the whole scan (s)")
    p.add_argument("--reply-timeout", type=float, default=0.05, help="wait per serial address (s)")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=cmd_scan)
    p = bench_parser("terminal", "an interactive console in the axis's own protocol, with history")
    p.add_argument("axis")
    p.set_defaults(func=cmd_terminal)
    p = sub.add_parser("config", help="read, compare, apply or store the bench file's drive parameters")
    p.add_argument("action", choices=("read", "diff", "apply", "store"))
    p.add_argument("bench", metavar="BENCH")
    p.add_argument("--axis", action="append", help="only this axis (repeatable)")
    p.add_argument("--all", action="store_true", help="read: every parameter the drive has, not just the file's")
    p.add_argument("--sim", action="store_true", help="run against the bench's simulated twin")
    p.set_defaults(func=cmd_config)


def main(argv: Optional[Sequence[str]] = None) -> int:  # pragma: no cover - via motorbus.cli
    from .cli import main as cli_main
    return cli_main(argv)

"""The ``motorbus`` command line (also ``python -m motorbus``).

    motorbus bus serve SPEC [--socketcand HOST:PORT] [--slcan-pty] [--channel NAME]   (SIGUSR1: counters)
    motorbus bus dump SPEC [--count N] [--log FILE]
    motorbus bus play FILE SPEC [--speed X]
    motorbus sim serve [--pty] [--bus virtual:NAME] [--bitrate N] [--socketcand HOST:PORT]...
                       [--slcan-pty]... --drive KIND:ADDR[,ADDR...]... [--baud N [--strict-baud]] [--store-dir DIR]
    motorbus sim serve --bench FILE [--write FILE] [--link-dir DIR] [--port PORT|BUS=PORT]... [--control]
    motorbus drives
    motorbus demo
    motorbus status|move|home|stop|enable|disable|clear|config ... BENCH [--json] [--sim]   (cli_bench.py)
    motorbus monitor BENCH [--rate HZ] [--axis NAME]... [--ask] [--sim]   (python/motorbus/cli_monitor.py)
    motorbus serve BENCH [--sim] [--prefix P] [--interface ADDR]... [--no-epics]   (cli_serve.py, docs/serve.md)
    motorbus --version;  motorbus -v|-vv|--trace COMMAND ...   (logging to stderr; --trace: frames and lines)

The exit codes are one table (cli_bench.EXIT_CODES), printed at the end of ``motorbus --help``.
"""
from __future__ import annotations

import argparse
import logging
import signal
import sys
import threading
from typing import Any, Optional, Sequence

from . import _core
from .bus import open_bus

log = logging.getLogger(__name__)


def _wait_for_signal(on_usr1: Optional[Any] = None) -> None:
    """Blocks until SIGINT or SIGTERM, then returns (so servers close cleanly);
    SIGUSR1 calls ``on_usr1`` (a status report) and goes on waiting."""
    stop = threading.Event()
    usr1 = threading.Event()

    def handler(signum: int, frame: Any) -> None:
        (usr1 if signum == signal.SIGUSR1 else stop).set()

    signals = [signal.SIGINT, signal.SIGTERM] + ([signal.SIGUSR1] if on_usr1 is not None else [])
    old = {s: signal.signal(s, handler) for s in signals}
    try:
        while not stop.wait(0.2):
            if usr1.is_set():
                usr1.clear()
                on_usr1()
    finally:
        for s, h in old.items():
            signal.signal(s, h)


def _say(line: str) -> None:
    print(line, flush=True)


# ---------------------------------------------------------------------------
def cmd_bus_serve(args: argparse.Namespace) -> int:
    """Serves one bus to other processes until SIGINT/SIGTERM (see motorbus.bus_server)."""
    from .bus_server import BusServers

    socketcand = args.socketcand or ([] if args.slcan_pty else ["127.0.0.1:0"])
    with BusServers(args.spec, socketcand=socketcand, slcan_ptys=args.slcan_pty, channel=args.channel) as servers:
        for line in servers.announce():
            _say(line)
        _wait_for_signal(on_usr1=lambda: _report(servers))
        _report(servers)
    return 0


def _report(servers: Any) -> None:
    """Counters and drops per server, on stderr (stdout carries the announce lines)."""
    for line in servers.report():
        print(line, file=sys.stderr, flush=True)


def _refuse_served(spec: str, what: str) -> None:
    from .cli_bench import refuse_served_link

    refuse_served_link(spec, what)


def cmd_bus_dump(args: argparse.Namespace) -> int:
    _refuse_served(args.spec, "a bus dump")
    bus = open_bus(args.spec)
    rec = _core.can.Recorder(bus, args.log) if args.log else None
    n = 0
    try:
        while args.count == 0 or n < args.count:
            f = bus.recv(0.2)
            if f is None:
                continue
            _say(f"({f.timestamp_ns / 1e9:.6f}) {args.spec} {f}")
            n += 1
    except KeyboardInterrupt:
        pass
    finally:
        if rec:
            rec.stop()
        bus.close()
    return 0


def cmd_bus_play(args: argparse.Namespace) -> int:
    _refuse_served(args.spec, "replaying frames onto its bus")
    entries, bad = _core.can.read_log(args.file)
    with open_bus(args.spec) as bus:
        n = _core.can.play(bus, entries, args.speed)
    _say(f"played {n} frames ({bad} unreadable lines skipped)")
    return 0


# ---------------------------------------------------------------------------
def cmd_sim_serve(args: argparse.Namespace) -> int:
    """Serial kinds on ptys, CAN kinds as nodes on one served bus (see motorbus.sim);
    with --bench, every axis of a bench file on stable paths (motorbus.sim.BenchTwin)."""
    from .sim import SimBench

    if args.bench:
        return _sim_serve_bench(args)
    if not args.drive:
        raise _core.InvalidArgument("sim serve: what to serve? --drive KIND:ADDR[,ADDR...] or --bench FILE")
    for flag in ("write", "link_dir", "port", "control"):
        if getattr(args, flag):
            raise _core.InvalidArgument(f"sim serve: --{flag.replace('_', '-')} goes with --bench FILE")
    with SimBench(args.drive, bus=args.bus, bitrate=args.bitrate, socketcand=args.socketcand or (),
                  slcan_ptys=args.slcan_pty, channel=args.channel, baud=args.baud,
                  strict_baud=args.strict_baud, store_dir=args.store_dir) as bench:
        for line in bench.announce():
            _say(line)
        report = (lambda: _report(bench.can)) if bench.can is not None else None
        _wait_for_signal(on_usr1=report)
        if report is not None:
            report()
    return 0


def _sim_serve_bench(args: argparse.Namespace) -> int:
    """``sim serve --bench FILE``: the file's twin, until SIGINT/SIGTERM (or, with
    --control, the end of stdin: a test that dies leaves no twin behind)."""
    from .sim import BenchTwin, TwinBusy

    for flag, given in (("--drive", args.drive), ("--bus", args.bus), ("--socketcand", args.socketcand),
                        ("--slcan-pty", args.slcan_pty)):
        if given:
            raise _core.InvalidArgument(f"sim serve --bench: {flag} does not apply (the file names the axes, "
                                        f"lines and buses; --port fixes the socketcand ports)")
    ports: Any = None
    for text in args.port or ():
        name, eq, number = text.rpartition("=")
        try:
            port = int(number)
        except ValueError:
            raise _core.InvalidArgument(f"--port {text!r}: expected PORT or BUS=PORT") from None
        if not eq and ports is None:
            ports = port
        elif eq and (ports is None or isinstance(ports, dict)):
            ports = {**(ports or {}), name: port}
        else:
            raise _core.InvalidArgument(f"--port {text!r}: give one PORT (buses in file order take PORT, "
                                        f"PORT+1...) or BUS=PORT for each bus, not both")
    try:
        twin = BenchTwin(args.bench, link_dir=args.link_dir, ports=ports, channel=args.channel, baud=args.baud,
                         strict_baud=args.strict_baud, bitrate=args.bitrate, store_dir=args.store_dir)
    except TwinBusy as e:
        print(f"motorbus: {e}", file=sys.stderr)
        return 4   # busy, as for a serial port another process holds (cli_bench.EXIT_BUSY)
    stop, usr1 = threading.Event(), threading.Event()

    def on_signal(signum: int, frame: Any) -> None:
        (usr1 if signum == signal.SIGUSR1 else stop).set()

    def report() -> None:
        for r in twin.report():
            print(r, file=sys.stderr, flush=True)

    # Handlers first: the end of --control input stops serving through the same event.
    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGUSR1)}
    try:
        with twin:
            for line in twin.announce():
                _say(line)
            if args.write:
                _say(f"bench {twin.write(args.write)}")   # last: a reader waiting for it finds the twin up
            if args.control:
                lock = threading.Lock()

                def answer(text: str) -> None:
                    with lock:
                        _say(text)

                def control() -> None:
                    twin.serve_control(sys.stdin, answer)
                    stop.set()     # end of input: a test that died leaves no twin behind

                threading.Thread(target=control, name="sim serve control", daemon=True).start()
            while not stop.wait(0.2):
                if usr1.is_set():
                    usr1.clear()
                    report()
            report()
    finally:
        for s, h in old.items():
            signal.signal(s, h)
    return 0


def cmd_drives(args: argparse.Namespace) -> int:
    """Lists the registered drive kinds."""
    from .registry import drive_plugins

    from .cli_bench import table

    rows = [(kind, plugin.transport, plugin.description) for kind, plugin in drive_plugins().items()]
    _say(table(rows, ("kind", "link", "description")))
    return 0


def cmd_demo(args: argparse.Namespace) -> int:
    if args.tour:
        from . import demo

        return demo.tour(quick=args.quick)
    from . import bench_demo

    return bench_demo.main(quick=args.quick, out=args.out, bench_file=args.bench)


# ---------------------------------------------------------------------------
def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("motorbus")
    except PackageNotFoundError:  # pragma: no cover - run from a source tree without metadata
        return "unknown (not installed)"


def _log_options(p: argparse.ArgumentParser, default: Any) -> None:
    """-v / --trace, on the top-level parser and after every command (``motorbus move ... -v``)."""
    p.add_argument("-v", "--verbose", action="count", default=default,
                   help="log what motorbus does to stderr (-v: opening links and drives; -vv: every drive command)")
    p.add_argument("--trace", action="store_true", default=default,
                   help="-vv and a protocol trace: every CAN frame on the bench's buses and every line on its "
                        "serial lines")


def setup_logging(verbose: int, trace: bool) -> None:
    """Python logging to stderr for the ``motorbus`` loggers (the library never configures
    logging itself; a program using it does, as here)."""
    from . import trace as protocol_trace

    if not verbose and not trace:
        return
    level = logging.DEBUG if trace or verbose >= 2 else logging.INFO
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(relativeCreated)9.1f ms %(name)s: %(message)s"))
    root = logging.getLogger("motorbus")
    root.addHandler(handler)
    root.setLevel(level)
    if trace:
        protocol_trace.enable()
    else:
        logging.getLogger("motorbus.trace").setLevel(logging.WARNING)


def build_parser() -> argparse.ArgumentParser:
    from .cli_bench import exit_codes_text

    p = argparse.ArgumentParser(prog="motorbus", description="Drive integrated motor controllers over CAN, "
                                "CANopen and serial lines; serve buses and simulated drives.",
                                epilog=exit_codes_text(), formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"motorbus {_version()}")
    _log_options(p, 0)
    # The same options after a command; SUPPRESS keeps the top-level value when not given there.
    common = argparse.ArgumentParser(add_help=False)
    _log_options(common, argparse.SUPPRESS)
    sub = p.add_subparsers(dest="command", required=True)

    bus = sub.add_parser("bus", help="serve, dump or replay a CAN bus").add_subparsers(dest="bus_cmd", required=True)
    s = bus.add_parser("serve", help="serve a bus over socketcand (TCP) and/or SLCAN (pty)")
    s.add_argument("spec", help="bus spec, e.g. virtual:bench")
    s.add_argument("--socketcand", action="append", metavar="HOST:PORT",
                   help="socketcand server address (port 0 picks a free port); repeatable")
    s.add_argument("--slcan-pty", action="count", default=0, help="serve an SLCAN adapter on a new pty; repeatable")
    s.add_argument("--channel", default="can0", help="channel name announced to socketcand clients")
    s.set_defaults(func=cmd_bus_serve)
    d = bus.add_parser("dump", help="print frames (candump style), optionally logging them")
    d.add_argument("spec")
    d.add_argument("--count", type=int, default=0, help="stop after N frames (0 = until Ctrl-C)")
    d.add_argument("--log", help="also write a candump (.log) or ASC (.asc) file")
    d.set_defaults(func=cmd_bus_dump)
    pl = bus.add_parser("play", help="replay a candump/ASC log onto a bus")
    pl.add_argument("file")
    pl.add_argument("spec")
    pl.add_argument("--speed", type=float, default=1.0, help="1 = original timing, 0 = as fast as possible")
    pl.set_defaults(func=cmd_bus_play)

    sim = sub.add_parser("sim", help="simulated drives; `sim serve --bench FILE` serves a bench's twin that lasts "
                                     "(--sim on other commands makes a fresh one per command)"
                         ).add_subparsers(dest="sim_cmd", required=True)
    ss = sim.add_parser(
        "serve", help="serve simulated drives: serial kinds on ptys, CAN kinds on a served bus",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Serve simulated drives to other processes until SIGINT/SIGTERM.\n\n"
                    "--drive KIND:ADDR...: drives of any kinds; prints `<spec> <pty>` per serial line and the CAN "
                    "servers.\n\n"
                    "--bench FILE: every axis of a bench file, with its `sim` options, as ONE twin that lasts. "
                    "`--sim` on status/move/home/monitor/... makes a fresh twin for that one command (its "
                    "positions and faults end with it); serve the twin here instead and point those commands, "
                    "notebooks and `pytest --bench` at the file --write writes:\n"
                    "  motorbus sim serve --bench bench.toml --write twin.toml &\n"
                    "  motorbus move twin.toml x 10; motorbus status twin.toml\n"
                    "Each serial line is the symlink LINK_DIR/<line name> to its pty (default LINK_DIR: "
                    "$TMPDIR or /tmp, then motorbus-sim-<uid>/<bench file name without .toml>); each bus a "
                    "socketcand server on 127.0.0.1 (--port fixes the port). Prints `line NAME LINK -> PTY`, "
                    "`bus NAME SPEC`, then `bench FILE` once written. Exit 4 (busy) if another twin serves LINK_DIR.\n\n"
                    "--control: commands on stdin, one per line, each answered by one line `ok ...` or "
                    "`error: ...`: `fault AXIS NAME [key=value ...]` (the kind's sim_faults, values read as "
                    "true/false, int, float or text), `faults AXIS` (the names), `axes`. End of stdin stops "
                    "serving. motorbus.sim.ServedBench runs all this from a test.")
    ss.add_argument("--drive", action="append", metavar="KIND:ADDR[,ADDR...]",
                    help="drives of one registered kind (`motorbus drives` lists them): a serial line with one "
                         "or more drives of a serial kind (KIND:01,02 = RS-485 multi-drop), or CAN nodes (cia402:5,6); "
                         "repeatable")
    ss.add_argument("--bench", default=None, metavar="FILE",
                    help="serve every axis of this bench file (with its sim options) instead of --drive")
    ss.add_argument("--write", default=None, metavar="FILE",
                    help="with --bench: write the bench file of what is served (same axes, units, params; "
                         "ports = the line symlinks, specs = the socketcand servers)")
    ss.add_argument("--link-dir", default=None, metavar="DIR",
                    help="with --bench: where the line symlinks DIR/<line name> go (default: see above)")
    ss.add_argument("--port", action="append", metavar="PORT|BUS=PORT",
                    help="with --bench: the socketcand port of the first bus (the next bus in the file gets "
                         "PORT+1...), or of the named bus (repeatable); default: free ports")
    ss.add_argument("--control", action="store_true",
                    help="with --bench: read fault-injection commands on stdin (see above)")
    ss.add_argument("--pty", action="store_true", help="serve serial lines on pseudo-terminals (the default)")
    ss.add_argument("--baud", type=int, default=0, help="pace serial replies at this baud rate (0 = unthrottled)")
    ss.add_argument("--strict-baud", action="store_true",
                    help="with --baud: requests sent at another baud rate arrive garbled and go unanswered, "
                         "as on a real UART (to check that a client or gateway sets the rate)")
    ss.add_argument("--store-dir", default=None, help="where drives persist their stored settings")
    ss.add_argument("--bus", default=None, metavar="SPEC",
                    help="the CAN bus the CAN drives sit on (default: a new virtual bus)")
    ss.add_argument("--bitrate", type=int, default=None, help="wire time of the virtual CAN bus (bit/s)")
    ss.add_argument("--socketcand", action="append", metavar="HOST:PORT",
                    help="serve the CAN bus over socketcand (port 0 picks a free port); repeatable; "
                         "default 127.0.0.1:0 when CAN drives are served")
    ss.add_argument("--slcan-pty", action="count", default=0, help="serve the CAN bus as an SLCAN adapter on a pty")
    ss.add_argument("--channel", default="can0", help="channel name announced to socketcand clients")
    ss.set_defaults(func=cmd_sim_serve)

    dl = sub.add_parser("drives", help="list the registered drive kinds", parents=[common])
    dl.set_defaults(func=cmd_drives)

    from . import cli_bench, cli_monitor, cli_serve
    cli_bench.add_commands(sub, common)
    cli_monitor.add_commands(sub, common)
    cli_serve.add_commands(sub, common)

    dm = sub.add_parser("demo", help="run the simulated bench demo")
    dm.add_argument("--quick", action="store_true", help="shorter moves (used by the tests)")
    dm.add_argument("--out", default=None, metavar="DIR",
                    help="where to write the recording and plot (default: ./motorbus-demo)")
    dm.add_argument("--bench", default=None, metavar="FILE",
                    help="bench file to simulate (default: the demo bench shipped with motorbus)")
    dm.add_argument("--tour", action="store_true", help="instead: the older tour of the transports one by one")
    dm.set_defaults(func=cmd_demo)
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    from .cli_bench import EXIT_INTERRUPTED, error_text, exit_code

    args = build_parser().parse_args(argv)
    setup_logging(getattr(args, "verbose", 0) or 0, bool(getattr(args, "trace", False)))
    try:
        return int(args.func(args) or 0)
    except _core.MotorbusError as e:
        # The exit code says what kind of failure (cli_bench.EXIT_CODES): a port held by
        # another process is not a mistake in the command line.
        print(error_text(e), file=sys.stderr)
        return exit_code(e)
    except KeyboardInterrupt:
        print("motorbus: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())

"""``motorbus status|move|home|stop|enable|disable|clear|config|scan|terminal`` — work a bench
described in a TOML file.

    motorbus status BENCH [--json] [--sim]
    motorbus move BENCH AXIS POSITION [--by] [--velocity V] [--timeout S] [--json] [--sim]
    motorbus home BENCH AXIS [--method M] [--timeout S] [--json] [--sim]
    motorbus stop BENCH [AXIS...] [--quick] [--sim]
    motorbus enable|disable|clear BENCH AXIS [--sim]
    motorbus config read|diff|apply|store BENCH [--axis NAME]... [--all] [--json] [--sim]
    motorbus scan [--serial PORT]... [--can SPEC]... [--kind KIND]... [--write BENCH] [--timeout S] [--json]
    motorbus terminal BENCH AXIS [--sim]     (the drive's own protocol, line by line, with history)

The exit codes are one table, :data:`EXIT_CODES` (``motorbus --help`` prints it).
``status``, ``config read`` and ``config diff`` only read: they send nothing that
changes a drive and stop nothing when they leave (another program may be moving the
bench).  A command naming axes opens only the lines and buses those axes are on.
``--sim`` runs the command against the bench's simulated twin: a fresh one per
command (every axis replaced by its simulator, at its power-on state).

While ``motorbus serve BENCH`` runs, every command above but ``scan`` and ``terminal``
goes through it (``--server ADDR`` names a service, ``--no-server`` opens the transports
here anyway); ``terminal``, and a ``scan`` of a line or bus it holds, are refused with
exit code 4 (docs/serve.md).  The exit codes stay the Drive API's outcome codes.
"""
from __future__ import annotations

import argparse
import json
import logging
import math
import os
import sys
import time
from typing import Any, Callable, Optional, Sequence

from . import _core
from .bench import Bench, BenchFileError
from .drive import MoveFailed

log = logging.getLogger(__name__)

# ---- exit codes: one table, printed by `motorbus --help` and docs/bench-files.md -----------------
EXIT_OK = 0
EXIT_DRIVE = 1          # a drive refused a command or failed (not a move outcome below)
EXIT_USAGE = 2          # the command line or the bench file is wrong
EXIT_DIFFERENT = 3      # config diff: the drives differ from the file
EXIT_BUSY = 4           # a serial port is held by another process
EXIT_LINK = 5           # a line or bus cannot be reached, or a drive does not answer
EXIT_MOVE_INTERRUPTED = 10   # a move stopped short: a stop from another program or a stop input
EXIT_MOVE_LIMIT = 11         # a move stopped at a hard or soft limit
EXIT_MOVE_FAULT = 12         # the drive faulted during the move
EXIT_MOVE_STALL = 13         # stall or following error
EXIT_MOVE_TIMEOUT = 14       # not at rest within --timeout (the axis was stopped)
EXIT_MOVE_FAILED = 15        # a move failed another way
EXIT_INTERRUPTED = 130       # Ctrl-C (a move or homing is stopped first)

EXIT_CODES: tuple[tuple[int, str], ...] = (
    (EXIT_OK, "done (a move or homing ended where it was sent)"),
    (EXIT_DRIVE, "a drive refused a command or failed (the message says which axis and why)"),
    (EXIT_USAGE, "the command line or the bench file is wrong (file:line: key, or the argument)"),
    (EXIT_DIFFERENT, "config diff found differences"),
    (EXIT_BUSY, "busy: a serial port is held by another process, or the bench by its `motorbus serve` "
                "(the message names it)"),
    (EXIT_LINK, "a line or bus cannot be reached, or a drive did not answer"),
    (EXIT_MOVE_INTERRUPTED, "move/home stopped short by a stop from another program or a drive stop input"),
    (EXIT_MOVE_LIMIT, "move/home stopped by a limit switch or soft limit"),
    (EXIT_MOVE_FAULT, "move/home ended by a drive fault (its code and text)"),
    (EXIT_MOVE_STALL, "move/home ended by a stall or following error"),
    (EXIT_MOVE_TIMEOUT, "move/home not finished within --timeout (the axis is stopped)"),
    (EXIT_MOVE_FAILED, "move/home failed another way"),
    (EXIT_INTERRUPTED, "Ctrl-C (a move or homing is stopped, and waited for, first)"),
)

#: MoveFailed.outcome -> exit code.
OUTCOME_EXIT = {"interrupted": EXIT_MOVE_INTERRUPTED, "limit": EXIT_MOVE_LIMIT, "fault": EXIT_MOVE_FAULT,
                "stall": EXIT_MOVE_STALL, "timeout": EXIT_MOVE_TIMEOUT, "failed": EXIT_MOVE_FAILED}


def exit_codes_text() -> str:
    """The exit-code table as ``motorbus --help`` prints it."""
    return "exit codes:\n" + "\n".join(f"  {code:<4d} {meaning}" for code, meaning in EXIT_CODES)


#: The largest position or speed, in native units, a command line may ask for: every
#: in-tree kind's position and speed registers are 32-bit (CiA 402 0x607A/0x6081 and the
#: vendors' own), so a larger value cannot be what was meant.
NATIVE_MAX = 2 ** 31 - 1


def is_busy(e: BaseException) -> bool:
    """A port held by another process (the C++ PortBusy, raised as a LinkDown)."""
    return isinstance(e, _core.LinkDown) and " is busy: " in str(e)


def _served_elsewhere(e: BaseException) -> bool:
    from .serve.lockfile import ServedElsewhere
    return isinstance(e, ServedElsewhere)


def exit_code(e: BaseException) -> int:
    """The exit code for an error that ended a command (see EXIT_CODES)."""
    if _served_elsewhere(e):
        return EXIT_BUSY       # the bench is held by its service, as a port held by another process
    if isinstance(e, MoveFailed):
        return OUTCOME_EXIT.get(e.outcome, EXIT_MOVE_FAILED)
    if isinstance(e, _core.InvalidArgument):       # BenchFileError too
        return EXIT_USAGE
    if is_busy(e):
        return EXIT_BUSY
    if isinstance(e, (_core.LinkDown, _core.TimeoutError)):
        return EXIT_LINK
    return EXIT_DRIVE


def error_text(e: BaseException) -> str:
    """One line for stderr: the error in its own words (the class name where it adds to them)."""
    if isinstance(e, (MoveFailed, _core.InvalidArgument)) or is_busy(e) or _served_elsewhere(e):
        return f"motorbus: {e}"
    return f"motorbus: {type(e).__name__}: {e}"


def table(rows: Sequence[Sequence[Any]], header: Sequence[str]) -> str:
    """Plain aligned columns: readable on a terminal and in a log file."""
    cells = [[str(c) for c in header]] + [[str(c) for c in r] for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _say(text: str) -> None:
    print(text, flush=True)


def _err(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def _json(obj: Any) -> None:
    print(json.dumps(obj, indent=2, default=_json_default), flush=True)


def _json_default(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, (bytes, bytearray)):
        return v.hex()
    if isinstance(v, (tuple, list)):
        return list(v)
    return str(v)


def _num(v: Any) -> Any:
    """JSON has no inf/nan: None instead."""
    return None if isinstance(v, float) and not math.isfinite(v) else v


# ---- opening a bench ------------------------------------------------------------------------------
class NotOpened:
    """An axis ``load_bench`` was told not to open (``open_axis`` said no): its place in
    the bench, with what the file says of it (``config``), and no Drive."""

    closed = True

    def __init__(self, config: Any) -> None:
        self.config, self.kind, self.name = config, config.kind, config.name

    def close(self) -> None:
        pass


def load_bench(path: str, *, sim: bool, axes: Optional[Sequence[str]] = None,
               open_axis: Optional[Callable[[Any], bool]] = None) -> Bench:
    """Opens the bench file; with ``axes``, only those axes and the lines and buses they
    are on (``stop BENCH z`` must not open, or need, the serial line of another axis).
    An axis name the file does not have is an InvalidArgument listing its axes.  With
    the protocol trace on (``--trace``), the bench's transports are traced from before
    its axes are opened.  ``open_axis(AxisConfig)`` False: that axis's links are opened
    but not the axis itself (``NotOpened`` in its place: nothing is sent to it)."""
    from . import trace

    wanted = list(dict.fromkeys(axes)) if axes else None
    tracer = trace.Tracer() if trace.enabled() else None

    class CliBench(Bench):
        # Bench.load reads and checks the file, then builds cls(data, ...): the data is
        # narrowed here, before anything is opened (the text keeps its line numbers).
        def __init__(self, data: Any, **kw: Any) -> None:
            super().__init__(data if wanted is None else _only_axes(data, wanted, path), **kw)

        def _open_links(self) -> None:
            shared: set = set()
            if tracer is not None:
                for name, cfg in self._bus_cfg.items():
                    if tracer.watch_spec(name, cfg["spec"]):
                        shared.add(name)
            super()._open_links()
            if tracer is not None:
                for name, bus in self.buses.items():
                    if name not in shared:
                        tracer.watch_bus(name, bus)
                for name, link in self.lines.items():
                    tracer.watch_line(name, link)

        def _open_axis(self, cfg: Any) -> Any:
            if open_axis is not None and not open_axis(cfg):
                return NotOpened(cfg)
            return super()._open_axis(cfg)

        def close(self) -> None:
            try:
                super().close()
            finally:
                if tracer is not None:
                    tracer.close()

    if wanted is None and tracer is None and open_axis is None:
        return Bench.load(path, sim=sim)
    return CliBench.load(path, sim=sim)


def _only_axes(data: Any, wanted: Sequence[str], source: str) -> Any:
    if not isinstance(data, dict) or not isinstance(data.get("axis"), dict):
        return data                      # malformed: the checker says how
    table_ = data["axis"]
    missing = [n for n in wanted if n not in table_]
    if missing:
        raise _core.InvalidArgument(f"bench {source}: no axis {missing[0]!r} (axes: {', '.join(table_)})")
    kept = {n: table_[n] for n in wanted}
    out = dict(data)
    out["axis"] = kept
    for section, key in (("bus", "bus"), ("line", "line")):
        links = data.get(section)
        if isinstance(links, dict):
            used = {t.get(key) for t in kept.values() if isinstance(t, dict)}
            out[section] = {name: t for name, t in links.items() if name in used}
            if not out[section]:
                del out[section]
    return out


# ---- a bench served by `motorbus serve` ------------------------------------------------------------
def service_address(args: argparse.Namespace) -> Optional[str]:
    """Where this command's bench is served, or None to open its transports here:
    ``--server ADDR`` as given; else the running service of the bench file
    (serve.find_service), unless ``--no-server``, or ``--sim`` while the service owns the
    hardware (then a fresh twin, as asked, and the hardware is left alone)."""
    if getattr(args, "no_server", False):
        _warn_served(args)
        return None
    server = getattr(args, "server", None)
    if server:
        return server
    info = _service_of(args)
    if info is None:
        return None
    if info.sim and not getattr(args, "sim", False):
        _err(f"motorbus: note: {args.bench} is served by motorbus serve --sim (pid {info.pid}): "
             f"this works its simulated twin")
    log.info("%s: through motorbus serve (pid %d) at %s", args.bench, info.pid, info.socket)
    return f"unix:{info.socket}"


def _warn_served(args: argparse.Namespace) -> None:
    info = _service_of(args)
    if info is not None:
        _err(f"motorbus: warning: {args.bench} is served by motorbus serve (pid {info.pid}); --no-server "
             f"talks to the drives beside it (a serial port it holds is busy; a CAN node answers both)")


def _service_of(args: argparse.Namespace) -> Any:
    """The running service of args.bench that matters to a command opening transports here."""
    from .serve.lockfile import find_service

    try:
        info = find_service(args.bench)
    except OSError:
        return None
    if info is None or (getattr(args, "sim", False) and not info.sim):
        return None
    return info


def refuse_if_served(args: argparse.Namespace, what: str) -> None:
    """``what`` (a protocol console, raw SDO) needs the bench's own transports: while its
    service runs, a ServedElsewhere naming the service's pid (exit code 4)."""
    from .serve.lockfile import ServedElsewhere

    info = _service_of(args)
    if info is not None:
        raise ServedElsewhere(args.bench, info.pid, what)


def refuse_served_link(link: str, what: str) -> None:
    """A bus spec or serial port that a running `motorbus serve` holds: ServedElsewhere."""
    from .serve.lockfile import ServedElsewhere, served_link

    info = served_link(link)
    if info is not None:
        raise ServedElsewhere(info.bench, info.pid, what)


def connect_service(address: str) -> Any:
    """A RemoteBench on the service at ``address`` (it quacks like a Bench)."""
    from .serve.client import connect

    return connect(address)


class _Narrowed:
    """A served bench seen through the axes a command named (``axes``): the service
    serves every axis; the command works, and stops on its way out, only its own."""

    def __init__(self, bench: Any, axes: Optional[Sequence[str]]) -> None:
        self._bench = bench
        names = list(dict.fromkeys(axes)) if axes else list(bench.axes)
        try:
            # An axis the service lacks: the bench's own InvalidArgument naming its axes.
            self.axes = {n: bench[n] for n in names}
        except BaseException:
            bench.close()
            raise

    def __getitem__(self, name: str) -> Any:
        return self._bench[name]

    def stop_all(self, how: str = "stop") -> list:
        failures = []
        for name, d in self.axes.items():
            try:
                getattr(d, how)()
            except _core.MotorbusError as e:
                failures.append((name, e))
        return failures

    def __getattr__(self, name: str) -> Any:
        return getattr(self._bench, name)


def _open(args: argparse.Namespace, axes: Optional[Sequence[str]], **kw: Any) -> tuple[Any, bool]:
    """(bench, served): through the bench's service when one runs (module doc), else
    the transports opened here (only ``axes``' lines and buses)."""
    address = service_address(args)
    if address is not None:
        return _Narrowed(connect_service(address), axes), True
    return load_bench(args.bench, sim=args.sim, axes=axes, **kw), False


def _run(args: argparse.Namespace, work: Callable[[Bench], int], *, axes: Optional[Sequence[str]] = None,
         stop_on_exit: bool = True) -> int:
    """Opens the bench (only ``axes`` when given), runs ``work``, maps errors to exit
    codes.  ``stop_on_exit``: every opened axis is stopped on the way out, as the Bench's
    ``with`` does; a command that only reads passes False and just closes (it must not
    stop what another program is moving).  With the bench served (``motorbus serve``),
    the same through the service: "opened" are the axes named."""
    try:
        bench, served = _open(args, axes)
    except _core.MotorbusError as e:
        return _failed(args, e)
    if served:
        log.info("%s: served: %s", args.bench, ", ".join(bench.axes))
    else:
        log.info("%s: opened %s%s (lines: %s; buses: %s)", bench.source, ", ".join(bench.axes),
                 " on its simulated twin" if bench.simulated else "", ", ".join(bench.lines) or "none",
                 ", ".join(bench.buses) or "none")
    try:
        try:
            return work(bench)
        except _core.MotorbusError as e:
            return _failed(args, e)
        finally:
            if stop_on_exit:
                log.info("stopping %s on the way out", ", ".join(bench.axes))
                for name, e in bench.stop_all():
                    _err(f"motorbus: {name}: could not stop: {type(e).__name__}: {e}")
    finally:
        bench.close()


def _failed(args: argparse.Namespace, e: BaseException) -> int:
    """An error that ended the command: on stderr, and with --json also as the result on
    stdout (``{"error", "message", "exit_code"}``) so a script parsing stdout gets one."""
    code = exit_code(e)
    _err(error_text(e))
    if is_busy(e) and getattr(args, "no_server", False):
        info = _service_of(args)
        if info is not None:
            _err(f"motorbus: {args.bench} is served by motorbus serve (pid {info.pid}), which holds its "
                 f"transports: drop --no-server to go through it, or stop the service")
    if getattr(args, "json", False):
        _json({"error": type(e).__name__, "message": str(e), "exit_code": code})
    return code


def _fmt(v: Any) -> str:
    return f"{v:.6g}" if isinstance(v, (int, float)) else str(v)


# ---- argument types: a typed error naming the argument, exit 2 ---------------------------------------
def finite_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a number, not {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"a finite number, not {text!r}")
    if abs(v) > 1e15:
        # No bench moves that far in any unit; such a number is a typo.
        raise argparse.ArgumentTypeError(f"{text} is beyond any drive's range")
    return v


def positive_float(text: str) -> float:
    v = finite_float(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"a number above 0, not {text}")
    return v


def seconds(text: str) -> float:
    v = finite_float(text)
    if v < 0:
        raise argparse.ArgumentTypeError(f"seconds >= 0, not {text}")
    return v


def homing_method(text: str) -> Any:
    """A CiA 402 method number (an INTEGER8 in 0x6098) or the kind's method name."""
    t = text.strip()
    if t.lstrip("+-").isdigit():
        if len(t) > 5 or not -128 <= int(t) <= 127:
            raise argparse.ArgumentTypeError(f"a homing method number is -128..127 (CiA 402 0x6098, an "
                                             f"INTEGER8), not {t}")
        return int(t)
    if not t:
        raise argparse.ArgumentTypeError("a method number or name, not an empty string")
    return t


def _check_native(d: Any, name: str, value: float) -> None:
    """Refuses, before anything is sent, a value the drive's 32-bit registers cannot hold."""
    native = abs(d.units.to_native(value))
    if not math.isfinite(native) or native > NATIVE_MAX:
        raise _core.InvalidArgument(f"argument {name}: {value:g} {d.units.name} is {native:.3g} native units, "
                                    f"beyond the drive's range (±{NATIVE_MAX})")


# ---- the commands -----------------------------------------------------------------------------------
def _flags(st: Any) -> list[str]:
    return [w for w, on in (("enabled", st.enabled), ("moving", st.moving), ("homed", st.homed),
                            ("FAULT", st.fault), ("+limit", st.limit_positive),
                            ("-limit", st.limit_negative)) if on]


def _outcome_json(last: Any) -> Any:
    if last is None:
        return None
    e = last.error
    return {"what": last.what, "target": _num(last.target), "position": _num(last.position), "outcome": last.state,
            "reason": last.reason, "code": getattr(e, "code", None)}


def cmd_status(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        rows, out = [], {}
        for name, d in bench.axes.items():
            st = d.status
            pos = d.position
            rows.append((name, d.kind, _fmt(pos), d.units.name, " ".join(_flags(st)) or "-", st.text))
            out[name] = {"kind": d.kind, "position": _num(pos), "units": d.units.name, "enabled": st.enabled,
                         "moving": st.moving, "homed": st.homed, "fault": st.fault, "at_target": st.at_target,
                         "limit_positive": st.limit_positive, "limit_negative": st.limit_negative,
                         "text": st.text, "last_move": _outcome_json(st.last_move)}
        if args.json:
            _json({"bench": bench.source, "simulated": bench.simulated, "axes": out})
        else:
            _say(table(rows, ("axis", "kind", "position", "units", "state", "drive says")))
        return EXIT_OK
    # Reads only: nothing is stopped on the way out (another program may be moving the bench).
    return _run(args, work, stop_on_exit=False)


def _stop_and_settle(d: Any, limit: float = 5.0) -> Optional[MoveFailed]:
    """Ctrl-C: stops the axis and waits (up to ``limit`` s) until it is at rest, so the
    position said afterwards is where it stopped, not where it was braking.  Returns the
    move's outcome error (None if it had ended anyway)."""
    try:
        d.stop()
    except _core.MotorbusError as e:
        log.warning("%s: stop after Ctrl-C failed: %s", d.name, e)
        return None
    try:
        d.wait_idle(timeout=limit)
    except MoveFailed as e:
        return e
    except _core.MotorbusError as e:
        log.warning("%s: waiting for rest after Ctrl-C: %s", d.name, e)
    return None


def _motion(args: argparse.Namespace, bench: Bench, what: str, action: Callable[[Any], None],
            target: Optional[float]) -> int:
    """Runs a move or homing on ``args.axis`` and reports how it ended: the position on
    stdout (or the JSON result), why it ended short on stderr, the outcome's exit code."""
    d = bench[args.axis]
    error: Optional[MoveFailed] = None
    interrupted = False
    try:
        if not d.status.enabled:
            d.enable()
        action(d)
    except MoveFailed as e:
        error = e
    except KeyboardInterrupt:
        interrupted = True
        try:
            error = _stop_and_settle(d)
        except KeyboardInterrupt:      # a second Ctrl-C: the fastest stop, no more waiting
            d.quick_stop()
    if isinstance(error, MoveFailed) and error.outcome == "timeout":
        _stop_and_settle(d)               # not left running past the time it was given; said at rest
    position = d.position
    if interrupted:
        rest = "at rest" if not d.status.moving else "still braking"
        goal = f", target {_fmt(target)} {d.units.name}" if target is not None else ""
        _err(f"{args.axis}: interrupted: axis stopped at {_fmt(position)} {d.units.name} by Ctrl-C ({rest}){goal}")
        code = EXIT_INTERRUPTED
    elif error is not None:
        _err(error_text(error))
        code = exit_code(error)
    else:
        code = EXIT_OK
    if args.json:
        _json({"axis": args.axis, "kind": d.kind, "what": what, "target": _num(target), "position": _num(position),
               "units": d.units.name,
               "outcome": "ctrl-c" if interrupted else (error.outcome if error else "done"),
               "reason": "Ctrl-C" if interrupted else (error.reason if error else ""),
               "code": getattr(error, "code", None), "exit_code": code})
    elif what == "home" and code == EXIT_OK:
        _say(f"{args.axis}: homed at {_fmt(position)} {d.units.name}")
    else:
        _say(f"{args.axis}: {_fmt(position)} {d.units.name}")
    log.info("%s: %s ended with exit code %d", args.axis, what, code)
    return code


def cmd_move(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        d = bench[args.axis]
        _check_native(d, "POSITION", args.position)
        if args.velocity is not None:
            _check_native(d, "--velocity", args.velocity)
        target = args.position
        if args.by:
            target = d.position + args.position
        # On stderr, so stdout stays the one result line scripts read.
        _err(f"{args.axis}: moving {'by' if args.by else 'to'} {_fmt(args.position)} {d.units.name} "
             "(Ctrl-C stops the axis)")
        move = d.move_by if args.by else d.move_to
        return _motion(args, bench, "move",
                       lambda d: move(args.position, velocity=args.velocity, timeout=args.timeout), target)
    return _run(args, work, axes=[args.axis])


def cmd_home(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        return _motion(args, bench, "home", lambda d: d.home(args.method, timeout=args.timeout), None)
    return _run(args, work, axes=[args.axis])


def cmd_stop(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        how = "quick_stop" if args.quick else "stop"
        failed = []
        for name, d in bench.axes.items():   # the named axes (all when none is named)
            try:
                getattr(d, how)()
                _say(f"{name}: stopped")
            except _core.MotorbusError as e:
                failed.append(exit_code(e))
                _err(f"motorbus: {name}: {type(e).__name__}: {e}")
        return max(failed) if failed else EXIT_OK
    # Only the named axes' lines and buses are opened; the stop itself is the command.
    return _run(args, work, axes=args.axes or None, stop_on_exit=False)


def _one_axis_command(verb: str, say: str) -> Callable[[argparse.Namespace], int]:
    def cmd(args: argparse.Namespace) -> int:
        def work(bench: Bench) -> int:
            d = bench[args.axis]
            getattr(d, verb)()
            st = d.status
            _say(f"{args.axis}: {say}; {' '.join(_flags(st)) or '-'}; {st.text}")
            return EXIT_OK
        # enable/disable/clear leave the axis as they made it: nothing stopped on the way out.
        return _run(args, work, axes=[args.axis], stop_on_exit=False)
    return cmd


cmd_enable = _one_axis_command("enable", "enabled")
cmd_disable = _one_axis_command("disable", "disabled")
cmd_clear = _one_axis_command("clear_faults", "faults cleared")


def cmd_config(args: argparse.Namespace) -> int:
    def work(bench: Bench) -> int:
        axes = args.axis or None
        if args.action == "read":
            params = bench.read_params(axes, all_params=args.all)
            if args.json:
                _json(params)
            else:
                _say(table([(axis, p, v) for axis, ps in params.items() for p, v in ps.items()],
                           ("axis", "parameter", "drive value")))
            return EXIT_OK
        if args.action == "diff":
            diffs = bench.diff(axes)
            if args.json:
                _json([{"axis": c.axis, "parameter": c.name, "file": c.file_value, "drive": c.drive_value}
                       for c in diffs])
            elif diffs:
                _say(table([(c.axis, c.name, c.file_value, c.drive_value) for c in diffs],
                           ("axis", "parameter", "file", "drive")))
            else:
                _say("no differences")
            return EXIT_DIFFERENT if diffs else EXIT_OK
        if args.action == "apply":
            changed = bench.apply(axes)
            if args.json:
                _json([{"axis": c.axis, "parameter": c.name, "was": c.drive_value, "now": c.file_value}
                       for c in changed])
            else:
                for c in changed:
                    _say(f"{c.axis}.{c.name}: {c.drive_value} -> {c.file_value}")
                _say(f"{len(changed)} parameter(s) written")
            return EXIT_OK
        bench.store(axes)
        if args.json:
            _json({"stored": list(bench.select(axes))})
        else:
            _say(f"stored on {', '.join(bench.select(axes))}")
        return EXIT_OK
    # read and diff only read: nothing is stopped on the way out.  apply and store write
    # parameters; the axes are stopped on the way out as after any changing command.
    return _run(args, work, axes=args.axis or None, stop_on_exit=args.action in ("apply", "store"))


#: Identity fields that are codes, shown in hex as the manuals print them.


def _check_writable(path: str) -> Optional[str]:
    """Why ``path`` cannot be written (None: it can), checked before a long scan."""
    full = os.path.abspath(path)
    parent = os.path.dirname(full) or "."
    if os.path.isdir(full):
        return f"{path} is a directory"
    if not os.path.isdir(parent):
        return f"no directory {parent}"
    if os.path.exists(full):
        if not os.path.isfile(full):
            return f"{path} is not a regular file"
        if not os.access(full, os.W_OK):
            return f"{path} is not writable"
    elif not os.access(parent, os.W_OK | os.X_OK):
        return f"cannot create files in {parent}"
    return None


def cmd_scan(args: argparse.Namespace) -> int:
    from . import trace
    from .discovery import discover, identity_text

    if not args.serial and not args.can:
        _err("motorbus scan: give --serial PORT and/or --can SPEC")
        return EXIT_USAGE
    try:
        for link in [*(args.serial or ()), *(args.can or ())]:
            refuse_served_link(link, f"a scan of {link}")
    except _core.MotorbusError as e:
        return _failed(args, e)
    if args.write:
        why = _check_writable(args.write)
        if why is not None:
            _err(f"motorbus scan: argument --write: {why}")
            return EXIT_USAGE
    if trace.enabled():
        log.info("scan: the protocol trace covers the opened benches, not the scan's probes")
    try:
        result = discover(args.serial or (), args.can or (), kinds=args.kind, timeout=args.timeout,
                          reply_timeout=args.reply_timeout, progress=not args.quiet and not args.json)
    except _core.MotorbusError as e:
        return _failed(args, e)
    if args.json:
        _json({"found": [{"kind": f.kind, "address": f.address, "line": f.line, "bus": f.bus, "baud": f.baud,
                          "identity": f.identity} for f in result.found],
               "skipped": [str(s) for s in result.skipped], "wrote": args.write})
    else:
        rows = [(f.kind, f.address, f.line or f.bus, f.baud or "", identity_text(f.identity))
                for f in result.found]
        _say(table(rows, ("kind", "address", "where", "baud", "identity")) if rows else "no drive answered")
    for s in result.skipped:
        _err(f"motorbus: not probed (time budget or port): {s}")
    if args.write:
        try:
            result.write(args.write)
        except OSError as e:
            _err(f"motorbus scan: argument --write: {args.write}: {e.strerror}")
            return EXIT_USAGE
        if not args.json:
            _say(f"wrote {args.write}")
    return EXIT_OK


def cmd_terminal(args: argparse.Namespace) -> int:
    """Reads lines (a prompt with history on a terminal, plain lines from a pipe), sends
    each in the axis's own protocol and prints the answer; errors are printed and the
    console goes on.  `quit`, `exit` or end of input leave (the axis is stopped)."""
    try:
        refuse_if_served(args, "a protocol console (terminal)")
    except _core.MotorbusError as e:
        return _failed(args, e)
    interactive = sys.stdin.isatty()
    history = os.path.expanduser("~/.motorbus_history")
    readline: Any = None
    if interactive:
        try:
            import readline
            try:
                readline.read_history_file(history)
            except OSError:
                pass
        except ImportError:  # pragma: no cover - readline is in every CPython on Linux
            readline = None

    def work(bench: Bench) -> int:
        from .drive import Drive

        d = bench[args.axis]
        if type(d)._console is Drive._console:
            raise _core.InvalidArgument(f"terminal: axis {args.axis!r} ({d.kind}) has no protocol console "
                                        "in motorbus")
        if interactive:
            if getattr(d.native, "sdo", None) is not None:    # a CANopen node: SDO reads and writes
                from .canopen.console import CONSOLE_HELP
                _say(f"{args.axis}: {d.kind} (CANopen) — SDO reads and writes; 'quit' leaves")
                _say(CONSOLE_HELP)
            else:
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
    return _run(args, work, axes=[args.axis])


def server_options(p: argparse.ArgumentParser) -> None:
    """--server / --no-server: how a command reaches a bench that `motorbus serve` owns."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("--server", metavar="ADDR", default=None,
                   help="go through this motorbus serve (unix:PATH, or a bench file it serves); default: the "
                        "running service of BENCH, if any")
    g.add_argument("--no-server", action="store_true",
                   help="open the bench's transports here even while motorbus serve owns them (its serial "
                        "ports are then busy)")


def add_commands(sub: Any, common: Any = None) -> None:
    """Adds the bench commands to the top-level parser's subparsers (``common``: a parent
    parser with the options every command takes, -v/--trace)."""
    parents = [common] if common is not None else []

    def bench_parser(name: str, help: str) -> argparse.ArgumentParser:
        p = sub.add_parser(name, help=help, description=help, parents=parents, epilog=exit_codes_text(),
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        p.add_argument("bench", metavar="BENCH", help="the bench file (TOML)")
        p.add_argument("--sim", action="store_true",
                       help="run against the bench's simulated twin (a fresh twin for this command only)")
        if name != "terminal":
            server_options(p)
        return p

    def with_json(p: argparse.ArgumentParser) -> None:
        p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")

    p = bench_parser("status", "a table of every axis: position, state, what the drive says (reads only)")
    with_json(p)
    p.set_defaults(func=cmd_status)
    p = bench_parser("move", "move an axis (in the bench's units); Ctrl-C stops it")
    p.add_argument("axis", metavar="AXIS", help="an axis of the bench file")
    p.add_argument("position", metavar="POSITION", type=finite_float, help="where to, in the axis's units")
    p.add_argument("--by", action="store_true", help="relative move")
    p.add_argument("--velocity", type=positive_float, default=None,
                   help="speed for this move only (user units/s); the drive's own setting is put back")
    p.add_argument("--timeout", type=seconds, default=None, help="seconds to wait for the end of the move")
    with_json(p)
    p.set_defaults(func=cmd_move)
    p = bench_parser("home", "home an axis; Ctrl-C stops it")
    p.add_argument("axis", metavar="AXIS")
    p.add_argument("--method", type=homing_method, default=None,
                   help="the drive's own homing method: a CiA 402 number or the kind's name (default: the kind's)")
    p.add_argument("--timeout", type=seconds, default=None)
    with_json(p)
    p.set_defaults(func=cmd_home)
    p = bench_parser("stop", "stop axes (all when none is named; opens only the named axes' links)")
    p.add_argument("axes", nargs="*", metavar="AXIS")
    p.add_argument("--quick", action="store_true", help="the fastest stop the drive has")
    p.set_defaults(func=cmd_stop)
    for verb, func, text in (("enable", cmd_enable, "power an axis (it holds position)"),
                             ("disable", cmd_disable, "power stage off: the axis no longer holds position"),
                             ("clear", cmd_clear, "clear an axis's latched faults (limit errors, drive faults)")):
        p = bench_parser(verb, text)
        p.add_argument("axis", metavar="AXIS")
        p.set_defaults(func=func)
    p = sub.add_parser("scan", help="find the drives on serial lines and CAN buses (reads only)", parents=parents)
    p.add_argument("--serial", action="append", metavar="PORT", help="a serial port to sweep; repeatable")
    p.add_argument("--can", action="append", metavar="SPEC", help="an open_bus spec to scan; repeatable")
    p.add_argument("--kind", action="append", help="only these kinds (default: every registered kind)")
    p.add_argument("--write", metavar="BENCH", help="write a bench file for what was found (checked before the scan)")
    p.add_argument("--timeout", type=positive_float, default=300.0, help="time budget for the whole scan (s)")
    p.add_argument("--reply-timeout", type=positive_float, default=0.05, help="wait per serial address (s)")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    with_json(p)
    p.set_defaults(func=cmd_scan)
    p = bench_parser("terminal", "an interactive console in the axis's own protocol, with history")
    p.add_argument("axis", metavar="AXIS")
    p.set_defaults(func=cmd_terminal)
    p = sub.add_parser("config", help="read, compare, apply or store the bench file's drive parameters",
                       parents=parents)
    p.add_argument("action", choices=("read", "diff", "apply", "store"))
    p.add_argument("bench", metavar="BENCH")
    p.add_argument("--axis", action="append", help="only this axis (repeatable)")
    p.add_argument("--all", action="store_true", help="read: every parameter the drive has, not just the file's")
    p.add_argument("--sim", action="store_true",
                   help="run against the bench's simulated twin (a fresh twin for this command only)")
    server_options(p)
    with_json(p)
    p.set_defaults(func=cmd_config)


def main(argv: Optional[Sequence[str]] = None) -> int:  # pragma: no cover - via motorbus.cli
    from .cli import main as cli_main
    return cli_main(argv)

"""``motorbus monitor BENCH [--rate HZ] [--axis NAME]... [--ask] [--sim]`` — watch a bench live.

A table (one row per axis: position, velocity, state, what the drive says) redrawn
``--rate`` times a second (default 10) with rich.  The monitor never commands motion
and stops nothing, neither while it runs nor when it leaves.  ``q`` or Ctrl-C quits
with exit code 0.  ``--axis`` opens only the lines and buses of the axes named.

What it does to the drives, by transport (docs/monitor.md says the same):

* a **serial** axis is asked (its position, speed and status, through the Drive API):
  a serial port is opened by one program at a time, so no other program can be
  talking to it — if one is, the monitor exits with the "busy" code (4);
* a **CAN** axis is, by default, only **listened to**: the monitor sends nothing to it
  and shows what the node sends by itself (heartbeat state, EMCY codes, PDOs or
  cyclic frames another program set up, with their count).  Asking a CANopen node
  would mean SDO requests on the COB-IDs another program uses for its own requests,
  and each would get the other's answers.  ``--ask`` polls CAN axes too: only when no
  other program talks to those nodes.  Under ``--sim`` the twin is the monitor's own
  and every axis is asked.

An axis that does not answer keeps its row, with the error in place of its readings.

While ``motorbus serve BENCH`` runs, the monitor goes through it (``--server ADDR``
names one, ``--no-server`` does not): the service is the one program talking to the
drives, so every axis, CAN ones too, is asked -- by the service, which any number of
monitors share (docs/serve.md).
"""
from __future__ import annotations

import argparse
import collections
import math
import os
import select
import sys
import threading
import time
from contextlib import contextmanager
from typing import Any, Iterator, Optional

from . import _core
from .bench import Bench
from .cli_bench import (EXIT_OK, EXIT_USAGE, NotOpened, _Narrowed, connect_service, error_text, exit_code, load_bench,
                        server_options, service_address)

#: NMT states as a heartbeat carries them (CiA 301).
_NMT = {0x00: "boot-up", 0x04: "stopped", 0x05: "operational", 0x7F: "pre-operational"}


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def _flags(st: Any) -> str:
    on = [w for w, f in (("enabled", st.enabled), ("moving", st.moving), ("homed", st.homed),
                         ("at target", st.at_target), ("+limit", st.limit_positive),
                         ("-limit", st.limit_negative)) if f]
    return " ".join(on) or "-"


class Listener:
    """What a CAN node sends by itself, heard without asking it (see the module doc)."""

    def __init__(self, bus: Any, cfg: Any) -> None:
        self.lock = threading.Lock()
        self.heartbeat: Optional[int] = None
        self.emcy: Optional[int] = None
        self.frames = 0
        self.last = ""
        self.ids: tuple = ()
        address = str(cfg.address)
        if address.isdigit():                 # a CANopen node-ID
            node = int(address)
            self.node = node
            self.ids = tuple(fc + node for fc in (0x080, 0x180, 0x280, 0x380, 0x480, 0x700))
        else:                                 # a receive id (a REGID kind): the drive answers on its transmit id
            tx = cfg.options.get("tx_id")
            self.node = None
            self.ids = (int(tx) if tx is not None else int(address, 0) - 0x80,)
        self._handles = [bus.subscribe(self._on_frame, id=i, mask=0x7FF) for i in self.ids]
        self._bus = bus

    def _on_frame(self, f: Any) -> None:
        with self.lock:
            if self.node is not None and f.id == 0x700 + self.node and f.dlc >= 1:
                self.heartbeat = f.data[0] & 0x7F
                return
            if self.node is not None and f.id == 0x080 + self.node and f.dlc >= 2:
                self.emcy = int.from_bytes(f.data[:2], "little")
                return
            self.frames += 1
            self.last = f"{f.id:03X}#{f.data.hex().upper()}"

    def row(self, name: str, kind: str, units: str) -> tuple:
        with self.lock:
            said = []
            if self.heartbeat is not None:
                said.append(f"heartbeat: {_NMT.get(self.heartbeat, hex(self.heartbeat))}")
            said.append(f"{self.frames} frames sent by the drive" + (f" (last {self.last})" if self.last else ""))
            said.append("not asked: --ask polls it")
            fault = "-" if not self.emcy else f"EMCY 0x{self.emcy:04X}"
            return (name, kind, "-", "-", units, "listening", fault, "; ".join(said))

    def close(self) -> None:
        for h in self._handles:
            try:
                self._bus.unsubscribe(h)
            except _core.MotorbusError:
                pass


class ServedReadings:
    """A monitor's readings of a served bench that cost the drives nothing per monitor:
    the position from the service's shared poll (monitors asking the same axes and rate
    share one Poller in the service), the velocity differentiated from it (every kind
    polls its position; not every kind has a velocity to poll), the
    status, which a poll holds only as the kind's raw word, asked at most ``STATUS_HZ``
    times a second."""

    STATUS_HZ = 2.0
    VELOCITY_WINDOW = 0.1      # seconds of polled positions a velocity is taken over

    def __init__(self, bench: Any, names: list[str], rate: float) -> None:
        self._poll = bench.poll(names, fields=("position",), rate_hz=max(rate, 10.0), keep=1.0)
        self._history: dict[str, collections.deque] = {n: collections.deque(maxlen=256) for n in names}
        self._status: dict[str, Any] = {}
        self._asked = -math.inf

    def _take(self) -> None:
        frame = self._poll.read()
        for name, history in self._history.items():
            ts = frame.get(f"{name}.t", frame.get("t"))
            ps = frame.get(f"{name}.position")
            if ts is None or ps is None:
                continue
            for t, p in zip(ts[-64:], ps[-64:]):
                if math.isfinite(p):
                    history.append((float(t), float(p)))

    def _velocity(self, name: str) -> Optional[float]:
        h = self._history[name]
        if len(h) < 2:
            return None
        t1, p1 = h[-1]
        for t0, p0 in reversed(h):
            if t1 - t0 >= self.VELOCITY_WINDOW:
                return (p1 - p0) / (t1 - t0)
        t0, p0 = h[0]
        return (p1 - p0) / (t1 - t0) if t1 > t0 else None

    def row(self, name: str, d: Any) -> tuple:
        self._take()
        now = time.monotonic()
        if now - self._asked >= 1.0 / self.STATUS_HZ:
            self._asked = now
            self._status = {}
        if name not in self._status:
            self._status[name] = d.status
        st = self._status[name]
        h = self._history[name]
        pos, vel = (h[-1][1] if h else None), self._velocity(name)
        return (name, d.kind, "…" if pos is None else _fmt(pos), "…" if vel is None else _fmt(vel), d.units.name,
                _flags(st), "FAULT" if st.fault else "-", st.text or "-")

    def close(self) -> None:
        try:
            self._poll.stop()
        except _core.MotorbusError:
            pass


def read_rows(bench: Bench, names: list[str], listeners: Optional[dict] = None,
              served: Optional[ServedReadings] = None) -> list[tuple]:
    """``(axis, kind, position, velocity, units, state, fault, drive says)`` per axis,
    read now (or, for an axis only listened to, what it has sent; through a service, from
    its shared poll); an axis that fails to answer says why instead."""
    rows = []
    for name in names:
        if served is not None:
            d = bench[name]
            try:
                rows.append(served.row(name, d))
            except _core.MotorbusError as e:
                rows.append((name, d.kind, "?", "?", d.units.name, "-", "no answer", f"{type(e).__name__}: {e}"))
            continue
        if listeners and name in listeners:
            cfg = bench.config[name]
            rows.append(listeners[name].row(name, cfg.kind, cfg.units.name if cfg.units else "native"))
            continue
        d = bench[name]
        try:
            st = d.status
            rows.append((name, d.kind, _fmt(d.position), _fmt(d.velocity), d.units.name, _flags(st),
                         "FAULT" if st.fault else "-", st.text or "-"))
        except _core.MotorbusError as e:
            rows.append((name, d.kind, "?", "?", d.units.name, "-", "no answer", f"{type(e).__name__}: {e}"))
    return rows


def render(bench: Bench, names: list[str], rate: float, frame: int, listeners: Optional[dict] = None,
           served: Optional[ServedReadings] = None) -> Any:
    from rich.table import Table

    sim = " (simulated twin)" if getattr(bench, "simulated", False) else ""
    via = " through motorbus serve" if isinstance(bench, _Narrowed) else ""
    table = Table(title=f"{getattr(bench, 'source', '')}{sim}{via}", caption=f"{rate:g} Hz, frame {frame} — q or Ctrl-C quits",
                  title_justify="left", caption_justify="left")
    for col, justify in (("axis", "left"), ("kind", "left"), ("position", "right"), ("velocity", "right"),
                         ("units", "left"), ("state", "left"), ("fault", "left"), ("drive says", "left")):
        table.add_column(col, justify=justify, no_wrap=col != "drive says")
    for row in read_rows(bench, names, listeners, served):
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
    # CAN axes are listened to, not asked, unless --ask (or the twin is this monitor's own).
    ask_can = args.ask or args.sim
    served = False
    try:
        address = service_address(args)
        if address is not None:
            # The service is the one program talking to the drives: it asks every axis.
            bench, served = _Narrowed(connect_service(address), args.axis), True
        else:
            bench = load_bench(args.bench, sim=args.sim, axes=args.axis,
                               open_axis=lambda cfg: ask_can or cfg.bus is None)
    except _core.MotorbusError as e:
        print(error_text(e), file=sys.stderr)
        return exit_code(e)
    listeners: dict = {}
    readings: Optional[ServedReadings] = None
    try:
        if served:
            readings = ServedReadings(bench, list(bench.axes), args.rate)
        else:
            for d in bench.axes.values():
                # Watching must not change what it watches: no stop when the monitor leaves.
                d.on_error = None
                d.on_exit = None
        names = list(bench.axes)
        for name in names:
            if not served and isinstance(bench[name], NotOpened):
                cfg = bench.config[name]
                listeners[name] = Listener(bench.buses[cfg.bus], cfg)
        period = 1.0 / args.rate
        keys = _Keys(sys.stdin)
        console = Console()
        frame = 0
        try:
            first = render(bench, names, args.rate, frame, listeners, readings)
            with _cbreak(sys.stdin), Live(first, console=console, auto_refresh=False, transient=False) as live:
                next_t = time.monotonic()
                while True:
                    next_t += period
                    key = keys.wait(max(0.0, next_t - time.monotonic()))
                    if "q" in key.lower():
                        break
                    if time.monotonic() > next_t + period:   # slow drives: do not try to catch up
                        next_t = time.monotonic()
                    frame += 1
                    live.update(render(bench, names, args.rate, frame, listeners, readings), refresh=True)
        except KeyboardInterrupt:
            pass
        return EXIT_OK
    finally:
        for listener in listeners.values():
            listener.close()
        if readings is not None:
            readings.close()
        bench.close()     # closes the links (a served bench: the connection); stops nothing


def add_commands(sub: Any, common: Any = None) -> None:
    p = sub.add_parser("monitor", help="a live table of every axis (reads only; q or Ctrl-C quits)",
                       parents=[common] if common is not None else [])
    p.add_argument("bench", metavar="BENCH", help="the bench file (TOML)")
    p.add_argument("--rate", type=float, default=10.0, metavar="HZ", help="redraws per second (default 10)")
    p.add_argument("--axis", action="append", help="only this axis (repeatable; default every axis)")
    p.add_argument("--ask", action="store_true",
                   help="also poll CAN axes (SDO/requests): only when no other program talks to those nodes; "
                        "by default a CAN axis is only listened to")
    p.add_argument("--sim", action="store_true", help="watch the bench's simulated twin (a fresh one, asked)")
    server_options(p)
    p.set_defaults(func=cmd_monitor)

"""Find the drives connected to serial lines and CAN buses, and write a bench file.

``discover(lines=["/dev/ttyUSB0"], buses=["socketcand:10.0.0.5:29536/can0"])`` asks
every registered kind's probe (its Drive class's ``probe`` / ``canopen_match``):

* a serial line: for each serial kind, each of its ``probe_bauds``, each of its
  ``probe_addresses``, the kind's identity query (its ``probe``: an identity or
  version request).  One missing address costs one reply timeout (plus the
  query's wire time at that rate), so a full sweep is bounded by kinds x bauds x
  addresses x timeout.  A line stops being swept at the first rate and kind that
  answered (one protocol at one rate per line).  Requests sent at a wrong rate
  reach the drives as garbage; some latch that as an error (a syntax error
  bit): ``clear_faults()`` acknowledges it;
* a CAN bus: one CANopen scan (boot-up and heartbeat listening plus SDO 0x1000
  and 0x1018 on nodes 1-127, answered in parallel) whose nodes go to the
  CANopen kinds' ``canopen_match``; then the probes of CAN kinds that are not
  CANopen.

Every line and bus is probed at the same time (a thread each): a scan takes as long as
its slowest place, not the sum of them.  Discovery never moves a motor and never writes a parameter: probes only read.
``timeout`` is a budget for the whole run: what is left unprobed when it runs out
is reported in ``Discovery.skipped``.  ``progress=True`` draws a bar on a
terminal and plain lines otherwise (or pass a callable taking one line).
"""
from __future__ import annotations

import concurrent.futures
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence, Union

from . import _core, registry
from .bus import open_bus

__all__ = ["Found", "Discovery", "discover", "bench_toml"]


@dataclass(frozen=True)
class Found:
    """One drive that answered."""

    kind: str
    address: str
    line: Optional[str] = None      # the serial port it answered on...
    baud: Optional[int] = None
    bus: Optional[str] = None       # ...or the bus spec
    identity: dict = field(default_factory=dict)


@dataclass
class Discovery:
    found: list[Found]
    seconds: float
    probes: int                      # identity queries sent (serial and non-CANopen CAN)
    skipped: list[str] = field(default_factory=list)   # what the time budget left unprobed

    def bench_toml(self) -> str:
        return bench_toml(self.found)

    def write(self, path: str) -> None:
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.bench_toml())


class _Progress:
    """A one-line bar on a terminal, plain lines elsewhere, or a callable."""

    def __init__(self, progress: Union[bool, Callable[[str], None]], total: int) -> None:
        self.total, self.done = max(1, total), 0
        self._lock = threading.Lock()       # every line and bus is probed from a thread of its own
        self.say: Optional[Callable[[str], None]] = None
        self.tty = False
        if callable(progress):
            self.say = progress
        elif progress:
            self.tty = sys.stderr.isatty()
            self.say = self._draw if self.tty else (lambda s: print(s, file=sys.stderr, flush=True))

    def _draw(self, text: str) -> None:
        width = 30
        filled = int(width * self.done / self.total)
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} {text[:60]:60s}")
        sys.stderr.flush()

    def step(self, text: str, n: int = 1) -> None:
        """One unit of work done: redraws the bar (a terminal only: a log gets notes)."""
        with self._lock:
            self.done = min(self.total, self.done + n)
            if self.tty:
                self._draw(text)

    def note(self, text: str) -> None:
        """A line worth keeping (what is being swept, what answered)."""
        with self._lock:
            if self.tty:
                sys.stderr.write("\r" + " " * 100 + "\r" + text + "\n")
                self._draw("")
            elif self.say:
                self.say(text)

    def finish(self, text: str) -> None:
        if self.tty:
            sys.stderr.write("\n")
        if self.say:
            self.say(text)


def discover(lines: Sequence[str] = (), buses: Sequence[Any] = (), *, kinds: Optional[Sequence[str]] = None,
             timeout: float = 120.0, reply_timeout: float = 0.05, sdo_timeout: float = 0.1,
             progress: Union[bool, Callable[[str], None]] = False) -> Discovery:
    """Probes ``lines`` (port paths) and ``buses`` (``open_bus`` specs or open Buses)."""
    plugins = registry.drive_plugins()
    lines = list(dict.fromkeys(lines))     # a port given twice is one wire: probed once, not from two threads
    if kinds is not None:
        unknown = sorted(set(kinds) - set(plugins))
        if unknown:
            raise _core.InvalidArgument(f"discover kinds: unknown {unknown} (registered: {', '.join(plugins)})")
        plugins = {k: p for k, p in plugins.items() if k in kinds}
    serial = [p for p in plugins.values() if p.transport == "serial" and p.provides("probe")]
    canopen = [p for p in plugins.values() if p.transport == "can" and p.provides("canopen_match")]
    can_probes = [p for p in plugins.values()
                  if p.transport == "can" and p.provides("probe") and not p.provides("canopen_match")]
    # Work units for the bar: one per (line, kind, baud, address), one per CANopen scan and CAN probe.
    total = sum(len(p.probe_bauds or (p.default_baud,)) * len(p.probe_addresses) for p in serial) * len(lines)
    total += len(buses) * ((1 if canopen else 0) + sum(len(p.probe_addresses) for p in can_probes))
    bar = _Progress(progress, total)
    t0 = time.monotonic()
    deadline = t0 + timeout
    # Each line and each bus is its own wire: they are probed at the same time, one thread
    # each, so a scan of several ports takes as long as the slowest one, not their sum.
    # The results are merged in the order the places were given.
    jobs = [(_probe_line, port, serial) for port in lines] + [(_probe_bus, spec, (canopen, can_probes))
                                                               for spec in buses]
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, len(jobs)),
                                               thread_name_prefix="discover") as pool:
        futures = [pool.submit(fn, place, plugins_, bar=bar, deadline=deadline, reply_timeout=reply_timeout,
                               sdo_timeout=sdo_timeout) for fn, place, plugins_ in jobs]
        results = [f.result() for f in futures]
    found: list[Found] = [x for r in results for x in r.found]
    skipped: list[str] = [x for r in results for x in r.skipped]
    probes = sum(r.probes for r in results)
    seconds = time.monotonic() - t0
    bar.finish(f"found {len(found)} drive(s) in {seconds:.1f} s" + (f", {len(skipped)} skipped" if skipped else ""))
    return Discovery(found, seconds, probes, skipped)


@dataclass
class _Place:
    """What probing one line or bus gave."""

    found: list = field(default_factory=list)
    skipped: list = field(default_factory=list)
    probes: int = 0

    def sweep(self, plugin: Any, link: Any, where: str, bar: _Progress, deadline: float,
              **place: Any) -> bool:
        """Probes each of the kind's addresses over ``link`` until the budget runs out; each
        answer is a Found at ``place`` (line and baud, or bus).  True when one answered."""
        answered = False
        for address in plugin.probe_addresses:
            if time.monotonic() >= deadline:
                self.skipped.append(f"{where} from {address}")
                break
            self.probes += 1
            ident = _safe_probe(plugin, link, address)
            bar.step(f"{where} {address}")
            if ident is not None:
                answered = True
                self.found.append(Found(plugin.kind, address, identity=ident, **place))
                bar.note(f"{where}: {address} answered: {ident}")
        return answered


def _probe_line(port: str, serial: list, *, bar: _Progress, deadline: float, reply_timeout: float,
                sdo_timeout: float) -> _Place:
    out = _Place()
    # One RS-485 line runs one protocol at one baud rate: once drives of a kind
    # answered at a rate, the other rates and kinds are not swept on that line.
    settled = False
    for plugin in serial:
        if settled:
            out.skipped.append(f"{port} {plugin.kind}: the line already answered another kind")
            continue
        for baud in plugin.probe_bauds or (plugin.default_baud,):
            if settled:
                break
            if time.monotonic() >= deadline:
                out.skipped.append(f"{port} {plugin.kind} @{baud}")
                continue
            bar.note(f"{port}: {plugin.kind} at {baud} baud, {len(plugin.probe_addresses)} addresses")
            try:
                opened = _core.serial.open_port(port, baud)
                link = _core.serial.LineLink(opened, reply_timeout=reply_timeout + _wire_time(baud),
                                             **(plugin.line_settings or {}))
            except _core.MotorbusError as e:
                out.skipped.append(f"{port}: {e}")
                break
            try:
                settled = out.sweep(plugin, link, f"{port} {plugin.kind} @{baud}", bar, deadline, line=port, baud=baud)
            finally:
                opened.close()
    return out


def _probe_bus(spec: Any, plugins: tuple, *, bar: _Progress, deadline: float, reply_timeout: float,
               sdo_timeout: float) -> _Place:
    canopen, can_probes = plugins
    out = _Place()
    bus = open_bus(spec) if isinstance(spec, str) else spec
    label = spec if isinstance(spec, str) else getattr(bus, "channel", "bus")
    try:
        if canopen and time.monotonic() < deadline:
            nodes = _core.canopen.scan_network(bus, sdo_timeout=sdo_timeout, listen=0.0)
            bar.step(f"{label}: CANopen scan, {len(nodes)} node(s)")
            bar.note(f"{label}: CANopen scan found node(s) {[n.node for n in nodes]}")
            for node in nodes:
                scores = sorted(((p.canopen_match(node) or 0, p.kind) for p in canopen), reverse=True)
                if scores and scores[0][0] > 0:
                    out.found.append(Found(scores[0][1], str(node.node), bus=label, identity=_node_identity(node)))
        for plugin in can_probes:
            out.sweep(plugin, bus, f"{label} {plugin.kind}", bar, deadline, bus=label)
    finally:
        if isinstance(spec, str):
            bus.close()
    return out


def _wire_time(baud: int) -> float:
    """What a short query and its reply spend on the wire at `baud` (40 bytes, 10 bits
    each): added to the reply timeout, or a slow line would look empty."""
    return 400.0 / baud if baud else 0.0


def _safe_probe(plugin: Any, link: Any, address: str) -> Optional[dict]:
    """A probe's silence, garbage or refusal all mean "not this kind here"."""
    try:
        ident = plugin.probe(link, address)
    except _core.MotorbusError:
        return None
    return dict(ident) if ident is not None else None


def _node_identity(node: Any) -> dict:
    out = {"device_type": node.device_type, "vendor_id": node.vendor_id, "product_code": node.product_code,
           "revision": node.revision, "serial": node.serial_number, "state": node.state}
    return {k: v for k, v in out.items() if v is not None}


#: CANopen identity fields (1000h, 1018h) are written in hex, as the manuals and EDS files do.
_HEX_IDENTITY = {"device_type", "vendor_id", "product_code", "revision", "serial"}


def identity_text(identity: dict) -> str:
    """``{"vendor_id": 0x1F4, "model": "DMX"}`` -> ``vendor_id=0x000001F4, model=DMX``."""
    return ", ".join(f"{k}=0x{v:08X}" if k in _HEX_IDENTITY and isinstance(v, int) and not isinstance(v, bool)
                     else f"{k}={v}" for k, v in identity.items())


def _toml_str(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return f"0x{v:08X}" if v > 0xFFFF else str(v)
    return '"' + str(v).replace("\\", "\\\\").replace('"', '\\"') + '"'


def bench_toml(found: Sequence[Found]) -> str:
    """A bench file for what was found: one [line]/[bus] per place, one [axis] per drive."""
    out = ["# Written by motorbus discovery: rename the axes, add units and params as needed.", ""]
    lines: dict[tuple, str] = {}
    buses: dict[str, str] = {}
    for f in found:
        if f.line is not None and (f.line, f.baud) not in lines:
            name = f"line{len(lines) + 1}"
            lines[(f.line, f.baud)] = name
            out += [f"[line.{name}]", f"port = {_toml_str(f.line)}", f"baud = {f.baud}", ""]
        if f.bus is not None and f.bus not in buses:
            name = f"can{len(buses)}"
            buses[f.bus] = name
            out += [f"[bus.{name}]", f"spec = {_toml_str(f.bus)}", ""]
    for i, f in enumerate(found, start=1):
        ident = identity_text(f.identity)
        out += [f"[axis.{f.kind.replace('-', '_')}_{i}]" + (f"  # {ident}" if ident else ""),
                f"kind = {_toml_str(f.kind)}"]
        out.append(f"line = {_toml_str(lines[(f.line, f.baud)])}" if f.line is not None
                   else f"bus = {_toml_str(buses[f.bus])}")
        out += [f"address = {_toml_str(f.address)}", ""]
    return "\n".join(out)

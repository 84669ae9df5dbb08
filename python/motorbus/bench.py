"""A bench: buses, serial lines and named axes, described once in a TOML file.

.. code-block:: toml

    [bus.can0]
    spec = "socketcand:10.0.0.5:29536/can0"     # any open_bus spec
    [line.rs485]
    port = "/dev/ttyUSB0"
    baud = 9600
    [axis.x]
    kind = "arcus"
    line = "rs485"
    address = 1
    units = { name = "mm", scale = 0.0025 }
    params = { HSPD = 10000, ACC = 100 }         # the vendor's own parameter names
    [axis.z]
    kind = "cia402"
    bus = "can0"
    address = 5

``Bench.load(path)`` opens every bus and line once and every axis on them
(``bench["x"]`` is a :class:`motorbus.Drive`).  ``sim=True`` replaces each axis
by its plugin's simulator behind the same kind of transport: a serial line
becomes a pty served by a line server, a bus a virtual bus served over
socketcand on 127.0.0.1 — so a file written for hardware runs unchanged
without it.  Nothing here names a vendor: every registered kind works.

Errors in a file are :class:`BenchFileError` (an ``InvalidArgument``) reading
``file:line: key: what was expected``.
"""
from __future__ import annotations

import itertools
import math
import os
import re
import time
import tomllib
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping, Optional, Sequence

from . import _core, registry
from .bus import open_bus
from .drive import Drive, DriveStatus, MoveFailed, Units

__all__ = ["Bench", "BenchFileError", "AxisConfig", "ParamDiff", "StartReport"]

_SECTIONS = ("bus", "line", "axis")
_BUS_KEYS = {"spec"}
_LINE_KEYS = {"port", "baud", "timeout", "turnaround"}
_AXIS_KEYS = {"kind", "line", "bus", "address", "units", "params", "options", "sim"}
_sim_names = itertools.count(1)


class BenchFileError(_core.InvalidArgument):
    """A mistake in a bench file: ``file:line: key: what was expected``."""

    def __init__(self, message: str, *, source: str = "<bench>", line: Optional[int] = None,
                 key: str = "") -> None:
        self.source, self.line, self.key, self.reason = source, line, key, message
        where = source if line is None else f"{source}:{line}"
        super().__init__(f"{where}: {key}: {message}" if key else f"{where}: {message}")


class _Locator:
    """Line numbers of tables and keys in TOML text (tomllib gives none).

    Understands what bench files use: ``[a.b]`` headers (bare or quoted parts),
    ``key = value`` lines and inline tables (``units = { name = "mm" }``: the
    inner keys are on the key's line).  A key it cannot place gets its table's
    line, or none."""

    _HEADER = re.compile(r'^\s*\[\s*([^\[\]]+?)\s*\]\s*(#.*)?$')
    _KEY = re.compile(r'^\s*("[^"]*"|\'[^\']*\'|[A-Za-z0-9_\-#.]+)\s*=')

    def __init__(self, text: Optional[str]) -> None:
        self.lines: dict[tuple, int] = {}
        if not text:
            return
        table: tuple = ()
        for n, raw in enumerate(text.splitlines(), start=1):
            m = self._HEADER.match(raw)
            if m:
                table = tuple(_unquote(p) for p in _split_dotted(m.group(1)))
                for k in range(1, len(table) + 1):  # [axis.x] is also where "axis" first appears
                    self.lines.setdefault(table[:k], n)
                continue
            m = self._KEY.match(raw)
            if m:
                path = table + tuple(_unquote(p) for p in _split_dotted(m.group(1)))
                self.lines.setdefault(path, n)
                brace = raw.find("{", m.end())
                if brace >= 0:  # inline table: its keys live on this line
                    for inner in re.finditer(r'("[^"]*"|[A-Za-z0-9_\-#]+)\s*=', raw[brace:]):
                        self.lines.setdefault(path + (_unquote(inner.group(1)),), n)

    def line(self, *path: str) -> Optional[int]:
        for k in range(len(path), 0, -1):
            if path[:k] in self.lines:
                return self.lines[path[:k]]
        return None


def _split_dotted(text: str) -> list[str]:
    return [p.strip() for p in re.findall(r'"[^"]*"|\'[^\']*\'|[^.]+', text)]


def _unquote(part: str) -> str:
    part = part.strip()
    return part[1:-1] if len(part) >= 2 and part[0] == part[-1] and part[0] in "\"'" else part


@dataclass
class AxisConfig:
    """One ``[axis.NAME]`` table, checked."""

    name: str
    kind: str
    address: str
    line: Optional[str] = None
    bus: Optional[str] = None
    units: Optional[Units] = None
    params: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    sim: dict = field(default_factory=dict)


@dataclass(frozen=True)
class ParamDiff:
    """A parameter whose value on the drive differs from the bench file's."""

    axis: str
    name: str
    file_value: Any
    drive_value: Any


@dataclass(frozen=True)
class StartReport:
    """How closely ``Bench.move_together`` started its axes.

    ``offsets[axis]``: seconds from the first axis's command being accepted to this
    axis's (0 for the first; axes started by their drives' own trigger share one
    offset); ``skew`` = the largest offset.  ``method``: "software" (commands sent
    back to back, each axis starting when its own command arrives), the drives'
    own method ("DMAC SYNCHRO TOP"), or both joined by " + "."""

    method: str
    offsets: dict
    skew: float


class _Checker:
    """Validates the parsed document; every error carries file:line: key."""

    def __init__(self, data: Mapping[str, Any], source: str, text: Optional[str]) -> None:
        self.data, self.source, self.where = data, source, _Locator(text)

    def fail(self, message: str, *path: str) -> BenchFileError:
        return BenchFileError(message, source=self.source, line=self.where.line(*path), key=".".join(path))

    def tables(self, section: str, allowed: set) -> dict[str, dict]:
        raw = self.data.get(section, {})
        if not isinstance(raw, Mapping):
            raise self.fail(f"expected tables [{section}.NAME], not a {type(raw).__name__}", section)
        out = {}
        for name, table in raw.items():
            if not isinstance(table, Mapping):
                raise self.fail(f"expected a table [{section}.{name}]", section, name)
            unknown = sorted(set(table) - allowed)
            if unknown:
                raise self.fail(f"unknown key (a {section} takes: {', '.join(sorted(allowed))})",
                                section, name, unknown[0])
            out[name] = dict(table)
        return out

    def text(self, table: Mapping, key: str, *path: str, required: bool = True) -> Optional[str]:
        if key not in table:
            if required:
                raise self.fail(f"missing (required: {key} = \"...\")", *path, key)
            return None
        v = table[key]
        if not isinstance(v, str) or not v.strip():
            raise self.fail(f"expected a non-empty string, not {v!r}", *path, key)
        return v.strip()

    def number(self, table: Mapping, key: str, *path: str, default: float, integer: bool = False,
               minimum: float = 0.0) -> float:
        v = table.get(key, default)
        ok = isinstance(v, int) if integer else isinstance(v, (int, float))
        if isinstance(v, bool) or not ok or not math.isfinite(v) or v < minimum:
            kind = "an integer" if integer else "a number"
            raise self.fail(f"expected {kind} >= {minimum:g}, not {v!r}", *path, key)
        return v

    def table(self, parent: Mapping, key: str, *path: str) -> dict:
        v = parent.get(key, {})
        if not isinstance(v, Mapping):
            raise self.fail(f"expected a table ({key} = {{ ... }}), not {v!r}", *path, key)
        return dict(v)

    def check(self) -> tuple[dict, dict, dict[str, AxisConfig]]:
        unknown = sorted(set(self.data) - set(_SECTIONS))
        if unknown:
            raise self.fail("unknown section (a bench file has [bus.NAME], [line.NAME] and [axis.NAME])",
                            unknown[0])
        buses = self.tables("bus", _BUS_KEYS)
        for name, t in buses.items():
            t["spec"] = self.text(t, "spec", "bus", name)
        lines = self.tables("line", _LINE_KEYS)
        for name, t in lines.items():
            t["port"] = self.text(t, "port", "line", name)
            if "baud" in t:
                t["baud"] = int(self.number(t, "baud", "line", name, default=0, integer=True))
            t["timeout"] = self.number(t, "timeout", "line", name, default=0.5)
            t["turnaround"] = self.number(t, "turnaround", "line", name, default=0.0)
        axes = {}
        for name, t in self.tables("axis", _AXIS_KEYS).items():
            axes[name] = self.axis(name, t, buses, lines)
        if not axes:
            raise self.fail("no [axis.NAME] table: a bench needs at least one axis", "axis")
        self.one_kind_per_line(axes, lines)
        return buses, lines, axes

    def axis(self, name: str, t: dict, buses: dict, lines: dict) -> AxisConfig:
        path = ("axis", name)
        kind = self.text(t, "kind", *path)
        kinds = sorted(registry.drive_kinds())
        if kind not in kinds:
            raise self.fail(f"unknown kind {kind!r} (registered: {', '.join(kinds)})", *path, "kind")
        plugin = registry.drive_plugin(kind)
        if "address" not in t:
            raise self.fail(f"missing (e.g. address = {plugin.default_address!r})", *path, "address")
        address = t["address"]
        if isinstance(address, bool) or not isinstance(address, (int, str)):
            raise self.fail(f"expected an integer or a string, not {address!r}", *path, "address")
        if isinstance(address, int) and plugin.transport == "serial" and len(plugin.default_address) > 1:
            address = str(address).zfill(len(plugin.default_address))  # 1 -> "01" for two-digit line addresses
        try:
            address = plugin.check_address(str(address).strip())
        except _core.InvalidArgument as e:
            raise self.fail(f"{e}", *path, "address") from None
        link_key = "line" if plugin.transport == "serial" else "bus"
        other = "bus" if link_key == "line" else "line"
        if other in t:
            raise self.fail(f"a {kind} axis is on a {'serial line' if link_key == 'line' else 'CAN bus'}: "
                            f"use {link_key} = \"NAME\", not {other}", *path, other)
        link = self.text(t, link_key, *path)
        known = lines if link_key == "line" else buses
        if link not in known:
            names = ", ".join(sorted(known)) or "none defined"
            plural = "lines" if link_key == "line" else "buses"
            raise self.fail(f"no [{link_key}.{link}] in this file ({plural}: {names})", *path, link_key)
        units = None
        if "units" in t:
            u = t["units"]
            if not isinstance(u, Mapping) or set(u) - {"name", "scale"} or "scale" not in u:
                raise self.fail("expected { name = \"mm\", scale = <user units per native unit> }", *path, "units")
            scale = u["scale"]
            if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale) \
                    or scale == 0:
                raise self.fail(f"scale must be a finite non-zero number, not {scale!r}", *path, "units", "scale")
            try:
                units = Units(str(u.get("name", "native")), float(scale))
            except _core.InvalidArgument as e:
                raise self.fail(str(e), *path, "units") from None
        return AxisConfig(name=name, kind=kind, address=address,
                          line=link if link_key == "line" else None, bus=link if link_key == "bus" else None,
                          units=units, params=self.table(t, "params", *path),
                          options=self.table(t, "options", *path), sim=self.table(t, "sim", *path))

    def one_kind_per_line(self, axes: dict[str, AxisConfig], lines: dict) -> None:
        # Two axes answering to one address on one bus would both answer every request.
        on_bus: dict[tuple, AxisConfig] = {}
        for a in axes.values():
            if a.bus is not None:
                first = on_bus.setdefault((a.bus, a.address), a)
                if first is not a:
                    raise self.fail(f"address {a.address} is also axis {first.name!r} ({first.kind}) "
                                    f"on bus {a.bus!r}", "axis", a.name, "address")
        # One RS-485 line speaks one protocol: the framing is the kind's.
        seen: dict[str, AxisConfig] = {}
        for a in axes.values():
            if a.line is None:
                continue
            first = seen.setdefault(a.line, a)
            if first.kind != a.kind:
                raise self.fail(f"line {a.line!r} already carries {first.kind} axis {first.name!r}: "
                                f"one protocol per line", "axis", a.name, "line")
            if first is not a and first.address == a.address:
                raise self.fail(f"address {a.address} is also axis {first.name!r} on line {a.line!r}",
                                "axis", a.name, "address")


class Bench:
    """Buses, lines and named axes opened from a bench description (see the module doc)."""

    def __init__(self, data: Mapping[str, Any], *, sim: bool = False, source: str = "<dict>",
                 text: Optional[str] = None, clock: Any = None) -> None:
        self._checker = _Checker(data, source, text)
        self.source = source
        self.simulated = sim
        self._bus_cfg, self._line_cfg, self.config = self._checker.check()
        self.buses: dict[str, Any] = {}
        self.lines: dict[str, Any] = {}
        self.sims: dict[str, Any] = {}          # axis name -> its simulator (sim=True)
        self._servers: list[Any] = []           # what serves the simulated transports
        # sim=True: the pty server of each simulated line and the BusServers of each
        # simulated bus, by name (fault injection cuts a line or spoils frames there)
        self.served_lines: dict[str, Any] = {}
        self.served_buses: dict[str, Any] = {}
        self._axes: dict[str, Drive] = {}
        self._closed = False
        try:
            if sim:
                self._serve_simulators(clock)
            self._open_links()
            for name, cfg in self.config.items():
                self._axes[name] = self._open_axis(cfg)
        except BaseException:
            self.close()
            raise

    # ---- construction ----------------------------------------------------------------------
    @classmethod
    def load(cls, path: "str | os.PathLike[str]", *, sim: bool = False, clock: Any = None) -> "Bench":
        """Reads a TOML bench file and opens everything in it."""
        source = os.fspath(path)
        try:
            with open(source, "rb") as f:
                raw = f.read()
        except OSError as e:
            raise BenchFileError(f"cannot read: {e.strerror}", source=source) from None
        try:
            text = raw.decode("utf-8")
            data = tomllib.loads(text)
        except UnicodeDecodeError as e:
            raise BenchFileError(f"not UTF-8 text ({e.reason} at byte {e.start})", source=source) from None
        except tomllib.TOMLDecodeError as e:
            m = re.search(r"\(at line (\d+), column (\d+)\)", str(e))
            line = int(m.group(1)) if m else None
            raise BenchFileError(f"bad TOML: {str(e).split(' (at line')[0]}", source=source, line=line) from None
        return cls(data, sim=sim, source=source, text=text, clock=clock)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, sim: bool = False, clock: Any = None) -> "Bench":
        """The same from an already-parsed description (``{"axis": {"x": {...}}, ...}``)."""
        return cls(data, sim=sim, source="<dict>", clock=clock)

    def _fail(self, message: str, *path: str) -> BenchFileError:
        return self._checker.fail(message, *path)

    def _serve_simulators(self, clock: Any) -> None:
        """Replaces every line by a pty and every bus by a served virtual bus,
        with each axis's simulator behind it; the links then open those."""
        from .bus_server import BusServers
        from .sim import make_sim

        for line_name, cfg in self._line_cfg.items():
            axes = [a for a in self.config.values() if a.line == line_name]
            if not axes:
                continue
            devices = []
            for a in axes:
                try:
                    devices.append(make_sim(a.kind, a.address, clock=clock, **a.sim))
                except _core.InvalidArgument as e:
                    raise self._fail(str(e), "axis", a.name, "sim") from None
                self.sims[a.name] = devices[-1]
            server = _core.PtyLineServer(devices=devices, baud=0)
            self._servers.append(server)
            self.served_lines[line_name] = server
            cfg["port"] = server.slave_path
        for bus_name, cfg in self._bus_cfg.items():
            axes = [a for a in self.config.values() if a.bus == bus_name]
            served = BusServers(f"virtual:bench-sim-{os.getpid()}-{next(_sim_names)}",
                                socketcand=["127.0.0.1:0"], channel="can0")
            self._servers.append(served)
            self.served_buses[bus_name] = served
            for a in axes:
                try:
                    sim = make_sim(a.kind, a.address, clock=clock, **a.sim)
                except _core.InvalidArgument as e:
                    raise self._fail(str(e), "axis", a.name, "sim") from None
                sim.attach(served.endpoint())
                self._servers.insert(0, sim)   # closed before the bus they sit on
                self.sims[a.name] = sim
            srv = served.servers[0]
            cfg["spec"] = f"socketcand:{srv.host}:{srv.port}/can0"

    def _open_links(self) -> None:
        for name, cfg in self._bus_cfg.items():
            try:
                self.buses[name] = open_bus(cfg["spec"])
            except _core.InvalidArgument as e:
                raise self._fail(str(e), "bus", name, "spec") from None
        for name, cfg in self._line_cfg.items():
            axes = [a for a in self.config.values() if a.line == name]
            if not axes:
                continue  # a described but unused line is not opened (it may not exist here)
            plugin = registry.drive_plugin(axes[0].kind)
            baud = cfg.get("baud", plugin.default_baud)
            try:
                port = _core.open_port(cfg["port"], baud)
            except _core.InvalidArgument as e:
                raise self._fail(str(e), "line", name, "port") from None
            settings = dict(plugin.line_settings or {})
            self.lines[name] = _core.LineLink(port, reply_timeout=cfg["timeout"], turnaround=cfg["turnaround"],
                                              **settings)

    def _open_axis(self, cfg: AxisConfig) -> Drive:
        plugin = registry.drive_plugin(cfg.kind)
        where = {"line": self.lines[cfg.line]} if cfg.line else {"bus": self.buses[cfg.bus]}
        try:
            drive = plugin.open(address=cfg.address, units=cfg.units, line=where.get("line"),
                                bus=where.get("bus"), **cfg.options)
        except TypeError as e:  # an option the plugin does not take
            raise self._fail(f"{cfg.kind} does not take this option set: {e}", "axis", cfg.name, "options") from None
        except _core.InvalidArgument as e:
            raise self._fail(str(e), "axis", cfg.name, "options") from None
        drive.name = cfg.name      # errors (MoveFailed...) name the bench's axis
        for pname in cfg.params:
            if pname not in drive.params:
                drive.close()
                known = ", ".join(sorted(drive.params))
                raise self._fail(f"{cfg.kind} has no parameter {pname!r} (it has: {known})",
                                 "axis", cfg.name, "params", pname)
        return drive

    # ---- use -----------------------------------------------------------------------------------
    @property
    def axes(self) -> dict[str, Drive]:
        """``{name: Drive}`` in file order."""
        return dict(self._axes)

    def __getitem__(self, name: str) -> Drive:
        try:
            return self._axes[name]
        except KeyError:
            raise _core.InvalidArgument(f"bench {self.source}: no axis {name!r} "
                                        f"(axes: {', '.join(self._axes)})") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._axes)

    def __len__(self) -> int:
        return len(self._axes)

    def select(self, names: Optional[Sequence[str]] = None) -> dict[str, Drive]:
        """The named axes (all when ``names`` is empty), each name checked."""
        return {n: self[n] for n in names} if names else self.axes

    def move_together(self, targets: Mapping[str, float], *, relative: bool = False,
                      velocity: Optional[float] = None, wait: bool = True,
                      timeout: Optional[float] = None) -> StartReport:
        """Starts moves on several axes together and reports how closely.

        Axes of one kind sharing a line or bus whose plugin offers a drive-level
        synchronised start (``DrivePlugin.synchronised_start``: DMAC ``SYNCHRO``)
        start on the drives' own trigger: their offsets are 0 by construction (one
        broadcast).  The others get a software start: commands back to back, each
        axis starting when its own command arrives; their offsets are measured
        (seconds from the first command accepted to this axis's).  A group started
        by its drives counts as one command in that sequence."""
        drives = {name: self[name] for name in targets}
        if not drives:
            raise _core.InvalidArgument("move_together: no axis given")
        groups: dict[tuple, list[str]] = {}
        for name in drives:
            cfg = self.config[name]
            groups.setdefault((cfg.kind, cfg.line, cfg.bus), []).append(name)
        offsets: dict[str, float] = {}
        methods: list[str] = []
        t0: Optional[float] = None

        def command(name: str) -> None:
            d = drives[name]
            (d.move_by if relative else d.move_to)(targets[name], velocity=velocity, wait=False)

        for (kind, line, bus), names in groups.items():
            sync = registry.drive_plugin(kind).synchronised_start
            if sync is not None and len(names) > 1:
                link = self.lines[line] if line else self.buses[bus]
                with sync(link, [drives[n] for n in names]) as how:
                    for n in names:
                        command(n)
                now = time.perf_counter()
                t0 = now if t0 is None else t0
                offsets.update({n: now - t0 for n in names})
                methods.append(how)
                continue
            for n in names:
                command(n)
                now = time.perf_counter()
                t0 = now if t0 is None else t0
                offsets[n] = now - t0
            methods.append("software")
        if wait:
            self._wait_all(drives, timeout)
        method = methods[0] if len(set(methods)) == 1 else " + ".join(dict.fromkeys(methods))
        return StartReport(method, offsets, max(offsets.values()))

    @staticmethod
    def _wait_all(drives: Mapping[str, Drive], timeout: Optional[float]) -> None:
        """Waits for every axis, even after one failed (each outcome is judged and kept in
        its ``status.last_move``); then raises the first axis's :class:`MoveFailed`, with
        ``failures`` = every failed axis's error by name."""
        failures: dict[str, MoveFailed] = {}
        for name, d in drives.items():
            try:
                d.wait_idle(timeout)
            except MoveFailed as e:
                failures[name] = e
        if failures:
            first = next(iter(failures.values()))
            first.failures = failures
            if len(failures) > 1:
                first.add_note("also: " + "; ".join(str(e) for e in list(failures.values())[1:]))
            raise first

    def status(self) -> dict[str, DriveStatus]:
        return {name: d.status for name, d in self._axes.items()}

    def stop_all(self, how: str = "stop") -> list[tuple[str, BaseException]]:
        """Stops every axis (``how``: "stop" or "quick_stop"); an axis that fails
        does not keep the others from stopping.  Returns the failures."""
        failures = []
        for name, d in self._axes.items():
            if d.closed:
                continue
            try:
                getattr(d, how)()
            except Exception as e:  # noqa: BLE001 - the others must still stop
                failures.append((name, e))
        return failures

    # ---- configuration ---------------------------------------------------------------------
    def read_params(self, names: Optional[Sequence[str]] = None, *, all_params: bool = False) -> dict[str, dict]:
        """``{axis: {param: value}}`` read from the drives: the file's parameters,
        or every parameter the drive has with ``all_params``."""
        out = {}
        for axis, d in self.select(names).items():
            wanted = list(d.params) if all_params else list(self.config[axis].params)
            out[axis] = {p: d.params[p] for p in wanted}
        return out

    def diff(self, names: Optional[Sequence[str]] = None) -> list[ParamDiff]:
        """The file's parameters whose drive value differs."""
        out = []
        for axis, d in self.select(names).items():
            for p, want in self.config[axis].params.items():
                have = d.params[p]
                if not _same(have, want):
                    out.append(ParamDiff(axis, p, want, have))
        return out

    def apply(self, names: Optional[Sequence[str]] = None) -> list[ParamDiff]:
        """Writes the file's parameters that differ; returns what it changed."""
        changed = self.diff(names)
        for c in changed:
            try:
                self[c.axis].params[c.name] = c.file_value
            except _core.InvalidArgument as e:
                raise self._fail(str(e), "axis", c.axis, "params", c.name) from None
        return changed

    def store(self, names: Optional[Sequence[str]] = None) -> None:
        """Persists the parameters on each drive (its own STORE/save)."""
        for d in self.select(names).values():
            d.store()

    # ---- lifetime --------------------------------------------------------------------------
    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        for d in self._axes.values():
            try:
                d.close()
            except Exception:  # noqa: BLE001 - close the rest
                pass
        for link in list(self.lines.values()) + list(self.buses.values()):
            try:
                link.close()
            except Exception:  # noqa: BLE001
                pass
        for s in self._servers:
            try:
                s.close()
            except Exception:  # noqa: BLE001
                pass
        self._servers = []
        self.served_lines, self.served_buses = {}, {}

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> "Bench":
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        # Every axis stops on the way out, exception or not: a bench script that
        # ends mid-move must not leave a motor running.
        try:
            self.stop_all("quick_stop" if exc_type is not None else "stop")
        finally:
            self.close()

    def __repr__(self) -> str:
        sim = " simulated" if self.simulated else ""
        return f"<Bench {self.source}{sim}: {', '.join(self._axes)}>"


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
        except (TypeError, ValueError):
            return False
    return a == b

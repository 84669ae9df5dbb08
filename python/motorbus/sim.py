"""Serving simulated drives, in-process or to other processes.

A drive spec is ``KIND:ADDR[,ADDR...]`` for any registered kind
(``motorbus.drive_kinds()``):

* a **serial** kind gets one serial line (a pty) per spec, carrying all its
  addresses as an RS-485 multi-drop bus does (every drive sees every request,
  only the addressed one answers): ``<kind>:01,02``;
* a **CAN** kind puts one node per address on the served CAN bus: ``cia402:5,6``.

``motorbus sim serve --drive <kind>:01 --drive cia402:5`` prints one line per
serial line (``<spec> <pty path>``) and one per CAN server (``socketcand
HOST:PORT CHANNEL`` / ``slcan PTY``), then serves until SIGINT/SIGTERM.

A bench file's twin that lasts (``--sim`` on ``status``/``move``/... makes a
fresh twin for each command): ``motorbus sim serve --bench FILE`` serves every
axis of the file with its ``sim`` options (:class:`BenchTwin`), each serial line
behind a stable symlink ``LINK_DIR/<line name>``, each bus over socketcand, and
writes the bench file of what it serves (``--write``), which any number of
commands, notebooks and test runs then open.  :class:`ServedBench` runs that
command from a test and injects simulator faults into it (``--control``).

In-process, :func:`serve_line` and :class:`SimBench` give the same simulators;
``make_sim(kind, address, ...)`` gives one drive's simulator without serving it.
"""
from __future__ import annotations

import copy
import dataclasses
import datetime
import fcntl
import json
import math
import os
import queue
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
from dataclasses import dataclass, field
from typing import Any, Mapping, Optional, Sequence

from . import _core, registry
from .bus_server import BusServers

__all__ = ["BenchTwin", "ServedBench", "ServedLine", "SimBench", "TwinBusy", "default_link_dir", "make_sim",
           "serve_line", "serve_lines"]


def make_sim(kind: str, address: str, clock: Any = None, store_dir: Optional[str] = None, **options: Any) -> Any:
    """One simulated drive of a registered kind (not served)."""
    plugin = registry.drive_plugin(kind)
    address = plugin.check_address(str(address))
    if store_dir is not None:
        options = {**plugin.store_options(store_dir, address), **options}
    return plugin.make_sim(address, clock=clock, **options)


@dataclass
class ServedLine:
    """A serial line on a pty with its simulated drives."""

    label: str
    server: Any
    drives: list = field(default_factory=list)

    @property
    def pty_path(self) -> str:
        return self.server.slave_path

    def close(self) -> None:
        self.server.close()

    def __enter__(self) -> "ServedLine":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def serve_line(spec: str, baud: int = 0, clock: Any = None, store_dir: Optional[str] = None,
               strict_baud: bool = False, **options: Any) -> ServedLine:
    """Starts one serial line (``KIND:ADDR[,ADDR...]`` of a serial kind) on a new pty.

    ``strict_baud`` (with ``baud``): requests sent at another rate arrive garbled and go
    unanswered, as on a real UART, so a client (or a gateway) that sets the wrong baud
    finds out."""
    plugin, addresses = registry.parse_drive_spec(spec)
    if plugin.transport != "serial":
        raise _core.InvalidArgument(f"drive spec {spec!r}: {plugin.kind} is a {plugin.transport} drive, not serial")
    drives = [make_sim(plugin.kind, a, clock=clock, store_dir=store_dir, **options) for a in addresses]
    # A kind may wire the modules of one line together (e.g. a synchronisation chain on their I/Os).
    plugin.wire_line(drives)
    server = _core.serial.PtyLineServer(devices=drives, baud=baud)
    server.enforce_baud = strict_baud
    return ServedLine(label=spec, server=server, drives=drives)


def serve_lines(specs: Sequence[str], baud: int = 0, clock: Any = None,
                store_dir: Optional[str] = None, strict_baud: bool = False) -> list[ServedLine]:
    lines: list[ServedLine] = []
    try:
        for spec in specs:
            lines.append(serve_line(spec, baud=baud, clock=clock, store_dir=store_dir, strict_baud=strict_baud))
    except Exception:
        for line in lines:
            line.close()
        raise
    return lines


class SimBench:
    """Simulated drives of any kinds, served as a bench would be wired.

    ``SimBench(["<serial kind>:01,02", "cia402:5"], bus="virtual:sim", socketcand=["127.0.0.1:0"])``:
    serial kinds on their ptys (``lines``), CAN kinds as nodes on ``bus``,
    exposed through the socketcand / SLCAN servers (``can``; with CAN drives and
    no server asked for, one socketcand server on 127.0.0.1 with a free port).
    ``sims[(kind, address)]`` reaches each simulator (to inject faults in tests);
    ``sim_options={kind: {...}}`` passes options to that kind's ``make_sim``."""

    def __init__(self, specs: Sequence[str], *, bus: Optional[str] = None, bitrate: Optional[int] = None,
                 socketcand: Sequence[str] = (), slcan_ptys: int = 0, channel: str = "can0", baud: int = 0,
                 strict_baud: bool = False, clock: Any = None, store_dir: Optional[str] = None,
                 sim_options: Optional[dict] = None) -> None:
        self.lines: list[ServedLine] = []
        self.can: Optional[BusServers] = None
        self.sims: dict[tuple[str, str], Any] = {}
        self._can_sims: list[Any] = []
        parsed = [(spec, *registry.parse_drive_spec(spec)) for spec in specs]
        try:
            for spec, plugin, addresses in parsed:
                if plugin.transport == "serial":
                    line = serve_line(spec, baud=baud, clock=clock, store_dir=store_dir, strict_baud=strict_baud,
                                      **(sim_options or {}).get(plugin.kind, {}))
                    self.lines.append(line)
                    self.sims.update({(plugin.kind, a): d for a, d in zip(addresses, line.drives)})
            can_specs = [(plugin, addresses) for _, plugin, addresses in parsed if plugin.transport == "can"]
            if can_specs or socketcand or slcan_ptys:
                if not socketcand and not slcan_ptys:
                    socketcand = ["127.0.0.1:0"]
                options = {"bitrate": bitrate} if bitrate else {}
                self.can = BusServers(bus or f"virtual:motorbus-sim-{id(self):x}", socketcand=socketcand,
                                      slcan_ptys=slcan_ptys, channel=channel, **options)
                for plugin, addresses in can_specs:
                    for a in addresses:
                        sim = make_sim(plugin.kind, a, clock=clock, store_dir=store_dir,
                                       **(sim_options or {}).get(plugin.kind, {}))
                        sim.attach(self.can.endpoint())
                        self._can_sims.append(sim)
                        self.sims[(plugin.kind, a)] = sim
        except Exception:
            self.close()
            raise

    def announce(self) -> list[str]:
        """``<spec> <pty>`` per serial line, then one line per CAN server."""
        out = [f"{line.label} {line.pty_path}" for line in self.lines]
        if self.can is not None:
            out += self.can.announce()
        return out

    def close(self) -> None:
        for sim in self._can_sims:
            sim.close()
        self._can_sims = []
        if self.can is not None:
            self.can.close()
            self.can = None
        for line in self.lines:
            line.close()
        self.lines = []

    def __enter__(self) -> "SimBench":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


# ---------------------------------------------------------------------------------------------
# A bench file's simulated twin that lasts: `motorbus sim serve --bench FILE`.

class TwinBusy(_core.MotorbusError):
    """Another process serves a twin with the same link directory."""


def default_link_dir(bench_file: "str | os.PathLike[str]") -> str:
    """Where ``sim serve --bench FILE`` puts its line symlinks unless told:
    ``<tmp>/motorbus-sim-<uid>/<file name without .toml>`` (``<tmp>`` is
    ``$TMPDIR`` or ``/tmp``), so the written bench file names the same paths each
    time the same bench is served."""
    stem = os.path.splitext(os.path.basename(os.fspath(bench_file)))[0] or "bench"
    return os.path.join(tempfile.gettempdir(), f"motorbus-sim-{os.getuid()}", stem)


def _parse_bench(path: "str | os.PathLike[str]") -> Any:
    """The bench file read and checked by :class:`motorbus.Bench` itself (same
    errors, ``file:line: key: ...``), without opening or serving anything."""
    from .bench import Bench

    class _Parsed(Bench):
        def _open_links(self) -> None:     # nothing to open: the twin is what will be opened
            pass

        def _open_axis(self, cfg: Any) -> Any:
            return None

    return _Parsed.load(path, sim=False)


_LINE_NAME = re.compile(r"^[A-Za-z0-9_+\-][A-Za-z0-9_.+\-]*$")


class BenchTwin:
    """Every axis of a bench file, simulated with the file's ``sim`` options and
    served on stable paths (what ``motorbus sim serve --bench FILE`` runs).

    * each ``[line.NAME]`` carrying axes: a pty served by a line server, reached
      through the symlink ``link_dir/NAME`` (``links[NAME]``; ``link_dir``
      defaults to :func:`default_link_dir`; one twin per directory at a time:
      another process's gets :class:`TwinBusy`);
    * each ``[bus.NAME]``: a virtual CAN bus served over socketcand on
      127.0.0.1, the axes' simulators on it (``specs[NAME]``, an ``open_bus``
      spec).  ``ports``: ``{bus name: port}``, or one int = the first bus's port,
      the next bus gets the next port, in file order; unnamed buses get a free
      port;
    * ``bench_text()`` / ``write(path)``: the bench file of what is served: the
      file's own tables and keys, line ports and bus specs replaced;
    * ``sims[axis]`` and ``inject(axis, name, **options)``: the kind's
      ``sim_faults``; ``control(line)``: the same as a one-line command."""

    def __init__(self, bench_file: "str | os.PathLike[str]", *, link_dir: Optional[str] = None,
                 ports: "int | Mapping[str, int] | None" = None, channel: str = "can0", baud: int = 0,
                 strict_baud: bool = False, bitrate: Optional[int] = None, store_dir: Optional[str] = None,
                 clock: Any = None) -> None:
        self._parsed = _parse_bench(bench_file)
        self.source = self._parsed.source
        self.config = self._parsed.config                      # {axis: AxisConfig}
        self.link_dir = os.path.abspath(link_dir or default_link_dir(bench_file))
        self.channel = channel
        self.sims: dict[str, Any] = {}
        self.lines: dict[str, ServedLine] = {}
        self.links: dict[str, str] = {}
        self.buses: dict[str, BusServers] = {}
        self.specs: dict[str, str] = {}
        self._can_sims: list[Any] = []
        self._lock_fd: Optional[int] = None
        bus_names = list(self._parsed._bus_cfg)
        wanted = self._ports(ports, bus_names)
        try:
            self._claim_link_dir()
            for name in self._parsed._line_cfg:
                axes = [a for a in self.config.values() if a.line == name]
                if axes:     # a described but unused line is left as it is (Bench does not open it)
                    self._serve_line(name, axes, baud, strict_baud, store_dir, clock)
            for name in bus_names:
                self._serve_bus(name, wanted.get(name, 0), bitrate, store_dir, clock)
        except BaseException:
            self.close()
            raise

    # ---- construction ----------------------------------------------------------------------
    def _ports(self, ports: "int | Mapping[str, int] | None", bus_names: list[str]) -> dict[str, int]:
        if ports is None:
            return {}
        if isinstance(ports, int) and not isinstance(ports, bool):
            if not bus_names:
                raise _core.InvalidArgument(f"socketcand port {ports}: {self.source} has no [bus.NAME]")
            if not 0 < ports <= 65536 - len(bus_names):
                raise _core.InvalidArgument(f"socketcand port {ports}: expected 1..{65536 - len(bus_names)} "
                                            f"({len(bus_names)} buses take consecutive ports)")
            return {name: ports + i for i, name in enumerate(bus_names)}
        out = {}
        for name, port in dict(ports).items():
            if name not in bus_names:
                raise _core.InvalidArgument(f"socketcand port for bus {name!r}: {self.source} has no such bus "
                                            f"(buses: {', '.join(bus_names) or 'none'})")
            if isinstance(port, bool) or not isinstance(port, int) or not 0 < port <= 65535:
                raise _core.InvalidArgument(f"socketcand port for bus {name!r}: expected 1..65535, not {port!r}")
            out[name] = port
        if len(set(out.values())) != len(out):
            raise _core.InvalidArgument(f"socketcand ports: two buses on one port ({out})")
        return out

    def _claim_link_dir(self) -> None:
        """One twin per link directory: the lock is the kernel's (flock), so a twin
        that died leaves nothing that blocks the next one."""
        os.makedirs(self.link_dir, mode=0o700, exist_ok=True)
        lock = os.path.join(self.link_dir, ".motorbus-sim.lock")
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o600)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise TwinBusy(f"{self.link_dir} is served by another `motorbus sim serve --bench` (pid {holder}): "
                           f"stop it, or give this one another --link-dir") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._lock_fd = fd

    def _serve_line(self, name: str, axes: list, baud: int, strict_baud: bool, store_dir: Optional[str],
                    clock: Any) -> None:
        if not _LINE_NAME.match(name):
            raise self._parsed._fail(f"line name {name!r} cannot name a symlink in {self.link_dir} "
                                     f"(letters, digits, _ . + - only)", "line", name)
        devices = []
        for a in axes:
            devices.append(self._make_sim(a, store_dir, clock))
            self.sims[a.name] = devices[-1]
        server = _core.serial.PtyLineServer(devices=devices, baud=baud)
        server.enforce_baud = strict_baud
        self.lines[name] = ServedLine(label=name, server=server, drives=devices)
        link = os.path.join(self.link_dir, name)
        if os.path.lexists(link) and not os.path.islink(link):
            raise _core.InvalidArgument(f"{link} exists and is not a symlink: not replacing it "
                                        f"(give another --link-dir)")
        tmp = f"{link}.{os.getpid()}.tmp"
        if os.path.lexists(tmp):
            os.unlink(tmp)
        os.symlink(server.slave_path, tmp)
        os.replace(tmp, link)         # atomic: a client never sees the path missing
        self.links[name] = link

    def _serve_bus(self, name: str, port: int, bitrate: Optional[int], store_dir: Optional[str],
                   clock: Any) -> None:
        options = {"bitrate": bitrate} if bitrate else {}
        served = BusServers(f"virtual:motorbus-twin-{os.getpid()}-{id(self):x}-{name}",
                            socketcand=[f"127.0.0.1:{port}"], channel=self.channel, **options)
        self.buses[name] = served
        for a in self.config.values():
            if a.bus == name:
                sim = self._make_sim(a, store_dir, clock, attach=served.endpoint)
                self._can_sims.append(sim)
                self.sims[a.name] = sim
        srv = served.servers[0]
        self.specs[name] = f"socketcand:{srv.host}:{srv.port}/{self.channel}"

    def _make_sim(self, a: Any, store_dir: Optional[str], clock: Any, attach: Any = None) -> Any:
        """The axis's simulator as ``Bench(sim=True)`` makes it (its errors name the
        option and the file's line), attached to ``attach()`` for a CAN kind."""
        plugin = registry.drive_plugin(a.kind)
        if store_dir is not None:
            a = dataclasses.replace(a, sim={**plugin.store_options(store_dir, a.address), **a.sim})
        bench_make = getattr(self._parsed, "_make_sim", None)
        if bench_make is not None:
            return bench_make(a, clock, attach=attach)
        try:      # a Bench without its own simulator maker
            sim = make_sim(a.kind, a.address, clock=clock, **a.sim)
        except (_core.InvalidArgument, TypeError) as e:
            raise self._parsed._fail(str(e), "axis", a.name, "sim") from None
        if attach is not None:
            sim.attach(attach())
        return sim

    # ---- what is served --------------------------------------------------------------------
    def announce(self) -> list[str]:
        """``line NAME LINK -> PTY`` per line, ``bus NAME SPEC`` per bus."""
        return ([f"line {n} {self.links[n]} -> {line.pty_path}" for n, line in self.lines.items()]
                + [f"bus {n} {spec}" for n, spec in self.specs.items()])

    def report(self) -> list[str]:
        return [f"bus {n}: {line}" for n, served in self.buses.items() for line in served.report()]

    def bench_data(self) -> dict:
        """The file's document with each served line's port and bus's spec replaced."""
        data = copy.deepcopy(dict(self._parsed._checker.data))
        for name, link in self.links.items():
            data["line"][name]["port"] = link
        for name, spec in self.specs.items():
            data["bus"][name]["spec"] = spec
        return data

    def bench_text(self) -> str:
        head = (f"# The simulated twin of {self.source}, served by `motorbus sim serve --bench` (pid {os.getpid()}).\n"
                f"# Valid while that process runs: its lines are the symlinks in {self.link_dir},\n"
                f"# its buses socketcand servers on 127.0.0.1.\n")
        return head + _toml_document(self.bench_data())

    def write(self, path: "str | os.PathLike[str]") -> str:
        """Writes :meth:`bench_text` to ``path`` (atomically: a reader never sees half
        a file); returns the absolute path."""
        path = os.path.abspath(os.fspath(path))
        tmp = f"{path}.{os.getpid()}.tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(self.bench_text())
        os.replace(tmp, path)
        return path

    # ---- faults ------------------------------------------------------------------------------
    def _axis(self, axis: str) -> Any:
        if axis not in self.config:
            raise _core.InvalidArgument(f"no axis {axis!r} in {self.source} (axes: {', '.join(self.config)})")
        return self.config[axis]

    def faults(self, axis: str) -> list[str]:
        """The fault names the axis's simulator offers (its kind's ``sim_faults``)."""
        return sorted(registry.drive_plugin(self._axis(axis).kind).sim_faults())

    def inject(self, axis: str, name: str, **options: Any) -> None:
        """Calls the axis kind's ``sim_faults[name](sim, **options)`` on its simulator."""
        kind = self._axis(axis).kind
        faults = registry.drive_plugin(kind).sim_faults()
        if name not in faults:
            raise _core.InvalidArgument(f"the {kind} simulator (axis {axis!r}) has no fault {name!r} "
                                        f"(it has: {', '.join(sorted(faults)) or 'none'})")
        try:
            faults[name](self.sims[axis], **options)
        except TypeError as e:   # an option the fault does not take
            raise _core.InvalidArgument(f"{kind} fault {name!r}: {e}") from None

    def control(self, line: str) -> Optional[str]:
        """One control command (``sim serve --control``), its one-line answer
        (``ok ...`` or ``error: ...``); None for a blank line or a ``#`` comment.

        * ``fault AXIS NAME [key=value ...]``: :meth:`inject`; a value reads as
          true/false, an integer (``0x`` prefixes too), a float, else a string
          (shell quoting for spaces);
        * ``faults AXIS``: ``ok NAME NAME ...``; ``axes``: ``ok AXIS=KIND ...``."""
        try:
            words = shlex.split(line, comments=True)
            if not words:
                return None
            cmd, rest = words[0], words[1:]
            if cmd == "fault" and len(rest) >= 2:
                options = {}
                for item in rest[2:]:
                    key, eq, value = item.partition("=")
                    if not eq or not key.isidentifier():
                        raise _core.InvalidArgument(f"fault option {item!r}: expected key=value")
                    options[key] = _control_value(value)
                self.inject(rest[0], rest[1], **options)
                return "ok"
            if cmd == "faults" and len(rest) == 1:
                return " ".join(["ok", *self.faults(rest[0])])
            if cmd == "axes" and not rest:
                return " ".join(["ok", *(f"{n}={a.kind}" for n, a in self.config.items())])
            raise _core.InvalidArgument(f"unknown command {line.strip()!r} (commands: fault AXIS NAME "
                                        f"[key=value ...], faults AXIS, axes)")
        except Exception as e:  # noqa: BLE001 - a failed command is answered; the twin goes on serving
            text = str(e) if isinstance(e, _core.MotorbusError) else f"{type(e).__name__}: {e}"
            return "error: " + " ".join(text.split())

    def serve_control(self, lines: Any, answer: Any) -> None:
        """Answers every command of ``lines`` (an iterable of text lines) through
        ``answer(text)``, until they end."""
        for line in lines:
            reply = self.control(line)
            if reply is not None:
                answer(reply)

    # ---- lifetime ----------------------------------------------------------------------------
    def close(self) -> None:
        for sim in self._can_sims:
            sim.close()
        self._can_sims = []
        for served in self.buses.values():
            served.close()
        self.buses = {}
        for name, line in self.lines.items():
            link = self.links.get(name)
            try:      # only our own link: another twin may have taken the directory since
                if link and os.readlink(link) == line.pty_path:
                    os.unlink(link)
            except OSError:
                pass
            line.close()
        self.lines = {}
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None

    def __enter__(self) -> "BenchTwin":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _control_value(text: str) -> Any:
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    for convert in (lambda t: int(t, 10), lambda t: int(t, 0), float):
        try:
            return convert(text)
        except ValueError:
            pass
    return text


# ---- a TOML writer for bench documents (tomllib only reads) ------------------------------------
_BARE_KEY = re.compile(r"^[A-Za-z0-9_\-]+$")


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key, ensure_ascii=False)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)   # JSON's escapes are a subset of TOML's basic strings
    if isinstance(v, (datetime.datetime, datetime.date, datetime.time)):
        return v.isoformat()
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_toml_key(str(k))} = {_toml_value(x)}" for k, x in v.items()) + " }" \
            if v else "{}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise _core.InvalidArgument(f"cannot write {v!r} ({type(v).__name__}) as TOML")


def _toml_document(data: Mapping[str, Any]) -> str:
    """A bench document: ``[section.NAME]`` tables of ``key = value`` lines
    (inline tables below that level)."""
    out = []
    for section, tables in data.items():
        if not all(isinstance(t, Mapping) for t in tables.values()):   # [epics]: keys, not tables
            out.append(f"\n[{_toml_key(section)}]")
            out.extend(f"{_toml_key(key)} = {_toml_value(value)}" for key, value in tables.items())
            continue
        for name, table in tables.items():
            out.append(f"\n[{_toml_key(section)}.{_toml_key(name)}]")
            for key, value in table.items():
                out.append(f"{_toml_key(key)} = {_toml_value(value)}")
    return "\n".join(out).lstrip("\n") + "\n"


# ---------------------------------------------------------------------------------------------
class ServedBench:
    """``motorbus sim serve --bench FILE --control --write TMP`` in a subprocess,
    for tests: the twin lives in another process, as a bench does, and every
    command, Bench or test opens ``bench_file`` (the written file).

        with ServedBench("bench.toml") as served:
            with Bench.load(served.bench_file) as bench:
                bench["z"].move_to(50, wait=False)
                served.inject("z", "limit", direction=1)
                ...

    * ``inject(axis, name, **options)``: the kind's ``sim_faults[name]`` called in
      the serving process (options as ``key=value``: ints, floats, bools and
      strings survive the trip); a refused injection raises InvalidArgument with
      the server's reason;
    * ``faults(axis)``: the names offered; ``close()``: SIGINT, then waits.

    ``bench_file``: a path, or a dict as ``Bench.from_dict`` takes it.
    ``link_dir`` defaults to a fresh temporary directory (tests side by side do
    not share one); ``port``: as ``--port``; ``args``: more ``sim serve``
    arguments.  ``timeout``: seconds to wait for the twin to start, and for each
    answer."""

    def __init__(self, bench_file: "str | os.PathLike[str] | Mapping[str, Any]", *, write: Optional[str] = None,
                 link_dir: Optional[str] = None, port: "int | str | None" = None, args: Sequence[str] = (),
                 timeout: float = 30.0) -> None:
        self._tmp = tempfile.mkdtemp(prefix="motorbus-served-")
        self.timeout = timeout
        if isinstance(bench_file, Mapping):   # a bench as Bench.from_dict takes it: written as TOML first
            source = os.path.join(self._tmp, "source.toml")
            with open(source, "w", encoding="utf-8") as f:
                f.write(_toml_document(bench_file))
            bench_file = source
        self.bench_file = os.path.abspath(write or os.path.join(self._tmp, "bench.toml"))
        self.link_dir = os.path.abspath(link_dir or os.path.join(self._tmp, "links"))
        self.announced: list[str] = []
        cmd = [sys.executable, "-m", "motorbus", "sim", "serve", "--bench", os.fspath(bench_file),
               "--control", "--write", self.bench_file, "--link-dir", self.link_dir, *args]
        if port is not None:
            cmd += ["--port", str(port)]
        self._stderr = open(os.path.join(self._tmp, "stderr.txt"), "w+b")  # a file: a full pipe would block it
        self._lines: "queue.Queue[Optional[str]]" = queue.Queue()
        self._write_lock = threading.Lock()
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._stderr,
                                     text=True, bufsize=1)
        threading.Thread(target=self._read, name="ServedBench stdout", daemon=True).start()
        try:
            while True:
                line = self._next("start serving")
                if line.startswith("bench "):
                    break
                self.announced.append(line)
        except BaseException:
            self.close()
            raise

    def _read(self) -> None:
        assert self.proc.stdout is not None
        try:
            for line in self.proc.stdout:
                self._lines.put(line.rstrip("\n"))
        except (OSError, ValueError):   # close() closed the pipe under us
            pass
        self._lines.put(None)

    def stderr(self) -> str:
        """What the serving process wrote on stderr so far."""
        self._stderr.flush()
        with open(self._stderr.name, "rb") as f:
            return f.read().decode(errors="replace")

    def _next(self, doing: str) -> str:
        try:
            line = self._lines.get(timeout=self.timeout)
        except queue.Empty:
            raise _core.TimeoutError(f"motorbus sim serve did not {doing} in {self.timeout:g} s "
                                     f"(stderr: {self.stderr().strip() or 'empty'})") from None
        if line is None:
            self._lines.put(None)   # every later call sees the end too
            code = self.proc.wait()
            raise _core.LinkDown(f"motorbus sim serve exited ({code}) before it could {doing}: "
                                 f"{self.stderr().strip() or 'no message'}")
        return line

    def command(self, text: str) -> str:
        """Sends one control command; returns the answer after ``ok`` (InvalidArgument
        with the server's reason on ``error: ...``)."""
        with self._write_lock:
            if self.proc.stdin is None or self.proc.poll() is not None:
                raise _core.LinkDown(f"motorbus sim serve is not running ({self.stderr().strip() or 'no message'})")
            self.proc.stdin.write(text + "\n")
            self.proc.stdin.flush()
            answer = self._next(f"answer {text!r}")
        if answer.startswith("error: "):
            raise _core.InvalidArgument(f"served twin: {text}: {answer[len('error: '):]}")
        if answer != "ok" and not answer.startswith("ok "):
            raise _core.ProtocolError(f"served twin: {text}: unexpected answer {answer!r}")
        return answer[3:]

    def inject(self, axis: str, name: str, **options: Any) -> None:
        words = ["fault", axis, name]
        for key, value in options.items():
            if isinstance(value, bool):
                value = "true" if value else "false"
            elif not isinstance(value, (int, float, str)):
                raise _core.InvalidArgument(f"inject {axis} {name}: option {key}={value!r}: "
                                            f"only ints, floats, bools and strings cross to the served twin")
            words.append(f"{key}={value}")
        self.command(" ".join(shlex.quote(str(w)) for w in words))

    def faults(self, axis: str) -> list[str]:
        return self.command(f"faults {shlex.quote(axis)}").split()

    def close(self) -> None:
        """SIGINT (the twin closes its servers and removes its links), then waits."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=max(self.timeout, 10.0))
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for stream in (self.proc.stdin, self.proc.stdout):
            try:
                if stream is not None:
                    stream.close()
            except OSError:
                pass
        self._stderr.close()
        shutil.rmtree(self._tmp, ignore_errors=True)

    def __enter__(self) -> "ServedBench":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

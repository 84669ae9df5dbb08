"""pytest plugin: hardware-in-the-loop tests against a bench, or its simulated twin.

Installed with motorbus (entry point ``pytest11``); load it by hand with
``-p motorbus.pytest_plugin``.  See docs/pytest-plugin.md.

* ``--bench FILE``: the real bench described by FILE (docs/bench-files.md);
* ``--bench-sim [FILE]``: FILE's simulated twin (every axis replaced by its
  simulator behind the same kind of transport).  Without FILE, and when neither
  option is given: the ini option ``motorbus_bench``, else a built-in bench with
  one axis of every registered drive kind (named after the kind).
* ``--bench-server [ADDR]``: the bench a running ``motorbus serve`` owns
  (docs/serve.md): ADDR is its bench file or ``unix:/path.sock``; without ADDR, the
  service of the ``--bench``/``--bench-sim``/ini bench file.  The fixtures' axes are
  then the service's (RemoteDrive; ``poller`` a RemotePoller of its shared poll), and
  other programs may use the bench meanwhile.

Fixtures: ``bench`` (a :class:`motorbus.Bench`), ``axis`` (one Drive, by name:
indirect parametrization or the ``axes`` marker), ``bus`` (a bench bus),
``poller`` (a running ``motorbus.Poller`` over the test's axes), ``sim_faults``
(fault injection on the simulated twin).  Marker ``@pytest.mark.axes("x", "z")``:
the test is skipped, saying why, when the bench lacks one of them.

The bench is opened once per session, the first time a test asks for it: a
suite that uses none of the fixtures opens nothing.  After every test that used
it every axis is stopped (stop, then quick_stop for an axis that refuses or does
not come to rest) — after a pass, a failure, an error, a timeout; on Ctrl-C and
at the end of the session too.  SIGTERM and SIGHUP (a cancelled CI job) take the
Ctrl-C path: motorbus raises ``TerminatedBySignal``, a ``KeyboardInterrupt``, and the
process then dies by the signal (docs/reliability.md, "Signals").
"""
from __future__ import annotations

import json
import os
import threading
from pathlib import Path
from typing import Any, Optional

import pytest

_FROM_DEFAULT = "\0default"          # --bench-sim given without a FILE
_SERVER_OF_FILE = "\0file"           # --bench-server given without an ADDR
_STOP_WAIT = 5.0                     # seconds an axis gets to come to rest after stop()


# ---- the bench of the session ------------------------------------------------------------
def default_bench() -> dict:
    """One axis of every registered kind at its default address, named after the kind:
    each serial kind on a line of its own, each CAN kind on a bus of its own (two kinds'
    identifiers could otherwise collide on one bus)."""
    from . import registry

    data: dict = {"line": {}, "bus": {}, "axis": {}}
    for kind, plugin in registry.drive_plugins().items():
        where = f"{kind}-link"
        if plugin.transport == "serial":
            data["line"][where] = {"port": f"/dev/null-{kind}"}   # replaced by a pty in the twin
            data["axis"][kind] = {"kind": kind, "line": where, "address": plugin.default_address}
        else:
            data["bus"][where] = {"spec": f"virtual:{kind}"}       # replaced by a served bus in the twin
            data["axis"][kind] = {"kind": kind, "bus": where, "address": plugin.default_address}
    return data


class BenchSession:
    """The session's bench: opened on first use, stopped after each test, closed at the end."""

    def __init__(self, config: pytest.Config) -> None:
        real = config.getoption("motorbus_bench")
        sim = config.getoption("motorbus_bench_sim")
        if real and sim:
            raise pytest.UsageError("--bench and --bench-sim: give one (the hardware or its simulated twin)")
        self.simulated = not real
        path = real or sim
        if path in (None, _FROM_DEFAULT):
            path = config.getini("motorbus_bench") or None
            if path:
                base = config.inipath.parent if config.inipath else config.rootpath
                path = str((base / path).resolve())
        self.path: Optional[str] = path
        self.server: Optional[str] = config.getoption("motorbus_bench_server")
        if self.server == _SERVER_OF_FILE:
            if not path:
                raise pytest.UsageError("--bench-server without ADDR: which bench? give ADDR (its bench file or "
                                        "unix:/path.sock), or --bench FILE / the motorbus_bench ini option")
            self.server = path
        self.explicit = bool(real or sim or self.server)
        self.bench: Any = None
        self.identities: dict[str, dict] = {}
        self.open_error: Optional[BaseException] = None
        self.reopen = False            # a test spoilt the twin (sim_faults): the next test gets a fresh one
        self._lock = threading.Lock()

    @property
    def label(self) -> str:
        if self.server:
            return f"{self.server} (through motorbus serve)"
        where = self.path or "built-in bench (one axis of every registered kind)"
        return f"{where} ({'simulated twin' if self.simulated else 'hardware'})"

    def get(self) -> Any:
        with self._lock:
            if self.open_error is not None:
                # A bench that did not open once (a wrong file, hardware switched off)
                # fails the tests that need it at once instead of timing out in each.
                raise self.open_error
            if self.bench is None:
                from .bench import Bench

                try:
                    if self.server:
                        self.bench = _connect_server(self.server)
                        self.simulated = bool(self.bench.simulated)
                    elif self.path is None:
                        self.bench = Bench.from_dict(default_bench(), sim=True)
                    else:
                        self.bench = Bench.load(self.path, sim=self.simulated)
                except Exception as e:
                    self.open_error = e
                    raise
                self.reopen = False
                # A served bench's drives answer through the service: identifying them would
                # need its transports.
                self.identities = {} if self.server else identify(self.bench)
            return self.bench

    def stop_all(self) -> list[str]:
        """Stops every axis; returns what went wrong (the test report shows it)."""
        bench = self.bench
        if bench is None or bench.closed:
            return []
        from .drive import MoveFailed, MoveTimedOut

        problems = []
        if self.server:
            # A served bench is shared: only what this session commanded is stopped, not
            # what another program moves meanwhile.
            axes = {n: d for n, d in bench.axes.items() if getattr(d, "commanded", False)}
            failed = {}
            for name, drive in axes.items():
                try:
                    drive.stop()
                except Exception as e:  # noqa: BLE001 - then the harder stop
                    failed[name] = e
        else:
            axes = bench.axes
            failed = dict(bench.stop_all("stop"))
        for name, drive in axes.items():
            if name in failed or drive.closed:
                continue
            try:
                drive.wait_idle(timeout=_STOP_WAIT)
            except MoveFailed as e:
                # The move this stop cut short (or that had already failed) is the test's
                # business; only an axis still moving needs the harder stop.
                if isinstance(e, MoveTimedOut):
                    failed[name] = e
            except Exception as e:  # noqa: BLE001 - then the harder stop
                failed[name] = e
        if failed:
            for name, e in failed.items():
                problems.append(f"{name}: stop: {type(e).__name__}: {e}")
            for name in failed:        # the harder stop, for those axes only
                drive = bench.axes[name]
                if drive.closed:
                    continue
                try:
                    drive.quick_stop()
                except Exception as e:  # noqa: BLE001 - the others must still be tried
                    problems.append(f"{name}: quick_stop: {type(e).__name__}: {e}")
        return problems

    def close(self) -> None:
        with self._lock:
            if self.bench is not None:
                try:
                    self.stop_all()
                finally:
                    self.bench.close()
                    self.bench = None
                    self.reopen = False


def _connect_server(address: str) -> Any:
    """The served bench at ``address``; a bench file with no service running says so."""
    from . import _core
    from .serve import find_service
    from .serve.client import connect

    if not address.startswith("unix:") and os.path.isfile(address) and find_service(address) is None:
        raise _core.LinkDown(f"--bench-server {address}: no motorbus serve runs for this bench file "
                             f"(start one: motorbus serve {address})")
    return connect(address)


_session_key = pytest.StashKey[BenchSession]()


def _session(config: pytest.Config) -> BenchSession:
    return config.stash[_session_key]


def identify(bench: Any) -> dict[str, dict]:
    """``{axis: {"kind", "address", "where", ...identity}}``: what each drive says it is
    (model, firmware, serial... as its plugin's discovery probe reads them; a CANopen
    node's 0x1000/0x1018).  Reads only; an axis that does not answer says so."""
    from . import registry

    out: dict[str, dict] = {}
    for name, cfg in bench.config.items():
        plugin = registry.drive_plugin(cfg.kind)
        entry: dict = {"kind": cfg.kind, "address": cfg.address,
                       "where": f"line {cfg.line}" if cfg.line else f"bus {cfg.bus}"}
        try:
            if plugin.provides("canopen_match"):
                from .canopen import scan_network

                node = int(cfg.address, 0)
                found = scan_network(bench.buses[cfg.bus], first=node, last=node, sdo_timeout=0.2)
                if found:
                    from .discovery import _node_identity

                    entry.update(_node_identity(found[0]))
                    entry.update(_canopen_strings(bench.buses[cfg.bus], node))
                else:
                    entry["identity"] = "no answer"
            elif plugin.provides("probe"):
                link = bench.lines[cfg.line] if cfg.line else bench.buses[cfg.bus]
                entry.update(plugin.probe(link, cfg.address) or {"identity": "no answer"})
            else:
                entry["identity"] = "the kind gives none"
        except Exception as e:  # noqa: BLE001 - the report says why instead of failing the run
            entry["identity"] = f"unreadable: {type(e).__name__}: {e}"
        out[name] = {k: (v if isinstance(v, (str, int, float, bool)) else str(v)) for k, v in entry.items()}
    return out


_CANOPEN_STRINGS = ((0x1008, "model"), (0x1009, "hardware"), (0x100A, "firmware"))


def _canopen_strings(bus: Any, node: int) -> dict:
    """CiA 301's optional name and versions (0x1008/0x1009/0x100A), those the node has."""
    from . import _core

    out = {}
    sdo = _core.canopen.SdoClient(bus, node, timeout=0.3)
    try:
        for index, key in _CANOPEN_STRINGS:
            try:
                text = sdo.read_string(index, 0).strip("\0 ")
            except _core.MotorbusError:    # the object is optional: an abort says the node has none
                continue
            if text:
                out[key] = text
    finally:
        close = getattr(sdo, "close", None)
        if close is not None:
            close()
    return out


# ---- options, marker, header -------------------------------------------------------------
def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("motorbus", "motorbus bench (hardware in the loop)")
    group.addoption("--bench", dest="motorbus_bench", metavar="FILE", default=None,
                    help="run the bench fixtures on the real bench described by FILE (TOML)")
    group.addoption("--bench-sim", dest="motorbus_bench_sim", metavar="FILE", nargs="?", const=_FROM_DEFAULT,
                    default=None, help="run them on FILE's simulated twin (the default; without FILE: the "
                                       "motorbus_bench ini option, else one axis of every registered kind)")
    group.addoption("--bench-server", dest="motorbus_bench_server", metavar="ADDR", nargs="?",
                    const=_SERVER_OF_FILE, default=None,
                    help="run them on the bench a running `motorbus serve` owns: ADDR is its bench file or "
                         "unix:/path.sock (without ADDR: the service of the --bench/--bench-sim/ini bench file)")
    parser.addini("motorbus_bench", "bench file for the motorbus fixtures when no --bench/--bench-sim FILE "
                                    "is given (its simulated twin unless --bench)", default="")
    parser.addini("motorbus_poll_rate", "sampling rate (Hz) of the poller fixture", default="100")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "axes(*names): the bench axes the test needs; skipped when the bench "
                                       "lacks one")
    config.stash[_session_key] = BenchSession(config)


def pytest_report_header(config: pytest.Config) -> Optional[str]:
    s = _session(config)
    return f"motorbus bench: {s.label}" if s.explicit else None


def pytest_unconfigure(config: pytest.Config) -> None:
    if _session_key in config.stash:
        _session(config).close()


def pytest_keyboard_interrupt(excinfo: Any) -> None:
    # Ctrl-C: the axes stop at once, before pytest prints its summary and tears down.
    for s in list(_live_sessions):
        s.stop_all()


_live_sessions: "set[BenchSession]" = set()


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish(session: pytest.Session) -> None:
    s = session.config.stash.get(_session_key, None)
    if s is not None:
        s.close()
        _live_sessions.discard(s)


@pytest.hookimpl(optionalhook=True, tryfirst=True)
def pytest_timeout_set_timer(item: pytest.Item, settings: Any) -> Optional[bool]:
    """pytest-timeout's ``thread`` method ends the process with os._exit (no teardown):
    stop the axes first.  The ``signal`` method fails the test; the teardown stops them."""
    s = item.config.stash.get(_session_key, None)
    if settings.method != "thread" or s is None or "bench" not in getattr(item, "fixturenames", ()):
        return None
    import pytest_timeout

    def expire() -> None:
        try:
            s.stop_all()
        finally:
            pytest_timeout.timeout_timer(item, settings)

    timer = threading.Timer(settings.timeout, expire)
    timer.name = f"motorbus-timeout {item.nodeid}"
    timer.daemon = True

    def cancel() -> None:
        timer.cancel()
        timer.join()

    item.cancel_timeout = cancel  # type: ignore[attr-defined]
    timer.start()
    return True


def _wanted_axes(request: pytest.FixtureRequest) -> tuple[str, ...]:
    marker = request.node.get_closest_marker("axes")
    return tuple(marker.args) if marker else ()


# ---- fixtures ----------------------------------------------------------------------------
@pytest.fixture
def bench(request: pytest.FixtureRequest) -> Any:
    """The session's bench (opened on first use); every axis is stopped after the test."""
    s = _session(request.config)
    b = s.get()
    _live_sessions.add(s)
    missing = [a for a in _wanted_axes(request) if a not in b.axes]
    if missing:
        pytest.skip(f"bench {s.label} has no axis {', '.join(map(repr, missing))} "
                    f"(it has: {', '.join(b.axes) or 'none'})")
    request.node.user_properties.append(("motorbus_bench", s.label))
    for name, ident in s.identities.items():
        request.node.user_properties.append((f"motorbus_axis_{name}", json.dumps(ident, sort_keys=True)))
    request.node.add_report_section("setup", "motorbus bench", _describe(s))
    try:
        yield b
    finally:
        if s.reopen:
            s.close()    # spoilt by sim_faults: stop what can be stopped, the next test gets a fresh twin
            problems = []
        else:
            problems = s.stop_all()
        if problems:
            request.node.add_report_section("teardown", "motorbus stop", "\n".join(problems))
            request.node.user_properties.append(("motorbus_stop_problems", "; ".join(problems)))


def _describe(s: BenchSession) -> str:
    lines = [f"bench: {s.label}"]
    for name, ident in s.identities.items():
        rest = ", ".join(f"{k}={v}" for k, v in ident.items() if k not in ("kind", "address", "where"))
        lines.append(f"  {name}: {ident['kind']} at {ident['address']} on {ident['where']}: {rest}")
    return "\n".join(lines)


@pytest.fixture
def axis(request: pytest.FixtureRequest, bench: Any) -> Any:
    """One axis (a motorbus.Drive): the name given by indirect parametrization
    (``@pytest.mark.parametrize("axis", ["x", "z"], indirect=True)``), else the first
    of the ``axes`` marker, else the bench's only axis."""
    name = getattr(request, "param", None)
    if name is None:
        wanted = _wanted_axes(request)
        if wanted:
            name = wanted[0]
        elif len(bench.axes) == 1:
            name = next(iter(bench.axes))
        else:
            raise pytest.UsageError(f"axis fixture: which axis of {', '.join(bench.axes)}? parametrize it "
                                    f"(indirect=True) or mark the test @pytest.mark.axes(NAME)")
    if name not in bench.axes:
        pytest.skip(f"bench {_session(request.config).label} has no axis {name!r} "
                    f"(it has: {', '.join(bench.axes)})")
    return bench[name]


@pytest.fixture
def bus(request: pytest.FixtureRequest, bench: Any) -> Any:
    """A bus of the bench (a motorbus.Bus): the name given by indirect parametrization,
    else the bench's only bus."""
    name = getattr(request, "param", None)
    if name is None:
        if len(bench.buses) != 1:
            pytest.skip(f"bus fixture: the bench has {len(bench.buses)} buses ({', '.join(bench.buses)}); "
                        f"parametrize it with one (indirect=True)")
        name = next(iter(bench.buses))
    if name not in bench.buses:
        pytest.skip(f"bench has no bus {name!r} (it has: {', '.join(bench.buses) or 'none'})")
    return bench.buses[name]


@pytest.fixture
def poller(request: pytest.FixtureRequest, bench: Any, tmp_path: Path) -> Any:
    """A running ``motorbus.Poller`` over the test's axes (the ``axes`` marker's, else
    the ``axis`` fixture's, else every axis) at the ini ``motorbus_poll_rate``; its samples are saved next to the
    test (``tmp_path / "motorbus-samples.npz"``) and named in the report."""
    import motorbus

    poller_cls = getattr(motorbus, "Poller", None)
    if _session(request.config).server:
        # The service's shared poll (one Poller in the service however many subscribe).
        def poller_cls(axes: Any, rate_hz: float) -> Any:
            return bench.poll(list(axes), rate_hz=rate_hz)
    if poller_cls is None:
        pytest.skip("motorbus.Poller is not available in this motorbus (poller fixture)")
    names = _wanted_axes(request)
    if not names and "axis" in request.fixturenames:     # the test's one axis
        drive = request.getfixturevalue("axis")
        names = tuple(n for n, d in bench.axes.items() if d is drive)
    names = names or tuple(bench.axes)
    rate = float(request.config.getini("motorbus_poll_rate"))
    with poller_cls({n: bench[n] for n in names}, rate_hz=rate) as p:
        try:
            yield p
        finally:
            path = tmp_path / "motorbus-samples.npz"
            try:
                p.save(path)
                request.node.user_properties.append(("motorbus_samples", str(path)))
                request.node.add_report_section("teardown", "motorbus samples", f"{path}\n{p.stats}")
            except Exception as e:  # noqa: BLE001 - the samples must not hide the test's own result
                request.node.add_report_section("teardown", "motorbus samples", f"not saved: {e}")


class SimFaults:
    """Fault injection on the simulated twin (the ``sim_faults`` fixture).

    * ``offered(axis)``: the faults that axis's simulator has (its kind's
      ``Drive.sim_faults()``); ``inject(axis, name, **options)`` provokes one;
    * bus and line faults, owned by the bench: ``spoil_frames(bus=None, drop=0.0,
      corrupt=0.0, delay=0.0, drop_every=0, seed=...)`` on a simulated bus (both
      directions), ``cut_line(line)`` / ``cut_bus(bus)`` end the served transport.

    The twin is not reused afterwards: the next test gets fresh simulators."""

    def __init__(self, session: BenchSession, bench: Any) -> None:
        self._session, self._bench = session, bench

    def offered(self, axis: str) -> list[str]:
        from . import registry

        self._bench[axis]  # names the axes when this one does not exist
        return sorted(registry.drive_plugin(self._bench.config[axis].kind).sim_faults())

    def inject(self, axis: str, fault: str, **options: Any) -> None:
        from . import _core, registry

        self._bench[axis]
        kind = self._bench.config[axis].kind
        faults = registry.drive_plugin(kind).sim_faults()
        if fault not in faults:
            raise _core.InvalidArgument(f"sim_faults: the {kind} simulator (axis {axis!r}) has no fault {fault!r} "
                                        f"(it has: {', '.join(sorted(faults)) or 'none'})")
        self._session.reopen = True
        try:
            faults[fault](self._bench.sims[axis], **options)
        except TypeError as e:  # an option the fault does not take
            raise _core.InvalidArgument(f"sim_faults: {kind} fault {fault!r}: {e}") from None

    def _one(self, what: str, served: dict, name: Optional[str]) -> tuple[str, Any]:
        from . import _core

        if name is None:
            if len(served) != 1:
                raise _core.InvalidArgument(f"sim_faults: which {what}? the bench has {', '.join(served) or 'none'}")
            name = next(iter(served))
        if name not in served:
            raise _core.InvalidArgument(f"sim_faults: no simulated {what} {name!r} "
                                        f"(the bench has: {', '.join(served) or 'none'})")
        return name, served[name]

    def spoil_frames(self, bus: Optional[str] = None, *, drop: float = 0.0, corrupt: float = 0.0,
                     delay: float = 0.0, drop_every: int = 0, seed: int = 24301) -> None:
        _, served = self._one("bus", self._bench.served_buses, bus)
        self._session.reopen = True
        served.set_faults(drop_every=drop_every, drop_probability=drop, corrupt_probability=corrupt,
                          delay=delay, seed=seed)

    def cut_line(self, line: Optional[str] = None) -> None:
        _, server = self._one("line", self._bench.served_lines, line)
        self._session.reopen = True
        server.close()

    def cut_bus(self, bus: Optional[str] = None) -> None:
        _, served = self._one("bus", self._bench.served_buses, bus)
        self._session.reopen = True
        for srv in served.servers:
            srv.close()


@pytest.fixture
def sim_faults(request: pytest.FixtureRequest, bench: Any) -> SimFaults:
    """Fault injection on the simulated twin (skipped on real hardware): see SimFaults."""
    s = _session(request.config)
    if s.server:
        pytest.skip(f"sim_faults: the bench is served ({s.label}); its simulators, if any, live in the "
                    f"service's process")
    if not s.simulated:
        pytest.skip(f"sim_faults: the bench is real hardware ({s.label}); faults are injected on its "
                    f"simulated twin only (--bench-sim)")
    return SimFaults(s, bench)

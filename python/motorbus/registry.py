"""The registry of drive kinds and bus schemes, filled from entry points.

Two entry-point groups, read once and lazily (as python-can reads ``can.interface``):

* ``motorbus.drive``: ``<kind> = "package.module:PLUGIN"``, a :class:`DrivePlugin`;
* ``motorbus.bus``: ``<scheme> = "package.module:SCHEME"``, a :class:`BusScheme`.

motorbus declares its own vendors and schemes in its ``pyproject.toml`` exactly
as another package declares its own (docs/plugins.md), so nothing in motorbus
names a vendor outside the vendor's own module.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from importlib import metadata
from typing import Any, Callable, Optional

from . import _core

__all__ = ["DRIVE_GROUP", "BUS_GROUP", "DrivePlugin", "PollSpec", "BusScheme", "drive_plugin", "drive_plugins",
           "drive_kinds", "bus_scheme", "bus_schemes", "parse_drive_spec"]

DRIVE_GROUP = "motorbus.drive"
BUS_GROUP = "motorbus.bus"


@dataclass(frozen=True)
class PollSpec:
    """What a drive kind's ``poll_fields(drive, fields)`` gives :class:`motorbus.Poller`.

    * ``source``: a ``_core.PollSource`` (built on the kind's native C++ client)
      that reads the fields, in the order asked, on the poll thread;
    * ``scales``: per field, the factor from the source's reading to the Drive's
      native units (the Poller then applies ``drive.units`` to position and velocity);
    * ``transport``: the LineLink or Bus the source talks over: axes on one
      transport share one poll thread (their requests take turns on it anyway);
    * ``bus``: the CAN Bus (for ``candump=``), None on a serial line;
    * ``stamped``: True for a capture source (the drive pushes, the source takes
      the latest pushed values): its first column is when the data arrived
      (monotonic ns, NaN until it did), before the fields — the Poller shows it
      as ``<axis>.t``;
    * ``close``: called once when the Poller stops (a capture source stops the
      transmissions it started), or None.
    """

    source: Any
    scales: tuple
    transport: Any
    bus: Any = None
    stamped: bool = False
    close: Optional[Callable[[], None]] = None


@dataclass(frozen=True)
class DrivePlugin:
    """What a vendor module exports as ``PLUGIN``.

    * ``transport``: ``"serial"`` (a line, shared by drives of one kind: RS-485
      multi-drop) or ``"can"`` (a node on a CAN bus).
    * ``open(*, line, bus, address, units, **options) -> Drive``: the Drive adapter.
    * ``make_sim(address, clock=None, **options)``: a simulated drive.  Serial:
      a LineDevice for a PtyLineServer.  CAN: an object with ``attach(bus)`` and
      ``close()`` (``make_sim(..., bus=bus)`` attaches at once).
    * ``line_settings``: serial only, the framing (request/reply terminators,
      max line) a line server and a LineLink need.
    * ``check_address(text) -> str``: the canonical form of an address, or
      InvalidArgument naming the problem.
    * Discovery (``motorbus.discover``; it never moves a motor nor writes a
      parameter): ``probe(link, address) -> dict | None`` asks one address for
      its identity (``{"model": ..., "firmware": ..., "serial": ...}``, what the
      protocol gives) over a LineLink framed with ``line_settings`` (serial) or
      a Bus (CAN kinds that are not CANopen); ``probe_addresses`` and
      ``probe_bauds`` are what a sweep tries.  CANopen kinds set
      ``canopen_match(node) -> int`` instead: a score for a node found by the
      CANopen scan (``NodeInfo``: device type, vendor id, product code...), 0 =
      not this kind; the highest score names the node's kind.
    * ``synchronised_start(link, drives)``, ``sim_faults``: see the fields' comments.
    * ``poll_fields(drive, fields) -> PollSpec``: see the field's comment.
    """

    kind: str
    description: str
    transport: str
    open: Callable[..., Any]
    make_sim: Callable[..., Any]
    check_address: Callable[[str], str]
    default_address: str
    line_settings: Optional[dict] = None
    default_baud: int = 0
    sim_options: tuple = ()
    #: Options make_sim takes per served drive from ``sim serve --store-dir``: a
    #: function (store_dir, address) -> dict of options.
    store_options: Optional[Callable[[str, str], dict]] = None
    probe: Optional[Callable[..., Optional[dict]]] = None
    probe_addresses: tuple = ()
    probe_bauds: tuple = ()
    canopen_match: Optional[Callable[[Any], int]] = None
    #: A drive-level synchronised start for axes of this kind sharing one link:
    #: ``synchronised_start(link, drives)`` is a context manager; moves commanded
    #: inside it start together when it exits (``Bench.move_together`` uses it).
    synchronised_start: Optional[Callable[..., Any]] = None
    #: Faults the kind's simulator can be given for robustness tests (the pytest
    #: plugin's ``sim_faults`` fixture): ``{name: fault(sim, **options)}``, each
    #: provoking what its name says on one simulated drive (a limit switch trips,
    #: the rotor stalls, the supply drops...).  Names are the kind's own; the
    #: fixture lists them when asked for one the kind does not have.
    sim_faults: Optional[dict] = None
    #: What ``motorbus.Poller`` reads from an open Drive of this kind on its C++
    #: poll thread: ``poll_fields(drive, fields) -> PollSpec`` for a tuple of
    #: field names among "position", "velocity", "status" (InvalidArgument for a
    #: field the kind cannot give).  None: the kind cannot be polled.
    poll_fields: Optional[Callable[..., "PollSpec"]] = None
    #: The kind's own profile model for a position move of an open Drive:
    #: ``plan_move(drive, start, target) -> motion.Profile`` in native units,
    #: t = 0 at the command, from the drive's current speed/ramp parameters
    #: (``motorbus.plot.planned``, ``motorbus demo``).  None: no model.
    plan_move: Optional[Callable[..., Any]] = None
    #: For kinds whose drive can push its data (CANopen TPDOs, cyclic registers):
    #: ``capture_fields(drive, fields, period) -> PollSpec`` (period in s) sets the
    #: drive to transmit the fields about every period and returns a capture
    #: source (``stamped=True``) that takes what arrives instead of asking.
    #: None: the kind can only be asked (``poll_fields``).
    capture_fields: Optional[Callable[..., "PollSpec"]] = None

    def __post_init__(self) -> None:
        if self.transport not in ("serial", "can"):
            raise _core.InvalidArgument(f"drive plugin {self.kind!r}: transport 'serial' or 'can', "
                                        f"not {self.transport!r}")


@dataclass(frozen=True)
class BusScheme:
    """What a bus backend module exports for ``open_bus("<scheme>:...")``.

    ``parse(rest) -> dict`` turns the text after ``<scheme>:`` into keyword
    arguments of ``open(**kwargs, **options) -> Bus``."""

    scheme: str
    description: str
    parse: Callable[[str], dict]
    open: Callable[..., Any]
    example: str = ""


_lock = threading.Lock()
_cache: dict[str, dict[str, Any]] = {}


def _load(group: str) -> dict[str, Any]:
    with _lock:
        if group in _cache:
            return _cache[group]
        found: dict[str, Any] = {}
        for ep in metadata.entry_points(group=group):
            found.setdefault(ep.name, ep)  # first declaration wins, as importlib orders them
        _cache[group] = found
        return found


def _resolve(group: str, name: str, what: str) -> Any:
    entries = _load(group)
    ep = entries.get(name)
    if ep is None:
        known = ", ".join(sorted(entries)) or "none registered: is motorbus installed (pip install -e .)?"
        raise _core.InvalidArgument(f"unknown {what} {name!r} (registered: {known})")
    if not isinstance(ep, metadata.EntryPoint):
        return ep
    try:
        obj = ep.load()
    except Exception as e:  # a broken plugin must say which one and why
        raise _core.InvalidArgument(f"{what} {name!r}: its entry point {ep.value} does not load: "
                                    f"{type(e).__name__}: {e}") from e
    with _lock:
        _cache[group][name] = obj
    return obj


def register(group: str, name: str, obj: Any) -> None:
    """Adds a plugin at run time (tests, notebooks); entry points are the normal way."""
    if group not in (DRIVE_GROUP, BUS_GROUP):
        raise _core.InvalidArgument(f"registry group: {DRIVE_GROUP!r} or {BUS_GROUP!r}, not {group!r}")
    _load(group)
    with _lock:
        _cache[group][name] = obj


def drive_plugin(kind: str) -> DrivePlugin:
    plugin = _resolve(DRIVE_GROUP, kind, "drive kind")
    if not isinstance(plugin, DrivePlugin):
        raise _core.InvalidArgument(f"drive kind {kind!r}: its entry point is not a motorbus.registry.DrivePlugin")
    return plugin


def drive_plugins() -> dict[str, DrivePlugin]:
    """Every registered drive kind, loaded (imports each vendor module)."""
    return {kind: drive_plugin(kind) for kind in sorted(_load(DRIVE_GROUP))}


def drive_kinds() -> dict[str, str]:
    """``{kind: one-line description}`` of every registered drive kind."""
    return {kind: plugin.description for kind, plugin in drive_plugins().items()}


def bus_scheme(scheme: str) -> BusScheme:
    obj = _resolve(BUS_GROUP, scheme, "bus scheme")
    if not isinstance(obj, BusScheme):
        raise _core.InvalidArgument(f"bus scheme {scheme!r}: its entry point is not a motorbus.registry.BusScheme")
    return obj


def bus_schemes() -> dict[str, BusScheme]:
    return {name: bus_scheme(name) for name in sorted(_load(BUS_GROUP))}


def parse_drive_spec(spec: str) -> tuple[DrivePlugin, list[str]]:
    """``"<kind>:01,02"`` -> (that kind's plugin, ["01", "02"]); InvalidArgument naming the problem."""
    kind, sep, addrs = spec.partition(":")
    if not sep or not addrs:
        raise _core.InvalidArgument(f"drive spec {spec!r}: expected KIND:ADDR[,ADDR...], e.g. cia402:5")
    plugin = drive_plugin(kind)
    addresses = [plugin.check_address(a.strip()) for a in addrs.split(",")]
    if len(set(addresses)) != len(addresses):
        raise _core.InvalidArgument(f"drive spec {spec!r}: addresses must be distinct")
    return plugin, addresses

"""The registry of drive kinds and bus schemes, filled from entry points.

Two entry-point groups, read once and lazily (as python-can reads ``can.interface``):

* ``motorbus.drive``: ``<kind> = "package.module:SomeDrive"``, the kind's
  :class:`motorbus.Drive` subclass (as python-can's ``can.interface`` names a bus
  class): its class attributes say what the kind is, its methods and
  classmethods are the kind's hooks (docs/plugins.md);
* ``motorbus.bus``: ``<scheme> = "package.module:SCHEME"``, a :class:`BusScheme`.

motorbus declares its own vendors and schemes in its ``pyproject.toml`` exactly
as another package declares its own (docs/plugins.md), so nothing in motorbus
names a vendor outside the vendor's own module.
"""
from __future__ import annotations

import inspect

import threading
from dataclasses import dataclass
from importlib import metadata
from typing import TYPE_CHECKING, Any, Callable, Optional

from . import _core

if TYPE_CHECKING:
    from .drive import Drive

__all__ = ["DRIVE_GROUP", "BUS_GROUP", "PollSpec", "BusScheme", "drive_plugin", "drive_plugins",
           "drive_kinds", "bus_scheme", "bus_schemes", "parse_drive_spec"]

DRIVE_GROUP = "motorbus.drive"
BUS_GROUP = "motorbus.bus"


@dataclass(frozen=True)
class PollSpec:
    """What a drive's ``poll_fields(fields)`` gives :class:`motorbus.Poller`.

    * ``source``: a ``_core.poll.PollSource`` (built on the kind's native C++ client)
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


# The registry sits below the Drive class (drive.py imports it to open a kind), so it does
# not import drive.py back: the Drive class names itself here when it is defined.
_drive_base: Optional[type] = None


def set_drive_base(cls: type) -> None:
    """Called once by motorbus.drive: the class every registered drive kind must subclass."""
    global _drive_base
    _drive_base = cls


def drive_plugin(kind: str) -> "type[Drive]":
    """The :class:`motorbus.Drive` subclass registered as ``kind`` (its entry point loaded)."""
    cls = _resolve(DRIVE_GROUP, kind, "drive kind")
    if _drive_base is None:  # only if motorbus.registry were imported without the package
        raise _core.InvalidArgument("drive kinds: import motorbus first (motorbus.drive defines their base class)")
    if not (isinstance(cls, type) and issubclass(cls, _drive_base)):
        raise _core.InvalidArgument(f"drive kind {kind!r}: its entry point is not a motorbus.Drive subclass "
                                    f"(it is {cls!r})")
    if cls.transport not in ("serial", "can"):
        raise _core.InvalidArgument(f"drive kind {kind!r} ({cls.__qualname__}): transport 'serial' or 'can', "
                                    f"not {cls.transport!r}")
    # A hook that talks to the drive as a plain function would block every task of an
    # event loop (motorbus.aio) while it waits: say so when the kind is loaded.
    plain = [h for h in _drive_base.COROUTINE_HOOKS if not inspect.iscoroutinefunction(getattr(cls, h))]
    if plain:
        raise _core.InvalidArgument(f"drive kind {kind!r} ({cls.__qualname__}): {', '.join(plain)} must be "
                                    "coroutine functions (async def, exchanges awaited on self.io: docs/plugins.md)")
    return cls


def drive_plugins() -> "dict[str, type[Drive]]":
    """Every registered drive kind's Drive subclass, loaded (imports each vendor module)."""
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


def parse_drive_spec(spec: str) -> "tuple[type[Drive], list[str]]":
    """``"<kind>:01,02"`` -> (that kind's Drive subclass, ["01", "02"]); InvalidArgument naming the problem."""
    kind, sep, addrs = spec.partition(":")
    if not sep or not addrs:
        raise _core.InvalidArgument(f"drive spec {spec!r}: expected KIND:ADDR[,ADDR...], e.g. cia402:5")
    plugin = drive_plugin(kind)
    addresses = [plugin.check_address(a.strip()) for a in addrs.split(",")]
    if len(set(addresses)) != len(addresses):
        raise _core.InvalidArgument(f"drive spec {spec!r}: addresses must be distinct")
    return plugin, addresses

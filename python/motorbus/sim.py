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

In-process, :func:`serve_line` and :class:`SimBench` give the same simulators;
``make_sim(kind, address, ...)`` gives one drive's simulator without serving it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional, Sequence

from . import _core, registry
from .bus_server import BusServers

__all__ = ["ServedLine", "SimBench", "make_sim", "serve_line", "serve_lines"]


def make_sim(kind: str, address: str, clock: Any = None, store_dir: Optional[str] = None, **options: Any) -> Any:
    """One simulated drive of a registered kind (not served)."""
    plugin = registry.drive_plugin(kind)
    address = plugin.check_address(str(address))
    if store_dir is not None and plugin.store_options is not None:
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
    server = _core.PtyLineServer(devices=drives, baud=baud)
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

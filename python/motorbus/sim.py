"""Serving simulated drives to other processes.

A *line* is one serial line (a pty) carrying one or more drives of one kind,
as an RS-485 multi-drop bus does: every drive sees every request and only the
addressed one answers.  Line specs::

    arcus:01          one Arcus DMX-CAN at address 01
    arcus:01,02,03    three DMX-CANs sharing one RS-485 line
    dmac:00           one Midi DMAC at address 00

``motorbus sim serve --pty --drive arcus:01 --drive dmac:00`` prints one line
per serial line, ``<spec> <pty path>``, then serves until SIGINT/SIGTERM.
"""
from __future__ import annotations

import importlib
import os
from dataclasses import dataclass, field
from typing import Any, Optional

from . import _core

# kind -> module providing make_sim(address, clock=None, **options) -> LineDevice
DRIVE_KINDS = {
    "arcus": "motorbus.drives.arcus",
    "dmac": "motorbus.drives.dmac",
}


def parse_line_spec(spec: str) -> tuple[str, list[str]]:
    """'arcus:01,02' -> ('arcus', ['01', '02']); InvalidArgument naming the problem."""
    kind, sep, addrs = spec.partition(":")
    if not sep or not addrs:
        raise _core.InvalidArgument(f"drive spec {spec!r}: expected KIND:ADDR[,ADDR...], e.g. arcus:01")
    if kind not in DRIVE_KINDS:
        raise _core.InvalidArgument(f"drive spec {spec!r}: unknown kind {kind!r} ({', '.join(DRIVE_KINDS)})")
    addresses = [a.strip() for a in addrs.split(",")]
    if any(not a for a in addresses) or len(set(addresses)) != len(addresses):
        raise _core.InvalidArgument(f"drive spec {spec!r}: addresses must be non-empty and distinct")
    return kind, addresses


def make_drive(kind: str, address: str, clock: Any = None, store_dir: Optional[str] = None,
               **options: Any) -> Any:
    """Builds one simulated drive (a LineDevice)."""
    mod = importlib.import_module(DRIVE_KINDS[kind])
    if store_dir is not None and kind == "arcus":
        options["store_path"] = os.path.join(store_dir, f"{kind}-{address}.store")
    return mod.make_sim(address, clock=clock, **options)


@dataclass
class ServedLine:
    """A serial line on a pty with its simulated drives."""

    label: str
    server: Any
    drives: list[Any] = field(default_factory=list)

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
               **options: Any) -> ServedLine:
    """Starts one line (see the module doc for the spec) on a new pty."""
    kind, addresses = parse_line_spec(spec)
    drives = [make_drive(kind, a, clock=clock, store_dir=store_dir, **options) for a in addresses]
    server = _core.PtyLineServer(devices=drives, baud=baud)
    return ServedLine(label=spec, server=server, drives=drives)


def serve_lines(specs: list[str], baud: int = 0, clock: Any = None,
                store_dir: Optional[str] = None) -> list[ServedLine]:
    lines: list[ServedLine] = []
    try:
        for spec in specs:
            lines.append(serve_line(spec, baud=baud, clock=clock, store_dir=store_dir))
    except Exception:
        for line in lines:
            line.close()
        raise
    return lines

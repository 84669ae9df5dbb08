"""The protocol trace of the command line (``motorbus --trace ...``): every CAN frame on
the bench's buses and every line exchanged on its serial lines, as DEBUG records of the
``motorbus.trace`` logger (``motorbus -v`` / ``--trace`` send them to stderr).

* CAN: a second endpoint on each bus spec (socketcand, socketcan, virtual) hears every
  frame on the bus: this program's requests, the drives' answers, other programs'
  traffic.  An SLCAN adapter cannot be opened twice: there only the frames this program
  receives are traced (its own requests are not), and the trace says so.
* Serial: ``LineLink.set_trace`` reports each request written (``>``), each reply line
  read (``<``) and each request left without a reply (``!``).

The trace starts before the axes are opened, so it shows what opening a drive sends.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

from . import _core

log = logging.getLogger("motorbus.trace")

_enabled = False

#: CANopen function codes (COB-ID & 0x780), for a readable label after each frame.
_CANOPEN = {0x000: "NMT", 0x080: "SYNC/EMCY", 0x100: "TIME", 0x180: "TPDO1", 0x200: "RPDO1", 0x280: "TPDO2",
            0x300: "RPDO2", 0x380: "TPDO3", 0x400: "RPDO3", 0x480: "TPDO4", 0x500: "RPDO4",
            0x580: "SDO answer", 0x600: "SDO request", 0x700: "heartbeat"}

# Schemes where a second endpoint sees every frame of the bus (the first one's too).
_SHAREABLE = ("socketcand", "socketcan", "virtual")


def enable(on: bool = True) -> None:
    """Turns the trace on for benches opened from now on (the CLI's ``--trace``)."""
    global _enabled
    _enabled = on


def enabled() -> bool:
    return _enabled


def frame_text(frame: Any) -> str:
    """``605#40416000  (SDO request, node 5)``: candump notation and, for a standard
    identifier, what the CANopen predefined connection set calls it."""
    text = str(frame)
    if not frame.extended:
        fc, node = frame.id & 0x780, frame.id & 0x7F
        name = _CANOPEN.get(fc)
        if name is not None and (node or fc in (0x000, 0x080, 0x100)):
            if fc == 0x080 and node:
                name = "EMCY"
            elif fc == 0x080:
                name = "SYNC"
            text += f"  ({name}{f', node {node}' if node else ''})"
    return text


def _printable(data: bytes) -> str:
    return data.decode("ascii", "backslashreplace").replace("\r", "\\r").replace("\n", "\\n")


class Tracer:
    """Traces the transports of one bench until ``close()``."""

    def __init__(self) -> None:
        self._undo: list[Callable[[], None]] = []

    def watch_spec(self, name: str, spec: str) -> bool:
        """Listens to bus ``spec`` on an endpoint of its own; False when its scheme cannot
        be opened twice (``watch_bus`` then)."""
        from .bus import open_bus

        scheme = spec.partition(":")[0]
        if scheme not in _SHAREABLE:
            return False
        try:
            listener = open_bus(spec)
        except _core.MotorbusError as e:   # the bench's own open of the spec reports it
            log.debug("%s: not traced: %s", name, e)
            return False
        listener.subscribe(lambda f: log.debug("%s %s", name, frame_text(f)))
        self._undo.append(listener.close)
        log.debug("%s: tracing every frame on %s", name, spec)
        return True

    def watch_bus(self, name: str, bus: Any) -> None:
        """The frames ``bus`` receives (not the ones this program sends on it)."""
        handle = bus.subscribe(lambda f: log.debug("%s %s", name, frame_text(f)))
        self._undo.append(lambda: bus.unsubscribe(handle))
        log.debug("%s: tracing received frames only (this adapter cannot be opened twice)", name)

    def watch_line(self, name: str, link: Any) -> None:
        def on_line(direction: str, data: Any) -> None:
            log.debug("%s %s %s", name, direction, _printable(bytes(data)))

        link.set_trace(on_line)
        self._undo.append(lambda: link.set_trace(None))

    def close(self) -> None:
        undo, self._undo = self._undo, []
        for step in reversed(undo):
            try:
                step()
            except Exception:  # noqa: BLE001 - a closed link has nothing left to untrace
                pass


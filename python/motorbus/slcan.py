"""SLCAN (Lawicel ASCII over a serial line: CANable, USBtin, CANUSB...).

* ``open_slcan(path, bitrate=500000, ...)`` -> :class:`SlcanBus`, a motorbus Bus
  through an adapter (also reachable as ``open_bus("slcan:/dev/ttyACM0@500000")``).
* ``SlcanServer(bus)`` serves any motorbus Bus as an SLCAN adapter on a new pty;
  python-can's ``slcan`` interface (or slcand) joins it through ``.pty_path``.
* ``slcan_encode`` / ``SlcanDecoder``: the pure codec, for tests and tools.

See docs/slcan.md.
"""
from __future__ import annotations

from . import _core, registry
from ._core.can import (
    SlcanBus, SlcanDecoder, SlcanDecoderCounters, SlcanEvent, SlcanEventKind, SlcanServer, SlcanServerStats,
    SlcanStats, open_slcan, slcan_encode,
)

__all__ = ["SlcanBus", "SlcanDecoder", "SlcanDecoderCounters", "SlcanEvent", "SlcanEventKind", "SlcanServer",
           "SlcanServerStats", "SlcanStats", "open_slcan", "slcan_encode",
           "STATUS_FLAGS", "SCHEME"]

#: Bits of the ``F`` status reply (Lawicel CAN232/CANUSB manual, SJA1000 based).
STATUS_FLAGS = {
    "rx_fifo_full": 0x01,
    "tx_fifo_full": 0x02,
    "error_warning": 0x04,
    "data_overrun": 0x08,
    "error_passive": 0x20,
    "arbitration_lost": 0x40,
    "bus_error": 0x80,
}


def _parse(rest: str) -> dict:
    """``PATH[@BITRATE]``."""
    path, at, rate = rest.rpartition("@") if "@" in rest else (rest, "", "")
    args: dict = {"path": path}
    if at:
        try:
            args["bitrate"] = int(rate)
        except ValueError:
            raise _core.InvalidArgument(f"bitrate {rate!r} is not an integer") from None
    return args


#: ``slcan:PATH[@BITRATE]`` for open_bus.
SCHEME = registry.BusScheme("slcan", "Lawicel adapter on a serial line (CANable, USBtin, a pty)",
                            parse=_parse, open=open_slcan, example="slcan:/dev/ttyACM0@500000")

"""Midi Ingénierie DMAC17/23/34 over its ASCII protocol: client, simulator, helpers.

Example — a simulated module on a pty, driven through the typed client::

    from motorbus._core import SimClock
    from motorbus.serial import PtyLineServer
    from motorbus.drives.dmac import DmacClient, make_sim, open_link

    clock = SimClock()
    with PtyLineServer([make_sim("00", clock=clock)]) as server:
        link = open_link(server.slave_path)
        with DmacClient(link, address=0) as axis:   # STOP on error and at exit
            axis.move_to(200000)                    # 20 turns, 1/10000 rev units
            clock.advance(5_000_000_000)            # 5 s of device time
            assert axis.position == 200000

Units are the module's: positions in 1/10000 rev, speeds in 0.01 rpm, times in ms.
Requests end with CR, replies with CR LF (``LINE_SETTINGS``; the manual does not
say, see docs/drives/dmac.md).
"""
from __future__ import annotations

from typing import Any, Iterable, Optional, Sequence

from .. import _core, _stop_at_exit

DmacSim = _core.DmacSim
DmacStatus = _core.DmacStatus
DmacErrorWord = _core.DmacErrorWord
UnknownCommand = _core.DmacUnknownCommand
CommandRejected = _core.DmacCommandRejected
format_value = _core.dmac_format_value
parse_read_reply = _core.dmac_parse_read_reply
status_names = _core.dmac_status_names
error_names = _core.dmac_error_names
variable_info = _core.dmac_variable

#: Line settings of a DMAC bus (what ``motorbus sim serve --drive dmac:NN`` uses).
LINE_SETTINGS = {"request_terminator": b"\r", "reply_terminators": [b"\r\n"], "max_line": 256}
#: The single byte a full interpolation FIFO answers to MOVE_INTERPOL.
XON_ERROR = b"\x17"
#: Baud rates SET_BAUDRATE accepts; 38400 is the factory default.
BAUDRATES = (9600, 19200, 38400, 115200)

__all__ = [
    "BAUDRATES",
    "CommandRejected",
    "DmacClient",
    "DmacErrorWord",
    "DmacSim",
    "DmacStatus",
    "LINE_SETTINGS",
    "UnknownCommand",
    "XON_ERROR",
    "error_names",
    "format_value",
    "make_sim",
    "open_link",
    "parse_read_reply",
    "status_names",
    "stream_interpolation",
    "synchro",
    "variable_info",
]



class DmacClient(_stop_at_exit.StopsMotor, _core.DmacClient):
    """Typed DMAC commands for the module at ``address`` on a ``LineLink``.

    ``DmacClient(link, address=0, verify=True, timeout=None, sleep=None)``

    * ``verify``: each command frame ends with ``READ #ERROR`` so a rejected
      command raises at once (``UnknownCommand`` for bit 12, ``CommandRejected``
      for bits 7/8).
    * ``timeout``: seconds per transaction (None = the link's reply timeout).
    * ``sleep``: how the client waits when polling or backing off (seconds);
      pass ``lambda s: clock.advance(int(s * 1e9))`` to run on a SimClock.

    As a context manager it sends STOP when an exception leaves the block; every
    client that is still open at interpreter exit is stopped too.
    """

    def __init__(self, link: Any, address: int = 0, verify: bool = True,
                 timeout: Optional[float] = None, sleep: Any = None) -> None:
        super().__init__(link, address=address, verify=verify, timeout=timeout, sleep=sleep)
        self._open = True
        _stop_at_exit.track(self)

    def _stop_on_error(self) -> None:
        self._emergency_stop()

    def close(self) -> None:
        """Forget this client for the exit-time STOP (the link stays open)."""
        self._open = False
        _stop_at_exit.untrack(self)

    def _stop_at_exit(self) -> None:
        self._emergency_stop()

    def _emergency_stop(self) -> None:
        if not getattr(self, "_open", False):
            return
        try:
            # STOP plus a READ, so we know the module took it before we go on;
            # no error checking that could itself raise.
            self.raw(f"{self.address:02d}STOP, READ #STATUS", expect_reply=True)
        except Exception:  # the link may already be gone; nothing more to do
            pass

    def __repr__(self) -> str:
        return f"DmacClient(address={self.address:02d})"


def open_link(port: Any, baud: int = 38400, timeout: float = 0.5) -> Any:
    """A ``LineLink`` with the DMAC line settings on a path or an open Port."""
    from ..serial import LineLink, open_port

    if isinstance(port, str):
        port = open_port(port, baud)
    return LineLink(port, request_terminator=LINE_SETTINGS["request_terminator"],
                    reply_terminators=LINE_SETTINGS["reply_terminators"],
                    max_line=LINE_SETTINGS["max_line"], reply_timeout=timeout)


def _parse_address(address: Any) -> int:
    try:
        a = int(address)
    except (TypeError, ValueError):
        raise _core.InvalidArgument(f"DMAC address: {address!r} is not a number 00..63") from None
    if not 0 <= a <= 63:
        raise _core.InvalidArgument(f"DMAC address: {a} is outside 00..63")
    return a


def make_sim(address: Any = "00", clock: Any = None, **options: Any) -> DmacSim:
    """Factory for ``motorbus sim serve --pty --drive dmac:00``.

    ``address`` is "00".."63" (or an int).  Options: ``model`` ("DMAC17",
    "DMAC23-1", "DMAC23-2", "DMAC34-1", "DMAC34-2"), ``supply_voltage`` (mV),
    ``baudrate``, ``request_terminator`` / ``reply_terminator`` (bytes),
    ``positive_end_switch`` / ``negative_end_switch`` (position in 1/10000 rev
    where a mechanical end-stop switch on IN1/IN2 or IN9/IN10 closes) and
    ``end_switch_active_low``.
    ``clock`` is a motorbus Clock (SimClock for tests); None = real time.
    """
    allowed = {"model", "supply_voltage", "baudrate", "request_terminator", "reply_terminator",
               "positive_end_switch", "negative_end_switch", "end_switch_active_low"}
    unknown = set(options) - allowed
    if unknown:
        raise _core.InvalidArgument(f"make_sim: unknown option(s) {sorted(unknown)}; allowed: {sorted(allowed)}")
    for k in ("request_terminator", "reply_terminator"):
        if isinstance(options.get(k), str):
            options[k] = options[k].encode()
    if "supply_voltage" in options:
        options["supply_voltage"] = int(options["supply_voltage"])
    if "baudrate" in options:
        options["baudrate"] = int(options["baudrate"])
    return DmacSim(clock, address=_parse_address(address), **options)


def synchro(link: Any, what: str) -> None:
    """Global ``SYNCHRO ON|OFF|TOP|INTERPOL`` (no module answers it)."""
    _core.dmac_synchro(link, what)


def stream_interpolation(axes: Sequence[DmacClient], segments: Iterable[Sequence[int]],
                         interpol_time_ms: int = 100, fifo_size: int = 64, sleep: Any = None,
                         backoff: Optional[float] = None) -> dict:
    """Stream ``segments[k][axis]`` (MOVE_INTERPOL offsets) to every axis.

    Pre-fills each FIFO, starts all axes with the global SYNCHRO INTERPOL, then
    keeps every FIFO fed, backing off on XON_ERROR.  Returns counters
    (``xon_errors``, ``underruns``, ``min_level_after_start``...).
    """
    return _core.dmac_stream_interpolation(list(axes), [list(map(int, s)) for s in segments],
                                           interpol_time_ms, fifo_size, sleep, backoff)

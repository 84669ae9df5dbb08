"""Opening buses: ``open_bus(spec, **options)`` and the python-can bridge.

Specs are URL-like strings, one scheme per registered backend (entry-point group
``motorbus.bus``, see docs/plugins.md); the ones motorbus brings::

    virtual:NAME                    in-process hub (bitrate=, tx_queue=, receive_own=, rx_spin=)
    slcan:PATH[@BITRATE]            Lawicel adapter on a serial line (CANable, USBtin, a pty)
    socketcand:HOST:PORT/CHANNEL    socketcand server over TCP
    socketcan:IFACE                 Linux AF_CAN raw socket (can0, vcan0)

or a python-can ``can.BusABC`` instance, which is wrapped so every motorbus
client (SDO, drives, recorder) runs on it.
"""
from __future__ import annotations

import threading
import time
from typing import Any

from . import _core, registry

__all__ = ["open_bus", "parse_spec", "frame_to_message", "message_to_frame", "wall_time"]

# Offset from the monotonic clock of frame timestamps to the epoch, fixed once
# so converted timestamps keep their spacing.
_EPOCH_OFFSET = time.time() - time.monotonic_ns() / 1e9


def wall_time(timestamp_ns: int) -> float:
    """Epoch seconds for a Frame.timestamp_ns (python-can's timestamp convention)."""
    return timestamp_ns / 1e9 + _EPOCH_OFFSET


def parse_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """Split a bus spec into (scheme, arguments) through the registered scheme.

    InvalidArgument names the problem (an unknown scheme lists the registered ones)."""
    scheme, sep, rest = spec.partition(":")
    if not sep or not rest:
        raise _core.InvalidArgument(f"bus spec {spec!r}: expected SCHEME:ARGS, e.g. virtual:bench")
    try:
        return scheme, registry.bus_scheme(scheme).parse(rest)
    except _core.InvalidArgument as e:
        raise _core.InvalidArgument(f"bus spec {spec!r}: {e}") from None


def open_bus(spec: Any, **options: Any) -> _core.can.Bus:
    """Open a bus from a spec string or wrap a python-can bus. See the module doc."""
    if not isinstance(spec, str):
        return _bridge(spec, **options)
    scheme, args = parse_spec(spec)
    return registry.bus_scheme(scheme).open(**args, **options)


def _parse_virtual(rest: str) -> dict[str, Any]:
    return {"name": rest}


#: ``virtual:NAME``: every bus opened with one NAME in this process is one CAN bus.
VIRTUAL = registry.BusScheme("virtual", "in-process hub: wire time at a bit rate, arbitration, fault injection",
                             parse=_parse_virtual, open=_core.can.open_virtual, example="virtual:bench")


# ---------------------------------------------------------------------------
# python-can -> motorbus

def message_to_frame(msg: Any) -> _core.can.Frame:
    """python-can Message -> Frame (validated)."""
    if msg.is_remote_frame:
        return _core.can.Frame(msg.arbitration_id, b"", extended=msg.is_extended_id, rtr=True, dlc=msg.dlc)
    return _core.can.Frame(msg.arbitration_id, bytes(msg.data), extended=msg.is_extended_id)


def frame_to_message(frame: _core.can.Frame, channel: Any = None) -> Any:
    """Frame -> python-can Message (timestamp in epoch seconds, as python-can uses)."""
    import can

    return can.Message(
        timestamp=wall_time(frame.timestamp_ns) if frame.timestamp_ns else time.time(),
        arbitration_id=frame.id,
        is_extended_id=frame.extended,
        is_remote_frame=frame.rtr,
        is_error_frame=frame.is_error,
        dlc=frame.dlc,
        data=None if frame.rtr else frame.data,
        channel=channel,
        is_rx=not frame.is_loopback,
    )


class _Bridge:
    """Owns the reader thread that moves frames from a python-can bus into an ExternalBus."""

    def __init__(self, pcbus: Any, poll: float, receive_own: bool) -> None:
        self._pc = pcbus
        self._poll = poll
        self._stop = threading.Event()
        self.bus = _core.can.ExternalBus(
            channel=f"python-can:{getattr(pcbus, 'channel_info', type(pcbus).__name__)}",
            send=self._send,
            close=self._close,
            receive_own=receive_own,
        )
        self._thread = threading.Thread(target=self._reader, name="motorbus-python-can-bridge", daemon=True)
        self._thread.start()

    def _send(self, frame: _core.can.Frame, timeout: float) -> None:
        import can

        try:
            self._pc.send(frame_to_message(frame), timeout=timeout)
        except can.CanOperationError as e:
            raise _core.TimeoutError(f"python-can bus did not accept the frame: {e}") from e

    def _reader(self) -> None:
        while not self._stop.is_set():
            try:
                msg = self._pc.recv(self._poll)
            except Exception:  # a foreign bus that fails to parse must not end the bridge
                self.bus.feed_parse_error()
                continue
            if msg is None or msg.is_error_frame:
                continue
            try:
                frame = message_to_frame(msg)
            except _core.InvalidArgument:
                self.bus.feed_parse_error()
                continue
            frame.timestamp_ns = _core.runtime.monotonic_ns()
            self.bus.feed(frame)

    def _close(self) -> None:
        self._stop.set()
        if threading.current_thread() is not self._thread:
            self._thread.join()


def _bridge(pcbus: Any, poll: float = 0.01, receive_own: bool = False) -> _core.can.Bus:
    import can

    if not isinstance(pcbus, can.BusABC):
        raise _core.InvalidArgument(
            f"open_bus: expected a spec string or a can.BusABC, got {type(pcbus).__name__}")
    return _Bridge(pcbus, poll, receive_own).bus

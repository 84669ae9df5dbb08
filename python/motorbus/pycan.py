"""motorbus as a python-can interface (entry point ``can.interface: motorbus``).

    bus = can.Bus(interface="motorbus", channel="virtual:bench")

lets python-can and canopen code run on any motorbus bus spec.
"""
from __future__ import annotations

from typing import Any, Optional

import can

from . import _core
from .bus import frame_to_message, message_to_frame, open_bus


class MotorbusCanBus(can.BusABC):
    """A python-can bus backed by a motorbus bus (``channel`` is a motorbus spec)."""

    def __init__(self, channel: str, can_filters: Any = None, receive_own_messages: bool = False,
                 **kwargs: Any) -> None:
        if not isinstance(channel, str):
            raise can.CanInitializationError("motorbus: channel must be a bus spec such as 'virtual:x'")
        options = {k: v for k, v in kwargs.items() if k in ("bitrate", "tx_queue", "rx_queue_size", "rx_spin")}
        try:
            self._bus = open_bus(channel, receive_own=receive_own_messages, **options)
        except (_core.MotorbusError, TypeError) as e:
            raise can.CanInitializationError(f"motorbus: cannot open {channel!r}: {e}") from e
        self.channel_info = f"motorbus {channel}"
        self._channel = channel
        super().__init__(channel=channel, can_filters=can_filters, **kwargs)

    def _apply_filters(self, filters: Optional[can.typechecking.CanFilters]) -> None:
        self._bus.set_filters(list(filters) if filters else None)
        self._is_filtered = bool(filters)

    def _recv_internal(self, timeout: Optional[float]) -> tuple[Optional[can.Message], bool]:
        frame = self._bus.recv(timeout)
        if frame is None:
            return None, self._is_filtered
        return frame_to_message(frame, channel=self._channel), self._is_filtered

    def send(self, msg: can.Message, timeout: Optional[float] = None) -> None:
        try:
            self._bus.send(message_to_frame(msg), timeout if timeout is not None else 1.0)
        except _core.TimeoutError as e:
            raise can.CanOperationError(str(e)) from e
        except _core.InvalidArgument as e:
            raise can.CanOperationError(str(e)) from e

    def shutdown(self) -> None:
        super().shutdown()
        self._bus.close()

    @property
    def motorbus_bus(self) -> _core.Bus:
        """The underlying motorbus bus (counters, subscribe, ...)."""
        return self._bus

"""motorbus as a python-can interface (entry point ``can.interface: motorbus``).

    bus = can.Bus(interface="motorbus", channel="virtual:bench")

lets python-can and canopen code run on any motorbus bus spec.

The bus behaves like python-can's own interfaces (``can/interfaces/virtual.py`` is
the reference), so python-can's ``Notifier`` and canopen's ``Network`` work on it:

* every error leaving this class is a ``can.CanError``: opening fails with
  ``CanInitializationError``, a failed ``send``/``recv``/``set_filters`` raises
  ``CanOperationError`` (the motorbus error is chained as ``__cause__``);
* a ``recv()`` in flight when the bus is shut down returns ``None``; ``recv()`` or
  ``send()`` after ``shutdown()`` raise ``CanOperationError``; ``shutdown()`` twice is fine;
* classic CAN only: ``fd=True`` (or a ``can.BitTimingFd``) is refused with
  ``can.CanInterfaceNotImplementedError``, sending an FD message with ``CanOperationError``;
* a bus still open when the interpreter exits is shut down by an ``atexit`` hook, which
  waits for the receives in flight (a Notifier's daemon thread) to come back from the
  C++ core: a thread still waiting in C++ when the interpreter finalizes aborts the process.
  From then on ``recv()`` on it waits in Python and returns None, as python-can's virtual bus does.
"""
from __future__ import annotations

import atexit
import threading
import time
import weakref
from typing import Any, Optional

import can

from . import _core
from .bus import frame_to_message, message_to_frame, open_bus

#: keyword arguments passed on to motorbus; any other (python-can's generic ones such
#: as ``single_handle``, or another interface's) is ignored, as python-can interfaces do.
_MOTORBUS_OPTIONS = ("bitrate", "tx_queue", "rx_queue_size", "rx_spin")


_live: "weakref.WeakSet[MotorbusCanBus]" = weakref.WeakSet()
_live_lock = threading.Lock()
_exiting = threading.Event()


def _shutdown_all_at_exit(wait: float = 2.0) -> None:
    """atexit: shut down every bus still open and wait (GIL released) until no thread
    is inside the C++ recv any more."""
    _exiting.set()
    with _live_lock:
        buses = list(_live)
    for bus in buses:
        try:
            bus.shutdown()
        except Exception:  # noqa: BLE001 - best effort: one bus must not keep the others open
            pass
    deadline = time.monotonic() + wait
    while any(b._receivers for b in buses) and time.monotonic() < deadline:
        time.sleep(0.001)


atexit.register(_shutdown_all_at_exit)


class _ShutDownWhileReceiving(can.CanOperationError):
    """Raised by _recv_internal when shutdown() closed the bus under a waiting receive;
    recv() turns it into None (python-can's behaviour for a receive that gets nothing)."""


class MotorbusCanBus(can.BusABC):
    """A python-can bus backed by a motorbus bus (``channel`` is a motorbus spec)."""

    def __init__(self, channel: str, can_filters: Any = None, receive_own_messages: bool = False,
                 fd: bool = False, **kwargs: Any) -> None:
        self._shutting_down = threading.Event()
        self._receivers = 0  # threads inside the C++ recv (see _shutdown_all_at_exit)
        self._receivers_lock = threading.Lock()
        if fd or isinstance(kwargs.get("timing"), can.BitTimingFd):
            raise can.CanInterfaceNotImplementedError(
                f"CAN FD is not supported by {type(self).__name__} (motorbus buses are classic CAN)")
        if not isinstance(channel, str):
            raise can.CanInitializationError("motorbus: channel must be a bus spec such as 'virtual:x'")
        options = {k: kwargs[k] for k in _MOTORBUS_OPTIONS if k in kwargs}
        try:
            self._bus = open_bus(channel, receive_own=receive_own_messages, **options)
        except (_core.MotorbusError, TypeError, ValueError, OSError) as e:
            raise can.CanInitializationError(f"motorbus: cannot open {channel!r}: {e}") from e
        self.channel_info = f"motorbus {channel}"
        self._channel = channel
        self._is_filtered = False
        try:
            super().__init__(channel=channel, can_filters=can_filters, **kwargs)
        except BaseException:
            self._bus.close()
            raise
        with _live_lock:
            _live.add(self)

    def _check_open(self) -> None:
        if self._shutting_down.is_set():
            raise can.CanOperationError(f"motorbus {self._channel}: cannot operate on a closed bus")

    def _apply_filters(self, filters: Optional[can.typechecking.CanFilters]) -> None:
        self._check_open()
        try:
            self._bus.set_filters(list(filters) if filters else None)
        except _core.MotorbusError as e:
            raise can.CanOperationError(f"motorbus {self._channel}: set_filters: {e}") from e
        self._is_filtered = bool(filters)

    def recv(self, timeout: Optional[float] = None) -> Optional[can.Message]:
        try:
            return super().recv(timeout)
        except _ShutDownWhileReceiving:
            return None

    def _recv_internal(self, timeout: Optional[float]) -> tuple[Optional[can.Message], bool]:
        if _exiting.is_set():  # interpreter exit: nothing arrives any more; never enter C++ again
            threading.Event().wait(timeout)
            return None, False
        self._check_open()
        with self._receivers_lock:
            self._receivers += 1
        try:
            frame = self._bus.recv(timeout)
        except _core.ClosedError as e:
            if self._shutting_down.is_set():
                raise _ShutDownWhileReceiving(f"motorbus {self._channel}: shut down while receiving") from e
            raise can.CanOperationError(f"motorbus {self._channel}: {e}") from e
        except _core.MotorbusError as e:
            raise can.CanOperationError(f"motorbus {self._channel}: {e}") from e
        finally:
            with self._receivers_lock:
                self._receivers -= 1
        if frame is None:
            return None, self._is_filtered
        return frame_to_message(frame, channel=self._channel), self._is_filtered

    def send(self, msg: can.Message, timeout: Optional[float] = None) -> None:
        """Send ``msg``; ``timeout=None`` waits at most 1 s (motorbus's send default) for the
        medium, then raises ``CanOperationError`` (back-pressure, never a silent drop)."""
        self._check_open()
        if msg.is_fd:
            raise can.CanOperationError(
                f"motorbus {self._channel}: cannot send a CAN FD message, motorbus buses are classic CAN")
        try:
            frame = message_to_frame(msg)
            self._bus.send(frame, timeout if timeout is not None else 1.0)
        except _core.MotorbusError as e:  # TimeoutError, InvalidArgument, LinkDown, ClosedError, ...
            raise can.CanOperationError(f"motorbus {self._channel}: {e}") from e
        except (TypeError, ValueError, OverflowError) as e:  # a Message field that is no CAN frame
            raise can.CanOperationError(f"motorbus {self._channel}: invalid message: {e}") from e

    def shutdown(self) -> None:
        if self._shutting_down.is_set():
            return
        self._shutting_down.set()  # before close(): a receive woken by close() returns None
        try:
            super().shutdown()  # stops periodic tasks (they may still be sending: they get CanOperationError)
        finally:
            self._bus.close()
            with _live_lock:
                _live.discard(self)

    @property
    def state(self) -> can.BusState:
        """python-can's view of the motorbus state: error-passive -> PASSIVE, bus-off/closed/link-down -> ERROR."""
        s = self._bus.state
        if s == "error-passive":
            return can.BusState.PASSIVE
        if s in ("bus-off", "closed", "link-down"):
            return can.BusState.ERROR
        return can.BusState.ACTIVE

    @state.setter
    def state(self, new_state: can.BusState) -> None:
        raise NotImplementedError("motorbus: the bus state cannot be set through python-can")

    @property
    def motorbus_bus(self) -> _core.can.Bus:
        """The underlying motorbus bus (counters, subscribe, ...)."""
        return self._bus

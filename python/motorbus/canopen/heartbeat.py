"""Heartbeat (CiA 301): consumer, producer, and the service of a served node.

    from motorbus.canopen import HeartbeatConsumer
    hb = HeartbeatConsumer(bus)
    hb.on_event = lambda node, event, state: print(node, event, state)
    hb.monitor(5, timeout=0.3)          # "lost" after 300 ms of silence
    hb.start()                          # timers on a C++ thread
    hb.health(5)                        # NodeHealth(node=5, state='OPERATIONAL', alive=True, ...)

States are the strings INITIALISING, STOPPED, OPERATIONAL, PRE-OPERATIONAL and
UNKNOWN (nothing heard, or a byte outside that set: never treated as running).
"""
from __future__ import annotations

from typing import Callable, Optional

from .. import _core

__all__ = ["HeartbeatConsumer", "HeartbeatProducer", "HeartbeatService", "NodeHealth",
           "heartbeat_encode", "heartbeat_decode"]

from .._core.canopen import heartbeat_encode, heartbeat_decode, NodeHealth, HeartbeatProducer  # noqa: E402,F401
#: HeartbeatService(local_node, consumer_entries=4, producer_ms=0): 0x1017/0x1016 of a served
#: node; set_lost_callback(cb) for the loss-of-master reaction.
from .._core.canopen import HeartbeatService  # noqa: E402,F401


class HeartbeatConsumer:
    """Per-node heartbeat timeouts; events: started, lost, back, reset,
    state-changed, unknown-state."""

    def __init__(self, bus: _core.can.Bus, clock: Optional[_core.runtime.Clock] = None) -> None:
        self._c = _core.canopen.HeartbeatConsumer(bus, clock)
        self._cb = None

    def monitor(self, node: int, timeout: float) -> None:
        self._c.monitor(node, timeout)

    def forget(self, node: int) -> None:
        self._c.forget(node)

    def health(self, node: int) -> NodeHealth:
        return self._c.health(node)

    def process(self, now_ns: Optional[int] = None) -> int:
        """Check deadlines now (for simulated clocks); returns the next deadline or -1."""
        return self._c.process(now_ns)

    def start(self) -> None:
        self._c.start()

    def stop(self) -> None:
        self._c.stop()

    @property
    def on_event(self):
        return self._cb

    @on_event.setter
    def on_event(self, cb: Optional[Callable[[int, str, str], None]]) -> None:
        self._cb = cb
        self._c.set_callback(cb)

    @property
    def ignored_frames(self) -> int:
        return self._c.ignored_frames


class NodeHeartbeat:
    """``node.heartbeat``: the network's heartbeat consumer, for one node."""

    def __init__(self, consumer: "_core.canopen.HeartbeatConsumer", node_id: int) -> None:
        self._c = consumer
        self.node_id = node_id
        self._callbacks: list = []

    def monitor(self, timeout: float) -> None:
        """Report "lost" when no heartbeat arrives for ``timeout`` seconds."""
        self._c.monitor(self.node_id, timeout)

    def forget(self) -> None:
        self._c.forget(self.node_id)

    @property
    def health(self) -> NodeHealth:
        return self._c.health(self.node_id)

    def add_callback(self, callback: Callable[[str, str], None]) -> None:
        """callback(event, state) on the bus or timer thread; events: started, lost,
        back, reset, state-changed, unknown-state."""
        self._callbacks.append(callback)

    def _dispatch(self, event: str, state: str) -> None:
        for cb in list(self._callbacks):
            cb(event, state)

"""NMT master, heartbeat consumer/producer (CiA 301).

    from motorbus.canopen import NmtMaster, HeartbeatConsumer
    nmt = NmtMaster(bus)
    nmt.start(5)                        # or nmt.start() for every node
    nmt.wait_for_state(5, "OPERATIONAL", timeout=1.0)

    hb = HeartbeatConsumer(bus)
    hb.on_event = lambda node, event, state: print(node, event, state)
    hb.monitor(5, timeout=0.3)          # "lost" after 300 ms of silence
    hb.start()                          # timers on a C++ thread

States are the strings INITIALISING, STOPPED, OPERATIONAL, PRE-OPERATIONAL and
UNKNOWN (nothing heard, or a byte outside that set: never treated as running).
"""
from __future__ import annotations

import enum
from typing import Callable, Optional

from .. import _core

__all__ = ["NmtCommand", "NmtMaster", "HeartbeatConsumer", "HeartbeatProducer", "HeartbeatService",
           "NMT_STATES", "nmt_encode", "nmt_decode", "heartbeat_encode", "heartbeat_decode"]

NMT_STATES = ("INITIALISING", "STOPPED", "OPERATIONAL", "PRE-OPERATIONAL", "UNKNOWN")

nmt_encode = _core.nmt_encode
nmt_decode = _core.nmt_decode
heartbeat_encode = _core.heartbeat_encode
heartbeat_decode = _core.heartbeat_decode


class NmtCommand(enum.IntEnum):
    START = 0x01
    STOP = 0x02
    ENTER_PRE_OPERATIONAL = 0x80
    RESET_NODE = 0x81
    RESET_COMMUNICATION = 0x82


class NmtMaster:
    """Commands nodes (node 0 = all) and tracks their states from heartbeats."""

    def __init__(self, bus: _core.Bus, own_node_id: Optional[int] = None) -> None:
        self._m = _core.NmtMaster(bus, own_node_id)
        self._cb: Optional[Callable[[int, str, str], None]] = None

    def send(self, command: int, node: int = 0) -> None:
        self._m.send(int(command), node)

    def start(self, node: int = 0) -> None:
        self.send(NmtCommand.START, node)

    def stop(self, node: int = 0) -> None:
        self.send(NmtCommand.STOP, node)

    def enter_pre_operational(self, node: int = 0) -> None:
        self.send(NmtCommand.ENTER_PRE_OPERATIONAL, node)

    pre_operational = enter_pre_operational

    def reset_node(self, node: int = 0) -> None:
        self.send(NmtCommand.RESET_NODE, node)

    def reset_communication(self, node: int = 0) -> None:
        self.send(NmtCommand.RESET_COMMUNICATION, node)

    def state(self, node: int) -> str:
        return self._m.state(node)

    def raw_state(self, node: int) -> Optional[int]:
        return self._m.raw_state(node)

    def wait_for_state(self, node: int, state: str, timeout: float = 1.0) -> bool:
        return self._m.wait_for_state(node, state, timeout)

    def wait_for_boot(self, node: int, timeout: float = 1.0) -> bool:
        return self._m.wait_for_boot(node, timeout)

    @property
    def on_state_change(self) -> Optional[Callable[[int, str, str], None]]:
        """callback(node, old_state, new_state), called on the bus thread."""
        return self._cb

    @on_state_change.setter
    def on_state_change(self, cb: Optional[Callable[[int, str, str], None]]) -> None:
        self._cb = cb
        self._m.set_callback(cb)

    @property
    def foreign_commands_ignored(self) -> int:
        return self._m.foreign_commands_ignored


class HeartbeatConsumer:
    """Per-node heartbeat timeouts; events: started, lost, back, reset,
    state-changed, unknown-state."""

    def __init__(self, bus: _core.Bus, clock: Optional[_core.Clock] = None) -> None:
        self._c = _core.HeartbeatConsumer(bus, clock)
        self._cb = None

    def monitor(self, node: int, timeout: float) -> None:
        self._c.monitor(node, timeout)

    def forget(self, node: int) -> None:
        self._c.forget(node)

    def health(self, node: int) -> dict:
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


HeartbeatProducer = _core.HeartbeatProducer

#: HeartbeatService(local_node, consumer_entries=4, producer_ms=0): 0x1017/0x1016 of a served
#: node; set_lost_callback(cb) for the loss-of-master reaction.
HeartbeatService = _core.HeartbeatService

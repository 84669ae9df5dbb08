"""EMCY consumer and producer (CiA 301).

    from motorbus.canopen import EmcyConsumer
    emcy = EmcyConsumer(bus, history=32)
    emcy.on_emcy = lambda e: print(e.node, hex(e.code), e.text)
    err = emcy.wait(node=5, timeout=1.0)      # EmcyError or None
    emcy.active(5)                            # codes not yet reset by EEC 0x0000
"""
from __future__ import annotations

from typing import Callable, List, Optional

from .. import _core

__all__ = ["EmcyError", "EmcyConsumer", "EmcyProducer", "emcy_encode", "emcy_decode", "emcy_code_text"]

#: One received message: node, code, register, data, short, timestamp_ns, text, is_reset.
from .._core.canopen import EmcyError, EmcyProducer, emcy_encode, emcy_decode, emcy_code_text  # noqa: E402,F401


class EmcyConsumer:
    def __init__(self, bus: _core.can.Bus, history: int = 32) -> None:
        self._c = _core.canopen.EmcyConsumer(bus, history)
        self._cb = None

    def history(self, node: int) -> List[EmcyError]:
        return self._c.history(node)

    def active(self, node: int) -> List[int]:
        return list(self._c.active(node))

    def clear(self, node: int) -> None:
        self._c.clear(node)

    def wait(self, node: int = 0, timeout: float = 1.0) -> Optional[EmcyError]:
        return self._c.wait(node, timeout)

    @property
    def on_emcy(self):
        return self._cb

    @on_emcy.setter
    def on_emcy(self, cb: Optional[Callable[[EmcyError], None]]) -> None:
        self._cb = cb
        self._c.set_callback(cb)

    @property
    def received(self) -> int:
        return self._c.received

    @property
    def ignored_frames(self) -> int:
        return self._c.ignored_frames


class NodeEmcy:
    """``node.emcy``: the network's EMCY consumer, for one node (names as in the
    `canopen` package: ``active``, ``log``, ``wait``, ``add_callback``, ``reset``)."""

    def __init__(self, consumer: "_core.canopen.EmcyConsumer", node_id: int) -> None:
        self._c = consumer
        self.node_id = node_id
        self._callbacks: list = []

    @property
    def active(self) -> List[int]:
        """Error codes raised and not yet cleared by EEC 0x0000."""
        return list(self._c.active(self.node_id))

    @property
    def log(self) -> List[EmcyError]:
        """Messages received, oldest first (bounded by the network's history)."""
        return self._c.history(self.node_id)

    def wait(self, timeout: float = 10.0) -> Optional[EmcyError]:
        """The next message not handed out yet (oldest first), or None on timeout."""
        return self._c.wait(self.node_id, timeout)

    def add_callback(self, callback: Callable[[EmcyError], None]) -> None:
        """callback(EmcyError) on the bus thread."""
        self._callbacks.append(callback)

    def reset(self) -> None:
        """Forget this node's history and active codes."""
        self._c.clear(self.node_id)

    def _dispatch(self, e: EmcyError) -> None:
        for cb in list(self._callbacks):
            cb(e)

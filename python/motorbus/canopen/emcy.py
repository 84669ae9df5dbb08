"""EMCY consumer and producer (CiA 301).

    from motorbus.canopen import EmcyConsumer
    emcy = EmcyConsumer(bus, history=32)
    emcy.on_emcy = lambda e: print(e.node, hex(e.code), e.text)
    err = emcy.wait(node=5, timeout=1.0)      # EmcyError or None
    emcy.active(5)                            # codes not yet reset by EEC 0x0000
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, List, Optional

from .. import _core

__all__ = ["EmcyError", "EmcyConsumer", "EmcyProducer", "emcy_encode", "emcy_decode", "emcy_code_text"]

emcy_encode = _core.emcy_encode
emcy_code_text = _core.emcy_code_text


@dataclass(frozen=True)
class EmcyError:
    node: int
    code: int
    register: int
    data: bytes
    short: bool          # the frame had fewer than 8 bytes (missing ones read as 0)
    timestamp_ns: int
    text: str

    @classmethod
    def _from(cls, d: dict) -> "EmcyError":
        return cls(d["node"], d["code"], d["register"], d["data"], d["short"], d["timestamp_ns"], d["text"])

    @property
    def is_reset(self) -> bool:
        return self.code == 0


def emcy_decode(frame: _core.Frame) -> Optional[EmcyError]:
    d = _core.emcy_decode(frame)
    return None if d is None else EmcyError._from(d)


class EmcyConsumer:
    def __init__(self, bus: _core.Bus, history: int = 32) -> None:
        self._c = _core.EmcyConsumer(bus, history)
        self._cb = None

    def history(self, node: int) -> List[EmcyError]:
        return [EmcyError._from(d) for d in self._c.history(node)]

    def active(self, node: int) -> List[int]:
        return list(self._c.active(node))

    def clear(self, node: int) -> None:
        self._c.clear(node)

    def wait(self, node: int = 0, timeout: float = 1.0) -> Optional[EmcyError]:
        d = self._c.wait(node, timeout)
        return None if d is None else EmcyError._from(d)

    @property
    def on_emcy(self):
        return self._cb

    @on_emcy.setter
    def on_emcy(self, cb: Optional[Callable[[EmcyError], None]]) -> None:
        self._cb = cb
        self._c.set_callback(None if cb is None else (lambda d: cb(EmcyError._from(d))))

    @property
    def received(self) -> int:
        return self._c.received

    @property
    def ignored_frames(self) -> int:
        return self._c.ignored_frames


EmcyProducer = _core.EmcyProducer

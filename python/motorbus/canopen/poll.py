"""Poll sources for CANopen drives: objects read by SDO on the poller's C++ thread.

A drive kind's ``poll_fields`` (see :class:`motorbus.registry.PollSpec`) names
which object gives each field; :func:`sdo_poll_spec` builds the source on the
drive's own SDO client (shared with the Drive: the client serializes transfers).
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from .. import _core
from ..registry import PollSpec

__all__ = ["sdo_poll_spec", "CIA402_POLL_OBJECTS"]

#: The CiA 402 objects of the Drive's readings: (index, subindex, type, scale to native units).
CIA402_POLL_OBJECTS = {
    "position": (0x6064, 0, "i32", 1.0),   # position actual value
    "velocity": (0x606C, 0, "i32", 1.0),   # velocity actual value
    "status": (0x6041, 0, "u16", 1.0),     # statusword
}


def sdo_poll_spec(kind: str, sdo: Any, bus: Any, fields: Sequence[str],
                  objects: Mapping[str, tuple]) -> PollSpec:
    """A PollSpec reading ``objects[field]`` = (index, sub, type, scale) for each field by SDO."""
    rows = []
    for f in fields:
        if f not in objects:
            raise _core.InvalidArgument(f"{kind} poll field {f!r}: this kind gives {', '.join(objects)}")
        rows.append(objects[f])
    source = _core.sdo_poll_source(sdo, [(i, s, t) for (i, s, t, _) in rows])
    return PollSpec(source=source, scales=tuple(float(r[3]) for r in rows),
                    transport=bus if bus is not None else sdo, bus=bus)

"""Poll sources for CANopen drives, on the poller's C++ thread.

A drive kind's ``poll_fields`` (see :class:`motorbus.registry.PollSpec`) names
which object gives each field; :func:`sdo_poll_spec` builds a source asking by
SDO on the drive's own SDO client (shared with the Drive: the client serializes
transfers).  A kind whose drive can map those objects into TPDOs offers
``capture_fields`` with :func:`tpdo_capture_spec`: the objects are mapped into
TPDOs (as few as fit, 64 bits each) sent on the event timer at the poll period,
and a capture source takes the latest ones as they arrive.

Why the event timer and not SYNC: with SYNC the poller would have to send a
SYNC frame per period, and a SYNC's reply TPDOs would arrive after the sample
that sent it, a period late; the event timer paces the data by the drive's own
clock and each row's ``<axis>.t`` says when it arrived.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from .. import _core
from ..registry import PollSpec

__all__ = ["sdo_poll_spec", "tpdo_capture_spec", "CIA402_POLL_OBJECTS"]

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
    source = _core.canopen.sdo_poll_source(sdo, [(i, s, t) for (i, s, t, _) in rows])
    return PollSpec(source=source, scales=tuple(float(r[3]) for r in rows),
                    transport=bus if bus is not None else sdo, bus=bus)


_BITS = {"i8": (8, True), "i16": (16, True), "i32": (32, True), "u8": (8, False), "u16": (16, False),
         "u32": (32, False)}


def tpdo_capture_spec(kind: str, sdo: Any, bus: Any, node: int, fields: Sequence[str],
                      objects: Mapping[str, tuple], period: float, first_tpdo: int = 1,
                      procedure: str = "cia301") -> PollSpec:
    """A PollSpec capturing ``objects[field]`` from TPDOs the drive sends on its event timer.

    Maps the fields, in order, into TPDO ``first_tpdo``, ``first_tpdo + 1``... (a new
    one when the next object would pass 64 bits), transmission type 254 with the
    event timer at the period in whole ms (at least 1), then starts the node (NMT:
    PDOs flow only in OPERATIONAL).  The returned ``close`` disables those TPDOs.
    ``procedure``: how the TPDOs are written (``"cia301"``, or ``"direct"`` for drives
    that document changing a PDO in place instead of the CiA 301 procedure).
    Data older than 3 timer periods + 2 ms counts as stale."""
    rows = []
    for f in fields:
        if f not in objects:
            raise _core.InvalidArgument(f"{kind} poll field {f!r}: this kind gives {', '.join(objects)}")
        index, sub, type_, scale = objects[f]
        if type_ not in _BITS:
            raise _core.InvalidArgument(f"{kind} poll field {f!r}: type {type_!r} cannot be captured from a TPDO")
        rows.append((index, sub, *_BITS[type_], float(scale)))
    pdos: list[list[tuple]] = [[]]
    columns = []
    for (index, sub, bits, signed, _) in rows:
        if sum(e[2] for e in pdos[-1]) + bits > 64:
            pdos.append([])
        columns.append((len(pdos) - 1, len(pdos[-1])))
        pdos[-1].append((index, sub, bits, signed))
    if first_tpdo + len(pdos) - 1 > 4:
        raise _core.InvalidArgument(f"{kind} capture: {len(pdos)} TPDOs from TPDO {first_tpdo} pass TPDO 4")
    timer_ms = min(65535, max(1, int(round(period * 1000))))
    numbers = list(range(first_tpdo, first_tpdo + len(pdos)))
    tpdos = []
    for number, mapping in zip(numbers, pdos):
        cob = 0x180 + 0x100 * (number - 1) + node   # the predefined connection set's COB-ID
        _core.canopen.pdo_write_config(sdo, node, True, number, cob_id=cob, transmission_type=254, inhibit_100us=0,
                                       event_timer_ms=timer_ms, mapping=mapping, procedure=procedure)
        tpdos.append((cob, mapping))
    source = _core.canopen.PdoCaptureSource(bus, node, tpdos, columns, max_age=(3 * timer_ms + 2) / 1000)
    bus.send(_core.canopen.nmt_encode(_core.canopen.NmtCommand.START, node))   # PDOs flow only in OPERATIONAL

    def close() -> None:
        source.close()
        for number, (cob, _) in zip(numbers, tpdos):
            _core.canopen.pdo_write_config(sdo, node, True, number, cob_id=cob, enabled=False, procedure="direct")


    return PollSpec(source=source, scales=tuple(r[4] for r in rows), transport=bus, bus=bus,
                    stamped=True, close=close)

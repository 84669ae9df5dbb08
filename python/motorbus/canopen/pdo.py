"""PDO mapping, bit-exact pack/unpack, configuration over SDO, SYNC.

    from motorbus.canopen import PdoMap, configure_pdo
    m = PdoMap([(0x6041, 0, 16), (0x6064, 0, 32, True)])   # (index, sub, bits[, signed])
    m.pack([0x0637, -100])          # b'\\x37\\x06\\x9c\\xff\\xff\\xff'
    m.unpack(b'\\x37\\x06\\x9c\\xff\\xff\\xff')   # [1591, -100]

    configure_pdo(bus, 5, tpdo=1, cob_id=0x187, transmission_type=255,
                  inhibit_100us=50, event_timer_ms=1000, mapping=[(0x6012, 0, 16)])

`sdo` arguments take a motorbus Bus (an SDO client per node is created) or any
object with ``upload(index, sub) -> bytes`` and ``download(index, sub, data)``.
"""
from __future__ import annotations

from typing import Iterable, List, Optional, Sequence, Tuple, Union

from .. import _core

__all__ = ["PdoMap", "pack", "unpack", "configure_pdo", "read_pdo_config", "PdoReceiver", "PdoService",
           "PdoSender", "SyncProducer", "sync_encode", "time_encode", "time_decode"]

Entry = Union[Tuple[int, int, int], Tuple[int, int, int, bool]]

PdoReceiver = _core.PdoReceiver
#: PdoService(local_node, strict=True): the PDO engine of a served LocalNode.
#: strict=False accepts parameter changes while a PDO is valid (as the PMC007 does).
PdoService = _core.PdoService
PdoSender = _core.PdoSender
SyncProducer = _core.SyncProducer
sync_encode = _core.sync_encode
time_encode = _core.time_encode
time_decode = _core.time_decode


class PdoMap:
    """A PDO mapping: entries follow each other LSB first, any bit offset, little-endian."""

    def __init__(self, entries: Iterable[Entry]) -> None:
        self.entries = [tuple(e) for e in entries]
        self._layout = _core.PdoLayout(self.entries)

    def __repr__(self) -> str:
        return f"PdoMap({self.entries!r})"

    def __len__(self) -> int:
        return len(self.entries)

    @property
    def length(self) -> int:
        """Frame length in bytes."""
        return self._layout.length

    @property
    def total_bits(self) -> int:
        return self._layout.total_bits

    def offset(self, i: int) -> int:
        """Bit offset of entry i in the frame."""
        return self._layout.offset(i)

    @property
    def mapping_words(self) -> List[int]:
        """The 0x1600/0x1A00 sub-entry values (index << 16 | sub << 8 | bits)."""
        return [(e[0] << 16) | (e[1] << 8) | e[2] for e in self.entries]

    def pack(self, values: Sequence[int]) -> bytes:
        return self._layout.pack([int(v) for v in values])

    def unpack(self, data: bytes) -> List[int]:
        return list(self._layout.unpack(bytes(data)))

    def unpack_dict(self, data: bytes) -> dict:
        return {(e[0], e[1]): v for e, v in zip(self.entries, self.unpack(data))}


def pack(entries: Iterable[Entry], values: Sequence[int]) -> bytes:
    return PdoMap(entries).pack(values)


def unpack(entries: Iterable[Entry], data: bytes) -> List[int]:
    return PdoMap(entries).unpack(data)


def configure_pdo(sdo, node: int, *, tpdo: Optional[int] = None, rpdo: Optional[int] = None,
                  cob_id: Optional[int] = None, enabled: bool = True,
                  transmission_type: Optional[int] = None, inhibit_100us: Optional[int] = None,
                  event_timer_ms: Optional[int] = None, sync_start: Optional[int] = None,
                  mapping: Optional[Iterable[Entry]] = None, procedure: str = "cia301") -> None:
    """Write a PDO's parameters and mapping. procedure='cia301' disables the PDO,
    clears the mapping, writes the entries and re-enables it; 'direct' writes in
    the order devices such as the PMC007 document, without those steps."""
    if (tpdo is None) == (rpdo is None):
        raise _core.InvalidArgument("configure_pdo: give exactly one of tpdo= or rpdo=")
    _core.pdo_write_config(sdo, node, tpdo is not None, tpdo if tpdo is not None else rpdo,
                           cob_id, enabled, transmission_type, inhibit_100us, event_timer_ms,
                           sync_start, None if mapping is None else [tuple(e) for e in mapping],
                           procedure)


def read_pdo_config(sdo, node: int, *, tpdo: Optional[int] = None, rpdo: Optional[int] = None) -> dict:
    if (tpdo is None) == (rpdo is None):
        raise _core.InvalidArgument("read_pdo_config: give exactly one of tpdo= or rpdo=")
    return _core.pdo_read_config(sdo, node, tpdo is not None, tpdo if tpdo is not None else rpdo)

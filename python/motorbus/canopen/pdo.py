"""PDO mapping, bit-exact pack/unpack, configuration over SDO, and ``node.tpdo`` /
``node.rpdo`` of a remote node (SYNC and TIME are in sync.py and time.py).

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

import functools
import threading
from typing import Callable, Dict, Iterable, List, Optional, Sequence, Tuple, Union

from .. import _core, faces

__all__ = ["PdoMap", "pack", "unpack", "configure_pdo", "read_pdo_config", "PdoConfig", "PdoCounters",
           "PdoReceiver", "PdoService", "PdoSender", "PdoChannel", "PdoChannels"]

Entry = Union[Tuple[int, int, int], Tuple[int, int, int, bool]]

from .._core.canopen import PdoReceiver  # noqa: E402,F401
#: PdoService(local_node, strict=True): the PDO engine of a served LocalNode.
#: strict=False accepts parameter changes while a PDO is valid (as some devices do).
from .._core.canopen import PdoService, PdoSender, PdoConfig, PdoCounters  # noqa: E402,F401


class PdoMap:
    """A PDO mapping: entries follow each other LSB first, any bit offset, little-endian."""

    def __init__(self, entries: Iterable[Entry]) -> None:
        self.entries = [tuple(e) for e in entries]
        self._layout = _core.canopen.PdoLayout(self.entries)

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
                  mapping: Optional[Iterable[Entry]] = None,
                  procedure: "str | _core.canopen.PdoProcedure" = "cia301") -> None:
    """Write a PDO's parameters and mapping. procedure='cia301' (PdoProcedure.CIA301) disables the PDO,
    clears the mapping, writes the entries and re-enables it; 'direct' writes in
    the order some devices' manuals document, without those steps."""
    if (tpdo is None) == (rpdo is None):
        raise _core.InvalidArgument("configure_pdo: give exactly one of tpdo= or rpdo=")
    _core.canopen.pdo_write_config(sdo, node, tpdo is not None, tpdo if tpdo is not None else rpdo,
                                   cob_id, enabled, transmission_type, inhibit_100us, event_timer_ms,
                                   sync_start, None if mapping is None else [tuple(e) for e in mapping],
                                   procedure)


def read_pdo_config(sdo, node: int, *, tpdo: Optional[int] = None, rpdo: Optional[int] = None) -> PdoConfig:
    if (tpdo is None) == (rpdo is None):
        raise _core.InvalidArgument("read_pdo_config: give exactly one of tpdo= or rpdo=")
    return _core.canopen.pdo_read_config(sdo, node, tpdo is not None, tpdo if tpdo is not None else rpdo)


# Signed CiA 301 types (INTEGER8..64, INTEGER24..56): their PDO fields are sign-extended.
_SIGNED_TYPES = frozenset({0x02, 0x03, 0x04, 0x10, 0x12, 0x13, 0x14, 0x15})


class PdoChannel:
    """One PDO of a remote node (``node.tpdo[1]``, ``node.rpdo[1]``).

    ``read()`` reads its configuration from the device, ``configure(...)``
    writes it (as :func:`configure_pdo`); a TPDO delivers its values to
    ``add_callback`` callbacks and :meth:`wait_for_reception`, keyed by
    ``(index, subindex)``; an RPDO is sent with :meth:`transmit`."""

    def __init__(self, node, tpdo: bool, number: int) -> None:
        self._node = node
        self.tpdo = tpdo
        self.number = number
        self.config: Optional[PdoConfig] = None
        #: Receive time (s, the bus clock) of the latest TPDO, set before its callbacks run.
        self.timestamp: Optional[float] = None
        self._rx: Optional[_core.canopen.PdoReceiver] = None
        self._tx: Optional[_core.canopen.PdoSender] = None
        self._callbacks: List[Callable[[Dict[Tuple[int, int], int]], None]] = []
        self._lock = threading.Lock()

    def __repr__(self) -> str:
        return f"<PdoChannel node {self._node.id} {'TPDO' if self.tpdo else 'RPDO'}{self.number}>"

    def _kw(self) -> dict:
        return {"tpdo": self.number} if self.tpdo else {"rpdo": self.number}

    def read(self) -> PdoConfig:
        self.config = read_pdo_config(self._node.sdo.client, self._node.id, **self._kw())
        return self.config

    def configure(self, **kwargs) -> PdoConfig:
        """``cob_id=, enabled=, transmission_type=, inhibit_100us=, event_timer_ms=,
        sync_start=, mapping=, procedure=`` as :func:`configure_pdo`; returns the
        configuration read back from the device."""
        configure_pdo(self._node.sdo.client, self._node.id, **self._kw(), **kwargs)
        with self._lock:  # a new mapping or COB-ID: receivers are rebuilt on demand
            self._rx = self._tx = None
        return self.read()

    # Awaitable twins.  The configuration sequence (read_pdo/write_pdo: 6-20 SDO
    # transfers and the CiA 301 disable-map-enable order) is C++ logic over a
    # blocking SDO access; awaited, it runs whole on the node's link worker
    # (faces.NativeIo: one thread per link while busy, gone after an idle second),
    # so it is written once and never copied into Python.  Its transfers queue on
    # the node's SDO channel with the awaited ones, never interleaved.
    async def read_async(self) -> PdoConfig:
        """Awaitable :meth:`read`."""
        client = self._node.sdo.client
        self.config = await faces.NativeIo(client).do(
            functools.partial(read_pdo_config, client, self._node.id, **self._kw()))
        return self.config

    async def configure_async(self, **kwargs) -> PdoConfig:
        """Awaitable :meth:`configure` (same arguments); the configuration read back."""
        client = self._node.sdo.client
        await faces.NativeIo(client).do(
            functools.partial(configure_pdo, client, self._node.id, **self._kw(), **kwargs))
        with self._lock:
            self._rx = self._tx = None
        return await self.read_async()

    @property
    def cob_id(self) -> int:
        return self._config().cob_id & 0x1FFFFFFF

    @property
    def mapping(self) -> List[Tuple[int, int, int]]:
        return self._config().mapping

    def _config(self) -> PdoConfig:
        return self.config if self.config is not None else self.read()

    def _entries(self) -> list:
        od = self._node.object_dictionary
        out = []
        for index, sub, bits in self.mapping:
            signed = od is not None and (index, sub) in od and int(od[index, sub].data_type) in _SIGNED_TYPES
            out.append((index, sub, bits, signed))
        if not out:
            raise _core.InvalidArgument(f"{self!r}: nothing is mapped (configure(mapping=...) first)")
        return out

    def _receiver(self) -> _core.canopen.PdoReceiver:
        if not self.tpdo:
            raise _core.InvalidArgument(f"{self!r}: an RPDO is sent by the host, not received (use transmit)")
        with self._lock:
            if self._rx is None:
                entries = self._entries()
                rx = _core.canopen.PdoReceiver(self._node.bus, self.cob_id, entries)
                self._keys = [(e[0], e[1]) for e in entries]
                # The receiver keeps raw field bits; signed objects are sign-extended here.
                self._signs = [(1 << (e[2] - 1)) if e[3] else 0 for e in entries]
                rx.set_callback(self._on_receive)
                self._rx = rx
            return self._rx

    def _decode(self, values: Sequence[int]) -> Dict[Tuple[int, int], int]:
        return {k: (v - 2 * s if s and v >= s else v) for k, v, s in zip(self._keys, values, self._signs)}

    def _on_receive(self, values: Sequence[int], timestamp_ns: int) -> None:
        self.timestamp = timestamp_ns / 1e9     # before the callbacks, which may read it
        self._dispatch(self._decode(values))

    def _dispatch(self, values: Dict[Tuple[int, int], int]) -> None:
        for cb in list(self._callbacks):
            cb(values)

    def add_callback(self, callback: Callable[[Dict[Tuple[int, int], int]], None]) -> None:
        """callback({(index, subindex): value}) on the bus thread for every TPDO received."""
        self._callbacks.append(callback)
        self._receiver()

    def remove_callback(self, callback: Callable[[Dict[Tuple[int, int], int]], None]) -> None:
        """Stops calling ``callback`` (given to add_callback); unknown callbacks are ignored."""
        if callback in self._callbacks:
            self._callbacks.remove(callback)

    @property
    def values(self) -> Dict[Tuple[int, int], int]:
        """The latest values received ({} before the first)."""
        rx = self._receiver()
        return self._decode(rx.values) if rx.received else {}

    def wait_for_reception(self, timeout: float = 10.0) -> Dict[Tuple[int, int], int]:
        """Waits for the next TPDO; its values. motorbus.TimeoutError when none comes."""
        rx = self._receiver()
        if not rx.wait_newer(rx.received, timeout):
            raise _core.TimeoutError(f"{self!r}: nothing received within {timeout} s")
        return self._decode(rx.values)

    def transmit(self, values: Sequence[int], timeout: float = 1.0) -> None:
        """Sends this RPDO with ``values`` in mapping order."""
        if self.tpdo:
            raise _core.InvalidArgument(f"{self!r}: a TPDO is sent by the device (use add_callback)")
        with self._lock:
            if self._tx is None:
                self._tx = _core.canopen.PdoSender(self._node.bus, self.cob_id, self._entries())
            tx = self._tx
        tx.send([int(v) for v in values], timeout)

    def _close(self) -> None:
        with self._lock:
            if self._rx is not None:
                self._rx.set_callback(None)
            self._rx = self._tx = None


class PdoChannels:
    """``node.tpdo`` / ``node.rpdo``: PDO 1-512 of a remote node, made on first use."""

    def __init__(self, node, tpdo: bool) -> None:
        self._node = node
        self._tpdo = tpdo
        self._channels: Dict[int, PdoChannel] = {}

    def __getitem__(self, number: int) -> PdoChannel:
        if not 1 <= int(number) <= 512:
            raise _core.InvalidArgument(f"{'TPDO' if self._tpdo else 'RPDO'} number {number} is outside 1-512")
        ch = self._channels.get(int(number))
        if ch is None:
            ch = self._channels[int(number)] = PdoChannel(self._node, self._tpdo, int(number))
        return ch

    def read(self, numbers: Iterable[int] = (1, 2, 3, 4)) -> List[PdoConfig]:
        """Reads the configuration of these PDOs (default: the predefined four)."""
        return [self[n].read() for n in numbers]

    def _close(self) -> None:
        for ch in self._channels.values():
            ch._close()

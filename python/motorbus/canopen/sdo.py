"""SDO client, the SDO errors (C++ core; see docs/canopen.md), and ``node.sdo``:
objects of a remote node addressed as the `canopen` package does.

    node.sdo[0x1018][1].raw                 # by index and sub-index
    node.sdo["Identity object"]["Vendor-ID"].raw     # by name (the node has an OD / EDS)
    node.sdo["Device name"].value           # typed: int, float, bool, str or bytes per the data type
    node.sdo[0x2000][0].write(1234, size=4) # no OD: the size of an integer must be given
"""
from __future__ import annotations

from typing import Iterator, Optional, Union

from .. import _core
from .._core import SdoAbortError, SdoProtocolError, SdoTimeout  # noqa: F401
from .._core.canopen import ABORT_CODES, SdoClient, SdoClientCounters, abort_text  # noqa: F401
from .od import NotFound, ObjectDictionary, Variable

__all__ = ["SdoClient", "SdoClientCounters", "SdoAbortError", "SdoTimeout", "SdoProtocolError", "abort_text",
           "ABORT_CODES", "SdoVariables", "SdoObject", "SdoVariable"]

# CiA 301 types whose value is an integer (BOOLEAN, INTEGERn, UNSIGNEDn):
# `.raw` gives and takes an int for them, bytes for every other type.
_INTEGER_TYPES = frozenset({0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x10}) | frozenset(range(0x12, 0x1C))

Key = Union[int, str]


class SdoVariable:
    """One sub-object of a remote node, read and written over SDO on access."""

    def __init__(self, client: SdoClient, index: int, subindex: int, od_var: Optional[Variable] = None) -> None:
        self._client = client
        self.index = index
        self.subindex = subindex
        self.od = od_var  # the dictionary entry (data type, name), None without an OD

    @property
    def name(self) -> str:
        return self.od.name if self.od is not None else f"0x{self.index:04X}:{self.subindex:02X}"

    def __repr__(self) -> str:
        return f"<SdoVariable 0x{self.index:04X}:{self.subindex:02X} {self.name!r}>"

    def _is_integer(self) -> bool:
        return self.od is not None and int(self.od.data_type) in _INTEGER_TYPES

    def read(self) -> bytes:
        """The object's bytes as uploaded."""
        return self._client.upload(self.index, self.subindex)

    def write(self, value: Union[int, bytes, bytearray], size: Optional[int] = None, signed: bool = False) -> None:
        """Download bytes, or an int as ``size`` little-endian bytes (``size`` is
        needed when the data type is not known from a dictionary)."""
        if isinstance(value, (bytes, bytearray, memoryview)):
            data = bytes(value)
        elif size is not None:
            try:
                data = int(value).to_bytes(size, "little", signed=signed)
            except OverflowError:
                raise _core.InvalidArgument(f"{self.name}: {value} does not fit {size} bytes") from None
        elif self._is_integer():
            data = self.od.encode(int(value))
        else:
            raise _core.InvalidArgument(
                f"{self.name}: no integer data type known for {value!r}: pass bytes or write(value, size=)")
        self._client.download(self.index, self.subindex, data)

    @property
    def raw(self) -> Union[int, bytes]:
        """The int for integer types (signed per the type), else the bytes; bytes without an OD."""
        data = self.read()
        if self._is_integer():
            return int(self.od.decode(data))
        return data

    @raw.setter
    def raw(self, value: Union[int, bytes]) -> None:
        self.write(value)

    @property
    def value(self):
        """Typed by the OD data type: int (signed or not), float, bool, str or bytes."""
        return self._typed("read").decode(self.read())

    @value.setter
    def value(self, v) -> None:
        self._client.download(self.index, self.subindex, self._typed("write").encode(v))

    def _typed(self, what: str) -> Variable:
        """The dictionary entry whose C++ codec gives and takes the value."""
        if self.od is None:
            raise _core.InvalidArgument(
                f"{self.name}: .value needs the data type: give add_node() an EDS or ObjectDictionary "
                f"(or use .raw to {what} bytes)")
        return self.od


class SdoObject:
    """An object (index) of a remote node: ``[sub]`` / ``["SubName"]`` gives its
    sub-objects; a VAR object (or any object when there is no OD) also reads
    and writes as a variable itself (``.raw``, ``.value``) through sub-index 0."""

    def __init__(self, sdo: "SdoVariables", index: int) -> None:
        self._sdo = sdo
        self.index = index
        od = sdo.od
        self.object_code = od.object_code(index) if od is not None else None
        self.name = (od.object_name(index) if od is not None else None) or f"0x{index:04X}"

    def __repr__(self) -> str:
        return f"<SdoObject 0x{self.index:04X} {self.name!r}>"

    def __getitem__(self, key: Key) -> SdoVariable:
        od = self._sdo.od
        if isinstance(key, str):
            if od is None:
                raise NotFound(f"{self.name}: sub-object {key!r} by name needs an EDS or ObjectDictionary")
            for s in od.subindices(self.index):
                if od[self.index, s].name == key:
                    return SdoVariable(self._sdo.client, self.index, s, od[self.index, s])
            raise NotFound(f"{self.name} (0x{self.index:04X}) has no sub-object named {key!r}")
        sub = int(key)
        if not 0 <= sub <= 0xFF:
            raise _core.InvalidArgument(f"{self.name}: sub-index {sub} is outside 0-255")
        if od is None:
            return SdoVariable(self._sdo.client, self.index, sub)
        if (self.index, sub) not in od:
            raise NotFound(f"{self.name} (0x{self.index:04X}) has no sub-index {sub} in the dictionary")
        return SdoVariable(self._sdo.client, self.index, sub, od[self.index, sub])

    def __iter__(self) -> Iterator[int]:
        od = self._sdo.od
        return iter(od.subindices(self.index) if od is not None else ())

    def _var(self) -> SdoVariable:
        if self.object_code not in (None, "VAR"):
            raise _core.InvalidArgument(f"{self.name} (0x{self.index:04X}) is a {self.object_code}: "
                                        f"pick a sub-object, e.g. [1]")
        return self[0]

    @property
    def raw(self):
        return self._var().raw

    @raw.setter
    def raw(self, value) -> None:
        self._var().raw = value

    @property
    def value(self):
        return self._var().value

    @value.setter
    def value(self, v) -> None:
        self._var().value = v

    def read(self) -> bytes:
        return self._var().read()

    def write(self, value, size: Optional[int] = None, signed: bool = False) -> None:
        self._var().write(value, size, signed)


class SdoVariables:
    """``node.sdo``: the objects of a remote node over one SdoClient (one client
    per node: two on one COB-ID would take each other's responses).

    ``[index]`` or ``["Object name"]`` gives an :class:`SdoObject`;
    ``["Record.Member"]`` a :class:`SdoVariable`; ``upload``/``download`` pass through."""

    def __init__(self, client: SdoClient, od: Optional[ObjectDictionary] = None) -> None:
        self.client = client
        self.od = od
        self._names = {od.object_name(i): i for i in od.indices()} if od is not None else {}

    def __getitem__(self, key: Key) -> Union[SdoObject, SdoVariable]:
        if isinstance(key, str):
            if key in self._names:
                return SdoObject(self, self._names[key])
            if self.od is not None and key in self.od:  # "Record.Member" or "0x1018:1"
                v = self.od[key]
                return SdoVariable(self.client, v.index, v.subindex, v)
            if self.od is None:
                raise NotFound(f"object {key!r}: access by name needs an EDS or ObjectDictionary (add_node(id, eds))")
            raise NotFound(f"node {self.client.node_id} has no object named {key!r} in its dictionary")
        index = int(key)
        if not 0 <= index <= 0xFFFF:
            raise _core.InvalidArgument(f"object index {index:#x} is outside 0x0000-0xFFFF")
        if self.od is not None and index not in self.od:
            raise NotFound(f"node {self.client.node_id} has no object 0x{index:04X} in its dictionary")
        return SdoObject(self, index)

    def __contains__(self, key: Key) -> bool:
        if self.od is None:
            return False
        return key in self._names or key in self.od

    def upload(self, index: int, subindex: int = 0, block: bool = False) -> bytes:
        return self.client.upload(index, subindex, block)

    def download(self, index: int, subindex: int, data: bytes, block: bool = False, segmented: bool = False) -> None:
        self.client.download(index, subindex, data, block, segmented)

    @property
    def timeout(self) -> float:
        return self.client.timeout

    @timeout.setter
    def timeout(self, t: float) -> None:
        self.client.timeout = t

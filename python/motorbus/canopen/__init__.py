"""CANopen: object dictionary, EDS, SDO client and server (LocalNode).

    import motorbus
    from motorbus.canopen import SdoClient, ObjectDictionary, LocalNode

    bus = motorbus.open_bus("virtual:lab")
    sdo = SdoClient(bus, 5, timeout=0.5)
    status = sdo.read_u8(0x6001, 0)
"""
from __future__ import annotations

from .eds import load_eds, save_eds, to_eds  # noqa: F401
from .node import LocalNode  # noqa: F401
from .od import DataType, ObjectDictionary, Variable  # noqa: F401
from .sdo import (  # noqa: F401
    ABORT_CODES,
    SdoAbortError,
    SdoClient,
    SdoProtocolError,
    SdoTimeout,
    abort_text,
)

__all__ = [
    "ABORT_CODES", "DataType", "LocalNode", "ObjectDictionary", "SdoAbortError", "SdoClient",
    "SdoProtocolError", "SdoTimeout", "Variable", "abort_text", "load_eds", "save_eds", "to_eds",
]

# ---- canopen-svc exports (NMT, SYNC, EMCY, heartbeat, TIME, PDO, CiA 402, scanner) go below ----

"""CANopen: object dictionary, EDS, SDO client and server (LocalNode), NMT, heartbeat, EMCY,
SYNC, PDO, CiA 402 and a network scanner.

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

# NMT, SYNC, EMCY, heartbeat, TIME, PDO, CiA 402 and the scanner
from .services import *  # noqa: E402,F401,F403
from .services import __all__ as _services_all  # noqa: E402

__all__ += _services_all

"""motorbus: drive integrated motor controllers over CAN, CANopen and serial lines."""
from __future__ import annotations

from ._core import (  # noqa: F401
    Bus,
    ClosedError,
    DriveFault,
    Frame,
    InvalidArgument,
    LinkDown,
    MotorbusError,
    ProtocolError,
    TimeoutError,
    monotonic_ns,
)

__version__ = "0.1.0"

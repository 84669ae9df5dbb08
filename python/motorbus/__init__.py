"""motorbus: drive integrated motor controllers over CAN, CANopen and serial lines."""
from __future__ import annotations

from ._core import (  # noqa: F401
    ClosedError, DriveFault, InvalidArgument, LinkDown, MotorbusError, ProtocolError, TimeoutError,
)
from ._core.can import Bus, ExternalBus, VirtualBus, Frame  # noqa: F401
from ._core.runtime import monotonic_ns  # noqa: F401

from .bus import open_bus  # noqa: E402,F401
from .log import LogEntry, Recorder, play, read_log  # noqa: E402,F401
from . import motion, serial, slcan  # noqa: E402,F401
from ._core import LimitExceeded  # noqa: E402,F401
from .slcan import SlcanBus, SlcanServer, open_slcan  # noqa: E402,F401
from . import socketcand  # noqa: E402,F401
from .socketcand import (  # noqa: E402,F401
    SocketCanBus,
    SocketcandBus,
    SocketcandServer,
    open_socketcan,
    open_socketcand,
    socketcan_unavailable_reason,
)
from . import canopen  # noqa: E402,F401
from ._core import SdoAbortError, SdoProtocolError, SdoTimeout  # noqa: E402,F401
from . import registry  # noqa: E402,F401
from .drive import (  # noqa: E402,F401
    Capability, Drive, DriveStatus, LimitReached, MoveFailed, MoveFaulted, MoveInterrupted, MoveOutcome, MoveStalled,
    MoveTimedOut, ParamInfo, Units, open_drive,
)
from .registry import drive_kinds  # noqa: E402,F401
from .bench import Bench, BenchFileError  # noqa: E402,F401
from .poller import Poller, load_frame  # noqa: E402,F401
from ._stop_at_exit import (  # noqa: E402,F401 - SIGTERM/SIGHUP stop the drives (docs/reliability.md)
    TerminatedBySignal, handle_signal as stop_on_signal, stop_all as stop_all_drives,
)

__version__ = "0.1.0"

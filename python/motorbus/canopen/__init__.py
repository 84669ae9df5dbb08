"""CANopen: a node-centric Network (as the `canopen` package has it) over the
services underneath -- object dictionary, EDS, SDO client and server
(LocalNode), NMT, heartbeat, EMCY, SYNC, TIME, PDO, CiA 402 and a scanner.

    import motorbus
    from motorbus.canopen import Network

    with Network("virtual:lab") as network:
        node = network.add_node(5, "drive.eds")
        print(node.sdo["Statusword"].raw)

The services stand on their own too:

    from motorbus.canopen import SdoClient
    sdo = SdoClient(motorbus.open_bus("virtual:lab"), 5, timeout=0.5)
    status = sdo.read_u8(0x6001, 0)
"""
from __future__ import annotations

from .cia402 import *  # noqa: F401,F403
from .eds import *  # noqa: F401,F403
from .emcy import *  # noqa: F401,F403
from .heartbeat import *  # noqa: F401,F403
from .network import *  # noqa: F401,F403
from .nmt import *  # noqa: F401,F403
from .node import *  # noqa: F401,F403
from .od import *  # noqa: F401,F403
from .pdo import *  # noqa: F401,F403
from .scanner import *  # noqa: F401,F403
from .sdo import *  # noqa: F401,F403
from .sync import *  # noqa: F401,F403
from .time import *  # noqa: F401,F403
from . import cia402, eds, emcy, heartbeat, network, nmt, node, od, pdo, scanner, sdo, sync, time  # noqa: F401,E402

__all__ = (cia402.__all__ + eds.__all__ + emcy.__all__ + heartbeat.__all__ + network.__all__ + nmt.__all__
           + node.__all__ + od.__all__ + pdo.__all__ + scanner.__all__ + sdo.__all__ + sync.__all__ + time.__all__)

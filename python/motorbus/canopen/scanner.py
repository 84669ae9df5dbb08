"""Find CANopen nodes: boot-up/heartbeat listening plus parallel SDO probes.

    from motorbus.canopen import scan_network
    for n in scan_network(bus, sdo_timeout=0.2):
        print(n.node, hex(n.device_type or 0), n.vendor_id, n.state)
"""
from __future__ import annotations

from typing import List

from .. import _core

__all__ = ["NodeInfo", "scan_network"]

from .._core.canopen import NodeInfo  # noqa: E402,F401


def scan_network(bus: _core.can.Bus, first: int = 1, last: int = 127, sdo_timeout: float = 0.2,
                 listen: float = 0.0, probe_sdo: bool = True, identity: bool = True) -> List[NodeInfo]:
    """Nodes that answered an SDO probe of 0x1000 or were heard; sorted by node id.
    Takes about (1 + 4 if identity) x sdo_timeout, plus `listen`."""
    return _core.canopen.scan_network(bus, first, last, sdo_timeout, listen, probe_sdo, identity)

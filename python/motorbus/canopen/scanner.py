"""Find CANopen nodes: boot-up/heartbeat listening plus parallel SDO probes.

    from motorbus.canopen import scan_network
    for n in scan_network(bus, sdo_timeout=0.2):
        print(n.node, hex(n.device_type or 0), n.vendor_id, n.state)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional

from .. import _core

__all__ = ["NodeInfo", "scan_network"]


@dataclass(frozen=True)
class NodeInfo:
    node: int
    sdo_answered: bool
    heard_heartbeat: bool
    heard_boot_up: bool
    state: str
    device_type: Optional[int]
    device_type_abort: Optional[int]
    vendor_id: Optional[int]
    product_code: Optional[int]
    revision: Optional[int]
    serial_number: Optional[int]

    @property
    def profile(self) -> Optional[int]:
        """Device profile number (402 for drives) from 0x1000's low 16 bits."""
        return None if self.device_type is None else self.device_type & 0xFFFF


def scan_network(bus: _core.Bus, first: int = 1, last: int = 127, sdo_timeout: float = 0.2,
                 listen: float = 0.0, probe_sdo: bool = True, identity: bool = True) -> List[NodeInfo]:
    """Nodes that answered an SDO probe of 0x1000 or were heard; sorted by node id.
    Takes about (1 + 4 if identity) x sdo_timeout, plus `listen`."""
    return [NodeInfo(**d) for d in _core.scan_network(bus, first, last, sdo_timeout, listen, probe_sdo, identity)]

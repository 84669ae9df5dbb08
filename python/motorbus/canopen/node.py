"""Nodes: ``RemoteNode`` (a device we talk to, from ``Network.add_node``) and
``LocalNode`` (a dictionary we serve: SDO server, boot-up, NMT slave)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Optional

from .._core import LocalNode, LocalNodeCounters, SdoClient, SdoServerCounters  # noqa: F401
from .cia402 import Cia402
from .emcy import NodeEmcy
from .heartbeat import NodeHeartbeat
from .nmt import NodeNmt
from .od import ObjectDictionary
from .pdo import PdoChannels
from .sdo import SdoVariables

if TYPE_CHECKING:
    from .network import Network

__all__ = ["LocalNode", "LocalNodeCounters", "SdoServerCounters", "RemoteNode"]


class RemoteNode:
    """A device on a :class:`~motorbus.canopen.Network`, with its services:

    * ``sdo`` -- objects by index or name (``node.sdo["Statusword"].raw``);
    * ``nmt`` -- ``state`` (read: last reported; write: command), ``wait_for_bootup``,
      ``wait_for_heartbeat``;
    * ``tpdo`` / ``rpdo`` -- configuration and values of its PDOs;
    * ``emcy``, ``heartbeat`` -- the network's consumers, for this node;
    * ``cia402`` -- a :class:`Cia402` drive object on this node's SDO client (made on first use).
    """

    def __init__(self, network: "Network", node_id: int, od: Optional[ObjectDictionary],
                 sdo_timeout: float) -> None:
        self.network = network
        self.id = node_id
        self.object_dictionary = od
        self.sdo = SdoVariables(SdoClient(network.bus, node_id, timeout=sdo_timeout), od)
        self.nmt = NodeNmt(network.nmt, node_id)
        self.emcy = NodeEmcy(network._emcy, node_id)
        self.heartbeat = NodeHeartbeat(network._heartbeat, node_id)
        self.tpdo = PdoChannels(self, tpdo=True)
        self.rpdo = PdoChannels(self, tpdo=False)
        self._cia402: Optional[Cia402] = None

    def __repr__(self) -> str:
        return f"<RemoteNode {self.id} {'with' if self.object_dictionary is not None else 'without'} OD>"

    @property
    def cia402(self) -> Cia402:
        """The CiA 402 drive object of this node (one per node; it shares the
        node's SDO client, and stops the motor as every motorbus drive object)."""
        if self._cia402 is None:
            self._cia402 = Cia402(self.sdo.client, self.id, timeout=max(2.0, self.sdo.timeout),
                                  bus=self.network.bus)
        return self._cia402

    def close(self) -> None:
        """Stops this node's PDO receivers and closes its CiA 402 object (its
        watchdog is disarmed; the motor is left as it is)."""
        self.tpdo._close()
        self.rpdo._close()
        if self._cia402 is not None:
            self._cia402.close()

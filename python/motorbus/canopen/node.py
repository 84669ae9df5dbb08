"""Nodes: ``RemoteNode`` (a device we talk to, from ``Network.add_node``) and
``LocalNode`` (a dictionary we serve: SDO server, boot-up, NMT slave)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional, Union

from .. import _core
from .._core.canopen import LocalNode, LocalNodeCounters, SdoClient, SdoServerCounters  # noqa: F401
from .cia402 import Cia402
from .emcy import NodeEmcy
from .heartbeat import NodeHeartbeat
from .nmt import NmtMaster, NodeNmt
from .od import ObjectDictionary
from .pdo import PdoChannels
from .sdo import SdoVariables

if TYPE_CHECKING:
    from .network import Network

__all__ = ["LocalNode", "LocalNodeCounters", "SdoServerCounters", "RemoteNode", "check_node_id"]


def check_node_id(address: Union[str, int], kind: str = "CANopen") -> int:
    """A CANopen node-ID 1..127 from an address: an int means that integer; text is
    decimal ("05" too) or 0x hex.  Every CANopen drive kind checks its address here;
    ``kind`` names it in the InvalidArgument."""
    if isinstance(address, bool):
        raise _core.InvalidArgument(f"{kind} address: a CANopen node-ID 1..127, not {address!r}")
    if isinstance(address, int):
        node = address
    else:
        text = str(address).strip()
        node = None
        if len(text) <= 12:     # a 100 000-digit "address" is refused, not converted
            try:
                node = int(text, 0)
            except ValueError:
                node = int(text, 10) if text.isdigit() else None   # "05": decimal with a leading zero
        if node is None:
            raise _core.InvalidArgument(f"{kind} address: a CANopen node-ID 1..127, not {address!r}")
    if not 1 <= node <= 127:
        raise _core.InvalidArgument(f"{kind} address: node-ID {node} is outside 1..127")
    return node


class RemoteNode:
    """A device on a :class:`~motorbus.canopen.Network`, with its services:

    * ``sdo`` -- objects by index or name (``node.sdo["Statusword"].raw``);
    * ``nmt`` -- ``state`` (read: last reported; write: command), ``wait_for_bootup``,
      ``wait_for_heartbeat``;
    * ``tpdo`` / ``rpdo`` -- configuration and values of its PDOs;
    * ``emcy``, ``heartbeat`` -- the network's consumers, for this node;
    * ``cia402`` -- a :class:`Cia402` drive object on this node's SDO client (made on first use).

    A node may also stand on a bus alone (``RemoteNode(bus, node_id, od, timeout)``):
    a device profile made without a Network (``open_drive``'s vendor clients).  It
    has SDO, NMT and PDOs; EMCY and heartbeat consumers come with a Network.
    """

    def __init__(self, network: "Union[Network, _core.can.Bus]", node_id: int, od: Optional[ObjectDictionary],
                 sdo_timeout: float) -> None:
        if isinstance(network, _core.can.Bus):
            self.network, self.bus = None, network
        else:
            self.network, self.bus = network, network.bus
        self.id = node_id
        self.object_dictionary = od
        self.sdo = SdoVariables(SdoClient(self.bus, node_id, timeout=sdo_timeout), od)
        on_network = self.network is not None
        self._nmt: Optional[NodeNmt] = NodeNmt(network.nmt, node_id) if on_network else None
        # Kept objects: the network dispatches to them and they hold this node's callbacks.
        self._emcy = NodeEmcy(network._emcy, node_id) if on_network else None
        self._heartbeat = NodeHeartbeat(network._heartbeat, node_id) if on_network else None
        self.tpdo = PdoChannels(self, tpdo=True)
        self.rpdo = PdoChannels(self, tpdo=False)
        self._cia402: Optional[Cia402] = None

    @property
    def nmt(self) -> NodeNmt:
        """NMT of this node (the network's master; a node alone on a bus makes its own on first use)."""
        if self._nmt is None:
            self._nmt = NodeNmt(NmtMaster(self.bus), self.id)
        return self._nmt

    @property
    def emcy(self) -> NodeEmcy:
        return self._on_network("emcy", self._emcy)

    @property
    def heartbeat(self) -> NodeHeartbeat:
        return self._on_network("heartbeat", self._heartbeat)

    def _on_network(self, what: str, service: Any) -> Any:
        if service is None:
            raise _core.InvalidArgument(f"node {self.id}: {what} consumers come with a Network "
                                        f"(Network(bus).add_node({self.id}, od)); this node stands on a bus alone")
        return service

    def __repr__(self) -> str:
        return f"<RemoteNode {self.id} {'with' if self.object_dictionary is not None else 'without'} OD>"

    @property
    def cia402(self) -> Cia402:
        """The CiA 402 drive object of this node (one per node; it shares the
        node's SDO client, and stops the motor as every motorbus drive object)."""
        if self._cia402 is None:
            self._cia402 = Cia402(self.sdo.client, self.id, timeout=max(2.0, self.sdo.timeout),
                                  bus=self.bus)
        return self._cia402

    def close(self) -> None:
        """Stops this node's PDO receivers, closes its CiA 402 object (its
        watchdog is disarmed; the motor is left as it is), then its SDO client:
        transfers still awaited end with ClosedError at once, later ones too."""
        self.tpdo._close()
        self.rpdo._close()
        if self._cia402 is not None:
            self._cia402.close()
        self.sdo.client.close()

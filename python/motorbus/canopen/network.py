"""A CANopen network seen from the host, node by node, in the idiom of the
`canopen` package:

    from motorbus.canopen import Network
    with Network("virtual:lab") as network:          # or an open motorbus Bus
        node = network.add_node(5, "drive.eds")      # EDS path, ObjectDictionary or None
        node.nmt.state = "OPERATIONAL"
        print(node.sdo["Manufacturer device name"].value, node.nmt.wait_for_heartbeat(1.0))
        node.tpdo[1].add_callback(lambda values: print(values))
        node.cia402.enable()

Underneath are the free-standing services (SdoClient per node; one NmtMaster,
HeartbeatConsumer and EmcyConsumer per network; PdoReceiver per TPDO; Cia402),
which keep working on their own.
"""
from __future__ import annotations

import os
from typing import Dict, Iterator, List, Optional, Union

from .. import _core
from ..bus import open_bus
from .eds import load_eds
from .nmt import NmtMaster
from .node import RemoteNode
from .od import NotFound, ObjectDictionary
from .scanner import NodeInfo, scan_network

__all__ = ["Network"]

EdsSource = Union[None, str, "os.PathLike[str]", ObjectDictionary]


class Network:
    """``Network(bus, sdo_timeout=1.0, emcy_history=32)``: ``bus`` is a motorbus Bus
    or an ``open_bus`` spec string (the network then owns the bus and closes it)."""

    def __init__(self, bus: Union[str, _core.can.Bus], *, sdo_timeout: float = 1.0, emcy_history: int = 32) -> None:
        if isinstance(bus, str):
            self.bus = open_bus(bus)
            self._owns_bus = True
        elif isinstance(bus, _core.can.Bus):
            self.bus = bus
            self._owns_bus = False
        else:
            raise _core.InvalidArgument(f"Network bus: a motorbus Bus or a spec string such as "
                                        f"'virtual:lab', not {type(bus).__name__}")
        self.sdo_timeout = sdo_timeout
        self.nodes: Dict[int, RemoteNode] = {}
        # Made at once, so boot-ups, heartbeats and EMCYs sent before a node is
        # added (or waited for) are already seen.
        self.nmt = NmtMaster(self.bus)
        self._heartbeat = _core.canopen.HeartbeatConsumer(self.bus, None)
        self._heartbeat.set_callback(self._on_heartbeat)
        self._heartbeat.start()
        self._emcy = _core.canopen.EmcyConsumer(self.bus, emcy_history)
        self._emcy.set_callback(self._on_emcy)
        self._closed = False

    # ---- nodes -------------------------------------------------------------------
    def add_node(self, node_id: int, eds: EdsSource = None, *, sdo_timeout: Optional[float] = None) -> RemoteNode:
        """A remote node; ``eds``: an EDS/DCF path or an ObjectDictionary (needed
        for access by name and for ``.value``)."""
        if isinstance(node_id, bool) or not isinstance(node_id, int) or not 1 <= node_id <= 127:
            raise _core.InvalidArgument(f"add_node: node id must be 1-127, not {node_id!r}")
        if node_id in self.nodes:
            raise _core.InvalidArgument(f"add_node: node {node_id} is already on this network")
        if eds is None or isinstance(eds, ObjectDictionary):
            od = eds
        elif isinstance(eds, (str, os.PathLike)):
            od = load_eds(eds, node_id)
        else:
            raise _core.InvalidArgument(f"add_node eds: an EDS path or an ObjectDictionary, not {type(eds).__name__}")
        node = RemoteNode(self, node_id, od, self.sdo_timeout if sdo_timeout is None else sdo_timeout)
        self.nodes[node_id] = node
        return node

    def __getitem__(self, node_id: int) -> RemoteNode:
        try:
            return self.nodes[node_id]
        except KeyError:
            raise NotFound(f"node {node_id!r} is not on this network (add_node first)") from None

    def __contains__(self, node_id: int) -> bool:
        return node_id in self.nodes

    def __iter__(self) -> Iterator[int]:
        return iter(self.nodes)

    def __len__(self) -> int:
        return len(self.nodes)

    def scan(self, first: int = 1, last: int = 127, sdo_timeout: float = 0.2, listen: float = 0.0) -> List[NodeInfo]:
        """Nodes that answer an SDO probe of 0x1000 or are heard (see scan_network)."""
        return scan_network(self.bus, first, last, sdo_timeout, listen)

    # ---- dispatch from the shared consumers (bus / timer threads) -------------------------
    def _on_heartbeat(self, node_id: int, event: str, state: str) -> None:
        node = self.nodes.get(node_id)
        if node is not None:
            node.heartbeat._dispatch(event, state)

    def _on_emcy(self, e) -> None:
        node = self.nodes.get(e.node)
        if node is not None:
            node.emcy._dispatch(e)

    # ---- lifecycle ---------------------------------------------------------------------
    def close(self) -> None:
        """Closes the nodes' services (CiA 402 objects, PDO receivers), the
        network's consumers, and the bus when the network opened it."""
        if self._closed:
            return
        self._closed = True
        for node in self.nodes.values():
            node.close()
        # The consumers hold these bound methods: drop them, or network and
        # consumers keep each other alive through C++.
        self._heartbeat.set_callback(None)
        self._heartbeat.stop()
        self._emcy.set_callback(None)
        if self._owns_bus:
            self.bus.close()

    def __enter__(self) -> "Network":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

"""Everything of the CANopen services in one place (motorbus.canopen re-exports it)."""
from __future__ import annotations

from .ds402 import Controlword, Ds402, Ds402Device, Ds402Host, OpMode, decode_statusword  # noqa: F401
from .emcy import EmcyConsumer, EmcyError, EmcyProducer, emcy_code_text  # noqa: F401
from .nmt import HeartbeatConsumer, HeartbeatProducer, HeartbeatService, NmtCommand, NmtMaster  # noqa: F401
from .pdo import (PdoMap, PdoReceiver, PdoSender, PdoService, SyncProducer, configure_pdo, pack,  # noqa: F401
                  read_pdo_config, unpack)
from .scanner import NodeInfo, scan_network  # noqa: F401

__all__ = ["Controlword", "Ds402", "Ds402Device", "Ds402Host", "OpMode", "decode_statusword",
           "EmcyConsumer", "EmcyError", "EmcyProducer", "emcy_code_text",
           "HeartbeatConsumer", "HeartbeatProducer", "HeartbeatService", "NmtCommand", "NmtMaster",
           "PdoMap", "PdoReceiver", "PdoSender", "PdoService", "SyncProducer", "configure_pdo", "pack",
           "read_pdo_config", "unpack", "NodeInfo", "scan_network"]

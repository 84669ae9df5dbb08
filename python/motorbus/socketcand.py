"""socketcand (CAN over TCP) and SocketCAN (Linux AF_CAN) backends.

Client::

    from motorbus.socketcand import open_socketcand
    bus = open_socketcand("gateway.local", 29536, "can0")

Server: expose any motorbus bus so python-can, socketcandcl, Kayak or another
motorbus process can join it over TCP::

    from motorbus import open_bus
    from motorbus.socketcand import SocketcandServer
    with SocketcandServer(open_bus("virtual:bench")) as server:
        print("connect to", server.host, server.port)

SocketCAN::

    from motorbus.socketcand import open_socketcan, socketcan_unavailable_reason
    if socketcan_unavailable_reason() is None:
        bus = open_socketcan("vcan0")
"""
from __future__ import annotations

from ._core import (  # noqa: F401
    SocketCanBus,
    SocketcandBus,
    SocketcandServer,
    open_socketcan,
    open_socketcand,
    socketcan_unavailable_reason,
)

__all__ = [
    "SocketCanBus",
    "SocketcandBus",
    "SocketcandServer",
    "open_socketcan",
    "open_socketcand",
    "socketcan_unavailable_reason",
]

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

from . import _core, registry
from ._core.can import (  # noqa: F401
    SocketCanBus, SocketcandBus, SocketcandServer, open_socketcan, open_socketcand, socketcan_unavailable_reason,
)

__all__ = [
    "SocketCanBus",
    "SocketcandBus",
    "SocketcandServer",
    "open_socketcan",
    "open_socketcand",
    "socketcan_unavailable_reason",
    "SOCKETCAND",
    "SOCKETCAN",
]


def _parse_socketcand(rest: str) -> dict:
    """``HOST:PORT/CHANNEL``."""
    hostport, slash, channel = rest.partition("/")
    host, colon, port = hostport.rpartition(":")
    if not slash or not colon or not channel:
        raise _core.InvalidArgument("expected socketcand:HOST:PORT/CHANNEL")
    try:
        return {"host": host, "port": int(port), "channel": channel}
    except ValueError:
        raise _core.InvalidArgument(f"port {port!r} is not an integer") from None


def _parse_socketcan(rest: str) -> dict:
    return {"iface": rest}


#: ``socketcand:HOST:PORT/CHANNEL`` for open_bus.
SOCKETCAND = registry.BusScheme("socketcand", "a socketcand server over TCP (remote buses, gateways)",
                                parse=_parse_socketcand, open=open_socketcand,
                                example="socketcand:127.0.0.1:29536/can0")
#: ``socketcan:IFACE`` for open_bus.
SOCKETCAN = registry.BusScheme("socketcan", "Linux AF_CAN raw socket (can0, vcan0)",
                               parse=_parse_socketcan, open=open_socketcan, example="socketcan:vcan0")

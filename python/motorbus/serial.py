"""Serial lines: termios ports, pty pairs, request/reply line framing and simulated line devices.

Example — a simulated device on a pty, talked to through the line link::

    from motorbus.serial import LineDevice, LineLink, PtyLineServer, open_port

    class Echo(LineDevice):
        def on_line(self, line: bytes) -> bytes:
            return b"E:" + line + b"\\r\\n"

    with PtyLineServer([Echo()]) as server:
        link = LineLink(open_port(server.slave_path, 115200))
        assert link.transact("hello") == b"E:hello"

A line behind a serial gateway (ser2net) opens the same way, by URL:
``open_port("socket://host:port")`` (raw TCP, the gateway sets the line) or
``open_port("rfc2217://host:port", 9600)`` (the baud is sent to the gateway);
see docs/serial.md, "Remote lines".

Everything that blocks releases the GIL.  Errors are the motorbus ones:
``TimeoutError`` (no complete reply in time), ``ReplyTooLong`` (a
``ProtocolError``; reply longer than ``max_line``), ``LinkDown`` (EOF/EIO, the
adapter is gone), ``ClosedError`` and ``InvalidArgument``.

The classes' own docstrings are written once, in the extension (bindings/serial.cpp).
"""
from __future__ import annotations

from ._core import ReplyTooLong  # noqa: F401
from ._core.serial import (  # noqa: F401
    EchoLineDevice, LineDevice, LineLink, Port, PtyLineServer, PtyPair, Rfc2217Port, TcpPort, TtyPort, open_port,
)

__all__ = [
    "EchoLineDevice",
    "LineDevice",
    "LineLink",
    "Port",
    "PtyLineServer",
    "PtyPair",
    "ReplyTooLong",
    "Rfc2217Port",
    "TcpPort",
    "TtyPort",
    "open_port",
]

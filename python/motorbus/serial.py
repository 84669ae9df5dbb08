"""Serial lines: termios ports, pty pairs, request/reply line framing and simulated line devices.

Example — a simulated device on a pty, talked to through the line link::

    from motorbus.serial import LineDevice, LineLink, PtyLineServer, open_port

    class Echo(LineDevice):
        def on_line(self, line: bytes) -> bytes:
            return b"E:" + line + b"\\r\\n"

    with PtyLineServer([Echo()]) as server:
        link = LineLink(open_port(server.slave_path, 115200))
        assert link.transact("hello") == b"E:hello"

Everything that blocks releases the GIL.  Errors are the motorbus ones:
``TimeoutError`` (no complete reply in time), ``ReplyTooLong`` (a
``ProtocolError``; reply longer than ``max_line``), ``LinkDown`` (EOF/EIO, the
adapter is gone), ``ClosedError`` and ``InvalidArgument``.
"""
from __future__ import annotations

from ._core import (  # noqa: F401
    EchoLineDevice,
    LineDevice,
    LineLink,
    Port,
    PtyLineServer,
    PtyPair,
    ReplyTooLong,
    TtyPort,
    open_port,
)

__all__ = [
    "EchoLineDevice",
    "LineDevice",
    "LineLink",
    "Port",
    "PtyLineServer",
    "PtyPair",
    "ReplyTooLong",
    "TtyPort",
    "open_port",
]

# Docstrings for the compiled classes live here so `help()` shows the contract
# in one place; the C++ headers (cpp/motorbus/serial/*.hpp) are the reference.
Port.__doc__ = """A bidirectional byte stream (a serial device or one side of a pty).

    write(data)                 blocks until all bytes are written; LinkDown if the peer is gone
    read(size=4096, timeout=None) -> bytes   b'' on timeout; timeout None = wait forever
    flush_input()               drops unread input
    drain()                     waits until written bytes left the UART (no-op on a pty)
    close()                     wakes blocked readers/writers, which raise ClosedError
"""

TtyPort.__doc__ = """A termios serial device in raw 8N1 mode: TtyPort(path, baud=0).

    baud=0 keeps the current speed.  Standard rates use the B* constants; any
    other rate (e.g. 250000) goes through termios2/BOTHER and raises
    InvalidArgument if the driver refuses it.  `.baud` reads/sets the speed.
"""

PtyPair.__doc__ = """A raw pseudo-terminal pair for tests.

    .port        our side (a Port)
    .slave_path  e.g. '/dev/pts/7', for a peer: serial.Serial(path), can.Bus('slcan', channel=path)
    open_slave(baud=0) -> TtyPort   a second motorbus port on the slave
    release_slave()  drop the pair's own hold on the slave: once every peer has
                     closed it, reads on .port raise LinkDown (an unplugged adapter)
"""

LineLink.__doc__ = """Request/reply line framing on a Port.

    LineLink(port, request_terminator="\\r", reply_terminators=["\\r\\n"], max_line=256,
             reply_timeout=0.5, flush_before_request=True, echo_suppression=False,
             turnaround=0.0)

    transact(request, timeout=None) -> bytes
        Drops stale input (flush_before_request), writes request + terminator,
        waits `turnaround` s (RS-485 direction switch), skips the exact echo of
        our own bytes (echo_suppression), then reads until ANY reply terminator,
        reassembling replies split across reads.  Returns the reply without its
        terminator.  timeout None = reply_timeout.  TimeoutError discards the
        partial reply; ReplyTooLong when the reply exceeds max_line (the rest is
        discarded up to the terminator).  Concurrent calls are serialized.
    send(request)              write without waiting (broadcasts)
    read_line(timeout=None) -> bytes | None   one line (unsolicited); None on timeout
    counters                   dict: bytes_in, bytes_out, requests, replies, timeouts,
                               stale_bytes, overlong_lines, echo_bytes, echo_mismatches
"""

LineDevice.__doc__ = """A simulated serial device; subclass it (call super().__init__()).

    on_line(line: bytes) -> bytes | str | None
        One request without its terminator; return the exact reply bytes,
        terminator included.  None/b'' = stay silent (not addressed).
        Exceptions are reported as unraisable and the device stays silent.
    request_terminator() -> bytes | str     default "\\r"
    max_request() -> int                    default 256
    on_overlong() -> bytes | str | None     reply to an over-long request (default silent)

    Called from the server thread with the GIL held.
"""

PtyLineServer.__doc__ = """Serves LineDevices on a pty, like drives on one RS-485 line.

    PtyLineServer(devices=[], baud=0, port=None)

    Every complete request line goes to EVERY device (each decides whether it
    is addressed); replies are written in device order.  Request lines longer
    than a device's max_request() get its on_overlong() reply, and the line
    resyncs at the next terminator.  baud > 0 paces both directions at 10 bit
    times per byte, so a pty behaves like a real line for benchmarks.  port=
    serves on an existing Port instead of a new pty (slave_path is then "").
    Use as a context manager or call close(); counters is a dict.
"""

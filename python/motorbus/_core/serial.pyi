from __future__ import annotations
import collections.abc
import motorbus._core.runtime
import typing
__all__: list[str] = ['EchoLineDevice', 'LineCounters', 'LineDevice', 'LineLink', 'LineServerCounters', 'Port', 'PtyLineServer', 'PtyPair', 'Rfc2217Port', 'TcpPort', 'TtyPort', 'open_port']
class LineCounters:
    """
    LineLink counters, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def bytes_in(self) -> int:
        """
        read from the port (echo and stale bytes included)
        """
    @property
    def bytes_out(self) -> int:
        """
        written, terminators included
        """
    @property
    def echo_bytes(self) -> int:
        """
        own bytes skipped by echo suppression
        """
    @property
    def echo_mismatches(self) -> int:
        """
        expected echo did not arrive as sent
        """
    @property
    def overlong_lines(self) -> int:
        """
        replies longer than max_line (ReplyTooLong)
        """
    @property
    def replies(self) -> int:
        """
        lines returned by transact()/read_line()
        """
    @property
    def requests(self) -> int:
        """
        transact() + send() calls that wrote
        """
    @property
    def stale_bytes(self) -> int:
        """
        discarded by the flush before a request
        """
    @property
    def timeouts(self) -> int:
        """
        transact() calls that got no complete reply
        """
class LineServerCounters:
    """
    PtyLineServer counters, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def bytes_in(self) -> int:
        ...
    @property
    def bytes_out(self) -> int:
        ...
    @property
    def device_errors(self) -> int:
        """
        a device broke its no-throw promise (reply dropped)
        """
    @property
    def dropped_replies(self) -> int:
        """
        the client stopped reading; reply not written
        """
    @property
    def lines(self) -> int:
        """
        complete request lines handed to the devices
        """
    @property
    def overlong_lines(self) -> int:
        """
        request lines longer than every device accepts
        """
    @property
    def replies(self) -> int:
        """
        non-empty replies written
        """
class Port:
    """
    A bidirectional byte stream (a serial device or one side of a pty).
    
        write(data)                 blocks until all bytes are written; LinkDown if the peer is gone
        read(size=4096, timeout=None) -> bytes   b'' on timeout; timeout None = wait forever
        flush_input()               drops unread input
        drain()                     waits until written bytes left the UART (no-op on a pty)
        close()                     wakes blocked readers/writers, which raise ClosedError
    """
    def __enter__(self) -> Port:
        ...
    def __exit__(self, *args) -> None:
        ...
    def close(self) -> None:
        ...
    def drain(self) -> None:
        ...
    def flush_input(self) -> None:
        ...
    def read(self, size: typing.SupportsInt | typing.SupportsIndex = 4096, timeout: typing.Any = None) -> bytes:
        """
        Returns what is available (b'' on timeout); waits up to `timeout` s for the first byte (None = forever). LinkDown on EOF/EIO.
        """
    def write(self, data: typing.Any) -> None:
        """
        Writes all bytes (blocking). LinkDown if the peer is gone.
        """
    @property
    def name(self) -> str:
        ...
class TtyPort(Port):
    """
    A termios serial device in raw 8N1 mode: TtyPort(path, baud=0).
    
        baud=0 keeps the current speed.  Standard rates use the B* constants; any
        other rate (e.g. 250000) goes through termios2/BOTHER and raises
        InvalidArgument if the driver refuses it.  `.baud` reads/sets the speed.
    """
    def __init__(self, path: str, baud: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def set_baud(self, baud: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_write_timeout(self, timeout: typing.Any) -> None:
        ...
    @property
    def baud(self) -> int:
        ...
    @baud.setter
    def baud(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def is_open(self) -> bool:
        ...
class PtyPair:
    """
    A raw pseudo-terminal pair for tests.
    
        .port        our side (a Port)
        .slave_path  e.g. '/dev/pts/7', for a peer: serial.Serial(path), can.Bus('slcan', channel=path)
        open_slave(baud=0) -> TtyPort   a second motorbus port on the slave
        release_slave()  drop the pair's own hold on the slave: once every peer has
                         closed it, reads on .port raise LinkDown (an unplugged adapter)
    """
    def __enter__(self) -> PtyPair:
        ...
    def __exit__(self, *args) -> None:
        ...
    def __init__(self) -> None:
        ...
    def close(self) -> None:
        ...
    def open_slave(self, baud: typing.SupportsInt | typing.SupportsIndex = 0) -> TtyPort:
        ...
    def release_slave(self) -> None:
        ...
    @property
    def port(self) -> TtyPort:
        ...
    @property
    def slave_path(self) -> str:
        ...
class TcpPort(Port):
    """
    A serial line behind a gateway, raw TCP: open_port("socket://host:port").
    
        Bytes pass unchanged; the gateway (e.g. ser2net's `accepter: tcp,...`) owns the
        line settings, so open_port's baud is ignored.  A dropped connection raises
        LinkDown naming host:port; close() wakes a blocked read with ClosedError.
    """
    @property
    def is_open(self) -> bool:
        ...
    @property
    def peer(self) -> str:
        """
        'host:port'
        """
class Rfc2217Port(TcpPort):
    """
    A serial line behind an RFC 2217 (Telnet COM-PORT-OPTION) gateway: open_port("rfc2217://host:port", baud).
    
        The baud and 8N1 are sent to the gateway (e.g. ser2net's `accepter:
        telnet(rfc2217),tcp,...`), which sets them on its serial port; each is
        waited for.  baud=0 asks the gateway for its current rate.  `.baud`
        reads the rate the gateway acknowledged and sets a new one.
    """
    def set_baud(self, baud: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def baud(self) -> int:
        ...
    @baud.setter
    def baud(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class LineLink:
    """
    Request/reply line framing on a Port.
    
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
        counters -> LineCounters   .bytes_in .bytes_out .requests .replies .timeouts
                                   .stale_bytes .overlong_lines .echo_bytes .echo_mismatches
    """
    def __init__(self, port: Port, request_terminator: typing.Any = '\r', reply_terminators: typing.Any = ['\r\n'], max_line: typing.SupportsInt | typing.SupportsIndex = 256, reply_timeout: typing.Any = 0.5, flush_before_request: bool = True, echo_suppression: bool = False, turnaround: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def read_line(self, timeout: typing.Any = None) -> typing.Any:
        """
        One line (e.g. unsolicited) or None on timeout; a partial line stays buffered.
        """
    def send(self, request: typing.Any) -> None:
        ...
    def set_trace(self, callback: typing.Any) -> None:
        """
        A protocol trace: callback(direction, data) with '>' and each request written (a list of byte values, without its terminator), '<' and each reply line read, '!' and a note when a request got no reply in time; on the transacting thread (it must not use this link).  None turns it off.
        """
    def transact(self, request: typing.Any, timeout: typing.Any = None) -> bytes:
        """
        Sends request + terminator and returns the reply without its terminator. timeout None = the link's reply_timeout.
        """
    def transact_async(self, request: typing.Any, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex, timeout: typing.Any = None) -> None:
        """
        transact() for an event loop: returns at once; the reply (bytes) or the error arrives in `completions` under `token`, from the link's own worker thread (motorbus.aio.transact awaits it).
        """
    @property
    def counters(self) -> LineCounters:
        """
        LineCounters (a snapshot)
        """
    @property
    def max_line(self) -> int:
        ...
    @property
    def port(self) -> Port:
        ...
    @property
    def reply_terminators(self) -> list:
        ...
    @property
    def request_terminator(self) -> bytes:
        ...
class LineDevice:
    """
    A simulated serial device; subclass it (call super().__init__()).
    
        on_line(line: bytes) -> bytes | str | None
            One request without its terminator; return the exact reply bytes,
            terminator included.  None/b'' = stay silent (not addressed).
            Exceptions are reported as unraisable and the device stays silent.
        request_terminator() -> bytes | str     default "\\r"
        max_request() -> int                    default 256
        on_overlong() -> bytes | str | None     reply to an over-long request (default silent)
    
        Called from the server thread with the GIL held.
    """
    def __init__(self) -> None:
        ...
    def max_request(self) -> int:
        ...
    def on_line(self, line: typing.Any) -> bytes:
        ...
    def on_overlong(self) -> bytes:
        ...
    def request_terminator(self) -> bytes:
        ...
class EchoLineDevice(LineDevice):
    """
    C++ device answering prefix + line + reply_terminator (benchmarks, smoke tests).
    """
    def __init__(self, prefix: typing.Any = '', reply_terminator: typing.Any = '\r\n', request_terminator: typing.Any = '\r') -> None:
        ...
class PtyLineServer:
    """
    Serves LineDevices on a pty, like drives on one RS-485 line.
    
        PtyLineServer(devices=[], baud=0, port=None)
    
        Every complete request line goes to EVERY device (each decides whether it
        is addressed); replies are written in device order.  Request lines longer
        than a device's max_request() get its on_overlong() reply, and the line
        resyncs at the next terminator.  baud > 0 paces both directions at 10 bit
        times per byte, so a pty behaves like a real line for benchmarks.  port=
        serves on an existing Port instead of a new pty (slave_path is then "").
        Use as a context manager or call close(); counters is a LineServerCounters.
    """
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def __init__(self, devices: collections.abc.Sequence[typing.Any] = [], baud: typing.SupportsInt | typing.SupportsIndex = 0, port: Port = None) -> None:
        ...
    def attach(self, device: typing.Any) -> None:
        ...
    def close(self) -> None:
        ...
    @property
    def baud(self) -> int:
        ...
    @property
    def counters(self) -> LineServerCounters:
        """
        LineServerCounters (a snapshot)
        """
    @property
    def enforce_baud(self) -> bool:
        """
        With baud > 0: requests sent at another rate arrive garbled (no device answers them).
        """
    @enforce_baud.setter
    def enforce_baud(self, arg1: bool) -> None:
        ...
    @property
    def running(self) -> bool:
        ...
    @property
    def slave_path(self) -> str:
        ...
def open_port(path: str, baud: typing.SupportsInt | typing.SupportsIndex = 0) -> Port:
    """
    Opens a serial device at `baud` (0 = keep the current speed), or a line behind a serial gateway:
    'socket://host:port' (raw TCP, baud ignored) or 'rfc2217://host:port' (baud sent to the gateway).
    """

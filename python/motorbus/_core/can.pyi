from __future__ import annotations
import collections.abc
import motorbus._core.runtime
import typing
__all__: list[str] = ['AsyncReceiver', 'AsyncReceiverCounters', 'Bus', 'BusCounters', 'ExternalBus', 'Frame', 'LogEntry', 'LogFormat', 'Recorder', 'SimulatedDevice', 'SlcanBus', 'SlcanDecoder', 'SlcanDecoderCounters', 'SlcanEvent', 'SlcanEventKind', 'SlcanServer', 'SlcanServerStats', 'SlcanStats', 'SocketCanBus', 'SocketcandBus', 'SocketcandParserStats', 'SocketcandServer', 'SocketcandServerStats', 'VirtualBus', 'open_slcan', 'open_socketcan', 'open_socketcand', 'open_virtual', 'parse_candump_line', 'play', 'read_log', 'slcan_encode', 'socketcan_unavailable_reason', 'wire_bits_worst_case']
class Frame:
    """
    A CAN frame. Invalid fields are refused at construction.
    """
    def __eq__(self, arg0: Frame) -> bool:
        ...
    def __hash__(self) -> int:
        ...
    def __init__(self, id: typing.SupportsInt | typing.SupportsIndex, data: typing.Any = b'', extended: bool = False, rtr: bool = False, dlc: typing.Any = None) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __str__(self) -> str:
        ...
    @property
    def data(self) -> bytes:
        ...
    @property
    def dlc(self) -> int:
        ...
    @property
    def extended(self) -> bool:
        ...
    @property
    def flags(self) -> int:
        ...
    @property
    def id(self) -> int:
        ...
    @property
    def is_error(self) -> bool:
        ...
    @property
    def is_fd(self) -> bool:
        ...
    @property
    def is_loopback(self) -> bool:
        ...
    @property
    def rtr(self) -> bool:
        ...
    @property
    def timestamp_ns(self) -> int:
        ...
    @timestamp_ns.setter
    def timestamp_ns(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class BusCounters:
    """
    A bus's counters (Bus.counters), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def bus_errors(self) -> int:
        """
        error frames / BEL / error states reported
        """
    @property
    def ignored(self) -> int:
        """
        well-formed input not used (status lines etc.)
        """
    @property
    def overruns(self) -> int:
        """
        adapter/medium reported overrun or line too long
        """
    @property
    def parse_errors(self) -> int:
        """
        malformed input from the medium, discarded
        """
    @property
    def rx_bits(self) -> int:
        """
        wire bits of the frames received (worst-case stuffing; own echoes left out)
        """
    @property
    def rx_dropped(self) -> int:
        """
        received frames dropped because the recv() queue was full
        """
    @property
    def rx_frames(self) -> int:
        """
        frames received from the medium
        """
    @property
    def tx_bits(self) -> int:
        """
        wire bits of the frames sent (worst-case stuffing)
        """
    @property
    def tx_dropped(self) -> int:
        """
        frames the medium lost (fault injection, adapter NACK)
        """
    @property
    def tx_frames(self) -> int:
        """
        frames handed to the medium
        """
class Bus:
    """
    A CAN bus endpoint (open one with open_bus).
    """
    def __aiter__(self) -> 'motorbus.bus.FrameStream':
        """
        ``async for frame in bus``: ``bus.frames()`` with its defaults.
        """
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def _cancel_wait(self, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        Withdraws a _recv_or_wait waiter: False when it already completed.
        """
    def _recv_or_wait(self, max: typing.SupportsInt | typing.SupportsIndex, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex) -> list[Frame]:
        """
        recv() for an event loop (Bus.arecv): up to max queued frames, or [] and a waiter completed with a list of Frames (or recv()'s error) under token.
        """
    def arecv(self, timeout: float | None = None) -> 'typing.Coroutine[typing.Any, typing.Any, typing.Optional[motorbus._core.can.Frame]]':
        """
        ``await bus.arecv(timeout=None)``: the awaitable twin of ``recv()`` -- the
            next frame of the same queue, through the same filters (``set_filters``),
            or None after ``timeout`` seconds (None: wait forever).  ClosedError /
            LinkDown as ``recv()``.  No thread waits: the bus's receive thread
            completes the wait on the loop's completion queue.
        """
    def arecv_many(self, max: int = 1024, timeout: float | None = None) -> 'typing.Coroutine[typing.Any, typing.Any, list[motorbus._core.can.Frame]]':
        """
        ``await bus.arecv_many(max=1024, timeout=None)``: the awaitable twin of
            ``recv_many()`` -- up to ``max`` frames, oldest first, as soon as there is
            one; [] after ``timeout``.
        """
    def asend(self, frame: 'motorbus._core.can.Frame', timeout: float = 1.0) -> 'typing.Coroutine[typing.Any, typing.Any, None]':
        """
        ``await bus.asend(frame, timeout=1.0)``: the awaitable twin of ``send()``.
        
            ``send()`` blocks while the medium is full (a virtual bus's transmit queue,
            a socketcand server that stops reading); here the frame is offered without
            waiting and, while the medium stays full, offered again after a short
            sleep of the task (0.5 ms, doubling to 10 ms) until ``timeout``: then
            TimeoutError, as ``send()``.  A medium with room costs no sleep.
        """
    def close(self) -> None:
        ...
    def frames(self, filters: typing.Any = None, queue: int = 1024, batch: int = 256) -> 'motorbus.bus.FrameStream':
        """
        ``bus.frames(filters=None, queue=1024, batch=256)``: a :class:`FrameStream`
            of this bus (an async iterator of Frames with its own filters and bounded queue).
        """
    def recv(self, timeout: typing.Any = None) -> Frame | None:
        ...
    def recv_many(self, max: typing.SupportsInt | typing.SupportsIndex = 1024, timeout: typing.Any = None) -> list[Frame]:
        """
        Up to max frames, oldest first: waits like recv() for the first, then takes what is already queued. An empty list after timeout.
        """
    def send(self, frame: Frame, timeout: typing.Any = 1.0) -> None:
        ...
    def set_filters(self, filters: typing.Any = None) -> None:
        ...
    def subscribe(self, callback: collections.abc.Callable, id: typing.Any = None, mask: typing.Any = None, extended: bool = False) -> int:
        """
        Call callback(frame) on the bus thread for matching frames; returns a handle.
        """
    def unsubscribe(self, handle: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def channel(self) -> str:
        ...
    @property
    def closed(self) -> bool:
        ...
    @property
    def counters(self) -> BusCounters:
        """
        BusCounters (a snapshot)
        """
    @property
    def state(self) -> str:
        ...
class VirtualBus(Bus):
    """
    Endpoint on an in-process virtual CAN bus.
    """
    def set_bus_off(self, off: bool = True) -> None:
        ...
    def set_faults(self, drop_every: typing.SupportsInt | typing.SupportsIndex = 0, drop_probability: typing.SupportsFloat | typing.SupportsIndex = 0.0, corrupt_probability: typing.SupportsFloat | typing.SupportsIndex = 0.0, delay: typing.SupportsFloat | typing.SupportsIndex = 0.0, seed: typing.SupportsInt | typing.SupportsIndex = 24301) -> None:
        """
        Faults applied to frames this endpoint sends (delay in seconds).
        """
    @property
    def bitrate(self) -> float:
        ...
class ExternalBus(Bus):
    """
    A bus fed by Python code (the python-can bridge is built on it).
    """
    def __init__(self, channel: str, send: collections.abc.Callable, close: typing.Any = None, receive_own: bool = False) -> None:
        ...
    def feed(self, frame: Frame) -> None:
        ...
    def feed_parse_error(self) -> None:
        ...
class AsyncReceiverCounters:
    """
    A frame stream's counters, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def overflows(self) -> int:
        """
        of those, dropped (the newest) with the queue full
        """
    @property
    def received(self) -> int:
        """
        frames that passed the filters
        """
    @property
    def wakeups(self) -> int:
        """
        completions pushed: one per burst the loop waited for
        """
class AsyncReceiver:
    """
    A bus's frames for an event loop (Bus.frames): its own subscription, filters and bounded queue.
    """
    def __init__(self, bus: Bus, filters: typing.Any = None, queue: typing.SupportsInt | typing.SupportsIndex = 1024) -> None:
        ...
    def close(self) -> None:
        ...
    def disarm(self) -> bool:
        ...
    def take(self, max: typing.SupportsInt | typing.SupportsIndex = 1024) -> list[Frame]:
        ...
    def take_or_arm(self, max: typing.SupportsInt | typing.SupportsIndex, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex) -> list[Frame]:
        """
        Up to max queued frames, or [] and armed: the next frames complete token as a list of Frames.
        """
    @property
    def capacity(self) -> int:
        ...
    @property
    def counters(self) -> AsyncReceiverCounters:
        ...
    @property
    def ended(self) -> bool:
        ...
    @property
    def queued(self) -> int:
        ...
class LogEntry:
    """
    One logged frame: time (s), channel, direction.
    """
    def __repr__(self) -> str:
        ...
    @property
    def channel(self) -> str:
        ...
    @property
    def frame(self) -> Frame:
        ...
    @property
    def rx(self) -> bool:
        ...
    @property
    def time(self) -> float:
        ...
class LogFormat:
    """
    Log file formats: candump (.log) and Vector ASC (.asc).
    
    Members:
    
      CANDUMP
    
      ASC
    """
    ASC: typing.ClassVar[LogFormat]
    CANDUMP: typing.ClassVar[LogFormat]
    __members__: typing.ClassVar[dict[str, LogFormat]]
    @typing.overload
    def __eq__(self, other: LogFormat) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: LogFormat) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class Recorder:
    """
    Writes every frame a bus receives to a candump or ASC log.
    """
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def __init__(self, bus: Bus, path: str, format: typing.Any = None, channel: str = 'can0') -> None:
        ...
    def log_sent(self, frame: Frame) -> None:
        ...
    def stop(self) -> None:
        ...
    @property
    def count(self) -> int:
        ...
class SimulatedDevice:
    """
    A simulated CAN device: attach(bus) serves it on a bus (kept alive until close()), close() takes it off (idempotent); attach again to serve it anew.  Also a context manager (closes on exit).
    """
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def attach(self, bus: Bus) -> None:
        """
        Serve on `bus`; the simulator keeps it alive until close().  InvalidArgument if already attached.
        """
    def close(self) -> None:
        """
        Off the bus (idempotent); attach() may follow.
        """
    def describe(self) -> str:
        """
        '<kind> sim <address>', as errors name it.
        """
    def power_cycle(self) -> None:
        """
        Power off and on: stored settings take effect, volatile ones are lost.
        """
    @property
    def attached(self) -> bool:
        ...
    @property
    def node_bit_rate(self) -> float:
        """
        bit/s the simulated controller runs at (0: takes the wire's; < 0: matches no wire)
        """
class SlcanStats:
    """
    SLCAN link statistics (SlcanBus.stats), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def ack_timeouts(self) -> int:
        """
        commands never answered within ack_timeout
        """
    @property
    def acks(self) -> int:
        """
        CR / z / Z answering a command
        """
    @property
    def echoes_suppressed(self) -> int:
        ...
    @property
    def last_status(self) -> int:
        """
        last `F` flags
        """
    @property
    def link_downs(self) -> int:
        ...
    @property
    def link_up(self) -> bool:
        ...
    @property
    def nacks(self) -> int:
        """
        BEL answering a command (or unsolicited)
        """
    @property
    def partial_lines_dropped(self) -> int:
        ...
    @property
    def reconnects(self) -> int:
        """
        successful re-opens after a link down
        """
    @property
    def serial_number(self) -> str:
        """
        last `N` reply
        """
    @property
    def status_replies(self) -> int:
        ...
    @property
    def version(self) -> str:
        """
        last `V` reply, e.g. 'V1013'
        """
class SlcanServerStats:
    """
    SlcanServer statistics, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def commands(self) -> int:
        ...
    @property
    def forward_dropped(self) -> int:
        """
        queue full or peer not reading
        """
    @property
    def forwarded(self) -> int:
        """
        bus frames written to the peer
        """
    @property
    def invalid_commands(self) -> int:
        """
        answered BEL because malformed/unknown/refused
        """
    @property
    def open(self) -> bool:
        ...
    @property
    def transmit_failed(self) -> int:
        """
        the bus refused them (answered BEL)
        """
    @property
    def transmitted(self) -> int:
        """
        frames put on the bus for the peer
        """
class SlcanDecoderCounters:
    """
    SlcanDecoder counters, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def dropped_partial(self) -> int:
        """
        partial lines dropped by discard_partial()
        """
    @property
    def frames(self) -> int:
        ...
    @property
    def ignored(self) -> int:
        """
        unknown or unsupported non-frame lines
        """
    @property
    def rx_errors(self) -> int:
        """
        malformed lines
        """
    @property
    def rx_over_errors(self) -> int:
        """
        lines longer than 32 bytes
        """
class SlcanEventKind:
    """
    What an adapter->host SLCAN line was.
    
    Members:
    
      FRAME
    
      OK
    
      NACK
    
      TX_ACK
    
      STATUS
    
      VERSION
    
      SERIAL
    
      ERROR_REPORT
    
      STATE_REPORT
    
      UNKNOWN
    
      MALFORMED
    
      OVERFLOW
    """
    ERROR_REPORT: typing.ClassVar[SlcanEventKind]
    FRAME: typing.ClassVar[SlcanEventKind]
    MALFORMED: typing.ClassVar[SlcanEventKind]
    NACK: typing.ClassVar[SlcanEventKind]
    OK: typing.ClassVar[SlcanEventKind]
    OVERFLOW: typing.ClassVar[SlcanEventKind]
    SERIAL: typing.ClassVar[SlcanEventKind]
    STATE_REPORT: typing.ClassVar[SlcanEventKind]
    STATUS: typing.ClassVar[SlcanEventKind]
    TX_ACK: typing.ClassVar[SlcanEventKind]
    UNKNOWN: typing.ClassVar[SlcanEventKind]
    VERSION: typing.ClassVar[SlcanEventKind]
    __members__: typing.ClassVar[dict[str, SlcanEventKind]]
    @typing.overload
    def __eq__(self, other: SlcanEventKind) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: SlcanEventKind) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class SlcanEvent:
    """
    One decoded adapter->host SLCAN line, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def error_bits(self) -> int:
        """
        ERROR_REPORT
        """
    @property
    def extended(self) -> bool:
        """
        TX_ACK: `Z` (extended)
        """
    @property
    def frame(self) -> Frame | None:
        """
        the frame (FRAME), else None
        """
    @property
    def kind(self) -> SlcanEventKind:
        ...
    @property
    def rx_errors(self) -> int:
        """
        STATE_REPORT
        """
    @property
    def state(self) -> str:
        """
        STATUS / STATE_REPORT: bus state, as Bus.state
        """
    @property
    def status(self) -> int:
        """
        STATUS: the `F` flags
        """
    @property
    def text(self) -> bytes:
        """
        the line's bytes (no terminator)
        """
    @property
    def timestamp_ms(self) -> int | None:
        """
        adapter timestamp of a FRAME (Z1), else None
        """
    @property
    def tx_errors(self) -> int:
        """
        STATE_REPORT
        """
class SlcanBus(Bus):
    """
    A CAN bus through an SLCAN (Lawicel) adapter on a serial port.
    """
    def flush_tx(self, timeout: typing.Any = 1.0) -> None:
        """
        Wait until the adapter answered every command (None = forever; Ctrl-C interrupts); ProtocolError if it refused frames.
        """
    def query_status(self, timeout: typing.Any = 1.0) -> int:
        """
        Send `F`, return the status flags (bus state is updated).
        """
    @property
    def link_up(self) -> bool:
        ...
    @property
    def stats(self) -> SlcanStats:
        """
        SlcanStats (a snapshot)
        """
class SlcanServer:
    """
    Serve a Bus as an SLCAN adapter on a new pty; SLCAN tools open `pty_path`.
    """
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def __init__(self, bus: Bus, queue_size: typing.SupportsInt | typing.SupportsIndex = 65536, version: str = 'V1013', serial_number: str = 'NMB01', bus_send_timeout: typing.SupportsFloat | typing.SupportsIndex = 0.1, port: typing.Any = None, baud: typing.SupportsInt | typing.SupportsIndex = 115200) -> None:
        """
        Serve `bus` on a new pty, or on the serial device `port` (a UART wired to an SLCAN host).
        """
    def close(self) -> None:
        ...
    @property
    def is_open(self) -> bool:
        ...
    @property
    def pty_path(self) -> typing.Any:
        ...
    @property
    def stats(self) -> SlcanServerStats:
        """
        SlcanServerStats (a snapshot)
        """
class SlcanDecoder:
    """
    Incremental adapter->host SLCAN decoder (bounded, never raises).
    """
    def __init__(self) -> None:
        ...
    def discard_partial(self) -> bool:
        ...
    def feed(self, data: bytes) -> list[SlcanEvent]:
        """
        Feed bytes; returns the decoded SlcanEvents.
        """
    @property
    def counters(self) -> SlcanDecoderCounters:
        """
        SlcanDecoderCounters (a snapshot)
        """
    @property
    def pending(self) -> int:
        ...
class SocketcandParserStats:
    """
    The socketcand parser's view (SocketcandBus.parser_stats), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def bad_elements(self) -> int:
        """
        complete elements refused
        """
    @property
    def discarded_bytes(self) -> int:
        """
        non-blank bytes outside any element
        """
    @property
    def elements(self) -> int:
        """
        well-formed elements delivered
        """
    @property
    def interrupted(self) -> int:
        """
        elements cut short by a new '<'
        """
    @property
    def overlong(self) -> int:
        """
        elements abandoned at the length cap
        """
class SocketcandServerStats:
    """
    SocketcandServer statistics, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def bad_elements(self) -> int:
        """
        malformed elements from clients
        """
    @property
    def bus_send_failures(self) -> int:
        """
        sends reported back with < error >
        """
    @property
    def bus_send_retries(self) -> int:
        ...
    @property
    def clients_accepted(self) -> int:
        ...
    @property
    def clients_active(self) -> int:
        ...
    @property
    def clients_refused(self) -> int:
        """
        over max_clients or unknown channel
        """
    @property
    def error_replies(self) -> int:
        """
        every < error ... > sent
        """
    @property
    def frames_to_bus(self) -> int:
        """
        client sends put on the bus
        """
    @property
    def frames_to_clients(self) -> int:
        """
        frame elements written to clients
        """
    @property
    def queue_drops(self) -> int:
        """
        frames dropped for slow clients
        """
    @property
    def timeouts(self) -> int:
        """
        connections closed by a timeout
        """
class SocketcandBus(Bus):
    """
    A CAN bus reached through a socketcand server (raw mode).
    """
    def recv(self, timeout: typing.Any = None) -> Frame | None:
        ...
    def send(self, frame: Frame, timeout: typing.Any = 1.0) -> None:
        ...
    @property
    def host(self) -> str:
        ...
    @property
    def last_server_error(self) -> str:
        ...
    @property
    def link_down_reason(self) -> str:
        ...
    @property
    def link_up(self) -> bool:
        ...
    @property
    def parser_stats(self) -> SocketcandParserStats:
        """
        SocketcandParserStats (a snapshot)
        """
    @property
    def port(self) -> int:
        ...
class SocketcandServer:
    """
    Serve a motorbus Bus over TCP with the socketcand protocol (raw mode). Each client is a node on the bus: its frames go to the bus and to the other clients.
    """
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def __init__(self, bus: Bus, host: str = '127.0.0.1', port: typing.SupportsInt | typing.SupportsIndex = 0, channel: str = '', max_clients: typing.SupportsInt | typing.SupportsIndex = 64, client_queue: typing.SupportsInt | typing.SupportsIndex = 4096, idle_timeout: typing.Any = None, element_timeout: typing.Any = 2.0, open_timeout: typing.Any = 10.0, bus_send_budget: typing.Any = 0.02) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def close(self) -> None:
        ...
    @property
    def client_drops(self) -> list[int]:
        ...
    @property
    def host(self) -> str:
        ...
    @property
    def port(self) -> int:
        ...
    @property
    def stats(self) -> SocketcandServerStats:
        """
        SocketcandServerStats (a snapshot)
        """
class SocketCanBus(Bus):
    """
    A Linux AF_CAN raw socket (can0, vcan0, ...).
    """
def open_slcan(path: str, bitrate: typing.SupportsInt | typing.SupportsIndex = 500000, timestamps: bool = False, echo_suppression: bool = False, listen_only: bool = False, wait_for_acks: bool = True, tx_window: typing.SupportsInt | typing.SupportsIndex = 16, ack_timeout: typing.SupportsFloat | typing.SupportsIndex = 1.0, open_timeout: typing.SupportsFloat | typing.SupportsIndex = 1.0, status_poll: typing.SupportsFloat | typing.SupportsIndex = 0.0, tty_baud: typing.SupportsInt | typing.SupportsIndex = 115200, btr: typing.Any = None, receive_own: bool = False, rx_queue_size: typing.SupportsInt | typing.SupportsIndex = 65536, tx_coalesce: typing.SupportsFloat | typing.SupportsIndex = 2e-05) -> SlcanBus:
    """
    Open an SLCAN adapter at `path` (C, Sn, [Z1], O) as a Bus; bitrate 0 keeps the adapter's rate (no Sn); reconnects after unplug.
    """
def open_socketcan(iface: str, receive_own: bool = False, rx_queue_size: typing.SupportsInt | typing.SupportsIndex = 65536, kernel_filters: typing.Any = None, error_frames: bool = True, fd: bool = False) -> SocketCanBus:
    """
    Open a SocketCAN interface. kernel_filters: python-can style dicts {'can_id', 'can_mask', 'extended'} applied in the kernel (CAN_RAW_FILTER).
    """
def open_socketcand(host: str, port: typing.SupportsInt | typing.SupportsIndex, channel: str, receive_own: bool = False, rx_queue_size: typing.SupportsInt | typing.SupportsIndex = 65536, connect_timeout: typing.Any = 3.0, handshake_timeout: typing.Any = 3.0, keepalive: typing.Any = 1.0, keepalive_misses: typing.SupportsInt | typing.SupportsIndex = 3, tcp_keepalive: bool = True, tx_buffer_bytes: typing.SupportsInt | typing.SupportsIndex = 262144) -> SocketcandBus:
    """
    Connect to a socketcand server and open CHANNEL in raw mode. keepalive: seconds between < echo > probes on an idle link (None = off); the link is declared down after keepalive_misses silent periods.
    """
def open_virtual(name: str, bitrate: typing.SupportsFloat | typing.SupportsIndex = 0.0, tx_queue: typing.SupportsInt | typing.SupportsIndex = 64, rx_queue_size: typing.SupportsInt | typing.SupportsIndex = 65536, receive_own: bool = False, rx_spin: typing.SupportsFloat | typing.SupportsIndex = 2e-05) -> VirtualBus:
    """
    Joins the in-process hub NAME.  rx_spin: seconds the endpoint's receive thread polls for the next frame before sleeping (0 = always sleep).
    """
def parse_candump_line(line: str) -> LogEntry | None:
    ...
def play(bus: Bus, entries: collections.abc.Sequence[LogEntry], speed: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> int:
    """
    Replays entries onto bus: speed 1.0 = original timing, 0 = as fast as possible.
    """
def read_log(path: str) -> tuple[list[LogEntry], int]:
    """
    Reads a candump (.log) or ASC (.asc) file: (entries, bad_line_count).
    """
def slcan_encode(frame: Frame, timestamp_ms: typing.Any = None) -> bytes:
    """
    The SLCAN line for `frame` (t/T/r/R, CR included).
    """
def socketcan_unavailable_reason() -> typing.Any:
    """
    None when AF_CAN raw sockets work on this machine, else why not.
    """
def wire_bits_worst_case(frame: Frame) -> int:
    """
    Bits a classic frame occupies on the wire with worst-case stuffing, incl. intermission.
    """

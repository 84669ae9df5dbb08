"""
motorbus C++ core
"""
from __future__ import annotations
import collections.abc
import enum
from motorbus import ArcusBadSspd
from motorbus import ArcusEnableRs485
from motorbus import ArcusError
from motorbus import ArcusIndexOutOfRange
from motorbus import ArcusMotorNotMoving
from motorbus import ArcusMoving
from motorbus import ArcusScvOn
from motorbus import ArcusSpeedOutOfRange
from motorbus import ArcusStateError
from motorbus import ArcusUnknownCommand
from motorbus import ClosedError
from motorbus import DmacCommandRejected
from motorbus import DmacUnknownCommand
from motorbus import DriveFault
from motorbus import InvalidArgument
from motorbus import LimitExceeded
from motorbus import LinkDown
from motorbus import MotorbusError
from motorbus import ProtocolError
from motorbus import ReplyTooLong
from motorbus import TimeoutError
from motorbus import UnitekCyclicLimit
from motorbus import UnitekFrameError
from motorbus import UnitekUnknownRegister
from motorbus.canopen import SdoAbortError
from motorbus.canopen import SdoProtocolError
from motorbus.canopen import SdoTimeout
import numpy
import numpy.typing
import typing
__all__: list[str] = ['ABORT_CODES', 'ARCUS_MAX_MOVE_DISTANCE', 'ARCUS_MAX_REPLY', 'ARCUS_MAX_REQUEST', 'ArcusBadSspd', 'ArcusClientBase', 'ArcusClientCounters', 'ArcusCommandInfo', 'ArcusEnableRs485', 'ArcusError', 'ArcusHomeMethod', 'ArcusHoming', 'ArcusHomingMethod', 'ArcusHomingOptions', 'ArcusIndexOutOfRange', 'ArcusMotion', 'ArcusMotorNotMoving', 'ArcusMoving', 'ArcusPhase', 'ArcusProfileParams', 'ArcusScvOn', 'ArcusSim', 'ArcusSpeedOutOfRange', 'ArcusSpeedWindow', 'ArcusStateError', 'ArcusUnknownCommand', 'Bus', 'BusCounters', 'Cia402Device', 'Cia402Homing', 'Cia402HomingParams', 'Cia402Host', 'Cia402ProfileParams', 'Cia402ProfilePosition', 'Cia402Sim', 'Clock', 'ClosedError', 'DataType', 'DmacClient', 'DmacClientCounters', 'DmacCommandRejected', 'DmacEndStops', 'DmacKeyword', 'DmacMotion', 'DmacPolarity', 'DmacPowerMode', 'DmacProfileParams', 'DmacRadix', 'DmacReadReply', 'DmacSensor', 'DmacSim', 'DmacSimState', 'DmacStopWhat', 'DmacStreamStats', 'DmacUnknownCommand', 'DmacVariableInfo', 'DmacVersionInfo', 'DriveFault', 'EchoLineDevice', 'EmcyConsumer', 'EmcyError', 'EmcyProducer', 'ExternalBus', 'Frame', 'HeartbeatConsumer', 'HeartbeatProducer', 'HeartbeatService', 'InvalidArgument', 'JitterStats', 'LimitExceeded', 'Limits', 'LineCounters', 'LineDevice', 'LineLink', 'LineServerCounters', 'LinkDown', 'LocalNode', 'LocalNodeCounters', 'LogEntry', 'LogFormat', 'MotionState', 'MotorConfig', 'MotorEvent', 'MotorEventKind', 'MotorModel', 'MotorbusError', 'NmtCommand', 'NmtMaster', 'NodeHealth', 'NodeInfo', 'ObjectDictionary', 'PdoCaptureSource', 'PdoConfig', 'PdoCounters', 'PdoLayout', 'PdoProcedure', 'PdoReceiver', 'PdoSender', 'PdoService', 'Pmc007ProfileParams', 'Pmc007Sim', 'Pmc007Storage', 'PollGroup', 'PollSource', 'PollStats', 'Port', 'Profile', 'ProtocolError', 'PtyLineServer', 'PtyPair', 'RampShape', 'RealClock', 'Recorder', 'ReplyTooLong', 'Rfc2217Port', 'SdoAbortError', 'SdoClient', 'SdoClientCounters', 'SdoProtocolError', 'SdoServerCounters', 'SdoTimeout', 'SimClock', 'SimulatedDevice', 'SlcanBus', 'SlcanDecoder', 'SlcanDecoderCounters', 'SlcanEvent', 'SlcanEventKind', 'SlcanServer', 'SlcanServerStats', 'SlcanStats', 'SnlActivity', 'SnlConfig', 'SocketCanBus', 'SocketcandBus', 'SocketcandParserStats', 'SocketcandServer', 'SocketcandServerStats', 'StepNLoop', 'SwitchConfig', 'SyncProducer', 'TcpPort', 'TimeoutError', 'TtyPort', 'UnitekAccess', 'UnitekCaptureSource', 'UnitekClient', 'UnitekClientCounters', 'UnitekCyclicLimit', 'UnitekFrameError', 'UnitekQuantity', 'UnitekRampParams', 'UnitekRegister', 'UnitekRegisterTable', 'UnitekScalings', 'UnitekSim', 'UnitekSimCounters', 'UnitekStream', 'UnitekUnknownRegister', 'Variable', 'VirtualBus', 'abort_text', 'arcus_acc_range', 'arcus_build_request', 'arcus_canopen_object_dictionary', 'arcus_canopen_objects', 'arcus_check_strict', 'arcus_commands', 'arcus_effective', 'arcus_max_acc_ms', 'arcus_parse_reply', 'arcus_poll_source', 'arcus_speed_windows', 'arcus_window_for_hspd', 'arcus_window_for_sspdm', 'cia402_decode_statusword', 'cia402_next_step', 'cia402_object_dictionary', 'cia402_objects', 'cia402_position_profile', 'cia402_quick_stop_profile', 'cia402_velocity_profile', 'decode_value', 'dmac_error_names', 'dmac_format_value', 'dmac_parse_read_reply', 'dmac_poll_source', 'dmac_position_profile', 'dmac_ramp_time', 'dmac_speed_profile', 'dmac_status_names', 'dmac_stream_interpolation', 'dmac_synchro', 'dmac_variable', 'emcy_code_text', 'emcy_decode', 'emcy_encode', 'encode_value', 'heartbeat_decode', 'heartbeat_encode', 'jerk_limited_durations', 'monotonic_ns', 'nmt_decode', 'nmt_encode', 'open_port', 'open_slcan', 'open_socketcan', 'open_socketcand', 'open_virtual', 'parse_candump_line', 'pdo_read_config', 'pdo_write_config', 'plan_jerk_limited', 'plan_jerk_limited_velocity', 'plan_straight_line', 'plan_synchronized', 'plan_synchronized_jerk_limited', 'plan_trapezoid', 'plan_velocity', 'play', 'pmc007_assemble', 'pmc007_convert_position', 'pmc007_disassemble', 'pmc007_eds', 'pmc007_gear_acceleration', 'pmc007_microsteps', 'pmc007_object_dictionary', 'pmc007_position_profile', 'pmc007_speed_profile', 'pmc007_storage', 'read_log', 'scan_network', 'sdo_poll_source', 'slcan_encode', 'socketcan_unavailable_reason', 'split_interpolation', 'sync_encode', 'synchronized_jerk_limited_durations', 'time_decode', 'time_encode', 'unitek_analog_command_num', 'unitek_bit_rate_for_btr', 'unitek_bit_timings', 'unitek_btr_for_bit_rate', 'unitek_capture_source', 'unitek_continuous_current_num', 'unitek_decode_from_drive', 'unitek_decode_to_drive', 'unitek_device_currents', 'unitek_effective_current_limit_num', 'unitek_encode_request', 'unitek_encode_write', 'unitek_poll_source', 'unitek_sim_default_table', 'unitek_speed_profile', 'wire_bits_worst_case']
class Clock:
    def cancel(self) -> None:
        ...
    def now(self) -> int:
        """
        Current time in ns.
        """
    def sleep_until(self, t_ns: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        Wait until clock time t_ns; False if cancel() ended the wait. Ctrl-C interrupts.
        """
    @property
    def simulated(self) -> bool:
        ...
class RealClock(Clock):
    def __init__(self) -> None:
        ...
class SimClock(Clock):
    def __init__(self, start_ns: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def advance(self, dt_ns: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set(self, t_ns: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class PollSource:
    """
    What one drive gives a PollGroup per sample (made by the drive kind's poll_fields).
    """
    def __repr__(self) -> str:
        ...
    @property
    def columns(self) -> int:
        ...
    @property
    def stale(self) -> int:
        """
        reads that found pushed data too old or missing (0 for sources that ask)
        """
class PollStats:
    """
    Counters and timing of one PollGroup (times in ns).
    """
    def __repr__(self) -> str:
        ...
    @property
    def error(self) -> str:
        """
        why the group stopped on its own ('' if it did not)
        """
    @property
    def error_type(self) -> str:
        """
        'LinkDown', 'TimeoutError'... ('' if none)
        """
    @property
    def late(self) -> int:
        """
        samples whose reads ran past the next deadline
        """
    @property
    def missed(self) -> int:
        """
        deadlines skipped entirely (NaN rows in the data)
        """
    @property
    def overflowed(self) -> int:
        """
        rows lost because the reader fell a ring behind
        """
    @property
    def period_error_max_ns(self) -> int:
        ...
    @property
    def period_error_p50_ns(self) -> int:
        ...
    @property
    def period_error_p99_ns(self) -> int:
        ...
    @property
    def period_ns(self) -> int:
        ...
    @property
    def read_time_max_ns(self) -> int:
        ...
    @property
    def read_time_p50_ns(self) -> int:
        ...
    @property
    def read_time_p99_ns(self) -> int:
        ...
    @property
    def realtime(self) -> bool:
        """
        SCHED_FIFO asked for and granted
        """
    @property
    def running(self) -> bool:
        ...
    @property
    def samples(self) -> int:
        """
        samples read
        """
    @property
    def stale(self) -> int:
        """
        capture sources' reads that found pushed data older than its period allows (or none yet)
        """
    @property
    def wake_latency_max_ns(self) -> int:
        ...
    @property
    def wake_latency_p50_ns(self) -> int:
        ...
    @property
    def wake_latency_p99_ns(self) -> int:
        ...
class PollGroup:
    """
    One poll thread: reads its sources every period into a preallocated ring.
    """
    def __init__(self, sources: collections.abc.Sequence[PollSource], period: typing.Any, capacity: typing.SupportsInt | typing.SupportsIndex = 65536, spin: typing.Any = 0.0, realtime: bool = False, priority: typing.SupportsInt | typing.SupportsIndex = 50, start_ns: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def start(self) -> None:
        ...
    def stop(self) -> None:
        ...
    def take(self) -> tuple[numpy.typing.NDArray[numpy.int64], numpy.typing.NDArray[numpy.int64], numpy.typing.NDArray[numpy.float64], int]:
        """
        The rows written since the last take(): (deadline index int64[n], t int64 ns[n], values float64[n, columns], m); only the first m rows are valid (m < n after an overflow).
        """
    @property
    def capacity(self) -> int:
        ...
    @property
    def columns(self) -> int:
        ...
    @property
    def running(self) -> bool:
        ...
    @property
    def stats(self) -> PollStats:
        ...
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
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def close(self) -> None:
        ...
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
class DataType:
    """
    CiA 301 basic data types (codes as in EDS files).
    
    Members:
    
      BOOLEAN
    
      INTEGER8
    
      INTEGER16
    
      INTEGER32
    
      UNSIGNED8
    
      UNSIGNED16
    
      UNSIGNED32
    
      REAL32
    
      VISIBLE_STRING
    
      OCTET_STRING
    
      UNICODE_STRING
    
      TIME_OF_DAY
    
      TIME_DIFFERENCE
    
      DOMAIN
    
      INTEGER24
    
      REAL64
    
      INTEGER40
    
      INTEGER48
    
      INTEGER56
    
      INTEGER64
    
      UNSIGNED24
    
      UNSIGNED40
    
      UNSIGNED48
    
      UNSIGNED56
    
      UNSIGNED64
    """
    BOOLEAN: typing.ClassVar[DataType]
    DOMAIN: typing.ClassVar[DataType]
    INTEGER16: typing.ClassVar[DataType]
    INTEGER24: typing.ClassVar[DataType]
    INTEGER32: typing.ClassVar[DataType]
    INTEGER40: typing.ClassVar[DataType]
    INTEGER48: typing.ClassVar[DataType]
    INTEGER56: typing.ClassVar[DataType]
    INTEGER64: typing.ClassVar[DataType]
    INTEGER8: typing.ClassVar[DataType]
    OCTET_STRING: typing.ClassVar[DataType]
    REAL32: typing.ClassVar[DataType]
    REAL64: typing.ClassVar[DataType]
    TIME_DIFFERENCE: typing.ClassVar[DataType]
    TIME_OF_DAY: typing.ClassVar[DataType]
    UNICODE_STRING: typing.ClassVar[DataType]
    UNSIGNED16: typing.ClassVar[DataType]
    UNSIGNED24: typing.ClassVar[DataType]
    UNSIGNED32: typing.ClassVar[DataType]
    UNSIGNED40: typing.ClassVar[DataType]
    UNSIGNED48: typing.ClassVar[DataType]
    UNSIGNED56: typing.ClassVar[DataType]
    UNSIGNED64: typing.ClassVar[DataType]
    UNSIGNED8: typing.ClassVar[DataType]
    VISIBLE_STRING: typing.ClassVar[DataType]
    __members__: typing.ClassVar[dict[str, DataType]]
    @typing.overload
    def __eq__(self, other: DataType) -> bool:
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
    def __ne__(self, other: DataType) -> bool:
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
class Variable:
    """
    One object-dictionary entry.
    """
    def __repr__(self) -> str:
        ...
    def add_change_listener(self, callback: collections.abc.Callable) -> int:
        ...
    def decode(self, data: bytes) -> typing.Any:
        """
        The Python value of `data` as this entry's type (int, float, bool, str or bytes).
        """
    def encode(self, value: typing.Any) -> bytes:
        """
        The little-endian bytes of `value` as this entry's type (InvalidArgument if it does not fit the type; the limits are the device's to enforce).
        """
    def remove_change_listener(self, handle: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def reset(self) -> None:
        ...
    def set_read_hook(self, hook: typing.Any) -> None:
        """
        hook(variable, current: bytes) -> None | new value | abort code; called on a remote read.
        """
    def set_write_hook(self, hook: typing.Any) -> None:
        """
        hook(variable, data: bytes) -> None | abort code; called before a remote write commits.
        """
    @property
    def access(self) -> str:
        ...
    @property
    def data_type(self) -> DataType:
        ...
    @property
    def default(self) -> typing.Any:
        ...
    @property
    def high_limit(self) -> typing.Any:
        ...
    @property
    def index(self) -> int:
        ...
    @property
    def low_limit(self) -> typing.Any:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def pdo_mappable(self) -> bool:
        ...
    @property
    def raw(self) -> bytes:
        """
        value as little-endian bytes
        """
    @raw.setter
    def raw(self, arg1: typing.Any) -> None:
        ...
    @property
    def size(self) -> int:
        """
        fixed size in bytes; 0 for strings/domains
        """
    @property
    def subindex(self) -> int:
        ...
    @property
    def value(self) -> typing.Any:
        """
        value as int/float/bool/str/bytes by type (local write: limits checked, no hooks)
        """
    @value.setter
    def value(self, arg1: typing.Any) -> None:
        ...
    @property
    def value_range(self) -> typing.Any:
        """
        (low, high) a write may carry: the limits, else the integer type's range; None for other types
        """
class ObjectDictionary:
    """
    Objects addressed by (index, subindex) or by name ('Record.Member', '0x1018:1').
    """
    @staticmethod
    def from_eds(path: str, node_id: typing.SupportsInt | typing.SupportsIndex = 0, warnings: typing.Any = None) -> ObjectDictionary:
        """
        Load an EDS/DCF file; entries it cannot represent are appended to `warnings`.
        """
    @staticmethod
    def from_eds_text(text: str, node_id: typing.SupportsInt | typing.SupportsIndex = 0, warnings: typing.Any = None) -> ObjectDictionary:
        ...
    def __contains__(self, arg0: typing.Any) -> bool:
        ...
    def __getitem__(self, arg0: typing.Any) -> Variable:
        ...
    def __init__(self) -> None:
        ...
    def __len__(self) -> int:
        ...
    def add_member(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, name: str, data_type: typing.Any, access: str = 'rw', pdo_mappable: bool = False, low: typing.Any = None, high: typing.Any = None, default: typing.Any = None, max_size: typing.SupportsInt | typing.SupportsIndex = 0) -> Variable:
        ...
    def add_record(self, index: typing.SupportsInt | typing.SupportsIndex, name: str, array: bool = False) -> None:
        ...
    def add_variable(self, index: typing.SupportsInt | typing.SupportsIndex, name: str, data_type: typing.Any, access: str = 'rw', pdo_mappable: bool = False, low: typing.Any = None, high: typing.Any = None, default: typing.Any = None, max_size: typing.SupportsInt | typing.SupportsIndex = 0) -> Variable:
        ...
    def indices(self) -> list[int]:
        ...
    def object_code(self, index: typing.SupportsInt | typing.SupportsIndex) -> typing.Any:
        """
        'VAR', 'RECORD' or 'ARRAY'; None when the index is not in the dictionary.
        """
    def object_name(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> typing.Any:
        ...
    def save_eds(self, path: str, dcf: bool = False) -> None:
        ...
    def subindices(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> list[int]:
        ...
    def to_eds(self, dcf: bool = False) -> str:
        ...
    @property
    def max_variable_size(self) -> int:
        ...
    @max_variable_size.setter
    def max_variable_size(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def node_id(self) -> int:
        ...
    @node_id.setter
    def node_id(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class SdoClientCounters:
    """
    Counters of one SDO client, across its transfers.
    """
    def __repr__(self) -> str:
        ...
    @property
    def aborts_received(self) -> int:
        """
        the server aborted
        """
    @property
    def aborts_sent(self) -> int:
        """
        we aborted (timeout, protocol error)
        """
    @property
    def fallbacks(self) -> int:
        """
        block refused, retried segmented
        """
    @property
    def foreign_responses(self) -> int:
        """
        initiate responses / aborts naming another object: another client's on the same COB-IDs, ignored
        """
    @property
    def ignored_frames(self) -> int:
        """
        responses while idle, duplicates
        """
    @property
    def retransmit_requests(self) -> int:
        """
        block: sub-blocks acknowledged short (lost frames)
        """
    @property
    def timeouts(self) -> int:
        ...
    @property
    def transfers(self) -> int:
        ...
class SdoServerCounters:
    """
    Counters of a LocalNode's SDO server.
    """
    def __repr__(self) -> str:
        ...
    @property
    def aborts_received(self) -> int:
        ...
    @property
    def aborts_sent(self) -> int:
        ...
    @property
    def dropped(self) -> int:
        """
        requests dropped while the mailbox was full (S18)
        """
    @property
    def ignored(self) -> int:
        """
        DLC 0, stray block segments, duplicates
        """
    @property
    def requests(self) -> int:
        ...
    @property
    def responses(self) -> int:
        """
        including aborts
        """
    @property
    def timeouts(self) -> int:
        ...
    @property
    def transfers_completed(self) -> int:
        ...
class LocalNodeCounters:
    """
    Counters of a LocalNode: its SDO server and NMT.
    """
    def __repr__(self) -> str:
        ...
    @property
    def nmt_commands(self) -> int:
        """
        applied
        """
    @property
    def nmt_ignored(self) -> int:
        """
        wrong DLC, other node, unknown command
        """
    @property
    def sdo(self) -> SdoServerCounters:
        ...
    @property
    def sdo_bad_dlc(self) -> int:
        """
        SDO requests with DLC != 8 dropped (sdo_require_dlc8)
        """
    @property
    def sdo_while_stopped(self) -> int:
        ...
class SdoClient:
    """
    SDO client for one node (requests 0x600+n, responses 0x580+n).
    """
    def __init__(self, bus: Bus, node_id: typing.SupportsInt | typing.SupportsIndex, timeout: typing.SupportsFloat | typing.SupportsIndex = 1.0, max_transfer: typing.SupportsInt | typing.SupportsIndex = 1048576, block_size: typing.SupportsInt | typing.SupportsIndex = 127, read_retries: typing.SupportsInt | typing.SupportsIndex = 0, request_id: typing.SupportsInt | typing.SupportsIndex = 0, response_id: typing.SupportsInt | typing.SupportsIndex = 0, block_fallback: bool = False, block_crc: bool = True) -> None:
        """
        block_crc: block transfers offer and require CRC-16 (a server answering without it is refused, abort 0x05040004); False for a server without CRC, whose block data is then unchecked.
        """
    def download(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, data: typing.Any, block: bool = False, segmented: bool = False) -> None:
        ...
    def read_domain(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0, block: bool = False) -> bytes:
        ...
    def read_f32(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> float:
        ...
    def read_f64(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> float:
        ...
    def read_i16(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def read_i32(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def read_i64(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def read_i8(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def read_string(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> str:
        ...
    def read_u16(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def read_u32(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def read_u64(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def read_u8(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int:
        ...
    def upload(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0, block: bool = False) -> bytes:
        ...
    def write_domain(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, data: typing.Any, block: bool = False) -> None:
        ...
    def write_f32(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def write_f64(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def write_i16(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_i32(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_i64(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_i8(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_string(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: str) -> None:
        ...
    def write_u16(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_u32(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_u64(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_u8(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def counters(self) -> SdoClientCounters:
        ...
    @property
    def node_id(self) -> int:
        ...
    @property
    def request_id(self) -> int:
        ...
    @property
    def response_id(self) -> int:
        ...
    @property
    def timeout(self) -> float:
        """
        Seconds per response; inf (or None) = wait forever (Ctrl-C still interrupts).
        """
    @timeout.setter
    def timeout(self, arg1: typing.Any) -> None:
        ...
class LocalNode:
    """
    A node we serve: SDO server on 0x600+n/0x580+n, boot-up, NMT slave.
    """
    nmt_state: str
    def __enter__(self) -> typing.Any:
        ...
    def __exit__(self, *args) -> None:
        ...
    def __init__(self, bus: Bus, node_id: typing.SupportsInt | typing.SupportsIndex, od: ObjectDictionary, sdo_timeout: typing.SupportsFloat | typing.SupportsIndex = 1.0, block_transfer: bool = True, send_boot_up: bool = True) -> None:
        ...
    def add_state_listener(self, callback: collections.abc.Callable) -> int:
        """
        callback(previous: str, now: str) on every NMT transition
        """
    def close(self) -> None:
        ...
    def remove_state_listener(self, handle: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def send_boot_up(self) -> None:
        ...
    @property
    def counters(self) -> LocalNodeCounters:
        ...
    @property
    def node_id(self) -> int:
        ...
    @property
    def od(self) -> ObjectDictionary:
        ...
class EmcyError:
    """
    One EMCY message as received (CiA 301).
    """
    def __repr__(self) -> str:
        ...
    @property
    def code(self) -> int:
        """
        emergency error code (EEC)
        """
    @property
    def data(self) -> bytes:
        """
        manufacturer-specific bytes (5)
        """
    @property
    def is_reset(self) -> bool:
        """
        EEC 0x0000: the node's errors are cleared
        """
    @property
    def node(self) -> int:
        ...
    @property
    def register(self) -> int:
        """
        error register (0x1001) as sent
        """
    @property
    def short(self) -> bool:
        """
        the frame had fewer than 8 bytes (missing ones read as 0)
        """
    @property
    def text(self) -> str:
        ...
    @property
    def timestamp_ns(self) -> int:
        ...
class NodeHealth:
    """
    What a heartbeat consumer knows about one node.
    """
    def __repr__(self) -> str:
        ...
    @property
    def alive(self) -> bool:
        """
        heard within the consumer time
        """
    @property
    def boot_ups(self) -> int:
        ...
    @property
    def heartbeats(self) -> int:
        ...
    @property
    def last_seen_ns(self) -> int:
        ...
    @property
    def lost(self) -> bool:
        """
        timed out and not heard since
        """
    @property
    def node(self) -> int:
        ...
    @property
    def raw_state(self) -> int:
        ...
    @property
    def state(self) -> str:
        ...
    @property
    def timeouts(self) -> int:
        ...
class JitterStats:
    """
    SYNC period error (actual - nominal) over the last periods.
    """
    def __repr__(self) -> str:
        ...
    @property
    def count(self) -> int:
        """
        periods measured
        """
    @property
    def max_abs_ns(self) -> float:
        ...
    @property
    def max_ns(self) -> float:
        ...
    @property
    def mean_ns(self) -> float:
        ...
    @property
    def min_ns(self) -> float:
        ...
    @property
    def p99_abs_ns(self) -> float:
        """
        99th percentile of the error's magnitude
        """
class PdoCounters:
    """
    Counters of a served node's PDO engine.
    """
    def __repr__(self) -> str:
        ...
    @property
    def collisions(self) -> int:
        ...
    @property
    def rpdo_applied(self) -> int:
        ...
    @property
    def rpdo_ignored(self) -> int:
        ...
    @property
    def rpdo_length_errors(self) -> int:
        ...
    @property
    def rtr_ignored(self) -> int:
        ...
    @property
    def sync_errors(self) -> int:
        ...
    @property
    def sync_received(self) -> int:
        ...
    @property
    def tpdo_sent(self) -> int:
        ...
class PdoConfig:
    """
    A PDO's communication parameters and mapping as read from a device.
    """
    def __repr__(self) -> str:
        ...
    @property
    def cob_id(self) -> int | None:
        ...
    @property
    def enabled(self) -> bool:
        ...
    @property
    def event_timer_ms(self) -> int | None:
        ...
    @property
    def inhibit_100us(self) -> int | None:
        ...
    @property
    def mapping(self) -> list:
        """
        [(index, subindex, bits), ...]
        """
    @property
    def number(self) -> int:
        ...
    @property
    def sync_start(self) -> int | None:
        ...
    @property
    def tpdo(self) -> bool:
        ...
    @property
    def transmission_type(self) -> int | None:
        ...
class NodeInfo:
    """
    A node found by scan_network().
    """
    def __repr__(self) -> str:
        ...
    @property
    def device_type(self) -> int | None:
        """
        0x1000
        """
    @property
    def device_type_abort(self) -> int | None:
        """
        abort code when 0x1000 was refused
        """
    @property
    def heard_boot_up(self) -> bool:
        ...
    @property
    def heard_heartbeat(self) -> bool:
        ...
    @property
    def node(self) -> int:
        ...
    @property
    def product_code(self) -> int | None:
        ...
    @property
    def profile(self) -> int | None:
        """
        device profile number (402 for drives) from 0x1000's low 16 bits
        """
    @property
    def revision(self) -> int | None:
        ...
    @property
    def sdo_answered(self) -> bool:
        """
        any SDO reply (value or abort)
        """
    @property
    def serial_number(self) -> int | None:
        ...
    @property
    def state(self) -> str:
        ...
    @property
    def vendor_id(self) -> int | None:
        ...
class NmtCommand(enum.IntEnum):
    """
    NMT command specifiers (CiA 301).
    """
    ENTER_PRE_OPERATIONAL: typing.ClassVar[NmtCommand]
    RESET_COMMUNICATION: typing.ClassVar[NmtCommand]
    RESET_NODE: typing.ClassVar[NmtCommand]
    START: typing.ClassVar[NmtCommand]
    STOP: typing.ClassVar[NmtCommand]
    @classmethod
    def __new__(cls, value):
        ...
    def __format__(self, format_spec):
        ...
class PdoProcedure:
    """
    How pdo_write_config writes a PDO.
    
    Members:
    
      CIA301 : disable, parameters, clear sub0, entries, set sub0, enable
    
      DIRECT : COB-ID, parameters, sub0 = n, entries (no disable/enable)
    """
    CIA301: typing.ClassVar[PdoProcedure]
    DIRECT: typing.ClassVar[PdoProcedure]
    __members__: typing.ClassVar[dict[str, PdoProcedure]]
    @typing.overload
    def __eq__(self, other: PdoProcedure) -> bool:
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
    def __ne__(self, other: PdoProcedure) -> bool:
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
class NmtMaster:
    def __init__(self, bus: Bus, own_node_id: typing.SupportsInt | typing.SupportsIndex | None = None) -> None:
        ...
    def raw_state(self, node: typing.SupportsInt | typing.SupportsIndex) -> int | None:
        ...
    @typing.overload
    def send(self, command: NmtCommand, node: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def send(self, command: typing.SupportsInt | typing.SupportsIndex, node: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_callback(self, callback: typing.Any) -> None:
        ...
    def set_state(self, node: typing.SupportsInt | typing.SupportsIndex, state: str) -> None:
        ...
    def state(self, node: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def wait_for_boot(self, node: typing.SupportsInt | typing.SupportsIndex, timeout: typing.Any = 1.0) -> bool:
        ...
    def wait_for_heartbeat(self, node: typing.SupportsInt | typing.SupportsIndex, timeout: typing.Any = 1.0) -> str | None:
        ...
    def wait_for_state(self, node: typing.SupportsInt | typing.SupportsIndex, state: str, timeout: typing.Any = 1.0) -> bool:
        ...
    @property
    def foreign_commands_ignored(self) -> int:
        ...
class HeartbeatConsumer:
    """
    Per-node heartbeat supervision: started / lost / back / reset / state events.
    """
    def __init__(self, bus: Bus, clock: Clock = None) -> None:
        ...
    def forget(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def health(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> NodeHealth:
        ...
    def monitor(self, node: typing.SupportsInt | typing.SupportsIndex, timeout: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def process(self, now_ns: typing.SupportsInt | typing.SupportsIndex | None = None) -> int:
        ...
    def set_callback(self, callback: typing.Any) -> None:
        """
        callback(node, event, state); events: started, lost, back, reset, state-changed, unknown-state.
        """
    def start(self) -> None:
        ...
    def stop(self) -> None:
        ...
    @property
    def ignored_frames(self) -> int:
        ...
class HeartbeatProducer:
    def __init__(self, bus: Bus, node: typing.SupportsInt | typing.SupportsIndex, period: typing.SupportsFloat | typing.SupportsIndex, state: typing.Any = 'OPERATIONAL', clock: Clock = None) -> None:
        ...
    def process(self, now_ns: typing.SupportsInt | typing.SupportsIndex | None = None) -> int:
        ...
    def send_boot_up(self) -> None:
        ...
    def start(self) -> None:
        ...
    def stop(self) -> None:
        ...
    @property
    def send_failures(self) -> int:
        """
        heartbeats the bus refused (closed, full, link down) while started
        """
    @property
    def sent(self) -> int:
        ...
class EmcyConsumer:
    """
    Collects EMCY messages: bounded history and active codes per node.
    """
    def __init__(self, bus: Bus, history: typing.SupportsInt | typing.SupportsIndex = 32) -> None:
        ...
    def active(self, node: typing.SupportsInt | typing.SupportsIndex) -> list[int]:
        ...
    def clear(self, node: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def history(self, node: typing.SupportsInt | typing.SupportsIndex) -> list:
        ...
    def set_callback(self, callback: typing.Any) -> None:
        ...
    def wait(self, node: typing.SupportsInt | typing.SupportsIndex = 0, timeout: typing.Any = 1.0) -> typing.Any:
        ...
    @property
    def ignored_frames(self) -> int:
        ...
    @property
    def received(self) -> int:
        ...
class EmcyProducer:
    def __init__(self, bus: Bus, node: typing.SupportsInt | typing.SupportsIndex, inhibit_100us: typing.SupportsInt | typing.SupportsIndex = 0, queue_limit: typing.SupportsInt | typing.SupportsIndex = 16, clock: Clock = None) -> None:
        ...
    def process(self, now_ns: typing.SupportsInt | typing.SupportsIndex | None = None) -> int:
        ...
    def report(self, code: typing.SupportsInt | typing.SupportsIndex, register: typing.SupportsInt | typing.SupportsIndex = 0, data: bytes = b'') -> bool:
        ...
    def start(self) -> None:
        ...
    def stop(self) -> None:
        ...
    @property
    def dropped(self) -> int:
        ...
    @property
    def pending(self) -> int:
        ...
    @property
    def sent(self) -> int:
        ...
class SyncProducer:
    """
    SYNC on a C++ thread; jitter() reports the period error statistics.
    """
    def __init__(self, bus: Bus, period: typing.SupportsFloat | typing.SupportsIndex, counter_overflow: typing.SupportsInt | typing.SupportsIndex = 0, cob_id: typing.SupportsInt | typing.SupportsIndex = 128) -> None:
        ...
    def jitter(self) -> JitterStats:
        ...
    def reset_stats(self) -> None:
        ...
    def start(self, realtime: bool = False) -> None:
        """
        realtime=True asks for SCHED_FIFO; see realtime_granted.
        """
    def stop(self) -> None:
        ...
    @property
    def realtime_granted(self) -> bool:
        ...
    @property
    def running(self) -> bool:
        ...
    @property
    def sent(self) -> int:
        ...
class PdoLayout:
    """
    A compiled PDO mapping: bit-exact pack/unpack (CiA 301, little-endian).
    """
    def __init__(self, entries: collections.abc.Iterable) -> None:
        ...
    def offset(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def pack(self, values: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> bytes:
        """
        Values are ints (negative ones in two's complement of their width).
        """
    def pack_unsigned(self, values: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> bytes:
        ...
    def unpack(self, data: bytes) -> list:
        """
        Signed entries (4th tuple item True) are sign-extended.
        """
    @property
    def entries(self) -> list:
        ...
    @property
    def length(self) -> int:
        ...
    @property
    def total_bits(self) -> int:
        ...
class PdoReceiver:
    """
    Receives a device's TPDO on the bus and keeps the latest values.
    """
    def __init__(self, bus: Bus, cob_id: typing.SupportsInt | typing.SupportsIndex, entries: collections.abc.Iterable) -> None:
        ...
    def request(self) -> None:
        ...
    def set_callback(self, callback: typing.Any) -> None:
        """
        callback(values, timestamp_ns) on the bus thread.
        """
    def value(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> int | None:
        ...
    def wait_newer(self, after: typing.SupportsInt | typing.SupportsIndex, timeout: typing.Any = 1.0) -> int | None:
        ...
    @property
    def received(self) -> int:
        ...
    @property
    def short_frames(self) -> int:
        ...
    @property
    def values(self) -> list[int]:
        ...
class PdoSender:
    def __init__(self, bus: Bus, cob_id: typing.SupportsInt | typing.SupportsIndex, entries: collections.abc.Iterable) -> None:
        ...
    def send(self, values: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], timeout: typing.Any = 1.0) -> None:
        ...
class Cia402Host:
    """
    CiA 402 power state machine and PP/PV/HM handshakes, driven from the host.
    """
    def __init__(self, sdo: typing.Any, node: typing.SupportsInt | typing.SupportsIndex, timeout: typing.SupportsFloat | typing.SupportsIndex = 2.0, poll: typing.SupportsFloat | typing.SupportsIndex = 0.005) -> None:
        ...
    def fault_reset(self) -> None:
        ...
    def go_to(self, state: str) -> None:
        ...
    def home(self, method: typing.SupportsInt | typing.SupportsIndex | None = None, timeout: typing.Any = None) -> None:
        ...
    def move_to(self, target: typing.SupportsInt | typing.SupportsIndex, relative: bool = False, immediate: bool = True) -> None:
        ...
    def quick_stop(self) -> None:
        ...
    def set_mode(self, mode: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_velocity(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def use_statusword_pdo(self, receiver: PdoReceiver) -> None:
        """
        Wait on this TPDO receiver's statusword (0x6041 must be mapped); None = poll over SDO.
        """
    def wait_statusword(self, mask: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex, timeout: typing.Any = None) -> int:
        ...
    def wait_target_reached(self, timeout: typing.Any = None) -> None:
        ...
    def write_controlword(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def mode(self) -> int:
        ...
    @property
    def state(self) -> str:
        ...
    @property
    def statusword(self) -> int:
        ...
class Cia402Device:
    """
    Device-side CiA 402 state machine for simulators.
    """
    def __init__(self) -> None:
        ...
    def fault(self, error_code: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def fault_reaction_done(self) -> None:
        ...
    def loss_of_master(self) -> int:
        ...
    def motion_stopped(self) -> None:
        ...
    def on_controlword(self, controlword: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def set_abort_connection_option(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def set_mode(self, mode: typing.SupportsInt | typing.SupportsIndex) -> int:
        """
        0 or the SDO abort code (0x06090030).
        """
    def set_quick_stop_option(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def set_status_bits(self, mask: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_supported_modes(self, arg0: collections.abc.Set[typing.SupportsInt | typing.SupportsIndex]) -> None:
        ...
    @property
    def controlword(self) -> int:
        ...
    @property
    def drive_enabled(self) -> bool:
        ...
    @property
    def last_error_code(self) -> int:
        ...
    @property
    def mode(self) -> int:
        ...
    @property
    def state(self) -> str:
        ...
    @property
    def statusword(self) -> int:
        ...
class PdoService:
    """
    The PDO engine of a LocalNode: 0x1400-0x1BFF in its dictionary, TPDOs/RPDOs on its bus.
    """
    def __init__(self, node: LocalNode, rpdos: typing.SupportsInt | typing.SupportsIndex = 4, tpdos: typing.SupportsInt | typing.SupportsIndex = 4, max_mapped: typing.SupportsInt | typing.SupportsIndex = 8, strict: bool = True, sync_window_us: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def cob_id(self, tpdo: bool, number: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def mapping(self, tpdo: bool, number: typing.SupportsInt | typing.SupportsIndex) -> list:
        ...
    def notify_change(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def set_rpdo_timeout_callback(self, callback: typing.Any) -> None:
        """
        callback(rpdo_number) when an RPDO's event timer expires (P11).
        """
    def trigger_tpdo(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def counters(self) -> PdoCounters:
        ...
class HeartbeatService:
    """
    Heartbeat producer (0x1017) and consumer (0x1016) of a LocalNode; EMCY 0x8130 and 0x1029 on loss.
    """
    def __init__(self, node: LocalNode, consumer_entries: typing.SupportsInt | typing.SupportsIndex = 4, producer_ms: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def health(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> NodeHealth:
        ...
    def set_lost_callback(self, callback: typing.Any) -> None:
        """
        callback(node) when a consumed heartbeat is lost (e.g. Cia402Device.loss_of_master).
        """
    @property
    def heartbeats_sent(self) -> int:
        ...
class PdoCaptureSource(PollSource):
    """
    A PollSource taking the latest values of TPDOs (columns: arrival ns, values).
    """
    def __init__(self, bus: Bus, node: typing.SupportsInt | typing.SupportsIndex, tpdos: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, collections.abc.Iterable]], columns: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex]], max_age: typing.Any) -> None:
        """
        tpdos: [(cob_id, [(index, sub, bits, signed)])]; columns: [(tpdo i, entry j)] in row order; max_age (s): older data counts as stale.
        """
    def close(self) -> None:
        """
        Stops listening.
        """
    @property
    def received(self) -> int:
        ...
    @property
    def short_frames(self) -> int:
        ...
class MotionState:
    def __init__(self, p: typing.SupportsFloat | typing.SupportsIndex = 0.0, v: typing.SupportsFloat | typing.SupportsIndex = 0.0, a: typing.SupportsFloat | typing.SupportsIndex = 0.0, j: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def a(self) -> float:
        ...
    @a.setter
    def a(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def j(self) -> float:
        ...
    @j.setter
    def j(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def p(self) -> float:
        ...
    @p.setter
    def p(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def v(self) -> float:
        ...
    @v.setter
    def v(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Limits:
    def __init__(self, max_velocity: typing.SupportsFloat | typing.SupportsIndex, max_acceleration: typing.SupportsFloat | typing.SupportsIndex, max_deceleration: typing.SupportsFloat | typing.SupportsIndex = 0.0, max_jerk: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    @property
    def max_acceleration(self) -> float:
        ...
    @max_acceleration.setter
    def max_acceleration(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_deceleration(self) -> float:
        ...
    @max_deceleration.setter
    def max_deceleration(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_jerk(self) -> float:
        ...
    @max_jerk.setter
    def max_jerk(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_velocity(self) -> float:
        ...
    @max_velocity.setter
    def max_velocity(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class RampShape:
    """
    Members:
    
      TRAPEZOID
    
      SCURVE
    
      SIN2
    """
    SCURVE: typing.ClassVar[RampShape]
    SIN2: typing.ClassVar[RampShape]
    TRAPEZOID: typing.ClassVar[RampShape]
    __members__: typing.ClassVar[dict[str, RampShape]]
    @typing.overload
    def __eq__(self, other: RampShape) -> bool:
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
    def __ne__(self, other: RampShape) -> bool:
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
class Profile:
    """
    A planned motion: position/velocity/acceleration/jerk at any time.
    """
    def acceleration(self, t: typing.SupportsFloat | typing.SupportsIndex) -> float:
        ...
    def at(self, t: typing.SupportsFloat | typing.SupportsIndex) -> tuple:
        """
        (p, v, a, j) at time t (s).
        """
    def first_crossing(self, level: typing.SupportsFloat | typing.SupportsIndex, t_from: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> float:
        ...
    def jerk(self, t: typing.SupportsFloat | typing.SupportsIndex) -> float:
        ...
    def max_abs_acceleration(self) -> float:
        ...
    def max_abs_jerk(self) -> float:
        ...
    def max_abs_velocity(self) -> float:
        ...
    def position(self, t: typing.SupportsFloat | typing.SupportsIndex) -> float:
        ...
    def sample(self, n: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 5]"]:
        """
        n x 5 array: t, p, v, a, j over [0, duration].
        """
    def sample_at(self, t: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 5]"]:
        ...
    def segments(self) -> list:
        ...
    def step_times(self, t0_ns: typing.SupportsInt | typing.SupportsIndex = 0, max_steps: typing.SupportsInt | typing.SupportsIndex = 100000000) -> tuple[numpy.typing.NDArray[numpy.int64], numpy.typing.NDArray[numpy.int8]]:
        """
        Integer step times (ns, int64) and directions (int8) for positions in steps.
        """
    def step_times_seconds(self, max_steps: typing.SupportsInt | typing.SupportsIndex = 100000000) -> numpy.typing.NDArray[numpy.float64]:
        ...
    def velocity(self, t: typing.SupportsFloat | typing.SupportsIndex) -> float:
        ...
    @property
    def duration(self) -> float:
        ...
    @property
    def end_position(self) -> float:
        ...
    @property
    def final_velocity(self) -> float:
        ...
    @property
    def segment_count(self) -> int:
        ...
    @property
    def start_position(self) -> float:
        ...
class SnlConfig:
    enabled: bool
    def __init__(self) -> None:
        ...
    @property
    def error_range(self) -> int:
        ...
    @error_range.setter
    def error_range(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def idle_tolerance(self) -> int:
        ...
    @idle_tolerance.setter
    def idle_tolerance(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def max_attempts(self) -> int:
        ...
    @max_attempts.setter
    def max_attempts(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def ratio(self) -> float:
        ...
    @ratio.setter
    def ratio(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tolerance(self) -> int:
        ...
    @tolerance.setter
    def tolerance(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class SnlActivity:
    """
    What kind of motion StepNLoop.begin() starts.
    
    Members:
    
      MOVE
    
      JOG
    
      HOME
    
      ZHOME
    
      LIMIT_HOME
    
      STOP
    
      ABORT
    """
    ABORT: typing.ClassVar[SnlActivity]
    HOME: typing.ClassVar[SnlActivity]
    JOG: typing.ClassVar[SnlActivity]
    LIMIT_HOME: typing.ClassVar[SnlActivity]
    MOVE: typing.ClassVar[SnlActivity]
    STOP: typing.ClassVar[SnlActivity]
    ZHOME: typing.ClassVar[SnlActivity]
    __members__: typing.ClassVar[dict[str, SnlActivity]]
    @typing.overload
    def __eq__(self, other: SnlActivity) -> bool:
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
    def __ne__(self, other: SnlActivity) -> bool:
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
class StepNLoop:
    def __init__(self, config: SnlConfig = ...) -> None:
        ...
    @typing.overload
    def begin(self, activity: SnlActivity) -> bool:
        ...
    @typing.overload
    def begin(self, activity: str) -> bool:
        """
        The activity by name: 'move', 'jog', 'home', 'zhome', 'limit_home', 'stop', 'abort'.
        """
    def clear(self) -> None:
        ...
    def configure(self, arg0: SnlConfig) -> None:
        ...
    def idle_check(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> tuple[int, float, bool]:
        ...
    def limit_hit(self) -> None:
        ...
    def monitor(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> tuple[int, float, bool]:
        ...
    def motion_done(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> tuple[int, float, bool]:
        ...
    @property
    def attempts(self) -> int:
        ...
    @property
    def status(self) -> int:
        ...
    @property
    def status_name(self) -> str:
        ...
class Cia402ProfileParams:
    def __init__(self, profile_velocity: typing.SupportsFloat | typing.SupportsIndex = 1000.0, profile_acceleration: typing.SupportsFloat | typing.SupportsIndex = 10000.0, profile_deceleration: typing.SupportsFloat | typing.SupportsIndex = 10000.0, quick_stop_deceleration: typing.SupportsFloat | typing.SupportsIndex = 100000.0, motion_profile_type: typing.SupportsInt | typing.SupportsIndex = 0, max_profile_velocity: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    @property
    def max_profile_velocity(self) -> float:
        ...
    @max_profile_velocity.setter
    def max_profile_velocity(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def motion_profile_type(self) -> int:
        ...
    @motion_profile_type.setter
    def motion_profile_type(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def profile_acceleration(self) -> float:
        ...
    @profile_acceleration.setter
    def profile_acceleration(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def profile_deceleration(self) -> float:
        ...
    @profile_deceleration.setter
    def profile_deceleration(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def profile_velocity(self) -> float:
        ...
    @profile_velocity.setter
    def profile_velocity(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quick_stop_deceleration(self) -> float:
        ...
    @quick_stop_deceleration.setter
    def quick_stop_deceleration(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Cia402ProfilePosition:
    def __init__(self, params: Cia402ProfileParams = ..., position: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def halt(self, t: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def new_setpoint(self, t: typing.SupportsFloat | typing.SupportsIndex, target: typing.SupportsFloat | typing.SupportsIndex, relative: bool = False, change_immediately: bool = False, change_on_setpoint: bool = False) -> bool:
        ...
    def target_reached(self, t: typing.SupportsFloat | typing.SupportsIndex) -> bool:
        ...
    @property
    def profile(self) -> Profile:
        ...
    @property
    def setpoint_pending(self) -> bool:
        ...
class SwitchConfig:
    active_low: bool
    present: bool
    def __init__(self, present: bool = True, lo: typing.SupportsFloat | typing.SupportsIndex = 0.0, hi: typing.SupportsFloat | typing.SupportsIndex = 0.0, active_low: bool = True) -> None:
        ...
    @property
    def hi(self) -> float:
        ...
    @hi.setter
    def hi(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def lo(self) -> float:
        ...
    @lo.setter
    def lo(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class MotorConfig:
    home: SwitchConfig
    index_channel: bool
    minus_limit: SwitchConfig
    plus_limit: SwitchConfig
    def __init__(self) -> None:
        ...
    @property
    def counts_per_rev(self) -> float:
        ...
    @counts_per_rev.setter
    def counts_per_rev(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def index_position(self) -> float:
        ...
    @index_position.setter
    def index_position(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def index_width_steps(self) -> float:
        ...
    @index_width_steps.setter
    def index_width_steps(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_acceleration(self) -> float:
        ...
    @max_acceleration.setter
    def max_acceleration(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def pull_out_speed(self) -> float:
        ...
    @pull_out_speed.setter
    def pull_out_speed(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def steps_per_rev(self) -> float:
        ...
    @steps_per_rev.setter
    def steps_per_rev(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tick_ns(self) -> int:
        ...
    @tick_ns.setter
    def tick_ns(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class MotorEventKind:
    """
    What a MotorEvent reports.
    
    Members:
    
      HOME_ON
    
      HOME_OFF
    
      MINUS_LIMIT_ON
    
      MINUS_LIMIT_OFF
    
      PLUS_LIMIT_ON
    
      PLUS_LIMIT_OFF
    
      INDEX
    
      STALLED
    
      RECOVERED
    
      LATCHED
    
      PROFILE_DONE
    """
    HOME_OFF: typing.ClassVar[MotorEventKind]
    HOME_ON: typing.ClassVar[MotorEventKind]
    INDEX: typing.ClassVar[MotorEventKind]
    LATCHED: typing.ClassVar[MotorEventKind]
    MINUS_LIMIT_OFF: typing.ClassVar[MotorEventKind]
    MINUS_LIMIT_ON: typing.ClassVar[MotorEventKind]
    PLUS_LIMIT_OFF: typing.ClassVar[MotorEventKind]
    PLUS_LIMIT_ON: typing.ClassVar[MotorEventKind]
    PROFILE_DONE: typing.ClassVar[MotorEventKind]
    RECOVERED: typing.ClassVar[MotorEventKind]
    STALLED: typing.ClassVar[MotorEventKind]
    __members__: typing.ClassVar[dict[str, MotorEventKind]]
    @typing.overload
    def __eq__(self, other: MotorEventKind) -> bool:
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
    def __ne__(self, other: MotorEventKind) -> bool:
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
class MotorEvent:
    """
    One MotorModel event (MotorModel.add_listener), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def direction(self) -> int:
        """
        sign of the commanded velocity at t (0 at rest)
        """
    @property
    def encoder(self) -> int:
        ...
    @property
    def kind(self) -> MotorEventKind:
        ...
    @property
    def physical(self) -> float:
        """
        rotor position at t (steps)
        """
    @property
    def pulse(self) -> float:
        """
        pulse position at t
        """
    @property
    def t_ns(self) -> int:
        """
        exact time of the event (ns)
        """
class MotorModel:
    def __init__(self, clock: Clock, config: MotorConfig = ...) -> None:
        ...
    def add_listener(self, callback: collections.abc.Callable[[MotorEvent], None]) -> int:
        """
        callback(MotorEvent) for every event, called from update().
        """
    def advance_to(self, t_ns: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def arm_latch(self) -> None:
        ...
    def command(self, profile: Profile, start_ns: typing.SupportsInt | typing.SupportsIndex | None = None) -> None:
        ...
    def halt(self) -> None:
        ...
    def remove_listener(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_encoder(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_jammed(self, arg0: bool) -> None:
        ...
    def set_pulse_position(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def trigger_latch(self) -> None:
        ...
    def update(self) -> None:
        ...
    @property
    def commanded_velocity(self) -> float:
        ...
    @property
    def encoder(self) -> int:
        ...
    @property
    def home_active(self) -> bool:
        ...
    @property
    def index_active(self) -> bool:
        ...
    @property
    def latch_state(self) -> int:
        ...
    @property
    def latched_encoder(self) -> int:
        ...
    @property
    def latched_pulse(self) -> float:
        ...
    @property
    def minus_limit_active(self) -> bool:
        ...
    @property
    def moving(self) -> bool:
        ...
    @property
    def physical_position(self) -> float:
        ...
    @property
    def plus_limit_active(self) -> bool:
        ...
    @property
    def pulse_count(self) -> int:
        ...
    @property
    def pulse_position(self) -> float:
        ...
    @property
    def pulse_velocity(self) -> float:
        ...
    @property
    def slip(self) -> float:
        ...
    @property
    def stalled(self) -> bool:
        ...
    @property
    def velocity(self) -> float:
        ...
class Cia402HomingParams:
    def __init__(self, method: typing.SupportsInt | typing.SupportsIndex = 17, speed_switch: typing.SupportsFloat | typing.SupportsIndex = 1000.0, speed_zero: typing.SupportsFloat | typing.SupportsIndex = 100.0, acceleration: typing.SupportsFloat | typing.SupportsIndex = 10000.0, home_offset: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
class Cia402Homing:
    @staticmethod
    def supported(arg0: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def __init__(self, motor: MotorModel, params: Cia402HomingParams) -> None:
        ...
    def abort(self) -> None:
        ...
    def start(self) -> None:
        ...
    @property
    def attained(self) -> bool:
        ...
    @property
    def error(self) -> bool:
        ...
    @property
    def result(self) -> int:
        ...
class ArcusSpeedWindow:
    @property
    def delta(self) -> float:
        ...
    @property
    def hspd_high(self) -> float:
        ...
    @property
    def hspd_low(self) -> float:
        ...
    @property
    def min_acc_ms(self) -> float:
        ...
    @property
    def min_lspd(self) -> float:
        ...
    @property
    def number(self) -> int:
        ...
    @property
    def sspdm_first(self) -> int:
        ...
    @property
    def sspdm_last(self) -> int:
        ...
class ArcusProfileParams:
    edec: bool
    scv: bool
    def __init__(self, hspd: typing.SupportsFloat | typing.SupportsIndex = 1000.0, lspd: typing.SupportsFloat | typing.SupportsIndex = 100.0, acc_ms: typing.SupportsFloat | typing.SupportsIndex = 300.0, dec_ms: typing.SupportsFloat | typing.SupportsIndex = 300.0, edec: bool = False, scv: bool = False, snl_ratio: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> None:
        ...
    @property
    def acc_ms(self) -> float:
        ...
    @acc_ms.setter
    def acc_ms(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def dec_ms(self) -> float:
        ...
    @dec_ms.setter
    def dec_ms(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def hspd(self) -> float:
        ...
    @hspd.setter
    def hspd(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def lspd(self) -> float:
        ...
    @lspd.setter
    def lspd(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def snl_ratio(self) -> float:
        ...
    @snl_ratio.setter
    def snl_ratio(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class ArcusPhase:
    """
    Where an ArcusMotion is in its move (MST bits 0..2).
    
    Members:
    
      IDLE
    
      ACCEL
    
      CONST : at constant speed
    
      DECEL
    """
    ACCEL: typing.ClassVar[ArcusPhase]
    CONST: typing.ClassVar[ArcusPhase]
    DECEL: typing.ClassVar[ArcusPhase]
    IDLE: typing.ClassVar[ArcusPhase]
    __members__: typing.ClassVar[dict[str, ArcusPhase]]
    @typing.overload
    def __eq__(self, other: ArcusPhase) -> bool:
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
    def __ne__(self, other: ArcusPhase) -> bool:
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
class ArcusMotion:
    def __init__(self, params: ArcusProfileParams = ..., sspdm: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def abort(self, t: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def change_speed(self, t: typing.SupportsFloat | typing.SupportsIndex, hspd: typing.SupportsFloat | typing.SupportsIndex) -> str:
        ...
    def change_target(self, t: typing.SupportsFloat | typing.SupportsIndex, target: typing.SupportsFloat | typing.SupportsIndex) -> str:
        ...
    def jog(self, arg0: typing.SupportsFloat | typing.SupportsIndex, arg1: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def move(self, position: typing.SupportsFloat | typing.SupportsIndex, target: typing.SupportsFloat | typing.SupportsIndex) -> str:
        """
        X: returns '' or the drive's error reply.
        """
    def moving(self, t: typing.SupportsFloat | typing.SupportsIndex) -> bool:
        ...
    def phase(self, t: typing.SupportsFloat | typing.SupportsIndex) -> ArcusPhase:
        """
        The ArcusPhase at time t (MST bits 0..2).
        """
    def set_params(self, arg0: ArcusProfileParams) -> ArcusProfileParams:
        ...
    def set_sspdm(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def stop(self, t: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def effective(self) -> ArcusProfileParams:
        ...
    @property
    def profile(self) -> Profile:
        ...
class ArcusHomingOptions:
    def __init__(self, hca: typing.SupportsFloat | typing.SupportsIndex = 0.0, lca: typing.SupportsFloat | typing.SupportsIndex = 1000.0, rz: bool = False) -> None:
        ...
class ArcusHomingMethod:
    """
    The routines ArcusHoming runs on a MotorModel.
    
    Members:
    
      H
    
      HL
    
      L
    
      Z
    
      ZH
    """
    H: typing.ClassVar[ArcusHomingMethod]
    HL: typing.ClassVar[ArcusHomingMethod]
    L: typing.ClassVar[ArcusHomingMethod]
    Z: typing.ClassVar[ArcusHomingMethod]
    ZH: typing.ClassVar[ArcusHomingMethod]
    __members__: typing.ClassVar[dict[str, ArcusHomingMethod]]
    @typing.overload
    def __eq__(self, other: ArcusHomingMethod) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: ArcusHomingMethod) -> bool:
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
class ArcusHoming:
    def __init__(self, motor: MotorModel, params: ArcusProfileParams, options: ArcusHomingOptions = ...) -> None:
        ...
    def abort(self) -> None:
        ...
    def start(self, method: ArcusHomingMethod | str, direction: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def result(self) -> int:
        ...
    @property
    def running(self) -> bool:
        ...
    @property
    def snl_status(self) -> int:
        ...
class ArcusCommandInfo:
    """
    One row of the Arcus command table (arcus_commands()), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def action(self) -> bool:
        """
        a bare command answering OK ("J+")
        """
    @property
    def argument(self) -> bool:
        """
        takes a value glued to the name ("X1000")
        """
    @property
    def description(self) -> str:
        ...
    @property
    def indexed(self) -> int:
        """
        highest 1-based index (DI6 -> 6), 0 when not indexed
        """
    @property
    def motion(self) -> bool:
        """
        refused with ?Moving / ?State Error when busy or in error
        """
    @property
    def name(self) -> str:
        ...
    @property
    def query(self) -> bool:
        """
        answers the bare name ("HSPD" -> value)
        """
    @property
    def set(self) -> bool:
        """
        takes NAME=value
        """
    @property
    def stored(self) -> bool:
        """
        written to flash by STORE (Table 7.10)
        """
class ArcusSim(LineDevice, SimulatedDevice):
    """
    A simulated Arcus DMX-CAN: answers ASCII lines (a LineDevice for PtyLineServer) and, attached to a CAN bus, CANopen (a SimulatedDevice).
    """
    def __init__(self, clock: Clock = None, address: typing.SupportsInt | typing.SupportsIndex = 1, response_type: typing.SupportsInt | typing.SupportsIndex = 0, store_path: str = '', eo_boot: bool = False, snl: bool = True, home: tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex] = (8000.0, 8400.0), minus_limit: typing.SupportsFloat | typing.SupportsIndex | None = -400000.0, plus_limit: typing.SupportsFloat | typing.SupportsIndex | None = 400000.0, z_position: typing.SupportsFloat | typing.SupportsIndex = 1600.0, start_position: typing.SupportsFloat | typing.SupportsIndex = 0.0, tick: typing.SupportsFloat | typing.SupportsIndex = 0.0001, comm_type: typing.SupportsInt | typing.SupportsIndex = 0, node_id: typing.SupportsInt | typing.SupportsIndex = 1, store_time: typing.SupportsFloat | typing.SupportsIndex = 0.0, clear_time: typing.SupportsFloat | typing.SupportsIndex = 0.0, bit_rate: typing.SupportsInt | typing.SupportsIndex = 5) -> None:
        ...
    def disturb(self, steps: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def force_home(self, actuated: bool | None) -> None:
        ...
    def force_limit(self, direction: typing.SupportsInt | typing.SupportsIndex, actuated: bool | None) -> None:
        ...
    def on_can_frame(self, frame: Frame) -> list[Frame]:
        """
        One CAN frame in, the frames the drive answers out (what attach runs per frame).
        """
    def on_line(self, line: typing.Any) -> bytes:
        """
        One request line without CR -> the reply bytes (NUL included; b'' = silent).
        """
    def set_blocked(self, blocked: bool) -> None:
        ...
    def set_input(self, index: typing.SupportsInt | typing.SupportsIndex, actuated: bool) -> None:
        """
        DI1..DI6 (DI2 is the latch input).
        """
    @property
    def active_protocol(self) -> int:
        """
        Communication type in effect: 0 RS-232, 1 RS-485, 2 CAN (200Ah at the last boot).
        """
    @property
    def address(self) -> int:
        ...
    @property
    def busy(self) -> bool:
        ...
    @property
    def can_bit_rate(self) -> int:
        ...
    @property
    def can_node_id(self) -> int:
        ...
    @property
    def encoder_position(self) -> int:
        ...
    @property
    def motor_status(self) -> int:
        ...
    @property
    def physical_position(self) -> float:
        ...
    @property
    def pulse_position(self) -> int:
        ...
    @property
    def snl_status(self) -> int:
        ...
    @property
    def store_path(self) -> str:
        ...
class ArcusHomeMethod:
    """
    The homing routines: H, HL, ZH, Z, L (Table 11.0; + or - is the direction).
    
    Members:
    
      H
    
      HL
    
      ZH
    
      Z
    
      L
    """
    H: typing.ClassVar[ArcusHomeMethod]
    HL: typing.ClassVar[ArcusHomeMethod]
    L: typing.ClassVar[ArcusHomeMethod]
    Z: typing.ClassVar[ArcusHomeMethod]
    ZH: typing.ClassVar[ArcusHomeMethod]
    __members__: typing.ClassVar[dict[str, ArcusHomeMethod]]
    @typing.overload
    def __eq__(self, other: ArcusHomeMethod) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: ArcusHomeMethod) -> bool:
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
class ArcusClientCounters:
    """
    ArcusClient counters (ArcusClient.counters), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def device_errors(self) -> int:
        """
        Table 11.1 error replies
        """
    @property
    def noise_lines(self) -> int:
        """
        lines of non-printable bytes skipped (A10)
        """
    @property
    def protocol_errors(self) -> int:
        ...
    @property
    def requests(self) -> int:
        ...
    @property
    def retries(self) -> int:
        """
        queries sent again after a timeout
        """
    @property
    def timeouts(self) -> int:
        ...
class ArcusClientBase:
    """
    Typed client for one DMX-CAN address on a LineLink (see ArcusClient).
    """
    alarm_outputs: bool
    enabled: bool
    enabled_at_boot: bool
    return_to_zero: bool
    s_curve: bool
    snl_enabled: bool
    unique_deceleration: bool
    @staticmethod
    def broadcast(link: LineLink, command: str) -> None:
        ...
    def __init__(self, link: LineLink, address: typing.SupportsInt | typing.SupportsIndex = 1, timeout: typing.Any = None, query_retries: typing.SupportsInt | typing.SupportsIndex = 1) -> None:
        ...
    def abort(self) -> None:
        ...
    def absolute_mode(self) -> None:
        ...
    def action(self, name: str) -> None:
        ...
    def change_speed(self, pps: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def change_target(self, target: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def clear(self) -> None:
        ...
    def clear_snl(self) -> None:
        ...
    def command(self, command: str, idempotent: bool = False) -> str:
        ...
    def digital_input(self, n: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def digital_output(self, n: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def disable(self) -> None:
        ...
    def enable(self, on: bool = True) -> None:
        ...
    def enable_latch(self, on: bool = True) -> None:
        ...
    def home(self, method: ArcusHomeMethod | str, direction: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def incremental_mode(self) -> None:
        ...
    def jog(self, direction: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def move(self, target: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def query(self, name: str) -> int:
        ...
    def set(self, name: str, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_device_name(self, address: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        DN=DMCnn (takes effect after store() and a power cycle).
        """
    def set_digital_output(self, n: typing.SupportsInt | typing.SupportsIndex, on: bool) -> None:
        ...
    def set_encoder(self, counts: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_position(self, position: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def stop(self) -> None:
        ...
    def store(self) -> None:
        ...
    def sync_off(self) -> None:
        ...
    def sync_on(self) -> None:
        ...
    def wait_idle(self, timeout: typing.Any, poll: typing.Any = 0.005) -> None:
        ...
    @property
    def _latch_status_raw(self) -> int:
        ...
    @property
    def _snl_status_raw(self) -> int:
        ...
    @property
    def _status_raw(self) -> int:
        ...
    @property
    def _sync_condition_raw(self) -> int:
        ...
    @_sync_condition_raw.setter
    def _sync_condition_raw(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def _sync_status_raw(self) -> int:
        ...
    @property
    def acceleration(self) -> int:
        ...
    @acceleration.setter
    def acceleration(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def address(self) -> int:
        ...
    @property
    def baud_code(self) -> int:
        ...
    @baud_code.setter
    def baud_code(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def can_bit_rate_code(self) -> int:
        ...
    @can_bit_rate_code.setter
    def can_bit_rate_code(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def comm_mode(self) -> int:
        ...
    @comm_mode.setter
    def comm_mode(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def counters(self) -> ArcusClientCounters:
        ...
    @property
    def current(self) -> int:
        ...
    @property
    def deceleration(self) -> int:
        ...
    @deceleration.setter
    def deceleration(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def delta(self) -> int:
        ...
    @property
    def device_name(self) -> str:
        ...
    @property
    def digital_inputs(self) -> int:
        ...
    @property
    def digital_outputs(self) -> int:
        ...
    @digital_outputs.setter
    def digital_outputs(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def encoder(self) -> int:
        ...
    @property
    def high_speed(self) -> int:
        ...
    @high_speed.setter
    def high_speed(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def home_correction(self) -> int:
        ...
    @home_correction.setter
    def home_correction(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def id(self) -> str:
        ...
    @property
    def idle_current(self) -> int:
        ...
    @idle_current.setter
    def idle_current(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def idle_time(self) -> int:
        ...
    @idle_time.setter
    def idle_time(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def incremental(self) -> bool:
        ...
    @property
    def latched_encoder(self) -> int:
        ...
    @property
    def latched_position(self) -> int:
        ...
    @property
    def limit_correction(self) -> int:
        ...
    @limit_correction.setter
    def limit_correction(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def low_speed(self) -> int:
        ...
    @low_speed.setter
    def low_speed(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def moving(self) -> bool:
        ...
    @property
    def node_id(self) -> int:
        ...
    @node_id.setter
    def node_id(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def outputs_at_boot(self) -> int:
        ...
    @outputs_at_boot.setter
    def outputs_at_boot(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def polarity(self) -> int:
        ...
    @polarity.setter
    def polarity(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def position(self) -> int:
        ...
    @property
    def response_type(self) -> int:
        ...
    @response_type.setter
    def response_type(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def run_current(self) -> int:
        ...
    @run_current.setter
    def run_current(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def snl_error_range(self) -> int:
        ...
    @snl_error_range.setter
    def snl_error_range(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def snl_idle_tolerance(self) -> int:
        ...
    @snl_idle_tolerance.setter
    def snl_idle_tolerance(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def snl_max_attempts(self) -> int:
        ...
    @snl_max_attempts.setter
    def snl_max_attempts(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def snl_ratio(self) -> float:
        ...
    @snl_ratio.setter
    def snl_ratio(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def snl_tolerance(self) -> int:
        ...
    @snl_tolerance.setter
    def snl_tolerance(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def speed(self) -> int:
        ...
    @property
    def speed_window(self) -> int:
        ...
    @speed_window.setter
    def speed_window(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def sync_position(self) -> int:
        ...
    @sync_position.setter
    def sync_position(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def version(self) -> str:
        ...
class Cia402Sim(SimulatedDevice):
    """
    A simulated CiA 402 drive served by a LocalNode (see cpp/motorbus/drives/cia402/sim.hpp).
    """
    def __init__(self, node_id: typing.SupportsInt | typing.SupportsIndex, clock: Clock = None, *, steps_per_rev: typing.SupportsFloat | typing.SupportsIndex = 3200.0, home: tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex] = (1000.0, 1400.0), minus_limit: typing.SupportsFloat | typing.SupportsIndex | None = -100000.0, plus_limit: typing.SupportsFloat | typing.SupportsIndex | None = 100000.0, heartbeat_ms: typing.SupportsInt | typing.SupportsIndex = 0, start_position: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def force_limit(self, direction: typing.SupportsInt | typing.SupportsIndex, active: bool = True) -> None:
        """
        The +limit (+1) or -limit (-1) switch closes whatever the position: a motion toward it stops.
        """
    def inject_fault(self, error_code: typing.SupportsInt | typing.SupportsIndex = 21569) -> None:
        """
        The drive detects a fault (default 0x5441 interlock): the motor stops, FAULT, 603Fh holds the code.
        """
    def jam(self, jammed: bool = True) -> None:
        """
        The rotor blocks: past 6065h the drive faults with 0x8611 (statusword bit 13).
        """
    def set_stop_input(self, active: bool = True) -> None:
        """
        The quick-stop input (60FDh bit 16): its rising edge quick-stops a moving drive.
        """
    @property
    def heartbeat(self) -> HeartbeatService:
        ...
    @property
    def last_setpoint_ns(self) -> int | None:
        """
        Clock time (ns) of the last profile-position set-point the drive took, or None.
        """
    @property
    def lost_master(self) -> bool:
        """
        True once the master's heartbeat was lost (6007h applied).
        """
    @property
    def node_id(self) -> int:
        ...
    @property
    def od(self) -> ObjectDictionary:
        ...
    @property
    def pdo(self) -> PdoService:
        ...
    @property
    def position(self) -> float:
        ...
    @property
    def state(self) -> str:
        ...
class DmacProfileParams:
    s_curve: bool
    def __init__(self, high_speed: typing.SupportsInt | typing.SupportsIndex = 60000, low_speed: typing.SupportsInt | typing.SupportsIndex = 6000, accel_time_ms: typing.SupportsInt | typing.SupportsIndex = 1000, decel_time_ms: typing.SupportsInt | typing.SupportsIndex = 1000, s_curve: bool = False) -> None:
        ...
    @property
    def accel_time_ms(self) -> int:
        ...
    @accel_time_ms.setter
    def accel_time_ms(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def decel_time_ms(self) -> int:
        ...
    @decel_time_ms.setter
    def decel_time_ms(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def high_speed(self) -> int:
        ...
    @high_speed.setter
    def high_speed(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def low_speed(self) -> int:
        ...
    @low_speed.setter
    def low_speed(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class DmacMotion:
    def __init__(self, params: DmacProfileParams = ..., position: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def move_on(self, t: typing.SupportsFloat | typing.SupportsIndex, offset: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def move_speed(self, t: typing.SupportsFloat | typing.SupportsIndex, speed: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def move_to(self, t: typing.SupportsFloat | typing.SupportsIndex, target: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def moving(self, t: typing.SupportsFloat | typing.SupportsIndex) -> bool:
        ...
    def set_params(self, arg0: DmacProfileParams) -> None:
        ...
    def stop(self, t: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def profile(self) -> Profile:
        ...
class DmacRadix:
    """
    How a DMAC value is written: +123, h0000007B or b00000000 ... 01111011.
    
    Members:
    
      DEC
    
      HEX
    
      BIN
    """
    BIN: typing.ClassVar[DmacRadix]
    DEC: typing.ClassVar[DmacRadix]
    HEX: typing.ClassVar[DmacRadix]
    __members__: typing.ClassVar[dict[str, DmacRadix]]
    @typing.overload
    def __eq__(self, other: DmacRadix) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: DmacRadix) -> bool:
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
class DmacStopWhat:
    """
    What STOP / HALT stop: everything, the movement (MOUV) or the sequence (SEQ).
    
    Members:
    
      ALL
    
      MOVEMENT
    
      SEQUENCE
    """
    ALL: typing.ClassVar[DmacStopWhat]
    MOVEMENT: typing.ClassVar[DmacStopWhat]
    SEQUENCE: typing.ClassVar[DmacStopWhat]
    __members__: typing.ClassVar[dict[str, DmacStopWhat]]
    @typing.overload
    def __eq__(self, other: DmacStopWhat) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: DmacStopWhat) -> bool:
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
class DmacPowerMode:
    """
    POWER ON, OFF (freewheel) or SC (short-circuited coils).
    
    Members:
    
      ON
    
      OFF
    
      SC
    """
    OFF: typing.ClassVar[DmacPowerMode]
    ON: typing.ClassVar[DmacPowerMode]
    SC: typing.ClassVar[DmacPowerMode]
    __members__: typing.ClassVar[dict[str, DmacPowerMode]]
    @typing.overload
    def __eq__(self, other: DmacPowerMode) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: DmacPowerMode) -> bool:
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
class DmacEndStops:
    """
    HARD_ENDS: which hard end-stop inputs stop the motor.
    
    Members:
    
      OFF
    
      ALL
    
      POS
    
      NEG
    """
    ALL: typing.ClassVar[DmacEndStops]
    NEG: typing.ClassVar[DmacEndStops]
    OFF: typing.ClassVar[DmacEndStops]
    POS: typing.ClassVar[DmacEndStops]
    __members__: typing.ClassVar[dict[str, DmacEndStops]]
    @typing.overload
    def __eq__(self, other: DmacEndStops) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: DmacEndStops) -> bool:
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
class DmacPolarity:
    """
    INVERSE_POLARITY: which of the inputs and outputs are inverted.
    
    Members:
    
      OFF
    
      ALL
    
      IN
    
      OUT
    """
    ALL: typing.ClassVar[DmacPolarity]
    IN: typing.ClassVar[DmacPolarity]
    OFF: typing.ClassVar[DmacPolarity]
    OUT: typing.ClassVar[DmacPolarity]
    __members__: typing.ClassVar[dict[str, DmacPolarity]]
    @typing.overload
    def __eq__(self, other: DmacPolarity) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: DmacPolarity) -> bool:
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
class DmacKeyword:
    """
    The keywords of the DMAC command language.
    
    Members:
    
      ON
    
      OFF
    
      SC
    
      ALL
    
      POS
    
      NEG
    
      IN
    
      OUT
    
      MOUV
    
      SEQ
    
      TOP
    
      INTERPOL
    """
    ALL: typing.ClassVar[DmacKeyword]
    IN: typing.ClassVar[DmacKeyword]
    INTERPOL: typing.ClassVar[DmacKeyword]
    MOUV: typing.ClassVar[DmacKeyword]
    NEG: typing.ClassVar[DmacKeyword]
    OFF: typing.ClassVar[DmacKeyword]
    ON: typing.ClassVar[DmacKeyword]
    OUT: typing.ClassVar[DmacKeyword]
    POS: typing.ClassVar[DmacKeyword]
    SC: typing.ClassVar[DmacKeyword]
    SEQ: typing.ClassVar[DmacKeyword]
    TOP: typing.ClassVar[DmacKeyword]
    __members__: typing.ClassVar[dict[str, DmacKeyword]]
    @typing.overload
    def __eq__(self, other: DmacKeyword) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: DmacKeyword) -> bool:
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
class DmacReadReply:
    """
    One parsed 'aa#MNE[.bit]=value' reply (dmac_parse_read_reply), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def address(self) -> int:
        ...
    @property
    def bit(self) -> int:
        """
        0 for a whole-variable read
        """
    @property
    def mnemonic(self) -> str:
        """
        '#ATI'
        """
    @property
    def radix(self) -> DmacRadix:
        ...
    @property
    def value(self) -> int:
        ...
class DmacVariableInfo:
    """
    One DMAC variable (dmac_variable()), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def dmac34_only(self) -> bool:
        """
        exists on the DMAC34 only
        """
    @property
    def factory(self) -> int:
        """
        value after MODULE_RESET ALL (stored) or reset (volatile)
        """
    @property
    def max(self) -> int:
        """
        highest value a write accepts
        """
    @property
    def min(self) -> int:
        """
        lowest value a write accepts
        """
    @property
    def mnemonic(self) -> str:
        """
        '#ATI'
        """
    @property
    def name(self) -> str:
        """
        '#ACCEL_TIME'
        """
    @property
    def read_only(self) -> bool:
        ...
    @property
    def stored(self) -> bool:
        """
        survives power cycle / MODULE_RESET
        """
class DmacVersionInfo:
    """
    A parsed REQUEST_VERSION banner (DmacClient.request_version()), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def address(self) -> int:
        ...
    @property
    def boot(self) -> str:
        """
        'v1.1'
        """
    @property
    def code(self) -> str:
        """
        'H142'
        """
    @property
    def ident(self) -> str:
        """
        the text between the quotes
        """
    @property
    def manufacturer(self) -> str:
        ...
    @property
    def manufacturing_date(self) -> str:
        ...
    @property
    def model(self) -> str:
        """
        from the code table, e.g. 'DMAC34 standard'
        """
    @property
    def phase(self) -> str:
        """
        '6A'
        """
    @property
    def product(self) -> str:
        ...
    @property
    def release(self) -> int:
        """
        7 in v1.7
        """
    @property
    def revision_date(self) -> str:
        ...
    @property
    def serial(self) -> str:
        ...
    @property
    def version(self) -> int:
        """
        1 in v1.7
        """
class DmacSensor:
    """
    The temperature sensors of a module (DmacSim.set_temperature).
    
    Members:
    
      CPU
    
      DRIVER
    
      MOTOR
    """
    CPU: typing.ClassVar[DmacSensor]
    DRIVER: typing.ClassVar[DmacSensor]
    MOTOR: typing.ClassVar[DmacSensor]
    __members__: typing.ClassVar[dict[str, DmacSensor]]
    @typing.overload
    def __eq__(self, other: DmacSensor) -> bool:
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
    @typing.overload
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, name: str) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: DmacSensor) -> bool:
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
class DmacSimState:
    """
    A snapshot of a DmacSim (DmacSim.state()), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def error(self) -> int:
        """
        #ERROR bits
        """
    @property
    def fifo_count(self) -> int:
        """
        interpolation segments queued
        """
    @property
    def interpolating(self) -> bool:
        ...
    @property
    def line(self) -> int:
        """
        sequencer line running (0 = stopped)
        """
    @property
    def now_ms(self) -> int:
        """
        device time (ms)
        """
    @property
    def position(self) -> int:
        """
        #POSITION (1/10000 rev)
        """
    @property
    def power(self) -> bool:
        """
        the motor is powered
        """
    @property
    def sequencer_running(self) -> bool:
        ...
    @property
    def speed(self) -> int:
        """
        #SPEED (0.01 rpm, signed)
        """
    @property
    def status(self) -> int:
        """
        #STATUS bits
        """
class DmacSim(LineDevice):
    """
    A simulated DMAC module (a LineDevice: serve it with PtyLineServer). Device time runs on `clock` (a SimClock in tests); nothing runs in the background.
    """
    @staticmethod
    def chain_ultrasync(modules: collections.abc.Sequence[DmacSim]) -> None:
        """
        Wire IN6/OUT1 of these modules into one UltraSYNC chain (5.11), before serving them: with #INTERPOL_MODE:=-1 a segment ends when it is finished on every chained module.
        """
    def __init__(self, clock: Clock = None, address: typing.SupportsInt | typing.SupportsIndex = 0, model: str = 'DMAC34-1', request_terminator: bytes = b'\r', reply_terminator: bytes = b'\r\n', supply_voltage: typing.SupportsInt | typing.SupportsIndex = 32000, baudrate: typing.SupportsInt | typing.SupportsIndex = 38400, positive_end_switch: typing.SupportsFloat | typing.SupportsIndex | None = None, negative_end_switch: typing.SupportsFloat | typing.SupportsIndex | None = None, end_switch_active_low: bool = False, reference_switch: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        ...
    def inject_error(self, bit: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Sets an #ERROR bit; fault bits 2..5 also stop the motor as the real fault does.
        """
    def physical_outputs(self) -> int:
        ...
    def poll(self) -> None:
        """
        Catch up with the clock.
        """
    def power_cycle(self) -> None:
        ...
    def read(self, variable: str) -> int:
        ...
    def sequence_line(self, n: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def set_analog(self, channel: typing.SupportsInt | typing.SupportsIndex, mv: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_input(self, n: typing.SupportsInt | typing.SupportsIndex, active: bool) -> None:
        ...
    def set_speed_limit(self, inc_per_s: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        A mechanical limit (friction, a brake): an interpolation segment faster than this (increments/s) lasts |offset|/limit instead of #INTERPOL_TIME. 0 = none.
        """
    def set_supply_voltage(self, mv: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Supply voltage in mV; outside the model's range latches undervoltage/overvoltage and stops the motor.
        """
    def set_temperature(self, sensor: DmacSensor | str, tenths_c: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Temperature in 0.1 degC; CPU > 120 degC or driver/motor > 85 degC latches a thermal fault.
        """
    def state(self) -> DmacSimState:
        """
        A DmacSimState snapshot.
        """
    @property
    def address(self) -> int:
        ...
    @property
    def baudrate(self) -> int:
        ...
    @property
    def lines_handled(self) -> int:
        ...
    @property
    def lines_rejected(self) -> int:
        ...
    @property
    def reply_terminator(self) -> bytes:
        ...
class DmacClientCounters:
    """
    DmacClient counters (DmacClient.counters), read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def device_resets(self) -> int:
        """
        version banners seen unsolicited
        """
    @property
    def stray_lines(self) -> int:
        """
        lines that were not the awaited reply (late, misrouted)
        """
    @property
    def transactions(self) -> int:
        ...
    @property
    def xon_errors(self) -> int:
        """
        MOVE_INTERPOL refused: FIFO full
        """
class DmacClient:
    """
    Typed DMAC commands over a LineLink (one client per module address).
    """
    def __init__(self, link: LineLink, address: typing.SupportsInt | typing.SupportsIndex = 0, *, baud: typing.SupportsInt | typing.SupportsIndex = 38400, verify: bool = True, timeout: typing.Any = None, sleep: typing.Any = None) -> None:
        ...
    def analog_input(self, channel: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def brake(self, on: bool) -> None:
        ...
    def clear_error(self) -> None:
        ...
    def command(self, command: str) -> None:
        ...
    def halt(self, what: DmacStopWhat | str = ...) -> None:
        ...
    def hard_ends(self, which: DmacEndStops | str) -> None:
        ...
    def inverse_polarity(self, which: DmacPolarity | str) -> None:
        ...
    def memorized_var(self, n: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def module_reset(self, factory: bool = False) -> None:
        ...
    def move_interpol(self, offset: typing.SupportsInt | typing.SupportsIndex) -> int | None:
        """
        Queues one segment; returns the FIFO level, or None when the FIFO was full (XON_ERROR).
        """
    def move_on(self, offset: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def move_speed(self, speed: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def move_to(self, position: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def optimized_current(self, on: bool) -> None:
        ...
    def power(self, mode: DmacPowerMode | str) -> None:
        ...
    def raw(self, frame: str, expect_reply: bool = True) -> bytes:
        ...
    def read(self, variable: str, radix: DmacRadix | str = ...) -> int:
        """
        READ a variable; radix is a DmacRadix or 'dec'/'hex'/'bin' (default DmacRadix.DEC).
        """
    def read_bit(self, variable: str, bit: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def read_sequence(self, first: typing.SupportsInt | typing.SupportsIndex, last: typing.SupportsInt | typing.SupportsIndex) -> list[str]:
        ...
    def read_sequence_line(self, n: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def reference(self, on: bool) -> None:
        ...
    def request_version(self) -> DmacVersionInfo:
        """
        REQUEST_VERSION, parsed into a DmacVersionInfo.
        """
    def s_curve(self, on: bool) -> None:
        ...
    def set_address(self, address: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_analog_output(self, channel: typing.SupportsInt | typing.SupportsIndex, mv: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_baudrate(self, baud: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_interpolation(self, time_ms: typing.SupportsInt | typing.SupportsIndex, fifo_size: typing.SupportsInt | typing.SupportsIndex, mode: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def set_memorized_var(self, n: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_output(self, n: typing.SupportsInt | typing.SupportsIndex, on: bool) -> None:
        ...
    def set_position(self, position: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_profile(self, high_speed: typing.SupportsInt | typing.SupportsIndex | None = None, low_speed: typing.SupportsInt | typing.SupportsIndex | None = None, accel_ms: typing.SupportsInt | typing.SupportsIndex | None = None, decel_ms: typing.SupportsInt | typing.SupportsIndex | None = None) -> None:
        """
        #HIGH_SPEED / #LOW_SPEED (0.01 rpm), #ACCEL_TIME / #DECEL_TIME (ms) in one frame.
        """
    def set_soft_limits(self, negative: typing.SupportsInt | typing.SupportsIndex, positive: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_timer(self, n: typing.SupportsInt | typing.SupportsIndex, ms: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def set_user_var(self, n: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def soft_ends(self, on: bool) -> None:
        ...
    def soft_limits(self) -> tuple[int, int]:
        """
        (#NEGATIVE_END, #POSITIVE_END)
        """
    def start_sequence(self, line: typing.SupportsInt | typing.SupportsIndex = 1) -> None:
        ...
    def step(self, line: typing.SupportsInt | typing.SupportsIndex | None = None) -> None:
        ...
    def stop(self, what: DmacStopWhat | str = ...) -> None:
        ...
    def stop_sequence(self) -> None:
        ...
    def timer(self, n: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def upload_sequence(self, lines: collections.abc.Sequence[str], first: typing.SupportsInt | typing.SupportsIndex = 1, verify_readback: bool = True) -> None:
        ...
    def user_var(self, n: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def wait_idle(self, timeout: typing.Any, poll: typing.Any = 0.01) -> int:
        """
        Polls #STATUS until not busy; returns the position. TimeoutError after `timeout` s (None = wait forever; Ctrl-C interrupts).
        """
    def write(self, variable: str, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_bit(self, variable: str, bit: typing.SupportsInt | typing.SupportsIndex, value: bool) -> None:
        ...
    @property
    def accel_time(self) -> int:
        """
        #ACCEL_TIME (ms).
        """
    @accel_time.setter
    def accel_time(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def address(self) -> int:
        ...
    @property
    def capture(self) -> int:
        """
        #CAPTURE: #POSITION at the last IN5 rising edge.
        """
    @property
    def counters(self) -> DmacClientCounters:
        ...
    @property
    def cpu_temperature(self) -> int:
        """
        #CPU_TEMPERATURE (0.1 degC).
        """
    @property
    def decel_time(self) -> int:
        """
        #DECEL_TIME (ms).
        """
    @decel_time.setter
    def decel_time(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def driver_temperature(self) -> int:
        """
        #DRIVER_TEMPERATURE (DMAC34, 0.1 degC).
        """
    @property
    def error(self) -> typing.Any:
        """
        #ERROR as a DmacErrorWord (enum.IntFlag); clear_error() acknowledges it.
        """
    @property
    def high_speed(self) -> int:
        """
        #HIGH_SPEED (0.01 rpm).
        """
    @high_speed.setter
    def high_speed(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def inputs(self) -> int:
        """
        #INPUT (bit 0 = IN1).
        """
    @property
    def interpol_count(self) -> int:
        """
        #INTERPOL_COUNT (segments queued).
        """
    @property
    def is_dmac34(self) -> bool:
        """
        The module is a DMAC34 (from REQUEST_VERSION, cached).
        """
    @property
    def line(self) -> int:
        """
        #LINE: sequencer line running (0 = stopped).
        """
    @property
    def line_delay(self) -> int:
        """
        #LINE_DELAY (us).
        """
    @line_delay.setter
    def line_delay(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def low_speed(self) -> int:
        """
        #LOW_SPEED (0.01 rpm).
        """
    @low_speed.setter
    def low_speed(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def motor_temperature(self) -> int:
        """
        #MOTOR_TEMPERATURE (DMAC34, 0.1 degC).
        """
    @property
    def on_reset(self) -> int:
        """
        #ON_RESET (sequencer line, 0 = none).
        """
    @on_reset.setter
    def on_reset(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def output_config(self) -> int:
        """
        #OUTPUT_CONFIG.
        """
    @output_config.setter
    def output_config(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def outputs(self) -> int:
        """
        #OUTPUT (bit 0 = OUT1).
        """
    @outputs.setter
    def outputs(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def position(self) -> int:
        """
        #POSITION (1/10000 rev); assigning re-homes the axis.
        """
    @position.setter
    def position(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def profile_speed(self) -> int:
        """
        #PROFILE_SPEED, computed (0.01 rpm).
        """
    @property
    def speed(self) -> int:
        """
        #SPEED, measured (0.01 rpm, signed).
        """
    @property
    def status(self) -> typing.Any:
        """
        #STATUS as a DmacStatus (enum.IntFlag).
        """
    @property
    def supply_voltage(self) -> int:
        """
        #SUPPLY_VOLTAGE (mV).
        """
    @property
    def torque_ratio(self) -> int:
        """
        #TORQUE_RATIO (%).
        """
    @torque_ratio.setter
    def torque_ratio(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class DmacStreamStats:
    """
    What dmac_stream_interpolation did, read-only.
    """
    def __repr__(self) -> str:
        ...
    @property
    def frames(self) -> int:
        """
        MOVE_INTERPOL frames sent (all axes, retries included)
        """
    @property
    def min_level_after_start(self) -> int:
        """
        lowest FIFO level seen once moving (0 = underrun)
        """
    @property
    def segments(self) -> int:
        """
        segments queued per axis
        """
    @property
    def underruns(self) -> int:
        """
        times an axis reported an empty FIFO before the end
        """
    @property
    def xon_errors(self) -> int:
        """
        refusals on a full FIFO
        """
class Pmc007ProfileParams:
    def __init__(self, speed: typing.SupportsFloat | typing.SupportsIndex = 1000.0, start_speed: typing.SupportsFloat | typing.SupportsIndex = 400.0, stop_speed: typing.SupportsFloat | typing.SupportsIndex = 0.0, accel_gear: typing.SupportsInt | typing.SupportsIndex = 0, decel_gear: typing.SupportsInt | typing.SupportsIndex = 0, microstepping: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    @property
    def accel_gear(self) -> int:
        ...
    @accel_gear.setter
    def accel_gear(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def decel_gear(self) -> int:
        ...
    @decel_gear.setter
    def decel_gear(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def microstepping(self) -> int:
        ...
    @microstepping.setter
    def microstepping(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def speed(self) -> float:
        ...
    @speed.setter
    def speed(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def start_speed(self) -> float:
        ...
    @start_speed.setter
    def start_speed(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def stop_speed(self) -> float:
        ...
    @stop_speed.setter
    def stop_speed(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Pmc007Storage:
    """
    How an object behaves over reset node / power-up (B-P37).
    
    Members:
    
      ROM : saved to flash by 2007h = 2, reloaded at reset node
    
      RAM : back to the default at reset node / power-up
    
      CONST : never changes
    """
    CONST: typing.ClassVar[Pmc007Storage]
    RAM: typing.ClassVar[Pmc007Storage]
    ROM: typing.ClassVar[Pmc007Storage]
    __members__: typing.ClassVar[dict[str, Pmc007Storage]]
    @typing.overload
    def __eq__(self, other: Pmc007Storage) -> bool:
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
    def __ne__(self, other: Pmc007Storage) -> bool:
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
class Pmc007Sim(SimulatedDevice):
    """
    A simulated CQPUSI PMC007 CANopen node (see sim.hpp).
    """
    def __init__(self, node_id: typing.SupportsInt | typing.SupportsIndex = 5, clock: Clock = None, steps_per_rev: typing.SupportsFloat | typing.SupportsIndex = 200.0, pull_out_speed: typing.SupportsFloat | typing.SupportsIndex = 0.0, ext1_switch: tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex] | None = None, store_path: str = '', vendor_id: typing.SupportsInt | typing.SupportsIndex = 0, product_code: typing.SupportsInt | typing.SupportsIndex = 7, revision: typing.SupportsInt | typing.SupportsIndex = 65536, serial: typing.SupportsInt | typing.SupportsIndex = 1) -> None:
        ...
    def inject_error(self, bits: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Latch 6000h error bits (EMCY sent).
        """
    def poll(self) -> None:
        ...
    def set_input(self, bit: typing.SupportsInt | typing.SupportsIndex, high: bool) -> None:
        """
        Electrical level of input port `bit` (6012h bit 0..10; 7 EXT1, 8 EXT2, 9 ENC1/EXT3).
        """
    def set_jammed(self, jammed: bool) -> None:
        ...
    @property
    def active_baud_index(self) -> int:
        ...
    @property
    def active_encoder_cpr(self) -> int:
        """
        The encoder CPR in use: 6021h as it was at the last power-up or reset node (B-P40).
        """
    @property
    def busy(self) -> bool:
        ...
    @property
    def controller_status(self) -> int:
        ...
    @property
    def emcy_sent(self) -> int:
        ...
    @property
    def enabled(self) -> bool:
        ...
    @property
    def error_status(self) -> int:
        ...
    @property
    def flash_program(self) -> list[int]:
        ...
    @property
    def gpio_value(self) -> int:
        ...
    @property
    def in_bootloader(self) -> bool:
        ...
    @property
    def last_error(self) -> str:
        """
        why the last node-ID switch or return to the bus failed ('' if none did)
        """
    @property
    def node_id(self) -> int:
        ...
    @property
    def od(self) -> ObjectDictionary:
        ...
    @property
    def position(self) -> int:
        ...
    @property
    def program_counter(self) -> int:
        ...
    @property
    def program_pointer(self) -> int:
        ...
    @property
    def program_running(self) -> bool:
        ...
    @property
    def ram_program(self) -> list[int]:
        ...
    @property
    def velocity(self) -> float:
        ...
class UnitekRampParams:
    def __init__(self, n_max_rpm: typing.SupportsFloat | typing.SupportsIndex = 3000.0, acc_ramp_ms: typing.SupportsFloat | typing.SupportsIndex = 1000.0, dec_ramp_ms: typing.SupportsFloat | typing.SupportsIndex = 1000.0) -> None:
        ...
    @property
    def acc_ramp_ms(self) -> float:
        ...
    @acc_ramp_ms.setter
    def acc_ramp_ms(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def dec_ramp_ms(self) -> float:
        ...
    @dec_ramp_ms.setter
    def dec_ramp_ms(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def n_max_rpm(self) -> float:
        ...
    @n_max_rpm.setter
    def n_max_rpm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class UnitekAccess:
    """
    Members:
    
      RW
    
      RO
    
      WO
    """
    RO: typing.ClassVar[UnitekAccess]
    RW: typing.ClassVar[UnitekAccess]
    WO: typing.ClassVar[UnitekAccess]
    __members__: typing.ClassVar[dict[str, UnitekAccess]]
    @typing.overload
    def __eq__(self, other: UnitekAccess) -> bool:
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
    def __ne__(self, other: UnitekAccess) -> bool:
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
class UnitekQuantity:
    """
    Members:
    
      RAW
    
      SPEED
    
      POSITION
    
      CURRENT
    
      TORQUE
    
      TIME
    """
    CURRENT: typing.ClassVar[UnitekQuantity]
    POSITION: typing.ClassVar[UnitekQuantity]
    RAW: typing.ClassVar[UnitekQuantity]
    SPEED: typing.ClassVar[UnitekQuantity]
    TIME: typing.ClassVar[UnitekQuantity]
    TORQUE: typing.ClassVar[UnitekQuantity]
    __members__: typing.ClassVar[dict[str, UnitekQuantity]]
    @typing.overload
    def __eq__(self, other: UnitekQuantity) -> bool:
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
    def __ne__(self, other: UnitekQuantity) -> bool:
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
class UnitekRegister:
    """
    One row of the UNITEK register table.
    """
    def __init__(self, regid: typing.SupportsInt | typing.SupportsIndex, name: str, bits: typing.SupportsInt | typing.SupportsIndex = 16, signed: bool = False, access: UnitekAccess = ..., quantity: UnitekQuantity = ..., unit: str = '', scale: typing.SupportsFloat | typing.SupportsIndex = 1.0, min: typing.SupportsInt | typing.SupportsIndex | None = None, max: typing.SupportsInt | typing.SupportsIndex | None = None, description: str = '') -> None:
        ...
    def __repr__(self) -> str:
        ...
    def from_raw(self, raw: typing.SupportsInt | typing.SupportsIndex, bits: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    @property
    def access(self) -> UnitekAccess:
        ...
    @property
    def bits(self) -> int:
        ...
    @property
    def description(self) -> str:
        ...
    @property
    def max(self) -> int:
        ...
    @property
    def min(self) -> int:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def quantity(self) -> UnitekQuantity:
        ...
    @property
    def readable(self) -> bool:
        ...
    @property
    def regid(self) -> int:
        ...
    @property
    def scale(self) -> float:
        ...
    @property
    def signed(self) -> bool:
        ...
    @property
    def unit(self) -> str:
        ...
    @property
    def writable(self) -> bool:
        ...
class UnitekRegisterTable:
    """
    The UNITEK REGIDs: the 12 documented ones, extendable.
    """
    def __contains__(self, arg0: typing.Any) -> bool:
        ...
    def __getitem__(self, arg0: typing.Any) -> UnitekRegister:
        ...
    def __init__(self, builtin: bool = True) -> None:
        ...
    def __len__(self) -> int:
        ...
    def add(self, register: UnitekRegister) -> None:
        ...
    def rows(self) -> list[UnitekRegister]:
        ...
class UnitekScalings:
    """
    §6.1 scalings: N max, 65536 num/rev, device current.
    """
    def __init__(self, n_max_rpm: typing.SupportsFloat | typing.SupportsIndex = 3000.0, counts_per_rev: typing.SupportsFloat | typing.SupportsIndex = 65536.0, i_max_num: typing.SupportsFloat | typing.SupportsIndex = 160.0, i_max_a: typing.SupportsFloat | typing.SupportsIndex = 10.0) -> None:
        ...
    def to_num(self, register: UnitekRegister, value: typing.SupportsFloat | typing.SupportsIndex) -> int:
        ...
    def to_physical(self, register: UnitekRegister, num: typing.SupportsInt | typing.SupportsIndex) -> float:
        ...
    @property
    def counts_per_rev(self) -> float:
        ...
    @property
    def i_max_a(self) -> float:
        ...
    @property
    def i_max_num(self) -> float:
        ...
    @property
    def n_max_rpm(self) -> float:
        ...
class UnitekStream:
    """
    One cyclic register: a ring of (timestamp ns, value num) filled by the bus thread.
    """
    def read(self, max: typing.SupportsInt | typing.SupportsIndex = -1) -> tuple:
        """
        (timestamps int64 ns, values int64 num) received since the last read, oldest first
        """
    @property
    def active(self) -> bool:
        ...
    @property
    def capacity(self) -> int:
        ...
    @property
    def count(self) -> int:
        """
        samples received since the subscription
        """
    @property
    def interval_ms(self) -> int:
        ...
    @property
    def lost(self) -> int:
        """
        samples overwritten before read() took them
        """
    @property
    def regid(self) -> int:
        ...
    @property
    def times(self) -> numpy.typing.NDArray[numpy.int64]:
        """
        the whole ring (zero-copy, read-only use; sample k at k % capacity)
        """
    @property
    def values(self) -> numpy.typing.NDArray[numpy.int64]:
        ...
class UnitekClientCounters:
    @property
    def callback_errors(self) -> int:
        ...
    @property
    def rejected(self) -> int:
        ...
    @property
    def replies(self) -> int:
        ...
    @property
    def unsolicited(self) -> int:
        ...
class UnitekClient:
    """
    UNITEK register protocol client over a CAN bus (see client.hpp).
    """
    def __init__(self, bus: Bus, rx_id: typing.SupportsInt | typing.SupportsIndex = 513, tx_id: typing.SupportsInt | typing.SupportsIndex = 385, timeout: typing.Any = 0.2, table: UnitekRegisterTable | None = None, clock: Clock = None) -> None:
        ...
    def add_register(self, register: UnitekRegister) -> None:
        ...
    def close(self) -> None:
        ...
    def disable(self) -> None:
        ...
    def enable(self) -> None:
        ...
    def on_status(self, callback: typing.Any) -> None:
        ...
    def read(self, regid: typing.SupportsInt | typing.SupportsIndex, timeout: typing.Any = None) -> int:
        ...
    def set_events(self, on: bool, mask: typing.SupportsInt | typing.SupportsIndex | None = None) -> None:
        ...
    def set_receive_id(self, rx_id: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def store_eeprom(self, level: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def subscribe(self, regid: typing.SupportsInt | typing.SupportsIndex, interval_ms: typing.SupportsInt | typing.SupportsIndex, capacity: typing.SupportsInt | typing.SupportsIndex = 65536, callback: typing.Any = None) -> UnitekStream:
        ...
    def unsubscribe(self, regid: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write(self, regid: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_raw(self, regid: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex, bits: typing.SupportsInt | typing.SupportsIndex = 16) -> None:
        ...
    @property
    def counters(self) -> UnitekClientCounters:
        ...
    @property
    def cyclic(self) -> list[tuple[int, int]]:
        ...
    @property
    def events(self) -> int:
        ...
    @property
    def last_event_status(self) -> int | None:
        ...
    @property
    def mode(self) -> int:
        ...
    @property
    def rx_id(self) -> int:
        ...
    @property
    def table(self) -> UnitekRegisterTable:
        ...
    @property
    def tx_id(self) -> int:
        ...
class UnitekSimCounters:
    @property
    def bit_rate_mismatch(self) -> int:
        ...
    @property
    def cyclic_refused(self) -> int:
        ...
    @property
    def events_out(self) -> int:
        ...
    @property
    def frames_in(self) -> int:
        ...
    @property
    def frames_out(self) -> int:
        ...
    @property
    def ignored(self) -> int:
        ...
    @property
    def malformed(self) -> int:
        ...
    @property
    def refused(self) -> int:
        ...
    @property
    def unknown(self) -> int:
        ...
class UnitekSim(SimulatedDevice):
    """
    A simulated UNITEK servo on the register protocol (see sim.hpp).
    """
    def __init__(self, clock: Clock, rx_id: typing.SupportsInt | typing.SupportsIndex = 513, tx_id: typing.SupportsInt | typing.SupportsIndex = 385, n_max_rpm: typing.SupportsFloat | typing.SupportsIndex = 3000.0, acc_ramp_ms: typing.SupportsFloat | typing.SupportsIndex = 1000.0, dec_ramp_ms: typing.SupportsFloat | typing.SupportsIndex = 1000.0, position_control: bool = True, speed_control: bool = True, calibrated: bool = False, tol_num: typing.SupportsInt | typing.SupportsIndex = 64, minus_limit_num: typing.SupportsFloat | typing.SupportsIndex | None = -6553600.0, plus_limit_num: typing.SupportsFloat | typing.SupportsIndex | None = 6553600.0, torque_continuous_num: typing.SupportsInt | typing.SupportsIndex = 32767, dummy: typing.SupportsInt | typing.SupportsIndex = 0, table: UnitekRegisterTable | None = None, device: str = 'DS 205/405', motor_i_max_num: typing.SupportsInt | typing.SupportsIndex | None = None, btr: typing.SupportsInt | typing.SupportsIndex = 16421, analog_command: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
        ...
    def eeprom(self) -> dict[int, int]:
        ...
    def force_error(self, bits: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        latch NDrive error (0-15: power stage off) / warning (16-31) bits in 0x8F
        """
    def force_icns(self, active: bool | None) -> None:
        ...
    def force_limit(self, direction: typing.SupportsInt | typing.SupportsIndex, active: bool | None) -> None:
        ...
    def load_eeprom(self, values: collections.abc.Mapping[typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex]) -> None:
        ...
    def on_eeprom_store(self, callback: typing.Any) -> None:
        """
        callback(dict regid -> value) after each EEPROM store (0x84)
        """
    def on_frame(self, frame: Frame) -> None:
        ...
    def sent(self, regid: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def service(self) -> int:
        """
        emit every frame due by the clock's now; returns the next due time (ns, -1 none)
        """
    def set_analog_input(self, channel: typing.SupportsInt | typing.SupportsIndex, volts: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        AIN1/AIN2 (+/- 10 V, 2949 num/V); the speed command when analog_command names the input
        """
    def set_calibrated(self, on: bool) -> None:
        ...
    def set_hardware_enable(self, on: bool) -> None:
        ...
    def value(self, regid: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    @property
    def bit_rate(self) -> float:
        """
        bit/s of its BTR (§3.1 table)
        """
    @property
    def bus_bit_rate(self) -> float:
        """
        bit/s of the bus it is attached to (0: none modelled)
        """
    @property
    def counters(self) -> UnitekSimCounters:
        ...
    @property
    def cyclic(self) -> list[tuple[int, int]]:
        ...
    @property
    def n_max_rpm(self) -> float:
        ...
    @property
    def position_num(self) -> float:
        ...
    @property
    def rx_id(self) -> int:
        ...
    @property
    def speed_num(self) -> float:
        ...
    @property
    def status(self) -> int:
        ...
    @property
    def tx_id(self) -> int:
        ...
class UnitekCaptureSource(PollSource):
    """
    A PollSource taking the latest cyclic transmission of each register (columns: arrival ns, values).
    """
    def close(self) -> None:
        """
        Stops the cyclic transmissions this source started (idempotent).
        """
    @property
    def interval_ms(self) -> int:
        ...
    @property
    def max_age(self) -> float:
        ...
def abort_text(code: typing.SupportsInt | typing.SupportsIndex) -> typing.Any:
    """
    CiA 301 text for an SDO abort code (None if unknown).
    """
def arcus_acc_range(hspd: typing.SupportsInt | typing.SupportsIndex, lspd: typing.SupportsInt | typing.SupportsIndex) -> tuple[int, int]:
    """
    (min, max) ACC in ms the drive accepts for HSPD/LSPD (Table A.0; max truncated to 10 ms like the manual's examples).
    """
def arcus_build_request(address: typing.SupportsInt | typing.SupportsIndex, command: str) -> bytes:
    """
    b'@NN<command>\\r' (validated).
    """
def arcus_canopen_object_dictionary() -> ObjectDictionary:
    """
    Table 10.1 as a typed canopen.ObjectDictionary (types, access, limits, defaults, codecs): what the arcus-canopen client reads and writes by, and the source of the shipped EDS.
    """
def arcus_canopen_objects() -> list:
    """
    The DMX-CAN object dictionary the simulator serves (Table 10.1): (index, sub, name, type, access, default, low, high, unit, persists) tuples.
    """
def arcus_check_strict(params: ArcusProfileParams) -> None:
    ...
def arcus_commands() -> list[ArcusCommandInfo]:
    """
    The command table (Table 11.0 plus the commands the sections describe).
    """
def arcus_effective(params: ArcusProfileParams) -> tuple[ArcusProfileParams, int, list[str]]:
    """
    (effective params, window number, [adjustments]) after Appendix A.
    """
def arcus_max_acc_ms(hspd_pps: typing.SupportsFloat | typing.SupportsIndex, lspd_pps: typing.SupportsFloat | typing.SupportsIndex) -> float:
    ...
def arcus_parse_reply(raw: typing.Any) -> tuple[typing.Any, str]:
    """
    (address or None, body) of one reply without its NUL; ProtocolError on bytes it never sends.
    """
def arcus_poll_source(link: LineLink, address: typing.SupportsInt | typing.SupportsIndex, names: collections.abc.Sequence[str], timeout: typing.Any = None, query_retries: typing.SupportsInt | typing.SupportsIndex = 1) -> PollSource:
    ...
def arcus_speed_windows() -> list[ArcusSpeedWindow]:
    ...
def arcus_window_for_hspd(hspd_pps: typing.SupportsFloat | typing.SupportsIndex) -> ArcusSpeedWindow:
    ...
def arcus_window_for_sspdm(sspdm: typing.SupportsInt | typing.SupportsIndex) -> ArcusSpeedWindow:
    ...
def cia402_decode_statusword(statusword: typing.SupportsInt | typing.SupportsIndex) -> str:
    """
    State name; 'UNKNOWN' for patterns outside the table.
    """
def cia402_next_step(from_state: str, to_state: str) -> typing.Any:
    ...
def cia402_object_dictionary(node_id: typing.SupportsInt | typing.SupportsIndex = 1) -> ObjectDictionary:
    """
    The same objects as a typed canopen.ObjectDictionary (types, access, limits, defaults, codecs): what the generic Drive adapter reads and writes by.
    """
def cia402_objects() -> list:
    """
    The generic CiA 402 simulator's objects: (index, sub, name, type, access, default, low, high, unit, persists, description).
    """
def cia402_position_profile(start: MotionState, target: typing.SupportsFloat | typing.SupportsIndex, params: Cia402ProfileParams) -> Profile:
    ...
def cia402_quick_stop_profile(start: MotionState, params: Cia402ProfileParams) -> Profile:
    ...
def cia402_velocity_profile(start: MotionState, target_velocity: typing.SupportsFloat | typing.SupportsIndex, params: Cia402ProfileParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> Profile:
    ...
def decode_value(data_type: DataType, data: bytes) -> typing.Any:
    """
    The Python value of little-endian bytes of a CiA 301 type (int, float, bool, str or bytes).
    """
def dmac_error_names(error: typing.SupportsInt | typing.SupportsIndex) -> list[str]:
    ...
def dmac_format_value(value: typing.SupportsInt | typing.SupportsIndex, radix: DmacRadix | str = ...) -> str:
    """
    '+123', 'h0000007B' or 'b00000000 ... 01111011'; radix is a DmacRadix or 'dec'/'hex'/'bin'.
    """
def dmac_parse_read_reply(reply: bytes) -> DmacReadReply | None:
    """
    Parses 'aa#MNE[.bit]=value' strictly into a DmacReadReply; None when it breaks the grammar.
    """
def dmac_poll_source(link: LineLink, address: typing.SupportsInt | typing.SupportsIndex, names: collections.abc.Sequence[str], baud: typing.SupportsInt | typing.SupportsIndex = 38400, timeout: typing.Any = None) -> PollSource:
    ...
def dmac_position_profile(start: MotionState, target: typing.SupportsFloat | typing.SupportsIndex, params: DmacProfileParams) -> Profile:
    ...
def dmac_ramp_time(params: DmacProfileParams, v_from: typing.SupportsFloat | typing.SupportsIndex, v_to: typing.SupportsFloat | typing.SupportsIndex) -> float:
    ...
def dmac_speed_profile(start: MotionState, speed: typing.SupportsFloat | typing.SupportsIndex, params: DmacProfileParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> Profile:
    ...
def dmac_status_names(status: typing.SupportsInt | typing.SupportsIndex) -> list[str]:
    ...
def dmac_stream_interpolation(axes: collections.abc.Sequence[DmacClient], segments: collections.abc.Sequence[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]], interpol_time_ms: typing.SupportsInt | typing.SupportsIndex = 100, fifo_size: typing.SupportsInt | typing.SupportsIndex = 64, sleep: typing.Any = None, backoff: typing.Any = None) -> DmacStreamStats:
    """
    Streams segments[k][axis] to every axis, starting them with SYNCHRO INTERPOL.
    """
def dmac_synchro(link: LineLink, what: DmacKeyword | str) -> None:
    """
    Global SYNCHRO ON|OFF|TOP|INTERPOL (no reply).
    """
def dmac_variable(name: str) -> DmacVariableInfo:
    """
    The DmacVariableInfo of a variable, by full name or mnemonic ('#ACCEL_TIME', 'ATI').
    """
def emcy_code_text(code: typing.SupportsInt | typing.SupportsIndex) -> str:
    ...
def emcy_decode(frame: Frame) -> typing.Any:
    ...
def emcy_encode(node: typing.SupportsInt | typing.SupportsIndex, code: typing.SupportsInt | typing.SupportsIndex, register: typing.SupportsInt | typing.SupportsIndex = 0, data: bytes = b'') -> Frame:
    ...
def encode_value(data_type: DataType, value: typing.Any) -> bytes:
    """
    The little-endian bytes of `value` as a CiA 301 type; InvalidArgument when it does not fit.
    """
def heartbeat_decode(frame: Frame) -> typing.Any:
    """
    (node, state name, raw byte) or None (DLC != 1, bad id).
    """
def heartbeat_encode(node: typing.SupportsInt | typing.SupportsIndex, state: str) -> Frame:
    ...
def jerk_limited_durations(cases: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    Rows: p0, v0, a0, target, vmax, amax, jmax; the duration of each row's plan.
    """
def monotonic_ns() -> int:
    """
    The monotonic clock frame timestamps use (ns).
    """
def nmt_decode(frame: Frame) -> typing.Any:
    """
    (command, node) or None for anything that is not a valid NMT frame.
    """
@typing.overload
def nmt_encode(command: NmtCommand, node: typing.SupportsInt | typing.SupportsIndex) -> Frame:
    ...
@typing.overload
def nmt_encode(command: typing.SupportsInt | typing.SupportsIndex, node: typing.SupportsInt | typing.SupportsIndex) -> Frame:
    ...
def open_port(path: str, baud: typing.SupportsInt | typing.SupportsIndex = 0) -> Port:
    """
    Opens a serial device at `baud` (0 = keep the current speed), or a line behind a serial gateway:
    'socket://host:port' (raw TCP, baud ignored) or 'rfc2217://host:port' (baud sent to the gateway).
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
def pdo_read_config(sdo: typing.Any, node: typing.SupportsInt | typing.SupportsIndex, tpdo: bool, number: typing.SupportsInt | typing.SupportsIndex) -> PdoConfig:
    ...
def pdo_write_config(sdo: typing.Any, node: typing.SupportsInt | typing.SupportsIndex, tpdo: bool, number: typing.SupportsInt | typing.SupportsIndex, cob_id: typing.SupportsInt | typing.SupportsIndex | None = None, enabled: bool = True, transmission_type: typing.SupportsInt | typing.SupportsIndex | None = None, inhibit_100us: typing.SupportsInt | typing.SupportsIndex | None = None, event_timer_ms: typing.SupportsInt | typing.SupportsIndex | None = None, sync_start: typing.SupportsInt | typing.SupportsIndex | None = None, mapping: collections.abc.Iterable | None = None, procedure: typing.Any = 'cia301') -> None:
    """
    procedure: a PdoProcedure or its name ('cia301', 'direct').
    """
def plan_jerk_limited(start: MotionState, target: typing.SupportsFloat | typing.SupportsIndex, limits: Limits) -> Profile:
    ...
def plan_jerk_limited_velocity(start: MotionState, target_velocity: typing.SupportsFloat | typing.SupportsIndex, limits: Limits, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> Profile:
    ...
def plan_straight_line(start: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], target: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], limits: collections.abc.Sequence[Limits], shape: RampShape = ...) -> list[Profile]:
    ...
def plan_synchronized(start: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], target: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], limits: collections.abc.Sequence[Limits], shape: RampShape = ...) -> list[Profile]:
    ...
def plan_synchronized_jerk_limited(start: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], target: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], limits: collections.abc.Sequence[Limits]) -> list[Profile]:
    ...
@typing.overload
def plan_trapezoid(start: MotionState, target: typing.SupportsFloat | typing.SupportsIndex, limits: Limits) -> Profile:
    ...
@typing.overload
def plan_trapezoid(start: MotionState, target: typing.SupportsFloat | typing.SupportsIndex, limits: Limits, shape: RampShape) -> Profile:
    ...
def plan_velocity(start: MotionState, target_velocity: typing.SupportsFloat | typing.SupportsIndex, limits: Limits, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0, shape: RampShape = ...) -> Profile:
    ...
def play(bus: Bus, entries: collections.abc.Sequence[LogEntry], speed: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> int:
    """
    Replays entries onto bus: speed 1.0 = original timing, 0 = as fast as possible.
    """
def pmc007_assemble(text: str) -> list[int]:
    """
    Mnemonic text -> 32-bit words (the spec's reading of the encoding).
    """
def pmc007_convert_position(position: typing.SupportsFloat | typing.SupportsIndex, from_setting: typing.SupportsInt | typing.SupportsIndex, to_setting: typing.SupportsInt | typing.SupportsIndex) -> float:
    ...
def pmc007_disassemble(words: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> str:
    ...
def pmc007_eds() -> str:
    """
    The EDS text generated from the table (node-ID as $NODEID).
    """
def pmc007_gear_acceleration(gear: typing.SupportsInt | typing.SupportsIndex) -> float:
    ...
def pmc007_microsteps(setting: typing.SupportsInt | typing.SupportsIndex) -> int:
    ...
def pmc007_object_dictionary(node_id: typing.SupportsInt | typing.SupportsIndex = 5) -> ObjectDictionary:
    """
    The PMC007 dictionary (every row of the table), defaults evaluated for `node_id`.
    """
def pmc007_position_profile(start: MotionState, target: typing.SupportsFloat | typing.SupportsIndex, params: Pmc007ProfileParams) -> Profile:
    ...
def pmc007_speed_profile(start: MotionState, speed: typing.SupportsFloat | typing.SupportsIndex, params: Pmc007ProfileParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> Profile:
    ...
def pmc007_storage(index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> Pmc007Storage:
    """
    The table's storage class of one object (B-P37).
    """
def read_log(path: str) -> tuple[list[LogEntry], int]:
    """
    Reads a candump (.log) or ASC (.asc) file: (entries, bad_line_count).
    """
def scan_network(bus: Bus, first: typing.SupportsInt | typing.SupportsIndex = 1, last: typing.SupportsInt | typing.SupportsIndex = 127, sdo_timeout: typing.SupportsFloat | typing.SupportsIndex = 0.2, listen: typing.SupportsFloat | typing.SupportsIndex = 0.0, probe_sdo: bool = True, identity: bool = True) -> list[NodeInfo]:
    ...
def sdo_poll_source(sdo: SdoClient, objects: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex, str]]) -> PollSource:
    """
    A PollSource uploading [(index, subindex, type)] each sample (type: 'i32', 'u16', ...).
    """
def slcan_encode(frame: Frame, timestamp_ms: typing.Any = None) -> bytes:
    """
    The SLCAN line for `frame` (t/T/r/R, CR included).
    """
def socketcan_unavailable_reason() -> typing.Any:
    """
    None when AF_CAN raw sockets work on this machine, else why not.
    """
def split_interpolation(axes: collections.abc.Sequence[Profile], period_ms: typing.SupportsInt | typing.SupportsIndex) -> list[list[int]]:
    ...
def sync_encode(counter: typing.SupportsInt | typing.SupportsIndex | None = None, cob_id: typing.SupportsInt | typing.SupportsIndex = 128) -> Frame:
    ...
def synchronized_jerk_limited_durations(cases: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    Rows: 3 axes x (p0, target, vmax, amax, jmax); the common duration of each row.
    """
def time_decode(frame: Frame) -> typing.Any:
    """
    Unix time in ms, or None.
    """
def time_encode(unix_ms: typing.SupportsInt | typing.SupportsIndex) -> Frame:
    ...
def unitek_analog_command_num(volts: typing.SupportsFloat | typing.SupportsIndex) -> int:
    """
    §6.1: the num of an analog command (10 V = 29490)
    """
def unitek_bit_rate_for_btr(btr: typing.SupportsInt | typing.SupportsIndex) -> float:
    ...
def unitek_bit_timings() -> list:
    """
    §3.1: bit rate (kbit/s), BTR setting value, longest line (m)
    """
def unitek_btr_for_bit_rate(bit_rate: typing.SupportsFloat | typing.SupportsIndex) -> int:
    ...
def unitek_capture_source(client: UnitekClient, regids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], interval_ms: typing.SupportsInt | typing.SupportsIndex, max_age: typing.Any = None) -> UnitekCaptureSource:
    """
    Subscribes each register every interval_ms (unless it already transmits) and captures it; max_age (s, default 3 intervals + 2 ms): older data counts as stale.
    """
def unitek_continuous_current_num(device: str, amps: typing.SupportsFloat | typing.SupportsIndex) -> int:
    ...
def unitek_decode_from_drive(data: typing.Any) -> tuple[int, int, int]:
    """
    (regid, raw value, bits) of a frame from the drive; UnitekFrameError unless DLC 4 or 6
    """
def unitek_decode_to_drive(data: typing.Any) -> tuple[int, int, int]:
    """
    (regid, raw value, bits) as the drive evaluates the frame; UnitekFrameError for DLC < 3 or > 8
    """
def unitek_device_currents() -> list:
    ...
def unitek_effective_current_limit_num(device: str, motor_limit_num: typing.SupportsInt | typing.SupportsIndex) -> int:
    """
    §6.1: the smaller of the motor's and the device's peak current (num)
    """
def unitek_encode_request(regid: typing.SupportsInt | typing.SupportsIndex, interval: typing.SupportsInt | typing.SupportsIndex) -> bytes:
    ...
def unitek_encode_write(regid: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex, bits: typing.SupportsInt | typing.SupportsIndex = 16) -> bytes:
    ...
def unitek_poll_source(client: UnitekClient, regids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> PollSource:
    """
    A PollSource reading each register (3D REGID 00) every sample.
    """
def unitek_sim_default_table() -> UnitekRegisterTable:
    ...
def unitek_speed_profile(start: MotionState, speed_num: typing.SupportsFloat | typing.SupportsIndex, params: UnitekRampParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> Profile:
    ...
def wire_bits_worst_case(frame: Frame) -> int:
    """
    Bits a classic frame occupies on the wire with worst-case stuffing, incl. intermission.
    """
ABORT_CODES: dict = {84082688: 'Toggle bit not alternated', 84148224: 'SDO protocol timed out', 84148225: 'Client/server command specifier not valid or unknown', 84148226: 'Invalid block size (block mode only)', 84148227: 'Invalid sequence number (block mode only)', 84148228: 'CRC error (block mode only)', 84148229: 'Out of memory', 100728832: 'Unsupported access to an object', 100728833: 'Attempt to read a write only object', 100728834: 'Attempt to write a read only object', 100794368: 'Object does not exist in the object dictionary', 100925505: 'Object cannot be mapped to the PDO', 100925506: 'The number and length of the objects to be mapped would exceed PDO length', 100925507: 'General parameter incompatibility reason', 100925511: 'General internal incompatibility in the device', 101056512: 'Access failed due to a hardware error', 101122064: 'Data type does not match, length of service parameter does not match', 101122066: 'Data type does not match, length of service parameter too high', 101122067: 'Data type does not match, length of service parameter too low', 101253137: 'Sub-index does not exist', 101253168: 'Invalid value for parameter (download only)', 101253169: 'Value of parameter written too high (download only)', 101253170: 'Value of parameter written too low (download only)', 101253174: 'Maximum value is less than minimum value', 101318691: 'Resource not available: SDO connection', 134217728: 'General error', 134217760: 'Data cannot be transferred or stored to the application', 134217761: 'Data cannot be transferred or stored to the application because of local control', 134217762: 'Data cannot be transferred or stored to the application because of the present device state', 134217763: 'Object dictionary dynamic generation fails or no object dictionary is present', 134217764: 'No data available'}
ARCUS_MAX_MOVE_DISTANCE: int = 262143
ARCUS_MAX_REPLY: int = 72
ARCUS_MAX_REQUEST: int = 64

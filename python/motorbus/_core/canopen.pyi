from __future__ import annotations
import collections.abc
import enum
import motorbus._core.can
import motorbus._core.poll
import motorbus._core.runtime
import typing
__all__: list[str] = ['ABORT_CODES', 'Cia402Device', 'Cia402Host', 'DataType', 'EmcyConsumer', 'EmcyError', 'EmcyProducer', 'HeartbeatConsumer', 'HeartbeatProducer', 'HeartbeatService', 'JitterStats', 'LocalNode', 'LocalNodeCounters', 'NmtCommand', 'NmtEventWait', 'NmtMaster', 'NodeHealth', 'NodeInfo', 'ObjectDictionary', 'PdoCaptureSource', 'PdoConfig', 'PdoCounters', 'PdoLayout', 'PdoProcedure', 'PdoReceiver', 'PdoSender', 'PdoService', 'SdoClient', 'SdoClientCounters', 'SdoServerCounters', 'SyncProducer', 'Variable', 'abort_text', 'cia402_decode_statusword', 'cia402_next_step', 'decode_value', 'emcy_code_text', 'emcy_decode', 'emcy_encode', 'encode_value', 'heartbeat_decode', 'heartbeat_encode', 'nmt_decode', 'nmt_encode', 'nmt_wait_async', 'pdo_read_config', 'pdo_write_config', 'scan_network', 'sdo_poll_source', 'sync_encode', 'time_decode', 'time_encode']
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
    def __init__(self, bus: motorbus._core.can.Bus, node_id: typing.SupportsInt | typing.SupportsIndex, timeout: typing.SupportsFloat | typing.SupportsIndex = 1.0, max_transfer: typing.SupportsInt | typing.SupportsIndex = 1048576, block_size: typing.SupportsInt | typing.SupportsIndex = 127, read_retries: typing.SupportsInt | typing.SupportsIndex = 0, request_id: typing.SupportsInt | typing.SupportsIndex = 0, response_id: typing.SupportsInt | typing.SupportsIndex = 0, block_fallback: bool = False, block_crc: bool = True) -> None:
        """
        block_crc: block transfers offer and require CRC-16 (a server answering without it is refused, abort 0x05040004); False for a server without CRC, whose block data is then unchecked.
        """
    def cancel_async(self, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        Withdraws an async transfer (the running one is aborted on the wire); False if already done.
        """
    def check_deadline(self) -> typing.Any:
        """
        Fires the running async transfer's due timers; the next deadline (monotonic_ns) or None.
        """
    def close(self) -> None:
        """
        Fails pending async transfers with ClosedError; later transfers raise ClosedError.
        """
    def download(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, data: typing.Any, block: bool = False, segmented: bool = False) -> None:
        ...
    def download_async(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, data: typing.Any, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex, block: bool = False, segmented: bool = False) -> None:
        """
        Starts a download; completes `token` on `completions` with None.
        """
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
    def upload_async(self, index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex, block: bool = False) -> None:
        """
        Starts an upload; completes `token` on `completions` with its bytes.
        """
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
    def async_pending(self) -> int:
        ...
    @property
    def closed(self) -> bool:
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
    def __init__(self, bus: motorbus._core.can.Bus, node_id: typing.SupportsInt | typing.SupportsIndex, od: ObjectDictionary, sdo_timeout: typing.SupportsFloat | typing.SupportsIndex = 1.0, block_transfer: bool = True, send_boot_up: bool = True) -> None:
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
    def __init__(self, bus: motorbus._core.can.Bus, own_node_id: typing.SupportsInt | typing.SupportsIndex | None = None) -> None:
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
class NmtEventWait:
    """
    An awaited NMT event of one node (motorbus.canopen.nmt's *_async waits).
    """
    def cancel(self) -> None:
        ...
class HeartbeatConsumer:
    """
    Per-node heartbeat supervision: started / lost / back / reset / state events.
    """
    def __init__(self, bus: motorbus._core.can.Bus, clock: motorbus._core.runtime.Clock = None) -> None:
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
    def __init__(self, bus: motorbus._core.can.Bus, node: typing.SupportsInt | typing.SupportsIndex, period: typing.SupportsFloat | typing.SupportsIndex, state: typing.Any = 'OPERATIONAL', clock: motorbus._core.runtime.Clock = None) -> None:
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
    def __init__(self, bus: motorbus._core.can.Bus, history: typing.SupportsInt | typing.SupportsIndex = 32) -> None:
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
    def __init__(self, bus: motorbus._core.can.Bus, node: typing.SupportsInt | typing.SupportsIndex, inhibit_100us: typing.SupportsInt | typing.SupportsIndex = 0, queue_limit: typing.SupportsInt | typing.SupportsIndex = 16, clock: motorbus._core.runtime.Clock = None) -> None:
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
    def __init__(self, bus: motorbus._core.can.Bus, period: typing.SupportsFloat | typing.SupportsIndex, counter_overflow: typing.SupportsInt | typing.SupportsIndex = 0, cob_id: typing.SupportsInt | typing.SupportsIndex = 128) -> None:
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
    def __init__(self, bus: motorbus._core.can.Bus, cob_id: typing.SupportsInt | typing.SupportsIndex, entries: collections.abc.Iterable) -> None:
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
    def __init__(self, bus: motorbus._core.can.Bus, cob_id: typing.SupportsInt | typing.SupportsIndex, entries: collections.abc.Iterable) -> None:
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
class PdoCaptureSource(motorbus._core.poll.PollSource):
    """
    A PollSource taking the latest values of TPDOs (columns: arrival ns, values).
    """
    def __init__(self, bus: motorbus._core.can.Bus, node: typing.SupportsInt | typing.SupportsIndex, tpdos: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, collections.abc.Iterable]], columns: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex]], max_age: typing.Any) -> None:
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
def abort_text(code: typing.SupportsInt | typing.SupportsIndex) -> typing.Any:
    """
    CiA 301 text for an SDO abort code (None if unknown).
    """
def cia402_decode_statusword(statusword: typing.SupportsInt | typing.SupportsIndex) -> str:
    """
    State name; 'UNKNOWN' for patterns outside the table.
    """
def cia402_next_step(from_state: str, to_state: str) -> typing.Any:
    ...
def decode_value(data_type: DataType, data: bytes) -> typing.Any:
    """
    The Python value of little-endian bytes of a CiA 301 type (int, float, bool, str or bytes).
    """
def emcy_code_text(code: typing.SupportsInt | typing.SupportsIndex) -> str:
    ...
def emcy_decode(frame: motorbus._core.can.Frame) -> typing.Any:
    ...
def emcy_encode(node: typing.SupportsInt | typing.SupportsIndex, code: typing.SupportsInt | typing.SupportsIndex, register: typing.SupportsInt | typing.SupportsIndex = 0, data: bytes = b'') -> motorbus._core.can.Frame:
    ...
def encode_value(data_type: DataType, value: typing.Any) -> bytes:
    """
    The little-endian bytes of `value` as a CiA 301 type; InvalidArgument when it does not fit.
    """
def heartbeat_decode(frame: motorbus._core.can.Frame) -> typing.Any:
    """
    (node, state name, raw byte) or None (DLC != 1, bad id).
    """
def heartbeat_encode(node: typing.SupportsInt | typing.SupportsIndex, state: str) -> motorbus._core.can.Frame:
    ...
def nmt_decode(frame: motorbus._core.can.Frame) -> typing.Any:
    """
    (command, node) or None for anything that is not a valid NMT frame.
    """
@typing.overload
def nmt_encode(command: NmtCommand, node: typing.SupportsInt | typing.SupportsIndex) -> motorbus._core.can.Frame:
    ...
@typing.overload
def nmt_encode(command: typing.SupportsInt | typing.SupportsIndex, node: typing.SupportsInt | typing.SupportsIndex) -> motorbus._core.can.Frame:
    ...
def nmt_wait_async(bus: motorbus._core.can.Bus, node: typing.SupportsInt | typing.SupportsIndex, state: str | None = None, boot_up: bool = False, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex) -> NmtEventWait:
    """
    Completes `token` with the state name of node's next boot-up (boot_up), heartbeat in `state`, or any heartbeat; cancel() the returned waiter when no longer wanted (C++ canopen::NmtEventWait).
    """
def pdo_read_config(sdo: typing.Any, node: typing.SupportsInt | typing.SupportsIndex, tpdo: bool, number: typing.SupportsInt | typing.SupportsIndex) -> PdoConfig:
    ...
def pdo_write_config(sdo: typing.Any, node: typing.SupportsInt | typing.SupportsIndex, tpdo: bool, number: typing.SupportsInt | typing.SupportsIndex, cob_id: typing.SupportsInt | typing.SupportsIndex | None = None, enabled: bool = True, transmission_type: typing.SupportsInt | typing.SupportsIndex | None = None, inhibit_100us: typing.SupportsInt | typing.SupportsIndex | None = None, event_timer_ms: typing.SupportsInt | typing.SupportsIndex | None = None, sync_start: typing.SupportsInt | typing.SupportsIndex | None = None, mapping: collections.abc.Iterable | None = None, procedure: typing.Any = 'cia301') -> None:
    """
    procedure: a PdoProcedure or its name ('cia301', 'direct').
    """
def scan_network(bus: motorbus._core.can.Bus, first: typing.SupportsInt | typing.SupportsIndex = 1, last: typing.SupportsInt | typing.SupportsIndex = 127, sdo_timeout: typing.SupportsFloat | typing.SupportsIndex = 0.2, listen: typing.SupportsFloat | typing.SupportsIndex = 0.0, probe_sdo: bool = True, identity: bool = True) -> list[NodeInfo]:
    ...
def sdo_poll_source(sdo: SdoClient, objects: collections.abc.Sequence[tuple[typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex, str]]) -> motorbus._core.poll.PollSource:
    """
    A PollSource uploading [(index, subindex, type)] each sample (type: 'i32', 'u16', ...).
    """
def sync_encode(counter: typing.SupportsInt | typing.SupportsIndex | None = None, cob_id: typing.SupportsInt | typing.SupportsIndex = 128) -> motorbus._core.can.Frame:
    ...
def time_decode(frame: motorbus._core.can.Frame) -> typing.Any:
    """
    Unix time in ms, or None.
    """
def time_encode(unix_ms: typing.SupportsInt | typing.SupportsIndex) -> motorbus._core.can.Frame:
    ...
ABORT_CODES: dict = {84082688: 'Toggle bit not alternated', 84148224: 'SDO protocol timed out', 84148225: 'Client/server command specifier not valid or unknown', 84148226: 'Invalid block size (block mode only)', 84148227: 'Invalid sequence number (block mode only)', 84148228: 'CRC error (block mode only)', 84148229: 'Out of memory', 100728832: 'Unsupported access to an object', 100728833: 'Attempt to read a write only object', 100728834: 'Attempt to write a read only object', 100794368: 'Object does not exist in the object dictionary', 100925505: 'Object cannot be mapped to the PDO', 100925506: 'The number and length of the objects to be mapped would exceed PDO length', 100925507: 'General parameter incompatibility reason', 100925511: 'General internal incompatibility in the device', 101056512: 'Access failed due to a hardware error', 101122064: 'Data type does not match, length of service parameter does not match', 101122066: 'Data type does not match, length of service parameter too high', 101122067: 'Data type does not match, length of service parameter too low', 101253137: 'Sub-index does not exist', 101253168: 'Invalid value for parameter (download only)', 101253169: 'Value of parameter written too high (download only)', 101253170: 'Value of parameter written too low (download only)', 101253174: 'Maximum value is less than minimum value', 101318691: 'Resource not available: SDO connection', 134217728: 'General error', 134217760: 'Data cannot be transferred or stored to the application', 134217761: 'Data cannot be transferred or stored to the application because of local control', 134217762: 'Data cannot be transferred or stored to the application because of the present device state', 134217763: 'Object dictionary dynamic generation fails or no object dictionary is present', 134217764: 'No data available'}

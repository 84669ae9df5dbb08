from __future__ import annotations
import collections.abc
import motorbus._core.can
import motorbus._core.motion
import motorbus._core.poll
import motorbus._core.runtime
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Access', 'CaptureSource', 'Client', 'ClientCounters', 'Quantity', 'RampParams', 'Register', 'RegisterTable', 'Scalings', 'Sim', 'SimCounters', 'Stream', 'analog_command_num', 'bit_rate_for_btr', 'bit_timings', 'btr_for_bit_rate', 'capture_source', 'continuous_current_num', 'decode_from_drive', 'decode_to_drive', 'device_currents', 'effective_current_limit_num', 'encode_request', 'encode_write', 'poll_source', 'sim_default_table', 'speed_profile']
class RampParams:
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
class Access:
    """
    Members:
    
      RW
    
      RO
    
      WO
    """
    RO: typing.ClassVar[Access]
    RW: typing.ClassVar[Access]
    WO: typing.ClassVar[Access]
    __members__: typing.ClassVar[dict[str, Access]]
    @typing.overload
    def __eq__(self, other: Access) -> bool:
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
    def __ne__(self, other: Access) -> bool:
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
class Quantity:
    """
    Members:
    
      RAW
    
      SPEED
    
      POSITION
    
      CURRENT
    
      TORQUE
    
      TIME
    """
    CURRENT: typing.ClassVar[Quantity]
    POSITION: typing.ClassVar[Quantity]
    RAW: typing.ClassVar[Quantity]
    SPEED: typing.ClassVar[Quantity]
    TIME: typing.ClassVar[Quantity]
    TORQUE: typing.ClassVar[Quantity]
    __members__: typing.ClassVar[dict[str, Quantity]]
    @typing.overload
    def __eq__(self, other: Quantity) -> bool:
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
    def __ne__(self, other: Quantity) -> bool:
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
class Register:
    """
    One row of the UNITEK register table.
    """
    def __init__(self, regid: typing.SupportsInt | typing.SupportsIndex, name: str, bits: typing.SupportsInt | typing.SupportsIndex = 16, signed: bool = False, access: Access = ..., quantity: Quantity = ..., unit: str = '', scale: typing.SupportsFloat | typing.SupportsIndex = 1.0, min: typing.SupportsInt | typing.SupportsIndex | None = None, max: typing.SupportsInt | typing.SupportsIndex | None = None, description: str = '') -> None:
        ...
    def __repr__(self) -> str:
        ...
    def from_raw(self, raw: typing.SupportsInt | typing.SupportsIndex, bits: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    @property
    def access(self) -> Access:
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
    def quantity(self) -> Quantity:
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
class RegisterTable:
    """
    The UNITEK REGIDs: the 12 documented ones, extendable.
    """
    def __contains__(self, arg0: typing.Any) -> bool:
        ...
    def __getitem__(self, arg0: typing.Any) -> Register:
        ...
    def __init__(self, builtin: bool = True) -> None:
        ...
    def __len__(self) -> int:
        ...
    def add(self, register: Register) -> None:
        ...
    def rows(self) -> list[Register]:
        ...
class Scalings:
    """
    §6.1 scalings: N max, 65536 num/rev, device current.
    """
    def __init__(self, n_max_rpm: typing.SupportsFloat | typing.SupportsIndex = 3000.0, counts_per_rev: typing.SupportsFloat | typing.SupportsIndex = 65536.0, i_max_num: typing.SupportsFloat | typing.SupportsIndex = 160.0, i_max_a: typing.SupportsFloat | typing.SupportsIndex = 10.0) -> None:
        ...
    def to_num(self, register: Register, value: typing.SupportsFloat | typing.SupportsIndex) -> int:
        ...
    def to_physical(self, register: Register, num: typing.SupportsInt | typing.SupportsIndex) -> float:
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
class Stream:
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
class ClientCounters:
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
class Client:
    """
    UNITEK register protocol client over a CAN bus (see client.hpp).
    """
    def __init__(self, bus: motorbus._core.can.Bus, rx_id: typing.SupportsInt | typing.SupportsIndex = 513, tx_id: typing.SupportsInt | typing.SupportsIndex = 385, timeout: typing.Any = 0.2, table: RegisterTable | None = None, clock: motorbus._core.runtime.Clock = None) -> None:
        ...
    def add_register(self, register: Register) -> None:
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
    def subscribe(self, regid: typing.SupportsInt | typing.SupportsIndex, interval_ms: typing.SupportsInt | typing.SupportsIndex, capacity: typing.SupportsInt | typing.SupportsIndex = 65536, callback: typing.Any = None) -> Stream:
        ...
    def unsubscribe(self, regid: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write(self, regid: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def write_raw(self, regid: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex, bits: typing.SupportsInt | typing.SupportsIndex = 16) -> None:
        ...
    @property
    def counters(self) -> ClientCounters:
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
    def table(self) -> RegisterTable:
        ...
    @property
    def tx_id(self) -> int:
        ...
class SimCounters:
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
class Sim(motorbus._core.can.SimulatedDevice):
    """
    A simulated UNITEK servo on the register protocol (see sim.hpp).
    """
    def __init__(self, clock: motorbus._core.runtime.Clock, rx_id: typing.SupportsInt | typing.SupportsIndex = 513, tx_id: typing.SupportsInt | typing.SupportsIndex = 385, n_max_rpm: typing.SupportsFloat | typing.SupportsIndex = 3000.0, acc_ramp_ms: typing.SupportsFloat | typing.SupportsIndex = 1000.0, dec_ramp_ms: typing.SupportsFloat | typing.SupportsIndex = 1000.0, position_control: bool = True, speed_control: bool = True, calibrated: bool = False, tol_num: typing.SupportsInt | typing.SupportsIndex = 64, minus_limit_num: typing.SupportsFloat | typing.SupportsIndex | None = -6553600.0, plus_limit_num: typing.SupportsFloat | typing.SupportsIndex | None = 6553600.0, torque_continuous_num: typing.SupportsInt | typing.SupportsIndex = 32767, dummy: typing.SupportsInt | typing.SupportsIndex = 0, table: RegisterTable | None = None, device: str = 'DS 205/405', motor_i_max_num: typing.SupportsInt | typing.SupportsIndex | None = None, btr: typing.SupportsInt | typing.SupportsIndex = 16421, analog_command: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
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
    def on_frame(self, frame: motorbus._core.can.Frame) -> None:
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
    def counters(self) -> SimCounters:
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
class CaptureSource(motorbus._core.poll.PollSource):
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
def analog_command_num(volts: typing.SupportsFloat | typing.SupportsIndex) -> int:
    """
    §6.1: the num of an analog command (10 V = 29490)
    """
def bit_rate_for_btr(btr: typing.SupportsInt | typing.SupportsIndex) -> float:
    ...
def bit_timings() -> list:
    """
    §3.1: bit rate (kbit/s), BTR setting value, longest line (m)
    """
def btr_for_bit_rate(bit_rate: typing.SupportsFloat | typing.SupportsIndex) -> int:
    ...
def capture_source(client: Client, regids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], interval_ms: typing.SupportsInt | typing.SupportsIndex, max_age: typing.Any = None) -> CaptureSource:
    """
    Subscribes each register every interval_ms (unless it already transmits) and captures it; max_age (s, default 3 intervals + 2 ms): older data counts as stale.
    """
def continuous_current_num(device: str, amps: typing.SupportsFloat | typing.SupportsIndex) -> int:
    ...
def decode_from_drive(data: typing.Any) -> tuple[int, int, int]:
    """
    (regid, raw value, bits) of a frame from the drive; UnitekFrameError unless DLC 4 or 6
    """
def decode_to_drive(data: typing.Any) -> tuple[int, int, int]:
    """
    (regid, raw value, bits) as the drive evaluates the frame; UnitekFrameError for DLC < 3 or > 8
    """
def device_currents() -> list:
    ...
def effective_current_limit_num(device: str, motor_limit_num: typing.SupportsInt | typing.SupportsIndex) -> int:
    """
    §6.1: the smaller of the motor's and the device's peak current (num)
    """
def encode_request(regid: typing.SupportsInt | typing.SupportsIndex, interval: typing.SupportsInt | typing.SupportsIndex) -> bytes:
    ...
def encode_write(regid: typing.SupportsInt | typing.SupportsIndex, value: typing.SupportsInt | typing.SupportsIndex, bits: typing.SupportsInt | typing.SupportsIndex = 16) -> bytes:
    ...
def poll_source(client: Client, regids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> motorbus._core.poll.PollSource:
    """
    A PollSource reading each register (3D REGID 00) every sample.
    """
def sim_default_table() -> RegisterTable:
    ...
def speed_profile(start: motorbus._core.motion.MotionState, speed_num: typing.SupportsFloat | typing.SupportsIndex, params: RampParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> motorbus._core.motion.Profile:
    ...

from __future__ import annotations
import collections.abc
import motorbus._core.can
import motorbus._core.canopen
import motorbus._core.motion
import motorbus._core.poll
import motorbus._core.runtime
import motorbus._core.serial
import typing
__all__: list[str] = ['ClientBase', 'ClientCounters', 'CommandInfo', 'HomeMethod', 'Homing', 'HomingMethod', 'HomingOptions', 'MAX_MOVE_DISTANCE', 'MAX_REPLY', 'MAX_REQUEST', 'Motion', 'Phase', 'ProfileParams', 'Sim', 'SpeedWindow', 'acc_range', 'build_request', 'canopen_object_dictionary', 'canopen_objects', 'check_strict', 'commands', 'effective', 'max_acc_ms', 'parse_reply', 'poll_source', 'speed_windows', 'window_for_hspd', 'window_for_sspdm']
class SpeedWindow:
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
class ProfileParams:
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
class Phase:
    """
    Where an Motion is in its move (MST bits 0..2).
    
    Members:
    
      IDLE
    
      ACCEL
    
      CONST : at constant speed
    
      DECEL
    """
    ACCEL: typing.ClassVar[Phase]
    CONST: typing.ClassVar[Phase]
    DECEL: typing.ClassVar[Phase]
    IDLE: typing.ClassVar[Phase]
    __members__: typing.ClassVar[dict[str, Phase]]
    @typing.overload
    def __eq__(self, other: Phase) -> bool:
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
    def __ne__(self, other: Phase) -> bool:
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
class Motion:
    def __init__(self, params: ProfileParams = ..., sspdm: typing.SupportsInt | typing.SupportsIndex = 0) -> None:
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
    def phase(self, t: typing.SupportsFloat | typing.SupportsIndex) -> Phase:
        """
        The Phase at time t (MST bits 0..2).
        """
    def set_params(self, arg0: ProfileParams) -> ProfileParams:
        ...
    def set_sspdm(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def stop(self, t: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def effective(self) -> ProfileParams:
        ...
    @property
    def profile(self) -> motorbus._core.motion.Profile:
        ...
class HomingOptions:
    def __init__(self, hca: typing.SupportsFloat | typing.SupportsIndex = 0.0, lca: typing.SupportsFloat | typing.SupportsIndex = 1000.0, rz: bool = False) -> None:
        ...
class HomingMethod:
    """
    The routines Homing runs on a MotorModel.
    
    Members:
    
      H
    
      HL
    
      L
    
      Z
    
      ZH
    """
    H: typing.ClassVar[HomingMethod]
    HL: typing.ClassVar[HomingMethod]
    L: typing.ClassVar[HomingMethod]
    Z: typing.ClassVar[HomingMethod]
    ZH: typing.ClassVar[HomingMethod]
    __members__: typing.ClassVar[dict[str, HomingMethod]]
    @typing.overload
    def __eq__(self, other: HomingMethod) -> bool:
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
    def __ne__(self, other: HomingMethod) -> bool:
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
class Homing:
    def __init__(self, motor: motorbus._core.motion.MotorModel, params: ProfileParams, options: HomingOptions = ...) -> None:
        ...
    def abort(self) -> None:
        ...
    def start(self, method: HomingMethod | str, direction: typing.SupportsInt | typing.SupportsIndex) -> None:
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
class CommandInfo:
    """
    One row of the Arcus command table (commands()), read-only.
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
class Sim(motorbus._core.serial.LineDevice, motorbus._core.can.SimulatedDevice):
    """
    A simulated Arcus DMX-CAN: answers ASCII lines (a LineDevice for PtyLineServer) and, attached to a CAN bus, CANopen (a SimulatedDevice).
    """
    def __init__(self, clock: motorbus._core.runtime.Clock = None, address: typing.SupportsInt | typing.SupportsIndex = 1, response_type: typing.SupportsInt | typing.SupportsIndex = 0, store_path: str = '', eo_boot: bool = False, snl: bool = True, home: tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex] = (8000.0, 8400.0), minus_limit: typing.SupportsFloat | typing.SupportsIndex | None = -400000.0, plus_limit: typing.SupportsFloat | typing.SupportsIndex | None = 400000.0, z_position: typing.SupportsFloat | typing.SupportsIndex = 1600.0, start_position: typing.SupportsFloat | typing.SupportsIndex = 0.0, tick: typing.SupportsFloat | typing.SupportsIndex = 0.0001, comm_type: typing.SupportsInt | typing.SupportsIndex = 0, node_id: typing.SupportsInt | typing.SupportsIndex = 1, store_time: typing.SupportsFloat | typing.SupportsIndex = 0.0, clear_time: typing.SupportsFloat | typing.SupportsIndex = 0.0, bit_rate: typing.SupportsInt | typing.SupportsIndex = 5) -> None:
        ...
    def disturb(self, steps: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def force_home(self, actuated: bool | None) -> None:
        ...
    def force_limit(self, direction: typing.SupportsInt | typing.SupportsIndex, actuated: bool | None) -> None:
        ...
    def on_can_frame(self, frame: motorbus._core.can.Frame) -> list[motorbus._core.can.Frame]:
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
class HomeMethod:
    """
    The homing routines: H, HL, ZH, Z, L (Table 11.0; + or - is the direction).
    
    Members:
    
      H
    
      HL
    
      ZH
    
      Z
    
      L
    """
    H: typing.ClassVar[HomeMethod]
    HL: typing.ClassVar[HomeMethod]
    L: typing.ClassVar[HomeMethod]
    Z: typing.ClassVar[HomeMethod]
    ZH: typing.ClassVar[HomeMethod]
    __members__: typing.ClassVar[dict[str, HomeMethod]]
    @typing.overload
    def __eq__(self, other: HomeMethod) -> bool:
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
    def __ne__(self, other: HomeMethod) -> bool:
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
class ClientCounters:
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
class ClientBase:
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
    def broadcast(link: motorbus._core.serial.LineLink, command: str) -> None:
        ...
    def __init__(self, link: motorbus._core.serial.LineLink, address: typing.SupportsInt | typing.SupportsIndex = 1, timeout: typing.Any = None, query_retries: typing.SupportsInt | typing.SupportsIndex = 1) -> None:
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
    def home(self, method: HomeMethod | str, direction: typing.SupportsInt | typing.SupportsIndex) -> None:
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
    def counters(self) -> ClientCounters:
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
def acc_range(hspd: typing.SupportsInt | typing.SupportsIndex, lspd: typing.SupportsInt | typing.SupportsIndex) -> tuple[int, int]:
    """
    (min, max) ACC in ms the drive accepts for HSPD/LSPD (Table A.0; max truncated to 10 ms like the manual's examples).
    """
def build_request(address: typing.SupportsInt | typing.SupportsIndex, command: str) -> bytes:
    """
    b'@NN<command>\\r' (validated).
    """
def canopen_object_dictionary() -> motorbus._core.canopen.ObjectDictionary:
    """
    Table 10.1 as a typed canopen.ObjectDictionary (types, access, limits, defaults, codecs): what the arcus-canopen client reads and writes by, and the source of the shipped EDS.
    """
def canopen_objects() -> list:
    """
    The DMX-CAN object dictionary the simulator serves (Table 10.1): (index, sub, name, type, access, default, low, high, unit, persists) tuples.
    """
def check_strict(params: ProfileParams) -> None:
    ...
def commands() -> list[CommandInfo]:
    """
    The command table (Table 11.0 plus the commands the sections describe).
    """
def effective(params: ProfileParams) -> tuple[ProfileParams, int, list[str]]:
    """
    (effective params, window number, [adjustments]) after Appendix A.
    """
def max_acc_ms(hspd_pps: typing.SupportsFloat | typing.SupportsIndex, lspd_pps: typing.SupportsFloat | typing.SupportsIndex) -> float:
    ...
def parse_reply(raw: typing.Any) -> tuple[typing.Any, str]:
    """
    (address or None, body) of one reply without its NUL; ProtocolError on bytes it never sends.
    """
def poll_source(link: motorbus._core.serial.LineLink, address: typing.SupportsInt | typing.SupportsIndex, names: collections.abc.Sequence[str], timeout: typing.Any = None, query_retries: typing.SupportsInt | typing.SupportsIndex = 1) -> motorbus._core.poll.PollSource:
    ...
def speed_windows() -> list[SpeedWindow]:
    ...
def window_for_hspd(hspd_pps: typing.SupportsFloat | typing.SupportsIndex) -> SpeedWindow:
    ...
def window_for_sspdm(sspdm: typing.SupportsInt | typing.SupportsIndex) -> SpeedWindow:
    ...
MAX_MOVE_DISTANCE: int = 262143
MAX_REPLY: int = 72
MAX_REQUEST: int = 64

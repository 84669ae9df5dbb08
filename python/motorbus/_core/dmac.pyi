from __future__ import annotations
import collections.abc
import motorbus._core.motion
import motorbus._core.poll
import motorbus._core.runtime
import motorbus._core.serial
import typing
__all__: list[str] = ['Client', 'ClientCounters', 'EndStops', 'Keyword', 'Motion', 'Polarity', 'PowerMode', 'ProfileParams', 'Radix', 'ReadReply', 'Sensor', 'Sim', 'SimState', 'StopWhat', 'StreamStats', 'VariableInfo', 'VersionInfo', 'error_names', 'format_value', 'parse_read_reply', 'poll_source', 'position_profile', 'ramp_time', 'speed_profile', 'status_names', 'stream_interpolation', 'synchro', 'variable']
class ProfileParams:
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
class Motion:
    def __init__(self, params: ProfileParams = ..., position: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def move_on(self, t: typing.SupportsFloat | typing.SupportsIndex, offset: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def move_speed(self, t: typing.SupportsFloat | typing.SupportsIndex, speed: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def move_to(self, t: typing.SupportsFloat | typing.SupportsIndex, target: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def moving(self, t: typing.SupportsFloat | typing.SupportsIndex) -> bool:
        ...
    def set_params(self, arg0: ProfileParams) -> None:
        ...
    def stop(self, t: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def profile(self) -> motorbus._core.motion.Profile:
        ...
class Radix:
    """
    How a DMAC value is written: +123, h0000007B or b00000000 ... 01111011.
    
    Members:
    
      DEC
    
      HEX
    
      BIN
    """
    BIN: typing.ClassVar[Radix]
    DEC: typing.ClassVar[Radix]
    HEX: typing.ClassVar[Radix]
    __members__: typing.ClassVar[dict[str, Radix]]
    @typing.overload
    def __eq__(self, other: Radix) -> bool:
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
    def __ne__(self, other: Radix) -> bool:
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
class StopWhat:
    """
    What STOP / HALT stop: everything, the movement (MOUV) or the sequence (SEQ).
    
    Members:
    
      ALL
    
      MOVEMENT
    
      SEQUENCE
    """
    ALL: typing.ClassVar[StopWhat]
    MOVEMENT: typing.ClassVar[StopWhat]
    SEQUENCE: typing.ClassVar[StopWhat]
    __members__: typing.ClassVar[dict[str, StopWhat]]
    @typing.overload
    def __eq__(self, other: StopWhat) -> bool:
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
    def __ne__(self, other: StopWhat) -> bool:
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
class PowerMode:
    """
    POWER ON, OFF (freewheel) or SC (short-circuited coils).
    
    Members:
    
      ON
    
      OFF
    
      SC
    """
    OFF: typing.ClassVar[PowerMode]
    ON: typing.ClassVar[PowerMode]
    SC: typing.ClassVar[PowerMode]
    __members__: typing.ClassVar[dict[str, PowerMode]]
    @typing.overload
    def __eq__(self, other: PowerMode) -> bool:
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
    def __ne__(self, other: PowerMode) -> bool:
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
class EndStops:
    """
    HARD_ENDS: which hard end-stop inputs stop the motor.
    
    Members:
    
      OFF
    
      ALL
    
      POS
    
      NEG
    """
    ALL: typing.ClassVar[EndStops]
    NEG: typing.ClassVar[EndStops]
    OFF: typing.ClassVar[EndStops]
    POS: typing.ClassVar[EndStops]
    __members__: typing.ClassVar[dict[str, EndStops]]
    @typing.overload
    def __eq__(self, other: EndStops) -> bool:
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
    def __ne__(self, other: EndStops) -> bool:
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
class Polarity:
    """
    INVERSE_POLARITY: which of the inputs and outputs are inverted.
    
    Members:
    
      OFF
    
      ALL
    
      IN
    
      OUT
    """
    ALL: typing.ClassVar[Polarity]
    IN: typing.ClassVar[Polarity]
    OFF: typing.ClassVar[Polarity]
    OUT: typing.ClassVar[Polarity]
    __members__: typing.ClassVar[dict[str, Polarity]]
    @typing.overload
    def __eq__(self, other: Polarity) -> bool:
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
    def __ne__(self, other: Polarity) -> bool:
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
class Keyword:
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
    ALL: typing.ClassVar[Keyword]
    IN: typing.ClassVar[Keyword]
    INTERPOL: typing.ClassVar[Keyword]
    MOUV: typing.ClassVar[Keyword]
    NEG: typing.ClassVar[Keyword]
    OFF: typing.ClassVar[Keyword]
    ON: typing.ClassVar[Keyword]
    OUT: typing.ClassVar[Keyword]
    POS: typing.ClassVar[Keyword]
    SC: typing.ClassVar[Keyword]
    SEQ: typing.ClassVar[Keyword]
    TOP: typing.ClassVar[Keyword]
    __members__: typing.ClassVar[dict[str, Keyword]]
    @typing.overload
    def __eq__(self, other: Keyword) -> bool:
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
    def __ne__(self, other: Keyword) -> bool:
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
class ReadReply:
    """
    One parsed 'aa#MNE[.bit]=value' reply (parse_read_reply), read-only.
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
    def radix(self) -> Radix:
        ...
    @property
    def value(self) -> int:
        ...
class VariableInfo:
    """
    One DMAC variable (variable()), read-only.
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
class VersionInfo:
    """
    A parsed REQUEST_VERSION banner (Client.request_version()), read-only.
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
class Sensor:
    """
    The temperature sensors of a module (Sim.set_temperature).
    
    Members:
    
      CPU
    
      DRIVER
    
      MOTOR
    """
    CPU: typing.ClassVar[Sensor]
    DRIVER: typing.ClassVar[Sensor]
    MOTOR: typing.ClassVar[Sensor]
    __members__: typing.ClassVar[dict[str, Sensor]]
    @typing.overload
    def __eq__(self, other: Sensor) -> bool:
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
    def __ne__(self, other: Sensor) -> bool:
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
class SimState:
    """
    A snapshot of a Sim (Sim.state()), read-only.
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
class Sim(motorbus._core.serial.LineDevice):
    """
    A simulated DMAC module (a LineDevice: serve it with PtyLineServer). Device time runs on `clock` (a SimClock in tests); nothing runs in the background.
    """
    @staticmethod
    def chain_ultrasync(modules: collections.abc.Sequence[Sim]) -> None:
        """
        Wire IN6/OUT1 of these modules into one UltraSYNC chain (5.11), before serving them: with #INTERPOL_MODE:=-1 a segment ends when it is finished on every chained module.
        """
    def __init__(self, clock: motorbus._core.runtime.Clock = None, address: typing.SupportsInt | typing.SupportsIndex = 0, model: str = 'DMAC34-1', request_terminator: bytes = b'\r', reply_terminator: bytes = b'\r\n', supply_voltage: typing.SupportsInt | typing.SupportsIndex = 32000, baudrate: typing.SupportsInt | typing.SupportsIndex = 38400, positive_end_switch: typing.SupportsFloat | typing.SupportsIndex | None = None, negative_end_switch: typing.SupportsFloat | typing.SupportsIndex | None = None, end_switch_active_low: bool = False, reference_switch: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
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
    def set_temperature(self, sensor: Sensor | str, tenths_c: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Temperature in 0.1 degC; CPU > 120 degC or driver/motor > 85 degC latches a thermal fault.
        """
    def state(self) -> SimState:
        """
        A SimState snapshot.
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
class ClientCounters:
    """
    Client counters (Client.counters), read-only.
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
class Client:
    """
    Typed DMAC commands over a LineLink (one client per module address).
    """
    def __init__(self, link: motorbus._core.serial.LineLink, address: typing.SupportsInt | typing.SupportsIndex = 0, *, baud: typing.SupportsInt | typing.SupportsIndex = 38400, verify: bool = True, timeout: typing.Any = None, sleep: typing.Any = None) -> None:
        ...
    def analog_input(self, channel: typing.SupportsInt | typing.SupportsIndex) -> int:
        ...
    def brake(self, on: bool) -> None:
        ...
    def clear_error(self) -> None:
        ...
    def command(self, command: str) -> None:
        ...
    def halt(self, what: StopWhat | str = ...) -> None:
        ...
    def hard_ends(self, which: EndStops | str) -> None:
        ...
    def inverse_polarity(self, which: Polarity | str) -> None:
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
    def power(self, mode: PowerMode | str) -> None:
        ...
    def raw(self, frame: str, expect_reply: bool = True) -> bytes:
        ...
    def read(self, variable: str, radix: Radix | str = ...) -> int:
        """
        READ a variable; radix is a Radix or 'dec'/'hex'/'bin' (default Radix.DEC).
        """
    def read_bit(self, variable: str, bit: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def read_sequence(self, first: typing.SupportsInt | typing.SupportsIndex, last: typing.SupportsInt | typing.SupportsIndex) -> list[str]:
        ...
    def read_sequence_line(self, n: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def reference(self, on: bool) -> None:
        ...
    def request_version(self) -> VersionInfo:
        """
        REQUEST_VERSION, parsed into a VersionInfo.
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
    def stop(self, what: StopWhat | str = ...) -> None:
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
    def counters(self) -> ClientCounters:
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
class StreamStats:
    """
    What stream_interpolation did, read-only.
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
def error_names(error: typing.SupportsInt | typing.SupportsIndex) -> list[str]:
    ...
def format_value(value: typing.SupportsInt | typing.SupportsIndex, radix: Radix | str = ...) -> str:
    """
    '+123', 'h0000007B' or 'b00000000 ... 01111011'; radix is a Radix or 'dec'/'hex'/'bin'.
    """
def parse_read_reply(reply: bytes) -> ReadReply | None:
    """
    Parses 'aa#MNE[.bit]=value' strictly into a ReadReply; None when it breaks the grammar.
    """
def poll_source(link: motorbus._core.serial.LineLink, address: typing.SupportsInt | typing.SupportsIndex, names: collections.abc.Sequence[str], baud: typing.SupportsInt | typing.SupportsIndex = 38400, timeout: typing.Any = None) -> motorbus._core.poll.PollSource:
    ...
def position_profile(start: motorbus._core.motion.MotionState, target: typing.SupportsFloat | typing.SupportsIndex, params: ProfileParams) -> motorbus._core.motion.Profile:
    ...
def ramp_time(params: ProfileParams, v_from: typing.SupportsFloat | typing.SupportsIndex, v_to: typing.SupportsFloat | typing.SupportsIndex) -> float:
    ...
def speed_profile(start: motorbus._core.motion.MotionState, speed: typing.SupportsFloat | typing.SupportsIndex, params: ProfileParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> motorbus._core.motion.Profile:
    ...
def status_names(status: typing.SupportsInt | typing.SupportsIndex) -> list[str]:
    ...
def stream_interpolation(axes: collections.abc.Sequence[Client], segments: collections.abc.Sequence[collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]], interpol_time_ms: typing.SupportsInt | typing.SupportsIndex = 100, fifo_size: typing.SupportsInt | typing.SupportsIndex = 64, sleep: typing.Any = None, backoff: typing.Any = None) -> StreamStats:
    """
    Streams segments[k][axis] to every axis, starting them with SYNCHRO INTERPOL.
    """
def synchro(link: motorbus._core.serial.LineLink, what: Keyword | str) -> None:
    """
    Global SYNCHRO ON|OFF|TOP|INTERPOL (no reply).
    """
def variable(name: str) -> VariableInfo:
    """
    The VariableInfo of a variable, by full name or mnemonic ('#ACCEL_TIME', 'ATI').
    """

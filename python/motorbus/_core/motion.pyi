from __future__ import annotations
import collections.abc
import motorbus._core.runtime
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Cia402Homing', 'Cia402HomingParams', 'Cia402ProfileParams', 'Cia402ProfilePosition', 'Limits', 'MotionState', 'MotorConfig', 'MotorEvent', 'MotorEventKind', 'MotorModel', 'Profile', 'RampShape', 'SnlActivity', 'SnlConfig', 'StepNLoop', 'SwitchConfig', 'cia402_position_profile', 'cia402_quick_stop_profile', 'cia402_velocity_profile', 'jerk_limited_durations', 'plan_jerk_limited', 'plan_jerk_limited_velocity', 'plan_straight_line', 'plan_synchronized', 'plan_synchronized_jerk_limited', 'plan_trapezoid', 'plan_velocity', 'split_interpolation', 'synchronized_jerk_limited_durations']
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
    def __init__(self, clock: motorbus._core.runtime.Clock, config: MotorConfig = ...) -> None:
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
def cia402_position_profile(start: MotionState, target: typing.SupportsFloat | typing.SupportsIndex, params: Cia402ProfileParams) -> Profile:
    ...
def cia402_quick_stop_profile(start: MotionState, params: Cia402ProfileParams) -> Profile:
    ...
def cia402_velocity_profile(start: MotionState, target_velocity: typing.SupportsFloat | typing.SupportsIndex, params: Cia402ProfileParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> Profile:
    ...
def jerk_limited_durations(cases: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    Rows: p0, v0, a0, target, vmax, amax, jmax; the duration of each row's plan.
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
def split_interpolation(axes: collections.abc.Sequence[Profile], period_ms: typing.SupportsInt | typing.SupportsIndex) -> list[list[int]]:
    ...
def synchronized_jerk_limited_durations(cases: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    Rows: 3 axes x (p0, target, vmax, amax, jmax); the common duration of each row.
    """

from __future__ import annotations
import collections.abc
import motorbus._core.can
import motorbus._core.canopen
import motorbus._core.motion
import motorbus._core.runtime
import typing
__all__: list[str] = ['ProfileParams', 'Sim', 'Storage', 'assemble', 'convert_position', 'disassemble', 'eds', 'gear_acceleration', 'microsteps', 'object_dictionary', 'position_profile', 'speed_profile', 'storage']
class ProfileParams:
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
class Storage:
    """
    How an object behaves over reset node / power-up (B-P37).
    
    Members:
    
      ROM : saved to flash by 2007h = 2, reloaded at reset node
    
      RAM : back to the default at reset node / power-up
    
      CONST : never changes
    """
    CONST: typing.ClassVar[Storage]
    RAM: typing.ClassVar[Storage]
    ROM: typing.ClassVar[Storage]
    __members__: typing.ClassVar[dict[str, Storage]]
    @typing.overload
    def __eq__(self, other: Storage) -> bool:
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
    def __ne__(self, other: Storage) -> bool:
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
class Sim(motorbus._core.can.SimulatedDevice):
    """
    A simulated CQPUSI PMC007 CANopen node (see sim.hpp).
    """
    def __init__(self, node_id: typing.SupportsInt | typing.SupportsIndex = 5, clock: motorbus._core.runtime.Clock = None, steps_per_rev: typing.SupportsFloat | typing.SupportsIndex = 200.0, pull_out_speed: typing.SupportsFloat | typing.SupportsIndex = 0.0, ext1_switch: tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex] | None = None, store_path: str = '', vendor_id: typing.SupportsInt | typing.SupportsIndex = 0, product_code: typing.SupportsInt | typing.SupportsIndex = 7, revision: typing.SupportsInt | typing.SupportsIndex = 65536, serial: typing.SupportsInt | typing.SupportsIndex = 1) -> None:
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
    def od(self) -> motorbus._core.canopen.ObjectDictionary:
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
def assemble(text: str) -> list[int]:
    """
    Mnemonic text -> 32-bit words (the spec's reading of the encoding).
    """
def convert_position(position: typing.SupportsFloat | typing.SupportsIndex, from_setting: typing.SupportsInt | typing.SupportsIndex, to_setting: typing.SupportsInt | typing.SupportsIndex) -> float:
    ...
def disassemble(words: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> str:
    ...
def eds() -> str:
    """
    The EDS text generated from the table (node-ID as $NODEID).
    """
def gear_acceleration(gear: typing.SupportsInt | typing.SupportsIndex) -> float:
    ...
def microsteps(setting: typing.SupportsInt | typing.SupportsIndex) -> int:
    ...
def object_dictionary(node_id: typing.SupportsInt | typing.SupportsIndex = 5) -> motorbus._core.canopen.ObjectDictionary:
    """
    The PMC007 dictionary (every row of the table), defaults evaluated for `node_id`.
    """
def position_profile(start: motorbus._core.motion.MotionState, target: typing.SupportsFloat | typing.SupportsIndex, params: ProfileParams) -> motorbus._core.motion.Profile:
    ...
def speed_profile(start: motorbus._core.motion.MotionState, speed: typing.SupportsFloat | typing.SupportsIndex, params: ProfileParams, hold: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> motorbus._core.motion.Profile:
    ...
def storage(index: typing.SupportsInt | typing.SupportsIndex, subindex: typing.SupportsInt | typing.SupportsIndex = 0) -> Storage:
    """
    The table's storage class of one object (B-P37).
    """

from __future__ import annotations
import motorbus._core.can
import motorbus._core.canopen
import motorbus._core.runtime
import typing
__all__: list[str] = ['Sim', 'object_dictionary', 'objects']
class Sim(motorbus._core.can.SimulatedDevice):
    """
    A simulated CiA 402 drive served by a LocalNode (see cpp/motorbus/drives/cia402/sim.hpp).
    """
    def __init__(self, node_id: typing.SupportsInt | typing.SupportsIndex, clock: motorbus._core.runtime.Clock = None, *, steps_per_rev: typing.SupportsFloat | typing.SupportsIndex = 3200.0, home: tuple[typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex] = (1000.0, 1400.0), minus_limit: typing.SupportsFloat | typing.SupportsIndex | None = -100000.0, plus_limit: typing.SupportsFloat | typing.SupportsIndex | None = 100000.0, heartbeat_ms: typing.SupportsInt | typing.SupportsIndex = 0, start_position: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
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
    def heartbeat(self) -> motorbus._core.canopen.HeartbeatService:
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
    def od(self) -> motorbus._core.canopen.ObjectDictionary:
        ...
    @property
    def pdo(self) -> motorbus._core.canopen.PdoService:
        ...
    @property
    def position(self) -> float:
        ...
    @property
    def state(self) -> str:
        ...
def object_dictionary(node_id: typing.SupportsInt | typing.SupportsIndex = 1) -> motorbus._core.canopen.ObjectDictionary:
    """
    The same objects as a typed canopen.ObjectDictionary (types, access, limits, defaults, codecs): what the generic Drive adapter reads and writes by.
    """
def objects() -> list:
    """
    The generic CiA 402 simulator's objects: (index, sub, name, type, access, default, low, high, unit, persists, description).
    """

from __future__ import annotations
import typing
__all__: list[str] = ['Clock', 'RealClock', 'SimClock', 'monotonic_ns']
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
def monotonic_ns() -> int:
    """
    The monotonic clock frame timestamps use (ns).
    """

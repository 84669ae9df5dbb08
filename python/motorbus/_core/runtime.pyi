from __future__ import annotations
import typing
__all__: list[str] = ['Clock', 'CompletionFailure', 'Completions', 'RealClock', 'SimClock', 'monotonic_ns']
class CompletionFailure:
    def rethrow(self) -> None:
        """
        Raises the operation's error.
        """
class Completions:
    """
    Finished operations for one event loop: a queue and the eventfd the loop watches (motorbus.aio drains it; see cpp/motorbus/runtime/completions.hpp).
    """
    def __init__(self) -> None:
        ...
    def drain(self) -> list:
        """
        [(token, value, failure or None)] of everything queued, oldest first.
        """
    def fileno(self) -> int:
        ...
    def notify(self) -> None:
        """
        Wakes the loop without a completion.
        """
    def push_none(self, token: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Queues an empty completion (tests; Python threads deliver their results another way).
        """
    def set_wakeup(self, function: typing.Any) -> None:
        """
        A function called at each wake-up (loops without add_reader); None = none.
        """
    @property
    def pending(self) -> int:
        ...
    @property
    def pushed(self) -> int:
        ...
    @property
    def wakeups(self) -> int:
        ...
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

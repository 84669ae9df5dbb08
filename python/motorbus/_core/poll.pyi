from __future__ import annotations
import collections.abc
import motorbus._core.runtime
import numpy
import numpy.typing
import typing
__all__: list[str] = ['PollGroup', 'PollSource', 'PollStats']
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
    def cancel_notify(self) -> bool:
        ...
    def notify_when(self, rows: typing.SupportsInt | typing.SupportsIndex, completions: motorbus._core.runtime.Completions, token: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        For an event loop: False, and token completes (with the unread row count) once the ring holds rows unread rows or the thread ended; True when that is already so.
        """
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

"""SYNC producer (CiA 301) on its own C++ thread.

    from motorbus.canopen import SyncProducer
    sync = SyncProducer(bus, 0.001, counter_overflow=0)   # 1 ms
    sync.start()                                          # realtime=True asks for SCHED_FIFO
    sync.jitter()                                         # JitterStats(count=..., p99_abs_ns=...)
"""
from __future__ import annotations


__all__ = ["SyncProducer", "JitterStats", "sync_encode"]

from .._core.canopen import SyncProducer, JitterStats, sync_encode  # noqa: E402,F401

"""SYNC producer (CiA 301) on its own C++ thread.

    from motorbus.canopen import SyncProducer
    sync = SyncProducer(bus, 0.001, counter_overflow=0)   # 1 ms
    sync.start()                                          # realtime=True asks for SCHED_FIFO
    sync.jitter()                                         # JitterStats(count=..., p99_abs_ns=...)
"""
from __future__ import annotations

from .. import _core

__all__ = ["SyncProducer", "JitterStats", "sync_encode"]

SyncProducer = _core.SyncProducer
JitterStats = _core.JitterStats
sync_encode = _core.sync_encode

"""TIME (CiA 301 TIME_OF_DAY): milliseconds after midnight, days since 1984-01-01.

    from motorbus.canopen import time_encode, time_decode
    frame = time_encode(unix_ms)        # the 6-byte TIME frame on 0x100
    time_decode(frame)                  # unix ms, or None for anything else
"""
from __future__ import annotations


__all__ = ["time_encode", "time_decode"]

from .._core.canopen import time_encode, time_decode  # noqa: E402,F401

"""What several benchmarks measure the same way (imported, never run by tools/bench.sh)."""
from __future__ import annotations

import time
from typing import Callable, Sequence


def percentile(values: Sequence[float], p: float) -> float:
    """The p-quantile (0..1) by rank, no interpolation."""
    v = sorted(values)
    return v[min(len(v) - 1, int(len(v) * p))]


def rate(fn: Callable[[], object], seconds: float) -> tuple[float, float, float]:
    """Calls fn until `seconds` passed; returns (calls/s, median us, p99 us)."""
    lat = []
    t_end = time.perf_counter() + seconds
    while True:
        t = time.perf_counter()
        fn()
        t2 = time.perf_counter()
        lat.append((t2 - t) * 1e6)
        if t2 >= t_end:
            break
    return len(lat) / sum(lat) * 1e6, percentile(lat, 0.5), percentile(lat, 0.99)

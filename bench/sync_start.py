"""How far apart two CiA 402 axes start: one CANopen SYNC vs a software start.

Two simulated ``cia402`` nodes behind one socketcand server (``Bench(sim=True)``), N
starts each way, alternated.  The figure is measured on the drives' side: the time each
simulated drive accepted its profile-position set-point (``sim.last_setpoint_ns``),
|a - b|.  The software start is what a host without a synchronised start does (and what
python-can + canopen glued by hand do): one SDO set-point handshake per axis, back to back.

    .venv/bin/python bench/sync_start.py [--n 30]
"""
from __future__ import annotations

import argparse
import statistics

from motorbus import Bench, registry


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=30, help="starts of each kind")
    args = ap.parse_args()
    bench = Bench.from_dict({"bus": {"can0": {"spec": "socketcand:127.0.0.1:1/can0"}},
                             "axis": {"a": {"kind": "cia402", "bus": "can0", "address": 5},
                                      "b": {"kind": "cia402", "bus": "can0", "address": 6}}}, sim=True)
    sync = registry.drive_plugin("cia402").synchronised_start
    skew: dict[str, list[float]] = {"SYNC": [], "software": []}
    with bench:
        a, b = bench["a"], bench["b"]
        for d in (a, b):
            d.enable()
            d.params["0x6081"] = 1_000_000
        sims = bench.sims["a"], bench.sims["b"]

        def started() -> float:
            a.wait_idle(10)
            b.wait_idle(10)
            return abs(sims[0].last_setpoint_ns - sims[1].last_setpoint_ns) / 1e3

        for i in range(args.n):
            target = 1000 * (i % 2 + 1)
            with sync(bench.buses["can0"], [a, b]):
                a.move_to(target, wait=False)
                b.move_to(target, wait=False)
            skew["SYNC"].append(started())
            a.move_to(-target, wait=False)
            b.move_to(-target, wait=False)
            skew["software"].append(started())
    for name, v in skew.items():
        print(f"{name:9s} start skew: median {statistics.median(v):8.1f} us   max {max(v):8.1f} us   (n={len(v)})")
    ratio = statistics.median(skew["software"]) / statistics.median(skew["SYNC"])
    print(f"ratio (software / SYNC, medians): {ratio:.1f}x")


if __name__ == "__main__":
    main()

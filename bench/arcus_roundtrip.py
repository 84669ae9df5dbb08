"""Command-to-reply round trip to the Arcus simulator on a pty, from Python.

Compares motorbus' ArcusClient.position with a plain pyserial loop (the
reference) on the same PtyLineServer, unthrottled and paced at 115200 baud.

    PYTHONPATH=python python3 bench/arcus_roundtrip.py [iterations]
"""
from __future__ import annotations

import statistics
import sys
import time

import serial

import motorbus._core as core
from motorbus.drives.arcus import ArcusClient, make_sim


def summarize(us):
    us = sorted(us)
    return statistics.fmean(us), us[len(us) // 2], us[min(len(us) - 1, len(us) * 99 // 100)]


def bench_motorbus(path, n):
    with ArcusClient(path, "01", baud=0, timeout=1.0, query_retries=0, on_exit=None) as c:
        for _ in range(50):
            c.position
        us = []
        for _ in range(n):
            t = time.perf_counter()
            c.position
            us.append((time.perf_counter() - t) * 1e6)
    return summarize(us)


def bench_pyserial(path, n):
    with serial.Serial(path, 115200, timeout=1) as p:
        def rt():
            p.write(b"@01PX\r")
            out = b""
            while not out.endswith(b"\0"):
                c = p.read(1)
                if not c:
                    raise TimeoutError("no reply")
                out += c
            return out

        for _ in range(50):
            rt()
        us = []
        for _ in range(n):
            t = time.perf_counter()
            rt()
            us.append((time.perf_counter() - t) * 1e6)
    return summarize(us)


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    print(f"Arcus round trip '@01PX\\r' -> '<n>\\0' on a pty, {n} iterations (Python)")
    for name, baud in (("unthrottled", 0), ("115200 baud", 115200)):
        with core.serial.PtyLineServer([make_sim("01")], baud, None) as server:
            mb = bench_motorbus(server.slave_path, n)
            ref = bench_pyserial(server.slave_path, n)
        print(f"{name:12s} motorbus ArcusClient: mean {mb[0]:8.1f} us  p50 {mb[1]:8.1f}  p99 {mb[2]:8.1f} | "
              f"pyserial loop: mean {ref[0]:8.1f} us  p50 {ref[1]:8.1f}  p99 {ref[2]:8.1f} | "
              f"ratio (pyserial/motorbus, mean) {ref[0] / mb[0]:.2f}x")


if __name__ == "__main__":
    main()

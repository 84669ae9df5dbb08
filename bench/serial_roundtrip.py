"""Request->reply round trips over a pty, from Python.

motorbus LineLink.transact() vs a plain pyserial write/read_until loop, both
against the SAME PtyLineServer (C++ EchoLineDevice) in the same run,
unthrottled and paced at 115200 baud.  Also: the server with a Python
LineDevice (the GIL round trip into the server thread).

    PYTHONPATH=python python3 bench/serial_roundtrip.py [iterations]
"""
from __future__ import annotations

import sys
import time

import serial  # pyserial, the reference

from motorbus.serial import EchoLineDevice, LineDevice, LineLink, PtyLineServer, open_port

REQ = b"1PX"


class PyEcho(LineDevice):
    def on_line(self, line: bytes) -> bytes:
        return line + b"\r\n"


def stats(lat_ns: list[int], total_s: float) -> tuple[float, float, float]:
    lat = sorted(lat_ns)
    return len(lat) / total_s, lat[len(lat) // 2] / 1e3, lat[min(len(lat) - 1, len(lat) * 99 // 100)] / 1e3


def run_motorbus(path: str, n: int) -> tuple[float, float, float]:
    link = LineLink(open_port(path, 115200), reply_timeout=2.0)
    for _ in range(50):
        link.transact(REQ)
    lat = []
    clock = time.perf_counter_ns
    t0 = time.perf_counter()
    for _ in range(n):
        a = clock()
        r = link.transact(REQ)
        lat.append(clock() - a)
        assert r == REQ, r
    total = time.perf_counter() - t0
    link.port.close()
    return stats(lat, total)


def run_pyserial(path: str, n: int) -> tuple[float, float, float]:
    with serial.Serial(path, 115200, timeout=2) as s:
        for _ in range(50):
            s.write(REQ + b"\r")
            s.read_until(b"\r\n")
        lat = []
        clock = time.perf_counter_ns
        t0 = time.perf_counter()
        for _ in range(n):
            a = clock()
            s.write(REQ + b"\r")
            r = s.read_until(b"\r\n")
            lat.append(clock() - a)
            assert r == REQ + b"\r\n", r
        total = time.perf_counter() - t0
    return stats(lat, total)


def line(label: str, who: str, s: tuple[float, float, float]) -> None:
    print(f"{label:<34} {who:<24} {s[0]:9.0f} rt/s  median {s[1]:7.1f} us  p99 {s[2]:7.1f} us")


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 3000
    cases = [
        ("unthrottled pty, C++ echo device", lambda: EchoLineDevice(), 0, n),
        ("paced 115200, C++ echo device", lambda: EchoLineDevice(), 115200, min(n, 1500)),
        ("unthrottled pty, Python device", lambda: PyEcho(), 0, n),
    ]
    for label, make, baud, iters in cases:
        with PtyLineServer([make()], baud=baud) as server:
            ours = run_motorbus(server.slave_path, iters)
            ref = run_pyserial(server.slave_path, iters)
        line(label, "motorbus LineLink", ours)
        line(label, "pyserial loop", ref)
        print(f"{label:<34} ratio motorbus/pyserial: throughput x{ours[0] / ref[0]:.2f}, "
              f"median latency x{ours[1] / ref[1]:.2f} (lower is better)")
    print(f"(n={n}; wire floor at 115200 for 4+5 bytes: {9 * 10 * 1e6 / 115200:.1f} us)")


if __name__ == "__main__":
    main()

"""DMAC command-to-reply round trip on a pty, from Python.

Same run, same simulator, same pty server: motorbus DmacClient (C++ client
through the bindings) against a plain pyserial loop that writes the same
request and reads up to CR LF.  Unthrottled (pty as fast as it goes) and paced
like a 115200-baud UART by the line server.

    PYTHONPATH=python python3 bench/dmac_roundtrip.py [--n 2000]
"""
from __future__ import annotations

import argparse
import statistics
import time

import serial

from motorbus.drives.dmac import DmacClient, make_sim, open_line
from motorbus.serial import PtyLineServer


def stats(samples):
    s = sorted(samples)
    return statistics.median(s) * 1e6, s[int(len(s) * 0.99) - 1] * 1e6


def run_motorbus(path, n):
    link = open_line(path, baud=115200, timeout=1.0)
    c = DmacClient(link, address=0, baud=115200)
    for _ in range(50):
        c.read("#POSITION")
    out = []
    for _ in range(n):
        t = time.perf_counter()
        c.read("#POSITION")
        out.append(time.perf_counter() - t)
    c.close()
    return out


def run_pyserial(path, n):
    out = []
    with serial.Serial(path, 115200, timeout=1.0) as ser:
        for _ in range(50):
            ser.write(b"00READ #POSITION\r")
            ser.read_until(b"\r\n")
        for _ in range(n):
            t = time.perf_counter()
            ser.write(b"00READ #POSITION\r")
            r = ser.read_until(b"\r\n")
            out.append(time.perf_counter() - t)
            assert r == b"00#POS=+0\r\n", r
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=2000)
    args = ap.parse_args()
    print(f"DMAC '00READ #POSITION' round trip, {args.n} requests each (median / p99, us)")
    for baud in (0, 115200):
        with PtyLineServer([make_sim("00")], baud) as server:
            ours = stats(run_motorbus(server.slave_path, args.n))
            ref = stats(run_pyserial(server.slave_path, args.n))
        label = "unthrottled" if baud == 0 else f"paced {baud} baud"
        print(f"{label:>20}: motorbus DmacClient {ours[0]:8.1f} / {ours[1]:8.1f}   "
              f"pyserial loop {ref[0]:8.1f} / {ref[1]:8.1f}   ratio (pyserial/motorbus, median) "
              f"{ref[0] / ours[0]:5.2f}")


if __name__ == "__main__":
    main()

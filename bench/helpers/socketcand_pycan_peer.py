"""python-can's socketcand interface as a benchmark peer, driven by
bench_socketcand_throughput (C++) over stdin/stdout:

    python bench/helpers/socketcand_pycan_peer.py PORT tx N   -> sends N frames as fast as it can
    python bench/helpers/socketcand_pycan_peer.py PORT rx N   -> receives N frames, prints the time

It prints READY once connected, then waits for a line on stdin before starting,
so process start-up and the handshake stay out of the measurement.
"""
from __future__ import annotations

import sys
import time

import logging

import can


def main() -> None:
    logging.getLogger("can").setLevel(logging.ERROR)  # python-can warns on every partial read
    port, mode, n = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
    bus = can.Bus(interface="socketcand", host="127.0.0.1", port=port, channel="vcan0")
    print("READY", flush=True)
    sys.stdin.readline()
    if mode == "tx":
        msg = can.Message(arbitration_id=0x123, is_extended_id=False, data=bytes(range(8)))
        t0 = time.perf_counter()
        for _ in range(n):
            bus.send(msg)
        print(f"SENT {time.perf_counter() - t0:.6f}", flush=True)
    else:
        got = 0
        t0 = None
        while got < n:
            m = bus.recv(5.0)
            if m is None:
                break
            if t0 is None:
                t0 = time.perf_counter()
            got += 1
        elapsed = time.perf_counter() - (t0 or time.perf_counter())
        print(f"RECEIVED {got} {elapsed:.6f}", flush=True)
    sys.stdin.readline()  # keep the connection until the driver is done counting
    bus.shutdown()


if __name__ == "__main__":
    main()

"""socketcand over loopback from Python: motorbus's client vs python-can's
`socketcand` interface, against the same motorbus SocketcandServer in the same run.

    PYTHONPATH=python python3 bench/socketcand_throughput.py [--frames 50000] [--pings 1000] [--reps 3]

Measured per client: frames/s sent (from the first send() until the bus has
them all), frames/s received (frames already queued on the way, timed from the
first recv() to the last), and one-way latency with one frame in flight.
"""
from __future__ import annotations

import argparse
import logging
import statistics
import time

import can

from motorbus import Frame
from motorbus._core.can import open_virtual
from motorbus.socketcand import SocketcandServer, open_socketcand

logging.getLogger("can").setLevel(logging.ERROR)  # python-can warns on every partial read


def wait_rx(node, want: int, limit: float = 60.0) -> None:
    end = time.perf_counter() + limit
    while node.counters.rx_frames < want and time.perf_counter() < end:
        time.sleep(0.0002)
    got = node.counters.rx_frames
    if got != want:
        raise SystemExit(f"FAILED: the bus counted {got} frames, {want} expected")


def drain(node) -> None:
    """Empties the node's recv() queue, so a later recv() waits for a new frame."""
    while node.recv(0) is not None:
        pass


def check_received(who: str, got: int, n: int) -> None:
    if got != n:
        raise SystemExit(f"FAILED: {who} received {got} of {n} frames")


def pct(values: list[float]) -> tuple[float, float]:
    v = sorted(values)
    return statistics.median(v), v[min(len(v) - 1, len(v) * 99 // 100)]


def measure(label: str, bus, msg, node, n: int, pings: int, reps: int) -> dict:
    """One client, measured exactly the same way whichever library it is (fairness by construction)."""
    f = Frame(0x123, bytes(range(8)))
    tx = rx = 0.0
    for _ in range(reps):
        base = node.counters.rx_frames
        t0 = time.perf_counter()
        for _ in range(n):
            bus.send(msg)
        wait_rx(node, base + n)
        tx = max(tx, n / (time.perf_counter() - t0))

        for _ in range(n):
            node.send(f)
        got = 0
        bus.recv(5.0)
        t0 = time.perf_counter()
        while got < n - 1 and bus.recv(5.0) is not None:
            got += 1
        elapsed = time.perf_counter() - t0
        check_received(label, got + 1, n)
        rx = max(rx, got / elapsed)

    # The node's recv() queue still holds every frame of the tx runs: without
    # this, node.recv() below would return at once and "latency" would be send() alone.
    drain(node)
    up, down = [], []
    for _ in range(pings):
        t = time.perf_counter_ns()
        bus.send(msg)
        node.recv(1.0)
        up.append((time.perf_counter_ns() - t) / 1e3)
        t = time.perf_counter_ns()
        node.send(f)
        bus.recv(1.0)
        down.append((time.perf_counter_ns() - t) / 1e3)
    return {"tx": tx, "rx": rx, "up": pct(up), "down": pct(down)}


def bench_ours(server, node, n: int, pings: int, reps: int) -> dict:
    bus = open_socketcand("127.0.0.1", server.port, "vcan0", rx_queue_size=1 << 22)
    time.sleep(0.01)
    try:
        return measure("motorbus", bus, Frame(0x123, bytes(range(8))), node, n, pings, reps)
    finally:
        bus.close()


def bench_pycan(server, node, n: int, pings: int, reps: int) -> dict:
    bus = can.Bus(interface="socketcand", host="127.0.0.1", port=server.port, channel="vcan0")
    time.sleep(0.01)
    msg = can.Message(arbitration_id=0x123, is_extended_id=False, data=bytes(range(8)))
    try:
        return measure("python-can", bus, msg, node, n, pings, reps)
    finally:
        bus.shutdown()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=50000)
    ap.add_argument("--pings", type=int, default=1000)
    ap.add_argument("--reps", type=int, default=3, help="throughput = best of this many runs, for both")
    args = ap.parse_args()

    served = open_virtual("bench-py-socketcand", rx_queue_size=1 << 22, tx_queue=4096)
    node = open_virtual("bench-py-socketcand", rx_queue_size=1 << 22, tx_queue=4096)
    with SocketcandServer(served, client_queue=1 << 22) as server:
        ours = bench_ours(server, node, args.frames, args.pings, args.reps)
        while node.recv(0) is not None:
            pass
        ref = bench_pycan(server, node, args.frames, args.pings, args.reps)
    print(f"socketcand over 127.0.0.1 from Python, {args.frames} frames of 8 bytes (best of {args.reps}),"
          f" {args.pings} pings")
    for name, r in (("motorbus", ours), ("python-can", ref)):
        print(f"  {name:<11} tx {r['tx']:>9.0f} frames/s  rx {r['rx']:>9.0f} frames/s  "
              f"latency client->bus median {r['up'][0]:.1f} us p99 {r['up'][1]:.1f} us, "
              f"bus->client median {r['down'][0]:.1f} us p99 {r['down'][1]:.1f} us")
    print(f"  ratio motorbus/python-can: tx {ours['tx'] / ref['tx']:.1f}x  rx {ours['rx'] / ref['rx']:.1f}x"
          f"  (target >= 5x)")
    node.close()
    served.close()


if __name__ == "__main__":
    main()

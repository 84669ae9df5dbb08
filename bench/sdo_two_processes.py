"""SDO expedited reads per second between two processes through `motorbus bus serve --socketcand`
(a server subprocess): motorbus's SdoClient over its socketcand client vs the `canopen` package's
SDO client over python-can's `socketcand` interface, in the same run, against the same node.

    .venv/bin/python bench/sdo_two_processes.py [--reads 3000] [--canopen-reads 1000]

Process A (a child, `--node PORT`) serves node 5 with motorbus's LocalNode on its own motorbus
socketcand client; process B (this one) reads 0x2000:0 (a u32) over its own socketcand client,
first with motorbus, then with canopen.  Every value is checked; a wrong value fails the run.
"""
from __future__ import annotations

import argparse
import logging
import subprocess
import sys
import time

logging.getLogger("can").setLevel(logging.ERROR)  # python-can warns on every partial read

NODE, INDEX, VALUE = 5, 0x2000, 0x12345678
WARMUP = 50


def serve_node(port: int) -> None:
    """Process A: a LocalNode behind a motorbus socketcand client."""
    from motorbus.canopen import LocalNode, ObjectDictionary
    from motorbus.socketcand import open_socketcand
    bus = open_socketcand("127.0.0.1", port, "can0")
    od = ObjectDictionary()
    od.add_variable(INDEX, "Value", "u32", "rw", default=VALUE)
    node = LocalNode(bus, NODE, od, send_boot_up=False)
    print("ready", flush=True)
    sys.stdin.read()  # until the parent closes our stdin
    node.close()
    bus.close()


def bench_motorbus(port: int, reads: int) -> float:
    from motorbus.canopen import SdoClient
    from motorbus.socketcand import open_socketcand
    with open_socketcand("127.0.0.1", port, "can0") as bus:
        sdo = SdoClient(bus, NODE, timeout=1.0)
        for _ in range(WARMUP):
            assert sdo.read_u32(INDEX) == VALUE
        lat = []
        t0 = time.perf_counter()
        for _ in range(reads):
            t = time.perf_counter()
            if sdo.read_u32(INDEX) != VALUE:
                raise SystemExit("motorbus: wrong value")
            lat.append(time.perf_counter() - t)
        return reads / (time.perf_counter() - t0), lat


def bench_canopen(port: int, reads: int) -> float:
    import canopen
    network = canopen.Network()
    network.connect(interface="socketcand", host="127.0.0.1", port=port, channel="can0")
    try:
        node = canopen.RemoteNode(NODE, canopen.ObjectDictionary())
        network.add_node(node)
        want = VALUE.to_bytes(4, "little")
        for _ in range(WARMUP):
            assert node.sdo.upload(INDEX, 0) == want
        lat = []
        t0 = time.perf_counter()
        for _ in range(reads):
            t = time.perf_counter()
            if node.sdo.upload(INDEX, 0) != want:
                raise SystemExit("canopen: wrong value")
            lat.append(time.perf_counter() - t)
        return reads / (time.perf_counter() - t0), lat
    finally:
        network.disconnect()


def _pct(lat: list) -> str:
    s = sorted(lat)
    return "median / p99 / max %.0f / %.0f / %.0f us" % (s[len(s) // 2] * 1e6, s[int(len(s) * 0.99)] * 1e6,
                                                          s[-1] * 1e6)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reads", type=int, default=3000)
    ap.add_argument("--canopen-reads", type=int, default=1000)
    ap.add_argument("--node", type=int, help=argparse.SUPPRESS)  # process A
    args = ap.parse_args()
    if args.node:
        serve_node(args.node)
        return
    server = subprocess.Popen([sys.executable, "-m", "motorbus", "bus", "serve", "virtual:sdo-two-processes",
                               "--socketcand", "127.0.0.1:0"], stdout=subprocess.PIPE, text=True)
    node = None
    try:
        kind, hostport, _channel = server.stdout.readline().split()
        port = int(hostport.rsplit(":", 1)[1])
        node = subprocess.Popen([sys.executable, __file__, "--node", str(port)],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        assert node.stdout.readline().strip() == "ready"
        mb, mb_lat = bench_motorbus(port, args.reads)
        co, co_lat = bench_canopen(port, args.canopen_reads)
        print(f"SDO expedited reads between two processes via `motorbus bus serve --socketcand` (127.0.0.1)")
        print(f"  motorbus SdoClient  / motorbus socketcand client : {mb:9.0f} reads/s ({args.reads} reads), "
              f"{_pct(mb_lat)}")
        print(f"  canopen SdoClient   / python-can socketcand      : {co:9.0f} reads/s ({args.canopen_reads} reads), "
              f"{_pct(co_lat)}")
        print(f"  ratio motorbus / canopen: {mb / co:.1f}x")
    finally:
        if node is not None:
            node.stdin.close()
            node.wait(10)
        server.terminate()
        server.wait(10)


if __name__ == "__main__":
    main()

"""Client-to-client round trip through `motorbus bus serve --socketcand` (a server
subprocess): motorbus's socketcand client vs python-can's `socketcand` interface,
in the same run.

    .venv/bin/python bench/socketcand_roundtrip.py [--pings 2000] [--pycan-pings 1000]

The requester (this process) sends 0x601 and waits for the responder's 0x581;
the responder is a second process (`--respond LIB`, no GIL shared with the
requester) that answers every 0x601 with 0x581 carrying the same bytes — the
shape of an SDO request/reply between two processes sharing a served bus.
Both libraries use the same server process, the same frames, the same loop.
Every reply's payload is checked; a lost or wrong reply fails the run.

For scale, the one-way client -> bus latency of the same client library
(send, then a virtual-bus node in this process receives; in-process
SocketcandServer, as in bench/socketcand_throughput.py) is measured in the same
run: the target is a client-to-client round trip within ~2x that.
"""
from __future__ import annotations

import argparse
import logging
import os
import statistics
import subprocess
import sys
import time

import can

from motorbus import Frame
from motorbus._core.can import open_virtual
from motorbus.socketcand import SocketcandServer, open_socketcand

logging.getLogger("can").setLevel(logging.ERROR)  # python-can warns on every partial read

REQ, REP, STOP = 0x601, 0x581, 0x7FF
WARMUP = 50


class Client:
    """The same four operations over either library, so both are timed by one loop."""

    def __init__(self, lib: str, port: int, channel: str) -> None:
        self.lib = lib
        if lib == "motorbus":
            self.bus = open_socketcand("127.0.0.1", port, channel)
        else:
            self.bus = can.Bus(interface="socketcand", host="127.0.0.1", port=port, channel=channel)

    def send(self, can_id: int, data: bytes) -> None:
        if self.lib == "motorbus":
            self.bus.send(Frame(can_id, data))
        else:
            self.bus.send(can.Message(arbitration_id=can_id, is_extended_id=False, data=data))

    def recv(self, timeout: float) -> tuple[int, bytes] | None:
        m = self.bus.recv(timeout)
        if m is None:
            return None
        if self.lib == "motorbus":
            return m.id, m.data
        return m.arbitration_id, bytes(m.data)

    def close(self) -> None:
        if self.lib == "motorbus":
            self.bus.close()
        else:
            self.bus.shutdown()


def respond(lib: str, port: int, channel: str) -> None:
    """The responder process: answers 0x601 with 0x581 (same bytes) until 0x7FF."""
    c = Client(lib, port, channel)
    try:
        print("READY", flush=True)
        while True:
            got = c.recv(10.0)
            if got is None or got[0] == STOP:
                return
            if got[0] == REQ:
                c.send(REP, got[1])
    finally:
        c.close()


def pct(values: list[float]) -> dict:
    v = sorted(values)
    return {"median": statistics.median(v), "p99": v[min(len(v) - 1, len(v) * 99 // 100)],
            "mean": statistics.fmean(v)}


def round_trips(lib: str, port: int, channel: str, pings: int) -> dict:
    responder = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--respond", lib,
                                  "--port", str(port), "--channel", channel],
                                 stdout=subprocess.PIPE, text=True)
    try:
        if responder.stdout.readline().strip() != "READY":
            raise SystemExit(f"FAILED: {lib} responder did not start")
        c = Client(lib, port, channel)
        try:
            time.sleep(0.02)  # past the server's rawmode settle time for both clients
            us = []
            for i in range(WARMUP + pings):
                data = i.to_bytes(4, "little") + b"\x40\x00\x10\x00"
                t = time.perf_counter_ns()
                c.send(REQ, data)
                got = c.recv(2.0)
                dt = (time.perf_counter_ns() - t) / 1e3
                if got != (REP, data):
                    raise SystemExit(f"FAILED: {lib} round trip {i}: got {got}, expected {(REP, data)}")
                if i >= WARMUP:
                    us.append(dt)
            c.send(STOP, b"")
        finally:
            c.close()
        responder.wait(10)
    finally:
        if responder.poll() is None:
            responder.kill()
    return pct(us)


def client_to_bus(lib: str, pings: int) -> tuple[dict, dict]:
    """One-way latencies client -> in-process server -> virtual bus node and back, same client library."""
    name = f"bench-rt-c2b-{os.getpid()}-{lib}"
    served, node = open_virtual(name), open_virtual(name)
    with SocketcandServer(served) as server:
        c = Client(lib, server.port, "vcan0")
        try:
            time.sleep(0.02)
            up, down = [], []
            data = bytes(range(8))
            for i in range(WARMUP + pings):
                t = time.perf_counter_ns()
                c.send(REQ, data)
                got = node.recv(2.0)
                dt_up = (time.perf_counter_ns() - t) / 1e3
                if got is None or got.id != REQ or got.data != data:
                    raise SystemExit(f"FAILED: {lib} client->bus ping {i}: got {got}")
                t = time.perf_counter_ns()
                node.send(Frame(REP, data))
                back = c.recv(2.0)
                dt_down = (time.perf_counter_ns() - t) / 1e3
                if back != (REP, data):
                    raise SystemExit(f"FAILED: {lib} bus->client ping {i}: got {back}")
                if i >= WARMUP:
                    up.append(dt_up)
                    down.append(dt_down)
        finally:
            c.close()
    node.close()
    served.close()
    return pct(up), pct(down)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pings", type=int, default=2000, help="round trips for motorbus")
    ap.add_argument("--pycan-pings", type=int, default=1000, help="round trips for python-can")
    ap.add_argument("--respond", choices=("motorbus", "pycan"), help=argparse.SUPPRESS)
    ap.add_argument("--port", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--channel", default="can0", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.respond:
        respond(args.respond, args.port, args.channel)
        return

    server = subprocess.Popen([sys.executable, "-m", "motorbus", "bus", "serve", f"virtual:bench-rt-{os.getpid()}",
                               "--socketcand", "127.0.0.1:0", "--channel", "can0"],
                              stdout=subprocess.PIPE, text=True)
    try:
        kind, hostport, channel = server.stdout.readline().split()
        if kind != "socketcand":
            raise SystemExit(f"FAILED: unexpected server line {kind} {hostport} {channel}")
        port = int(hostport.rsplit(":", 1)[1])
        ours = round_trips("motorbus", port, channel, args.pings)
        ref = round_trips("pycan", port, channel, args.pycan_pings)
    finally:
        server.terminate()
        server.wait(10)
    ours_up, ours_down = client_to_bus("motorbus", args.pings)
    ref_up, ref_down = client_to_bus("pycan", args.pycan_pings)

    print(f"socketcand client-to-client round trip through `motorbus bus serve --socketcand` (subprocess),"
          f" responder in its own process; {args.pings} (motorbus) / {args.pycan_pings} (python-can) round trips")
    # Each leg of a client-to-client round trip crosses the server twice, as a
    # client<->bus round trip (client->bus + bus->client) does once: the target
    # is a client-to-client round trip within ~2x the client<->bus one.
    for name, r, up, down in (("motorbus", ours, ours_up, ours_down), ("python-can", ref, ref_up, ref_down)):
        c2b = up["median"] + down["median"]
        print(f"  {name:<11} client-to-client round trip median {r['median']:8.1f} us  p99 {r['p99']:8.1f} us"
              f"  mean {r['mean']:8.1f} us | client->bus median {up['median']:6.1f} us,"
              f" bus->client {down['median']:6.1f} us | round trip / client<->bus {r['median'] / c2b:.2f}x"
              f" (target <= ~2x)")
    print(f"  ratio python-can/motorbus (client-to-client round trip median) {ref['median'] / ours['median']:.2f}x")


if __name__ == "__main__":
    main()

"""Benches: what discovery costs, and what reading a position through a Bench costs.

1. Discovery, serial: a full sweep of one line with no drive on it (every serial
   kind, every rate, every address: the worst case) against its bound, kinds x
   rates x addresses x (reply timeout + the query's wire time); and a line whose
   drives answer at the first rate (the sweep stops there).
2. Discovery, CAN: motorbus's CANopen scan of nodes 1-127 (2 nodes present) on a
   socketcand-served bus, against canopen's NodeScanner through python-can's
   socketcand interface in the same run.  canopen's scanner does not know when to
   stop: its figure is the time until the 2 present nodes had answered, which it
   could only know by being told; ours is the whole scan, absent nodes included.
3. ``drive.position`` through a ``Bench(sim=True)`` over each transport (serial
   kinds on a pty, CAN kinds over socketcand) against the kind's native client
   reading the same position, blocks alternated; medians.

    .venv/bin/python bench/bench_files.py [--n 300] [--skip-serial-sweep]
"""
from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from typing import Any, Callable

import motorbus
from motorbus import Bench, _core, registry
from motorbus.bus_server import BusServers
from motorbus.discovery import _wire_time, discover


def emit(**row: Any) -> None:
    print(json.dumps(row), flush=True)


def serial_sweep(reply_timeout: float) -> None:
    plugins = [p for p in registry.drive_plugins().values() if p.transport == "serial" and p.provides("probe")]
    empty = _core.serial.PtyLineServer([], 9600)
    try:
        t = time.perf_counter()
        r = discover([empty.slave_path], [], reply_timeout=reply_timeout, timeout=3600)
        took = time.perf_counter() - t
    finally:
        empty.close()
    bound = sum(len(p.probe_addresses) * (reply_timeout + _wire_time(b))
                for p in plugins for b in (p.probe_bauds or (p.default_baud,)))
    emit(bench="discovery serial, empty line (worst case)", kinds=[p.kind for p in plugins], probes=r.probes,
         seconds=round(took, 2), bound_seconds=round(bound, 2), per_probe_ms=round(1000 * took / r.probes, 1),
         reply_timeout=reply_timeout)
    from motorbus.drives import arcus
    line = _core.serial.PtyLineServer([arcus.make_sim("07"), arcus.make_sim("42")], 9600)
    try:
        t = time.perf_counter()
        r = discover([line.slave_path], [], reply_timeout=reply_timeout, timeout=3600)
        took = time.perf_counter() - t
    finally:
        line.close()
    emit(bench="discovery serial, arcus 07 and 42 at 9600", found=len(r.found), probes=r.probes,
         seconds=round(took, 2))


def can_sweep(sdo_timeout: float) -> None:
    from motorbus.drives import cia402
    servers = BusServers("virtual:bench-files-scan", socketcand=["127.0.0.1:0"], channel="can0")
    sims = [cia402.make_sim(n) for n in (9, 77)]
    for s in sims:
        s.attach(servers.endpoint())
    srv = servers.servers[0]
    spec = f"socketcand:{srv.host}:{srv.port}/can0"
    try:
        ours = []
        for _ in range(3):
            t = time.perf_counter()
            r = discover([], [spec], sdo_timeout=sdo_timeout)
            ours.append(time.perf_counter() - t)
            assert sorted(int(f.address) for f in r.found) == [9, 77], r.found
        ref = None
        try:
            import can
            import canopen
            theirs = []
            for _ in range(3):
                net = canopen.Network()
                net.connect(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
                try:
                    t = time.perf_counter()
                    net.scanner.search()
                    while len(net.scanner.nodes) < 2 and time.perf_counter() - t < 5:
                        time.sleep(0.001)
                    theirs.append(time.perf_counter() - t)
                finally:
                    net.disconnect()
            ref = statistics.median(theirs)
        except ImportError:
            pass
        emit(bench="discovery CAN, nodes 1-127 (2 present), socketcand", sdo_timeout=sdo_timeout,
             ours_seconds=round(statistics.median(ours), 3),
             canopen_until_both_answered_seconds=None if ref is None else round(ref, 3))
    finally:
        for s in sims:
            s.close()
        servers.close()


BENCH_TOML = """
[bus.can0]
spec = "socketcan:can0"
[line.a]
port = "/dev/ttyUSB0"
[line.d]
port = "/dev/ttyUSB1"
[axis.arcus]
kind = "arcus"
line = "a"
address = 1
[axis.dmac]
kind = "dmac"
line = "d"
address = 0
params = { "#LINE_DELAY" = 100 }
[axis.cia402]
kind = "cia402"
bus = "can0"
address = 5
"""

NATIVE: dict[str, Callable[[Any], Any]] = {
    "arcus": lambda d: d.native.encoder,
    "dmac": lambda d: d.native.position,
    "cia402": lambda d: d.native.sdo.upload(0x6064, 0),
}


def position(n: int) -> None:
    with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
        f.write(BENCH_TOML)
    with Bench.load(f.name, sim=True) as bench:
        bench.apply()
        for name, d in bench.axes.items():
            native = NATIVE[d.kind]
            a, b = [], []
            for _ in range(max(1, n // 50)):
                for _ in range(50):
                    t = time.perf_counter_ns()
                    _ = d.position
                    a.append(time.perf_counter_ns() - t)
                for _ in range(50):
                    t = time.perf_counter_ns()
                    native(d)
                    b.append(time.perf_counter_ns() - t)
            transport = "pty" if registry.drive_plugin(d.kind).transport == "serial" else "socketcand"
            ma, mb = statistics.median(a) / 1000, statistics.median(b) / 1000
            emit(bench="drive.position through a Bench", kind=d.kind, transport=transport, n=len(a),
                 bench_us=round(ma, 1), native_us=round(mb, 1), ratio=round(ma / mb, 3))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--reply-timeout", type=float, default=0.05)
    ap.add_argument("--skip-serial-sweep", action="store_true")
    args = ap.parse_args()
    if not args.skip_serial_sweep:
        serial_sweep(args.reply_timeout)
    can_sweep(0.1)
    position(args.n)


if __name__ == "__main__":
    main()

"""UNITEK cyclic transmissions over socketcand: the simulator sending 8 registers every
1 ms for D seconds, against python-can's send_periodic sending the same 8 x 1 ms schedule,
in the same run, both received by the same kind of motorbus socketcand client.

    PYTHONPATH=python python3 bench/unitek_cyclic.py [--seconds 10]

Per source: frames expected / received / lost, the receive-side period error p50/p99
(|period - 1 ms| measured on the receiver's timestamps: the transmitter's jitter plus the
loopback TCP path, the same path for both sources) and the process CPU time per second
of run (sender, server and receiver all live in this process for both runs).
"""
from __future__ import annotations

import argparse
import logging
import time

import can
import numpy as np

import motorbus
from motorbus.drives.unitek import Reg, Unitek
from motorbus.sim import SimBench

logging.getLogger("can").setLevel(logging.ERROR)
REGS = [Reg.SPEED_IST, Reg.SPEED_CMD, Reg.ACC_RAMP, Reg.KERN_STATUS, Reg.EVENT_MASK, Reg.POS_DEST,
        Reg.TORQUE_CMD, Reg.POS_IST]


def stats(name: str, expected: int, series: list) -> str:
    got = sum(len(t) for t in series)
    err = np.concatenate([np.abs(np.diff(t) - 1_000_000) for t in series if len(t) > 1]) / 1e3
    return (f"{name:28s} expected {expected:6d} received {got:6d} lost {max(expected - got, 0):5d}  "
            f"period error p50 {np.percentile(err, 50):7.1f} us p99 {np.percentile(err, 99):7.1f} us")


def run_sim(seconds: float, where: str, bench) -> tuple:
    sim = bench.sims[("unitek", "0x201")]
    with motorbus.open_bus(where) as bus:
        # The same receiver as for python-can: a subscriber on the bus thread keeping timestamps.
        got: dict = {int(r): [] for r in REGS}
        bus.subscribe(lambda f: got[f.data[0]].append(f.timestamp_ns) if f.data[0] in got else None, id=0x181)
        d = Unitek(bus, 0x201, timeout=2.0)
        cpu0, t0 = time.process_time(), time.perf_counter()
        for r in REGS:
            d.subscribe(r, 1, capacity=int(seconds * 1000) + 1000)
        time.sleep(seconds)
        for r in REGS:
            d.unsubscribe(r)
        time.sleep(0.2)
        cpu = (time.process_time() - cpu0) / (time.perf_counter() - t0)
        sent = sum(sim.sent(r) for r in REGS)
        d.close()
    return sent, [np.array(got[int(r)], dtype=np.int64) for r in REGS], cpu


def run_pycan(seconds: float, host: str, port: int, where: str) -> tuple:
    ids = list(range(0x281, 0x289))  # eight ids nobody else uses on this bus
    with motorbus.open_bus(where) as rx:
        got: dict = {i: [] for i in ids}
        for i in ids:
            rx.subscribe(lambda f, i=i: got[i].append(f.timestamp_ns), id=i)
        sender = can.Bus(interface="socketcand", host=host, port=port, channel="can0")
        try:
            cpu0, t0 = time.process_time(), time.perf_counter()
            tasks = [sender.send_periodic(can.Message(arbitration_id=i, data=[0x30, 0, 0, 0], is_extended_id=False),
                                          0.001, store_task=False) for i in ids]
            time.sleep(seconds)
            for task in tasks:
                task.stop()
            elapsed_send = time.perf_counter() - t0
            time.sleep(0.2)
            cpu = (time.process_time() - cpu0) / (time.perf_counter() - t0)
        finally:
            sender.shutdown()
    expected = int(round(elapsed_send * 1000)) * len(ids)
    return expected, [np.array(got[i], dtype=np.int64) for i in ids], cpu


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=10.0)
    a = ap.parse_args()
    with SimBench(["unitek:0x201"]) as bench:
        srv = bench.can.servers[0]
        where = f"socketcand:{srv.host}:{srv.port}/can0"
        sent, series, cpu_sim = run_sim(a.seconds, where, bench)
        print(stats("motorbus UnitekSim cyclic", sent, series) + f"  CPU {cpu_sim * 100:5.1f} %")
        expected, series_pc, cpu_pc = run_pycan(a.seconds, srv.host, srv.port, where)
        print(stats("python-can send_periodic", expected, series_pc) + f"  CPU {cpu_pc * 100:5.1f} %")
        sim_rate = sent / a.seconds
        pc_rate = sum(len(t) for t in series_pc) / a.seconds
        print(f"frames/s delivered: sim {sim_rate:.0f}, python-can {pc_rate:.0f} (ratio {sim_rate / max(pc_rate, 1):.2f})")


if __name__ == "__main__":
    main()

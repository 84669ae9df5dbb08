"""Polling 4 axes on 2 transports at 1 kHz: motorbus.Poller (C++ threads) vs a Python `threading` loop.

Four simulated drives served OUT of process, as real drives would be (other processes):
``motorbus sim serve --drive arcus:01,02 --drive unitek:0x201,0x202`` in a child process
serves two ``arcus`` on one pty line (unthrottled) and two ``unitek`` on one CAN bus over
socketcand on 127.0.0.1; this process opens them as a user would (the pty, the
socketcand bus).  Each sample reads position, velocity and status of every axis while
the axes jog slowly: on the line 6 ASCII queries; on the bus, with ``--mode auto`` (the
default), the UNITEK drives push the 3 registers every 1 ms (cyclic transmission) and
the Poller captures them (``--mode ask``: 6 register reads per sample instead).  Then
the same reads, with the same native clients on the same links, from one Python thread
per transport on the same absolute schedule (t0 + k * period, ``time.sleep`` to the
deadline) in the same run, one after the other (for the captured group: the newest
sample of each register's cyclic stream).  Both are measured the same way from their
sample timestamps:

* missed: deadlines skipped entirely (the sample before ran past a whole period);
* late: samples whose reads ran past the next deadline;
* period error: | interval between consecutive samples - period |, p50 / p99 / max.

    .venv/bin/python bench/poller.py [--seconds 60] [--rate 1000] [--spin-us 0] [--mode auto|ask]
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import threading
import time

import numpy as np

from motorbus import Bench, Poller

SIM_SERVE = ["--drive", "arcus:01,02", "--drive", "unitek:0x201,0x202"]


def serve_sims() -> tuple[subprocess.Popen, dict]:
    """``motorbus sim serve`` in a child process; the bench file that reaches its drives."""
    child = subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", *SIM_SERVE],
                             stdout=subprocess.PIPE, text=True)
    pty = spec = None
    deadline = time.monotonic() + 30
    while (pty is None or spec is None) and time.monotonic() < deadline:
        line = child.stdout.readline()
        if not line:
            child.kill()
            raise SystemExit("motorbus sim serve ended before announcing its drives")
        words = line.split()
        if words[0].startswith("arcus:"):
            pty = words[1]
        elif words[0] == "socketcand":
            spec = f"socketcand:{words[1]}/{words[2]}"
    if pty is None or spec is None:
        child.kill()
        raise SystemExit("motorbus sim serve did not announce its drives in 30 s")
    bench = {
        "line": {"rs485": {"port": pty}},
        "bus": {"can0": {"spec": spec}},
        "axis": {
            "a1": {"kind": "arcus", "line": "rs485", "address": 1},
            "a2": {"kind": "arcus", "line": "rs485", "address": 2},
            "u1": {"kind": "unitek", "bus": "can0", "address": "0x201"},
            "u2": {"kind": "unitek", "bus": "can0", "address": "0x202"},
        },
    }
    return child, bench


def figures(t_ns: np.ndarray, k: np.ndarray, period_ns: int, late: int) -> dict:
    """The same figures for both pollers, from (deadline index, start time) of each sample taken."""
    consecutive = np.diff(k) == 1
    err = np.abs(np.diff(t_ns)[consecutive] - period_ns) / 1e3
    missed = int(k[-1] - k[0] + 1 - len(k)) if len(k) else 0
    return {"samples": len(k), "missed": missed, "late": late,
            "p50": float(np.percentile(err, 50)) if len(err) else float("nan"),
            "p99": float(np.percentile(err, 99)) if len(err) else float("nan"),
            "max": float(err.max()) if len(err) else float("nan")}


def native_reads(drive, fields, captured: bool, interval_ms: int):
    """The same reads the poller's source makes, as Python calls on the native client."""
    if captured:   # the newest sample of each register's cyclic stream (the Poller's capture)
        from motorbus.drives.unitek import Reg

        regs = {"position": Reg.POS_IST, "velocity": Reg.SPEED_IST, "status": Reg.KERN_STATUS}
        streams = [drive.native.subscribe(regs[f], interval_ms, capacity=256) for f in fields]

        def newest(s):
            t, v = s.read()
            return int(v[-1]) if len(v) else None
        return lambda: [newest(s) for s in streams]
    if drive.kind == "arcus":
        c = drive.native
        names = {"position": "EX" if drive._snl else "PX", "velocity": "PS", "status": "MST"}
        calls = [lambda n=names[f]: c.query(n) for f in fields]
    elif drive.kind == "unitek":
        from motorbus.drives.unitek import Reg

        regs = {"position": Reg.POS_IST, "velocity": Reg.SPEED_IST, "status": Reg.KERN_STATUS}
        c = drive.native
        calls = [lambda r=regs[f]: c.read(r) for f in fields]
    else:
        sdo = drive._sdo
        objects = {"position": (sdo.read_i32, 0x6064), "velocity": (sdo.read_i32, 0x606C),
                   "status": (sdo.read_u16, 0x6041)}
        calls = [lambda r=objects[f]: r[0](r[1]) for f in fields]
    return lambda: [c() for c in calls]


def python_loop(groups: dict, seconds: float, period_ns: int) -> dict:
    """One threading.Thread per transport, absolute deadlines, the late/missed rules of the C++ poller."""
    results: dict = {}
    t0 = time.monotonic_ns() + 20_000_000
    end = t0 + int(seconds * 1e9)

    def run(name, reads):
        n = (end - t0) // period_ns + 1
        ks, ts = np.empty(n, np.int64), np.empty(n, np.int64)
        values = []
        count, late, k = 0, 0, 0
        while True:
            deadline = t0 + k * period_ns
            if deadline >= end:
                break
            now = time.monotonic_ns()
            if deadline > now:
                time.sleep((deadline - now) / 1e9)
            start = time.monotonic_ns()
            k = max(k, (start - t0) // period_ns)   # woken past later deadlines: those are missed
            values.append([r() for r in reads])
            done = time.monotonic_ns()
            ks[count], ts[count] = k, start
            count += 1
            if done >= t0 + (k + 1) * period_ns:
                late += 1
                k = max(k + 1, (done - t0) // period_ns)
            else:
                k += 1
        results[name] = (ks[:count], ts[:count], late)

    threads = [threading.Thread(target=run, args=(name, reads)) for name, reads in groups.items()]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    return {name: figures(ts, ks, period_ns, late) for name, (ks, ts, late) in results.items()}


def poller_run(bench, fields, seconds: float, rate: float, spin_us: float, realtime: bool,
               mode: str) -> tuple[dict, dict]:
    with Poller(bench.axes, fields=fields, rate_hz=rate, spin_us=spin_us, realtime=realtime, mode=mode) as poller:
        end = time.monotonic() + seconds + 0.02
        while time.monotonic() < end:   # drain as a user would: the ring holds 10 s by default
            time.sleep(min(0.5, max(0.0, end - time.monotonic())))
            poller.read()
    frame = poller.frame()
    stats = poller.stats
    out = {}
    for label, s in stats.items():
        axis = s["axes"][0]
        if s["captured"]:
            # A captured axis's <axis>.t is when its data arrived, not when the poll thread ran:
            # the thread's own timing comes from its histograms (1 µs bins, same definitions).
            out[label] = {"samples": s["samples"], "missed": s["missed"], "late": s["late"],
                          "p50": s["period_error_p50"] * 1e6, "p99": s["period_error_p99"] * 1e6,
                          "max": s["period_error_max"] * 1e6}
            ages = frame["t"] - frame[f"{axis}.t"]
            ages = ages[~np.isnan(ages)]
            out[label]["age_p50"] = float(np.percentile(ages, 50)) * 1e6 if len(ages) else float("nan")
            out[label]["age_p99"] = float(np.percentile(ages, 99)) * 1e6 if len(ages) else float("nan")
        else:
            taken = ~np.isnan(frame[f"{axis}.t"])
            t_ns = np.round(frame[f"{axis}.t"][taken] * 1e9).astype(np.int64)
            k = np.round((frame["t"][taken] - frame["t"][0]) * rate).astype(np.int64)
            out[label] = figures(t_ns, k, poller.period_ns, s["late"])
        out[label]["missed_stats"] = s["missed"]
        out[label]["stale"] = s["stale"]
        out[label]["captured"] = bool(s["captured"])
        if s["error"]:
            out[label]["error"] = f"{s['error_type']}: {s['error']}"
    return out, stats


def show(title: str, figs: dict) -> None:
    print(title)
    for label, f in figs.items():
        extra = f"  ERROR {f['error']}" if f.get("error") else ""
        if f.get("captured"):
            extra += (f"  captured: stale {f['stale']}, data age (deadline - arrival) p50 {f['age_p50']:.0f} us "
                      f"p99 {f['age_p99']:.0f} us")
        print(f"  {label:8s} samples {f['samples']:7d}  missed {f['missed']:5d}  late {f['late']:5d}  "
              f"period error p50 {f['p50']:8.1f} us  p99 {f['p99']:8.1f} us  max {f['max']:9.1f} us{extra}")


FLOOR_EXE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "dev", "bench_timer_floor")


def timer_floor(seconds: float, rate: float) -> str:
    """A bare 1 kHz sleep-to-deadline loop in C++ on this idle machine (bench/cpp/timer_floor.cpp):
    no poller can wake more punctually than that."""
    if not os.path.exists(FLOOR_EXE):
        return "not measured (build/dev/bench_timer_floor is built by make build, MOTORBUS_BENCH=ON)"
    out = subprocess.run([FLOOR_EXE, f"{seconds:g}", f"{rate:g}"], capture_output=True, text=True, check=True)
    return out.stdout.strip().removeprefix("timer floor: ")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="seconds of polling, each way")
    ap.add_argument("--rate", type=float, default=1000.0, help="Hz")
    ap.add_argument("--spin-us", type=float, default=0.0, help="Poller spin before each deadline (µs)")
    ap.add_argument("--realtime", action="store_true", help="Poller: try SCHED_FIFO")
    ap.add_argument("--fields", default="position,velocity,status", help="comma-separated Poller fields")
    ap.add_argument("--jog", type=float, default=20.0, help="jog every axis at this speed while polling (0: idle)")
    ap.add_argument("--mode", default="auto", choices=("auto", "ask"),
                    help="Poller mode: auto captures the UNITEK drives' cyclic registers, ask reads them")
    args = ap.parse_args()
    period_ns = int(round(1e9 / args.rate))
    fields = tuple(f.strip() for f in args.fields.split(",") if f.strip())
    print(f"{time.strftime('%Y-%m-%d %H:%M:%S %Z')}  load {os.getloadavg()}  {os.cpu_count()} CPUs  "
          f"{args.rate:g} Hz, {args.seconds:g} s each way, spin {args.spin_us:g} us, fields {','.join(fields)}, "
          f"jog {args.jog:g}, mode {args.mode}")
    floor = timer_floor(args.seconds, args.rate)
    child, spec = serve_sims()
    try:
        with Bench.from_dict(spec) as bench:
            for d in bench.axes.values():
                d.enable()
                if args.jog:
                    d.jog(args.jog)   # slowly, so the readings change
            cpp, stats = poller_run(bench, fields, args.seconds, args.rate, args.spin_us, args.realtime, args.mode)
            interval_ms = max(1, int(round(period_ns / 1e6)))
            groups = {}
            for label, s in stats.items():
                groups[label] = [native_reads(bench[a], fields, a in s["captured"], interval_ms) for a in s["axes"]]
            time.sleep(0.05)   # the streams' first samples
            py = python_loop(groups, args.seconds, period_ns)
            for d in bench.axes.values():
                if args.jog:
                    d.stop()
    finally:
        child.terminate()
        child.wait(timeout=10)
    show("motorbus.Poller (C++ thread per transport):", cpp)
    for label, s in stats.items():
        print(f"    C++ histograms {label}: period error p50/p99/max {s['period_error_p50'] * 1e6:.0f}/"
              f"{s['period_error_p99'] * 1e6:.0f}/{s['period_error_max'] * 1e6:.0f} us, wake latency p99 "
              f"{s['wake_latency_p99'] * 1e6:.0f} us, reads p50 {s['read_time_p50'] * 1e6:.0f} us, "
              f"realtime {s['realtime']}")
    show("Python threading loop, same reads on the native clients:", py)
    print(f"this machine's floor, measured before the sims started ({os.path.basename(FLOOR_EXE)}): {floor}")
    for label in cpp:
        c, p = cpp[label], py[label]
        print(f"  ratio {label}: p99 period error Python / Poller {p['p99'] / max(c['p99'], 1e-9):.1f}x, "
              f"max {p['max'] / max(c['max'], 1e-9):.1f}x, missed {p['missed']} vs {c['missed']}")


if __name__ == "__main__":
    main()

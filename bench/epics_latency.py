"""How late a move is over Channel Access, against the same move through motorbus.aio.

Two figures per kind, in the same run:

* **put -> motion start**: from just before a CA client puts ``VAL`` (pyepics, libca) to
  the first sample where the simulated motor's shaft has left its position; the reference
  is from just before ``await drive.move_to(target)`` in-process to the same event.
* **rest -> DMOV=1**: from the first sample where the shaft stands on its final position
  to the client's DMOV=1 monitor callback; the reference is from the same event to the
  return of ``move_to(..., wait=True)``.  Also shown: rest -> the put's completion
  (``caput(wait=True)`` put-callback).

The service runs as it does under ``motorbus serve``: another process (this script with
``--serve``), one axis of the kind on its simulated twin, its CA face on 127.0.0.1 at a
port of its own, with a watcher thread sampling the simulator's shaft every ~0.1 ms.
The reference runs the same twin and the same watcher in this process.  Both processes
read CLOCK_MONOTONIC (``time.monotonic``), one clock on Linux, so an event seen by the
service's watcher and a callback in the client are on one time line.  The watcher's
sampling period (and the simulator's own step) bound the resolution of "motion start"
and "rest", alike for both sides.  Goal (issue 26): within 2 ms of the in-process move.

    .venv/bin/python bench/epics_latency.py [--n 30] [--kinds cia402,arcus]
"""
from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import subprocess
import sys
import threading
import time
from typing import Any, Optional

SCALE = 0.01          # mm per native unit
STEP = 1.0            # mm per move: short, so the run is about latency, not travel
VELO = 100.0          # mm/s, both sides (the CA face passes VELO as move_to's velocity)
NO_VELOCITY = {"unitek"}
PORT = 24064          # CA port of the served twin (not 5064: nothing else on this host is touched)
PREFIX = "MBBENCH:"

# The fast profiles of the test kinds (tests/python/drive_kinds.py): moves of 1 mm take a
# few ms, so the figures are the command path's, not the motor's.
PROFILES = {
    "cia402": ({"0x6081": 20000, "0x6083": 400000, "0x6084": 400000}, lambda sim: sim.position),
    "arcus": ({"HSPD": 20000, "LSPD": 2000, "ACC": 20}, lambda sim: sim.pulse_position),
    "dmac": ({}, lambda sim: sim.state().position),
    "pmc007": ({"maximum_speed": 20000}, lambda sim: sim.position),
    "unitek": ({"ACC_RAMP": 20}, lambda sim: sim.position_num),
    "arcus-canopen": ({"0x6081": 20000, "0x6083": 20, "0x6084": 20}, lambda sim: sim.pulse_position),
}


def ca_env(port: int) -> dict[str, str]:
    """Loopback only: searches to 127.0.0.1, beacons to 127.0.0.1 (caproto's default is
    255.255.255.255), the server's interface 127.0.0.1."""
    return {"EPICS_CA_SERVER_PORT": str(port), "EPICS_CA_REPEATER_PORT": str(port + 1),
            "EPICS_CA_AUTO_ADDR_LIST": "NO", "EPICS_CA_ADDR_LIST": "127.0.0.1",
            "EPICS_CAS_INTF_ADDR_LIST": "127.0.0.1", "EPICS_CAS_AUTO_BEACON_ADDR_LIST": "NO",
            "EPICS_CAS_BEACON_ADDR_LIST": "127.0.0.1", "EPICS_CAS_BEACON_PORT": str(port + 1)}


def bench_data(kind: str) -> dict:
    import motorbus

    plugin = motorbus.registry.drive_plugin(kind)
    params, _ = PROFILES[kind]
    axis = {"kind": kind, "address": plugin.default_address, "units": {"name": "mm", "scale": SCALE},
            "params": dict(params)}
    if plugin.transport == "serial":
        return {"line": {"l": {"port": "/dev/null-bench"}}, "axis": {kind: dict(axis, line="l")}}
    return {"bus": {"b": {"spec": f"virtual:epics-bench-{kind}"}}, "axis": {kind: dict(axis, bus="b")}}


class Watcher:
    """Samples the simulator's shaft every ~0.1 ms while armed (a thread of its own)."""

    def __init__(self, shaft: Any) -> None:
        self.shaft = shaft
        self.samples: list[tuple[float, float]] = []
        self.armed = threading.Event()
        self.alive = True
        threading.Thread(target=self._run, name="shaft-watcher", daemon=True).start()

    def _run(self) -> None:
        while self.alive:
            if not self.armed.wait(0.1):
                continue
            self.samples.append((time.monotonic(), self.shaft()))
            time.sleep(0.0001)

    def arm(self) -> None:
        self.samples = []
        self.armed.set()

    def disarm(self) -> dict[str, Optional[float]]:
        """The move's motion start (first sample off the first position) and rest (first
        sample on the final position, after which it never left)."""
        self.armed.clear()
        time.sleep(0.002)
        s = self.samples
        if not s:
            return {"start": None, "rest": None}
        first, last = s[0][1], s[-1][1]
        start = next((t for t, p in s if p != first), None)
        rest = None
        for t, p in reversed(s):
            if p != last:
                break
            rest = t
        return {"start": start, "rest": rest if start is not None else None}


# -- the service side (a child process) -----------------------------------------------------

def serve(kind: str, port: int) -> None:
    """The twin served over CA; stdin 'arm'/'disarm' drive the watcher, answers on stdout."""
    from motorbus import aio
    from motorbus.serve.epics import start_ca

    loop = asyncio.new_event_loop()
    threading.Thread(target=loop.run_forever, name="ca-face", daemon=True).start()

    def run(coro: Any) -> Any:
        return asyncio.run_coroutine_threadsafe(coro, loop).result(60)

    async def open_() -> tuple[Any, Any]:
        bench = await aio.Bench.from_dict(bench_data(kind), sim=True)
        await bench[kind].clear_faults()
        await bench[kind].enable()
        return bench, await start_ca(bench, prefix=PREFIX, interfaces=("127.0.0.1",), port=port)

    bench, face = run(open_())
    sim = bench.sync.sims[kind]
    _, shaft = PROFILES[kind]
    watcher = Watcher(lambda: shaft(sim) * SCALE)
    print(json.dumps({"ready": True, "port": face.port, "pid": os.getpid()}), flush=True)
    for line in sys.stdin:
        cmd = line.strip()
        if cmd == "arm":
            watcher.arm()
            print(json.dumps({"armed": True}), flush=True)
        elif cmd == "disarm":
            print(json.dumps(watcher.disarm()), flush=True)
        elif cmd == "quit":
            break
    run(face.close())
    run(bench.aclose())


# -- the reference: the same move in-process through motorbus.aio -----------------------------

def reference(kind: str, n: int) -> dict[str, list[float]]:
    from motorbus import aio

    async def main() -> dict[str, list[float]]:
        bench = await aio.Bench.from_dict(bench_data(kind), sim=True)
        try:
            drive = bench[kind]
            await drive.clear_faults()
            await drive.enable()
            sim = bench.sync.sims[kind]
            _, shaft = PROFILES[kind]
            watcher = Watcher(lambda: shaft(sim) * SCALE)
            out: dict[str, list[float]] = {"start": [], "done": []}
            # UNITEK takes no per-move speed (an NDrive parameter); the CA face then ignores VELO too.
            speed = {} if kind in NO_VELOCITY else {"velocity": VELO}
            here = await drive.position()
            for i in range(n + 2):
                target = round(here + (STEP if i % 2 == 0 else -STEP), 2)
                watcher.arm()
                await asyncio.sleep(0.002)
                t0 = time.monotonic()
                await drive.move_to(target, wait=True, **speed)
                t_done = time.monotonic()
                await asyncio.sleep(0.005)
                ev = watcher.disarm()
                here = target
                if i < 2 or ev["start"] is None or ev["rest"] is None:
                    continue        # two warm-up moves; a move the watcher did not see is not timed
                out["start"].append(ev["start"] - t0)
                out["done"].append(t_done - ev["rest"])
                await asyncio.sleep(0.01)
            watcher.alive = False
            return out
        finally:
            await bench.aclose()

    return asyncio.run(main())


# -- the CA side: a pyepics client against the served twin -----------------------------------

def over_ca(kind: str, n: int, port: int) -> dict[str, list[float]]:
    env = dict(os.environ, **ca_env(port))
    child = subprocess.Popen([sys.executable, __file__, "--serve", kind, "--port", str(port)], env=env,
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        ready = json.loads(child.stdout.readline())
        assert ready.get("ready"), ready
        os.environ.update(ca_env(port))          # before libca loads
        import epicscorelibs.path.pyepics  # noqa: F401
        import epics

        def ask(cmd: str) -> dict:
            child.stdin.write(cmd + "\n")
            child.stdin.flush()
            return json.loads(child.stdout.readline())

        name = f"{PREFIX}{kind}"
        val = epics.PV(name, auto_monitor=False)
        dmov_seen: list[tuple[float, int]] = []
        dmov = epics.PV(name + ".DMOV", auto_monitor=True,
                        callback=lambda value=None, **kw: dmov_seen.append((time.monotonic(), int(value))))
        rbv = epics.PV(name + ".RBV")
        for p in (val, dmov, rbv):
            if not p.wait_for_connection(10):
                raise SystemExit(f"{p.pvname}: no connection on 127.0.0.1:{port}")
        epics.caput(name + ".VELO", VELO, wait=True)      # the face moves with velocity=VELO, as the reference
        out: dict[str, list[float]] = {"start": [], "dmov": [], "complete": []}
        here = rbv.get()
        for i in range(n + 2):
            target = round(here + (STEP if i % 2 == 0 else -STEP), 2)
            ask("arm")
            time.sleep(0.002)
            dmov_seen.clear()
            done = threading.Event()
            t_complete: list[float] = []

            def completed(**kw: Any) -> None:
                t_complete.append(time.monotonic())
                done.set()

            t0 = time.monotonic()
            val.put(target, use_complete=True, callback=completed)
            if not done.wait(10):
                raise SystemExit(f"{name}: the put to {target} did not complete in 10 s")
            time.sleep(0.01)
            ev = ask("disarm")
            here = target
            ones = [t for t, v in dmov_seen if v == 1]
            zeros = [t for t, v in dmov_seen if v == 0]
            if i < 2 or ev["start"] is None or ev["rest"] is None or not zeros or not ones:
                continue
            out["start"].append(ev["start"] - t0)
            out["dmov"].append(ones[-1] - ev["rest"])
            out["complete"].append(t_complete[0] - ev["rest"])
            time.sleep(0.01)
        return out
    finally:
        try:
            child.stdin.write("quit\n")
            child.stdin.flush()
            child.wait(10)
        except Exception:
            child.kill()
            child.wait()


def ms(values: list[float]) -> str:
    if not values:
        return "     n/a"
    return f"{statistics.median(values) * 1e3:7.2f}"


def p90(values: list[float]) -> str:
    if not values:
        return "n/a"
    v = sorted(values)
    return f"{v[min(len(v) - 1, int(len(v) * 0.9))] * 1e3:.2f}"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=30)
    ap.add_argument("--kinds", default="cia402,arcus")
    ap.add_argument("--serve", help=argparse.SUPPRESS)
    ap.add_argument("--port", type=int, default=PORT)
    ap.add_argument("--json", action="store_true", help="one JSON line per kind as well")
    args = ap.parse_args()
    if args.serve:
        serve(args.serve, args.port)
        return
    print(f"CA put -> motion start and rest -> DMOV=1, against motorbus.aio in-process; ms, median (p90), n={args.n}")
    for kind in args.kinds.split(","):
        ref = reference(kind, args.n)
        ca = over_ca(kind, args.n, args.port)
        d_start = statistics.median(ca["start"]) - statistics.median(ref["start"]) if ca["start"] else float("nan")
        d_done = statistics.median(ca["dmov"]) - statistics.median(ref["done"]) if ca["dmov"] else float("nan")
        print(f"{kind:14s} start : aio {ms(ref['start'])} ({p90(ref['start'])})  CA put {ms(ca['start'])} "
              f"({p90(ca['start'])})  CA - aio {d_start * 1e3:+.2f} ms")
        print(f"{kind:14s} done  : aio {ms(ref['done'])} ({p90(ref['done'])})  CA DMOV=1 {ms(ca['dmov'])} "
              f"({p90(ca['dmov'])})  CA - aio {d_done * 1e3:+.2f} ms;  put completion {ms(ca['complete'])} "
              f"({p90(ca['complete'])})")
        if args.json:
            print(json.dumps({"bench": "epics_latency", "kind": kind, "n": args.n,
                              "aio_start_ms": statistics.median(ref["start"]) * 1e3,
                              "ca_start_ms": statistics.median(ca["start"]) * 1e3 if ca["start"] else None,
                              "aio_done_ms": statistics.median(ref["done"]) * 1e3,
                              "ca_dmov_ms": statistics.median(ca["dmov"]) * 1e3 if ca["dmov"] else None,
                              "ca_complete_ms": statistics.median(ca["complete"]) * 1e3 if ca["complete"] else None}))


if __name__ == "__main__":
    main()

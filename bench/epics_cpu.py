"""CPU of the CA face serving 64 simulated axes to 10 monitoring clients.

The service runs as under ``motorbus serve --sim``: a child process (this script with
``--serve``) holding a 64-axis simulated twin (16 CiA 402, 12 ARCUS CANopen and 12 PMC007
drives on three virtual CAN buses, 8 UNITEK on a fourth, 8 DMAC and 8 ARCUS on two
RS-485 lines) and the CA face on 127.0.0.1.  Its CPU is read from /proc/<pid>/stat
(utime + stime) over each phase and shown as a share of one core (CPU time / wall time):

1. at rest: nobody connected; then 10 client processes each monitoring RBV, DMOV, MOVN,
   MSTA, VAL and SEVR of every axis (3 840 subscriptions); then 10 client processes each
   reading RBV and DMOV of every axis ten times a second (``caget_many``: 12 800 reads/s);
2. moving: one mover client (this process, pyepics) keeps 16 of the axes (every 4th, all
   kinds) moving, 2 mm back and forth at 10 mm/s, the next put when DMOV=1 arrives; alone,
   then with the 10 monitoring clients, then with the 10 polling clients.  (All 64 moving
   at once keep the simulators alone busy for a full core of the 2-core VM.)

The 10 clients are separate processes at nice 10 (on a 2-core VM they compete with the
service for the cores; the "late rounds" of the pollers show when they lose).  The
simulators live in the service process (``--sim``), so every phase includes their
CPU, and the clients' cost is what they add to the phase without clients.  For scale, it
first runs the same twin with no CA face at all (``--serve --no-face``), at rest and with
the same moves issued in-process through motorbus.aio.  The service's stderr goes to
``--log``; the count of tracebacks in it is printed.

    .venv/bin/python bench/epics_cpu.py [--seconds 10]
"""
from __future__ import annotations

import argparse
import asyncio
import json
import os
import subprocess
import sys
import threading
import time
from typing import Any

SCALE = 0.01
PORT = 24080
PREFIX = "MBCPU:"
STEP = 2.0            # mm per move
VELO = 10.0           # mm/s: a move takes ~0.2 s, so every axis is moving most of the time
CLIENTS = 10
MOVING_EVERY = 4      # the moving phases move every 4th axis (16 of 64, each kind): all 64 moving
                      # at once keep the simulators alone busy for a core of this 2-core VM
RATE = 10.0           # Hz, the pollers

PROFILES = {
    "cia402": {"0x6081": 20000, "0x6083": 400000, "0x6084": 400000},
    "arcus": {"HSPD": 20000, "LSPD": 2000, "ACC": 20},
    "dmac": {},
    "pmc007": {"maximum_speed": 20000},
    "unitek": {"ACC_RAMP": 20},
    "arcus-canopen": {"0x6081": 20000, "0x6083": 20, "0x6084": 20},
}
# kind -> (link, addresses)
LAYOUT = {
    "cia402": ("can1", [str(n) for n in range(1, 17)]),
    "arcus-canopen": ("can2", [str(n) for n in range(1, 13)]),
    "pmc007": ("can3", [str(n) for n in range(1, 13)]),
    "unitek": ("can4", [hex(0x201 + n) for n in range(8)]),
    "dmac": ("rs485a", [f"{n:02d}" for n in range(8)]),
    "arcus": ("rs485b", [f"{n:02d}" for n in range(1, 9)]),
}


def ca_env(port: int) -> dict[str, str]:
    return {"EPICS_CA_SERVER_PORT": str(port), "EPICS_CA_REPEATER_PORT": str(port + 1),
            "EPICS_CA_AUTO_ADDR_LIST": "NO", "EPICS_CA_ADDR_LIST": "127.0.0.1",
            "EPICS_CAS_INTF_ADDR_LIST": "127.0.0.1", "EPICS_CAS_AUTO_BEACON_ADDR_LIST": "NO",
            "EPICS_CAS_BEACON_ADDR_LIST": "127.0.0.1", "EPICS_CAS_BEACON_PORT": str(port + 1),
            "EPICS_CA_MAX_ARRAY_BYTES": "16384"}


def bench_data() -> dict:
    data: dict = {"line": {}, "bus": {}, "axis": {}}
    for kind, (link, addresses) in LAYOUT.items():
        serial = link.startswith("rs485")
        if serial:
            data["line"][link] = {"port": f"/dev/null-{link}"}
        else:
            data["bus"][link] = {"spec": f"virtual:epics-cpu-{link}"}
        for i, address in enumerate(addresses):
            name = f"{kind.replace('-', '')}{i}"
            data["axis"][name] = {"kind": kind, "address": address, "units": {"name": "mm", "scale": SCALE},
                                  "params": dict(PROFILES[kind]), ("line" if serial else "bus"): link}
    assert len(data["axis"]) == 64, len(data["axis"])
    return data


def cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


# -- the service (child process) --------------------------------------------------------------

def serve(port: int, face_on: bool) -> None:
    """The 64-axis twin, served over CA (or, --no-face, moved in-process through
    motorbus.aio the way the mover moves it over CA).  Runs until stdin closes."""
    from motorbus import aio

    loop = asyncio.new_event_loop()
    threading.Thread(target=loop.run_forever, name="service", daemon=True).start()

    def run(coro: Any, timeout: float = 120) -> Any:
        return asyncio.run_coroutine_threadsafe(coro, loop).result(timeout)

    async def open_() -> tuple[Any, Any]:
        bench = await aio.Bench.from_dict(bench_data(), sim=True)
        await asyncio.gather(*(d.clear_faults() for d in bench.axes.values()))
        await asyncio.gather(*(d.enable() for d in bench.axes.values()))
        face = None
        if face_on:
            from motorbus.serve.epics import start_ca

            face = await start_ca(bench, prefix=PREFIX, interfaces=("127.0.0.1",), port=port)
        return bench, face

    bench, face = run(open_())
    mover: list = []

    async def move_forever(name: str) -> None:
        drive = bench[name]
        here = await drive.position()
        sign = 1
        while True:
            here = round(here + sign * STEP, 2)
            sign = -sign
            await drive.move_to(here, velocity=VELO, wait=True)

    print(json.dumps({"ready": True, "pid": os.getpid(), "axes": len(bench)}), flush=True)
    for line in sys.stdin:
        cmd = line.strip()
        if cmd == "move" and not face_on:
            mover = [asyncio.run_coroutine_threadsafe(move_forever(n), loop) for n in list(bench.axes)[::MOVING_EVERY]]
            print(json.dumps({"moving": True}), flush=True)
        elif cmd == "quit":
            break
    for f in mover:
        f.cancel()
    if face is not None:
        run(face.close())
    run(bench.stop_all())
    run(bench.aclose())


# -- the clients ------------------------------------------------------------------------------

def names(data: dict) -> list[str]:
    return [f"{PREFIX}{n}" for n in data["axis"]]


def client(mode: str, seconds: float) -> None:
    """One monitoring client (a child process): subscriptions, or reads at RATE."""
    import epicscorelibs.path.pyepics  # noqa: F401
    import epics

    records = names(bench_data())
    events = [0]
    if mode == "monitor":
        def count(**kw: Any) -> None:
            events[0] += 1
        pvs = [epics.PV(f"{r}.{f}", auto_monitor=True, callback=count)
               for r in records for f in ("RBV", "DMOV", "MOVN", "MSTA", "VAL", "SEVR")]
        for p in pvs:
            p.wait_for_connection(10)
        print(json.dumps({"connected": len(pvs)}), flush=True)
        time.sleep(seconds)
    else:
        wanted = [f"{r}.{f}" for r in records for f in ("RBV", "DMOV")]
        epics.caget_many(wanted, timeout=10)
        print(json.dumps({"connected": len(wanted)}), flush=True)
        period = 1.0 / RATE
        t_next = time.monotonic()
        end = t_next + seconds
        late = 0
        while time.monotonic() < end:
            values = epics.caget_many(wanted, timeout=5)
            events[0] += sum(v is not None for v in values)
            t_next += period
            delay = t_next - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                late += 1
        print(json.dumps({"late": late}), flush=True)
    print(json.dumps({"events": events[0]}), flush=True)


class Mover:
    """Keeps every axis moving over CA: STEP back and forth at VELO, the next put on DMOV=1."""

    def __init__(self, records: list[str]) -> None:
        import epics

        self.epics = epics
        self.records = records
        self.puts = 0
        self.alive = True
        self.val = {r: epics.PV(r + ".VAL", auto_monitor=False) for r in records}
        self.dmov = {r: epics.PV(r + ".DMOV", auto_monitor=True) for r in records}
        for r in records:
            self.val[r].wait_for_connection(10)
            self.dmov[r].wait_for_connection(10)
            epics.caput(r + ".VELO", VELO, wait=True)
        self.target = {r: epics.caget(r + ".RBV") for r in records}
        self.sign = {r: 1 for r in records}
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while self.alive:
            for r in self.records:
                if self.dmov[r].get(use_monitor=True) == 1:
                    self.target[r] = round(self.target[r] + self.sign[r] * STEP, 2)
                    self.sign[r] = -self.sign[r]
                    self.val[r].put(self.target[r], wait=False)
                    self.puts += 1
            time.sleep(0.02)

    def stop(self) -> None:
        self.alive = False
        self.thread.join(5)


def spawn(args: list[str], env: dict, stderr: Any = None, nice: int = 0) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, __file__, *args], env=env, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=stderr, text=True,
                            preexec_fn=(lambda: os.nice(nice)) if nice else None)


def measure(pid: int, seconds: float) -> float:
    c0, t0 = cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    return (cpu_seconds(pid) - c0) / (time.monotonic() - t0)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--port", type=int, default=PORT)
    ap.add_argument("--log", default="/tmp/motorbus-epics-cpu-service.log", help="the service's stderr")
    ap.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--no-face", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--client", choices=("monitor", "poll"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.serve:
        serve(args.port, not args.no_face)
        return
    if args.client:
        client(args.client, args.seconds)
        return
    env = dict(os.environ, **ca_env(args.port))
    os.environ.update(ca_env(args.port))      # before libca loads (the mover)
    results: dict[str, float] = {}
    notes: dict[str, str] = {}
    print(f"service CPU (CPU time / wall, share of one core), 64 simulated axes, {args.seconds:.0f} s per phase")

    # Phase 0: the reference, no CA face: the same twin moved in-process through motorbus.aio.
    ref = spawn(["--serve", "--no-face"], env)
    try:
        ready = json.loads(ref.stdout.readline())
        time.sleep(1.0)
        results["no face, idle"] = measure(ready["pid"], args.seconds)
        ref.stdin.write("move\n")
        ref.stdin.flush()
        ref.stdout.readline()
        time.sleep(1.0)
        results["no face, 16 moving (aio in-process)"] = measure(ready["pid"], args.seconds)
    finally:
        ref.stdin.close()
        ref.wait(30)

    log = open(args.log, "w")
    service = spawn(["--serve", "--port", str(args.port)], env, stderr=log)
    mover = None
    try:
        ready = json.loads(service.stdout.readline())
        pid = ready["pid"]
        time.sleep(1.0)
        results["CA face, at rest, no client"] = measure(pid, args.seconds)
        import epicscorelibs.path.pyepics  # noqa: F401
        import epics  # noqa: F401

        def with_clients(mode: str, label: str) -> None:
            # The clients run at nice 10: on this 2-core VM they would otherwise take the cores
            # the service needs, and its CPU share would show the contention, not its demand.
            clients = [spawn(["--client", mode, "--seconds", str(args.seconds + 4)], env, nice=10)
                       for _ in range(CLIENTS)]
            try:
                for c in clients:
                    json.loads(c.stdout.readline())          # connected
                time.sleep(1.0)
                puts0 = mover.puts if mover is not None else 0
                results[label] = measure(pid, args.seconds)
                moved = f", {(mover.puts - puts0) / args.seconds:.0f} moves/s" if mover is not None else ""
                tails = [c.communicate(timeout=60)[0] for c in clients]
            finally:
                for c in clients:
                    if c.poll() is None:
                        c.kill()
            events = sum(json.loads(t.strip().splitlines()[-1])["events"] for t in tails)
            late = [json.loads(line)["late"] for t in tails for line in t.strip().splitlines() if '"late"' in line]
            notes[label] = f"{events / args.seconds:.0f} updates or values/s received" + (
                f", {sum(late)} of {CLIENTS * int(args.seconds * RATE)} rounds late" if late else "") + moved

        with_clients("monitor", "CA face, at rest, 10 monitoring clients")
        with_clients("poll", "CA face, at rest, 10 clients polling at 10 Hz")
        mover = Mover(names(bench_data())[::MOVING_EVERY])
        time.sleep(1.0)
        puts0 = mover.puts
        results["CA face, 16 moving (1 mover client)"] = measure(pid, args.seconds)
        notes["CA face, 16 moving (1 mover client)"] = f"{(mover.puts - puts0) / args.seconds:.0f} moves/s over CA"
        with_clients("monitor", "CA face, 16 moving, 10 monitoring clients")
        with_clients("poll", "CA face, 16 moving, 10 clients polling at 10 Hz")
        mover.stop()
        time.sleep(1.0)            # the last moves end before the service closes
    finally:
        if mover is not None:
            mover.stop()
        service.stdin.close()
        service.wait(30)
        log.close()
    for label, share in results.items():
        print(f"{label:48s} {share * 100:6.1f} % of a core" + (f"   ({notes[label]})" if label in notes else ""))
    with open(args.log) as f:
        errors = sum(1 for line in f if line.startswith("Traceback"))
    print(f"service stderr: {errors} tracebacks ({args.log})")
    print(json.dumps({"bench": "epics_cpu", "seconds": args.seconds,
                      **{k: round(v * 100, 2) for k, v in results.items()}}))


if __name__ == "__main__":
    main()

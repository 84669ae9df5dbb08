"""13: one bench, many programs (motorbus serve): a served simulated bench, moved by
one program while another watches it and a third stops it.

    python examples/13_served_bench.py

`motorbus serve BENCH --sim` owns the bench (here its simulated twin) and serves it;
every other program goes through it: `motorbus.Bench.connect(BENCH)` in Python, and
`motorbus status/move/stop/monitor BENCH` on the command line find it by the lock file
next to the bench file.  A stop from any of them stops the axis at once, and the move
it cuts short ends as the Drive API says (MoveInterrupted).  docs/serve.md.
"""
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np

import motorbus
from motorbus.serve import find_service

BENCH = """\
[line.rs485]
port = "/dev/ttyUSB0"            # the twin puts a pty here

[bus.can0]
spec = "socketcan:can0"          # the twin puts a served virtual bus here

[axis.x]
kind = "arcus"
line = "rs485"
address = "01"
units = { name = "mm", scale = 0.01 }
params = { HSPD = 20000, ACC = 20 }

[axis.z]
kind = "cia402"
bus = "can0"
address = 5
units = { name = "mm", scale = 0.01 }
params = { "0x6081" = 20000, "0x6083" = 400000, "0x6084" = 400000 }
"""


def motorbus_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "motorbus", *args], capture_output=True, text=True, timeout=60)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        bench_file = os.path.join(tmp, "bench.toml")
        with open(bench_file, "w") as f:
            f.write(BENCH)

        # The owner: `motorbus serve` (no EPICS here: --no-epics needs no caproto).
        service = subprocess.Popen([sys.executable, "-m", "motorbus", "serve", bench_file, "--sim", "--no-epics"],
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        try:
            for line in service.stdout:
                if line.startswith("ready"):
                    break
            info = find_service(bench_file)
            print(f"found the service: {info.pid == service.pid}, simulated twin: {info.sim}")
            print(motorbus_cli("config", "apply", bench_file).stdout.splitlines()[-1])

            # Program 1 (this one): moves both axes through the service.
            with motorbus.Bench.connect(bench_file) as bench:
                for d in bench.axes.values():
                    if not d.status.enabled:
                        d.enable()
                bench.move_together({"x": 5.0, "z": 5.0})
                print(f"x at {bench['x'].position:.2f} mm, z at {bench['z'].position:.2f} mm")

                # Program 2 watches (a shared poll of the service, at 200 Hz) while program 3,
                # `motorbus stop`, stops z in the middle of a long move.
                watched = []
                with bench.poll(["z"], ("position",), rate_hz=200) as poller:
                    mover = threading.Thread(target=lambda: watched.append(_long_move(bench["z"])))
                    mover.start()
                    while bench["z"].position < 20:
                        time.sleep(0.01)
                    print(motorbus_cli("stop", bench_file, "z").stdout.strip())
                    mover.join()
                    rows = poller.frame()["z.position"]
                print(f"z's move: {watched[0]}")
                print(f"z at rest short of 900 mm: {not bench['z'].status.moving and bench['z'].position < 900}")
                # (NaN: a missed deadline, or one before the first value arrived: docs/poller.md)
                print(f"the watcher saw z pass 20 mm: {bool(np.nanmax(rows) > 20)}")

            # `motorbus terminal` needs the transports: refused while the service runs.
            r = motorbus_cli("terminal", bench_file, "x")
            print(f"terminal: exit code {r.returncode} ({'served by motorbus serve' in r.stderr})")
        finally:
            service.send_signal(signal.SIGTERM)   # stops every axis, then ends the service
            print(f"service ended with exit code {service.wait(timeout=30)}")


def _long_move(z: "motorbus.Drive") -> str:
    try:
        z.move_to(900.0)          # 4.5 s at 200 mm/s
        return "reached 900 mm"
    except motorbus.MoveInterrupted as e:
        return f"interrupted ({type(e).__name__})"


if __name__ == "__main__":
    main()

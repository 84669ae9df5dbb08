"""10: a bluesky scan of a simulated bench axis through motorbus.ophyd.

An Arcus DMX-CAN on its serial line (a pty) and a CiA 402 drive on a CAN bus
served over socketcand on 127.0.0.1, opened as a bench; each axis becomes an
ophyd-async motor, and a real bluesky RunEngine scans x while reading z.  Every
drive call is awaited on the RunEngine's own event loop through the axis's
motorbus.aio twin (no executor thread; docs/bluesky.md says how).

    pip install "motorbus[bluesky]"
    python examples/10_bluesky_scan.py
"""
import bluesky.plan_stubs as bps
from bluesky import RunEngine
from bluesky.plans import scan
from ophyd_async.plan_stubs import ensure_connected

from motorbus import Bench
from motorbus.ophyd import devices_from_bench

BENCH = {
    "line": {"rs485": {"port": "/dev/ttyUSB0"}},          # sim=True serves a pty instead
    "bus": {"can0": {"spec": "socketcan:can0"}},          # ... and socketcand on 127.0.0.1
    "axis": {
        "x": {"kind": "arcus", "line": "rs485", "address": "01", "units": {"name": "mm", "scale": 0.01},
              "params": {"HSPD": 20000, "ACC": 20}},
        "z": {"kind": "cia402", "bus": "can0", "address": 5, "units": {"name": "mm", "scale": 0.01},
              "params": {"0x6081": 20000, "0x6083": 400000, "0x6084": 400000}},
    },
}


def show(name, doc):
    if name == "event":
        print(f"event {doc['seq_num']}: x={doc['data']['x']:.2f} z={doc['data']['z']:.2f}")
    elif name == "stop":
        print("run:", doc["exit_status"])


RE = RunEngine({})
with Bench.from_dict(BENCH, sim=True) as bench:
    bench.apply()                                  # the params above, through each protocol
    for drive in bench.axes.values():
        drive.enable()
    motors = devices_from_bench(bench)
    RE(ensure_connected(*motors.values()))
    RE(bps.mv(motors["z"], 2.5))
    RE(scan([motors["z"]], motors["x"], 0.0, 4.0, 5), show)
    print(f"x stands at {bench['x'].position:.2f} mm")

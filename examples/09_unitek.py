"""09: a UNITEK servo on its REGID register protocol, simulated on a virtual bus with a
simulated clock: writes (never acknowledged), a read, a cyclic register into numpy,
a position move with Tol.

    python examples/09_unitek.py
"""
import time

import numpy as np

import motorbus
from motorbus import _core
from motorbus.drives.unitek import Reg, Status, Unitek, make_sim

clock = _core.runtime.SimClock(0)


def run(ms, sim, stream=None):
    """Advance the simulated time by `ms` milliseconds, one at a time; with a stream,
    let each frame reach it before time moves on (its timestamps come from `clock`)."""
    for _ in range(ms):
        clock.advance(1_000_000)
        sim.service()
        while stream is not None and stream.count < sim.sent(stream.regid):
            time.sleep(0)                # the frame is crossing the bus on its own thread


with motorbus.open_bus("virtual:unitek-example") as sim_bus, motorbus.open_bus("virtual:unitek-example") as bus:
    sim = make_sim("0x201", clock, bus=sim_bus)
    with Unitek(bus, 0x201, clock=clock, on_error="disable") as drive:
        st = drive.status                                       # 3D 40 00 -> 40 81 01 00
        print(f"KERN_STATUS 0x{int(st):04X} ({st!r})")
        drive.write(Reg.ACC_RAMP, 1000)                          # 35 E8 03 (example 6)
        print("ACC_RAMP", drive.read(Reg.ACC_RAMP), "ms")
        stream = drive.subscribe(Reg.SPEED_IST, 10)              # 3D 30 0A
        drive.speed_rpm = 300                                   # 31 CD 0C: 10 % of N max 3000 rpm
        drive.read(Reg.KERN_STATUS)     # writes are never acknowledged: a read is the sync point
        run(200, sim, stream)
        t, num = stream.read()
        periods = np.diff(t) / 1e6
        print(f"stream 0x30: {len(t)} samples, periods {periods.min():.1f}..{periods.max():.1f} ms, lost {stream.lost}")
        print(f"speed {stream.physical(num)[-1]:.1f} rpm after 200 ms")
        drive.unsubscribe(Reg.SPEED_IST)                         # 3D 30 FF
        drive.stop()                                            # 31 00 00
        drive.read(Reg.KERN_STATUS)
        run(200, sim)
        drive.move_to_rev(1.0)                                  # 6E 00 00 01 00
        drive.read(Reg.KERN_STATUS)
        run(1000, sim)
        print(f"position {drive.position_rev:.3f} rev, Tol {bool(drive.status & Status.TOL)}")
    sim.close()

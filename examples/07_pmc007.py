"""07: a simulated CQPUSI PMC007 on a virtual bus, driven through its native client: a step
command, the status flags, an offline program uploaded, read back and run, on a simulated clock.

    python examples/07_pmc007.py
"""
import motorbus
from motorbus import _core
from motorbus.drives import pmc007

clock = _core.runtime.SimClock(0)                       # the sim's time moves only when we say so
with motorbus.open_bus("virtual:example-07") as sim_bus, motorbus.open_bus("virtual:example-07") as bus:
    sim = pmc007.make_sim(5, clock=clock, bus=sim_bus)
    drive = pmc007.Pmc007(bus, 5)

    drive.step(3200, speed=1600)                # 6003h = +1600 pps, then 6004h = 3200 steps
    print("status:", repr(drive.controller_status))
    clock.advance(2_100_000_000)
    sim.poll()
    print("position", drive.position, "busy", drive.busy)

    program = "VSET 0,1000\nDIR 0,0\nROT 0,500\nWAIT 1,0\nCNTI\nCMP 1,3\nJNE 0,2\n"
    words = drive.upload_program(program)
    print("program:", " ".join(f"{w:08X}" for w in words), "verified", drive.verify_program(program))
    drive.start_program()
    clock.advance(1_600_000_000)                # three moves of 0.5 s each
    sim.poll()
    print("after the program: position", drive.position, "counter", sim.program_counter,
          "running", sim.program_running)
    sim.close()

"""06: one Drive API over three kinds of simulated drives, each on its real link.

An Arcus DMX-CAN and a Midi DMAC on their serial lines (ptys), a CiA 402 drive
behind a socketcand server: the same script moves each of them in millimetres.

    python examples/06_drive_api.py

(The Drive API is motorbus's Python layer; the C++ side of each drive is its
native client, shown in examples 03, 04 and 05.)
"""
import motorbus
from motorbus import Units
from motorbus.sim import SimBench

print("kinds:", ", ".join(sorted(motorbus.drive_kinds())))

with SimBench(["arcus:01", "dmac:00", "cia402:5"]) as bench:
    line = {served.label.split(":")[0]: served.pty_path for served in bench.lines}
    server = bench.can.servers[0]
    drives = [
        motorbus.open_drive("arcus", line=line["arcus"], address="01", units=Units("mm", 0.01)),
        motorbus.open_drive("dmac", line=line["dmac"], address="00", units=Units("mm", 0.001)),
        motorbus.open_drive("cia402", bus=f"socketcand:{server.host}:{server.port}/can0", address=5,
                            units=Units("mm", 0.01)),
    ]
    for drive in drives:
        with drive:                      # an exception in here would stop this motor
            drive.enable()
            drive.move_to(5.0, timeout=30)
            drive.move_by(-1.5, timeout=30)
            status = drive.status
            print(f"{drive.kind}: at {drive.position:.2f} {drive.units.name}, "
                  f"enabled={status.enabled} moving={status.moving} fault={status.fault}")

"""03: an Arcus DMX-CAN simulator on a pty, driven through motorbus.Drive and its native client.

    python examples/03_arcus.py
"""
import motorbus
import motorbus._core as core
from motorbus.drives.arcus import make_sim

# The simulator answers on a pty exactly like the device (real time); the home
# switch sits 400 steps away so H+ homing is quick.
sim = make_sim("01", eo_boot=True, home=(400, 800))
with core.serial.PtyLineServer([sim], 0, None) as server:
    units = motorbus.Units("mm", 0.01)  # 100 encoder counts per mm (StepNLoop on)
    with motorbus.open_drive("arcus", line=server.slave_path, address="01", units=units) as x:
        x.params["HSPD"] = 20000        # counts/s: the manual's own names
        x.params["ACC"] = 20
        x.enable()
        x.move_to(12.5)
        print(f"position {x.position:.2f} mm, EX={x.native.encoder}")
        x.home("H-")                     # back toward the switch (the default H+ searches in +)
        print(f"homed {x.status.homed}, SLS {x.native.snl_status.name}")
        x.native.snl_tolerance = 10      # a native setting is a property
        print(f"SLT={x.params['SLT']} SLR={x.params['SLR']:.3f} ID={x.native.id}")
        print(x.status.text)

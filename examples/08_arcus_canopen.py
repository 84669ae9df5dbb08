"""Example 08: the Arcus DMX-CAN's two personas — one simulated drive, ASCII then CANopen.

A factory-fresh DMX-CAN talks RS-232.  Storing communication type CAN (ASCII CM=2,
CANopen 200Ah) and power-cycling moves it to CAN, with its stored settings.  Then the
Drive API drives it over CANopen: enable, a profile-position move, homing method 19.
"""
import tempfile

import motorbus
from motorbus.drives import arcus_canopen

with tempfile.TemporaryDirectory() as flash, motorbus.open_bus("virtual:example-08") as sim_bus:
    sim = arcus_canopen.make_sim(1, protocol="ascii", store_path=f"{flash}/dmx.store", bus=sim_bus)
    print("serial:", sim.on_line("@01CM").rstrip(b"\0").decode(), "(0 = RS-232), protocol", sim.active_protocol)
    for cmd in ("CURR=1200", "CM=2", "STORE"):
        sim.on_line(f"@01{cmd}")
    sim.power_cycle()                                  # the stored CM=2 takes effect now
    print("after store + power cycle: protocol", sim.active_protocol, "serial reply", sim.on_line("@01CM"))

    with motorbus.open_drive("arcus-canopen", bus="virtual:example-08", address=1) as axis:
        print("run current over CANopen (2004h:02):", axis.native.run_current, "mA")
        axis.params["Profile velocity"] = 20000        # counts/s (StepNLoop on)
        axis.params["0x6083"] = 20                     # ms
        axis.params["0x6084"] = 20
        axis.params["0x6099:01"] = 20000
        axis.params["0x6099:02"] = 2000
        axis.params["0x609A"] = 20
        axis.enable()
        axis.move_to(1000, timeout=5)
        print("moved to", axis.position, "counts, state", axis.native.state)
        axis.home(19, timeout=10)                      # manual 000: home input, positive
        print("homed at", axis.position, "StepNLoop", axis.native.snl_status.name)
    sim.close()

"""05: a CiA 402 drive simulated on a virtual bus (LocalNode + Cia402Device),
enabled and moved in profile position mode through ``node.cia402``.

    python examples/05_cia402.py
"""
import motorbus
from motorbus.canopen import Cia402Device, LocalNode, Network, ObjectDictionary, OpMode


class SimulatedDrive:
    """The device side: 0x6040/0x6041 through Cia402Device; a new set-point
    (controlword bit 4) in PP moves the position to 0x607A at once and sets
    target reached (statusword bit 10)."""

    def __init__(self, bus, node_id):
        self.dev = Cia402Device()
        self.od = od = ObjectDictionary()
        od.add_variable(0x6040, "Controlword", "u16", "rw")
        od.add_variable(0x6041, "Statusword", "u16", "ro")
        od.add_variable(0x6060, "Modes of operation", "i8", "rw")
        od.add_variable(0x6061, "Modes of operation display", "i8", "ro")
        od.add_variable(0x6064, "Position actual value", "i32", "ro")
        od.add_variable(0x607A, "Target position", "i32", "rw")
        od[0x6040].set_write_hook(lambda var, data: self.controlword(int.from_bytes(data, "little")))
        od[0x6060].set_write_hook(lambda var, data: self.dev.set_mode(int.from_bytes(data, "little", signed=True)) or None)
        # Reads come live from the state machine.
        od[0x6041].set_read_hook(lambda var, cur: self.dev.statusword.to_bytes(2, "little"))
        od[0x6061].set_read_hook(lambda var, cur: (self.dev.mode & 0xFF).to_bytes(1, "little"))
        self.node = LocalNode(bus, node_id, od)

    def controlword(self, cw):
        new_setpoint = cw & 0x10 and self.dev.state == "OPERATION ENABLED" and self.dev.mode == OpMode.PROFILE_POSITION
        self.dev.on_controlword(cw)
        if new_setpoint:
            self.od[0x6064].value = self.od[0x607A].value
            self.dev.set_status_bits(0x0400, 0x0400)


with motorbus.open_bus("virtual:cia402-example") as device_bus:
    sim = SimulatedDrive(device_bus, 5)
    with Network("virtual:cia402-example") as network:
        node = network.add_node(5, sim.od)
        with node.cia402 as drive:               # an exception in here quick-stops the drive
            drive.set_mode(OpMode.PROFILE_POSITION)
            drive.enable()                       # 2, 3, 4: shutdown, switch on, enable operation
            print("state:", drive.state)
            drive.move_to(10_000)                # new set-point / acknowledge handshake
            drive.wait_target_reached(timeout=2.0)
            print("position:", node.sdo["Position actual value"].raw)
            drive.disable()
            print("state:", drive.state)
    sim.node.close()

"""02: SDO by index and by name: a node served by LocalNode on a virtual bus,
read and written through the Network facade.

    python examples/02_sdo.py
"""
from motorbus.canopen import LocalNode, Network, ObjectDictionary, SdoAbortError
import motorbus

od = ObjectDictionary()
od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "ro", default="example drive")
od.add_record(0x1018, "Identity object")
od.add_member(0x1018, 1, "Vendor-ID", "u32", "ro", default=0x12E)
od.add_variable(0x2000, "Offset", "i16", "rw", default=-5)
od.add_variable(0x2003, "Baud index", "u8", "rw", low=0, high=8, default=4)

with motorbus.open_bus("virtual:sdo-example") as device_bus, LocalNode(device_bus, 5, od):
    with Network("virtual:sdo-example") as network:
        node = network.add_node(5, od)           # an EDS path works too
        print("name:", node.sdo["Manufacturer device name"].value)
        print("vendor:", hex(node.sdo[0x1018][1].raw))
        node.sdo["Offset"].raw = -300
        print("offset:", node.sdo["Offset"].raw, "served:", od[0x2000].value)
        try:
            node.sdo["Baud index"].raw = 9       # above the object's high limit
        except SdoAbortError as e:
            print(f"refused: {e.code:#010x} {e.text}")
        print("client:", node.sdo.client.counters)

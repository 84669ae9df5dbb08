"""SDO expedited reads/s from the canopen package's client: against the simulated PMC007
(motorbus C++ sim behind the python-can bridge) and against canopen's own LocalNode, in the
same run, on python-can's `virtual` interface; ratio printed.

    python bench/pmc007_sdo.py [--seconds 3]

Both servers answer the same request (an expedited upload of a 1-byte object) to the same
client code, so the ratio is the servers' cost seen through canopen's client (the client and
python-can's virtual bus dominate both sides).
"""
from __future__ import annotations

import argparse

from helpers.timing import rate  # bench/helpers: shared by the benchmarks



def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    a = ap.parse_args()

    import can
    import canopen

    import motorbus
    from motorbus.drives import pmc007

    # 1. canopen's client -> the PMC007 sim (C++), through motorbus's python-can bridge.
    pc = can.Bus(interface="virtual", channel="bench-pmc007-sdo")
    bus = motorbus.open_bus(pc)
    sim = pmc007.make_sim(5, bus=bus)
    net = canopen.Network()
    net.connect(interface="virtual", channel="bench-pmc007-sdo")
    remote = net.add_node(5, pmc007.EDS_PATH)
    assert remote.sdo.upload(0x6006, 0) == (400).to_bytes(2, "little")
    ours = rate(lambda: remote.sdo.upload(0x6005, 0), a.seconds)
    net.disconnect()
    sim.close()
    bus.close()

    # 2. canopen's client -> canopen's LocalNode with the same EDS.
    server, client = canopen.Network(), canopen.Network()
    server.connect(interface="virtual", channel="bench-pmc007-ref")
    client.connect(interface="virtual", channel="bench-pmc007-ref")
    local = canopen.LocalNode(5, pmc007.EDS_PATH)
    server.add_node(local)
    remote = client.add_node(5, pmc007.EDS_PATH)
    ref = rate(lambda: remote.sdo.upload(0x6005, 0), a.seconds)
    client.disconnect()
    server.disconnect()

    print(f"canopen client -> motorbus PMC007 sim : {ours[0]:9.0f} reads/s  median {ours[1]:6.1f} us  p99 {ours[2]:6.1f} us")
    print(f"canopen client -> canopen LocalNode   : {ref[0]:9.0f} reads/s  median {ref[1]:6.1f} us  p99 {ref[2]:6.1f} us")
    print(f"ratio (sim / canopen LocalNode)        : {ours[0] / ref[0]:.2f}x")


if __name__ == "__main__":
    main()

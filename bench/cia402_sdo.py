"""SDO expedited reads/s from the canopen package's client: against the generic C++ CiA 402
simulator and against canopen's own LocalNode with the same dictionary (the EDS the
simulator exports), in the same run; ratio printed.  Two transports, each the same for both
servers:

* ``virtual`` (as bench/pmc007_sdo.py): python-can's `virtual` interface; the simulator sits
  behind motorbus's python-can bridge (a Python reader thread), the LocalNode behind its
  Network's notifier thread.
* ``motorbus``: python-can's ``motorbus`` interface (``can.Bus(interface="motorbus",
  channel="virtual:…")``, motorbus's C++ virtual hub behind python-can's API); the simulator
  is another endpoint of the client's hub (no Python on its side), the LocalNode's Network
  opens the same interface on a hub of its own.
* ``socketcand``: the client talks socketcand (python-can's interface) to a motorbus
  SocketcandServer on 127.0.0.1; the simulator is on the served bus itself (no Python on its
  side), the LocalNode reaches its own server through python-can's socketcand interface too
  (a Python program serving a node has no other way onto a served bus).

    python bench/cia402_sdo.py [--seconds 3] [--object 0x6041] [--transport all] [--rounds 6]

Both servers answer the same request (an expedited upload of 6041h, the statusword a master
polls; --object picks another, e.g. 0x6081 a plain setting) to the same client code.  The
simulator's statusword is computed when read (the motion is evaluated); the LocalNode's is
a stored value.  Both servers run side by side and are measured in alternating rounds
(seconds / rounds each), so a change of the machine's load touches both alike.  "CPU" is this
process's CPU time (every thread: client, server, bridge) per read.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time
from typing import Callable

from helpers.timing import rate  # bench/helpers: shared by the benchmarks


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0, help="per server and transport")
    ap.add_argument("--object", type=lambda s: int(s, 0), default=0x6041)
    ap.add_argument("--transport", choices=("virtual", "motorbus", "socketcand", "all"), default="all")
    ap.add_argument("--rounds", type=int, default=6)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for transport in ("virtual", "motorbus", "socketcand") if a.transport == "all" else (a.transport,):
            {"virtual": virtual, "motorbus": motorbus_interface, "socketcand": socketcand}[transport](
                a, os.path.join(tmp, "cia402.eds"))


def alternate(a: argparse.Namespace, ours: Callable[[], object], ref: Callable[[], object]) -> tuple:
    """(reads/s, median us, p99 us, CPU us per read of this whole process) of each, over
    rounds taken in turn."""
    assert len(ours()) == len(ref())  # same object, same size, both answering
    runs: dict[str, list] = {"ours": [], "ref": []}

    def measured(fn: Callable[[], object]) -> tuple:
        cpu0 = time.process_time()
        r = rate(fn, a.seconds / a.rounds)
        cpu = time.process_time() - cpu0
        return (*r, cpu / (r[0] * a.seconds / a.rounds) * 1e6)
    for _ in range(a.rounds):
        runs["ours"].append(measured(ours))
        runs["ref"].append(measured(ref))

    def total(rs: list) -> tuple:
        # reads/s over all rounds (each round's rate weighs the same time), medians of the rounds
        return (statistics.fmean(r[0] for r in rs), statistics.median(r[1] for r in rs),
                statistics.median(r[2] for r in rs), statistics.median(r[3] for r in rs))
    return total(runs["ours"]), total(runs["ref"])


def report(transport: str, index: int, ours: tuple, ref: tuple) -> None:
    print(f"[{transport}] canopen client -> motorbus cia402 sim : {ours[0]:9.0f} reads/s  median {ours[1]:6.1f} us  "
          f"p99 {ours[2]:6.1f} us  CPU {ours[3]:5.1f} us/read")
    print(f"[{transport}] canopen client -> canopen LocalNode   : {ref[0]:9.0f} reads/s  median {ref[1]:6.1f} us  "
          f"p99 {ref[2]:6.1f} us  CPU {ref[3]:5.1f} us/read")
    print(f"[{transport}] ratio (sim / canopen LocalNode)        : {ours[0] / ref[0]:.2f}x  "
          f"(object 0x{index:04X}, load {os.getloadavg()[0]:.1f})")
    print(json.dumps({"bench": "cia402_sdo", "transport": transport, "object": f"0x{index:04X}",
                      "sim_reads_per_s": round(ours[0]), "localnode_reads_per_s": round(ref[0]),
                      "ratio": round(ours[0] / ref[0], 3),
                      "sim_cpu_us_per_read": round(ours[3], 1), "localnode_cpu_us_per_read": round(ref[3], 1)}))


def virtual(a: argparse.Namespace, eds: str) -> None:
    import can
    import canopen

    import motorbus
    from motorbus.drives import cia402

    index = a.object
    # canopen's client -> the C++ cia402 sim, through motorbus's python-can bridge.
    pc = can.Bus(interface="virtual", channel="bench-cia402-sdo")
    bus = motorbus.open_bus(pc)
    sim = cia402.make_sim(5, bus=bus)
    with open(eds, "w") as f:
        f.write(sim.od.to_eds(False))
    net = canopen.Network()
    net.connect(interface="virtual", channel="bench-cia402-sdo")
    to_sim = net.add_node(5, eds)
    # canopen's client -> canopen's LocalNode with the same EDS.
    server, client = canopen.Network(), canopen.Network()
    server.connect(interface="virtual", channel="bench-cia402-ref")
    client.connect(interface="virtual", channel="bench-cia402-ref")
    server.add_node(canopen.LocalNode(5, eds))
    to_ref = client.add_node(5, eds)
    try:
        ours, ref = alternate(a, lambda: to_sim.sdo.upload(index, 0), lambda: to_ref.sdo.upload(index, 0))
    finally:
        client.disconnect()
        server.disconnect()
        net.disconnect()
        sim.close()
        bus.close()
    report("virtual", index, ours, ref)


def motorbus_interface(a: argparse.Namespace, eds: str) -> None:
    import canopen

    import motorbus
    from motorbus.drives import cia402

    index = a.object
    nets: list = []

    def network(channel: str) -> "canopen.Network":
        net = canopen.Network()
        net.connect(interface="motorbus", channel=channel)
        nets.append(net)
        return net

    with motorbus.open_bus("virtual:bench-cia402-pycan") as node_side:
        sim = cia402.make_sim(5, bus=node_side)
        with open(eds, "w") as f:
            f.write(sim.od.to_eds(False))
        try:
            to_sim = network("virtual:bench-cia402-pycan").add_node(5, eds)
            network("virtual:bench-cia402-pycan-ref").add_node(canopen.LocalNode(5, eds))
            to_ref = network("virtual:bench-cia402-pycan-ref").add_node(5, eds)
            ours, ref = alternate(a, lambda: to_sim.sdo.upload(index, 0), lambda: to_ref.sdo.upload(index, 0))
        finally:
            for net in nets:
                net.disconnect()
            sim.close()
    report("motorbus", index, ours, ref)


def socketcand(a: argparse.Namespace, eds: str) -> None:
    import can
    import canopen

    import motorbus
    from motorbus import _core
    from motorbus.drives import cia402

    index = a.object
    nets: list = []

    def connect(server: "_core.can.SocketcandServer") -> "canopen.Network":
        net = canopen.Network(can.Bus(interface="socketcand", host=server.host, port=server.port, channel="can0"))
        net.connect = lambda *args, **kw: None  # the bus is open already
        net.notifier = can.Notifier(net.bus, net.listeners, 0.1)
        nets.append(net)
        return net

    # Two endpoints of one virtual hub: the server's and the simulator's (an endpoint does not
    # hear its own frames).  The LocalNode gets a hub and server of its own.
    with motorbus.open_bus("virtual:bench-cia402-served") as hub, \
            motorbus.open_bus("virtual:bench-cia402-served") as node_side, \
            motorbus.open_bus("virtual:bench-cia402-served-ref") as ref_hub:
        sim = cia402.make_sim(5, bus=node_side)
        with open(eds, "w") as f:
            f.write(sim.od.to_eds(False))
        with _core.can.SocketcandServer(hub, host="127.0.0.1", port=0, channel="can0") as srv, \
                _core.can.SocketcandServer(ref_hub, host="127.0.0.1", port=0, channel="can0") as ref_srv:
            try:
                to_sim = connect(srv).add_node(5, eds)
                connect(ref_srv).add_node(canopen.LocalNode(5, eds))
                to_ref = connect(ref_srv).add_node(5, eds)
                ours, ref = alternate(a, lambda: to_sim.sdo.upload(index, 0), lambda: to_ref.sdo.upload(index, 0))
            finally:
                for net in nets:
                    net.notifier.stop()
                    net.bus.shutdown()
        sim.close()
    report("socketcand", index, ours, ref)


if __name__ == "__main__":
    main()

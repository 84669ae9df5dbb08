"""A 1000-count profile-position move of the simulated DMX-CAN, commanded and confirmed
over socketcand: motorbus's Drive API vs the `canopen` package's BaseNode402 (over
python-can's `socketcand` interface), in the same run, against the same simulated drive.

* command latency: from the call to the set-point acknowledged and new set-point
  lowered (607Ah written, controlword with bit 4, statusword bit 12 seen, controlword
  without bit 4): ``drive.move_by(1000, wait=False)`` vs the same four SDO steps by hand
  on BaseNode402 (``sdo[0x607A].raw``, ``controlword``, ``statusword``);
* confirmation latency: from the end of the command to target reached seen (statusword
  bit 10): ``drive.wait_idle()`` (poll interval set to 0: it polls statusword + 606Ch)
  vs polling ``statusword`` on BaseNode402.  This contains the move itself (about 10 ms
  at 200 000 counts/s with 1 ms ramps), the same for both.

The two clients share the node's single SDO channel (0x601/0x581), so a block
ends with a 50 ms pause (not timed): canopen re-sends a request whose answer is late
under load, and the second answer must not land in the other client's transfer.

Moves alternate direction (+1000, -1000) and the two clients alternate in blocks so load
changes hit both alike.  Prints medians and the ratio (reference / motorbus).

    .venv/bin/python bench/arcus_canopen_move.py [--n 200]
"""
from __future__ import annotations

import argparse
import logging
import statistics
import time

import can
import canopen

import motorbus
from motorbus.sim import SimBench

NODE = 1


def _od() -> canopen.ObjectDictionary:
    od = canopen.ObjectDictionary()
    for index, dtype in ((0x6040, canopen.objectdictionary.UNSIGNED16), (0x6041, canopen.objectdictionary.UNSIGNED16),
                         (0x6060, canopen.objectdictionary.INTEGER8), (0x6061, canopen.objectdictionary.INTEGER8),
                         (0x6064, canopen.objectdictionary.INTEGER32), (0x607A, canopen.objectdictionary.INTEGER32),
                         (0x6502, canopen.objectdictionary.UNSIGNED32)):
        var = canopen.objectdictionary.ODVariable(f"o{index:04X}", index, 0)
        var.data_type = dtype
        var.access_type = "rw"
        od.add_object(var)
    return od


def bench_drive(drive, n: int, sign: list) -> tuple[list, list]:
    cmd, conf = [], []
    for _ in range(n):
        t0 = time.perf_counter()
        drive.move_by(1000 * sign[0], wait=False)
        t1 = time.perf_counter()
        drive.wait_idle(timeout=5)
        t2 = time.perf_counter()
        sign[0] = -sign[0]
        cmd.append(t1 - t0)
        conf.append(t2 - t1)
    return cmd, conf


def bench_canopen(node, n: int, sign: list) -> tuple[list, list]:
    cmd, conf = [], []
    for _ in range(n):
        t0 = time.perf_counter()
        node.sdo[0x607A].raw = 1000 * sign[0]
        node.controlword = 0x5F                 # new set-point, relative
        while not node.statusword & 0x1000:     # set-point acknowledge
            pass
        node.controlword = 0x4F
        t1 = time.perf_counter()
        while not node.statusword & 0x0400:     # target reached
            pass
        t2 = time.perf_counter()
        sign[0] = -sign[0]
        cmd.append(t1 - t0)
        conf.append(t2 - t1)
    return cmd, conf


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=200, help="moves per client")
    ap.add_argument("--block", type=int, default=20)
    args = ap.parse_args()
    logging.getLogger("canopen").setLevel(logging.ERROR)  # "0x6041 is not a configured TPDO" on every read
    with SimBench([f"arcus-canopen:{NODE}"], bus="virtual:arcus-canopen-bench") as bench:
        srv = bench.can.servers[0]
        drive = motorbus.open_drive("arcus-canopen", bus=f"socketcand:{srv.host}:{srv.port}/can0", address=NODE)
        drive.poll_interval = 0.0
        drive.params["0x6081"] = 200000
        drive.params["0x6082"] = 1000
        drive.params["0x6083"] = 1
        drive.params["0x6084"] = 1
        drive.enable()
        drive.move_by(0, wait=True)             # profile position mode, Operation enabled
        pbus = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        net = canopen.Network(pbus)
        net.connect = lambda *a, **k: None
        net.notifier = can.Notifier(pbus, net.listeners, 1)
        node = canopen.BaseNode402(NODE, _od())
        net.add_node(node)
        node.setup_402_state_machine(read_pdos=False)
        try:
            ours_c, ours_f, ref_c, ref_f = [], [], [], []
            sign = [1]
            done = 0
            while done < args.n:
                k = min(args.block, args.n - done)
                c, f = bench_drive(drive, k, sign)
                ours_c += c
                ours_f += f
                time.sleep(0.05)  # the clients share the node's one SDO channel: let stray replies land
                c, f = bench_canopen(node, k, sign)
                ref_c += c
                ref_f += f
                time.sleep(0.05)
                done += k
            med = lambda xs: statistics.median(xs) * 1e6  # noqa: E731
            print(f"1000-count PP move over socketcand, n={args.n} per client (medians, us)")
            print(f"  command (set-point acknowledged): motorbus Drive API {med(ours_c):9.1f}   "
                  f"canopen BaseNode402 {med(ref_c):9.1f}   ratio {med(ref_c) / med(ours_c):5.2f}x")
            print(f"  confirmation (target reached):    motorbus Drive API {med(ours_f):9.1f}   "
                  f"canopen BaseNode402 {med(ref_f):9.1f}   ratio {med(ref_f) / med(ours_f):5.2f}x")
            print(f"  whole move:                       motorbus Drive API "
                  f"{med([a + b for a, b in zip(ours_c, ours_f)]):9.1f}   canopen BaseNode402 "
                  f"{med([a + b for a, b in zip(ref_c, ref_f)]):9.1f}")
        finally:
            net.notifier.stop()
            pbus.shutdown()
            drive.close()


if __name__ == "__main__":
    main()

"""PDO pack/unpack from Python: motorbus.canopen.PdoMap vs the `canopen` package,
same mapping, same frames, same run; plus SYNC producer jitter.

    PYTHONPATH=python python3 bench/pdo.py [--sync-seconds 2] [--period-us 1000]
"""
from __future__ import annotations

import argparse
import time
import timeit

import canopen
from canopen import objectdictionary as odm
from canopen.pdo.base import PdoMap as CoPdoMap

from motorbus import _core
from motorbus.canopen.pdo import PdoMap
from motorbus.canopen.sync import SyncProducer

ENTRIES = [(0x6041, 0, 16), (0x6064, 0, 32, True), (0x6061, 0, 8, True)]
FRAME = bytes.fromhex("37061027000001")
VALUES = [0x0637, 10000, 1]


def canopen_map():
    od = canopen.ObjectDictionary()
    for index, dt in ((0x6041, odm.UNSIGNED16), (0x6064, odm.INTEGER32), (0x6061, odm.INTEGER8)):
        v = odm.ODVariable(f"v{index:x}", index, 0)
        v.data_type = dt
        od.add_object(v)
    node = canopen.RemoteNode(5, od)
    m = CoPdoMap(node.tpdo, None, None)
    m.cob_id = 0x185
    for e in ENTRIES:
        m.add_variable(e[0], e[1], e[2])
    return m


def best(fn, number=20000):
    return min(timeit.repeat(fn, number=number, repeat=5)) / number * 1e9


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sync-seconds", type=float, default=2.0)
    ap.add_argument("--period-us", type=int, default=1000)
    a = ap.parse_args()

    ours = PdoMap(ENTRIES)
    co = canopen_map()
    co_tx = canopen_map()  # a received map holds immutable bytes; encode with its own map
    assert ours.unpack(FRAME) == VALUES

    def co_decode():
        co.on_message(0x185, FRAME, 0.0)
        return [v.raw for v in co.map]

    def co_encode():
        for var, value in zip(co_tx.map, VALUES):
            var.raw = value
        return bytes(co_tx.data)

    assert co_decode() == VALUES and co_encode() == FRAME
    rows = [("unpack", best(lambda: ours.unpack(FRAME)), best(co_decode)),
            ("pack", best(lambda: ours.pack(VALUES)), best(co_encode))]
    print("PDO from Python, 7-byte frame 0x6041/0x6064/0x6061 (ns per frame, best of 5)")
    for name, m_ns, c_ns in rows:
        print(f"  {name:7s} motorbus {m_ns:8.0f}   canopen {c_ns:8.0f}   ratio {c_ns / m_ns:5.1f}x")

    name = f"bench-pdo-{time.monotonic_ns()}"
    bus, _sink = _core.can.open_virtual(name), _core.can.open_virtual(name)
    for rt in (False, True):
        s = SyncProducer(bus, a.period_us / 1e6)
        s.start(realtime=rt)
        time.sleep(a.sync_seconds)
        s.stop()
        j = s.jitter()
        label = (" SCHED_FIFO" if s.realtime_granted else " (SCHED_FIFO refused)") if rt else ""
        print(f"SYNC producer{label} {a.period_us} us for {a.sync_seconds} s: {j.count} periods, error "
              f"min {j.min_ns / 1e3:.1f} us mean {j.mean_ns / 1e3:.2f} us max {j.max_ns / 1e3:.1f} us "
              f"p99 |error| {j.p99_abs_ns / 1e3:.1f} us")


if __name__ == "__main__":
    main()

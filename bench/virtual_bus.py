"""Virtual bus from Python: motorbus vs python-can's virtual interface, same run.

    python bench/virtual_bus.py [N]
"""
import json
import sys
import threading
import time

import can

import motorbus


def throughput(send, recv, n):
    """Frames/s from the first send until `n` frames were received: a sender
    thread calls send() n times while this thread calls recv() (the same
    routine for both libraries, so they are measured the same way)."""
    t0 = time.perf_counter()
    th = threading.Thread(target=lambda: [send() for _ in range(n)])
    th.start()
    got = 0
    while got < n and recv() is not None:
        got += 1
    th.join()
    return got / (time.perf_counter() - t0)


def motorbus_throughput(n):
    tx, rx = motorbus.open_bus("virtual:pyb"), motorbus.open_bus("virtual:pyb")
    f = motorbus.Frame(0x123, bytes(range(8)))
    try:
        return throughput(lambda: tx.send(f), lambda: rx.recv(2.0), n)
    finally:
        tx.close(), rx.close()


def pythoncan_throughput(n):
    tx = can.Bus(interface="virtual", channel="pcb")
    rx = can.Bus(interface="virtual", channel="pcb")
    m = can.Message(arbitration_id=0x123, data=bytes(range(8)), is_extended_id=False)
    try:
        return throughput(lambda: tx.send(m), lambda: rx.recv(2.0), n)
    finally:
        tx.shutdown(), rx.shutdown()


def latency(send, recv, k=3000):
    lat = []
    for _ in range(k):
        t = time.perf_counter()
        send()
        recv()
        lat.append((time.perf_counter() - t) * 1e6)
    lat.sort()
    return lat[len(lat) // 2], lat[len(lat) * 99 // 100]


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100000
    mb = motorbus_throughput(n)
    pc = pythoncan_throughput(n)
    print(json.dumps({"bench": "virtual_py_throughput", "motorbus_fps": round(mb), "python_can_fps": round(pc),
                      "ratio": round(mb / pc, 2)}))
    a, b = motorbus.open_bus("virtual:pyl"), motorbus.open_bus("virtual:pyl")
    f = motorbus.Frame(0x1, b"\x01")
    mb_lat = latency(lambda: a.send(f), lambda: b.recv(1.0))
    a.close(), b.close()
    pa, pb = can.Bus(interface="virtual", channel="pcl"), can.Bus(interface="virtual", channel="pcl")
    m = can.Message(arbitration_id=1, data=b"\x01", is_extended_id=False)
    pc_lat = latency(lambda: pa.send(m), lambda: pb.recv(1.0))
    pa.shutdown(), pb.shutdown()
    print(json.dumps({"bench": "virtual_py_latency_us", "motorbus_median": round(mb_lat[0], 1),
                      "motorbus_p99": round(mb_lat[1], 1), "python_can_median": round(pc_lat[0], 1),
                      "python_can_p99": round(pc_lat[1], 1)}))


if __name__ == "__main__":
    main()

"""01: two endpoints on a virtual CAN bus, a subscriber, and a log.

    python examples/01_virtual_bus.py
"""
import threading

import motorbus
from motorbus import Frame

with motorbus.open_bus("virtual:example") as a, motorbus.open_bus("virtual:example") as b:
    got = threading.Event()
    b.subscribe(lambda f: (print("callback:", f), got.set()), id=0x181)  # runs on b's bus thread

    with motorbus.Recorder(b, "/tmp/motorbus-example.log"):
        a.send(Frame(0x181, b"\x01\x02\x03"))
        a.send(Frame(0x1ABCDEF0, b"\xff", extended=True))
        print("recv:", b.recv(1.0), b.recv(1.0))
        got.wait(1.0)
    print("counters:", b.counters)
    entries, bad = motorbus.read_log("/tmp/motorbus-example.log")
    print("logged:", [str(e.frame) for e in entries])

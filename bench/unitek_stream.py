"""The UNITEK client's numpy stream under a flood, against a python-can Notifier +
listener doing the same decode, in the same run, on the same frames.

    PYTHONPATH=python python3 bench/unitek_stream.py [--frames 200000]

A sender floods SPEED_IST replies (`181 [4]: 30 lo hi 00`) on a motorbus virtual bus:
motorbus's log player (C++, GIL released, speed 0 = as fast as possible) with --sender play
(default), or a Python send() loop with --sender python.
Two receivers see every frame: motorbus's Unitek client (its subscription decodes into a
C++ ring on the bus thread, no GIL) and python-can (`can.Bus(interface="motorbus")` on the
same virtual bus, a Notifier whose listener decodes the value with int.from_bytes and
stores timestamp + value).  Reported per receiver: frames kept, frames lost, and the
sustained rate (frames kept / time from the first send to the last frame processed).
"""
from __future__ import annotations

import argparse
import logging
import threading
import time

import can
import numpy as np

import motorbus
from motorbus import Frame
from motorbus.drives.unitek import Reg, Unitek

logging.getLogger("can").setLevel(logging.ERROR)


class Decode(can.Listener):
    def __init__(self, n: int) -> None:
        self.t = np.zeros(n, dtype=np.int64)
        self.v = np.zeros(n, dtype=np.int64)
        self.n = 0
        self.last = 0.0

    def on_message_received(self, msg: can.Message) -> None:
        if msg.arbitration_id != 0x181 or msg.dlc != 4 or msg.data[0] != 0x30:
            return
        if self.n < len(self.t):
            self.t[self.n] = int(msg.timestamp * 1e9)
            self.v[self.n] = int.from_bytes(msg.data[1:3], "little", signed=True)
            self.n += 1
        self.last = time.perf_counter()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=200_000)
    ap.add_argument("--sender", choices=("play", "python"), default="play")
    a = ap.parse_args()
    name = "virtual:unitek-flood"
    with motorbus.open_bus(name) as ours_bus, motorbus.open_bus(name) as flood:
        ours = Unitek(ours_bus, 0x201, timeout=1.0)
        stream = ours.subscribe(Reg.SPEED_IST, 1, capacity=a.frames + 16)  # nobody answers: the flood does
        pc_bus = can.Bus(interface="motorbus", channel=name)
        listener = Decode(a.frames)
        notifier = can.Notifier(pc_bus, [listener], timeout=0.05)
        frames = [Frame(0x181, bytes([0x30, i & 0xFF, (i >> 8) & 0x7F, 0])) for i in range(256)]
        time.sleep(0.2)
        ours_last = [0.0]
        done = threading.Event()

        def watch() -> None:  # when did our ring stop growing
            last_count = -1
            while not done.is_set():
                c = stream.count
                if c != last_count:
                    last_count, ours_last[0] = c, time.perf_counter()
                time.sleep(0.0005)

        w = threading.Thread(target=watch)
        w.start()
        entries = None
        if a.sender == "play":
            import tempfile

            from motorbus import _core
            with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as f:
                for i in range(a.frames):
                    f.write(f"(0.000000) can0 181#30{i & 0xFF:02X}{(i >> 8) & 0x7F:02X}00\n")
            entries, bad = _core.can.read_log(f.name)
            assert bad == 0 and len(entries) == a.frames
        t0 = time.perf_counter()
        if entries is not None:
            _core.can.play(flood, entries, 0.0)
        else:
            for i in range(a.frames):
                flood.send(frames[i & 0xFF])
        t_sent = time.perf_counter()
        time.sleep(2.0)  # let both drain
        done.set()
        w.join()
        notifier.stop()
        pc_bus.shutdown()
        t, v = stream.read()
        ours.close()
    send_rate = a.frames / (t_sent - t0)
    ours_rate = len(t) / max(max(ours_last[0], t_sent) - t0, 1e-9)  # never faster than the sender
    pc_rate = listener.n / max(listener.last - t0, 1e-9)
    print(f"flood: {a.frames} frames sent at {send_rate:,.0f} frames/s")
    print(f"motorbus Unitek numpy stream   kept {len(t):7d} lost {a.frames - len(t):7d}  sustained {ours_rate:12,.0f} frames/s")
    print(f"python-can Notifier + listener kept {listener.n:7d} lost {a.frames - listener.n:7d}  sustained {pc_rate:12,.0f} frames/s")
    print(f"ratio (motorbus / python-can): {ours_rate / max(pc_rate, 1):.2f}")
    assert (v[:256] == np.array([(i & 0xFF) | (((i >> 8) & 0x7F) << 8) for i in range(256)])).all()


if __name__ == "__main__":
    main()

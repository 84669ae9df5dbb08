"""SLCAN over a pty: frames/s and round-trip latency, motorbus (from Python) vs python-can.

A harness process owns the pty master and plays the wire; the library under
test (the "agent") opens the slave path as an SLCAN host and runs a tiny
protocol, so the very same harness times both libraries:

* rx:  the harness writes N data frames (id 0x200) as fast as the pty takes
       them, then a sync frame 0x201; the agent answers 0x202 with its count.
* tx:  the harness sends 0x300 with N; the agent sends N frames (0x400) as
       fast as it can; the harness times its command to the agent's last line.
* rtt: the harness sends 0x100 and waits for the agent's echo 0x101, K times.

    PYTHONPATH=python python3 bench/slcan_throughput.py [--n 20000] [--k 500]

Also used by bench/cpp/slcan_throughput.cpp as the python-can agent:
    python3 bench/slcan_throughput.py --agent pycan --path /dev/pts/N
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import statistics
import struct
import sys
import time
import tty

STOP_ID, SYNC_ID, SYNC_REPLY, TX_CMD, TX_FRAME, PING, PONG, LOAD = (
    0x7FF, 0x201, 0x202, 0x300, 0x400, 0x100, 0x101, 0x200)


# --------------------------------------------------------------------- agents --

def serve_agent(recv, send, frame, id_and_data) -> None:
    """The agent's protocol, the same for both libraries: count LOAD frames,
    answer PING and SYNC, send n frames on TX_CMD, stop on STOP (or after 30 s
    of silence).  `frame(id, data)` builds a message, `id_and_data(m)` reads one."""
    count = 0
    while True:
        m = recv(30)
        if m is None:
            return
        i, data = id_and_data(m)
        if i == LOAD:
            count += 1
        elif i == PING:
            send(frame(PONG, data))
        elif i == SYNC_ID:
            send(frame(SYNC_REPLY, struct.pack("<I", count)))
            count = 0
        elif i == TX_CMD:
            (n,) = struct.unpack("<I", bytes(data[:4]))
            out = frame(TX_FRAME, b"\x01\x02\x03\x04\x05\x06\x07\x08")
            for _ in range(n):
                send(out)
        elif i == STOP_ID:
            return


def agent_pycan(path: str) -> None:
    import can
    bus = can.Bus(interface="slcan", channel=path, bitrate=500000, sleep_after_open=0)
    try:
        serve_agent(bus.recv, bus.send,
                    lambda i, d: can.Message(arbitration_id=i, data=d, is_extended_id=False),
                    lambda m: (m.arbitration_id, m.data))
    finally:
        bus.shutdown()


def agent_motorbus(path: str) -> None:
    import motorbus
    from motorbus.slcan import open_slcan
    # The harness plays a silent wire (no acks), like a python-can peer.
    bus = open_slcan(path, 500000, wait_for_acks=False)
    try:
        serve_agent(bus.recv, bus.send, motorbus.Frame, lambda f: (f.id, f.data))
    finally:
        bus.close()


AGENTS = {"pycan": agent_pycan, "motorbus": agent_motorbus}


# -------------------------------------------------------------------- harness --

class Wire:
    """The master side of the pty: writes lines, reads and splits lines."""

    def __init__(self, fd: int) -> None:
        self.fd = fd
        self.buf = b""

    def write(self, data: bytes) -> None:
        view = memoryview(data)
        while view:
            n = os.write(self.fd, view)
            view = view[n:]

    def lines(self, timeout: float):
        import select
        end = time.monotonic() + timeout
        while True:
            while b"\r" in self.buf:
                line, _, self.buf = self.buf.partition(b"\r")
                yield line
            left = end - time.monotonic()
            if left <= 0:
                raise TimeoutError("harness: no reply")
            r, _, _ = select.select([self.fd], [], [], left)
            if r:
                self.buf += os.read(self.fd, 1 << 16)

    def wait_for(self, prefix: bytes, timeout: float = 30.0) -> bytes:
        for line in self.lines(timeout):
            if line.startswith(prefix):
                return line
        raise AssertionError("unreachable")


def frame_line(can_id: int, data: bytes) -> bytes:
    return b"t%03X%d%s\r" % (can_id, len(data), data.hex().upper().encode())


def harness(fd: int, n: int, k: int) -> dict:
    w = Wire(fd)
    # readiness: ping until the agent echoes
    for _ in range(200):
        w.write(frame_line(PING, b"\x00"))
        try:
            w.wait_for(b"t1011", timeout=0.1)
            break
        except TimeoutError:
            continue
    else:
        raise RuntimeError("agent never answered")
    time.sleep(0.1)
    w.buf = b""
    # rtt
    rtts = []
    for i in range(k):
        payload = struct.pack("<I", i)
        line = frame_line(PING, payload)
        t0 = time.perf_counter_ns()
        w.write(line)
        want = b"t1014" + payload.hex().upper().encode()
        w.wait_for(want)
        rtts.append(time.perf_counter_ns() - t0)
    # rx
    block = frame_line(LOAD, b"\x11\x22\x33\x44\x55\x66\x77\x88") * n
    t0 = time.perf_counter()
    w.write(block)
    w.write(frame_line(SYNC_ID, b""))
    reply = w.wait_for(b"t2024", timeout=120)
    rx_elapsed = time.perf_counter() - t0
    got = struct.unpack("<I", bytes.fromhex(reply[5:13].decode()))[0]
    # tx
    w.buf = b""
    t_first = time.perf_counter()  # from the command: includes the agent's reaction time
    w.write(frame_line(TX_CMD, struct.pack("<I", n)))
    # the agent sends nothing else meanwhile: count line ends in raw chunks
    import select
    seen = 0
    end = time.monotonic() + 120
    while seen < n and time.monotonic() < end:
        r, _, _ = select.select([fd], [], [], 1.0)
        if not r:
            continue
        seen += os.read(fd, 1 << 16).count(b"\r")
    tx_elapsed = time.perf_counter() - t_first
    w.write(frame_line(STOP_ID, b""))
    rtts.sort()
    return {
        "rx_fps": got / rx_elapsed, "rx_received": got, "n": n,
        "tx_fps": n / tx_elapsed,
        "rtt_median_us": statistics.median(rtts) / 1e3,
        "rtt_p99_us": rtts[min(len(rtts) - 1, int(len(rtts) * 0.99))] / 1e3,
    }


def _harness_proc(fd: int, n: int, k: int, q) -> None:
    try:
        q.put(harness(fd, n, k))
    except Exception as e:  # report, never hang the parent
        q.put({"error": repr(e)})


def run(agent: str, n: int, k: int) -> dict:
    master, slave = os.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    q = mp.get_context("fork").Queue()
    p = mp.get_context("fork").Process(target=_harness_proc, args=(master, n, k, q))
    p.start()
    try:
        AGENTS[agent](path)
    finally:
        result = q.get(timeout=180)
        p.join()
        os.close(master)
        os.close(slave)
    if "error" in result:
        raise RuntimeError(f"{agent}: {result['error']}")
    return result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--agent", choices=sorted(AGENTS))
    ap.add_argument("--path")
    ap.add_argument("--n", type=int, default=20000, help="frames per throughput phase")
    ap.add_argument("--k", type=int, default=500, help="round trips")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    if a.agent and a.path:
        AGENTS[a.agent](a.path)
        return
    import can
    results = {}
    for agent in ("pycan", "motorbus"):
        results[agent] = run(agent, a.n, a.k)
    if a.json:
        print(json.dumps(results))
        return
    ref, ours = results["pycan"], results["motorbus"]
    print(f"SLCAN over a pty, {a.n} frames per phase, {a.k} round trips (python-can {can.__version__})")
    print(f"{'':22}{'python-can':>14}{'motorbus(py)':>14}{'ratio':>9}")
    for key, label, better in (("rx_fps", "rx frames/s", "hi"), ("tx_fps", "tx frames/s", "hi"),
                               ("rtt_median_us", "rtt median (us)", "lo"), ("rtt_p99_us", "rtt p99 (us)", "lo")):
        r = ours[key] / ref[key] if better == "hi" else ref[key] / ours[key]
        print(f"{label:22}{ref[key]:>14.0f}{ours[key]:>14.0f}{r:>8.1f}x")
    print("(ratio: how many times better motorbus is; rx counts checked: "
          f"{ref['rx_received']}/{a.n} and {ours['rx_received']}/{a.n})")


if __name__ == "__main__":
    sys.exit(main())

"""``motorbus demo --tour``: the transports under the drives, one at a time, no hardware.

(``motorbus demo`` itself is the bench demo in ``bench_demo.py``: every registered drive
kind, serial and CAN, simulated and driven through the Drive API — discover, home, a
coordinated move, polling, candump logs, a plot.  The tour shows what those drives stand
on, with no drive kind in it, so it names no vendor.)

1. CAN: a virtual bus served over SLCAN (a pty) and socketcand (TCP) by
   ``motorbus bus serve``; python-can clients on both exchange frames, and a
   recorder writes the traffic as a candump log.
2. CANopen: a simulated node on a virtual bus served over socketcand, read and
   written by the SDO client (expedited, segmented, block), its dictionary
   exported as EDS.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time

from . import _core


def _title(text: str) -> None:
    print(f"\n== {text}", flush=True)


def _spawn(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "motorbus", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _served_lines(proc: subprocess.Popen, n: int) -> list[list[str]]:
    lines = []
    for _ in range(n):
        line = proc.stdout.readline()
        if not line:
            raise RuntimeError(f"server exited: {proc.stderr.read()}")
        lines.append(line.split())
    return lines


def _stop(proc: subprocess.Popen) -> None:
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(10)
    except subprocess.TimeoutExpired:
        proc.kill()


def can_bench(quick: bool, workdir: str) -> None:
    import can

    from .bus import open_bus

    _title("CAN: `motorbus bus serve virtual:demo --socketcand 127.0.0.1:0 --slcan-pty`")
    proc = _spawn("bus", "serve", "virtual:demo-served", "--socketcand", "127.0.0.1:0", "--slcan-pty")
    try:
        (_, hostport, channel), (_, pty) = _served_lines(proc, 2)
        host, port = hostport.rsplit(":", 1)
        print(f"  socketcand {hostport} channel {channel}; slcan {pty}")
        sc = can.Bus(interface="socketcand", host=host, port=int(port), channel=channel)
        sl = can.Bus(interface="slcan", channel=pty, bitrate=500000)
        try:
            time.sleep(0.2)
            n = 5 if quick else 50
            for i in range(n):
                sc.send(can.Message(arbitration_id=0x100 + i, data=bytes([i]) * 4, is_extended_id=False))
            got = []
            deadline = time.time() + 5
            while len(got) < n and time.time() < deadline:
                m = sl.recv(0.2)
                if m is not None:
                    got.append(m)
            print(f"  python-can socketcand -> python-can slcan: {len(got)}/{n} frames, "
                  f"first {got[0].arbitration_id:03X}#{bytes(got[0].data).hex().upper()}")
        finally:
            sc.shutdown()
            sl.shutdown()
    finally:
        _stop(proc)

    # In-process: a recorder on a virtual bus with wire time, and the log read back.
    log = os.path.join(workdir, "demo.log")
    with open_bus("virtual:demo", bitrate=500_000) as tx, open_bus("virtual:demo", bitrate=500_000) as rx:
        with _core.can.Recorder(rx, log) as rec:
            t0 = time.monotonic()
            for i in range(100):
                tx.send(_core.can.Frame(0x200 + (i % 8), bytes(8)))
            for _ in range(100):
                rx.recv(2.0)
            dt = time.monotonic() - t0
        print(f"  100 frames on a 500 kbit/s virtual bus took {dt * 1000:.1f} ms "
              f"(theory {100 * 135 / 500:.1f} ms); recorded {rec.count} frames to {log}")
    entries, bad = _core.can.read_log(log)
    print(f"  read back {len(entries)} frames ({bad} bad lines): {entries[0]!r} ...")


def canopen_bench(quick: bool, workdir: str) -> None:
    from . import canopen
    from .bus import open_bus

    _title("CANopen: a simulated node served over socketcand, read by the SDO client")
    od = canopen.ObjectDictionary()
    od.add_variable(0x1000, "Device type", "u32", "ro", default=0x00040192)
    od.add_variable(0x1008, "Manufacturer device name", "VISIBLE_STRING", "const", default="motorbus node (simulated)")
    od.add_record(0x1018, "Identity object")
    od.add_member(0x1018, 1, "Vendor-ID", "u32", "ro", default=0x000000AB)
    od.add_variable(0x2003, "Baud index", "u8", "rw", low=0, high=8, default=4)
    od.add_variable(0x1F50, "Program", "DOMAIN", "rw", max_size=256 * 1024)
    with open_bus("virtual:co-demo") as node_side, open_bus("virtual:co-demo") as server_side:
        node = canopen.LocalNode(node_side, 5, od)
        server = _core.can.SocketcandServer(server_side, host="127.0.0.1", port=0)
        try:
            with open_bus(f"socketcand:127.0.0.1:{server.port}/can0") as remote:
                sdo = canopen.SdoClient(remote, 5, timeout=1.0)
                print(f"  node 5 over socketcand 127.0.0.1:{server.port}: device type 0x{sdo.read_u32(0x1000):08X}, "
                      f"name {sdo.read_string(0x1008)!r}, vendor 0x{sdo.read_u32(0x1018, 1):X}")
                sdo.write_u8(0x2003, 0, 7)
                print(f"  wrote baud index 7 (800 kbit/s); node now holds {od[0x2003].value}")
                try:
                    sdo.write_u8(0x2003, 0, 9)
                except canopen.SdoAbortError as e:
                    print(f"  baud index 9 refused: abort 0x{e.code:08X} {e.text}")
                blob = bytes(range(256)) * (16 if quick else 256)
                t0 = time.monotonic()
                sdo.download(0x1F50, 0, blob, block=True)
                back = sdo.upload(0x1F50, 0, block=True)
                dt = time.monotonic() - t0
                print(f"  block transfer of {len(blob)} bytes down and up in {dt * 1000:.1f} ms, "
                      f"identical: {back == blob}")
            path = os.path.join(workdir, "node5.eds")
            canopen.save_eds(od, path)
            again = canopen.load_eds(path)
            print(f"  exported the node's dictionary to EDS and loaded it back: 0x1008 = {again[0x1008].value!r}")
        finally:
            server.close()
            node.close()


def tour(quick: bool = False) -> int:
    """``motorbus demo --tour``: the transports one by one."""
    print("motorbus demo --tour: the transports under the drives one by one (a pty, TCP on 127.0.0.1)")
    with tempfile.TemporaryDirectory(prefix="motorbus-demo-") as workdir:
        can_bench(quick, workdir)
        canopen_bench(quick, workdir)
    print("\ndemo finished")
    return 0

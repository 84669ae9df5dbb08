"""What the Drive API costs over each vendor's native client, from Python.

For each kind, in one run against the same simulated drive on its real link
(serial kinds: a pty; CiA 402: an in-process virtual bus, the fastest link, so
the overhead is not hidden behind the transport; the DMAC answers after its
#LINE_DELAY, set to its minimum of 100 us here (factory 3 ms)):

* ``position``: ``drive.position`` (units, checks, the adapter) vs the native
  client's own position read;
* ``small move``: issuing a 10-step relative move without waiting,
  ``drive.move_by(..., wait=False)`` vs the native move command (the wait for
  the end of the move is not timed).

Blocks of calls alternate between the two so load changes hit both alike; the
first figure is the difference of the medians, which carries the transport's
noise (several us: each reply wakes the caller with cold caches).  The second,
"Drive layer alone", times the same Drive call with the native client replaced
by a no-op stand-in (best of 5 batches of 20 000 calls): what the Drive layer
itself adds.  Target: <= 2 us added per call.

    .venv/bin/python bench/drive_api.py [--n 2000] [--kinds arcus,dmac,cia402]
"""
from __future__ import annotations

import argparse
import statistics
import time
from typing import Any, Callable

import motorbus
from motorbus import Units
from motorbus.sim import SimBench


def _cia402_native_position(d: Any) -> int:
    return int.from_bytes(d.native.sdo.upload(0x6064, 0), "little", signed=True)


def _cia402_setup(d: Any) -> None:
    d.params["0x6081"] = 200000
    d.params["0x6083"] = 10_000_000
    d.params["0x6084"] = 10_000_000
    d.enable()
    d.move_by(0, wait=True)  # leaves the drive in profile position mode, as the native call expects


def _arcus_setup(d: Any) -> None:
    d.params["HSPD"] = 50000
    d.params["ACC"] = 1
    d.enable()
    d.move_by(0, wait=True)  # INC mode, as the native relative move below expects


def _dmac_setup(d: Any) -> None:
    d.params["#LINE_DELAY"] = 100   # the shortest turnaround the DMAC allows (factory 3 ms)
    d.enable()                      # BRAKE OFF, POWER ON


# kind -> (address, native position read, native relative move of n steps, setup)
NATIVE: dict[str, tuple[str, Callable[[Any], Any], Callable[[Any, int], Any], Callable[[Any], None]]] = {
    "arcus": ("01", lambda d: d.native.encoder, lambda d, n: d.native.move(n), _arcus_setup),
    "dmac": ("00", lambda d: d.native.position, lambda d, n: d.native.move_on(n), _dmac_setup),
    "cia402": ("5", _cia402_native_position, lambda d, n: d.native.move_to(n, relative=True), _cia402_setup),
}


def timed(fn: Callable[[], Any], n: int, between: Callable[[], None]) -> list[float]:
    out = []
    for _ in range(n):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
        between()  # not timed
    return out


def compare(native: Callable[[], Any], api: Callable[[], Any], n: int, blocks: int = 10,
            between: Callable[[], None] = lambda: None) -> tuple[float, float]:
    a: list[float] = []
    b: list[float] = []
    for _ in range(blocks):
        a += timed(native, n // blocks, between)
        b += timed(api, n // blocks, between)
    return statistics.median(a) * 1e6, statistics.median(b) * 1e6


class NoopNative:
    """Stands in for every kind's native client (and the CiA 402 SDO client): each
    call returns at once, so timing the Drive call measures the Drive layer alone."""

    encoder = position = 5
    sdo = None

    def __init__(self) -> None:
        self.sdo = self

    def upload(self, index: int, sub: int) -> bytes:
        return b"\x05\x00\x00\x00"

    def move(self, n: int) -> None: ...

    def move_on(self, n: int) -> None: ...

    def move_to(self, n: int, relative: bool = False) -> None: ...


def layer_cost(drive: Any, call: Callable[[], Any], n: int) -> float:
    """us per Drive call with the native client replaced by NoopNative."""
    stub = NoopNative()
    saved = {name: getattr(drive, name) for name in ("native", "_sdo") if hasattr(drive, name)}
    for name in saved:
        object.__setattr__(drive, name, stub)
    try:
        best = float("inf")
        for _ in range(5):  # best of 5 batches: the machine's other work only adds
            t = time.perf_counter()
            for _ in range(n):
                call()
            best = min(best, (time.perf_counter() - t) / n)
    finally:
        for name, obj in saved.items():
            object.__setattr__(drive, name, obj)
    return best * 1e6


def open_rig(kind: str, address: str):
    plugin = motorbus.registry.drive_plugin(kind)
    units = Units("mm", 0.01)
    if plugin.transport == "serial":
        bench = SimBench([f"{kind}:{address}"])
        return bench, motorbus.open_drive(kind, line=bench.lines[0].pty_path, address=address, units=units)
    bus_name = f"virtual:bench-drive-api-{kind}"
    sim_bus = motorbus.open_bus(bus_name)
    sim = plugin.make_sim(address, bus=sim_bus)

    class Rig:
        def close(self) -> None:
            sim.close()
            sim_bus.close()
    return Rig(), motorbus.open_drive(kind, bus=bus_name, address=address, units=units)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--kinds", default=",".join(NATIVE))
    args = ap.parse_args()
    print("Drive API overhead over the native client, medians in us (added = Drive - native)")
    for kind in args.kinds.split(","):
        address, native_pos, native_move, setup = NATIVE[kind]
        rig, drive = open_rig(kind, address)
        try:
            setup(drive)
            n_pos, a_pos = compare(lambda: native_pos(drive), lambda: drive.position, args.n)
            own_pos = layer_cost(drive, lambda: drive.position, 20000)
            print(f"{kind:7s} position    native {n_pos:8.1f}  Drive {a_pos:8.1f}  added {a_pos - n_pos:+6.2f}"
                  f"  (Drive layer alone {own_pos:.2f})")
            step = [1]

            def settle() -> None:
                drive.wait_idle(timeout=10)
                step[0] = -step[0]

            n_mv, a_mv = compare(lambda: native_move(drive, 10 * step[0]),
                                 lambda: drive.move_by(0.1 * step[0], wait=False), max(args.n // 10, 20),
                                 between=settle)
            own_mv = layer_cost(drive, lambda: drive.move_by(0.1, wait=False), 20000)
            print(f"{kind:7s} small move  native {n_mv:8.1f}  Drive {a_mv:8.1f}  added {a_mv - n_mv:+6.2f}"
                  f"  (Drive layer alone {own_mv:.2f})")
        finally:
            drive.close()
            rig.close()


if __name__ == "__main__":
    main()

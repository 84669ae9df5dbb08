"""Many simulated PMC007 nodes on one virtual bus answering SYNC with one TPDO each.

    python bench/pmc007_scale.py                          # 127 nodes, SYNC 1 kHz, 10 s, no wire time
    python bench/pmc007_scale.py --bitrate 1000000 --rate max   # wire time at 1 Mbit/s, the largest
                                                          # SYNC rate the bus carries (from theory)

Each node maps 600Ch (motor position, 32 bits) into TPDO1, transmission type 1 (every SYNC),
set through SDO with the manual's sequence, then NMT start (broadcast).  A host endpoint
produces SYNC (motorbus SyncProducer, C++ thread) and counts the TPDOs.  Printed: PDOs
expected / received / lost, CPU seconds used by the process per wall second, SYNC period error
(p99, max), and with a bit rate the bus load against the theory (worst-case bit stuffing).

No reference library runs here: canopen's LocalNode sends no SYNC-triggered TPDOs by itself,
so there is nothing equivalent to compare with (the SDO benchmark bench/pmc007_sdo.py has one).
"""
from __future__ import annotations

import argparse
import resource
import time


def frame_bits(nbytes: int) -> int:
    """Worst-case stuffed length of a standard data frame with `nbytes` data bytes, with the
    3-bit intermission: SOF..CRC (34 + 8n bits) can be stuffed, then CRC delimiter, ACK, EOF
    (10 bits) and IFS (3 bits)."""
    body = 34 + 8 * nbytes
    return body + (body - 1) // 4 + 10 + 3


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--nodes", type=int, default=127)
    ap.add_argument("--rate", default="1000", help="SYNC per second, or 'max' (from the bus theory)")
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--bitrate", type=float, default=0.0)
    a = ap.parse_args()

    import motorbus
    from motorbus import _core
    from motorbus.drives import pmc007

    cycle_bits = frame_bits(0) + a.nodes * frame_bits(4)
    if a.rate == "max":
        if not a.bitrate:
            raise SystemExit("--rate max needs --bitrate")
        rate = 0.95 * a.bitrate / cycle_bits   # 5 % head room for SDO-free jitter
    else:
        rate = float(a.rate)
    name = f"virtual:bench-pmc007-scale-{time.monotonic_ns()}"
    opts = {"bitrate": a.bitrate} if a.bitrate else {}
    dev = motorbus.open_bus(name, **opts)
    host = motorbus.open_bus(name, **opts)
    sims = [pmc007.make_sim(n) for n in range(1, a.nodes + 1)]
    if a.bitrate and a.bitrate != 125000:
        # A simulated PMC007 talks only at its 2003h baud (factory 125 kbit/s), like a real one:
        # set it as on a real bench -- on a bus without wire time: node-ID (2002h) and baud,
        # saved (2007h = 2), NMT reset node; then onto the bus at the new rate.
        bauds = {20e3: 0, 25e3: 1, 50e3: 2, 100e3: 3, 125e3: 4, 250e3: 5, 500e3: 6, 800e3: 7, 1e6: 8}
        if a.bitrate not in bauds:
            raise SystemExit(f"--bitrate {a.bitrate:g}: a PMC007 baud (003 §4.3.2): {sorted(bauds)}")
        with motorbus.open_bus(name + "-setup") as sb, motorbus.open_bus(name + "-setup") as sh:
            for n, sim in enumerate(sims, 1):
                sim.attach(sb)
                setup = _core.canopen.SdoClient(sh, n, timeout=2.0)
                setup.download(0x2002, 0, bytes([n]))
                setup.download(0x2003, 0, bytes([bauds[a.bitrate]]))
                setup.download(0x2007, 0, bytes([2]))
                sh.send(_core.can.Frame(0, bytes([0x81, n])))
                deadline = time.monotonic() + 2
                while sim.active_baud_index != bauds[a.bitrate]:
                    if time.monotonic() > deadline:
                        raise SystemExit(f"node {n}: baud index still {sim.active_baud_index} after NMT reset")
                    time.sleep(0.001)
                sim.close()
    for sim in sims:
        sim.attach(dev)
    for n in range(1, a.nodes + 1):
        sdo = _core.canopen.SdoClient(host, n, timeout=2.0)
        sdo.download(0x1800, 1, (0x180 + n).to_bytes(4, "little"))
        sdo.download(0x1800, 2, bytes([1]))                       # every SYNC
        sdo.download(0x1A00, 0, bytes([1]))
        sdo.download(0x1A00, 1, (0x600C0020).to_bytes(4, "little"))
    # Counted in C++ (bus counters), not by a Python callback: at 127 k frames/s the
    # GIL, not the simulators, would be measured.
    host.set_filters([{"can_id": 0x180, "can_mask": 0x780}])
    host.send(_core.can.Frame(0, bytes([0x01, 0x00])))               # NMT start, all nodes
    time.sleep(0.2)
    sync = _core.canopen.SyncProducer(host, 1.0 / rate)
    rx0, tx0 = host.counters.rx_frames, dev.counters.tx_frames
    r0, t0 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    sync.start()
    time.sleep(a.seconds)
    sync.stop()
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    time.sleep(0.3)                                               # the last SYNC's PDOs
    sent = sync.sent
    j = sync.jitter()
    received = host.counters.rx_frames - rx0                      # an endpoint does not receive its own SYNC
    produced = dev.counters.tx_frames - tx0
    expected = sent * a.nodes
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    print(f"nodes {a.nodes}, SYNC {rate:.1f}/s for {wall:.2f} s, bitrate {a.bitrate or 'none (no wire time)'}")
    print(f"SYNC sent {sent}; TPDOs expected {expected}, sent by the nodes {produced}, received {received}, "
          f"lost {expected - received} ({100.0 * (expected - received) / max(1, expected):.3f} %)")
    print(f"CPU {cpu:.2f} s in {wall:.2f} s = {cpu / wall:.2f} cores")
    print(f"SYNC period error: p99 |err| {j.p99_abs_ns / 1000:.1f} us, max |err| {j.max_abs_ns / 1000:.1f} us, "
          f"mean {j.mean_ns / 1000:.2f} us")
    if a.bitrate:
        load_theory = cycle_bits * rate / a.bitrate
        frames_per_s = (sent + received) / wall
        print(f"bus load, theory for this rate: {100 * load_theory:.1f} % ({cycle_bits} bits per SYNC cycle); "
              f"measured frames/s {frames_per_s:.0f} vs theory {(1 + a.nodes) * rate:.0f} "
              f"({100 * (frames_per_s / ((1 + a.nodes) * rate) - 1):+.2f} %)")
    for s in sims:
        s.close()
    dev.close()
    host.close()


if __name__ == "__main__":
    main()

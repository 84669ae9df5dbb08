"""SDO from Python: motorbus (SdoClient -> LocalNode, C++ core) vs the canopen
package, in the same run, ratios printed.

    python bench/sdo.py                 # both, with ratios
    python bench/sdo.py --reference     # canopen only, key=value lines (used by bench/cpp/sdo.cpp)

canopen is measured on python-can's `virtual` interface:
  * expedited and segmented: canopen's RemoteNode against canopen's LocalNode;
  * block: canopen's RemoteNode against our LocalNode through the python-can
    bridge (canopen's own server has no block mode).
"""
import argparse
import threading
import time

from helpers.timing import rate  # bench/helpers: shared by the benchmarks

DOMAIN_MAX = 1 << 20
NODES = 8              # expedited_rate_8_nodes: served nodes = client threads
DEVICE_TYPE = 0x00020192



def _throughput(fn, nbytes, seconds):
    """Bytes/s of repeated fn() calls moving nbytes each."""
    n = 0
    t0 = time.perf_counter()
    while True:
        fn()
        n += 1
        dt = time.perf_counter() - t0
        if dt >= seconds:
            return n * nbytes / dt


def _rate_many(read_fns, seconds, label):
    """One thread per fn, each calling its fn back to back until the shared
    deadline; returns total calls/s.  Raises if any thread failed a read (timeout
    or otherwise), read a wrong value or completed none."""
    n = len(read_fns)
    reads, errors = [0] * n, [None] * n
    barrier = threading.Barrier(n + 1)
    box = {}

    def worker(k):
        fn = read_fns[k]
        barrier.wait()
        end = box["end"]
        c = 0
        try:
            while time.perf_counter() < end:
                v = fn()
                if v != DEVICE_TYPE:
                    raise AssertionError(f"read {v!r}")
                c += 1
        except Exception as e:  # noqa: BLE001 - reported below
            errors[k] = e
        reads[k] = c

    threads = [threading.Thread(target=worker, args=(k,), daemon=True) for k in range(n)]
    for t in threads:
        t.start()
    t0 = time.perf_counter()
    box["end"] = t0 + seconds
    barrier.wait()
    for t in threads:
        t.join()
    dt = time.perf_counter() - t0
    bad = [(k + 1, reads[k], errors[k]) for k in range(n) if errors[k] is not None or reads[k] == 0]
    if bad:
        raise SystemExit(f"{label}: expedited_rate_{n}_nodes FAILED: (node, reads, error) {bad}")
    return sum(reads) / dt


def ours(seconds):
    import motorbus
    from motorbus.canopen import LocalNode, ObjectDictionary, SdoClient

    host, dev = motorbus.open_bus("virtual:bench-sdo-py"), motorbus.open_bus("virtual:bench-sdo-py")
    od = ObjectDictionary()
    od.add_variable(0x2000, "Value", "u32", "rw", default=0x12345678)
    od.add_variable(0x2001, "Blob", "DOMAIN", "rw", max_size=DOMAIN_MAX)
    node = LocalNode(dev, 5, od)
    sdo = SdoClient(host, 5, timeout=1.0)
    seg = bytes(range(256)) * 16        # 4 KiB
    blk = bytes(range(256)) * 256       # 64 KiB
    r = {}
    r["expedited_rate"], r["expedited_median_us"], r["expedited_p99_us"] = rate(lambda: sdo.read_u32(0x2000), seconds)
    od[0x2001].raw = seg
    r["segmented_upload_Bps"] = _throughput(lambda: sdo.upload(0x2001, 0), len(seg), seconds)
    r["segmented_download_Bps"] = _throughput(lambda: sdo.download(0x2001, 0, seg, segmented=True), len(seg), seconds)
    od[0x2001].raw = blk
    r["block_upload_Bps"] = _throughput(lambda: sdo.upload(0x2001, 0, block=True), len(blk), seconds)
    r["block_download_Bps"] = _throughput(lambda: sdo.download(0x2001, 0, blk, block=True), len(blk), seconds)
    node.close()
    host.close()
    dev.close()

    # 8 nodes on one virtual bus, 8 threads each with its own SdoClient.
    host, dev = motorbus.open_bus("virtual:bench-sdo-py-many"), motorbus.open_bus("virtual:bench-sdo-py-many")
    nodes, clients = [], []
    for i in range(1, NODES + 1):
        od = ObjectDictionary()
        od.add_variable(0x1000, "Device type", "u32", "ro", default=DEVICE_TYPE)
        od.add_variable(0x2000, "Value", "u32", "rw", default=0x12345678)
        nodes.append(LocalNode(dev, i, od))
        clients.append(SdoClient(host, i, timeout=1.0))
    r[f"expedited_rate_{NODES}_nodes"] = _rate_many(
        [(lambda c=c: c.read_u32(0x1000)) for c in clients], seconds, "motorbus")
    for n in nodes:
        n.close()
    host.close()
    dev.close()
    return r


def reference(seconds):
    import can
    import canopen
    import motorbus
    from motorbus.canopen import LocalNode, ObjectDictionary

    import logging
    logging.getLogger("canopen").setLevel(logging.CRITICAL)

    def make_od():
        cod = canopen.ObjectDictionary()
        t = canopen.objectdictionary.ODVariable("Device type", 0x1000, 0)
        t.data_type = canopen.objectdictionary.UNSIGNED32
        t.access_type = "ro"
        t.default = DEVICE_TYPE
        cod.add_object(t)
        v = canopen.objectdictionary.ODVariable("Value", 0x2000, 0)
        v.data_type = canopen.objectdictionary.UNSIGNED32
        v.access_type = "rw"
        v.default = 0x12345678
        cod.add_object(v)
        d = canopen.objectdictionary.ODVariable("Blob", 0x2001, 0)
        d.data_type = canopen.objectdictionary.DOMAIN
        d.access_type = "rw"
        cod.add_object(d)
        return cod

    server_net, client_net = canopen.Network(), canopen.Network()
    server_net.connect(interface="virtual", channel="bench-sdo-ref")
    client_net.connect(interface="virtual", channel="bench-sdo-ref")
    local = canopen.LocalNode(6, make_od())
    server_net.add_node(local)
    remote = client_net.add_node(6, make_od())
    seg = bytes(range(256)) * 16
    blk = bytes(range(256)) * 256
    r = {}
    r["expedited_rate"], r["expedited_median_us"], r["expedited_p99_us"] = rate(
        lambda: remote.sdo.upload(0x2000, 0), seconds)
    local.sdo.download(0x2001, 0, seg)
    r["segmented_upload_Bps"] = _throughput(lambda: remote.sdo.upload(0x2001, 0), len(seg), seconds)
    r["segmented_download_Bps"] = _throughput(
        lambda: remote.sdo.download(0x2001, 0, seg, force_segment=True), len(seg), seconds)
    client_net.disconnect()
    server_net.disconnect()

    # Block: canopen's client against our server on the same python-can channel.
    pc = can.Bus(interface="virtual", channel="bench-sdo-blk")
    bus = motorbus.open_bus(pc)
    od = ObjectDictionary()
    od.add_variable(0x2001, "Blob", "DOMAIN", "rw", max_size=DOMAIN_MAX)
    od[0x2001].raw = blk
    node = LocalNode(bus, 7, od)
    net = canopen.Network()
    net.connect(interface="virtual", channel="bench-sdo-blk")
    remote = net.add_node(7, make_od())

    def block_up():
        with remote.sdo.open(0x2001, 0, "rb", block_transfer=True) as f:
            assert len(f.read()) == len(blk)

    def block_down():
        with remote.sdo.open(0x2001, 0, "wb", size=len(blk), block_transfer=True) as f:
            f.write(blk)

    r["block_upload_Bps"] = _throughput(block_up, len(blk), seconds)
    r["block_download_Bps"] = _throughput(block_down, len(blk), seconds)
    net.disconnect()
    node.close()
    bus.close()

    # 8 nodes: canopen's LocalNodes (ids 1..8) on one server Network, 8 RemoteNodes
    # sharing one client Network, 8 threads (same servers as the single-node
    # expedited figure above).
    server_net, client_net = canopen.Network(), canopen.Network()
    server_net.connect(interface="virtual", channel="bench-sdo-ref-many")
    client_net.connect(interface="virtual", channel="bench-sdo-ref-many")
    remotes = []
    for i in range(1, NODES + 1):
        server_net.add_node(canopen.LocalNode(i, make_od()))
        remotes.append(client_net.add_node(i, make_od()))
    r[f"expedited_rate_{NODES}_nodes"] = _rate_many(
        [(lambda rn=rn: int.from_bytes(rn.sdo.upload(0x1000, 0), "little")) for rn in remotes],
        seconds, "canopen")
    client_net.disconnect()
    server_net.disconnect()
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reference", action="store_true", help="canopen only, key=value lines")
    ap.add_argument("--seconds", type=float, default=2.0, help="per measurement")
    a = ap.parse_args()
    ref = reference(a.seconds)
    if a.reference:
        for k, v in ref.items():
            print(f"{k}={v:.6g}")
        return
    mine = ours(a.seconds)
    print(f"{'SDO from Python':28s} {'motorbus':>14s} {'canopen':>14s} {'ratio':>8s}")
    for k in mine:
        higher_better = not k.endswith("_us")
        ratio = mine[k] / ref[k] if higher_better else ref[k] / mine[k]
        print(f"{k:28s} {mine[k]:14.6g} {ref[k]:14.6g} {ratio:7.1f}x")


if __name__ == "__main__":
    main()

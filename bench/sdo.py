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
import time

DOMAIN_MAX = 1 << 20


def _percentile(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(len(v) * p))]


def _rate(fn, seconds):
    """Calls fn until `seconds` passed; returns (calls/s, median us, p99 us)."""
    lat = []
    t_end = time.perf_counter() + seconds
    while True:
        t = time.perf_counter()
        fn()
        t2 = time.perf_counter()
        lat.append((t2 - t) * 1e6)
        if t2 >= t_end:
            break
    return len(lat) / sum(lat) * 1e6, _percentile(lat, 0.5), _percentile(lat, 0.99)


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
    r["expedited_rate"], r["expedited_median_us"], r["expedited_p99_us"] = _rate(lambda: sdo.read_u32(0x2000), seconds)
    od[0x2001].raw = seg
    r["segmented_upload_Bps"] = _throughput(lambda: sdo.upload(0x2001, 0), len(seg), seconds)
    r["segmented_download_Bps"] = _throughput(lambda: sdo.download(0x2001, 0, seg, segmented=True), len(seg), seconds)
    od[0x2001].raw = blk
    r["block_upload_Bps"] = _throughput(lambda: sdo.upload(0x2001, 0, block=True), len(blk), seconds)
    r["block_download_Bps"] = _throughput(lambda: sdo.download(0x2001, 0, blk, block=True), len(blk), seconds)
    node.close()
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
    r["expedited_rate"], r["expedited_median_us"], r["expedited_p99_us"] = _rate(
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

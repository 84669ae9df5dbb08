"""Awaited SDO: motorbus's awaitable CANopen facade vs canopen-asyncio 2.4.1, in the
same run, ratios printed.

    python bench/aio_sdo.py [--seconds 3] [--nodes 32,127]

Measured (one JSON line each, then a summary table):

* expedited reads from N simulated nodes awaited at once on one event loop (N tasks,
  each reading its node's 0x1000 back to back), for N = 32 and 127:
  - in-process: motorbus (our LocalNodes on our virtual bus, ``await
    node.sdo["Device type"].get()``) vs canopen-asyncio (``await
    node.sdo["Device type"].aget_raw()``) against the `canopen` package's LocalNodes
    on python-can's ``virtual`` interface -- each library on its own in-process bus,
    as bench/sdo.py does;
  - served: both clients through one socketcand server on 127.0.0.1 (motorbus's,
    in this process) to the same LocalNodes (ours) on the server's virtual hub.
    The floor is the server's bare round trip: one expedited read by the C++
    blocking call (request and response through the server, no Python between);
    reads/s at N concurrent are compared with 1/floor;
* one awaited read vs the blocking call, one node, sequential (goal <= 1.5x):
  the typed facade (``await .get()`` vs ``.raw``) and the bare client
  (``await upload_async(client, ...)`` vs ``client.upload``); for scale, the
  completion-based call waited for with select() on the eventfd, no asyncio (the
  blocking call spins 50 us for its answer instead of sleeping);
* threads alive (/proc/self/task, C++ threads included) while 127 reads are
  awaited vs before they start, for both libraries.
"""
from __future__ import annotations

import argparse
import asyncio
import itertools
import json
import logging
import os
import select
import sys
import time

from helpers.timing import percentile

DEVICE_TYPE = 0x00020192
_names = itertools.count()


def threads_alive() -> int:
    return len(os.listdir("/proc/self/task"))


def emit(**kw) -> dict:
    print(json.dumps(kw), flush=True)
    return kw


async def _concurrent(read_fns, seconds: float, label: str) -> tuple[float, int]:
    """N tasks, each awaiting its fn back to back until the deadline; reads/s and
    the thread count seen while they all are in flight."""
    loop = asyncio.get_running_loop()
    counts = [0] * len(read_fns)
    end = loop.time() + seconds
    threads = [0]

    async def worker(k, fn, want):
        c = 0
        while loop.time() < end:
            v = await fn()
            if v != want:
                raise AssertionError(f"{label}: node {k} read {v!r}, want {want!r}")
            c += 1
        counts[k] = c

    async def sample():
        await asyncio.sleep(min(0.5, seconds / 3))
        threads[0] = threads_alive()

    t0 = time.perf_counter()
    await asyncio.gather(sample(), *[worker(k, fn, want) for k, (fn, want) in enumerate(read_fns)])
    dt = time.perf_counter() - t0
    if not all(counts):
        raise SystemExit(f"{label}: some node completed no read: {counts}")
    return sum(counts) / dt, threads[0]


# ---- motorbus ----------------------------------------------------------------------------
def _our_nodes(dev, n):
    from motorbus.canopen import LocalNode, ObjectDictionary
    ods, nodes = {}, []
    for i in range(1, n + 1):
        od = ObjectDictionary()
        od.add_variable(0x1000, "Device type", "u32", "ro", default=DEVICE_TYPE + i)
        ods[i] = od
        nodes.append(LocalNode(dev, i, od))
    return ods, nodes


def ours_concurrent(n: int, seconds: float, served: bool) -> dict:
    from motorbus import _core
    from motorbus.canopen import Network
    from motorbus.socketcand import SocketcandServer

    name = f"bench-aio-sdo-{next(_names)}"
    dev = _core.can.open_virtual(name)
    ods, nodes = _our_nodes(dev, n)
    server = server_bus = None
    if served:
        server_bus = _core.can.open_virtual(name)
        server = SocketcandServer(server_bus)
        spec = f"socketcand:127.0.0.1:{server.port}/can0"
    else:
        spec = f"virtual:{name}"
    net = Network(spec, sdo_timeout=2.0)
    remote = [net.add_node(i, ods[i]) for i in range(1, n + 1)]
    r = {}
    try:
        before = threads_alive()
        fns = [(remote[i - 1].sdo["Device type"].get, DEVICE_TYPE + i) for i in range(1, n + 1)]
        r["rate"], r["threads_during"] = asyncio.run(_concurrent(fns, seconds, f"motorbus {n}"))
        r["threads_before"] = before
        if served:
            # The floor: the server's bare round trip, one expedited read by the C++
            # blocking call (no Python between request and response).
            client = remote[0].sdo.client
            lat = []
            for _ in range(300):
                t = time.perf_counter()
                client.read_u32(0x1000)
                lat.append(time.perf_counter() - t)
            r["floor_us"] = percentile(lat, 0.5) * 1e6
            r["server_port"] = server.port
    finally:
        net.close()
        for x in nodes:
            x.close()
        if server is not None:
            server.close()
            server_bus.close()
        dev.close()
    return r


def ours_single(seconds: float) -> dict:
    """One node, sequential: the awaited read vs the blocking one, typed and bare, and
    the completion-based call waited for without asyncio.  The four are measured in
    alternating slices inside one loop, so a change of the machine's load during
    the run moves them together."""
    from motorbus import _core
    from motorbus.canopen import Network
    from motorbus.canopen import sdo as sdo_mod

    name = f"bench-aio-sdo-1-{next(_names)}"
    dev = _core.can.open_virtual(name)
    ods, nodes = _our_nodes(dev, 1)
    net = Network(f"virtual:{name}", sdo_timeout=2.0)
    node = net.add_node(1, ods[1])
    var, client = node.sdo["Device type"], node.sdo.client
    want = DEVICE_TYPE + 1
    want_bytes = want.to_bytes(4, "little")
    done = _core.runtime.Completions()
    fd = done.fileno()

    def completion_only():
        # Without asyncio: the completion-based call, then a sleep on the eventfd
        # (select) and the drain -- the thread wake-up an awaited read pays when
        # its answer is not there at once.
        client.upload_async(0x1000, 0, done, 1)
        while not done.pending:
            select.select([fd], [], [])
        return done.drain()[0][1]

    cases = {
        "blocking_typed": (False, lambda: var.raw, want),
        "awaited_typed": (True, var.get, want),
        "blocking_bare": (False, lambda: client.upload(0x1000, 0), want_bytes),
        "awaited_bare": (True, lambda: sdo_mod.upload_async(client, 0x1000, 0), want_bytes),
        "completion_floor": (False, completion_only, want_bytes),
    }
    lat = {k: [] for k in cases}

    async def measure():
        slices = 10
        for _ in range(slices):
            for key, (is_async, fn, expect) in cases.items():
                out = lat[key]
                end = time.perf_counter() + seconds / slices
                while True:
                    t = time.perf_counter()
                    v = (await fn()) if is_async else fn()
                    t2 = time.perf_counter()
                    out.append(t2 - t)
                    if v != expect:
                        raise SystemExit(f"{key}: read {v!r}")
                    if t2 >= end:
                        break

    try:
        asyncio.run(measure())
    finally:
        net.close()
        nodes[0].close()
        dev.close()
    return {f"{k}_us": percentile(v, 0.5) * 1e6 for k, v in lat.items()}


# ---- canopen-asyncio -------------------------------------------------------------------
def _canopen_od(canopen, value: int):
    od = canopen.ObjectDictionary()
    v = canopen.objectdictionary.ODVariable("Device type", 0x1000, 0)
    v.data_type = canopen.objectdictionary.UNSIGNED32
    v.access_type = "ro"
    v.default = value
    od.add_object(v)
    return od


def reference_concurrent(n: int, seconds: float, served_port: int | None = None) -> dict:
    """canopen-asyncio as client: against the `canopen` package's LocalNodes on python-can's
    virtual bus (in-process), or through the socketcand server on `served_port` to our nodes."""
    import canopen
    import canopen_asyncio
    from canopen_asyncio.async_guard import AllowBlocking

    logging.getLogger("canopen").setLevel(logging.CRITICAL)
    logging.getLogger("canopen_asyncio").setLevel(logging.CRITICAL)
    logging.getLogger("can").setLevel(logging.CRITICAL)
    channel = f"bench-aio-ref-{next(_names)}"
    server_net = None
    if served_port is None:
        server_net = canopen.Network()
        server_net.connect(interface="virtual", channel=channel)
        for i in range(1, n + 1):
            server_net.add_node(canopen.LocalNode(i, _canopen_od(canopen, DEVICE_TYPE + i)))

    async def main():
        loop = asyncio.get_running_loop()
        net = canopen_asyncio.Network(loop=loop)
        with AllowBlocking():
            if served_port is None:
                net.connect(interface="virtual", channel=channel)
            else:
                net.connect(interface="socketcand", host="127.0.0.1", port=served_port, channel="can0")
            nodes = [net.add_node(i, _canopen_od(canopen_asyncio, DEVICE_TYPE + i)) for i in range(1, n + 1)]
        before = threads_alive()
        try:
            fns = [(nodes[i - 1].sdo["Device type"].aget_raw, DEVICE_TYPE + i) for i in range(1, n + 1)]
            rate, during = await _concurrent(fns, seconds, f"canopen-asyncio {n}")
        finally:
            with AllowBlocking():
                net.disconnect()
        return {"rate": rate, "threads_during": during, "threads_before": before}

    try:
        return asyncio.run(main())
    finally:
        if server_net is not None:
            server_net.disconnect()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--nodes", default="32,127")
    a = ap.parse_args()
    counts = [int(x) for x in a.nodes.split(",")]
    rows = []
    import canopen_asyncio
    emit(bench="aio_sdo", reference=f"canopen-asyncio {canopen_asyncio.__version__}", python=sys.version.split()[0])
    for n in counts:
        ours = ours_concurrent(n, a.seconds, served=False)
        ref = reference_concurrent(n, a.seconds)
        rows.append(emit(bench="aio_sdo", case=f"in-process, {n} nodes awaited at once", motorbus_reads_s=round(ours["rate"]),
                         reference_reads_s=round(ref["rate"]), ratio=round(ours["rate"] / ref["rate"], 1),
                         motorbus_threads=f'{ours["threads_before"]}->{ours["threads_during"]}',
                         reference_threads=f'{ref["threads_before"]}->{ref["threads_during"]}'))
    for n in counts:
        ours = ours_concurrent(n, a.seconds, served=True)
        # A fresh server for the reference client, the same nodes and hub shape.
        from motorbus import _core
        from motorbus.socketcand import SocketcandServer
        name = f"bench-aio-sdo-ref-served-{next(_names)}"
        dev, sbus = _core.can.open_virtual(name), _core.can.open_virtual(name)
        _, nodes = _our_nodes(dev, n)
        server = SocketcandServer(sbus)
        try:
            ref = reference_concurrent(n, a.seconds, served_port=server.port)
        finally:
            server.close()
            for x in nodes:
                x.close()
            sbus.close()
            dev.close()
        floor_rate = 1e6 / ours["floor_us"]
        rows.append(emit(bench="aio_sdo", case=f"socketcand 127.0.0.1, {n} nodes awaited at once",
                         motorbus_reads_s=round(ours["rate"]), reference_reads_s=round(ref["rate"]),
                         ratio=round(ours["rate"] / ref["rate"], 1), floor_round_trip_us=round(ours["floor_us"], 1),
                         motorbus_vs_floor=round(ours["rate"] / floor_rate, 2),
                         reference_vs_floor=round(ref["rate"] / floor_rate, 2)))
    single = ours_single(min(a.seconds, 2.0))
    rows.append(emit(bench="aio_sdo", case="one read, sequential: awaited vs blocking",
                     typed_blocking_us=round(single["blocking_typed_us"], 1),
                     typed_awaited_us=round(single["awaited_typed_us"], 1),
                     typed_ratio=round(single["awaited_typed_us"] / single["blocking_typed_us"], 2),
                     bare_blocking_us=round(single["blocking_bare_us"], 1),
                     bare_awaited_us=round(single["awaited_bare_us"], 1),
                     bare_ratio=round(single["awaited_bare_us"] / single["blocking_bare_us"], 2),
                     completion_eventfd_us=round(single["completion_floor_us"], 1)))
    print("\n| case | motorbus | canopen-asyncio | ratio | notes |\n|---|---|---|---|---|")
    for r in rows:
        if "ratio" in r:
            notes = (f"threads {r['motorbus_threads']} vs {r['reference_threads']}" if "motorbus_threads" in r else
                     f"floor {r['floor_round_trip_us']} us = {1e6 / r['floor_round_trip_us']:.0f} reads/s; "
                     f"motorbus {r['motorbus_vs_floor']}x, canopen-asyncio {r['reference_vs_floor']}x of it")
            print(f"| {r['case']} | {r['motorbus_reads_s']} reads/s | {r['reference_reads_s']} reads/s | "
                  f"{r['ratio']}x | {notes} |")
        else:
            print(f"| {r['case']} | typed {r['typed_awaited_us']} us vs {r['typed_blocking_us']} us "
                  f"({r['typed_ratio']}x); bare {r['bare_awaited_us']} us vs {r['bare_blocking_us']} us "
                  f"({r['bare_ratio']}x) | | | completion + eventfd wake-up alone, no asyncio: "
                  f"{r['completion_eventfd_us']} us |")


if __name__ == "__main__":
    main()

"""Promise 6: an endpoint nobody reads costs a bounded queue, not memory without end, and every
dropped frame is counted: rx_dropped = received - rx_queue_size, exactly; the queue keeps the
newest frames."""
import os
import struct
import time

import motorbus
from motorbus import Frame
from motorbus.socketcand import SocketcandServer, open_socketcand

from _soak import hub, size

FRAMES = size(100_000, 1_000_000)
QUEUE = 1024
RSS_BOUND_MB = 64  # growth allowed across the flood (the queue itself is ~0.1 MB)


def _rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def _wait(pred, timeout=120):
    deadline = time.monotonic() + timeout
    while not pred():
        assert time.monotonic() < deadline, "the flood never finished arriving"
        time.sleep(0.01)


def _drain_and_check(bus, sent):
    frames = []
    while True:
        batch = bus.recv_many(4096, timeout=0)
        if not batch:
            break
        frames += batch
    seqs = [struct.unpack("<I", bytes(f.data))[0] for f in frames]
    assert seqs == list(range(sent - QUEUE, sent)), "the queue must hold the newest frames in order"


def _flood(send):
    for i in range(FRAMES):
        send(Frame(0x123, struct.pack("<I", i)))


def test_virtual_endpoint_nobody_reads():
    name = hub("rel-flood")
    tx = motorbus.open_bus(f"virtual:{name}")
    rx = motorbus.open_bus(f"virtual:{name}", rx_queue_size=QUEUE)
    try:
        before = _rss_mb()
        _flood(lambda f: tx.send(f, timeout=10))
        _wait(lambda: rx.counters.rx_frames == FRAMES)
        grown = _rss_mb() - before
        c = rx.counters
        assert c.rx_dropped == FRAMES - QUEUE
        assert tx.counters.tx_frames == FRAMES and tx.counters.tx_dropped == 0
        assert grown < RSS_BOUND_MB, f"RSS grew {grown:.1f} MB over {FRAMES} unread frames"
        _drain_and_check(rx, FRAMES)
        print(f"\n[flood virtual] {FRAMES} frames, queue {QUEUE}: rx_dropped={c.rx_dropped} "
              f"(= sent - queue), RSS growth {grown:.1f} MB")
    finally:
        rx.close()
        tx.close()


def test_socketcand_client_nobody_reads():
    name = hub("rel-flood-scd")
    served = motorbus.open_bus(f"virtual:{name}")
    # The server's own per-client queue (drop-oldest for slow clients, K15) is counted too: every
    # frame is either dropped there (stats.queue_drops) or reaches the client, which keeps QUEUE.
    server = SocketcandServer(served, host="127.0.0.1", port=0, client_queue=65536)
    tx = motorbus.open_bus(f"virtual:{name}")
    rx = open_socketcand("127.0.0.1", server.port, "can0", rx_queue_size=QUEUE)
    try:
        before = _rss_mb()
        _flood(lambda f: tx.send(f, timeout=10))
        _wait(lambda: rx.counters.rx_frames + server.stats.queue_drops == FRAMES)
        grown = _rss_mb() - before
        server_drops = server.stats.queue_drops
        c = rx.counters
        assert c.rx_frames == FRAMES - server_drops and c.rx_dropped == c.rx_frames - QUEUE
        assert c.parse_errors == 0 and c.overruns == 0
        assert rx.link_up
        assert grown < RSS_BOUND_MB, f"RSS grew {grown:.1f} MB over {FRAMES} unread frames"
        if server_drops == 0:
            _drain_and_check(rx, FRAMES)
        print(f"\n[flood socketcand] {FRAMES} frames, queue {QUEUE}: rx_dropped={c.rx_dropped} "
              f"(= received - queue), server queue_drops={server_drops}, RSS growth {grown:.1f} MB")
    finally:
        rx.close()
        tx.close()
        server.close()
        served.close()

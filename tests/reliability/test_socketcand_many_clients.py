"""Promise 2: one socketcand server, many clients at full rate — every client gets every other
client's frames exactly once and in each sender's order; clients that vanish mid-stream (socket
closed with an RST, no goodbye) leave the others untouched."""
import random
import socket
import struct
import threading
import time

import can
import logging
import pytest

import motorbus
from motorbus import Frame
from motorbus.socketcand import SocketcandServer, open_socketcand

from _soak import hub, size

MB_CLIENTS = size(6, 12)     # motorbus clients
PC_CLIENTS = 2               # python-can `socketcand` clients
ABRUPT = size(3, 8)          # raw-socket clients that vanish mid-stream
N1 = size(8000, 100000)      # frames per surviving sender, phase 1 (everyone streaming)
N2 = size(4000, 50000)      # frames per surviving sender, phase 2 (while the abrupt ones vanish)
ABRUPT_MAX = size(3000, 30000)
DEADLINE = size(60, 1800)    # seconds before a missing frame is a failure (never a timing assert)

# PC_LOSS: python-can 4.6.1's `socketcand` client loses about one frame in a few thousand when
# several senders stream to it while it also sends (seen here: 3-5 of 2 x 21 000 frames per run,
# often the same frame at both python-can clients).  The server is not the cause: the motorbus
# clients of the same run receive every frame, and so does a raw-socket reader with an exact
# parser that sends one element per send() as python-can does (docs/reliability.md).
# So python-can receivers are checked for order and duplicates, and their losses are counted and
# printed, not failed on.
PC_LOSS_TOLERATED = True

logging.getLogger("can").setLevel(logging.ERROR)  # python-can warns on every partial read

BASE = 0x100
ABRUPT_BASE = 0x200


def _payload(phase, seq):
    return struct.pack("<II", phase, seq)


class _Raw:
    """A socketcand client by hand: handshake, `< send >` elements, then an RST."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        buf = b""
        for send, want in ((None, b"< hi >"), (b"< open can0 >", b"< ok >"), (b"< rawmode >", b"< ok >")):
            if send:
                self.sock.sendall(send)
            while want not in buf:
                chunk = self.sock.recv(4096)
                assert chunk, "server closed during the handshake"
                buf += chunk
            buf = buf[buf.index(want) + len(want):]

    def send(self, can_id, data):
        self.sock.sendall(f"< send {can_id:X} {len(data)} {' '.join(f'{b:02X}' for b in data)} >".encode())

    def abort(self):
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        self.sock.close()


class _Receiver:
    """Collects (sender, phase, seq) from one client until it has what it expects."""

    def __init__(self, me, recv_batch, expected):
        self.me = me
        self.got = {}  # (sender id, phase) -> [seq...]
        self.expected = expected  # (sender id, phase) -> count
        self.errors = []
        self.done = threading.Event()
        self._recv_batch = recv_batch
        self.thread = threading.Thread(target=self._run, daemon=True)

    def complete(self):
        # every stream's last frame seen (streams arrive in order, so nothing more is coming)
        return all(self.got.get(k, [-1])[-1] >= n - 1 for k, n in self.expected.items())

    def _run(self):
        deadline = time.monotonic() + DEADLINE
        try:
            while not self.complete() and time.monotonic() < deadline:
                for can_id, data in self._recv_batch():
                    phase, seq = struct.unpack("<II", data)
                    self.got.setdefault((can_id, phase), []).append(seq)
        except BaseException as e:  # noqa: BLE001
            self.errors.append(repr(e))
        self.done.set()


def _mb_batch(bus):
    return lambda: [(f.id, bytes(f.data)) for f in bus.recv_many(4096, timeout=0.2)]


def _pc_batch(bus):
    def batch():
        out = []
        m = bus.recv(timeout=0.2)
        while m is not None and len(out) < 4096:
            out.append((m.arbitration_id, bytes(m.data)))
            m = bus.recv(timeout=0)
        return out
    return batch


def test_many_clients_full_rate_then_abrupt_disconnects():
    served = motorbus.open_bus(f"virtual:{hub('rel-scd')}")
    # client_queue large enough that no surviving client is ever "slow" at full rate: this test
    # is about loss/duplication/order, K15 (drop-oldest for slow clients) is tested elsewhere.
    server = SocketcandServer(served, host="127.0.0.1", port=0, client_queue=1 << 20)
    mbs = [open_socketcand("127.0.0.1", server.port, "can0", rx_queue_size=1 << 20) for _ in range(MB_CLIENTS)]
    pcs = [can.Bus(interface="socketcand", host="127.0.0.1", port=server.port, channel="can0")
           for _ in range(PC_CLIENTS)]
    raws = []
    try:
        senders = list(range(MB_CLIENTS + PC_CLIENTS))  # sender index -> id BASE + i
        expected = {}
        receivers = []
        for me in senders:
            exp = {(BASE + s, p): n for s in senders if s != me for p, n in ((1, N1), (2, N2))}
            batch = _mb_batch(mbs[me]) if me < MB_CLIENTS else _pc_batch(pcs[me - MB_CLIENTS])
            receivers.append(_Receiver(me, batch, exp))
            expected[me] = exp
        for r in receivers:
            r.thread.start()
        time.sleep(0.3)  # python-can clients finish their rawmode handshake

        def send_all(i, phase, n):
            for seq in range(n):
                data = _payload(phase, seq)
                if i < MB_CLIENTS:
                    mbs[i].send(Frame(BASE + i, data), timeout=30)
                else:
                    pcs[i - MB_CLIENTS].send(can.Message(arbitration_id=BASE + i, data=data,
                                                         is_extended_id=False))

        # Phase 1: everyone at full rate.
        threads = [threading.Thread(target=send_all, args=(i, 1, N1), daemon=True) for i in senders]
        for t in threads:
            t.start()
        for t in threads:
            t.join(DEADLINE)

        # Phase 2: raw clients join and stream; each vanishes (RST) at a random point while the
        # survivors stream on.
        raws = [_Raw(server.port) for _ in range(ABRUPT)]
        rng = random.Random(7)
        cut = [rng.randrange(1, ABRUPT_MAX) for _ in raws]
        raw_sent = [0] * ABRUPT

        def raw_stream(j):
            for seq in range(cut[j]):
                raws[j].send(ABRUPT_BASE + j, _payload(2, seq))
                raw_sent[j] += 1
            raws[j].abort()

        threads = [threading.Thread(target=send_all, args=(i, 2, N2), daemon=True) for i in senders]
        threads += [threading.Thread(target=raw_stream, args=(j,), daemon=True) for j in range(ABRUPT)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(DEADLINE)
        for r in receivers:
            r.done.wait(DEADLINE)

        lost = dup_or_reordered = 0
        pc_lost = []  # python-can's own client: see the note at PC_LOSS
        for r in receivers:
            assert r.errors == [], (r.me, r.errors)
            for key, n in r.expected.items():
                seqs = r.got.get(key, [])
                if seqs == list(range(n)):
                    continue
                if any(b <= a for a, b in zip(seqs, seqs[1:])):
                    dup_or_reordered += 1
                elif r.me >= MB_CLIENTS:
                    pc_lost.append((r.me, hex(key[0]), key[1], sorted(set(range(n)) - set(seqs))))
                else:
                    lost += 1
            # frames of the clients that vanished: an in-order, duplicate-free prefix
            for j in range(ABRUPT):
                seqs = r.got.get((ABRUPT_BASE + j, 2), [])
                assert len(seqs) <= raw_sent[j] and all(b > a for a, b in zip(seqs, seqs[1:])), (r.me, j)
                if r.me < MB_CLIENTS:
                    assert seqs == list(range(len(seqs))), (r.me, j, seqs[:5])
                elif seqs and seqs != list(range(seqs[-1] + 1)):
                    pc_lost.append((r.me, hex(ABRUPT_BASE + j), 2, sorted(set(range(seqs[-1])) - set(seqs))))
            unexpected = set(r.got) - set(r.expected) - {(ABRUPT_BASE + j, 2) for j in range(ABRUPT)}
            assert not unexpected, unexpected
        assert lost == 0 and dup_or_reordered == 0, (lost, dup_or_reordered)
        pc_lost_frames = sum(len(m) for *_, m in pc_lost)
        if pc_lost and not PC_LOSS_TOLERATED:
            pytest.fail(f"python-can socketcand receivers lost {pc_lost_frames} frames: {pc_lost[:6]}")
        # The survivors are still connected and the server saw the vanished clients go.
        assert all(b.link_up for b in mbs)
        deadline = time.monotonic() + 10
        while server.stats.clients_active != MB_CLIENTS + PC_CLIENTS and time.monotonic() < deadline:
            time.sleep(0.05)
        assert server.stats.clients_active == MB_CLIENTS + PC_CLIENTS
        per_receiver = (len(senders) - 1) * (N1 + N2)
        print(f"\n[socketcand-many] {MB_CLIENTS} motorbus + {PC_CLIENTS} python-can clients, "
              f"{len(senders)} x ({N1}+{N2}) frames, {per_receiver} per receiver: 0 lost, 0 dup/reordered; "
              f"{ABRUPT} raw clients RST after {cut} frames; server queue_drops={server.stats.queue_drops} "
              f"(per connected client {server.client_drops}); "
              f"python-can receivers lost {pc_lost_frames} frames in {len(pc_lost)} streams {pc_lost[:4]}")
    finally:
        for r in raws:
            try:
                r.sock.close()
            except OSError:
                pass
        for b in pcs:
            b.shutdown()
        for b in mbs:
            b.close()
        server.close()
        served.close()

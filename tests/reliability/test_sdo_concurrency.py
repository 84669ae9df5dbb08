"""Promise 1: many threads sharing one SdoClient against one LocalNode lose nothing and mix
nothing up — over the in-process virtual bus and through a socketcand server on 127.0.0.1."""
import threading

import pytest

import motorbus
from motorbus.canopen import LocalNode, ObjectDictionary, SdoClient
from motorbus.socketcand import SocketcandServer, open_socketcand

from _soak import hub, size

THREADS = size(8, 16)
OPS = size(1000, 20000)  # per thread; each op = one write and one read back


def _od():
    od = ObjectDictionary()
    for t in range(THREADS):
        od.add_variable(0x2000 + t, f"U32 {t}", "u32", "rw", default=0)   # expedited
        od.add_variable(0x3000 + t, f"Str {t}", "VISIBLE_STRING", "rw", default="")  # segmented
    return od


def _hammer(sdo):
    """THREADS threads, each on its own objects; returns (ok, wrong, errors)."""
    ok = [0] * THREADS
    wrong = []
    errors = []
    start = threading.Barrier(THREADS)

    def worker(t):
        start.wait()
        for i in range(OPS):
            value = (t << 24) | i
            try:
                if i % 4 == 3:  # every 4th op segmented (a 9-20 byte string)
                    text = f"t{t}-op{i}-" + "x" * (i % 8)
                    sdo.write_string(0x3000 + t, 0, text)
                    got = sdo.read_string(0x3000 + t, 0)
                    expected = text
                else:
                    sdo.write_u32(0x2000 + t, 0, value)
                    got = sdo.read_u32(0x2000 + t, 0)
                    expected = value
            except motorbus.MotorbusError as e:  # typed: counted, and there should be none
                errors.append((t, i, repr(e)))
                continue
            except BaseException as e:  # noqa: BLE001 - an untyped failure is a defect
                errors.append((t, i, "UNTYPED " + repr(e)))
                continue
            if got == expected:
                ok[t] += 1
            else:
                wrong.append((t, i, expected, got))

    threads = [threading.Thread(target=worker, args=(t,), daemon=True) for t in range(THREADS)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(timeout=600)
    assert not any(th.is_alive() for th in threads), "an SDO worker hung"
    return ok, wrong, errors


def _check(sdo, node, od, ok, wrong, errors):
    assert errors == [], errors[:10]
    assert wrong == [], wrong[:10]
    assert ok == [OPS] * THREADS
    # Every thread's last value is what the dictionary holds: nothing crossed over.
    for t in range(THREADS):
        last = OPS - 1 if (OPS - 1) % 4 != 3 else OPS - 2
        assert od[0x2000 + t].value == (t << 24) | last
    assert sdo.counters.transfers == 2 * THREADS * OPS
    assert sdo.counters.timeouts == 0 and sdo.counters.aborts_received == 0
    assert node.counters.sdo.dropped == 0


@pytest.mark.parametrize("transport", ["virtual", "socketcand"])
def test_many_threads_one_sdo_client_one_node(transport):
    name = hub("rel-sdo")
    dev = motorbus.open_bus(f"virtual:{name}")
    od = _od()
    node = LocalNode(dev, 7, od, sdo_timeout=5.0)
    server = host = None
    try:
        if transport == "virtual":
            host = motorbus.open_bus(f"virtual:{name}")
        else:
            server = SocketcandServer(motorbus.open_bus(f"virtual:{name}"), host="127.0.0.1", port=0)
            host = open_socketcand("127.0.0.1", server.port, "can0")
        sdo = SdoClient(host, 7, timeout=5.0)
        ok, wrong, errors = _hammer(sdo)
        _check(sdo, node, od, ok, wrong, errors)
        print(f"\n[sdo-concurrency {transport}] {THREADS} threads x {OPS} ops: "
              f"{sdo.counters.transfers} transfers, 0 lost, 0 wrong, 0 errors")
    finally:
        node.close()
        if host is not None:
            host.close()
        if server is not None:
            server.close()
        dev.close()

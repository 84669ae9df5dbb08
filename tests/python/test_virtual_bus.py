import threading
import time

import pytest

import motorbus
from motorbus import Frame


def test_open_bus_virtual_roundtrip_and_counters():
    with motorbus.open_bus("virtual:py-basic") as a, motorbus.open_bus("virtual:py-basic") as b:
        a.send(Frame(0x123, b"\x01\x02"))
        f = b.recv(1.0)
        assert f == Frame(0x123, b"\x01\x02")
        assert f.timestamp_ns > 0
        assert b.recv(0.01) is None
        assert a.counters.tx_frames == 1 and b.counters.rx_frames == 1
        assert a.state == "active"
    assert a.closed and a.state == "closed"


def test_counters_count_wire_bits_of_what_passes_but_not_own_echoes():
    # 0x123 with 2 bytes: 47 + 16 bits + (34 + 16 - 1) // 4 = 12 stuff bits (worst case) = 75;
    # an 8-byte extended frame: 67 + 64 + (54 + 64 - 1) // 4 = 29 -> 160.
    std, ext = Frame(0x123, b"\x01\x02"), Frame(0x1ABCDE, bytes(8), extended=True)
    assert motorbus._core.can.wire_bits_worst_case(std) == 75
    assert motorbus._core.can.wire_bits_worst_case(ext) == 160
    with motorbus.open_bus("virtual:py-bits", receive_own=True) as a, motorbus.open_bus("virtual:py-bits") as b:
        a.send(std)
        b.send(ext)
        assert b.recv(1.0) == std
        assert a.recv(1.0) is not None and a.recv(1.0) is not None     # the echo of std, then ext
        assert a.counters.tx_bits == 75 and b.counters.rx_bits == 75
        assert b.counters.tx_bits == 160 and a.counters.rx_bits == 160   # the echo is not on the wire twice


def test_bad_specs_name_the_problem():
    with pytest.raises(motorbus.InvalidArgument, match=r"unknown bus scheme .nope. \(registered: .*virtual"):
        motorbus.open_bus("nope:x")
    with pytest.raises(motorbus.InvalidArgument, match="SCHEME:ARGS"):
        motorbus.open_bus("virtual")
    with pytest.raises(motorbus.InvalidArgument, match="port"):
        motorbus.open_bus("socketcand:localhost:abc/can0")


@pytest.mark.threaded
def test_subscriber_callback_runs_on_bus_thread():
    seen = []
    done = threading.Event()
    with motorbus.open_bus("virtual:py-sub") as a, motorbus.open_bus("virtual:py-sub") as b:
        def cb(frame):
            seen.append((frame.id, frame.data, threading.current_thread() is threading.main_thread()))
            if len(seen) == 2:
                done.set()

        h = b.subscribe(cb, id=0x581)
        a.send(Frame(0x581, b"\xAA"))
        a.send(Frame(0x582, b"\xBB"))
        a.send(Frame(0x581, b"\xCC"))
        assert done.wait(2.0)
        assert seen == [(0x581, b"\xAA", False), (0x581, b"\xCC", False)]
        b.unsubscribe(h)


@pytest.mark.threaded
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_callback_exception_does_not_kill_the_bus():
    with motorbus.open_bus("virtual:py-exc") as a, motorbus.open_bus("virtual:py-exc") as b:
        b.subscribe(lambda f: 1 / 0)
        a.send(Frame(1))
        a.send(Frame(2))
        assert b.recv(1.0).id == 1
        assert b.recv(1.0).id == 2


def test_filters_python_can_style():
    with motorbus.open_bus("virtual:py-filt") as a, motorbus.open_bus("virtual:py-filt") as b:
        b.set_filters([{"can_id": 0x100, "can_mask": 0x700, "extended": False}])
        for i in (0x123, 0x223, 0x1FF):
            a.send(Frame(i))
        a.send(Frame(0x123, extended=True))
        assert [b.recv(1.0).id, b.recv(1.0).id] == [0x123, 0x1FF]
        assert b.recv(0.02) is None


def test_faults_drop_every_nth():
    with motorbus.open_bus("virtual:py-fault") as a, motorbus.open_bus("virtual:py-fault") as b:
        a.set_faults(drop_every=2)
        for i in range(6):
            a.send(Frame(i))
        got = []
        while (f := b.recv(0.05)) is not None:
            got.append(f.id)
        assert got == [0, 2, 4]
        assert a.counters.tx_dropped == 3


def test_wire_time_mode_paces_frames():
    with motorbus.open_bus("virtual:py-wire", bitrate=125000) as a, \
            motorbus.open_bus("virtual:py-wire", bitrate=125000) as b:
        assert a.bitrate == 125000
        for _ in range(10):
            a.send(Frame(0x10, bytes(8)))
        ts = [b.recv(2.0).timestamp_ns for _ in range(10)]
        # 135 bits worst case at 8 us/bit
        assert all(t2 - t1 == 135 * 8000 for t1, t2 in zip(ts, ts[1:]))


@pytest.mark.threaded
def test_recv_releases_the_gil():
    with motorbus.open_bus("virtual:py-gil") as a, motorbus.open_bus("virtual:py-gil") as b:
        def later():
            time.sleep(0.05)
            a.send(Frame(7))

        t = threading.Thread(target=later)
        t.start()
        f = b.recv(2.0)  # would deadlock if recv held the GIL
        t.join()
        assert f.id == 7


def test_bus_off_raises_link_down():
    with motorbus.open_bus("virtual:py-off") as a:
        a.set_bus_off(True)
        assert a.state == "bus-off"
        with pytest.raises(motorbus.LinkDown):
            a.send(Frame(1))
        with pytest.raises(ConnectionError):
            a.send(Frame(1))


@pytest.mark.threaded
@pytest.mark.parametrize("rx_spin", [0.0, 20e-6])
def test_receive_polling_option_delivers_every_callback(rx_spin):
    # rx_spin only changes how the endpoint's receive thread waits, never what it delivers
    got = []
    done = threading.Event()
    name = f"virtual:py-spin{rx_spin}"
    with motorbus.open_bus(name, rx_spin=rx_spin) as a, motorbus.open_bus(name, rx_spin=rx_spin) as b:
        def cb(frame):
            got.append(frame.data[0])
            if len(got) == 200:
                done.set()

        b.subscribe(cb, id=0x42)
        for i in range(200):
            a.send(Frame(0x42, bytes([i])))
        assert done.wait(5.0)
    assert got == list(range(200))


def test_receive_polling_must_not_be_negative():
    with pytest.raises(motorbus.InvalidArgument, match="rx_spin"):
        motorbus.open_bus("virtual:py-negspin", rx_spin=-1.0)


def test_recv_many_drains_in_order_and_times_out_empty():
    with motorbus.open_bus("virtual:py-many") as a, motorbus.open_bus("virtual:py-many") as b:
        assert b.recv_many(10, timeout=0.01) == []
        for i in range(5):
            a.send(Frame(0x100 + i, bytes([i])))
        first = b.recv_many(3, timeout=1.0)
        rest = b.recv_many(timeout=1.0)
        assert [f.id for f in first] == [0x100, 0x101, 0x102]
        assert [(f.id, f.data) for f in rest] == [(0x103, b"\x03"), (0x104, b"\x04")]
    with pytest.raises(motorbus.ClosedError):
        b.recv_many(timeout=0.1)

"""motorbus.Poller against simulated drives behind real transports (Arcus on a pty,
CiA 402 and UNITEK over socketcand on 127.0.0.1): the frame follows the drives while they
move, one row per deadline, late/missed samples counted and shown as NaN, a lost
link ends only its group, overflow counted, .npz/.csv round trips, candump; drives
that push (TPDOs, cyclic registers) are captured: values, arrival times, stale pushes."""
from __future__ import annotations

import time

import numpy as np
import pytest

import motorbus
from motorbus import Bench, Poller, load_frame


def _bench(**extra_axes):
    axes = {
        "x": {"kind": "arcus", "line": "rs485", "address": 1, "units": {"name": "mm", "scale": 0.0025}},
        "y": {"kind": "arcus", "line": "rs485", "address": 2},
        "z": {"kind": "cia402", "bus": "can0", "address": 5, "units": {"name": "deg", "scale": 0.1}},
    }
    axes.update(extra_axes)
    return Bench.from_dict({"line": {"rs485": {"port": "/dev/ttyUSB-poller-test"}},
                            "bus": {"can0": {"spec": "socketcan:can0"}}, "axis": axes}, sim=True)


def _prepare(bench):
    for name, d in bench.axes.items():
        d.enable()
        if d.kind == "arcus":
            d.params["HSPD"] = 20000
            d.params["ACC"] = 20
        else:
            d.params["0x6081"] = 20000
            d.params["0x6083"] = 400000
            d.params["0x6084"] = 400000


def _finite(a):
    return a[~np.isnan(a)]


def test_frame_follows_moving_drives_in_user_units():
    with _bench() as bench:
        _prepare(bench)
        x, z = bench["x"], bench["z"]
        with Poller(bench.axes, rate_hz=200, mode="ask") as poller:
            time.sleep(0.05)
            x.move_to(10.0)            # 4000 counts at 20000 counts/s: ~0.2 s
            z.move_to(300.0)           # 3000 increments
            x.wait_idle(timeout=10)
            z.wait_idle(timeout=10)
            time.sleep(0.1)
        frame = poller.frame()
        assert set(frame) == set(poller.columns)
        assert poller.columns[:5] == ["t", "x.t", "x.position", "x.velocity", "x.status"]
        for axis, drive in (("x", x), ("z", z)):
            pos = _finite(frame[f"{axis}.position"])
            assert len(pos) > 20
            assert np.all(np.diff(pos) >= 0), f"{axis}: position went back during a forward move"
            assert pos[0] == pytest.approx(0.0, abs=1e-9)
            assert pos[-1] == pytest.approx(drive.position, abs=1e-9)   # user units, the drive's own reading
            inside = pos[(pos > 0) & (pos < drive.position)]
            assert len(inside) >= 3, f"{axis}: no sample caught the move under way"
        # Velocity in user units: x's PS of 20000 counts/s is 50 mm/s at full speed.
        assert np.nanmax(frame["x.velocity"]) == pytest.approx(50.0, rel=0.05)
        assert np.nanmax(frame["z.velocity"]) == pytest.approx(2000.0, rel=0.05)   # 20000 inc/s * 0.1
        # Status: the raw words, unscaled: the last sample is what the drive says now.
        assert frame["x.status"][~np.isnan(frame["x.status"])][-1] == x.native.query("MST")
        assert frame["z.status"][~np.isnan(frame["z.status"])][-1] == z._sdo.read_u16(0x6041)
        # One row per deadline, on the asked period; each group's own timestamps increase.
        t = frame["t"]
        assert np.all(np.diff(t) > 0)
        assert np.allclose(np.diff(t), 0.005)
        for axis in ("x", "y", "z"):
            taken = ~np.isnan(frame[f"{axis}.t"])
            ts, deadlines = frame[f"{axis}.t"][taken], t[taken]
            assert np.all(np.diff(ts) > 0)
            # Each sample starts inside its own period: never before its deadline, never a period late...
            assert np.all(ts >= deadlines) and np.all(ts < deadlines + 0.005)
            # ...so over the run the samples keep the asked period on average (no drift), misses or not.
            assert (ts[-1] - ts[0]) / (deadlines[-1] - deadlines[0]) == pytest.approx(1.0, abs=0.05)
        # Two groups: the line of x and y, the bus of z.
        stats = poller.stats
        assert sorted(stats) == ["x+y", "z"]
        assert stats["x+y"]["transport"] == "serial" and stats["z"]["transport"] == "can"
        for s in stats.values():
            assert s["error"] == "" and not s["running"] and s["samples"] > 40
            rows = s["samples"] + s["missed"]
            assert rows == len(frame["t"]) or rows == len(frame["t"]) - 1 or rows == len(frame["t"]) + 1


def test_read_returns_only_new_rows_and_frame_all_of_them():
    with _bench() as bench:
        with Poller({"x": bench["x"], "z": bench["z"]}, fields=("position",), rate_hz=500) as poller:
            time.sleep(0.1)
            first = poller.read()
            time.sleep(0.1)
            second = poller.read()
        rest = poller.read()
        frame = poller.frame()
    assert list(first) == ["t", "x.t", "x.position", "z.t", "z.position"]
    assert len(first["t"]) > 10 and len(second["t"]) > 10
    joined = np.concatenate([first["t"], second["t"], rest["t"]])
    assert np.all(np.diff(joined) > 0), "a deadline came twice across reads"
    np.testing.assert_array_equal(frame["t"], joined)


def test_a_rate_the_line_cannot_carry_counts_late_and_missed_samples_as_nan_rows():
    # Six ASCII transactions on one pty line per sample cannot fit in 50 µs.
    with _bench() as bench:
        with Poller({"x": bench["x"], "y": bench["y"]}, rate_hz=20000) as poller:
            time.sleep(0.3)
        s = poller.stats["x+y"]
        frame = poller.frame()
    assert s["late"] > 10 and s["missed"] > 10
    missed_rows = np.isnan(frame["x.position"])
    assert int(missed_rows.sum()) == s["missed"]
    assert np.all(np.isnan(frame["x.t"][missed_rows]))
    assert s["read_time_p50"] > 50e-6
    assert len(frame["t"]) == s["samples"] + s["missed"]


@pytest.mark.parametrize("lose", ["line", "bus"])
def test_a_lost_link_ends_its_group_with_the_error_and_the_other_goes_on(lose):
    bench = _bench()
    try:
        with Poller(bench.axes, rate_hz=200) as poller:
            time.sleep(0.1)
            gone, other = ("x+y", "z") if lose == "line" else ("z", "x+y")
            kind = motorbus._core.serial.PtyLineServer if lose == "line" else motorbus.bus_server.BusServers
            for srv in [s for s in bench._servers if isinstance(s, kind)]:
                srv.close()
            deadline = time.monotonic() + 5
            while poller.stats[gone]["running"] and time.monotonic() < deadline:
                time.sleep(0.01)
            stats = poller.stats
            assert not stats[gone]["running"]
            assert stats[gone]["error_type"] in ("LinkDown", "TimeoutError"), stats[gone]
            if lose == "bus":   # z is captured (it sends nothing per sample): its source checks the bus
                assert stats[gone]["captured"] == ["z"] and stats[gone]["error_type"] == "LinkDown", stats[gone]
            assert stats[gone]["error"]
            before = stats[other]["samples"]
            time.sleep(0.1)
            assert poller.stats[other]["running"] and poller.stats[other]["samples"] > before
            t0 = time.monotonic()
        assert time.monotonic() - t0 < 2.0, "stop() took too long"
        assert not poller.running
    finally:
        bench.close()


def test_lost_serial_link_is_linkdown():
    bench = _bench()
    try:
        with Poller({"x": bench["x"]}, rate_hz=200) as poller:
            time.sleep(0.05)
            for srv in [s for s in bench._servers if isinstance(s, motorbus._core.serial.PtyLineServer)]:
                srv.close()
            deadline = time.monotonic() + 5
            while poller.running and time.monotonic() < deadline:
                time.sleep(0.01)
        assert poller.stats["x"]["error_type"] == "LinkDown"
    finally:
        bench.close()


def test_a_tiny_ring_counts_what_the_reader_lost():
    with _bench() as bench:
        with Poller({"z": bench["z"]}, fields=("position",), rate_hz=500, capacity=8) as poller:
            time.sleep(0.2)
        s = poller.stats["z"]
        frame = poller.frame()
    assert len(frame["t"]) == 8
    assert s["overflowed"] == s["samples"] + s["missed"] - 8 > 0


def test_save_npz_and_csv_round_trip(tmp_path):
    with _bench() as bench:
        with Poller(bench.axes, rate_hz=200) as poller:
            time.sleep(0.1)
        frame = poller.frame()
        poller.save(tmp_path / "run.npz")
        poller.save(tmp_path / "run.csv")
    for name in ("run.npz", "run.csv"):
        back = load_frame(tmp_path / name)
        assert list(back) == list(frame)
        for k in frame:
            np.testing.assert_array_equal(back[k], frame[k], err_msg=f"{name}: {k}")
    assert (tmp_path / "run.csv").read_text().splitlines()[0].startswith("t,x.t,x.position,")
    with pytest.raises(motorbus.InvalidArgument, match=".npz or .csv"):
        poller.save(tmp_path / "run.txt")


def test_candump_records_the_sdo_traffic_of_the_poll(tmp_path):
    log = tmp_path / "poll.log"
    with _bench() as bench:
        with Poller({"z": bench["z"]}, fields=("position", "status"), rate_hz=200, candump=log,
                    mode="ask") as poller:
            time.sleep(0.1)
        samples = poller.stats["z"]["samples"]
    entries, bad = motorbus.read_log(str(log))
    assert bad == 0
    responses = [bytes(e.frame.data) for e in entries if e.frame.id == 0x585]
    # One expedited upload response per object per sample: 6064h (4 bytes) and 6041h (2 bytes).
    position = [r for r in responses if r[:4] == bytes([0x43, 0x64, 0x60, 0x00])]
    status = [r for r in responses if r[:4] == bytes([0x4B, 0x41, 0x60, 0x00])]
    assert abs(len(position) - samples) <= 1 and abs(len(status) - samples) <= 1


def test_bad_arguments_are_named():
    with _bench() as bench:
        for kwargs, says in [(dict(rate_hz=0), "rate_hz"), (dict(fields=("torque",)), "torque"),
                             (dict(fields=()), "at least one"), (dict(capacity=0), "capacity"),
                             (dict(spin_us=5000), "spin_us"), (dict(fields=("position", "position")), "once")]:
            with pytest.raises(motorbus.InvalidArgument, match=says):
                Poller(bench.axes, **kwargs)
        with pytest.raises(motorbus.InvalidArgument, match="at least one axis"):
            Poller([])
        with pytest.raises(motorbus.InvalidArgument, match="twice"):
            Poller([bench["x"], bench["x"]])
        with pytest.raises(motorbus.InvalidArgument, match="a motorbus.Drive"):
            Poller({"q": 5})
        with pytest.raises(motorbus.InvalidArgument, match="mode"):
            Poller(bench.axes, mode="push")
        with pytest.raises(motorbus.InvalidArgument, match="'x' \\(arcus\\) cannot push"):
            Poller(bench.axes, mode="capture")
        p = Poller(bench["z"], start=False)
        p.start()
        with pytest.raises(motorbus.InvalidArgument, match="already started"):
            p.start()
        p.stop()


@pytest.mark.parametrize("kind,address,transport", [("dmac", "00", "line"), ("pmc007", "5", "bus"),
                                                     ("arcus-canopen", "1", "bus")])
def test_other_kinds_poll_their_own_objects(kind, address, transport):
    link = {"line": "l1"} if transport == "line" else {"bus": "can0"}
    bench = Bench.from_dict({"line": {"l1": {"port": "/dev/ttyUSB-poller-other"}},
                             "bus": {"can0": {"spec": "socketcan:can0"}},
                             "axis": {"q": {"kind": kind, "address": address, **link}}}, sim=True)
    with bench:
        q = bench["q"]
        q.enable()
        fields = ("position", "status") if kind == "pmc007" else ("position", "velocity", "status")
        with Poller(bench.axes, fields=fields, rate_hz=20) as poller:
            q.move_by(500)
            q.wait_idle(timeout=20)
            time.sleep(0.3)
        frame = poller.frame()
        assert poller.stats["q"]["error"] == ""
        # The PMC007 maps 600Ch and 6001h into TPDOs: captured; the DMX-CAN has no PDOs, DMAC is ASCII.
        assert poller.modes == {"q": "capture" if kind == "pmc007" else "ask"}
        pos = _finite(frame["q.position"])
        assert len(pos) >= 3
        assert np.all(np.diff(pos) >= 0)
        assert pos[-1] == pytest.approx(q.position)
        if kind == "pmc007":
            with pytest.raises(motorbus.InvalidArgument, match="velocity"):
                Poller(bench.axes, fields=("velocity",))


def _can_bench():
    return Bench.from_dict({"bus": {"can0": {"spec": "socketcan:can0"}},
                            "axis": {"z": {"kind": "cia402", "bus": "can0", "address": 5,
                                           "units": {"name": "deg", "scale": 0.1}},
                                     "u": {"kind": "unitek", "bus": "can0", "address": "0x201",
                                           "sim": {"calibrated": True}}}}, sim=True)


def _prepare_can(bench):
    z, u = bench["z"], bench["u"]
    for d in (z, u):
        d.enable()
    z.params["0x6081"] = 20000
    z.params["0x6083"] = 400000
    z.params["0x6084"] = 400000
    u.params["ACC_RAMP"] = 20


def test_captured_values_are_what_the_drives_hold_during_and_after_a_move():
    with _can_bench() as bench:
        _prepare_can(bench)
        z, u = bench["z"], bench["u"]
        with Poller(bench.axes, rate_hz=200) as poller:
            assert poller.modes == {"z": "capture", "u": "capture"}
            time.sleep(0.05)
            z.move_to(300.0)            # 3000 increments at 20000 inc/s
            u.move_by(20000)            # counts
            z.wait_idle(timeout=10)
            u.wait_idle(timeout=10)
            time.sleep(0.1)             # a few pushes after the stop
            during = poller.read()
        frame = poller.frame()
        stats = poller.stats["z+u"]
        assert stats["captured"] == ["z", "u"] and stats["error"] == ""
        for axis, drive in (("z", z), ("u", u)):
            pos = _finite(frame[f"{axis}.position"])
            assert len(pos) > 20
            assert pos[-1] == pytest.approx(drive.position, abs=1e-9), axis   # the drive's own reading now
            inside = pos[(pos > pos[0]) & (pos < drive.position)]
            assert len(inside) >= 3, f"{axis}: no captured sample caught the move under way"
            assert np.all(np.diff(pos) >= 0)
            status = _finite(frame[f"{axis}.status"])
            assert status[-1] == drive.status.raw
        assert z.position == pytest.approx(300.0)
        assert np.nanmax(frame["z.velocity"]) == pytest.approx(2000.0, rel=0.05)   # 20000 inc/s * 0.1
        assert np.nanmax(frame["u.velocity"]) > 0
        assert frame["u.velocity"][~np.isnan(frame["u.velocity"])][-1] == 0.0
        # <axis>.t is when the pushed frame arrived: never after the sample that took it was due
        # to end, never repeating a newer one's time backwards, and before the first push NaN.
        for axis in ("z", "u"):
            ts = frame[f"{axis}.t"]
            got = ~np.isnan(ts)
            assert np.all(np.diff(ts[got]) >= 0)
            assert np.all(ts[got] <= frame["t"][got] + 0.005)
            # The data's age stays within the push period + scheduling: fresh data, not the poll's clock.
            assert np.median(frame["t"][got] - ts[got]) < 0.010
            assert len(np.unique(ts[got])) > 20, f"{axis}: the arrival times do not follow the pushes"
        assert len(during["t"]) > 0
    # The drives stopped transmitting when the Poller stopped: the TPDO is disabled again.
    # (checked on a running bench below)


def test_a_push_that_stops_is_counted_stale_and_its_age_shows():
    with _can_bench() as bench:
        _prepare_can(bench)
        u = bench["u"]
        with Poller({"u": u}, fields=("position",), rate_hz=200) as poller:
            time.sleep(0.15)
            before = poller.stats["u"]["stale"]
            # The C++ client's own unsubscribe, behind the Python stream bookkeeping: the drive stops pushing.
            motorbus._core.unitek.Client.unsubscribe(u.native, int(motorbus.drives.unitek.Reg.POS_IST))
            time.sleep(0.2)
        stats = poller.stats["u"]
        frame = poller.frame()
    # The first samples before the first push count as stale; then none until the push stops.
    assert before <= 3
    # 0.2 s at 200 Hz after the stop, less the 3 periods + 2 ms of grace: ~35 stale samples
    # (fewer when a loaded machine makes the thread miss deadlines: those rows are NaN, not stale).
    assert stats["stale"] - before >= 15
    ts, t = frame["u.t"], frame["t"]
    last = ts[-1]
    assert not np.isnan(last)
    frozen = ts == last
    assert frozen.sum() >= 15, "the arrival time kept moving although nothing arrived"
    assert t[-1] - last > 0.15   # the age of the data shows in the frame
    # The last value is still given (it is the drive's last word), not NaN.
    assert not np.isnan(frame["u.position"][-1])


def test_capture_sends_nothing_per_sample_and_stops_the_pushes_at_stop(tmp_path):
    log = tmp_path / "capture.log"
    with _can_bench() as bench:
        _prepare_can(bench)
        z, u = bench["z"], bench["u"]
        with Poller(bench.axes, rate_hz=100, candump=log) as poller:
            time.sleep(0.3)
        samples = poller.stats["z+u"]["samples"]
        time.sleep(0.1)
        # After stop the drives no longer push: a new listener hears nothing of them.
        rx = motorbus._core.canopen.PdoReceiver(z.native.bus, 0x185, [(0x6064, 0, 32)])
        time.sleep(0.1)
        assert rx.received == 0, "the TPDO still flows after the Poller stopped"
        assert not u.native.cyclic
    entries, bad = motorbus.read_log(str(log))
    assert bad == 0
    sdo_requests = [e for e in entries if e.frame.id == 0x605]
    unitek_requests = [e for e in entries if e.frame.id == 0x201 and bytes(e.frame.data)[:1] == b"\x3d"]
    tpdos = [e for e in entries if e.frame.id in (0x185, 0x285)]
    pushes = [e for e in entries if e.frame.id == 0x181]
    assert samples > 20
    assert len(sdo_requests) < 20 and len(unitek_requests) < 10, "the capture asked per sample"
    assert len(tpdos) >= samples and len(pushes) >= samples   # ~one per 10 ms each


def test_mode_ask_reads_unitek_registers_each_sample(tmp_path):
    with _can_bench() as bench:
        _prepare_can(bench)
        u = bench["u"]
        with Poller({"u": u}, rate_hz=100, mode="ask") as poller:
            assert poller.modes == {"u": "ask"}
            u.move_by(5000)
            u.wait_idle(timeout=10)
            time.sleep(0.1)
        frame = poller.frame()
        assert poller.stats["u"]["stale"] == 0 and poller.stats["u"]["captured"] == []
        pos = _finite(frame["u.position"])
        assert pos[-1] == pytest.approx(u.position)
        assert _finite(frame["u.status"])[-1] == u.status.raw
        assert not u.native.cyclic


def test_a_lost_link_ends_a_captured_unitek_group_with_linkdown():
    bench = _can_bench()
    try:
        bench["u"].enable()
        with Poller({"u": bench["u"]}, rate_hz=200) as poller:
            time.sleep(0.1)
            assert poller.stats["u"]["running"] and poller.stats["u"]["captured"] == ["u"]
            for srv in [s for s in bench._servers if isinstance(s, motorbus.bus_server.BusServers)]:
                srv.close()
            deadline = time.monotonic() + 5
            while poller.running and time.monotonic() < deadline:
                time.sleep(0.01)
            t0 = time.monotonic()
        assert time.monotonic() - t0 < 2.0, "stop() took too long"
        s = poller.stats["u"]
        assert not s["running"] and s["error_type"] == "LinkDown" and "down" in s["error"], s
    finally:
        bench.close()

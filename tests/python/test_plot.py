"""motorbus.plot: bus load from a candump log of known frames (numbers computed by
hand from the frames' bit lengths), exact stuffing of a frame worked by hand, and a
simulated CiA 402 axis (served over socketcand) polled while moving, plotted against
its kind's own profile model."""
from __future__ import annotations

import sys
import time

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import motorbus  # noqa: E402
from motorbus import Bench, Poller, _core, plot  # noqa: E402


def test_bus_load_of_known_frames_matches_the_hand_count(tmp_path):
    log = tmp_path / "known.log"
    log.write_text(
        "(100.000000) can0 200#0000000000000000\n"   # standard, 8 bytes: 47 + 64 + (34 + 64 - 1) // 4 = 135 bits
        "(100.040000) can0 201#0102\n"               # standard, 2 bytes: 47 + 16 + (34 + 16 - 1) // 4 = 75
        "(100.150000) can0 12345678#\n"              # extended, 0 bytes: 67 + 0 + (54 - 1) // 4 = 80
        "(100.290000) can0 7FF#R\n")                 # remote, standard: 47 + 33 // 4 = 55
    fig, n = plot.bus_load(str(log), bitrate=125_000, window=0.1)
    assert n["count"] == 4 and n["stuffing"] == "worst"
    assert list(n["bits"]) == [135 + 75, 80, 55]
    assert list(n["frames"]) == [2, 1, 1]
    assert n["load"] == pytest.approx([210 / 12_500 * 100, 80 / 12_500 * 100, 55 / 12_500 * 100])
    assert n["peak"] == pytest.approx(1.68)
    assert n["mean"] == pytest.approx(345 / (125_000 * 0.3) * 100)
    assert n["t"] == pytest.approx([0.0, 0.1, 0.2])
    out = tmp_path / "load.png"
    fig.savefig(out)
    assert out.stat().st_size > 5000


def test_exact_stuffing_of_an_all_zero_frame():
    # id 0, no data: SOF..CRC are 34 dominant bits (the CRC of zeros is 0): a stuff bit
    # after the 5th, 10th, ... 30th = 6, so 34 + 6 + 13 = 53 (worst case says 55).
    f = _core.can.Frame(0, b"")
    assert plot.frame_bits(f, "exact") == 53
    assert plot.frame_bits(f, "worst") == 55
    assert plot.frame_bits(f, "none") == 47
    # Exact never exceeds the worst case nor falls below the unstuffed length.
    rng = np.random.default_rng(1)
    for _ in range(200):
        ext = bool(rng.integers(2))
        fr = _core.can.Frame(int(rng.integers(1 << (29 if ext else 11))), rng.integers(0, 256, rng.integers(9)).astype(np.uint8).tobytes(),
                             extended=ext)
        assert plot.frame_bits(fr, "none") <= plot.frame_bits(fr, "exact") <= plot.frame_bits(fr, "worst")
    with pytest.raises(motorbus.InvalidArgument, match="stuffing"):
        plot.frame_bits(f, "some")
    with pytest.raises(motorbus.InvalidArgument, match="bitrate"):
        plot.load_numbers([], bitrate=0)


def test_polled_axis_against_its_planned_profile(tmp_path):
    bench = Bench.from_dict({"bus": {"can0": {"spec": "socketcan:can0"}},
                             "axis": {"z": {"kind": "cia402", "bus": "can0", "address": 5,
                                            "units": {"name": "mm", "scale": 0.01}}}}, sim=True)
    with bench:
        z = bench["z"]
        z.enable()
        z.params["0x6081"] = 20000
        z.params["0x6083"] = 100000
        z.params["0x6084"] = 100000
        plan = plot.planned(z, 0.0, 50.0)          # 5000 increments: 0.2 s ramp up, 0.05 s cruise, 0.2 s down
        assert plan["p"][-1] == pytest.approx(50.0) and plan["t"][-1] == pytest.approx(0.45, abs=1e-6)
        with Poller(bench.axes, rate_hz=500, mode="ask") as poller:   # asked: read-time bound (see below)
            time.sleep(0.05)
            t_cmd = motorbus.monotonic_ns() / 1e9
            z.move_to(50.0)
            z.wait_idle(timeout=10)
            time.sleep(0.05)
        frame = poller.frame()
    c = plot.compare(frame, "z", plan, t_cmd)
    moving = (c["t"] > 0.02) & (c["t"] < 0.43)
    assert moving.sum() > 50
    assert c["measured"][-1] == pytest.approx(50.0)
    # Measured follows the plan once the command's latency (the SDO writes and the
    # controlword handshake; tens of ms on a loaded machine) is taken out: the best lag
    # is >= 0 (the drive cannot start before the command; a sample is stamped when its
    # read starts, so up to one read time earlier) and leaves little error.
    read_time = max(g["read_time_max"] for g in poller.stats.values())   # a sample's value comes this late
    lags = np.arange(-0.02, 0.2, 0.0005)
    worst = [np.max(np.abs(plot.compare(frame, "z", plan, t_cmd + lag)["error"])) for lag in lags]
    best = int(np.argmin(worst))
    assert lags[best] >= -(read_time + 0.001), (lags[best], read_time)
    # mm, on a 50 mm move at up to 200 mm/s: what one sample's read time allows at full speed
    assert worst[best] < 200.0 * (read_time + 0.002) + 0.5, (lags[best], worst[best], read_time)
    assert worst[0] > worst[best]                            # and the comparison does see timing
    ax_p, ax_v = plot.profile(frame, "z", plan, t0=t_cmd, velocity=True, units="mm")
    lines = ax_p.get_lines()
    assert [ln.get_label() for ln in lines] == ["z measured", "z planned"]
    assert np.nanmax(lines[0].get_ydata()) == pytest.approx(50.0)
    assert np.max(ax_v.get_lines()[1].get_ydata()) == pytest.approx(200.0, rel=1e-6)   # 20000 inc/s * 0.01
    png = tmp_path / "z.png"
    ax_p.figure.savefig(png)
    assert png.stat().st_size > 10_000
    with pytest.raises(motorbus.InvalidArgument, match="no column 'q.position'"):
        plot.compare(frame, "q", plan, t_cmd)


def test_missing_matplotlib_is_a_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(plot.MatplotlibMissing, match=r"pip install 'motorbus\[plot\]'"):
        plot.profile({"t": np.zeros(1), "z.position": np.zeros(1)}, "z")


def _demo_axis_bench(axis: str) -> Bench:
    """One axis of the demo's bench file (python/motorbus/demo_bench.toml) as its simulated twin."""
    import tomllib

    from motorbus.bench_demo import DEFAULT_BENCH

    with open(DEFAULT_BENCH, "rb") as f:
        data = tomllib.load(f)
    cfg = data["axis"][axis]
    keep = {"axis": {axis: cfg}}
    if "line" in cfg:
        keep["line"] = {cfg["line"]: data["line"][cfg["line"]]}
    else:
        keep["bus"] = {cfg["bus"]: data["bus"][cfg["bus"]]}
    return Bench.from_dict(keep, sim=True)


@pytest.mark.parametrize("axis,target", [("x", 10.0), ("rot", 360.0), ("tilt", 10.0), ("feed", 20.0)])
def test_each_kinds_plan_move_is_what_its_simulator_does(axis, target):
    """plan_move of arcus, dmac, arcus-canopen and pmc007 (cia402: the test above) against
    the kind's simulator over its real transport: once the command latency is taken out,
    the measured position stays within what one sample's read time allows at full speed.
    The poller asks (mode="ask") so that every sample's value was taken within its read:
    a captured TPDO is stamped on arrival, and its delivery delay (scheduling on a loaded
    host, a sanitizer) is not a property of the plan."""
    with _demo_axis_bench(axis) as bench:
        d = bench[axis]
        d.enable()
        bench.apply()
        start = d.position
        plan = plot.planned(d, start, target)
        assert plan["p"][0] == pytest.approx(start) and plan["p"][-1] == pytest.approx(target)
        with Poller(bench.axes, ("position",), rate_hz=1000, mode="ask") as poller:
            time.sleep(0.05)
            t_cmd = motorbus.monotonic_ns() / 1e9
            d.move_to(target)
            d.wait_idle(timeout=20)
            time.sleep(0.05)
        frame = poller.frame()
        read_time = max(g["read_time_max"] for g in poller.stats.values())
    vmax = np.max(np.abs(plan["v"]))
    lags = np.arange(-0.03, 0.2, 0.0005)
    worst = [np.max(np.abs(plot.compare(frame, axis, plan, t_cmd + lag)["error"])) for lag in lags]
    best = int(np.argmin(worst))
    c = plot.compare(frame, axis, plan, t_cmd + lags[best])
    assert c["measured"][-1] == pytest.approx(target, abs=1e-6)
    assert lags[best] >= -(read_time + 0.001), (lags[best], read_time)
    # The plan's duration is the drive's: the move ends when the plan says (within the sampling).
    ends = c["t"][np.argmax(np.abs(c["measured"] - target) < 1e-9)]
    assert ends == pytest.approx(plan["t"][-1], abs=read_time + 0.01)
    assert worst[best] < vmax * (read_time + 0.002) + 0.01 * abs(target - start), (axis, lags[best], worst[best])

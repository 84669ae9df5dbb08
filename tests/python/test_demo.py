"""The README's demo runs end to end (quick mode) and shows what it claims."""
import re
import subprocess
import sys
import textwrap

import pytest

from motorbus import registry


def test_demo_tour_quick_runs_every_transport():
    out = subprocess.run([sys.executable, "-m", "motorbus", "demo", "--tour", "--quick"], capture_output=True, text=True,
                         timeout=180)
    assert out.returncode == 0, out.stderr
    text = out.stdout
    # the drives themselves are the bench demo's (the next test): the tour is what they stand on
    assert "sim serve" not in text and "axes" not in text
    assert re.search(r"python-can socketcand -> python-can slcan: 5/5 frames", text)
    assert "recorded 100 frames" in text and "read back 100 frames (0 bad lines)" in text
    assert "device type 0x00040192, name 'motorbus node (simulated)', vendor 0xAB" in text
    assert "baud index 9 refused: abort 0x06090031" in text
    assert "block transfer of 4096 bytes down and up" in text and "identical: True" in text
    assert "loaded it back: 0x1008 = 'motorbus node (simulated)'" in text
    assert text.rstrip().endswith("demo finished")


def test_bench_demo_quick_discovers_homes_moves_polls_and_plots(tmp_path):
    np = pytest.importorskip("numpy")
    out = subprocess.run([sys.executable, "-m", "motorbus", "demo", "--quick", "--out", str(tmp_path)],
                         capture_output=True, text=True, timeout=240)
    assert out.returncode == 0, out.stderr + out.stdout
    text = out.stdout
    axes = {"x": "arcus", "y": "arcus", "rot": "dmac", "z": "cia402", "tilt": "arcus-canopen", "feed": "pmc007",
            "spindle": "unitek"}
    assert "7/7 axes found as the file describes them" in text
    assert "not in the file: nothing" in text
    assert "7 of 7 axes homed" in text
    for axis, kind in axes.items():   # one row per axis in the move's table, with its kind
        assert re.search(rf"\b{re.escape(axis)}\b\s*.\s*{re.escape(kind)}\b", text), (axis, text)
    # units in the table (quick: 0.4 of the targets), every row reached, a legend of its columns
    assert re.search(r"\bx\b\s*.\s*arcus\s*.\s*10 mm\s*.\s*10 mm\s*.\s*reached\s*.\s*[0-9.e-]+ mm\s", text), text
    assert re.search(r"\brot\b\s*.\s*dmac\s*.\s*288 deg\s*.\s*288 deg\s*.\s*reached", text), text
    assert "│ ✗" not in text
    assert "max |error| vs plan: the largest |measured - planned| position during the move" in text
    assert "missed: poll deadlines the poll thread passed" in text
    # every candump log it wrote is listed: one per CAN bus the poller recorded (can0, can1)
    assert f"recording: {tmp_path / 'demo_frame.npz'}, {tmp_path / 'demo_can.log'}, {tmp_path / 'demo_can-2.log'}\n" \
        in text
    assert (tmp_path / "demo_can-2.log").stat().st_size > 0
    assert f"plot: {tmp_path / 'demo.png'} (its arrays: {tmp_path / 'demo_plot.npz'})" in text
    png = tmp_path / "demo.png"
    assert png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    assert (tmp_path / "demo_can.log").stat().st_size > 0
    data = np.load(tmp_path / "demo_plot.npz")
    for axis in ("x", "y", "rot", "z", "tilt", "feed"):   # every polled axis: each kind has a profile model
        measured, planned, target = data[f"{axis}.measured"], data[f"{axis}.planned"], float(data[f"{axis}.target"])
        assert len(measured) > 20
        assert measured[-1] == pytest.approx(target, abs=1e-6), axis     # reached the target
        assert data[f"{axis}.planned"][-1] == pytest.approx(target, abs=1e-6)
        # follows its plan: the error stays within 10 % of the move (software start skew, poll timing)
        span = abs(target - measured[0])
        assert np.max(np.abs(measured - planned)) < 0.1 * span, axis
    assert np.max(data["bus_load.load"]) > 0
    assert text.rstrip().splitlines()[-1].startswith("demo finished")


def _demo(tmp_path, bench_text, *, block_matplotlib=False, timeout=240):
    bench = tmp_path / "bench.toml"
    bench.write_text(textwrap.dedent(bench_text))
    out = tmp_path / "out"
    args = ["demo", "--quick", "--bench", str(bench), "--out", str(out)]
    # sys.modules[name] = None makes `import name` fail, as on a machine without it
    code = "import sys; " + ("sys.modules['matplotlib'] = None; " if block_matplotlib else "") + \
        f"from motorbus.cli import main; sys.exit(main({args!r}))"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout), out


def test_demo_runs_a_bench_of_every_kind_each_on_a_link_of_its_own(tmp_path):
    """Another bench file than the shipped one (the pytest plugin's default shape: axes
    named after their kinds, native units, one line or bus per axis): it runs, and
    lists the candump log of every bus it recorded."""
    from motorbus.pytest_plugin import default_bench
    from motorbus.sim import _toml_document

    data = default_bench()
    if "unitek" in data["axis"]:
        data["axis"]["unitek"]["sim"] = {"calibrated": True}   # an uncalibrated UNITEK refuses to home
    r, out = _demo(tmp_path, _toml_document(data))
    assert r.returncode == 0, r.stdout + r.stderr
    kinds = registry.drive_kinds()
    assert f"{len(kinds)} of {len(kinds)} axes homed" in r.stdout
    for kind in kinds:   # axes not in the demo's targets move 10 * 0.4 user units
        assert re.search(rf"\n│ {re.escape(kind)}\s*│ {re.escape(kind)}\s*│\s*4 native │\s*4 native │ reached", r.stdout), \
            r.stdout
    can_buses = sum(1 for k in kinds if registry.drive_plugin(k).transport == "can")
    logs = [out / "demo_can.log"] + [out / f"demo_can-{i}.log" for i in range(2, can_buses + 1)]
    assert all(p.stat().st_size > 0 for p in logs)
    assert f"recording: {out / 'demo_frame.npz'}, {', '.join(map(str, logs))}\n" in r.stdout
    assert r.stdout.rstrip().splitlines()[-1].startswith("demo finished")


def test_demo_marks_a_move_stopped_short_and_exits_1(tmp_path):
    """A +limit switch inside the move: the row says so, the reason is printed, exit 1."""
    r, _ = _demo(tmp_path, """
        [bus.b]
        spec = "socketcan:can0"
        [axis.z]
        kind = "cia402"
        bus = "b"
        address = 5
        units = { name = "mm", scale = 0.01 }
        sim = { plus_limit = 2000 }
    """)
    assert r.returncode == 1, r.stdout + r.stderr
    row = re.search(r"\n│ z\s*│ cia402 │\s*40 mm │\s*([0-9.]+) mm │ ✗ limit\s*│", r.stdout)
    assert row, r.stdout
    assert 0 < float(row.group(1)) < 40
    assert re.search(rf"✗ z: LimitReached: z: stopped at {row.group(1)} mm by the \+limit", r.stdout), r.stdout
    assert r.stdout.rstrip().splitlines()[-1].endswith("1 of 1 axes did not reach their target (z)")


def test_demo_without_matplotlib_says_so_and_names_no_png(tmp_path):
    r, out = _demo(tmp_path, """
        [bus.b]
        spec = "socketcan:can0"
        [axis.z]
        kind = "cia402"
        bus = "b"
        address = 5
    """, block_matplotlib=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "no plot: motorbus.plot draws with matplotlib, which is not installed" in r.stdout
    assert "demo.png" not in r.stdout and not (out / "demo.png").exists()
    assert f"plot arrays: {out / 'demo_plot.npz'} (no PNG written)" in r.stdout
    assert (out / "demo_plot.npz").exists()

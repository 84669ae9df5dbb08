"""The README's demo runs end to end (quick mode) and shows what it claims."""
import re
import subprocess
import sys

import pytest


def test_demo_tour_quick_runs_every_transport():
    out = subprocess.run([sys.executable, "-m", "motorbus", "demo", "--tour", "--quick"], capture_output=True, text=True,
                         timeout=180)
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert "@01 X2000 -> EX=2000 PX=2000" in text
    assert "@02 X-1000 -> EX=-1000" in text
    assert "DMAC 00 MOVE_TO 5000 -> #POSITION=5000" in text
    assert re.search(r"python-can socketcand -> python-can slcan: 5/5 frames", text)
    assert "recorded 100 frames" in text and "read back 100 frames (0 bad lines)" in text
    assert "device type 0x00040192, name 'PMC007 (simulated)', vendor 0xAB" in text
    assert "baud index 9 refused: abort 0x06090031" in text
    assert "block transfer of 4096 bytes down and up" in text and "identical: True" in text
    assert "loaded it back: 0x1008 = 'PMC007 (simulated)'" in text
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
    assert "7 axes homed" in text
    for axis, kind in axes.items():   # one row per axis in the move's table, with its kind
        assert re.search(rf"\b{re.escape(axis)}\b\s*.\s*{re.escape(kind)}\b", text), (axis, text)
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

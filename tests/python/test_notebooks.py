"""The notebooks in notebooks/ run headless, top to bottom, in a real Jupyter kernel, and
print what they say they show.

Each notebook is executed by nbclient in a fresh ipykernel kernel running this interpreter
(sys.executable: a kernel spec of our own, under a name no user spec takes, so a "python3"
spec in ~/.local/share/jupyter cannot send the notebook to another Python), with notebooks/
as its working directory, the way `jupyter nbconvert --execute` would.  A cell that raises fails the test with the
cell's traceback.  The checks read the notebook's outputs: the values it prints and the
PNG its plot cell displays.
"""
from __future__ import annotations

import base64
import json
import pathlib
import re
import sys

import nbformat
import pytest
from nbclient import NotebookClient

# The kernel is a child process: the sanitizer run would not see inside it.
pytestmark = pytest.mark.subprocess

NOTEBOOKS = pathlib.Path(__file__).resolve().parents[2] / "notebooks"
CELL_TIMEOUT = 60   # s; each notebook takes a few seconds


KERNEL = "motorbus-tests"


@pytest.fixture
def kernel(tmp_path, monkeypatch) -> str:
    """A kernel spec that starts sys.executable, found through JUPYTER_PATH."""
    spec = tmp_path / "kernels" / KERNEL
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "motorbus tests", "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path))
    return KERNEL


def run(name: str, kernel: str) -> tuple[str, list[bytes]]:
    """Execute notebooks/<name>; return its printed text and its PNG images."""
    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell("import sys; print('kernel python', sys.executable)"))
    client = NotebookClient(nb, timeout=CELL_TIMEOUT, kernel_name=kernel,
                            resources={"metadata": {"path": str(NOTEBOOKS)}})
    client.execute()
    text, pngs = [], []
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            if out.output_type == "stream" and out.name == "stdout":
                text.append(out.text)
            elif out.output_type in ("display_data", "execute_result") and "image/png" in out.data:
                pngs.append(base64.b64decode(out.data["image/png"]))
    out = "".join(text)
    assert f"kernel python {sys.executable}" in out
    return out, pngs


def number(text: str, pattern: str) -> float:
    m = re.search(pattern, text)
    assert m, f"{pattern!r} not in the notebook's output:\n{text}"
    return float(m.group(1))


def test_notebooks_are_committed_without_outputs():
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        nbformat.validate(nb)
        for cell in nb.cells:
            if cell.cell_type == "code":
                assert not cell.outputs and cell.execution_count is None, f"{path.name}: clear its outputs"


def test_01_bench_tour(kernel):
    out, _ = run("01_bench_tour.ipynb", kernel)
    for name, kind in (("x", "arcus"), ("y", "dmac"), ("z", "cia402"), ("r", "arcus-canopen"), ("p", "pmc007"),
                       ("u", "unitek")):
        assert re.search(rf"^{name}: {kind} ", out, re.M), out
        assert f"position {name}: 10.00 mm" in out
        assert re.search(rf"^status {name}: enabled=True moving=False fault=False", out, re.M), out
    assert "identity x: DriveMax-CAN" in out                       # the Arcus ID reply
    assert "identity y: 00EV v1.7" in out                           # the DMAC's REQUEST_VERSION
    assert "identity z: motorbus CiA 402 sim" in out                # 1008h over SDO
    assert "identity p: PMC007 (motorbus sim)" in out
    assert "identity u: REGID drive receiving on 0x201, sending on 0x181" in out
    assert "diff after apply: []" in out
    assert "x encoder 1000" in out
    assert "moving: ['p', 'r', 'u', 'x', 'y', 'z']" in out         # every axis jogged...
    assert "stop failures: []" in out and "moving after stop: []" in out   # ...and stopped
    assert "frame spacing at 50 kbit/s (us): [2700.0]" in out      # every gap one 135-bit wire time


def test_02_motion_preview_vs_measured(kernel):
    out, pngs = run("02_motion_preview_vs_measured.ipynb", kernel)
    duration = number(out, r"planned duration ([\d.]+) s")
    assert duration == pytest.approx(1.25)        # 50 mm at 50 mm/s, 200 mm/s² ramps: 0.25 + 0.75 + 0.25
    assert number(out, r"motion.plan trapezoid ([\d.]+) s") == pytest.approx(duration, abs=1e-3)  # the kind's model
    assert number(out, r"final position ([-\d.]+) mm") == 50.0
    samples = number(out, r"samples during the move (\d+)")
    assert samples > 0.3 * duration * 1000        # a 1 kHz poll, of which a loaded machine misses some
    # Measured minus planned at each sample's timestamp.  The simulated drive follows its
    # profile exactly, so what is left is the time between the timestamp (the start of the
    # sample's reads) and the moment the drive read its position: never more than the
    # sample's read time at the peak 50 mm/s, plus the 0.01 mm of a position in whole
    # increments.  A drive off its plan, or a plan misaligned in time, breaks both bounds.
    read_time_max = number(out, r"read time max ([\d.]+) ms") / 1e3
    assert number(out, r"following error max ([\d.]+) mm") <= 50.0 * read_time_max + 0.011
    assert number(out, r"following error p50 ([\d.]+) mm") < 0.25     # half the samples within 5 ms
    assert len(pngs) == 2 and all(p.startswith(b"\x89PNG") for p in pngs)   # profile + bus load
    # The candump holds the drive's SDO responses: two per sample (position, velocity), plus
    # the move's own handshake.
    polled = number(out, r"poller: (\d+) samples")
    assert number(out, r"frames recorded (\d+)") >= 2 * polled
    assert 0 < number(out, r"bus load at 500 kbit/s: mean ([\d.]+) %") <= 100


def test_03_streaming(kernel):
    out, _ = run("03_streaming.ipynb", kernel)
    tpdos = number(out, r"TPDOs received (\d+)")
    assert tpdos >= 300                           # ~0.5 s of 1 ms SYNCs or more
    assert abs(tpdos - number(out, r"SYNCs sent (\d+)")) <= 1    # one TPDO per SYNC, none lost
    # Over the span, not gap by gap: a reader thread the host runs late takes several frames
    # at once (gaps of ~0), which says nothing of the drive.  The SYNC producer keeps a 1 ms
    # grid and skips slots it missed, so the period is 1 ms or longer, never shorter.
    assert 0.95 <= number(out, r"TPDO mean period ([\d.]+) ms") <= 1.5
    assert number(out, r"TPDO last position (-?\d+)") == 2000     # 20 mm at 0.01 mm per increment
    assert number(out, r"TPDO positions rising (\d+)") > 10       # the move seen while it happened
    samples = number(out, r"SPEED_IST samples (\d+)")
    assert number(out, r"POS_IST samples (\d+)") >= 75     # the second register, every 2 ms
    assert samples >= 150
    # The drive keeps its 1 ms cadence on its own clock (a late timer sends what was due, each
    # with the value of its instant), so the span holds one sample per millisecond.
    assert number(out, r"SPEED_IST mean period ([\d.]+) ms") == pytest.approx(1.0, abs=0.1)
    assert number(out, r"SPEED_IST samples \d+, lost (\d+)") == 0
    assert number(out, r"SPEED_IST peak ([\d.]+) rpm") > 0


def test_04_served_bench(kernel):
    pytest.importorskip("caproto")
    pytest.importorskip("epics")
    out, _ = run("04_served_bench.ipynb", kernel)
    assert "served axes: x, y, z, r, p, u" in out
    for name in "xyzrpu":
        assert f"position {name}: 5.00 mm" in out            # move_together through the service
    assert "poll columns: ['x.position', 'z.position']" in out
    assert number(out, r"poll samples: (\d+)") >= 5          # a 200 Hz poll over the move's ~0.1 s and more
    assert "last x: 15.0" in out
    assert "motorbus stop exit code: 0" in out
    assert "the move here: MoveInterrupted short of 200: True" in out   # the stop from the other program
    assert 5.0 < number(out, r"x.RBV over CA: ([\d.]+) mm") < 200.0   # where the stop left it, read over CA
    assert "z moved by caput with completion: 1" in out
    assert "z as this notebook sees it: 7.5" in out and "z DMOV: 1" in out
    assert "service exit code: 0" in out

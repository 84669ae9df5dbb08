"""``motorbus monitor`` in a real terminal (a tmux pane): the live table shows every
axis, a position moves while the axis jogs (started by another program before the
monitor opened the line), q and Ctrl-C quit with 0 — and the axis is still jogging
afterwards: the monitor stops nothing."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import time

import pytest

import motorbus
from motorbus import Units
from motorbus.sim import SimBench

from test_cli_terminal import Pane, pytestmark  # noqa: F401 - the tmux skip applies here too
from drive_kinds import KINDS

SCALE = 0.0025   # mm per step


@pytest.fixture
def pane(tmp_path):
    p = Pane(tmp_path)
    yield p
    p.close()


@pytest.fixture
def served(tmp_path):
    """An arcus on a pty and a cia402 node behind socketcand, served by this process,
    and a bench file pointing at them (as at hardware)."""
    cia = KINDS["cia402"].address
    with SimBench(["arcus:01", f"cia402:{cia}"]) as bench:
        srv = bench.can.servers[0]
        (tmp_path / "bench.toml").write_text(
            f'[line.rs485]\nport = "{bench.lines[0].pty_path}"\n'
            f'[bus.can0]\nspec = "socketcand:{srv.host}:{srv.port}/can0"\n'
            f'[axis.x]\nkind = "arcus"\nline = "rs485"\naddress = 1\nunits = {{ name = "mm", scale = {SCALE} }}\n'
            f'[axis.z]\nkind = "cia402"\nbus = "can0"\naddress = {cia}\n')
        yield bench


def _start_jog(served) -> None:
    """Another program jogs x, then leaves the line (closing a drive does not stop it)."""
    d = motorbus.open_drive("arcus", line=served.lines[0].pty_path, address="01", units=Units("mm", SCALE))
    try:
        d.params["HSPD"] = 20000
        d.params["ACC"] = 20
        d.enable()
        d.jog(5.0)        # 2000 steps/s: 200 s to the soft limit
    finally:
        d.close()


def _x_positions(text: str) -> list[float]:
    return [float(m.group(1)) for m in re.finditer(r"│ x\s+│ arcus\s+│\s+(-?[\d.e+-]+) │", text)]


def _still_jogging(served) -> bool:
    sim = served.sims[("arcus", "01")]
    a = sim.pulse_position
    time.sleep(0.2)
    return sim.pulse_position > a


def test_monitor_table_follows_a_jog_and_q_quits_without_stopping(pane, served):
    _start_jog(served)
    pane.type(f"{sys.executable} -m motorbus monitor bench.toml --rate 20; echo EXIT\"\"=$?")
    text = pane.wait_for("drive says", 60)
    assert "position" in text and "velocity" in text
    assert re.search(r"│ z\s+│ cia402 ", text), text
    seen: set = set()
    deadline = time.monotonic() + 20
    while len(seen) < 3:          # the x row is redrawn with new positions while it jogs
        assert time.monotonic() < deadline, pane.text()
        seen.update(_x_positions(pane.text()))
        time.sleep(0.15)
    assert re.search(r"│ x\s+│ arcus\s+│[^│]+│\s+5 │ mm\s+│ enabled moving", pane.text()), pane.text()
    pane.type("q", enter=False)
    assert "EXIT=0" in pane.wait_for("EXIT=", 20)
    assert _still_jogging(served)


def test_monitor_ctrl_c_quits_with_0_and_stops_nothing(pane, served):
    _start_jog(served)
    pane.type(f"{sys.executable} -m motorbus monitor bench.toml; echo EXIT\"\"=$?")
    pane.wait_for("drive says", 60)
    time.sleep(0.5)
    pane.ctrl_c()
    assert "EXIT=0" in pane.wait_for("EXIT=", 20)
    assert _still_jogging(served)


@pytest.mark.subprocess
def test_monitor_arguments(tmp_path):
    (tmp_path / "b.toml").write_text('[line.l]\nport = "/dev/null"\n[axis.x]\nkind = "arcus"\nline = "l"\naddress = 1\n')
    out = subprocess.run([sys.executable, "-m", "motorbus", "monitor", str(tmp_path / "b.toml"), "--sim",
                          "--rate", "0"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and "--rate: a rate above 0 Hz" in out.stderr
    out = subprocess.run([sys.executable, "-m", "motorbus", "monitor", str(tmp_path / "b.toml"), "--sim",
                          "--axis", "y"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and "no axis 'y'" in out.stderr
    # from a pipe: the table is drawn, q on stdin quits
    out = subprocess.run([sys.executable, "-m", "motorbus", "monitor", str(tmp_path / "b.toml"), "--sim"],
                         input="q", capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert re.search(r"│ x\s+│ arcus\s+│\s+0 │\s+0 │", out.stdout), out.stdout


@pytest.mark.subprocess
def test_monitor_sends_nothing_to_a_can_axis_unless_asked(served, tmp_path):
    """Beside another program on the CAN bus, the monitor's SDO requests would cross that
    program's: by default it only listens to a CAN axis (not one frame from it reaches the
    bus), and polls it only with --ask."""
    srv = served.can.servers[0]

    def watch(*extra: str) -> tuple[str, int]:
        before = srv.stats.frames_to_bus
        proc = subprocess.Popen([sys.executable, "-m", "motorbus", "monitor", "bench.toml", "--rate", "20", *extra],
                                cwd=tmp_path, env={**os.environ, "COLUMNS": "200"}, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        time.sleep(2.0)                       # some 20 redraws (the first one opens the bench)
        out, err = proc.communicate("q", timeout=30)
        assert proc.returncode == 0, err
        return out, srv.stats.frames_to_bus - before

    out, sent = watch("--axis", "z")
    assert sent == 0, out
    assert re.search(r"│ z\s+│ cia402\s+│\s+- │\s+- │ native\s+│ listening", out), out
    assert "not asked: --ask polls it" in out
    out, sent = watch("--axis", "z", "--ask")
    assert sent > 10, out                    # SDO requests, every redraw
    assert re.search(r"│ z\s+│ cia402\s+│\s+0 │\s+0 │", out), out

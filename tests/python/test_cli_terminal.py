"""The bench commands as a new user meets them: in a real terminal (a tmux pane, so
stdin/stderr are ttys): scan draws its progress bar and table, status its table, a
move is stopped by Ctrl-C.  The pane's text is what is asserted."""
from __future__ import annotations

import shutil
import subprocess
import sys
import time
import uuid

import pytest

from motorbus import _core
from motorbus.drives import arcus

pytestmark = pytest.mark.skipif(shutil.which("tmux") is None, reason="tmux is not installed (Makefile APT_PACKAGES)")

BENCH = """\
[line.rs485]
port = "/dev/ttyUSB0"
[axis.x]
kind = "arcus"
line = "rs485"
address = 1
units = { name = "mm", scale = 0.0025 }
"""


class Pane:
    """A tmux session on a tmux server of its own (-L): a test never races another test's
    server starting or exiting (a new session on a server that is exiting fails)."""

    def __init__(self, tmp_path):
        self.name = f"motorbus-{uuid.uuid4().hex[:8]}"
        self.tmux = ["tmux", "-L", self.name]
        subprocess.run(self.tmux + ["new-session", "-d", "-s", self.name, "-x", "160", "-y", "40",
                                    "-c", str(tmp_path)], check=True)

    def type(self, text: str, enter: bool = True) -> None:
        subprocess.run(self.tmux + ["send-keys", "-t", self.name, text] + (["Enter"] if enter else []), check=True)

    def ctrl_c(self) -> None:
        subprocess.run(self.tmux + ["send-keys", "-t", self.name, "C-c"], check=True)

    def text(self) -> str:
        return subprocess.run(self.tmux + ["capture-pane", "-p", "-t", self.name, "-S", "-200"], check=True,
                              capture_output=True, text=True).stdout

    def wait_for(self, needle: str, timeout: float = 60.0) -> str:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            t = self.text()
            if needle in t:
                return t
            time.sleep(0.1)
        raise AssertionError(f"{needle!r} never appeared in the pane:\n{self.text()}")

    def close(self) -> None:
        subprocess.run(self.tmux + ["kill-server"], check=False)


@pytest.fixture
def pane(tmp_path):
    p = Pane(tmp_path)
    yield p
    p.close()


def test_scan_status_move_and_ctrl_c_in_a_terminal(pane, tmp_path):
    line = _core.serial.PtyLineServer([arcus.make_sim("07")], 9600)
    try:
        mb = f"{sys.executable} -m motorbus"
        # (the echo's quotes keep the typed command line from matching what we wait for)
        # scan: only the arcus kind, so the sweep is short; the bar is drawn on the tty
        pane.type(f"{mb} scan --serial {line.slave_path} --kind arcus --reply-timeout 0.01 --write found.toml; echo SCAN\"\"-DONE")
        text = pane.wait_for("SCAN-DONE", 120)
        assert "[#" in text and "/" in text                   # the progress bar
        assert "kind   address  where" in text                  # the table header
        assert f"arcus  07       {line.slave_path}" in text     # the table row
        assert "wrote found.toml" in text
    finally:
        line.close()

    (tmp_path / "bench.toml").write_text(BENCH)
    pane.type(f"{mb} status bench.toml --sim; echo STATUS\"\"-DONE")
    text = pane.wait_for("STATUS-DONE")
    assert "axis  kind   position  units  state  drive says" in text
    assert "x     arcus  0         mm" in text

    # A long move (100 mm = 40 000 steps at 1 000 steps/s), interrupted from the keyboard.
    pane.type(f"{mb} move bench.toml x 100 --sim; echo EXIT\"\"=$?")
    time.sleep(2.5)
    pane.ctrl_c()
    text = pane.wait_for("EXIT=")
    assert "interrupted: axis stopped" in text
    assert "EXIT=130" in text

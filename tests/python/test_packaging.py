"""`pip install .` into a clean venv gives a motorbus whose every command works.

Builds the wheel (isolated build, as a user's `pip install` does) and installs it into a
new venv, then runs the commands there, so a dependency missing from pyproject.toml
(``ModuleNotFoundError: No module named 'can'``) fails here.  The build takes minutes,
so the test runs only when ``MOTORBUS_TEST_PACKAGING=1``:

    MOTORBUS_TEST_PACKAGING=1 .venv/bin/python -m pytest -q tests/python/test_packaging.py
"""
from __future__ import annotations

import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = [
    pytest.mark.slow,
    pytest.mark.subprocess,
    pytest.mark.skipif(os.environ.get("MOTORBUS_TEST_PACKAGING") != "1",
                       reason="builds a wheel (minutes): set MOTORBUS_TEST_PACKAGING=1"),
]


def _run(args, timeout, cwd):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    r = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, f"{' '.join(map(str, args))} -> {r.returncode}\n{r.stdout[-4000:]}\n{r.stderr[-4000:]}"
    return r.stdout


@pytest.mark.timeout(3600)
def test_pip_install_into_a_clean_venv_then_every_command(tmp_path):
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True, clear=True).create(env_dir)
    py, mb = env_dir / "bin" / "python", env_dir / "bin" / "motorbus"
    wheel_builds = lambda: sorted(p.name for p in (ROOT / "build").glob("cp3*"))  # noqa: E731 - build/<wheel tag>
    before = wheel_builds()
    _run([py, "-m", "pip", "install", "-q", str(ROOT)], timeout=3000, cwd=tmp_path)
    assert wheel_builds() == before, "pip install wrote its build into the source tree (pyproject build-dir)"
    # the installed package, not the checkout: run from tmp_path with no PYTHONPATH
    out = _run([py, "-c", "import motorbus, can, serial; print(motorbus.__file__)"], 120, tmp_path)
    assert str(env_dir) in out
    _run([mb, "--help"], 120, tmp_path)
    for sub in (["bus", "serve"], ["bus", "dump"], ["bus", "play"], ["sim", "serve"], ["demo"]):
        _run([mb, *sub, "--help"], 120, tmp_path)
    _run([py, "-m", "motorbus", "--help"], 120, tmp_path)
    # the web page's assets ship in the wheel (motorbus serve --http serves them from the package)
    out = _run([py, "-c", "from importlib import resources; w = resources.files('motorbus.serve') / 'web'; "
                          "print(sorted((n, len((w / n).read_bytes()) > 0) for n in ('index.html', 'app.js', "
                          "'style.css')))"], 120, tmp_path)
    assert out.strip() == "[('app.js', True), ('index.html', True), ('style.css', True)]", out
    # the python-can interface entry point of the installed distribution
    _run([py, "-c", "import can; b = can.Bus(interface='motorbus', channel='virtual:pkg'); "
                    "print(b.channel_info); b.shutdown()"], 120, tmp_path)
    # every drive kind's entry point loads
    assert "arcus" in _run([mb, "drives"], 120, tmp_path)
    out = _run([mb, "demo", "--quick"], 600, tmp_path)
    assert "demo finished" in out

"""A drive kind written outside motorbus: listed, opened, simulated and served.

``tests/plugin_kind/`` holds the "toy" kind as an out-of-tree package would: one C++
folder (``cpp/toy/``: simulator and client), one bindings file (``bindings/toy.cpp``,
built in through CMake's ``MOTORBUS_EXTRA_VENDOR_DIRS``) and one Python module
(``python/motorbus_toy``) whose Drive subclass is the plugin, declared by the entry
point of its own ``motorbus_toy-0.1.dist-info``.  No shared file names it: the kind
exists for a process exactly when that directory is on its path.
"""
from __future__ import annotations

import os
import pathlib
import re
import signal
import subprocess
import sys
import time
from importlib import metadata

import pytest

import motorbus
import motorbus.plot
import motorbus.sim
from motorbus import MoveFaulted, MoveInterrupted, registry

ROOT = pathlib.Path(__file__).resolve().parents[2]
PLUGIN_PATH = ROOT / "tests" / "plugin_kind" / "python"

pytestmark = pytest.mark.skipif(not hasattr(motorbus._core, "toy"),
                                reason="built without MOTORBUS_TESTS (the toy kind's C++ is not in _core)")


@pytest.fixture
def toy(monkeypatch):
    """The toy package on sys.path and a registry that reads the entry points afresh."""
    monkeypatch.syspath_prepend(str(PLUGIN_PATH))
    monkeypatch.setattr(registry, "_cache", {})
    import motorbus_toy
    return motorbus_toy.ToyDrive


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(PLUGIN_PATH), env.get("PYTHONPATH")]))
    return env


def test_not_a_kind_without_its_package():
    assert "toy" not in motorbus.drive_kinds()
    with pytest.raises(motorbus.InvalidArgument, match="unknown drive kind 'toy'"):
        registry.drive_plugin("toy")


def test_listed_from_its_own_entry_point(toy):
    assert motorbus.drive_kinds()["toy"] == toy.description
    assert registry.drive_plugin("toy") is toy
    [ep] = [ep for ep in metadata.entry_points(group=registry.DRIVE_GROUP) if ep.name == "toy"]
    assert ep.value == "motorbus_toy:ToyDrive" and ep.dist.name == "motorbus-toy"
    # What it overrides is what its consumers offer; the rest are Drive's defaults.
    assert [h for h in motorbus.drive.HOOKS if toy.provides(h)] == \
        ["open", "make_sim", "check_address", "probe", "sim_faults"]
    out = subprocess.run([sys.executable, "-m", "motorbus", "drives"], capture_output=True, text=True, timeout=60,
                         env=_env())
    assert out.returncode == 0, out.stderr
    assert re.search(r"^toy\s+serial\s+the out-of-tree test kind", out.stdout, re.MULTILINE), out.stdout


def test_what_it_lacks_says_so_through_the_defaults(toy):
    assert toy.canopen_match(object()) == 0 and toy.store_options("/tmp", "1") == {}
    with motorbus.sim.SimBench(["toy:1"]) as bench:
        with motorbus.open_drive("toy", line=bench.lines[0].pty_path, address=1) as d:
            with pytest.raises(motorbus.InvalidArgument, match="cannot be polled"):
                motorbus.Poller({"x": d}, rate_hz=100)
            with pytest.raises(motorbus.InvalidArgument, match="has no profile model"):
                motorbus.plot.planned(d, 0, 10)
            with pytest.raises(motorbus.InvalidArgument, match="no drive-level synchronised start"):
                toy.synchronised_start(bench.lines[0], [d])


def test_simulated_a_move_arrives_and_one_stopped_elsewhere_is_interrupted(toy):
    sim = toy.make_sim("1", speed=20000)
    assert sim.on_line(b"@1 POS?") == b"0\r\n" and sim.on_line(b"@2 POS?") == b""   # another address: silent
    with motorbus.sim.SimBench(["toy:1"], sim_options={"toy": {"speed": 5000}}) as bench:
        sim = bench.sims[("toy", "1")]
        with motorbus.open_drive("toy", line=bench.lines[0].pty_path, address="1",
                                 units=motorbus.Units("mm", 0.01)) as d:
            d.enable()
            d.move_to(5.0, timeout=10)                        # 500 steps
            assert d.position == pytest.approx(5.0) and sim.position == 500
            assert d.status.last_move.ok and d.status.at_target
            d.move_to(-50.0, wait=False)                      # 5500 steps at 5000 steps/s
            time.sleep(0.2)
            sim.on_line(b"@1 STOP")                           # another program on the line
            with pytest.raises(MoveInterrupted, match="a STOP on the line") as e:
                d.wait_idle(10)
            assert e.value.target == -50.0 and -50.0 < e.value.position < 5.0
            assert d.position == pytest.approx(sim.position * 0.01)
            d.move_to(0.0, wait=False)
            time.sleep(0.05)
            d.stop()                                          # this program's own stop
            with pytest.raises(MoveInterrupted, match=r"stop\(\) of this program"):
                d.wait_idle(10)
            d.move_to(40.0, wait=False)
            time.sleep(0.05)
            toy.sim_faults()["fault"](sim)                    # the fault input: MoveFaulted
            with pytest.raises(MoveFaulted, match="the fault input"):
                d.wait_idle(10)
            with pytest.raises(motorbus.DriveFault, match="fault input is still active"):
                d.clear_faults()


def test_opened_from_a_bench_file(toy, tmp_path):
    bench_file = tmp_path / "bench.toml"
    bench_file.write_text('[line.rs485]\nport = "/dev/ttyUSB0"\n\n'
                          '[axis.x]\nkind = "toy"\nline = "rs485"\naddress = 3\n'
                          'units = { name = "mm", scale = 0.01 }\nparams = { SPEED = 8000 }\n'
                          'sim = { start_position = 100 }\n')
    with motorbus.Bench.load(bench_file, sim=True) as bench:
        x = bench["x"]
        assert isinstance(x, toy) and x.native.address == 3
        assert x.params["SPEED"] == 4000 and x.position == pytest.approx(1.0)
        assert [(c.name, c.file_value) for c in bench.apply()] == [("SPEED", 8000)]
        assert x.params["SPEED"] == 8000 and bench.diff() == []
        x.enable()
        x.move_by(2.5, timeout=10)
        assert x.position == pytest.approx(3.5) and bench.sims["x"].position == 350
    bench_file.write_text(bench_file.read_text().replace("address = 3", "address = 12"))
    with pytest.raises(motorbus.InvalidArgument, match="axis.x.address: toy address: a digit 1..9, not '12'"):
        motorbus.Bench.load(bench_file, sim=True)


def test_served_by_sim_serve_and_driven_over_its_pty(toy):
    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", "--drive", "toy:1,2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env())
    try:
        spec, pty = proc.stdout.readline().split()
        assert spec == "toy:1,2" and pty.startswith("/dev/pts/")
        link = motorbus.serial.LineLink(motorbus.serial.open_port(pty, 9600), **toy.line_settings)
        try:
            with motorbus.open_drive("toy", line=link, address=1, units=motorbus.Units("mm", 0.01)) as one, \
                    motorbus.open_drive("toy", line=link, address=2) as two:
                one.enable()
                one.move_to(3.0, timeout=10)
                assert one.position == pytest.approx(3.0) and one.status.raw.last_stop.name == "TARGET"
                assert two.position == 0 and not two.status.enabled
                with pytest.raises(motorbus.DriveFault, match="ERR unknown command FOO"):
                    two.console("FOO")
                assert one.console("POS?") == "300"
        finally:
            link.port.close()
    finally:
        proc.send_signal(signal.SIGINT)
        assert proc.wait(10) == 0, proc.stderr.read()


def test_bad_input_is_typed(toy):
    for bad in ("0", "10", "x", True, None):
        with pytest.raises(motorbus.InvalidArgument, match="toy address: a digit 1..9"):
            toy.check_address(bad)
    with pytest.raises(motorbus.InvalidArgument, match=r"toy sim options: unknown \['speeed'\]"):
        toy.make_sim("1", speeed=3)
    with pytest.raises(motorbus.InvalidArgument, match="toy sim speed and accel"):
        toy.make_sim("1", speed=-1)
    with pytest.raises(motorbus.InvalidArgument, match="a serial drive takes line="):
        motorbus.open_drive("toy", bus="virtual:x", address=1)


def test_the_registry_refuses_what_is_not_a_drive_class(monkeypatch):
    monkeypatch.setattr(registry, "_cache", {})

    class NoTransport(motorbus.Drive):
        kind = "broken"

    registry.register(registry.DRIVE_GROUP, "broken", NoTransport)
    with pytest.raises(motorbus.InvalidArgument, match=r"drive kind 'broken' \(.*NoTransport\): transport "
                                                        r"'serial' or 'can', not ''"):
        registry.drive_plugin("broken")
    registry.register(registry.DRIVE_GROUP, "broken", object())
    with pytest.raises(motorbus.InvalidArgument, match="its entry point is not a motorbus.Drive subclass"):
        registry.drive_plugin("broken")
    with pytest.raises(motorbus.InvalidArgument, match="Drive.provides: a hook among"):
        motorbus.Drive.provides("fly")

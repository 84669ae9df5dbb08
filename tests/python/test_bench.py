"""Bench files and motorbus.Bench: one axis of every registered kind, simulated behind
the transport a real bench uses (ptys, socketcand on 127.0.0.1); every kind of mistake
in a file named by file:line: key; the bench commands of the command line."""
from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import motorbus
from motorbus import Bench, BenchFileError, registry

from drive_kinds import KINDS  # per-kind address, parameters, homing method, sim options
from test_hardening_bindings import sigint_default


def _toml_value(v):
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, dict):
        return "{ " + ", ".join(f'"{k}" = {_toml_value(x)}' for k, x in v.items()) + " }"
    return repr(v)


def _every_kind_file(tmp_path, params: dict) -> tuple[str, dict]:
    """A bench file with one axis per registered kind; returns (path, {axis: Kind})."""
    text = ["# every registered kind, one axis each", "[bus.can0]", 'spec = "socketcan:can0"', ""]
    axes = {}
    taken: set = set()    # node-IDs on the one bus: two kinds may default to the same one
    for kind in sorted(registry.drive_kinds()):
        if kind not in KINDS:
            pytest.fail(f"kind {kind!r} has no entry in tests/python/test_drive_api.py KINDS")
        k = KINDS[kind]
        plugin = registry.drive_plugin(kind)
        if plugin.transport == "can" and k.address.isdigit():
            node = int(k.address)
            while node in taken:
                node += 1
            taken.add(node)
            k = dataclasses.replace(k, address=str(node))
        name = kind.replace("-", "_")
        if plugin.transport == "serial":
            text += [f"[line.{name}]", f'port = "/dev/ttyUSB-{name}"', ""]
        text += [f"[axis.{name}]", f'kind = "{kind}"',
                 f'{"line" if plugin.transport == "serial" else "bus"} = "{name if plugin.transport == "serial" else "can0"}"',
                 f'address = "{k.address}"', f'units = {{ name = "mm", scale = {k.scale} }}']
        if params.get(kind):
            text.append(f"params = {_toml_value(params[kind])}")
        if k.sim_options:
            text.append(f"sim = {_toml_value(k.sim_options)}")
        if k.open_options:
            text.append(f"options = {_toml_value(k.open_options)}")
        text.append("")
        axes[name] = k
    path = tmp_path / "bench.toml"
    path.write_text("\n".join(text))
    return str(path), axes


def _setup_params(kind) -> dict:
    """What the shared Drive API test's setup() writes, captured as a params table."""
    class Capture:
        def __init__(self):
            self.params = {}
    c = Capture()
    if kind.setup:
        kind.setup(c)
    return c.params


@pytest.fixture
def every_kind(tmp_path):
    params = {k: _setup_params(KINDS[k]) for k in registry.drive_kinds() if k in KINDS}
    return _every_kind_file(tmp_path, params)


def test_every_registered_kind_loads_simulated_and_moves_homes_stops(every_kind):
    path, axes = every_kind
    with Bench.load(path, sim=True) as bench:
        assert list(bench) == list(axes)
        changed = bench.apply()            # the file's parameters written through each protocol
        assert bench.diff() == []
        assert {c.axis for c in changed} <= set(axes)
        for name, k in axes.items():
            d = bench[name]
            assert d.kind == k.kind and d.units.name == "mm"
            d.enable()
            assert d.status.enabled
            d.move_to(5.0, timeout=20)
            assert d.position == pytest.approx(5.0, abs=k.scale), name
            d.home(k.home, timeout=30)
            assert d.status.homed, name
            d.jog(k.jog)
            time.sleep(0.05)
            d.stop()
            d.wait_idle(timeout=10)
            assert not d.status.moving, name


def test_status_command_shows_every_axis(every_kind):
    path, axes = every_kind
    out = subprocess.run([sys.executable, "-m", "motorbus", "status", path, "--sim"], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    rows = out.stdout.splitlines()
    assert rows[0].split()[:4] == ["axis", "kind", "position", "units"]
    for name, k in axes.items():
        assert any(r.split()[:2] == [name, k.kind] for r in rows[2:]), out.stdout


def test_with_block_stops_every_axis_on_an_exception(every_kind):
    path, axes = every_kind
    with pytest.raises(RuntimeError):
        with Bench.load(path, sim=True) as bench:
            for name, k in axes.items():
                bench[name].enable()
                bench[name].jog(k.jog)
            time.sleep(0.1)
            assert all(bench[n].status.moving for n in axes)
            drives = bench.axes
            raise RuntimeError("test script failed mid-move")
    assert bench.closed and all(d.closed for d in drives.values())
    # The simulators outlive the bench object: each comes to rest (a decelerating
    # stop may take its ramp: UNITEK's default is 1 s to N max) and stays there.
    for name, sim in bench.sims.items():
        deadline = time.monotonic() + 10
        pos = _sim_position(sim)
        while True:
            time.sleep(0.1)
            now = _sim_position(sim)
            if now == pos:
                break
            assert time.monotonic() < deadline, f"{name} still moving 10 s after the bench closed"
            pos = now
        time.sleep(0.2)
        assert _sim_position(sim) == pos, name


def _sim_position(sim):
    """Where a simulator's motor is, whatever the kind exposes (never None: a
    comparison of two Nones would prove nothing)."""
    for holder in (sim, getattr(sim, "motor", None)):
        for attr in ("physical_position", "pulse_position", "position_num", "position"):
            v = getattr(holder, attr, None)
            if v is not None:
                return v() if callable(v) else v
    state = getattr(sim, "state", None)
    if callable(state):
        return state().position
    raise AssertionError(f"test_bench: no way to read the motor position of {sim!r}")


# ---- mistakes, each named by file:line: key ---------------------------------------------------

GOOD = """\
[bus.can0]
spec = "virtual:bench-test"

[line.rs485]
port = "/dev/ttyUSB0"

[axis.x]
kind = "arcus"
line = "rs485"
address = 1
units = { name = "mm", scale = 0.0025 }

[axis.z]
kind = "cia402"
bus = "can0"
address = 5
"""


def _error(tmp_path, text: str) -> BenchFileError:
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(BenchFileError) as e:
        Bench.load(p, sim=True)
    assert str(e.value).startswith(f"{p}:"), str(e.value)
    return e.value


def test_the_good_file_loads(tmp_path):
    p = tmp_path / "good.toml"
    p.write_text(GOOD)
    with Bench.load(p, sim=True) as bench:
        assert list(bench) == ["x", "z"]
        assert bench["x"].units.scale == 0.0025


@pytest.mark.parametrize("old,new,line,key,says", [
    ('kind = "arcus"', 'kind = "arcos"', 8, "axis.x.kind", "registered: "),
    ("address = 1", "address = 100", 10, "axis.x.address", ""),
    ("address = 5", "address = 128", 16, "axis.z.address", ""),
    ('bus = "can0"', 'bus = "can1"', 15, "axis.z.bus", "buses: can0"),
    ('line = "rs485"', 'bus = "can0"', 9, "axis.x.bus", "use line"),
    ("scale = 0.0025", "scale = 0", 11, "axis.x.units.scale", "non-zero"),
    ('units = { name = "mm", scale = 0.0025 }', 'units = "mm"', 11, "axis.x.units", "scale"),
    ("address = 5", 'address = 5\nspeed = 3', 17, "axis.z.speed", "unknown key"),
    ('spec = "virtual:bench-test"', "spec = 5", 2, "bus.can0.spec", "string"),
    ("address = 1", 'address = 1\nparams = { NOPE = 1 }', 11, "axis.x.params.NOPE", "no parameter"),
    ("address = 5", 'address = 5\n\n[axis.q]\nkind = "cia402"\nbus = "can0"\naddress = 5', 21,
     "axis.q.address", "also axis 'z'"),
])
def test_each_mistake_names_file_line_and_key(tmp_path, old, new, line, key, says):
    assert old in GOOD
    e = _error(tmp_path, GOOD.replace(old, new, 1))
    assert (e.line, e.key) == (line, key), str(e)
    assert says in str(e)


def test_unknown_kind_lists_the_registered_ones(tmp_path):
    e = _error(tmp_path, GOOD.replace('kind = "arcus"', 'kind = "arcos"'))
    for kind in registry.drive_kinds():
        assert kind in str(e)


def test_bad_toml_names_its_line(tmp_path):
    e = _error(tmp_path, GOOD.replace("address = 5", "address = = 5"))
    assert e.line == 16 and "bad TOML" in str(e)


def test_missing_axis_section_and_unknown_section(tmp_path):
    assert "at least one axis" in str(_error(tmp_path, '[bus.can0]\nspec = "virtual:x"\n'))
    e = _error(tmp_path, GOOD + '\n[motor.q]\nkind = "x"\n')
    assert e.key == "motor" and e.line == 18


def test_from_dict_and_missing_link(tmp_path):
    with pytest.raises(BenchFileError, match="axis.x.line: no \\[line.rs485\\]"):
        Bench.from_dict({"axis": {"x": {"kind": "arcus", "line": "rs485", "address": 1}}}, sim=True)


# ---- configuration and the command line ---------------------------------------------------------

def _cli(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "motorbus", *args], capture_output=True, text=True,
                          timeout=timeout)


def test_config_diff_apply_read(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(GOOD.replace("address = 1", "address = 1\nparams = { HSPD = 12000, ACC = 50 }"))
    with Bench.load(p, sim=True) as bench:
        assert {(c.name, c.file_value) for c in bench.diff()} == {("HSPD", 12000), ("ACC", 50)}
        bench.apply(["x"])
        assert bench.diff() == []
        assert bench.read_params(["x"]) == {"x": {"HSPD": 12000, "ACC": 50}}
        assert "LSPD" in bench.read_params(["x"], all_params=True)["x"]
    r = _cli("config", "diff", str(p), "--sim")        # a fresh simulated twin: factory values again
    assert r.returncode == 3 and "HSPD" in r.stdout, r
    r = _cli("config", "apply", str(p), "--sim")
    assert r.returncode == 0 and "2 parameter(s) written" in r.stdout, r


def test_cli_move_and_exit_codes(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(GOOD)
    r = _cli("move", str(p), "x", "0.5", "--sim")
    assert r.returncode == 0 and r.stdout.strip() == "x: 0.5 mm", r
    r = _cli("move", str(p), "nope", "1", "--sim")
    assert r.returncode == 2 and "no axis 'nope'" in r.stderr, r
    bad = tmp_path / "bad.toml"
    bad.write_text(GOOD.replace("address = 5", "address = 500"))
    r = _cli("status", str(bad), "--sim")
    assert r.returncode == 2 and f"{bad}:16: axis.z.address" in r.stderr, r


def test_ctrl_c_during_a_cli_move_stops_the_axis(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(GOOD)
    child = subprocess.Popen([sys.executable, "-m", "motorbus", "move", str(p), "x", "100", "--sim"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             preexec_fn=sigint_default)   # a background test run ignores SIGINT
    # The bench is up and the move (40 000 steps at 1 000 steps/s) under way once it says so.
    assert child.stderr.readline().startswith("x: moving to 100 mm")
    time.sleep(0.3)
    assert child.poll() is None
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=20)
    assert child.returncode == 130, (out, err)
    assert "axis stopped" in err
    pos = float(out.split()[1])
    assert 0 < pos < 100


def test_move_together_reports_the_skew(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(GOOD.replace("[axis.z]", '[axis.w]\nkind = "arcus"\nline = "rs485"\naddress = 2\n'
                                          'units = { name = "mm", scale = 0.0025 }\n\n[axis.z]'))
    with Bench.load(p, sim=True) as bench:
        for d in bench.axes.values():
            d.enable()
        report = bench.move_together({"x": 1.0, "w": 2.0, "z": 300}, timeout=30)
        assert report.method == "software"
        assert list(report.offsets) == ["x", "w", "z"] and report.offsets["x"] == 0
        assert report.skew == max(report.offsets.values()) > 0
        assert bench["x"].position == pytest.approx(1.0, abs=0.0025)
        assert bench["w"].position == pytest.approx(2.0, abs=0.0025)
        assert bench["z"].position == pytest.approx(300, abs=1)


def test_console_speaks_each_drives_own_protocol(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(GOOD)
    with Bench.load(p, sim=True) as bench:
        x, z = bench["x"], bench["z"]
        assert x.console("HSPD=4321") == "OK" and x.console("HSPD") == "4321"
        assert x.params["HSPD"] == 4321
        with pytest.raises(motorbus.MotorbusError):
            x.console("FOO")
        assert z.console("w 0x6081 20000 u32") == "OK"
        assert z.console("r 0x6081 u32") == "20000"
        assert z.console("r 0x6041").startswith("40 06")
        with pytest.raises(motorbus.SdoAbortError):
            z.console("r 0x9999")
        with pytest.raises(motorbus.InvalidArgument, match="INDEX"):
            z.console("bogus")


def test_terminal_command_reads_lines_and_keeps_going_after_errors(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(GOOD)
    r = subprocess.run([sys.executable, "-m", "motorbus", "terminal", str(p), "x", "--sim"],
                       input="HSPD=2500\nFOO\nHSPD\nquit\n", capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["OK", "! ArcusUnknownCommand: arcus: FOO -> ?FOO", "2500"]


def test_dmac_console(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text('[line.l]\nport = "/dev/ttyUSB9"\n[axis.y]\nkind = "dmac"\nline = "l"\naddress = 3\n')
    with Bench.load(p, sim=True) as bench:
        y = bench["y"]
        assert y.console("#HIGH_SPEED:=50000") == "OK"
        assert y.console("READ #HIGH_SPEED") == "03#HSP=+50000"   # the manual's short name in replies


TWO_DMAC = """\
[line.l]
port = "/dev/ttyUSB9"
[axis.a]
kind = "dmac"
line = "l"
address = 1
params = { "#HIGH_SPEED" = 50000 }
[axis.b]
kind = "dmac"
line = "l"
address = 2
params = { "#HIGH_SPEED" = 50000 }
[line.r]
port = "/dev/ttyUSB8"
[axis.x]
kind = "arcus"
line = "r"
address = 1
"""


def test_move_together_uses_the_drives_own_synchronised_start(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(TWO_DMAC)
    with Bench.load(p, sim=True) as bench:
        bench.apply()
        for d in bench.axes.values():
            d.enable()
        report = bench.move_together({"a": 200000, "b": 200000, "x": 1000}, wait=False)
        assert report.method == "DMAC SYNCHRO TOP + software"
        assert report.offsets["a"] == report.offsets["b"] == 0.0 < report.offsets["x"]
        time.sleep(0.2)
        # One SYNCHRO TOP started both modules: read at the same device millisecond
        # (their clocks are one), mid-ramp, they are at the same increment; a software
        # start leaves them one command round trip (>= 3 ms, ~50 increments) apart.
        for _ in range(500):
            sa, sb = bench.sims["a"].state(), bench.sims["b"].state()
            if sa.now_ms == sb.now_ms:
                break
        assert sa.now_ms == sb.now_ms, "never read both modules within one millisecond"
        assert sa.position > 0 and abs(sa.position - sb.position) <= 1, (sa.position, sb.position)
        for d in bench.axes.values():
            d.wait_idle(30)
        assert bench["a"].position == bench["b"].position == 200000


TWO_CIA402 = """\
[bus.can0]
spec = "socketcand:10.0.0.5:29536/can0"
[axis.a]
kind = "cia402"
bus = "can0"
address = 5
[axis.b]
kind = "cia402"
bus = "can0"
address = 6
"""


def test_cia402_axes_start_together_on_one_sync(tmp_path):
    """Set-points travel in synchronous RPDOs and wait in the drives: nothing moves until
    the one SYNC, then both drives accept their set-point on that frame."""
    p = tmp_path / "b.toml"
    p.write_text(TWO_CIA402)
    with Bench.load(p, sim=True) as bench:          # the bus is served over socketcand
        a, b = bench["a"], bench["b"]
        for d in (a, b):
            d.enable()
            d.params["0x6081"] = 20000
        sims = [bench.sims["a"], bench.sims["b"]]
        clock = motorbus._core.runtime.RealClock()          # the simulators' time base
        sync = registry.drive_plugin("cia402").synchronised_start
        with sync(bench.buses["can0"], [a, b]) as how:
            a.move_to(3000, wait=False)
            b.move_by(-2000, wait=False)
            time.sleep(0.1)                        # the RPDOs have arrived: still nothing moves
            assert [s.last_setpoint_ns for s in sims] == [None, None]
            assert a.position == b.position == 0
            before_sync = clock.now()
        assert how == "CANopen SYNC"
        # Both drives held their set-point until the block's one SYNC, and took it then
        # (the skew between them is measured in docs/bench-files.md, not asserted here).
        assert all(s.last_setpoint_ns > before_sync for s in sims)
        assert [s.pdo.counters.rpdo_applied for s in sims] == [1, 1]
        a.wait_idle(30)
        b.wait_idle(30)
        assert a.position == 3000 and b.position == -2000

        # Through the bench: one group started by its drives, offsets 0 by construction.
        report = bench.move_together({"a": 0, "b": 0}, timeout=30)
        assert report.method == "CANopen SYNC" and report.skew == 0.0
        assert a.position == b.position == 0


def test_a_failed_sync_block_starts_nothing(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(TWO_CIA402)
    with Bench.load(p, sim=True) as bench:
        a, b = bench["a"], bench["b"]
        for d in (a, b):
            d.enable()
        sync = registry.drive_plugin("cia402").synchronised_start
        with pytest.raises(RuntimeError, match="in the block"):
            with sync(bench.buses["can0"], [a, b]):
                a.move_to(5000, wait=False)
                raise RuntimeError("in the block")
        bench.buses["can0"].send(motorbus.Frame(0x080, b""))   # someone else's SYNC later
        time.sleep(0.1)
        assert bench.sims["a"].last_setpoint_ns is None and a.position == 0
        a.move_to(100, timeout=10)                 # and the axis still moves normally
        assert a.position == 100


def test_a_closed_bench_releases_its_serial_lines(tmp_path):
    """Bench.close() gives its lines back at once (not when the object is collected): the
    same program opens the same bench file again (it got "busy … already open by this
    process" before)."""
    from motorbus.sim import ServedBench

    src = tmp_path / "bench.toml"
    src.write_text('[line.l]\nport = "/dev/null"\n\n[axis.a]\nkind = "arcus"\nline = "l"\naddress = "01"\n')
    with ServedBench(src) as served:
        first = Bench.load(served.bench_file)
        position = first["a"].position
        first.close()
        with Bench.load(served.bench_file) as again:       # kept `first` alive on purpose
            assert again["a"].position == position
        assert first.closed

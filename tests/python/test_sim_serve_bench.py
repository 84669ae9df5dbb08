"""`motorbus sim serve --bench FILE`: one simulated twin of a bench file that lasts,
served in its own process, used by many commands (each its own process) through the
bench file it writes; fault injection into it from outside (``--control``,
``motorbus.sim.ServedBench``).

What a command did must still be there for the next command: the positions read by
one process are the ones another process moved to."""
from __future__ import annotations

import gc
import os
import signal
import socket
import subprocess
import sys
import textwrap
import time
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

from motorbus import Bench, InvalidArgument, registry
from motorbus.sim import BenchTwin, ServedBench, default_link_dir

pytestmark = pytest.mark.subprocess

DEMO_BENCH = Path(__file__).parents[2] / "python" / "motorbus" / "demo_bench.toml"
#: Where `motorbus move` sends each axis of the demo bench (user units), and back again by `home`.
MOVES = {"x": 3.0, "y": -2.0, "rot": 36.0, "z": 4.0, "tilt": 2.0, "feed": 5.0, "spindle": 500.0}


def motorbus(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "motorbus", *args], capture_output=True, text=True,
                          timeout=timeout)


def read_bench(bench_file, read):
    """``read(bench)`` on a Bench of this process, closed and collected after (its
    serial ports are held until then)."""
    bench = Bench.load(bench_file)
    try:
        return read(bench)
    finally:
        bench.close()
        del bench
        gc.collect()


def positions(bench_file) -> dict[str, float]:
    return read_bench(bench_file, lambda b: {n: d.position for n, d in b.axes.items()})


def free_ports(n: int) -> int:
    """A port P with P..P+n-1 free on 127.0.0.1 now (the twin binds them with SO_REUSEADDR)."""
    for _ in range(50):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            base = s.getsockname()[1]
        if base + n > 65535:
            continue
        try:
            socks = []
            for p in range(base, base + n):
                s = socket.socket()
                socks.append(s)
                s.bind(("127.0.0.1", p))
            return base
        except OSError:
            continue
        finally:
            for s in socks:
                s.close()
    pytest.fail("no run of free ports")


@pytest.fixture(scope="module")
def served():
    """The demo bench's twin, served once for the module's commands."""
    with ServedBench(DEMO_BENCH) as s:
        yield s


# ---- the written bench file ----------------------------------------------------------------
def test_written_file_is_the_source_file_pointing_at_the_twin(served):
    source = tomllib.loads(DEMO_BENCH.read_text())
    written = tomllib.loads(Path(served.bench_file).read_text())
    assert written["axis"] == source["axis"]          # same axes, kinds, addresses, units, params, sim
    assert set(written["line"]) == set(source["line"])
    for name, line in written["line"].items():
        assert line["port"] == os.path.join(served.link_dir, name)
        assert os.readlink(line["port"]).startswith("/dev/pts/")
        assert {k: v for k, v in line.items() if k != "port"} == \
            {k: v for k, v in source["line"][name].items() if k != "port"}
    announced = dict(a.split()[1:3] for a in served.announced if a.startswith("bus "))
    assert {n: b["spec"] for n, b in written["bus"].items()} == announced
    assert all(spec.startswith("socketcand:127.0.0.1:") and spec.endswith("/can0") for spec in announced.values())


def test_toml_writer_round_trips_awkward_keys_and_values(tmp_path):
    src = tmp_path / "odd.toml"
    src.write_text(textwrap.dedent('''
        [line."rs 485"]
        port = "/dev/ttyUSB9"
        timeout = 0.25

        [line.unused]
        port = "/dev/does-not-exist"

        [axis."x.1"]
        kind = "arcus"
        line = "rs 485"
        address = "01"
        units = { name = "µm \\"fine\\"", scale = 2.5e-3 }
        params = { HSPD = 10000, EDEC = true }
        options = {}
    '''))
    with pytest.raises(InvalidArgument, match=r"odd.toml:2: line.rs 485: line name 'rs 485' cannot name a symlink"):
        BenchTwin(src, link_dir=str(tmp_path / "links"))
    src.write_text(src.read_text().replace("rs 485", "rs485"))
    with BenchTwin(src, link_dir=str(tmp_path / "links")) as twin:
        data = tomllib.loads(twin.bench_text())
        assert data["axis"]["x.1"] == {"kind": "arcus", "line": "rs485", "address": "01",
                                       "units": {"name": 'µm "fine"', "scale": 2.5e-3},
                                       "params": {"HSPD": 10000, "EDEC": True}, "options": {}}
        assert data["line"]["rs485"] == {"port": str(tmp_path / "links" / "rs485"), "timeout": 0.25}
        assert data["line"]["unused"] == {"port": "/dev/does-not-exist"}   # no axis: not served, left as written
        assert twin.links == {"rs485": str(tmp_path / "links" / "rs485")}
    assert not (tmp_path / "links" / "rs485").exists()     # closed: its link is gone


# ---- many commands, one twin -----------------------------------------------------------------
def test_status_move_home_of_every_axis_as_separate_commands(served):
    """The issue's "must show": every kind of the demo bench (DMAC included, with its
    default homing method) moved and homed by separate `motorbus` processes."""
    bench = served.bench_file
    kinds = {c.split("=")[0]: c.split("=")[1] for c in served.command("axes").split()}
    assert set(kinds.values()) == set(registry.drive_kinds()) & set(kinds.values())
    assert {"arcus", "dmac", "cia402", "arcus-canopen", "pmc007", "unitek"} <= set(kinds.values())
    r = motorbus("status", bench)
    assert r.returncode == 0, r.stderr
    for axis in MOVES:
        assert r.stdout.count(f"\n{axis} ") == 1, r.stdout
    for axis, target in MOVES.items():
        r = motorbus("move", bench, axis, str(target))
        assert r.returncode == 0, f"move {axis}: {r.stdout}{r.stderr}"
        assert f"{axis}: {target:g}" in r.stdout, r.stdout
    # Another process reads them where the movers left them: one twin, not a fresh one per command.
    got = positions(bench)
    for axis, target in MOVES.items():
        assert got[axis] == pytest.approx(target, abs=0.02), axis
    for axis in MOVES:
        r = motorbus("home", bench, axis, "--timeout", "60")
        assert r.returncode == 0, f"home {axis}: {r.stdout}{r.stderr}"
    r = motorbus("status", bench)
    assert r.returncode == 0, r.stderr
    got = positions(bench)
    for axis, target in MOVES.items():
        assert abs(got[axis]) < abs(target) / 2, f"{axis} at {got[axis]} after homing (was at {target})"


def test_pytest_runs_against_the_served_twin(served, tmp_path):
    """`pytest --bench FILE` (the plugin's real-hardware mode) on the written file: the
    inner session sees the position a command of another process left."""
    r = motorbus("move", served.bench_file, "x", "1.5")
    assert r.returncode == 0, r.stdout + r.stderr
    (tmp_path / "test_inner.py").write_text(textwrap.dedent("""
        import pytest

        def test_x_where_the_command_left_it(bench):
            assert bench["x"].position == pytest.approx(1.5, abs=0.01)
    """))
    eps = metadata.entry_points(group="pytest11")
    plugin = [] if any(ep.value == "motorbus.pytest_plugin" for ep in eps) else ["-p", "motorbus.pytest_plugin"]
    r = subprocess.run([sys.executable, "-m", "pytest", *plugin, "-p", "no:cacheprovider", "-q",
                        "--bench", served.bench_file, str(tmp_path / "test_inner.py")],
                       capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "1 passed" in r.stdout


# ---- fault injection from outside ----------------------------------------------------------
def test_control_names_faults_and_refuses_bad_ones(served):
    for axis in MOVES:
        kind = served.command("axes").split(f"{axis}=")[1].split()[0]
        assert served.faults(axis) == sorted(registry.drive_plugin(kind).sim_faults())
    with pytest.raises(InvalidArgument, match=r"no axis 'w'.*axes: x, y, rot"):
        served.inject("w", "stall")
    with pytest.raises(InvalidArgument, match=r"the arcus simulator \(axis 'x'\) has no fault 'melt' \(it has: "):
        served.inject("x", "melt")
    with pytest.raises(InvalidArgument, match=r"arcus fault 'trip_limit'.*unexpected keyword argument 'side'"):
        served.inject("x", "trip_limit", side=1)
    with pytest.raises(InvalidArgument, match=r"unknown command 'explode x'"):
        served.command("explode x")
    with pytest.raises(InvalidArgument, match=r"only ints, floats, bools and strings"):
        served.inject("x", "trip_limit", direction=[1])


def test_served_bench_from_a_dict_of_every_kind():
    """Every registered kind serves: a dict (the pytest plugin's one-axis-per-kind bench)
    written, served, opened by this process; each axis offers its kind's faults."""
    from motorbus.pytest_plugin import default_bench

    data = default_bench()
    with ServedBench(data) as served:
        assert {c.split("=")[0] for c in served.command("axes").split()} == set(data["axis"])
        for axis, table in data["axis"].items():
            assert served.faults(axis) == sorted(registry.drive_plugin(table["kind"]).sim_faults())
        status = read_bench(served.bench_file, lambda b: {n: d.status for n, d in b.axes.items()})
        assert set(status) == set(data["axis"]) and not any(s.moving or s.fault for s in status.values())


def test_injected_limit_is_seen_by_another_process(tmp_path):
    """A fault injected through --control acts on the simulator the commands talk to."""
    with ServedBench(DEMO_BENCH) as served:
        assert not read_bench(served.bench_file, lambda b: b["y"].status.limit_positive)
        fault = "limit" if "limit" in served.faults("y") else "trip_limit"
        served.inject("y", fault, direction=1)
        y, x = read_bench(served.bench_file, lambda b: (b["y"].status, b["x"].status))
        assert y.limit_positive and not y.limit_negative
        assert not x.limit_positive       # the other drive on that line: untouched


# ---- lifetime, stable paths, refusals ------------------------------------------------------
def _serve(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", *args], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _until_bench_line(proc: subprocess.Popen) -> list[str]:
    lines = []
    while True:
        line = proc.stdout.readline()
        assert line, f"sim serve ended: {proc.stderr.read()}"
        lines.append(line.strip())
        if line.startswith("bench "):
            return lines


def test_fixed_ports_stable_links_and_one_twin_per_link_dir(tmp_path):
    base = free_ports(2)
    links = tmp_path / "links"
    args = ("--bench", str(DEMO_BENCH), "--link-dir", str(links), "--write", str(tmp_path / "twin.toml"),
            "--port", str(base), "--control")
    first = _serve(*args)
    try:
        lines = _until_bench_line(first)
        assert f"bus can0 socketcand:127.0.0.1:{base}/can0" in lines
        assert f"bus can1 socketcand:127.0.0.1:{base + 1}/can0" in lines
        assert f"line rs485 {links / 'rs485'} -> {os.readlink(links / 'rs485')}" in lines
        # Another twin on the same link directory is refused (exit 4, busy), naming the process serving it.
        r = subprocess.run([sys.executable, "-m", "motorbus", "sim", "serve", "--bench", str(DEMO_BENCH),
                            "--link-dir", str(links)], capture_output=True, text=True, timeout=60)
        assert r.returncode == 4
        assert f"{links} is served by another `motorbus sim serve --bench` (pid {first.pid})" in r.stderr
        written = (tmp_path / "twin.toml").read_text()
    finally:
        first.stdin.close()            # end of control input: the twin stops by itself
        assert first.wait(30) == 0
    assert not (links / "rs485").exists() and not (links / "rs232").exists()
    # Served again: the same file, byte for byte but the pid line (links and ports are the stable names).
    again = _serve(*args)
    try:
        _until_bench_line(again)
        rewritten = (tmp_path / "twin.toml").read_text()
        strip = lambda t: [ln for ln in t.splitlines() if not ln.startswith("# The simulated twin")]  # noqa: E731
        assert strip(rewritten) == strip(written)
        assert read_bench(tmp_path / "twin.toml", lambda b: b["z"].position) == 0
    finally:
        again.send_signal(signal.SIGINT)
        assert again.wait(30) == 0


def test_default_link_dir_is_per_user_and_bench_name():
    assert default_link_dir("/some/where/lab-7.toml") == os.path.join(
        os.environ.get("TMPDIR", "/tmp"), f"motorbus-sim-{os.getuid()}", "lab-7")


@pytest.mark.parametrize("extra, message", [
    ([], "what to serve? --drive KIND:ADDR"),
    (["--drive", "arcus:01", "--write", "x.toml"], "--write goes with --bench FILE"),
    (["--bench", str(DEMO_BENCH), "--drive", "arcus:01"], "--drive does not apply"),
    (["--bench", str(DEMO_BENCH), "--port", "29536", "--port", "can1=29540"], "not both"),
    (["--bench", str(DEMO_BENCH), "--port", "can7=29536"], "no such bus (buses: can0, can1)"),
    (["--bench", str(DEMO_BENCH), "--port", "65535"], "expected 1..65534 (2 buses take consecutive ports)"),
])
def test_command_line_mistakes_exit_2(extra, message, tmp_path):
    r = subprocess.run([sys.executable, "-m", "motorbus", "sim", "serve", *extra], capture_output=True, text=True,
                       timeout=60, cwd=tmp_path)
    assert r.returncode == 2
    assert message in r.stderr


def test_a_bad_sim_option_names_the_file_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[line.l]\nport = "/dev/x"\n[axis.x]\nkind = "arcus"\nline = "l"\naddress = 1\n'
                   'sim = { warp_speed = 9 }\n')
    r = subprocess.run([sys.executable, "-m", "motorbus", "sim", "serve", "--bench", str(bad), "--link-dir",
                        str(tmp_path / "links")], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert f"{bad}:7: axis.x.sim:" in r.stderr and "warp_speed" in r.stderr

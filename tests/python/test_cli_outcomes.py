"""How ``motorbus move`` / ``home`` end, said by exit code and message: against drives
served by another process (the simulators live there; faults are injected there with
the kinds' own ``sim_faults``), the move is a separate ``motorbus`` process.

Exit codes (cli_bench.EXIT_CODES): 0 done, 10 stopped short by another program or a
stop input, 11 limit, 12 drive fault, 13 stall, 14 timeout, 130 Ctrl-C."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import motorbus
from motorbus import Units

from test_hardening_bindings import sigint_default

MOTORBUS = [sys.executable, "-m", "motorbus"]

# SimBench in its own process; stdin takes "FAULT KIND ADDRESS NAME {options}" lines (the
# kind's sim_faults) and "POS KIND ADDRESS" (answers the simulated shaft's position).
_SERVER = textwrap.dedent("""
    import json, sys
    from motorbus import registry
    from motorbus.sim import SimBench
    specs, options = sys.argv[1:-1], json.loads(sys.argv[-1])
    with SimBench(specs, sim_options=options) as bench:
        for line in bench.announce():
            print(line, flush=True)
        print("ready", flush=True)
        for line in sys.stdin:
            words = line.split(maxsplit=4)
            if not words:
                continue
            sim = bench.sims[(words[1], words[2])]
            if words[0] == "FAULT":
                faults = registry.drive_plugin(words[1]).sim_faults()
                faults[words[3]](sim, **json.loads(words[4] if len(words) > 4 else "{}"))
                print("ok", flush=True)
""")


class Served:
    def __init__(self, tmp_path, specs, options, axes):
        self.proc = subprocess.Popen([sys.executable, "-c", _SERVER, *specs, json.dumps(options)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines, self.socketcand = {}, None
        for raw in iter(self.proc.stdout.readline, ""):
            words = raw.split()
            if words == ["ready"]:
                break
            if words[0] == "socketcand":
                host, port = words[1].rsplit(":", 1)
                self.socketcand = f"socketcand:{host}:{port}/{words[2]}"
            else:
                self.lines[words[0]] = words[1]
        else:
            raise AssertionError(self.proc.stderr.read())
        head = [f'[bus.can0]\nspec = "{self.socketcand}"\n'] if self.socketcand else []
        head += [f'[line.l{i}]\nport = "{pty}"\n' for i, pty in enumerate(self.lines.values())]
        self.path = str(tmp_path / "bench.toml")
        with open(self.path, "w") as f:
            f.write("\n".join(head) + "\n" + textwrap.dedent(axes))

    def fault(self, kind, address, name, **options):
        self.proc.stdin.write(f"FAULT {kind} {address} {name} {json.dumps(options)}\n")
        self.proc.stdin.flush()
        assert self.proc.stdout.readline().strip() == "ok"

    def close(self):
        self.proc.stdin.close()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


def start(*args, **kw) -> subprocess.Popen:
    return subprocess.Popen([*MOTORBUS, *map(str, args)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            **kw)


def run(*args, timeout=60) -> subprocess.CompletedProcess:
    return subprocess.run([*MOTORBUS, *map(str, args)], capture_output=True, text=True, timeout=timeout)


AXES = """\
    [axis.z]
    kind = "cia402"
    bus = "can0"
    address = 5
    units = { name = "mm", scale = 0.01 }

    [axis.x]
    kind = "arcus"
    line = "l0"
    address = 1
    units = { name = "mm", scale = 0.0025 }
    """


@pytest.fixture
def served(tmp_path):
    s = Served(tmp_path, ["cia402:5", "arcus:01"], {"cia402": {"plus_limit": 20000}}, AXES)
    yield s
    s.close()


def test_a_move_into_the_limit_exits_11_and_says_where_and_why(served):
    r = run("move", served.path, "z", "250", "--velocity", "100")
    assert r.returncode == 11, r
    assert r.stdout == "z: 200 mm\n"
    assert r.stderr.splitlines()[-1].startswith("motorbus: z: stopped at 200 mm by the +limit switch")
    assert r.stderr.splitlines()[-1].endswith(", target 250 mm")
    r = run("move", served.path, "z", "0", "--velocity", "100", "--json")   # back off the switch: done
    assert r.returncode == 0 and json.loads(r.stdout)["outcome"] == "done", r
    r = run("move", served.path, "z", "300", "--velocity", "100", "--json")
    assert r.returncode == 11
    out = json.loads(r.stdout)
    assert out["outcome"] == "limit" and out["target"] == 300 and out["position"] == 200 and out["exit_code"] == 11
    assert out["reason"].startswith("the +limit switch")


def test_a_drive_stop_input_exits_10(served):
    # Stopped short with no fault or limit: "interrupted" (a stop input of the drive, or
    # a stop from another program -- on a CAN bus that program's SDO requests would cross
    # the mover's, see docs/monitor.md, so the drive's own input stands in for it here).
    mover = start("move", served.path, "z", "150", "--velocity", "20")
    assert mover.stderr.readline().startswith("z: moving to 150 mm")
    time.sleep(0.5)
    served.fault("cia402", "5", "stop_input")
    out, err = mover.communicate(timeout=30)
    assert mover.returncode == 10, (out, err)
    pos = float(out.split()[1])
    assert 0 < pos < 150
    assert f"motorbus: z: stopped at {pos:g} mm by " in err and err.rstrip().endswith("target 150 mm"), err


def test_a_stop_from_another_process_exits_10(served):
    # `motorbus move ... &` then `motorbus stop BENCH z` from another shell: the mover says
    # it was stopped short, by another program, and exits 10 (it printed "z: 72.803 mm", 0).
    mover = start("move", served.path, "z", "150", "--velocity", "20")
    assert mover.stderr.readline().startswith("z: moving to 150 mm")
    time.sleep(0.5)
    r = run("stop", served.path, "z")
    assert r.returncode == 0 and r.stdout == "z: stopped\n", r
    out, err = mover.communicate(timeout=30)
    assert mover.returncode == 10, (out, err)
    pos = float(out.split()[1])
    assert 0 < pos < 150
    assert f"motorbus: z: stopped at {pos:g} mm by " in err and "from another program" in err, err
    assert err.rstrip().endswith("target 150 mm")


def test_a_drive_fault_during_the_move_exits_12_with_the_code(served):
    names = motorbus.registry.drive_plugin("cia402").sim_faults()
    name = "fault" if "fault" in names else "drive_fault"
    mover = start("move", served.path, "z", "150", "--velocity", "20", "--json")
    assert mover.stderr.readline().startswith("z: moving to 150 mm")
    time.sleep(0.5)
    served.fault("cia402", "5", name, code=0x5441)
    out, err = mover.communicate(timeout=30)
    assert mover.returncode == 12, (out, err)
    res = json.loads(out)
    assert res["outcome"] == "fault" and 0 < res["position"] < 150 and res["exit_code"] == 12
    assert "5441" in res["reason"].upper() or res["code"] == 0x5441, res
    r = run("clear", served.path, "z")
    assert r.returncode == 0 and "FAULT" not in r.stdout.split(";")[1], r


def test_a_timeout_exits_14_and_the_axis_is_stopped(served):
    r = run("move", served.path, "z", "150", "--velocity", "20", "--timeout", "0.5")
    assert r.returncode == 14, r
    assert "the timeout (0.5 s)" in r.stderr
    said = float(r.stdout.split()[1])
    r = run("status", served.path, "--json")
    z = json.loads(r.stdout)["axes"]["z"]
    assert z["moving"] is False                                     # stopped, not left running
    assert z["position"] == pytest.approx(said, abs=0.01)           # and said where it came to rest


def test_ctrl_c_stops_and_waits_for_rest_before_saying_where(served):
    # A long arcus move at its default speed; Ctrl-C: the axis decelerates and the position
    # printed is where it came to rest (a later status reads the same).
    mover = start("move", served.path, "x", "100", preexec_fn=sigint_default)
    assert mover.stderr.readline().startswith("x: moving to 100 mm")
    time.sleep(1.0)
    mover.send_signal(signal.SIGINT)
    out, err = mover.communicate(timeout=30)
    assert mover.returncode == 130, (out, err)
    said = float(out.split()[1])
    assert "x: interrupted: axis stopped at" in err and "(at rest)" in err and "target 100 mm" in err, err
    r = run("status", served.path, "--json")
    x = json.loads(r.stdout)["axes"]["x"]
    assert x["moving"] is False and x["position"] == pytest.approx(said, abs=0.0025), (said, x)
    assert 0 < said < 100


# Every kind whose simulator can close a limit switch: the move ends at the switch, exit 11.
LIMIT_KINDS = {
    # kind: (address, scale, sim options, velocity mm/s)
    "arcus": ("01", 0.01, {}, None),
    "arcus-canopen": ("1", 0.01, {}, None),
    "cia402": ("5", 0.01, {}, 20),
    "dmac": ("00", 0.01, {"reference_switch": 3000}, None),
}


@pytest.mark.parametrize("kind", [k for k in sorted(LIMIT_KINDS)
                                  if "limit" in motorbus.registry.drive_plugin(k).sim_faults()])
def test_every_kind_a_limit_during_a_move_exits_11(tmp_path, kind):
    address, scale, options, velocity = LIMIT_KINDS[kind]
    serial = motorbus.registry.drive_plugin(kind).transport == "serial"
    s = Served(tmp_path, [f"{kind}:{address}"], {kind: options}, f"""\
        [axis.a]
        kind = "{kind}"
        {'line = "l0"' if serial else 'bus = "can0"'}
        address = "{address}"
        units = {{ name = "mm", scale = {scale} }}
        """)
    try:
        args = ["move", s.path, "a", "100", "--json"] + (["--velocity", velocity] if velocity else [])
        mover = start(*args)
        assert mover.stderr.readline().startswith("a: moving to 100 mm")
        time.sleep(0.5)
        s.fault(kind, address, "limit", direction=1)
        out, err = mover.communicate(timeout=60)
        assert mover.returncode == 11, (kind, out, err)
        res = json.loads(out)
        assert res["outcome"] == "limit" and 0 < res["position"] < 100, res
        assert f"a: stopped at {res['position']:g} mm by " in err and "target 100 mm" in err, err
    finally:
        s.close()


def test_the_demo_bench_served_by_sim_serve_bench(tmp_path):
    """`motorbus sim serve --bench` (the shipped demo bench, every family) in one process;
    status, move and a limit injected during a move, each from a separate command."""
    from importlib.resources import files

    from motorbus.sim import ServedBench

    with ServedBench(str(files("motorbus") / "demo_bench.toml")) as served:
        r = run("status", served.bench_file, "--json")
        assert r.returncode == 0, r.stderr
        axes = json.loads(r.stdout)["axes"]
        assert {a["kind"] for a in axes.values()} == {"arcus", "dmac", "cia402", "arcus-canopen", "pmc007", "unitek"}
        r = run("move", served.bench_file, "z", "5", "--velocity", "50")
        assert r.returncode == 0 and r.stdout == "z: 5 mm\n", r
        mover = start("move", served.bench_file, "z", "150", "--velocity", "20")
        assert mover.stderr.readline().startswith("z: moving to 150 mm")
        time.sleep(0.5)
        served.inject("z", "limit", direction=1)
        out, err = mover.communicate(timeout=30)
        assert mover.returncode == 11, (out, err)
        pos = float(out.split()[1])
        assert 5 < pos < 150 and f"z: stopped at {pos:g} mm by the +limit switch" in err, err

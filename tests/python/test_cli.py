"""The ``motorbus`` command line as a test engineer scripts it: run as a subprocess
against simulated drives served by ANOTHER process (ptys and socketcand on 127.0.0.1,
as at hardware), asserting exit codes, messages and JSON — and that read-only commands
leave a moving axis alone.  Move outcomes (limit, stop, Ctrl-C): test_cli_outcomes.py."""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import motorbus
from motorbus import Units

MOTORBUS = [sys.executable, "-m", "motorbus"]

# The server: SimBench in its own process, one drive spec per argument, sim options as
# JSON per kind; prints its announce lines, then serves until SIGTERM/SIGINT.
_SERVER = textwrap.dedent("""
    import json, signal, sys, threading
    from motorbus.sim import SimBench
    specs, options = sys.argv[1:-1], json.loads(sys.argv[-1])
    with SimBench(specs, sim_options=options) as bench:
        for line in bench.announce():
            print(line, flush=True)
        print("ready", flush=True)
        stop = threading.Event()
        signal.signal(signal.SIGTERM, lambda *a: stop.set())
        signal.signal(signal.SIGINT, lambda *a: stop.set())
        while not stop.wait(0.2):
            pass
""")


class Served:
    """Simulated drives served by another process, and the bench file that points at them."""

    def __init__(self, tmp_path, specs: list[str], options: dict, axes: str) -> None:
        self.proc = subprocess.Popen([sys.executable, "-c", _SERVER, *specs, json.dumps(options)],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines: dict[str, str] = {}
        self.socketcand = None
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
            raise AssertionError(f"server failed: {self.proc.stderr.read()}")
        head = []
        if self.socketcand:
            head += ["[bus.can0]", f'spec = "{self.socketcand}"', ""]
        for i, (spec, pty) in enumerate(self.lines.items()):
            head += [f"[line.l{i}]", f'port = "{pty}"', ""]
        self.path = str(tmp_path / "bench.toml")
        with open(self.path, "w") as f:
            f.write("\n".join(head) + "\n" + textwrap.dedent(axes))

    def close(self) -> None:
        self.proc.send_signal(signal.SIGTERM)
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


def cli(*args, timeout=60, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([*MOTORBUS, *map(str, args)], capture_output=True, text=True, timeout=timeout, **kw)


def _cia_setup(d):
    d.params["0x6081"] = 20000   # profile velocity, increments/s
    d.params["0x6083"] = 200000
    d.params["0x6084"] = 200000


# ---- arguments: typed errors naming the argument, exit 2, no traceback ------------------------------

BENCH = """\
[line.rs485]
port = "/dev/ttyUSB0"
[bus.can0]
spec = "virtual:cli-test"
[axis.x]
kind = "arcus"
line = "rs485"
address = 1
units = { name = "mm", scale = 0.0025 }
[axis.z]
kind = "cia402"
bus = "can0"
address = 5
units = { name = "mm", scale = 0.01 }
"""


@pytest.fixture
def bench_file(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(BENCH)
    return str(p)


@pytest.mark.parametrize("args, argument, says", [
    (["move", "{b}", "x", "1e300", "--sim"], "POSITION", "beyond any drive's range"),
    (["move", "{b}", "x", "nan", "--sim"], "POSITION", "a finite number"),
    (["move", "{b}", "x", "1", "--velocity", "1e300", "--sim"], "--velocity", "beyond any drive's range"),
    (["move", "{b}", "x", "1", "--velocity", "-5", "--sim"], "--velocity", "a number above 0"),
    (["move", "{b}", "x", "1", "--timeout", "inf", "--sim"], "--timeout", "a finite number"),
    (["home", "{b}", "z", "--method", "-999999999999999999999", "--sim"], "--method", "-128..127"),
    (["scan", "--serial", "/dev/null", "--write", "/proc/nope/x.toml"], "--write", "no directory /proc/nope"),
    (["scan", "--serial", "/dev/null", "--timeout", "-1"], "--timeout", "a number above 0"),
])
def test_bad_arguments_are_typed_errors_naming_the_argument(bench_file, args, argument, says):
    t0 = time.monotonic()
    r = cli(*[a.format(b=bench_file) for a in args])
    assert r.returncode == 2, r
    assert f"argument {argument}: " in r.stderr and says in r.stderr, r.stderr
    assert "Traceback" not in r.stderr
    assert r.stdout == ""
    if args[0] == "scan":
        assert time.monotonic() - t0 < 20      # refused before any sweep (a full scan takes minutes)


def test_a_position_beyond_the_drives_register_is_refused_before_anything_moves(bench_file):
    # 1e12 mm passes the command line's sanity bound but is 4e14 steps for x: refused by the
    # axis's own units, naming the argument, and nothing was sent (the twin is at 0).
    r = cli("move", bench_file, "x", "1e12", "--sim")
    assert r.returncode == 2 and "argument POSITION: 1e+12 mm is 4e+14 native units" in r.stderr, r
    assert "Traceback" not in r.stderr


def test_version_help_epilog_and_drives_table():
    r = cli("--version")
    assert r.returncode == 0 and re.fullmatch(r"motorbus \S+\n", r.stdout), r
    r = cli("--help")
    assert r.returncode == 0
    codes = {int(m.group(1)): m.group(2) for m in re.finditer(r"^  (\d+)\s+(.+)$", r.stdout.split("exit codes:")[1],
                                                              re.M)}
    assert codes[0].startswith("done") and codes[2].startswith("the command line or the bench file")
    assert codes[4].startswith("busy") and codes[11].startswith("move/home stopped by a limit")
    assert {10, 11, 12, 13, 14, 130} <= set(codes)
    r = cli("drives")
    rows = r.stdout.splitlines()
    assert rows[0].split() == ["kind", "link", "description"]
    # every row's description starts in the same column
    col = rows[0].index("description")
    for row in rows[2:]:
        assert row[col - 2:col] == "  " and row[col] != " ", rows
    assert {row.split()[0] for row in rows[2:]} == set(motorbus.drive_kinds())


# ---- a bench served by another process -------------------------------------------------------------------

@pytest.fixture
def served(tmp_path):
    s = Served(tmp_path, ["arcus:01", "cia402:5"], {"cia402": {"plus_limit": 20000}}, """\
        [axis.x]
        kind = "arcus"
        line = "l0"
        address = 1
        units = { name = "mm", scale = 0.0025 }

        [axis.z]
        kind = "cia402"
        bus = "can0"
        address = 5
        units = { name = "mm", scale = 0.01 }
        """)
    yield s
    s.close()


def test_status_json_and_table_from_another_process(served):
    r = cli("status", served.path, "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["simulated"] is False and list(out["axes"]) == ["x", "z"]
    z = out["axes"]["z"]
    assert z["kind"] == "cia402" and z["position"] == 0 and z["units"] == "mm" and z["enabled"] is False
    assert z["last_move"] is None
    r = cli("status", served.path)
    assert r.returncode == 0
    assert re.search(r"^z\s+cia402\s+0\s+mm\s+-\s+", r.stdout, re.M), r.stdout


def test_enable_disable_clear_and_move_json(served):
    r = cli("enable", served.path, "z")
    assert r.returncode == 0 and r.stdout.startswith("z: enabled; enabled"), r
    r = cli("status", served.path, "--json")
    assert json.loads(r.stdout)["axes"]["z"]["enabled"] is True   # enable left it enabled
    r = cli("move", served.path, "z", "12.5", "--velocity", "100", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out == {"axis": "z", "kind": "cia402", "what": "move", "target": 12.5, "position": 12.5, "units": "mm",
                   "outcome": "done", "reason": "", "code": None, "exit_code": 0}
    r = cli("home", served.path, "z", "--method", "35", "--json")        # 35: here is home
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) == {"axis": "z", "kind": "cia402", "what": "home", "target": None, "position": 0.0,
                                    "units": "mm", "outcome": "done", "reason": "", "code": None, "exit_code": 0}
    r = cli("move", served.path, "x", "0.5", "--by")
    assert r.returncode == 0 and r.stdout == "x: 0.5 mm\n", r
    r = cli("disable", served.path, "z")
    assert r.returncode == 0 and r.stdout.startswith("z: disabled; -"), r
    r = cli("clear", served.path, "z")
    assert r.returncode == 0 and r.stdout.startswith("z: faults cleared"), r


def test_config_read_json(served):
    with open(served.path, "a") as f:
        f.write('params = { "0x6081" = 12345 }\n')          # on axis z (the last table)
    r = cli("config", "diff", served.path, "--json")
    assert r.returncode == 3 and json.loads(r.stdout) == [{"axis": "z", "parameter": "0x6081", "file": 12345,
                                                            "drive": json.loads(r.stdout)[0]["drive"]}], r
    r = cli("config", "apply", served.path, "--axis", "z")
    assert r.returncode == 0, r.stderr
    r = cli("config", "read", served.path, "--json")
    assert r.returncode == 0 and json.loads(r.stdout) == {"x": {}, "z": {"0x6081": 12345}}, r


def test_scan_shows_identities_in_hex_and_writes_a_bench_that_works(served, tmp_path):
    out = tmp_path / "found.toml"
    r = cli("scan", "--can", served.socketcand, "--kind", "cia402", "--quiet", "--write", out)
    assert r.returncode == 0, r.stderr
    assert re.search(r"^cia402\s+5\s+socketcand:\S+\s+device_type=0x00420192, vendor_id=0x", r.stdout, re.M), r.stdout
    r = cli("scan", "--can", served.socketcand, "--kind", "cia402", "--json")
    found = json.loads(r.stdout)["found"]
    assert [(f["kind"], f["address"], f["identity"]["device_type"]) for f in found] == [("cia402", "5", 0x00420192)]
    r = cli("status", out, "--json")
    assert r.returncode == 0 and [a["kind"] for a in json.loads(r.stdout)["axes"].values()] == ["cia402"], r


def test_json_commands_say_their_errors_in_json(served):
    r = cli("move", served.path, "nope", "1", "--json")
    assert r.returncode == 2
    assert json.loads(r.stdout) == {"error": "InvalidArgument", "exit_code": 2,
                                    "message": f"bench {served.path}: no axis 'nope' (axes: x, z)"}


def test_busy_port_has_its_own_exit_code(served):
    # A program holding the serial line: the command cannot open it, and says who has it.
    holder = subprocess.Popen([*MOTORBUS, "move", served.path, "x", "50"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    try:
        assert holder.stderr.readline().startswith("x: moving to 50 mm")
        r = cli("status", served.path)
        assert r.returncode == 4, r
        assert "is busy: already open by pid" in r.stderr and "Traceback" not in r.stderr
        # stop z opens only the CAN bus: the busy serial line does not stand in its way
        r = cli("stop", served.path, "z")
        assert r.returncode == 0 and r.stdout == "z: stopped\n", r
    finally:
        holder.send_signal(signal.SIGINT)
        holder.communicate(timeout=20)


def test_stop_opens_only_the_named_axis_links(served, tmp_path):
    # x's line points nowhere: `stop BENCH z` does not need it, `stop BENCH` (all) does.
    text = open(served.path).read()
    broken = tmp_path / "broken.toml"
    broken.write_text(re.sub(r'port = "[^"]+"', 'port = "/dev/nonexistent-tty"', text))
    r = cli("stop", broken, "z")
    assert r.returncode == 0 and r.stdout == "z: stopped\n", r
    r = cli("stop", broken)
    assert r.returncode == 2 and "line.l0.port" in r.stderr, r
    r = cli("stop", broken, "nope")
    assert r.returncode == 2 and "no axis 'nope' (axes: x, z)" in r.stderr, r


def test_unreachable_bus_is_not_a_usage_error(tmp_path):
    # A socketcand server that is not there: the link code (5), not "the file is wrong" (2).
    p = tmp_path / "b.toml"
    p.write_text('[bus.can0]\nspec = "socketcand:127.0.0.1:1/can0"\n[axis.z]\nkind = "cia402"\nbus = "can0"\n'
                 'address = 5\n')
    r = cli("status", p)
    assert r.returncode == 5, r
    assert "Traceback" not in r.stderr


def test_trace_shows_frames_and_lines(served):
    r = cli("--trace", "status", served.path)
    assert r.returncode == 0, r.stderr
    err = r.stderr
    # serial: the arcus requests and replies; CAN: the SDO requests and answers on node 5
    assert re.search(r"motorbus\.trace: l0 > @01MST$", err, re.M), err
    assert re.search(r"motorbus\.trace: l0 < ", err), err
    assert re.search(r"motorbus\.trace: can0 605#\w+  \(SDO request, node 5\)", err), err
    assert re.search(r"motorbus\.trace: can0 585#\w+  \(SDO answer, node 5\)", err), err
    r = cli("-vv", "move", served.path, "x", "0.25")
    assert r.returncode == 0
    assert "motorbus.drive: x: move_to 0.25 mm" in r.stderr and "motorbus.trace" not in r.stderr, r.stderr
    assert "motorbus.drive: x: move ended: done" in r.stderr
    r = cli("move", served.path, "x", "0.5", "-v")          # -v after the command works too: INFO only
    assert r.returncode == 0
    assert "motorbus.cli_bench: " in r.stderr and "opened x (lines: l0; buses: none)" in r.stderr, r.stderr
    assert "motorbus.drive" not in r.stderr


def test_line_link_trace_reports_requests_replies_and_timeouts():
    from motorbus import _core
    seen = []
    with _core.serial.PtyLineServer([_core.serial.EchoLineDevice("E:")]) as server:
        link = _core.serial.LineLink(_core.serial.open_port(server.slave_path), reply_timeout=0.2)
        link.set_trace(lambda direction, data: seen.append((direction, bytes(data))))
        assert link.transact("hello\x01") == b"E:hello\x01"
        link.set_trace(None)
        assert link.transact("quiet") == b"E:quiet"
    assert seen == [(">", b"hello\x01"), ("<", b"E:hello\x01")]
    with _core.serial.PtyPair() as pair:          # nobody answers on the other side
        link = _core.serial.LineLink(pair.open_slave(), reply_timeout=0.1)
        link.set_trace(lambda direction, data: seen.append((direction, bytes(data))))
        with pytest.raises(motorbus.TimeoutError):
            link.transact("ping")
        with pytest.raises(motorbus.InvalidArgument):
            link.set_trace(42)
    assert seen[2:] == [(">", b"ping"), ("!", b"no reply within 100 ms")]


# ---- read-only commands leave a moving axis alone (issue 28, item 2) ------------------------------------

CAN_KINDS = {
    "cia402": ("5", 0.01, {}, _cia_setup),
    "arcus-canopen": ("1", 0.01, {}, None),
    "unitek": ("0x201", 0.01, {"calibrated": True}, None),
    "pmc007": ("5", 0.01, {}, None),
}


@pytest.mark.parametrize("kind", sorted(CAN_KINDS))
def test_status_and_config_from_another_process_do_not_stop_a_jog(tmp_path, kind):
    address, scale, sim_options, setup = CAN_KINDS[kind]
    s = Served(tmp_path, [f"{kind}:{address}"], {kind: sim_options}, f"""\
        [axis.a]
        kind = "{kind}"
        bus = "can0"
        address = "{address}"
        units = {{ name = "mm", scale = {scale} }}
        """)
    try:
        d = motorbus.open_drive(kind, bus=s.socketcand, address=address, units=Units("mm", scale))
        try:
            if setup:
                setup(d)
            d.enable()
            d.jog(20.0)
            time.sleep(0.3)
            assert d.status.moving
            d.on_exit = None
        finally:
            d.close()        # closing stops nothing: the axis jogs on with nobody talking to it
        for args in (["status"], ["config", "read"], ["config", "diff"]):
            r = cli(*args, s.path)
            assert r.returncode == 0, (args, r.stderr)
        d = motorbus.open_drive(kind, bus=s.socketcand, address=address, units=Units("mm", scale))
        try:
            p0 = d.position
            time.sleep(0.3)
            p1 = d.position
            assert d.status.moving and p1 > p0 + 1, (kind, p0, p1)    # still jogging at 20 mm/s
            d.stop()
        finally:
            d.close()
    finally:
        s.close()


def test_terminal_on_a_canopen_axis_says_it_speaks_sdo(tmp_path, bench_file):
    import shutil
    if shutil.which("tmux") is None:
        pytest.skip("tmux is not installed (Makefile APT_PACKAGES)")
    from test_cli_terminal import Pane

    pane = Pane(tmp_path)
    try:
        pane.type(f"{sys.executable} -m motorbus terminal {bench_file} z --sim")
        text = pane.wait_for("\nz>", 60)
        assert "z: cia402 (CANopen) — SDO reads and writes; 'quit' leaves" in text
        assert "r INDEX[:SUB] [TYPE]" in text and "w INDEX[:SUB] VALUE [TYPE]" in text
        pane.type("r 0x1000 u32")
        assert "4325778" in pane.wait_for("4325778", 20)       # 0x00420192: profile 402
        pane.type("quit; echo EXIT\"\"=$?")
    finally:
        pane.close()

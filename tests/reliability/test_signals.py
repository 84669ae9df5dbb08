"""Issue 28 item 1: SIGTERM and SIGHUP stop every motor, as Ctrl-C does, and the process
then dies by that signal (the parent sees -signum).

The simulators must outlive the process that is ended, so they are served HERE (every
registered kind: serial kinds on ptys, CAN kinds behind socketcand on 127.0.0.1) and the
child opens them through a bench file, as it would open hardware.  Whether every shaft came
to rest is read from the simulators, from outside the child.  Four ways in: the Drive API
(a wait inside the drive when the signal lands), a `with Bench`, the `motorbus move` command
(one process per kind), an inner pytest session with the plugin and `--bench FILE`.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from test_pytest_plugin import _JOGGING_TESTS, _SIM_POSITION, ServedBench, _plugin_args  # noqa: E402

from _soak import size  # noqa: E402

pytestmark = pytest.mark.subprocess

SIGNALS = [signal.SIGTERM, signal.SIGHUP]
#: Seconds from the child's end to a shaft at rest.  What a stop takes on these simulators
#: (the test profiles: ramps of 20 ms or less, UNITEK's decelerating stop up to 1 s), with
#: room for a loaded 2-core host; it turns "never stops" into a failure, it measures nothing.
STOP_TIME = {kind: 3.0 for kind in _SIM_POSITION}
ROUNDS = size(1, 5)


def _signals_default() -> None:
    # A test run started under nohup or in the background inherits SIGHUP/SIGINT ignored,
    # and motorbus rightly leaves an ignored signal alone: give the child the defaults.
    for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(s, signal.SIG_DFL)


@pytest.fixture
def served(tmp_path):
    s = ServedBench(tmp_path)
    yield s
    s.close()


def _wait_all_moving(served, proc, limit=60.0):
    deadline = time.monotonic() + limit
    while True:
        moving = served.moving(settle=0.15)
        if sorted(moving) == sorted(served.kinds):
            return
        if proc.poll() is not None:
            pytest.fail(f"child ended before every axis moved (rc {proc.returncode}): {proc.communicate()[0]}")
        assert time.monotonic() < deadline, f"not every shaft turns: {moving}"


def _assert_at_rest(served, ended_at: float) -> dict:
    """Every shaft stops within its kind's STOP_TIME of the child's end; returns the
    seconds each took (from the end of the child)."""
    took = {}
    last = served.positions()
    still = set(served.kinds)
    deadline = ended_at + max(STOP_TIME.values())
    while still:
        time.sleep(0.1)
        now = served.positions()
        t = time.monotonic() - ended_at
        for k in list(still):
            if now[k] == last[k]:
                took[k] = t
                still.discard(k)
        last = now
        assert time.monotonic() < deadline, f"still moving {max(STOP_TIME.values())} s after the end: {sorted(still)}"
    time.sleep(0.3)   # and they stay at rest: nothing restarted them
    assert served.moving(settle=0.2) == []
    for k, t in took.items():
        assert t <= STOP_TIME[k], (k, t)
    print("at rest after the child's end (s, 0.1 s resolution):", {k: round(t, 2) for k, t in sorted(took.items())})
    return took


def _end(proc, sig, timeout=30.0):
    sent = time.monotonic()
    proc.send_signal(sig)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, _ = proc.communicate()
        pytest.fail(f"{sig.name}: the child did not end in {timeout} s: {out}")
    ended = time.monotonic()
    print(f"{sig.name} to the child's end: {1000 * (ended - sent):.0f} ms")
    return out, ended


_CHILD_BENCH = """
import sys, time, motorbus
bench = motorbus.Bench.load(sys.argv[1])
with bench:
    bench.apply()
    for name, d in bench.axes.items():
        d.enable()
        d.jog(JOG[name])
    print("READY", flush=True)
    while True:
        time.sleep(1)
"""

_CHILD_DRIVE_API = """
import sys, tomllib, motorbus
with open(sys.argv[1], "rb") as f:
    spec = tomllib.load(f)
drives = {}
for name, a in spec["axis"].items():   # each drive opened on its own, as a script without a bench would
    where = {"line": spec["line"][a["line"]]["port"]} if "line" in a else {"bus": spec["bus"][a["bus"]]["spec"]}
    d = motorbus.open_drive(a["kind"], address=a["address"], units=motorbus.Units("mm", a["units"]["scale"]),
                            **where)
    for p, v in a.get("params", {}).items():
        d.params[p] = v
    d.enable()
    d.jog(JOG[name])
    drives[name] = d
print("READY", flush=True)
next(iter(drives.values())).wait_idle()   # a jog never comes to rest: the signal lands inside the drive's wait
"""


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: s.name)
@pytest.mark.parametrize("how", ["bench", "drive_api"])
def test_signal_stops_every_kind_and_the_child_dies_by_it(served, tmp_path, how, sig):
    code = f"JOG = {served.jog!r}\n" + (_CHILD_BENCH if how == "bench" else _CHILD_DRIVE_API)
    for _ in range(ROUNDS):
        proc = subprocess.Popen([sys.executable, "-c", code, str(served.path)], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, preexec_fn=_signals_default)
        try:
            assert proc.stdout.readline().strip() == "READY", proc.communicate()[0]
            _wait_all_moving(served, proc)
            out, ended = _end(proc, sig)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
        _assert_at_rest(served, ended)
        assert proc.returncode == -sig, f"rc {proc.returncode}: {out}"
        assert f"motorbus: {sig.name}: stopping every drive" in out, out


def _toml(value) -> str:
    if isinstance(value, dict):
        return "{ " + ", ".join(f'"{k}" = {_toml(v)}' for k, v in value.items()) + " }"
    if isinstance(value, str):
        return '"' + value + '"'
    return repr(value)


def _one_axis_files(served, tmp_path) -> dict:
    """A bench file per axis (two `motorbus move` processes must not share one serial line)."""
    import tomllib

    spec = tomllib.loads(served.path.read_text())
    files = {}
    for name, axis in spec["axis"].items():
        lines = []
        if "line" in axis:
            lines += [f"[line.{axis['line']}]", f"port = {_toml(spec['line'][axis['line']]['port'])}"]
        else:
            lines += [f"[bus.{axis['bus']}]", f"spec = {_toml(spec['bus'][axis['bus']]['spec'])}"]
        lines.append(f"[axis.{name}]")
        lines += [f"{k} = {_toml(v)}" for k, v in axis.items()]
        path = tmp_path / f"{name}.toml"
        path.write_text("\n".join(lines) + "\n")
        files[name] = path
    return files


#: mm per kind for a move still running when the last kind has started: the UNITEK twin positions
#: at 3000 rpm (2000 mm = 3 revolutions take 60 ms, over before a loaded host starts the others).
DISTANCE = {"unitek": "200000"}


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: s.name)
def test_signal_during_cli_move_stops_the_axis(served, tmp_path, sig):
    """`motorbus move BENCH AXIS +2000 mm`, one process per kind, all ended by the signal."""
    for round_ in range(ROUNDS):
        if round_:   # fresh simulators at 0: another +2000 mm would run into a limit switch
            served.close()
            (tmp_path / f"round{round_}").mkdir()
            served = ServedBench(tmp_path / f"round{round_}")
        files = _one_axis_files(served, tmp_path / (f"round{round_}" if round_ else ""))
        procs = {}
        try:
            for name, path in files.items():
                for attempt in (1, 2):   # the test profile; what is tested is the move below
                    done = subprocess.run([sys.executable, "-m", "motorbus", "config", "apply", str(path)],
                                          capture_output=True, text=True, timeout=60, preexec_fn=_signals_default)
                    if done.returncode == 0:
                        break
                    print(f"{name}: config apply, attempt {attempt}: {done.stdout}{done.stderr}")
                assert done.returncode == 0, f"{name}: config apply: {done.stdout}{done.stderr}"
                procs[name] = subprocess.Popen(
                    [sys.executable, "-m", "motorbus", "move", str(path), name, DISTANCE.get(name, "2000"), "--by",
                     "--timeout", "600"],
                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, preexec_fn=_signals_default)
            deadline = time.monotonic() + 60
            while sorted(served.moving(settle=0.15)) != sorted(served.kinds):
                for name, p in procs.items():
                    assert p.poll() is None, f"{name}: ended before moving: {p.communicate()[0]}"
                assert time.monotonic() < deadline, served.moving()
            for p in procs.values():
                p.send_signal(sig)
            outs = {name: p.communicate(timeout=30)[0] for name, p in procs.items()}
            ended = time.monotonic()
        finally:
            for p in procs.values():
                if p.poll() is None:
                    p.kill()
                    p.communicate()
        try:
            _assert_at_rest(served, ended)
        finally:
            if round_:
                served.close()
        for name, p in procs.items():
            assert p.returncode == -sig, f"{name}: rc {p.returncode}: {outs[name]}"
            assert "interrupted: axis stopped" in outs[name], outs[name]


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: s.name)
def test_signal_to_an_inner_pytest_session_stops_every_axis(served, tmp_path, sig):
    (tmp_path / "inner").mkdir()
    (tmp_path / "inner" / "test_jogging.py").write_text(_JOGGING_TESTS.format(jog=served.jog))
    checkpoints = tmp_path / "checkpoints"
    checkpoints.mkdir()
    env = dict(os.environ, CHECKPOINTS=str(checkpoints))
    proc = subprocess.Popen([sys.executable, "-m", "pytest", *_plugin_args(), "-p", "no:cacheprovider", "-v",
                             "--bench", str(served.path), "-k", "fails_mid_jog", "test_jogging.py"],
                            cwd=tmp_path / "inner", env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, preexec_fn=_signals_default)
    try:
        deadline = time.monotonic() + 90
        while not (checkpoints / "failure-jogging.ready").exists():
            assert proc.poll() is None, f"inner pytest ended early: {proc.communicate()[0]}"
            assert time.monotonic() < deadline
            time.sleep(0.02)
        assert sorted(served.moving()) == sorted(served.kinds)
        out, ended = _end(proc, sig, timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    _assert_at_rest(served, ended)
    assert proc.returncode == -sig, f"rc {proc.returncode}: {out}"
    assert "KeyboardInterrupt" in out or "TerminatedBySignal" in out, out


def _run_child(served, code: str, sig, *, timeout=30.0) -> tuple[str, int]:
    proc = subprocess.Popen([sys.executable, "-c", f"JOG = {served.jog!r}\n" + code, str(served.path)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, preexec_fn=_signals_default)
    try:
        lines = []
        while True:
            line = proc.stdout.readline()
            assert line, f"child ended before READY: {''.join(lines)}{proc.communicate()[0]}"
            lines.append(line)
            if line.strip() == "READY":
                break
        _wait_all_moving(served, proc)
        out, ended = _end(proc, sig, timeout=timeout)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    _assert_at_rest(served, ended)
    return "".join(lines) + out, proc.returncode


def test_a_swallowed_interrupt_does_not_keep_the_motors_running(served):
    """The program catches KeyboardInterrupt and goes on: the watchdog stops every drive
    GRACE s after the signal, from its own thread, and the process still dies by it."""
    code = _CHILD_BENCH.replace("import sys, time, motorbus", "import sys, time, motorbus\n"
                                "motorbus._stop_at_exit.GRACE = 0.5").replace(
        "    while True:\n        time.sleep(1)\n",
        "    while True:\n        try:\n            time.sleep(1)\n        except KeyboardInterrupt:\n"
        "            print('SWALLOWED', flush=True)\n")
    out, rc = _run_child(served, code, signal.SIGTERM)
    assert "SWALLOWED" in out and rc == -signal.SIGTERM, (rc, out)


_CHILD_OWN_HANDLER = """
import signal, sys, time, motorbus
def mine(signum, frame):
    print("MINE", signal.Signals(signum).name, flush=True)
    motorbus.stop_on_signal(signum, frame)     # then what motorbus does: stop, die by the signal
signal.signal(signal.SIGTERM, mine)
signal.signal(signal.SIGHUP, signal.SIG_IGN)   # as under nohup
bench = motorbus.Bench.load(sys.argv[1])
print("TERM kept:", signal.getsignal(signal.SIGTERM) is mine,
      "HUP kept:", signal.getsignal(signal.SIGHUP) is signal.SIG_IGN, flush=True)
with bench:
    bench.apply()
    for name, d in bench.axes.items():
        d.enable()
        d.jog(JOG[name])
    print("READY", flush=True)
    while True:
        time.sleep(1)
"""


def test_a_programs_own_handler_is_kept_and_can_hand_over_to_motorbus(served):
    out, rc = _run_child(served, _CHILD_OWN_HANDLER, signal.SIGTERM)
    assert "TERM kept: True HUP kept: True" in out, out
    assert "MINE SIGTERM" in out and rc == -signal.SIGTERM, (rc, out)


def test_no_drive_open_the_signal_ends_the_process_at_once(tmp_path):
    """Handlers stay installed after the last drive closes: a signal then ends the process
    at once, as SIG_DFL would (no unwinding, no watchdog)."""
    code = textwrap.dedent("""
        import signal, sys, time, motorbus
        with motorbus.Bench.from_dict({"bus": {"b": {"spec": "virtual:x"}},
                                       "axis": {"z": {"kind": "cia402", "bus": "b", "address": 5}}}, sim=True):
            pass
        print("installed", signal.getsignal(signal.SIGTERM) is motorbus.stop_on_signal, flush=True)
        print("READY", flush=True)
        time.sleep(60)
        """)
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            preexec_fn=_signals_default)
    try:
        first = proc.stdout.readline()
        assert proc.stdout.readline().strip() == "READY", first + proc.communicate()[0]
        t0 = time.monotonic()
        out, _ = _end(proc, signal.SIGTERM)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert first.strip() == "installed True", first
    assert proc.returncode == -signal.SIGTERM and "stopping" not in out, (proc.returncode, out)
    assert time.monotonic() - t0 < 5   # not the watchdog's GRACE: at once


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: s.name)
def test_signal_during_cli_home_stops_the_axis(tmp_path, sig):
    """`motorbus home`: a DMAC whose reference switch is far away (a search of seconds)."""
    from motorbus.sim import SimBench

    with SimBench(["dmac:00"], sim_options={"dmac": {"reference_switch": 5_000_000}}) as rig:
        sim = rig.sims[("dmac", "00")]
        path = tmp_path / "home.toml"
        path.write_text(f'[line.l]\nport = "{rig.lines[0].pty_path}"\n[axis.d]\nkind = "dmac"\nline = "l"\n'
                        'address = "00"\nparams = { "#LOW_SPEED" = 60000 }\n')
        done = subprocess.run([sys.executable, "-m", "motorbus", "config", "apply", str(path)], capture_output=True,
                              text=True, timeout=60, preexec_fn=_signals_default)
        assert done.returncode == 0, done.stdout + done.stderr
        proc = subprocess.Popen([sys.executable, "-m", "motorbus", "home", str(path), "d", "--timeout", "600"],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                preexec_fn=_signals_default)
        try:
            deadline = time.monotonic() + 30
            while True:
                a = sim.state().position
                time.sleep(0.15)
                if sim.state().position != a:
                    break
                assert proc.poll() is None, proc.communicate()[0]
                assert time.monotonic() < deadline, "the homing search never moved"
            out, ended = _end(proc, sig)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
        last = sim.state().position
        while True:
            time.sleep(0.1)
            now = sim.state().position
            if now == last:
                break
            last = now
            assert time.monotonic() - ended < STOP_TIME["dmac"], "the homing search goes on"
    assert proc.returncode == -sig, f"rc {proc.returncode}: {out}"
    assert "interrupted: axis stopped" in out, out

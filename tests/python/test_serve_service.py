"""``motorbus serve``: the service process and what finds it (docs/serve.md).

One lasting simulated twin (``motorbus sim serve --bench``, another process, as hardware
is) and one ``motorbus serve`` of its bench file for the module, with Channel Access on
this xdist worker's own port.  What is asserted is seen from outside the service: its
lock file, the CLI's exit codes, a CA client using the environment the service printed,
and at the end the twin read directly once SIGTERM has ended the service.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import motorbus
from motorbus.serve import ServedElsewhere, find_service, lock_path
from motorbus.serve.client import RemoteBench, connect
from motorbus.sim import ServedBench

pytestmark = pytest.mark.subprocess
pytest_plugins = ["pytester"]

BENCH = textwrap.dedent("""\
    [epics]
    prefix = "T26S:"

    [line.ser]
    port = "/dev/null-ser"

    [bus.can]
    spec = "virtual:t26"

    [axis.x]
    kind = "arcus"
    line = "ser"
    address = "01"
    units = { name = "mm", scale = 0.01 }
    params = { HSPD = 20000, LSPD = 2000, ACC = 20 }

    [axis.z]
    kind = "cia402"
    bus = "can"
    address = 5
    units = { name = "mm", scale = 0.01 }
    params = { "0x6081" = 20000, "0x6083" = 400000, "0x6084" = 400000 }
    """)


def ca_port() -> int:
    """This xdist worker's CA port (the contract: 20000 + 16*worker; +8 is this module's)."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker[2:].isdigit() else 0
    return 20000 + 16 * index + 8


def motorbus_cli(*args: str, timeout: float = 30.0, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "motorbus", *args], capture_output=True, text=True,
                          timeout=timeout, **kw)


class Service:
    """``motorbus serve`` in a subprocess, its announce lines read up to ``ready``."""

    def __init__(self, bench: str, *args: str) -> None:
        self.err = open(f"{bench}.serve-stderr.txt", "w+")
        self.proc = subprocess.Popen([sys.executable, "-m", "motorbus", "serve", bench, *args],
                                     stdout=subprocess.PIPE, stderr=self.err, text=True)
        self.lines: list[str] = []
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))
            if line.startswith("ready"):
                break
        else:
            raise AssertionError(f"motorbus serve ended ({self.proc.wait()}): {self.stderr()}")

    def stderr(self) -> str:
        self.err.flush()
        with open(self.err.name) as f:
            return f.read()

    def end(self, sig: int = signal.SIGTERM) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            return self.proc.wait(timeout=20)
        finally:
            self.proc.stdout.close()
            self.err.close()


@pytest.fixture(scope="module")
def twin(tmp_path_factory):
    source = tmp_path_factory.mktemp("serve") / "bench.toml"
    source.write_text(BENCH)
    with ServedBench(str(source)) as served:
        yield served


@pytest.fixture(scope="module")
def service(twin):
    s = Service(twin.bench_file, "--ca-port", str(ca_port()))
    try:
        # The file's speeds, applied through the service (config apply goes through it too).
        r = motorbus_cli("config", "apply", twin.bench_file)
        assert r.returncode == 0, r.stderr
        yield s
    finally:
        s.end()


def test_lock_file_finds_the_service_and_its_announce(twin, service):
    info = find_service(twin.bench_file)
    assert info is not None and info.pid == service.proc.pid
    assert info.bench == os.path.realpath(twin.bench_file) and not info.sim
    assert os.path.basename(lock_path(twin.bench_file)) == ".bench.toml.serve.lock"
    assert len(os.fsencode(info.socket)) <= 107 and os.path.exists(info.socket)
    # The twin's serial line (a symlink in its link dir) and its bus are what the service holds.
    assert os.path.join(twin.link_dir, "ser") in info.links and any(s.startswith("socketcand:") for s in info.links)
    assert info.prefix == "T26S:" and info.ca_port == ca_port()          # the file's [epics] prefix
    assert info.env["EPICS_CA_SERVER_PORT"] == str(ca_port())
    assert f"rpc unix:{info.socket}" in service.lines
    assert f"export EPICS_CA_SERVER_PORT={ca_port()}" in service.lines
    # z (cia402) has a watchdog this bench file does not arm; x (arcus) has none to arm.
    notes = [line for line in service.stderr().splitlines() if "watchdog" in line]
    assert len(notes) == 1 and notes[0].startswith("motorbus serve: note: axis z's drive has a watchdog")


def test_a_second_service_of_the_bench_is_refused(twin, service):
    r = motorbus_cli("serve", twin.bench_file, "--no-epics")
    assert r.returncode == 4, r.stderr
    assert f"is served by motorbus serve (pid {service.proc.pid}): a second motorbus serve needs the transports" \
        in r.stderr
    assert find_service(twin.bench_file).pid == service.proc.pid       # the first one is untouched


def test_move_status_and_a_stop_from_another_program_through_the_service(twin, service):
    r = motorbus_cli("move", twin.bench_file, "x", "2.5", "--json")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["position"] == pytest.approx(2.5, abs=0.02)
    # A long move, then `motorbus stop` from a third program: the mover's exit code is the
    # Drive API's "interrupted" (10), and the axis is at rest short of the target.
    mover = subprocess.Popen([sys.executable, "-m", "motorbus", "move", twin.bench_file, "z", "900", "--json"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    with connect(twin.bench_file) as bench:
        deadline = time.monotonic() + 10
        while not (bench["z"].status.moving and bench["z"].position > 5):
            assert time.monotonic() < deadline and mover.poll() is None, mover.communicate()
            time.sleep(0.02)
        r = motorbus_cli("stop", twin.bench_file, "z")
        assert r.returncode == 0 and "z: stopped" in r.stdout, r.stderr
        out, err = mover.communicate(timeout=20)
        assert mover.returncode == 10, err
        result = json.loads(out)
        assert result["outcome"] == "interrupted" and 5 < result["position"] < 900
        assert not bench["z"].status.moving
    r = motorbus_cli("status", twin.bench_file, "--json")
    assert r.returncode == 0, r.stderr
    axes = json.loads(r.stdout)["axes"]
    assert axes["x"]["position"] == pytest.approx(2.5, abs=0.02)
    assert axes["z"]["position"] == pytest.approx(result["position"], abs=0.05)


def test_a_drive_fault_through_the_service_is_exit_code_12(twin, service):
    mover = subprocess.Popen([sys.executable, "-m", "motorbus", "move", twin.bench_file, "z", "800"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    with connect(twin.bench_file) as bench:
        deadline = time.monotonic() + 10
        while not bench["z"].status.moving:
            assert time.monotonic() < deadline and mover.poll() is None, mover.communicate()
            time.sleep(0.02)
        twin.inject("z", "fault")
        out, err = mover.communicate(timeout=20)
        assert mover.returncode == 12, err
        bench["z"].clear_faults()


def test_what_needs_the_transports_is_refused_while_served(twin, service):
    pid = service.proc.pid
    r = motorbus_cli("terminal", twin.bench_file, "x", input="VER\n")
    assert r.returncode == 4
    assert r.stderr.strip() == (f"motorbus: {os.path.realpath(twin.bench_file)} is served by motorbus serve "
                                f"(pid {pid}): a protocol console (terminal) needs the transports; stop the "
                                f"service first")
    spec = next(s for s in find_service(twin.bench_file).links if s.startswith("socketcand:"))
    r = motorbus_cli("bus", "dump", spec, "--count", "1")
    assert r.returncode == 4 and f"(pid {pid}): a bus dump needs the transports" in r.stderr
    line = os.path.join(twin.link_dir, "ser")
    r = motorbus_cli("scan", "--serial", os.path.realpath(line), "--quiet")    # the pty itself: the same line
    assert r.returncode == 4 and f"(pid {pid}): a scan of {os.path.realpath(line)} needs the transports" in r.stderr
    # --no-server opens the transports here: the serial line is the service's (busy), and the
    # message says which program holds it and how to go through it instead.
    r = motorbus_cli("status", twin.bench_file, "--no-server")
    assert r.returncode == 4
    assert f"served by motorbus serve (pid {pid}), which holds its transports: drop --no-server" in r.stderr


def test_channel_access_with_the_printed_environment(twin, service):
    """The CA face of the same service: RBV is where the CLI moved x, read by caproto-get
    with only the environment the service printed (and the lock file holds)."""
    assert motorbus_cli("move", twin.bench_file, "x", "2.5").returncode == 0
    env = {**os.environ, **find_service(twin.bench_file).env}
    r = subprocess.run([os.path.join(os.path.dirname(sys.executable), "caproto-get"), "--no-repeater", "-n",
                        "T26S:x.RBV", "T26S:x.DMOV"], capture_output=True, text=True, timeout=20, env=env)
    assert r.returncode == 0, r.stderr
    values = dict(line.split(None, 1) for line in r.stdout.splitlines())
    assert float(values["T26S:x.RBV"].strip("[]")) == pytest.approx(2.5, abs=0.02)
    assert values["T26S:x.DMOV"].strip("[]") == "1"


def test_pytest_plugin_bench_server(twin, service, pytester):
    """``pytest --bench-server``: the bench, axis and poller fixtures come from the service."""
    pytester.makepyfile(test_served="""
        import time
        import pytest
        from motorbus.serve.client import RemoteBench, RemotePoller

        def test_bench_is_the_service(bench):
            assert isinstance(bench, RemoteBench) and set(bench.axes) == {"x", "z"}

        @pytest.mark.axes("x")
        def test_axis_and_poller(axis, poller):
            assert isinstance(poller, RemotePoller)
            if not axis.status.enabled:
                axis.enable()
            axis.move_to(1.0)
            assert axis.position == pytest.approx(1.0, abs=0.02)
            seen, deadline = [], time.monotonic() + 5     # rows come in chunks from the service
            while not (seen and abs(seen[-1] - 1.0) < 0.02) and time.monotonic() < deadline:
                time.sleep(0.05)
                seen.extend(poller.read()["x.position"])
            assert seen[-1] == pytest.approx(1.0, abs=0.02)
        """)
    from importlib import metadata

    # -p motorbus.pytest_plugin unless the installed motorbus declares it (loading it twice is an error)
    plugin = [] if any(ep.value == "motorbus.pytest_plugin" for ep in metadata.entry_points(group="pytest11")) \
        else ["-p", "motorbus.pytest_plugin"]
    result = pytester.runpytest_subprocess(*plugin, "-p", "no:cacheprovider", "--bench-server", twin.bench_file,
                                           timeout=60)
    result.assert_outcomes(passed=2)
    r = motorbus_cli("status", twin.bench_file, "--json")
    assert json.loads(r.stdout)["axes"]["x"]["position"] == pytest.approx(1.0, abs=0.02)


def test_sigterm_stops_a_moving_axis_then_ends_the_service(twin, service):
    """Last: SIGTERM while z moves.  The service exits 0, frees the bench, and the twin,
    read directly afterwards, is at rest short of the target."""
    bench = connect(twin.bench_file)
    try:
        if not bench["z"].status.enabled:
            bench["z"].enable()
        start = bench["z"].position
        bench["z"].move_to(start + 300, wait=False)
        deadline = time.monotonic() + 10
        while not bench["z"].position > start + 5:
            assert time.monotonic() < deadline
            time.sleep(0.02)
    finally:
        bench.close()             # closing stops nothing (a wait=False move goes on): the service's stop is under test
    assert service.end(signal.SIGTERM) == 0, service.stderr()
    assert find_service(twin.bench_file) is None
    with motorbus.Bench.load(twin.bench_file) as direct:     # the transports are free again
        z = direct["z"]
        first = z.position
        time.sleep(0.3)
        assert not z.status.moving and z.position == first
        assert start + 5 < first < start + 300


WATCHDOG_BENCH = textwrap.dedent("""\
    [bus.can]
    spec = "virtual:t26wd"

    [axis.z]
    kind = "cia402"
    bus = "can"
    address = 5
    units = { name = "mm", scale = 0.01 }
    params = { "0x6081" = 20000, "0x6083" = 400000, "0x6084" = 400000 }
    options = { watchdog = { host_node = 127, period = 0.05 } }

    [axis.p]
    kind = "pmc007"
    bus = "can"
    address = 7
    units = { name = "mm", scale = 0.01 }
    params = { maximum_speed = 20000 }
    """)


def test_after_sigkill_only_the_drives_watchdogs_act(tmp_path):
    """docs/serve.md's table, for two kinds: a killed service (no shutdown runs) leaves the
    CiA 402 axis, whose heartbeat consumer the bench file arms, quick-stopped by the drive
    itself; the PMC007, which has no communication watchdog, goes on with its move."""
    source = tmp_path / "bench.toml"
    source.write_text(WATCHDOG_BENCH)
    with ServedBench(str(source)) as twin:
        s = Service(twin.bench_file, "--no-epics")
        try:
            assert motorbus_cli("config", "apply", twin.bench_file).returncode == 0
            assert "watchdog" not in s.stderr()        # armed by the file: no note
            bench = connect(twin.bench_file)
            for name in ("z", "p"):
                if not bench[name].status.enabled:
                    bench[name].enable()
                bench[name].move_to(300.0 if name == "z" else 1000.0, wait=False)   # p: 5 s of move left to see
            deadline = time.monotonic() + 10
            while not (bench["z"].position > 5 and bench["p"].position > 5):
                assert time.monotonic() < deadline
                time.sleep(0.02)
            bench.close()
        finally:
            s.end(signal.SIGKILL)
        assert find_service(twin.bench_file) is None     # the kernel let go of the dead service's lock
        time.sleep(0.5)             # the consumer's 150 ms and the quick stop's ramp, on a loaded machine too
        with motorbus.Bench.load(twin.bench_file) as direct:
            z, p = direct["z"], direct["p"]
            z_at, p_at = z.position, p.position
            time.sleep(0.2)
            assert not z.status.moving and z.position == z_at < 300 and not z.status.enabled
            assert p.status.moving and p_at < p.position < 1000


def test_example_13_served_bench():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    r = subprocess.run([sys.executable, os.path.join(root, "examples", "13_served_bench.py")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == [
        "found the service: True, simulated twin: True", "5 parameter(s) written", "x at 5.00 mm, z at 5.00 mm",
        "z: stopped", "z's move: interrupted (MoveInterrupted)", "z at rest short of 900 mm: True",
        "the watcher saw z pass 20 mm: True", "terminal: exit code 4 (True)", "service ended with exit code 0"]


def test_lock_and_the_missing_extra_in_process(tmp_path, monkeypatch):
    """The lock alone: a second holder gets ServedElsewhere naming the first's pid, a released
    lock is free at once; a socket path too long for sun_path is refused by name; and without
    caproto, serving EPICS names the extra and --no-epics, before any transport opens."""
    import asyncio
    import importlib.util

    from motorbus.serve.lockfile import ServiceLock, check_socket_path
    from motorbus.serve.service import BenchService

    bench = tmp_path / "b.toml"
    bench.write_text(BENCH)
    first, second = ServiceLock(bench), ServiceLock(bench)
    first.acquire()
    with pytest.raises(ServedElsewhere, match=rf"\(pid {os.getpid()}\): a second motorbus serve needs"):
        second.acquire()
    first.release()
    second.acquire()
    second.release()
    with pytest.raises(motorbus.InvalidArgument, match="a Unix socket path holds at most 107"):
        check_socket_path(str(tmp_path / ("s" * 120)))

    real_find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "caproto"
                        else real_find_spec(name, *a))
    service = BenchService(bench, sim=True, socket_path=str(tmp_path / "s.sock"))
    with pytest.raises(motorbus.InvalidArgument, match=r"motorbus\[epics\].*--no-epics"):
        asyncio.run(service.start())
    assert service.bench is None and find_service(bench) is None and not os.path.exists(tmp_path / "s.sock")
    again = ServiceLock(bench)         # let go: the next service may take it
    again.acquire()
    again.release()


SLOW_STOP_BENCH = textwrap.dedent("""\
    [bus.can]
    spec = "virtual:t26slow"

    [axis.z]
    kind = "cia402"
    bus = "can"
    address = 5
    units = { name = "mm", scale = 0.01 }
    params = { "0x6081" = 20000, "0x6083" = 400000, "0x6084" = 2000, "0x6085" = 400000 }
    """)


def test_a_second_signal_quick_stops_what_still_brakes(tmp_path):
    """The shutdown's stop brakes at 6084h = 2000 inc/s² (10 s from full speed); a second
    SIGTERM does not wait for that: a quick stop (6085h), and the service ends at once."""
    source = tmp_path / "bench.toml"
    source.write_text(SLOW_STOP_BENCH)
    with ServedBench(str(source)) as twin:
        s = Service(twin.bench_file, "--no-epics")
        try:
            assert motorbus_cli("config", "apply", twin.bench_file).returncode == 0
            bench = connect(twin.bench_file)
            bench["z"].enable()
            bench["z"].move_to(1000.0, wait=False)
            deadline = time.monotonic() + 10
            while bench["z"].velocity < 190:      # at speed (200 mm/s)
                assert time.monotonic() < deadline
                time.sleep(0.02)
            bench.close()
            s.proc.send_signal(signal.SIGTERM)
            time.sleep(0.5)                       # braking: far from rest yet
            assert s.proc.poll() is None
            t = time.monotonic()
            s.proc.send_signal(signal.SIGTERM)
            assert s.proc.wait(timeout=20) == 0 and time.monotonic() - t < 3
            assert "z: a second signal: quick stop" in s.stderr()
        finally:
            s.end()
        time.sleep(0.5)      # the quick stop's own ramp (6085h: under 0.1 s), even on a loaded machine
        with motorbus.Bench.load(twin.bench_file) as direct:
            at = direct["z"].position
            time.sleep(0.2)
            # Braking at 6084h alone from ~190 mm/s would run on for ~9 s and ~900 mm more.
            assert not direct["z"].status.moving and direct["z"].position == at < 400

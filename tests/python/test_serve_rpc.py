"""The native face of ``motorbus serve`` (serve/rpc.py + serve/client.py): a served bench used
from other connections through ``Bench.connect`` / ``aio.Bench.connect``, the Drive API exactly.

One service per module: ``start_rpc`` on an ``aio.Bench.from_dict(..., sim=True)`` (a serial
arcus axis on a pty, two CANopen cia402 nodes and a unitek behind socketcand on 127.0.0.1) in a
thread of its own with its own event loop, as ``motorbus serve`` runs it.  What the clients see
is checked against the simulators themselves (the shaft, not the drive objects' word).
"""
from __future__ import annotations

import asyncio
import os
import socket
import threading
import time
from typing import Any

import numpy as np
import pytest

import motorbus
from motorbus import aio, registry
from motorbus.serve import client as rclient
from motorbus.serve import rpc
from motorbus.serve.lockfile import ServedElsewhere

MM = {"name": "mm", "scale": 0.01}
BENCH = {
    "line": {"l1": {"port": "/dev/null-arcus"}},
    "bus": {"c1": {"spec": "virtual:cia"}, "c2": {"spec": "virtual:unitek"}},
    "axis": {
        "x": {"kind": "arcus", "line": "l1", "address": "01", "units": MM,
              "params": {"HSPD": 20000, "LSPD": 2000, "ACC": 20}},
        "z": {"kind": "cia402", "bus": "c1", "address": 5, "units": MM,
              "params": {"0x6081": 20000, "0x6083": 400000, "0x6084": 400000}},
        "f": {"kind": "cia402", "bus": "c1", "address": 6, "units": MM,     # the one the faults spoil
              "params": {"0x6081": 20000, "0x6083": 400000, "0x6084": 400000}},
        "u": {"kind": "unitek", "bus": "c2", "address": "0x201", "units": MM, "params": {"ACC_RAMP": 20},
              "sim": {"calibrated": True, "dec_ramp_ms": 20}},
    },
}
#: The simulator's shaft, native units (read from the simulator, not through any Drive).
SHAFT = {"arcus": lambda sim: sim.pulse_position, "cia402": lambda sim: sim.position,
         "unitek": lambda sim: sim.position_num}


class Service:
    """start_rpc on a simulated aio.Bench, on a loop in its own thread."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.loop = asyncio.new_event_loop()
        self.ready = threading.Event()
        self.error: Any = None
        self.thread = threading.Thread(target=self._run, name="test-serve-loop", daemon=True)
        self.thread.start()
        assert self.ready.wait(60), "the service did not start"
        if self.error is not None:
            raise self.error

    def _run(self) -> None:
        asyncio.set_event_loop(self.loop)

        async def start() -> None:
            try:
                self.bench = await aio.Bench.from_dict(BENCH, sim=True)
                self.face = await rpc.start_rpc(self.bench, self.path,
                                                info={"pid": os.getpid(), "bench": "/lab/test-bench.toml"})
            except BaseException as e:  # noqa: BLE001 - said by the constructor
                self.error = e
            finally:
                self.ready.set()

        self.loop.run_until_complete(start())
        self.loop.run_forever()

    def run(self, coro: Any, timeout: float = 30.0) -> Any:
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def shaft(self, axis: str) -> float:
        """Where the simulated shaft is, user units."""
        kind = self.bench.sync.config[axis].kind
        return SHAFT[kind](self.bench.sync.sims[axis]) * 0.01

    def fault(self, axis: str, name: str, **options: Any) -> None:
        kind = self.bench.sync.config[axis].kind
        registry.drive_plugin(kind).sim_faults()[name](self.bench.sync.sims[axis], **options)

    def close(self) -> None:
        async def stop() -> None:
            await self.face.close()
            await self.bench.stop_all()
            await self.bench.aclose()
        try:
            self.run(stop())
        finally:
            self.loop.call_soon_threadsafe(self.loop.stop)
            self.thread.join(10)


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    s = Service(str(tmp_path_factory.mktemp("serve") / "rpc.sock"))
    yield s
    s.close()


@pytest.fixture(scope="module")
def bench(service):
    b = motorbus.Bench.connect(f"unix:{service.path}")
    b.apply()                       # the file's fast profiles (and a round trip of apply)
    for d in b.axes.values():
        d.enable()
    yield b
    b.close()


def in_thread(call) -> tuple[threading.Thread, dict]:
    """Runs a blocking call (a move another connection will cut short) in a thread; its
    error, if any, lands in the dict under "error"."""
    result: dict = {}

    def run() -> None:
        try:
            call()
        except BaseException as e:  # noqa: BLE001 - the test looks at it
            result["error"] = e
    t = threading.Thread(target=run)
    t.start()
    return t, result


def wait_for(cond: Any, timeout: float = 10.0, what: str = "the condition") -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < deadline, f"{what} not within {timeout} s"
        time.sleep(0.01)


# ---- the bench as the service has it ------------------------------------------------------------
def test_connect_gives_drives_of_the_served_bench(service, bench):
    assert set(bench.axes) == {"x", "z", "f", "u"} and len(bench) == 4 and list(bench) == ["x", "z", "f", "u"]
    assert bench.simulated and bench.source == "<dict>"
    assert set(bench.lines) == {"l1"} and set(bench.buses) == {"c1", "c2"}
    assert bench.config["u"].kind == "unitek" and bench.config["z"].address == "5"
    assert bench.config["x"].units == motorbus.Units("mm", 0.01)
    assert bench.info == {"pid": os.getpid(), "bench": "/lab/test-bench.toml"}
    for name, d in bench.axes.items():
        local = service.bench[name].sync
        assert isinstance(d, motorbus.Drive) and d.name == name
        assert d.kind == local.kind and d.units == local.units and d.capabilities == local.capabilities
        assert isinstance(aio.Drive(d), aio.Drive)
    with pytest.raises(motorbus.InvalidArgument, match="no axis 'nope'.*axes: x, z, f, u"):
        bench["nope"]
    assert bench.select(["u", "x"]) == {"u": bench["u"], "x": bench["x"]}
    # The file's parameters were applied through the service: no difference left.
    assert bench.diff() == []
    assert bench.read_params(["z"]) == {"z": {"0x6081": 20000, "0x6083": 400000, "0x6084": 400000}}


@pytest.mark.parametrize("axis", ["x", "z", "u"])
def test_every_verb_round_trips(service, bench, axis):
    d = bench[axis]
    local = service.bench[axis].sync
    d.enable()
    st = d.status
    assert isinstance(st, motorbus.DriveStatus) and st.enabled and not st.moving
    d.move_to(3.0, timeout=10)
    assert service.shaft(axis) == pytest.approx(3.0, abs=0.011)
    assert d.position == pytest.approx(3.0, abs=0.011)
    assert d.status.last_move.ok and d.status.last_move.target == pytest.approx(3.0)
    d.move_by(-1.0, timeout=10)
    assert service.shaft(axis) == pytest.approx(2.0, abs=0.011)
    d.move_to(6.0, wait=False)
    d.wait_idle(timeout=10)
    assert service.shaft(axis) == pytest.approx(6.0, abs=0.011)
    d.jog(20.0)
    wait_for(lambda: service.shaft(axis) > 6.5, what=f"{axis} jogging")
    assert d.status.moving and d.velocity > 0
    d.stop()
    d.wait_idle(timeout=10)          # a jog ended by this program's stop is a success
    assert d.status.last_move.what == "jog" and d.status.last_move.ok
    d.move_to({"u": 4000.0}.get(axis, 300.0), wait=False)    # far: not there before the quick stop
    d.quick_stop()
    with pytest.raises(motorbus.MoveInterrupted):
        d.wait_idle(timeout=10)
    d.clear_faults()
    lo, hi = d.travel_limits
    assert (lo, hi) == local.travel_limits and lo <= hi
    # params: names, descriptions, reads and writes, all the service's Drive's
    assert list(d.params) == list(local.params) and len(d.params) == len(local.params)
    name = {"x": "HSPD", "z": "0x6081", "u": "ACC_RAMP"}[axis]
    assert name in d.params and "no-such-param" not in d.params
    assert d.params.describe(name) == local.params.describe(name)
    old = d.params[name]
    d.params[name] = old + 1
    assert local.params[name] == old + 1
    d.params[name] = old
    with pytest.raises(motorbus.drive.UnknownParameter) as e:
        d.params["no-such-param"]
    assert isinstance(e.value, KeyError)
    d.disable()
    assert not d.status.enabled
    d.enable()


def test_home_and_store_go_through(service, bench):
    z = bench["z"]
    z.move_to(2.0, timeout=10)
    z.home(19, timeout=20)
    st = z.status
    assert st.homed and st.last_move.what == "home" and st.last_move.ok
    assert z.position == pytest.approx(0.0, abs=0.011)
    z.store()                       # CiA 301 1010h on the simulator: no error
    bench.store(["u"])              # the bench-wide verb, on one axis


def test_bad_arguments_come_back_typed(bench):
    with pytest.raises(motorbus.InvalidArgument, match="position must be a finite number"):
        bench["z"].move_to("far")
    with pytest.raises(motorbus.InvalidArgument, match="timeout must be >= 0"):
        bench["z"].wait_idle(-1)
    with pytest.raises(motorbus.InvalidArgument, match="Bench.stop_all how"):
        bench.stop_all("brake")
    with pytest.raises(motorbus.InvalidArgument, match="no axis 'q'"):
        bench.move_together({"q": 1.0})


# ---- outcomes: the exact MoveFailed subclass, with its fields ------------------------------------
def test_a_drive_fault_during_a_move_is_a_move_faulted_with_its_fields(service, bench):
    f = bench["f"]
    f.enable()
    t, result = in_thread(lambda: f.move_to(300.0, timeout=20))
    wait_for(lambda: service.shaft("f") > 5.0, what="f moving")
    service.fault("f", "fault", code=0x5441)
    t.join(20)
    e = result["error"]
    assert type(e) is motorbus.MoveFaulted and isinstance(e, motorbus.DriveFault)
    assert e.axis == "f" and e.target == pytest.approx(300.0) and e.units == "mm" and e.outcome == "fault"
    assert e.position == pytest.approx(service.shaft("f"), abs=0.011) and e.position < 300.0
    local = service.bench["f"].sync.status.last_move.error
    assert (str(e), e.reason, e.code, e.status) == (str(local), local.reason, local.code, local.status)
    assert f.status.fault and f.status.last_move.state == "fault"
    f.clear_faults()
    f.enable()
    assert not f.status.fault


def test_a_limit_switch_is_limit_reached_with_its_side(service, bench):
    x = bench["x"]
    x.move_to(0.0, timeout=10)
    service.fault("x", "limit", direction=1)
    try:
        with pytest.raises(motorbus.LimitReached) as e:
            x.move_to(50.0, timeout=10)
        assert e.value.side == 1 and e.value.axis == "x" and e.value.target == pytest.approx(50.0)
        assert e.value.outcome == "limit" and e.value.position == pytest.approx(service.shaft("x"), abs=0.011)
    finally:
        service.bench.sync.sims["x"].force_limit(1, None)   # released, then the latch cleared
        x.clear_faults()
        x.enable()
    x.move_to(1.0, timeout=10)
    assert service.shaft("x") == pytest.approx(1.0, abs=0.011)


# ---- several programs at once -------------------------------------------------------------------
def test_a_stop_from_another_connection_stops_a_move_this_one_awaits(service, bench):
    z = bench["z"]
    z.move_to(0.0, timeout=10)
    other = motorbus.Bench.connect(f"unix:{service.path}")
    t, result = in_thread(lambda: z.move_to(400.0, timeout=20))
    try:
        wait_for(lambda: service.shaft("z") > 5.0, what="z moving")
        t_stop = time.monotonic()
        other["z"].stop()            # overtakes: the first connection is waiting on its move
        t.join(20)
        assert not t.is_alive()
        assert time.monotonic() - t_stop < 5.0
        e = result["error"]
        assert type(e) is motorbus.MoveInterrupted and e.axis == "z"
        # whose stop it was: the outcome every program reads names the stopping program
        assert f"stop() of the program with pid {os.getpid()} through motorbus serve" in e.reason, e.reason
        rest = service.shaft("z")
        assert 5.0 < rest < 400.0 and not service.bench["z"].sync.status.moving
        time.sleep(0.1)
        assert service.shaft("z") == rest        # at rest, stopped for good
    finally:
        other.close()


def test_wait_idle_reports_this_clients_move_even_if_another_clients_reading_judged_it(service, bench):
    z = bench["z"]
    z.move_to(0.0, timeout=10)
    z.move_to(300.0, wait=False)
    wait_for(lambda: service.shaft("z") > 5.0, what="z moving")
    with motorbus.Bench.connect(f"unix:{service.path}") as other, \
            motorbus.Bench.connect(f"unix:{service.path}") as monitor:
        other["z"].stop()
        wait_for(lambda: not monitor["z"].status.moving, what="z at rest")
        assert monitor["z"].status.last_move.state == "interrupted"     # judged by the monitor's reading
    with pytest.raises(motorbus.MoveInterrupted) as e:
        z.wait_idle(timeout=10)                                          # still this client's outcome
    assert e.value.target == pytest.approx(300.0) and 5.0 < e.value.position < 300.0
    z.wait_idle(timeout=10)                                              # once


def test_a_stop_from_another_thread_overtakes_the_move_this_connection_awaits(service, bench):
    z = bench["z"]
    z.move_to(0.0, timeout=10)
    t, result = in_thread(lambda: z.move_to(400.0, timeout=20))
    wait_for(lambda: service.shaft("z") > 5.0, what="z moving")
    assert z.position > 5.0                  # a reading overtakes the waiting move too
    z.stop()                                 # the same connection, another thread
    t.join(20)
    assert type(result["error"]) is motorbus.MoveInterrupted
    assert 5.0 < service.shaft("z") < 400.0 and not service.bench["z"].sync.status.moving


def test_a_dropped_client_stops_the_moves_it_awaited_but_not_one_it_left_running(service, bench):
    x, z, u = bench["x"], bench["z"], bench["u"]
    for d in (x, z, u):
        d.move_to(0.0, timeout=10)
    conn = rclient.Connection(service.path)          # the program that will die
    watcher = rclient.Connection(service.path)       # another one that only waits on u, and dies too

    def calling(c: Any, *args: Any, **kwargs: Any) -> threading.Thread:
        t = threading.Thread(target=lambda: pytest.raises(Exception, c.call, *args, **kwargs))
        t.start()
        return t
    waits = [calling(conn, "move_to", "z", 400.0, timeout=20)]       # awaited
    conn.call("move_to", "x", 300.0, wait=False)
    waits.append(calling(conn, "wait_idle", "x", 20))                 # its own move, awaited through wait_idle
    conn.call("move_to", "u", 4000.0, wait=False)                     # fire and forget: survives the program
    waits.append(calling(watcher, "wait_idle", "u", 30))              # someone else's move: not the watcher's to stop
    wait_for(lambda: service.shaft("z") > 5.0 and service.shaft("x") > 5.0, what="z and x moving")
    conn.close()                                      # the programs are gone
    watcher.close()
    for t in waits:
        t.join(10)
    for name, far in (("z", 400.0), ("x", 300.0)):
        wait_for(lambda name=name: not service.bench[name].sync.status.moving, what=f"{name} stopped after the drop")
        assert 5.0 < service.shaft(name) < far
        last = service.bench[name].sync.status.last_move
        assert last.state == "interrupted" and "cancellation" in last.reason, (name, last)
    # the move nobody (of its own) awaited goes on to its target
    wait_for(lambda: not service.bench["u"].sync.status.moving, timeout=30, what="u's move")
    assert service.bench["u"].sync.status.last_move.state == "done"
    assert service.shaft("u") == pytest.approx(4000.0, abs=0.011)
    wait_for(lambda: service.run(_counter(service, "clients")) == 1, what="the dropped clients counted out")


async def _counter(service: Service, name: str) -> int:
    return service.face.counters[name]


def test_move_together_and_stop_all(service, bench):
    report = bench.move_together({"z": 4.0, "u": 5.0}, timeout=10)
    assert isinstance(report, motorbus.bench.StartReport) and set(report.offsets) == {"z", "u"}
    assert service.shaft("z") == pytest.approx(4.0, abs=0.011) and service.shaft("u") == pytest.approx(5.0, abs=0.011)
    bench.move_together({"z": -2.0, "u": -2.0}, relative=True, wait=False)
    assert bench.stop_all() == []
    st = bench.status()
    assert set(st) == {"x", "z", "f", "u"} and all(isinstance(s, motorbus.DriveStatus) for s in st.values())
    for n in ("z", "u"):
        wait_for(lambda n=n: not service.bench[n].sync.status.moving)


def test_a_failed_move_together_says_every_axis(service, bench):
    z, f = bench["z"], bench["f"]
    f.enable()
    bench.move_together({"z": 0.0, "f": 0.0}, timeout=10)
    t, result = in_thread(lambda: bench.move_together({"z": 3.0, "f": 300.0}, timeout=20))
    wait_for(lambda: service.shaft("f") > 5.0, what="f moving")
    service.fault("f", "fault")
    t.join(20)
    e = result["error"]
    assert type(e) is motorbus.MoveFaulted and e.axis == "f"
    assert set(e.failures) == {"f"} and type(e.failures["f"]) is motorbus.MoveFaulted
    assert e.failures["f"].position == pytest.approx(e.position)
    assert z.status.last_move.ok and service.shaft("z") == pytest.approx(3.0, abs=0.011)
    f.clear_faults()
    f.enable()


def test_the_plain_axis_calls_and_info(service, bench):
    raw = rclient.Connection(service.path)
    try:
        local = service.bench["z"].sync
        assert raw.call("units", "z") == motorbus.Units("mm", 0.01)
        assert raw.call("kind", "z") == "cia402"
        assert raw.call("capabilities", "z") == local.capabilities
        assert raw.call("last_move", "z") == local.status.last_move
        assert raw.call("info") == {"pid": os.getpid(), "bench": "/lab/test-bench.toml"}
        hello = raw.call("hello")
        assert hello["protocol"] == rpc.PROTOCOL and set(hello["axes"]) == {"x", "z", "f", "u"}
    finally:
        raw.close()


def test_malformed_calls_are_typed_errors_and_counted(service, bench):
    before = bench.counters()
    raw = rclient.Connection(service.path)
    try:
        with pytest.raises(motorbus.InvalidArgument, match="no call 'fly'"):
            raw.call("fly")
        with pytest.raises(motorbus.InvalidArgument, match="no axis call 'fly'"):
            raw.call("fly", "z")
        with pytest.raises(motorbus.InvalidArgument, match="jog: missing a required argument: 'velocity'"):
            raw.call("jog", "z")
        with pytest.raises(motorbus.InvalidArgument, match="move_to: got an unexpected keyword argument 'speed'"):
            raw.call("move_to", "z", 1.0, speed=3)
        with pytest.raises(motorbus.InvalidArgument, match="no axis 'q'"):
            raw.call("position", "q")
        # a call the client library would never send: an id that cannot key a reply
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.connect(service.path)
        sock.sendall(rpc.frame(rpc.FRAME_JSON, rpc.dumps({"id": [1], "call": "info"})))
        size, kind = rpc.HEADER.unpack(sock.recv(rpc.HEADER.size, socket.MSG_WAITALL))
        reply = rpc.json.loads(sock.recv(size, socket.MSG_WAITALL))
        sock.close()
        assert kind == rpc.FRAME_JSON and reply["id"] is None
        assert "an integer or a text" in rpc.decode_error(reply["error"]).args[0]
    finally:
        raw.close()
    after = bench.counters()
    assert after["calls"] - before["calls"] >= 7          # the six above and counters() itself
    assert after["failed_calls"] - before["failed_calls"] == 6


def test_the_console_is_refused_naming_the_service(service, bench):
    with pytest.raises(ServedElsewhere) as e:
        bench["z"].console("r 6041")
    assert str(e.value) == (f"/lab/test-bench.toml is served by motorbus serve (pid {os.getpid()}): a protocol "
                            "console (axis 'z') needs the transports; stop the service first")
    assert e.value.pid == os.getpid() and e.value.bench == "/lab/test-bench.toml"


def test_an_exception_in_with_stops_what_this_program_moved_only(service, bench):
    bench["u"].move_to(0.0, timeout=10)
    bench["u"].move_to(4000.0, wait=False)          # another program's move (this module's bench)
    with pytest.raises(RuntimeError, match="script failed"):
        with motorbus.Bench.connect(f"unix:{service.path}") as mine:
            mine["z"].move_to(400.0, wait=False)
            wait_for(lambda: service.shaft("z") > 1.0, what="z moving")
            raise RuntimeError("script failed")
    wait_for(lambda: not service.bench["z"].sync.status.moving, what="z stopped by the with-block")
    assert service.shaft("z") < 400.0
    # not this program's: left to reach its target
    wait_for(lambda: not service.bench["u"].sync.status.moving, timeout=30, what="u's move")
    assert service.bench["u"].sync.status.last_move.state == "done"
    assert service.shaft("u") == pytest.approx(4000.0, abs=0.011)
    bench["z"].clear_faults()
    bench["z"].enable()          # a CiA 402 quick stop leaves the drive in SWITCH ON DISABLED


def test_the_exit_hook_stops_what_this_program_moved_only(service, bench):
    bench["u"].move_to(0.0, timeout=10)
    bench["z"].move_to(0.0, timeout=10)
    program = motorbus.Bench.connect(f"unix:{service.path}")
    try:
        bench["u"].move_to(4000.0, wait=False)               # another program's
        program["z"].move_to(400.0, wait=False)              # this program's
        wait_for(lambda: service.shaft("z") > 2.0, what="z moving")
        for d in program.axes.values():                      # what the interpreter's exit does
            d._stop_at_exit()
        wait_for(lambda: not service.bench["z"].sync.status.moving, what="z stopped by the exit hook")
        assert service.shaft("z") < 400.0 and program["z"].commanded and not program["u"].commanded
        wait_for(lambda: not service.bench["u"].sync.status.moving, timeout=30, what="u's move")
        assert service.shaft("u") == pytest.approx(4000.0, abs=0.011)   # not stopped: not this program's
    finally:
        program.close()


# ---- polls ---------------------------------------------------------------------------------------
async def _choke_last_subscriber(service: Service) -> Any:
    """The newest subscription's connection, its send buffers made tiny: a reader that has
    stopped reading fills them in a fraction of a second (instead of ~200 kB later)."""
    conn = max((c for c in service.face._conns if c.subs), key=lambda c: max(c.subs))
    conn.writer.get_extra_info("socket").setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
    conn.writer.transport.set_write_buffer_limits(high=4096)
    return conn


def test_a_1khz_poll_fanned_out_to_five_subscribers_is_one_poller(service, bench, monkeypatch):
    bench["z"].move_to(0.0, timeout=10)
    monkeypatch.setattr(rpc, "SUB_QUEUE_CHUNKS", 8)     # ~160 ms of rows may wait per subscriber
    dropped_before = bench.counters()["rows_dropped"]
    clients = [motorbus.Bench.connect(f"unix:{service.path}") for _ in range(5)]
    silent = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)   # subscribes, then never reads
    try:
        pollers = [c.poll(["z", "u"], ("position", "status"), rate_hz=1000) for c in clients]
        silent.connect(service.path)
        silent.sendall(rpc.frame(rpc.FRAME_JSON, rpc.dumps({"id": 1, "call": "poll", "args": [["z", "u"],
                                                            ["position", "status"], 1000]})))
        wait_for(lambda: service.run(_counter(service, "poll_subscribers")) == 6)
        silent_conn = service.run(_choke_last_subscriber(service))
        assert service.run(_counter(service, "pollers")) == 1
        assert len(service.face._polls) == 1
        time.sleep(0.1)                   # rows at rest first (a poll's first deadline is 20 ms after its start)
        bench["z"].move_to(2.0, wait=False)
        time.sleep(1.0)
        bench["z"].wait_idle(timeout=10)
        time.sleep(0.1)
        for p in pollers:
            fr = p.read()
            assert p.columns == ["t", "z.t", "z.position", "z.status", "u.t", "u.position", "u.status"]
            n = len(fr["t"])
            assert n >= 700, f"{n} rows in ~1.1 s at 1 kHz"
            assert np.allclose(np.diff(fr["t"]), 1e-3)               # one row per deadline, none lost
            assert p.overflowed == 0
            pos = fr["z.position"][~np.isnan(fr["z.position"])]
            assert pos[0] == pytest.approx(0.0, abs=0.011)
            assert pos[-1] == pytest.approx(2.0, abs=0.011)
            assert np.all(np.diff(pos) >= -1e-9)                      # the move, sample by sample
        # the silent one lost its oldest rows, counted, and held up nobody
        (silent_sub,) = silent_conn.subs.values()
        counted = bench.counters()["rows_dropped"] - dropped_before     # (it goes on dropping meanwhile)
        assert 0 < counted <= silent_sub.dropped and len(silent_sub.queue) <= 8
        # the same rows went to every subscriber: one poll, fanned out
        first = [p.frame()["t"][:200] for p in pollers]
        common = set(first[0]).intersection(*map(set, first[1:]))
        assert len(common) >= 100
        stats = pollers[0].stats
        assert stats["subscription"]["subscribers"] == 6
        for p in pollers:
            p.stop()
        silent.close()
        wait_for(lambda: service.run(_counter(service, "pollers")) == 0, what="the Poller stopped")
        assert service.run(_counter(service, "poll_subscribers")) == 0
    finally:
        silent.close()
        for c in clients:
            c.close()


def test_rows_that_overtake_a_subscription_are_kept_for_it(service, bench, monkeypatch):
    first = bench.poll(["z"], ("position",), rate_hz=1000)       # the shared poll runs already
    try:
        wait_for(lambda: len(first.frame()["t"]) > 50, what="rows")
        late = motorbus.Bench.connect(f"unix:{service.path}")
        slow_init = rclient.RemotePoller.__init__

        def registering_late(self: Any, *a: Any, **kw: Any) -> None:
            time.sleep(0.3)             # rows arrive before the subscriber is registered
            slow_init(self, *a, **kw)
        monkeypatch.setattr(rclient.RemotePoller, "__init__", registering_late)
        asked = motorbus._core.runtime.monotonic_ns() / 1e9
        p = late.poll(["z"], ("position",), rate_hz=1000)
        time.sleep(0.1)
        t = p.read()["t"]
        assert len(t) > 300 and t[0] < asked + 0.1          # nothing lost while it registered
        assert np.allclose(np.diff(t), 1e-3)
        late.close()
    finally:
        first.stop()


def test_a_local_poller_on_a_served_axis_says_where_to_poll(bench):
    with pytest.raises(motorbus.InvalidArgument, match=r"served by motorbus serve: poll it through the service, "
                                                        r"bench.poll\(\['z'\]"):
        motorbus.Poller({"z": bench["z"]}, rate_hz=100)


def test_a_slow_subscriber_loses_its_oldest_rows_counted():
    class Conn:
        class face:
            counters = {"rows_dropped": 0}
        wake = threading.Event()
    sub = rpc._Sub(1, Conn(), None, ["t"])
    for i in range(rpc.SUB_QUEUE_CHUNKS + 3):
        sub.push(np.full((10, 1), float(i)))
    assert len(sub.queue) == rpc.SUB_QUEUE_CHUNKS and sub.dropped == 30
    assert sub.queue[0][0, 0] == 3.0 and Conn.face.counters["rows_dropped"] == 30


def test_errors_and_values_cross_the_wire_as_themselves():
    from motorbus.bench import BenchFileError
    from motorbus.drive import DriveStatus, MoveOutcome, UnknownParameter

    def trip(v: Any) -> Any:
        return rpc.decode(rpc.json.loads(rpc.dumps(rpc.encode(v))))

    e = motorbus.LimitReached("x: stopped at 3 mm by the +limit switch, target 9 mm", side=1, axis="x", target=9.0,
                              position=3.0, reason="the +limit switch", code=None, status=0x1234, units="mm")
    e.add_note("also: y: ...")
    back = trip(e)
    assert type(back) is motorbus.LimitReached and str(back) == str(e) and back.__notes__ == ["also: y: ..."]
    assert (back.side, back.axis, back.target, back.position, back.reason, back.status, back.units) == \
        (1, "x", 9.0, 3.0, "the +limit switch", 0x1234, "mm")
    assert isinstance(back, motorbus.DriveFault) and back.outcome == "limit"
    t = trip(motorbus.MoveTimedOut("slow", axis="z", position=float("nan")))
    assert isinstance(t, motorbus.TimeoutError) and np.isnan(t.position)
    b = trip(BenchFileError("expected a number", source="b.toml", line=3, key="axis.x.address"))
    assert type(b) is BenchFileError and str(b) == "b.toml:3: axis.x.address: expected a number" and b.line == 3
    assert type(trip(UnknownParameter("arcus: no parameter 'Q'"))) is UnknownParameter
    assert type(trip(motorbus.SdoAbortError("0x06020000"))) is motorbus.SdoAbortError

    class Strange(Exception):
        pass
    odd = trip(Strange("what"))            # a class the client lacks, with no typed base: named in the text
    assert type(odd) is motorbus.MotorbusError and str(odd) == "Strange: what"
    k = trip(KeyError("k"))
    assert type(k) is KeyError and str(k) == "'k'" and k.args == ("k",)
    st = DriveStatus(True, False, True, False, True, False, False, raw=(1, b"\x02"), text="ok",
                     last_move=MoveOutcome("move", 1.0, 1.0, "done"))
    assert trip(st) == st
    assert trip({"lims": (-float("inf"), 2.5), "caps": frozenset({motorbus.Capability.HOMING})}) == \
        {"lims": (-float("inf"), 2.5), "caps": frozenset({motorbus.Capability.HOMING})}


# ---- the awaitable face --------------------------------------------------------------------------
def test_the_awaitable_face(service, bench):
    async def main() -> None:
        async with await aio.Bench.connect(f"unix:{service.path}") as ab:
            z = ab["z"]
            assert isinstance(z, aio.Drive) and isinstance(z.sync, motorbus.Drive)
            await z.move_to(1.0, timeout=10)
            assert await z.position() == pytest.approx(1.0, abs=0.011)
            assert service.shaft("z") == pytest.approx(1.0, abs=0.011)
            assert (await z.status()).last_move.ok
            assert await z.params.get("0x6081") == 20000
            assert set(await ab.status()) == {"x", "z", "f", "u"}
            # several calls at once on one connection
            p1, p2, lim = await asyncio.gather(z.position(), ab["u"].position(), z.travel_limits())
            assert p1 == pytest.approx(1.0, abs=0.011) and isinstance(lim, tuple)
            # cancelling an awaited move stops the motor before the CancelledError goes on
            task = asyncio.ensure_future(z.move_to(400.0, timeout=20))
            while service.shaft("z") < 3.0:
                await asyncio.sleep(0.01)
            task.cancel()
            with pytest.raises(asyncio.CancelledError):
                await task
            assert not service.bench["z"].sync.status.moving
            rest = service.shaft("z")
            assert 3.0 < rest < 400.0
            last = (await z.status()).last_move
            assert last.state == "interrupted" and "the cancellation of the awaiting task" in last.reason
            # a typed error, awaited
            with pytest.raises(motorbus.MoveInterrupted):
                await asyncio.gather(z.move_to(50.0, timeout=10), _stop_soon(z, service))
            # a poll, as chunks
            got = 0
            async with await ab.poll(["z"], ("position",), rate_hz=500) as poller:
                async for chunk in poller.chunks(50):
                    assert len(chunk["t"]) >= 50
                    got += len(chunk["t"])
                    if got >= 100:
                        break
            assert got >= 100 and not poller.running
    asyncio.run(main())
    wait_for(lambda: service.run(_counter(service, "pollers")) == 0)


async def _stop_soon(z: Any, service: Service) -> None:
    while service.shaft("z") < 3.0 + 0.5 and not (await z.status()).moving:
        await asyncio.sleep(0.005)
    await asyncio.sleep(0.05)
    await z.stop()


def test_closing_the_face_stops_what_its_clients_awaited_and_they_see_link_down(service, bench, tmp_path):
    path = str(tmp_path / "second.sock")
    face = service.run(rpc.start_rpc(service.bench, path, info={"pid": os.getpid()}))
    remote = motorbus.Bench.connect(f"unix:{path}")
    z = remote["z"]
    bench["z"].move_to(0.0, timeout=10)
    t, result = in_thread(lambda: z.move_to(400.0, timeout=20))
    try:
        wait_for(lambda: service.shaft("z") > 5.0, what="z moving")
        service.run(face.close())
        t.join(20)
        assert isinstance(result["error"], motorbus.LinkDown) and "connection lost" in str(result["error"])
        assert not service.bench["z"].sync.status.moving and 5.0 < service.shaft("z") < 400.0
        assert not os.path.exists(path)
        with pytest.raises(motorbus.LinkDown, match="connection lost"):
            z.position
    finally:
        remote.close()
    bench["z"].enable()


def test_a_lost_service_is_link_down_and_a_missing_one_is_said(tmp_path):
    with pytest.raises(motorbus.LinkDown, match="is the service running"):
        motorbus.Bench.connect(f"unix:{tmp_path / 'none.sock'}")
    bench_file = tmp_path / "b.toml"
    bench_file.write_text('[line.l]\nport = "/dev/null"\n[axis.x]\nkind = "arcus"\nline = "l"\naddress = "01"\n')
    with pytest.raises(motorbus.LinkDown, match="no motorbus serve runs for this bench"):
        motorbus.Bench.connect(bench_file)
    with pytest.raises(motorbus.InvalidArgument, match="no such bench file or socket"):
        motorbus.Bench.connect(tmp_path / "absent.toml")


def test_motorbus_ophyd_scans_a_served_bench(service, bench):
    pytest.importorskip("bluesky")
    pytest.importorskip("ophyd_async")
    from bluesky import RunEngine
    from bluesky.plans import scan
    from ophyd_async.plan_stubs import ensure_connected

    from motorbus.ophyd import devices_from_bench

    assert isinstance(bench, motorbus.Bench)
    motors = devices_from_bench(bench, ["z", "u"])
    RE = RunEngine()
    RE(ensure_connected(*motors.values()))
    events: list = []
    RE(scan([motors["u"]], motors["z"], 0.0, 2.0, 3), lambda name, doc: name == "event" and events.append(doc))
    assert [e["data"]["z"] for e in events] == pytest.approx([0.0, 1.0, 2.0], abs=0.011)
    assert service.shaft("z") == pytest.approx(2.0, abs=0.011)


def test_last_a_poll_whose_link_fails_ends_for_its_subscribers(service, bench):
    # Last in the module: it cuts the arcus axis's served line.
    with bench.poll(["x"], ("position",), rate_hz=200) as p:
        wait_for(lambda: len(p.frame()["t"]) > 20, what="rows from x")
        service.bench.sync.served_lines["l1"].close()
        wait_for(lambda: not p.running, what="the poll's end said to its subscriber")
        assert p.end_stats is not None
        (group,) = p.end_stats.values()
        assert group["axes"] == ["x"] and not group["running"] and group["error_type"]
        assert len(p.read()["t"]) + len(p.frame()["t"]) > 20
    wait_for(lambda: service.run(_counter(service, "pollers")) == 0)

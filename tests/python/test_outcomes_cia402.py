"""How a move ends on the CiA 402 kinds (cia402, arcus-canopen): every outcome a typed error
with its reason and the position reached, against each simulator served over socketcand on
127.0.0.1 (the client opens ``socketcand:HOST:PORT/can0`` as on a bench).

Faults are injected with the kind's own ``sim_faults`` (the standard names); a stop from a
second, independent client is a raw SDO write of the controlword over python-can on its own
socketcand connection.  Also: velocity= for one move, status.at_target after a halt, the
identity object of the generic simulator, write-only 6060h, and no simulator leak.
"""
from __future__ import annotations

import gc
import os
import threading
import time
import weakref

import pytest

import motorbus
from motorbus import faces, registry
from motorbus.drive import LimitReached, MoveFailed, MoveFaulted, MoveInterrupted, MoveStalled, MoveTimedOut
from motorbus.sim import SimBench

pytestmark = pytest.mark.threaded

ADDRESS = {"cia402": "5", "arcus-canopen": "1"}
KINDS = sorted(ADDRESS)
SPEED = 20000          # native units/s (6081h) for the tests' moves
FAR = 200_000          # a target several seconds away at SPEED (the DMX-CAN takes at most 262143 per move)


class Rig:
    def __init__(self, kind: str, bench: SimBench) -> None:
        self.kind = kind
        self.address = ADDRESS[kind]
        self.sim = bench.sims[(kind, self.address)]
        srv = bench.can.servers[0]
        self.spec = f"socketcand:{srv.host}:{srv.port}/can0"
        self.faults = registry.drive_plugin(kind).sim_faults()
        self.drive = motorbus.open_drive(kind, bus=self.spec, address=self.address)

    def inject(self, name: str, **options) -> None:
        self.faults[name](self.sim, **options)


@pytest.fixture(params=KINDS)
def rig(request):
    kind = request.param
    with SimBench([f"{kind}:{ADDRESS[kind]}"]) as bench:
        r = Rig(kind, bench)
        d = r.drive
        d.enable()
        d.params["0x6081"] = SPEED
        if kind == "cia402":
            d.params["0x6083"] = 100000
            d.params["0x6084"] = 100000
        else:
            d.params["0x6083"] = 20       # ms (manual 000: accelerations are times)
            d.params["0x6084"] = 20
        try:
            yield r
        finally:
            d.close()


def start_far_move(d, distance: float = FAR) -> tuple[float, float]:
    """Starts a long move and returns (start, target) once the axis is on its way."""
    start = d.position
    target = start + distance
    d.move_to(target, wait=False)
    t_end = time.monotonic() + 5
    while abs(d.position - start) < 500:
        assert time.monotonic() < t_end, "the move did not start"
        time.sleep(0.01)
    return start, target


def check_failure(d, e: MoveFailed, start: float, target: float) -> None:
    """Past the start, short of the target, where the drive now reads, recorded."""
    assert start < e.position < target, (start, e.position, target)
    assert e.position == pytest.approx(d.position, abs=1.0)
    assert e.target == pytest.approx(target)
    assert e.axis == d.kind and e.reason and str(e).startswith(f"{d.kind}: stopped at ")
    last = d.status.last_move
    assert last is not None and last.state == e.outcome and last.error is e
    assert last.position == pytest.approx(e.position) and not d.status.at_target


def test_a_normal_move_returns_at_its_target(rig):
    d = rig.drive
    d.move_to(3000, timeout=20)
    assert abs(d.position - 3000) <= faces.run(d._in_position_window())
    last = d.status.last_move
    assert last.ok and last.what == "move" and last.target == 3000 and last.position == pytest.approx(d.position)
    assert d.status.at_target


def test_in_position_window_is_the_drives_own(rig):
    d = rig.drive
    if rig.kind == "cia402":
        assert faces.run(d._in_position_window()) == 10              # 6067h as the simulator boots
        d.params["0x6067"] = 25
        assert faces.run(d._in_position_window()) == 25              # a write through params is read again
    else:
        assert faces.run(d._in_position_window()) == d.params["0x2001:03"] == 10   # StepNLoop tolerance (SLT)
        d.params["0x2001:01"] = 0
        assert faces.run(d._in_position_window()) == 0                              # open loop: exact


@pytest.mark.parametrize("side", [1, -1])
def test_a_move_into_a_limit_raises_limit_reached_with_the_side(rig, side):
    d = rig.drive
    start, target = start_far_move(d, side * FAR)
    rig.inject("limit", direction=side)
    with pytest.raises(LimitReached) as failed:
        d.wait_idle(timeout=20)
    e = failed.value
    assert e.side == side
    lo, hi = sorted((start, target))
    assert lo < e.position < hi and abs(e.position - start) > 500
    assert e.position == pytest.approx(d.position, abs=1.0)
    assert ("+limit" if side > 0 else "-limit") in e.reason
    assert d.status.last_move.state == "limit" and not d.status.at_target


def test_a_move_past_a_limit_switch_at_its_place_stops_on_it(rig):
    """Not injected: the switch where the simulator has it (cia402: +limit at 100000 increments)."""
    if rig.kind != "cia402":
        pytest.skip("the DMX-CAN simulator's switches are forced (force_limit), tested above")
    d = rig.drive
    with pytest.raises(LimitReached) as failed:
        d.move_to(150_000, timeout=30)
    e = failed.value
    assert e.side == 1 and e.position == pytest.approx(100_000, abs=50)
    assert "60FDh bit 1" in e.reason and "bit 11" in e.reason


def test_a_soft_limit_raises_limit_reached_at_607d(rig):
    if rig.kind != "cia402":
        pytest.skip("the DMX-CAN has no software position limits (no 607Dh in Table 10.1)")
    d = rig.drive
    d.params["0x607D:02"] = 20_000
    assert d.travel_limits == (-float("inf"), 20_000)
    with pytest.raises(LimitReached) as failed:
        d.move_to(50_000, timeout=30)
    e = failed.value
    assert e.side == 1 and e.position == 20_000 and "607Dh:02 = 20000" in e.reason
    d.move_to(10_000, timeout=30)          # inside the limits: an ordinary move again
    assert d.status.last_move.ok


def test_a_fault_mid_move_raises_move_faulted_with_the_code(rig):
    if "fault" not in rig.faults:
        assert rig.kind == "arcus-canopen"
        pytest.skip("the DMX-CAN has no fault beyond its limit and StepNLoop errors (no 603Fh): docs/drives/arcus.md")
    d = rig.drive
    start, target = start_far_move(d)
    rig.inject("fault", code=0x3210)
    with pytest.raises(MoveFaulted) as failed:
        d.wait_idle(timeout=20)
    e = failed.value
    assert e.code == 0x3210 and e.reason == "fault 0x3210 DC link over-voltage"
    assert e.status & 0x4F == 0x08            # the native statusword: FAULT
    check_failure(d, e, start, target)
    d.clear_faults()
    d.enable()
    d.move_to(start, timeout=30)                # cleared: moves again
    assert d.status.last_move.ok


def test_a_jammed_rotor_raises_move_stalled(rig):
    d = rig.drive
    start, target = start_far_move(d)
    rig.inject("stall")
    with pytest.raises(MoveStalled) as failed:
        d.wait_idle(timeout=20)
    e = failed.value
    if rig.kind == "cia402":
        assert e.code == 0x8611 and e.reason == "fault 0x8611 following error"
    else:
        assert e.code == 10 and e.reason == "StepNLoop error: stall (2003h = 10)"
    check_failure(d, e, start, target)


def test_a_stop_input_raises_move_interrupted(rig):
    if "stop_input" not in rig.faults:
        assert rig.kind == "arcus-canopen"
        pytest.skip("the DMX-CAN has no stop input (manual 000): docs/drives/arcus.md")
    d = rig.drive
    start, target = start_far_move(d)
    rig.inject("stop_input")
    with pytest.raises(MoveInterrupted) as failed:
        d.wait_idle(timeout=20)
    e = failed.value
    assert "stop input" in e.reason and "SWITCH ON DISABLED" in e.reason
    check_failure(d, e, start, target)


def test_stop_from_another_thread_raises_move_interrupted(rig):
    d = rig.drive
    start, target = start_far_move(d)
    threading.Timer(0.1, d.stop).start()
    with pytest.raises(MoveInterrupted) as failed:
        d.wait_idle(timeout=20)
    e = failed.value
    assert e.reason == "stop() of this program"
    check_failure(d, e, start, target)


def _halt_from_another_client(spec: str, node: int) -> None:
    """A second program: its own socketcand connection (python-can), a raw expedited SDO
    download of the controlword with halt (bit 8) — its reply told from the mover's ones."""
    can = pytest.importorskip("can")
    host, port = spec.split(":", 1)[1].split("/")[0].rsplit(":", 1)
    halt = 0x010F
    with can.Bus(interface="socketcand", host=host, port=int(port), channel="can0") as other:
        # First it looks, as a status command would (1000h, an object the mover never reads,
        # 30 times): replies the mover's client must not take for its own.
        for _ in range(30):
            other.send(can.Message(arbitration_id=0x600 + node, is_extended_id=False,
                                   data=bytes([0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])))
            t_end = time.monotonic() + 1
            while time.monotonic() < t_end:
                reply = other.recv(timeout=max(0.0, t_end - time.monotonic()))
                if reply is not None and reply.arbitration_id == 0x580 + node and bytes(reply.data[1:3]) == b"\x00\x10":
                    break
        other.send(can.Message(arbitration_id=0x600 + node, is_extended_id=False,
                               data=bytes([0x2B, 0x40, 0x60, 0x00, halt & 0xFF, halt >> 8, 0, 0])))
        t_end = time.monotonic() + 5
        while True:
            reply = other.recv(timeout=max(0.0, t_end - time.monotonic()))
            assert reply is not None, "no SDO reply to the halt"
            if reply.arbitration_id == 0x580 + node and bytes(reply.data[:4]) == bytes([0x60, 0x40, 0x60, 0x00]):
                return


@pytest.mark.parametrize("while_polling", [False, True], ids=["idle", "polling"])
def test_a_halt_from_a_second_independent_client_raises_move_interrupted(rig, while_polling):
    """``polling``: this program waits (SDO reads every 5 ms) while the other one writes: the
    two clients share the node's COB-IDs and see each other's replies, which must cost this
    program nothing but a repeated read."""
    d = rig.drive
    start, target = start_far_move(d)
    outcome: list = []
    waiter = None
    if while_polling:
        def wait() -> None:
            try:
                d.wait_idle(timeout=20)
                outcome.append(None)
            except BaseException as e:  # noqa: BLE001 - the test inspects it
                outcome.append(e)
        waiter = threading.Thread(target=wait)
        waiter.start()
        time.sleep(0.2)
    _halt_from_another_client(rig.spec, int(rig.address))
    if waiter is not None:
        waiter.join(30)
        e = outcome[0]
    else:
        with pytest.raises(MoveInterrupted) as failed:
            d.wait_idle(timeout=20)
        e = failed.value
    assert isinstance(e, MoveInterrupted), repr(e)
    assert e.reason == "a halt (controlword bit 8) from another program"
    check_failure(d, e, start, target)
    # The "halted at 10.2 of 60 mm shows at target": a Drive that did not start the
    # move (another program's view) must not say "at target" either.
    other_view = motorbus.open_drive(rig.kind, bus=rig.spec, address=rig.address)
    try:
        st = other_view.status
        assert not st.moving and not st.at_target and st.last_move is None
    finally:
        other_view.close()


def test_a_timeout_raises_move_timed_out_still_moving(rig):
    d = rig.drive
    start = d.position
    with pytest.raises(MoveTimedOut) as failed:
        d.move_to(start + FAR, timeout=0.5)
    e = failed.value
    assert isinstance(e, motorbus.TimeoutError) and "still moving at" in str(e)
    assert start < e.position < start + FAR
    assert d.status.moving and d.status.last_move.state == "timeout"
    d.stop()
    d.wait_idle(timeout=20)


def test_velocity_is_for_that_move_only(rig):
    d = rig.drive
    d.params["0x6081"] = 5000
    t0 = time.monotonic()
    d.move_by(20_000, velocity=40_000, timeout=20)
    fast = time.monotonic() - t0
    assert d.params["0x6081"] == 5000               # put back after the move
    assert d.status.last_move.ok
    # ... and also after a move that failed
    start, target = d.position, d.position + FAR
    d.move_to(target, velocity=30_000, wait=False)
    assert d.params["0x6081"] == 30_000              # in effect during the move
    threading.Timer(0.2, d.stop).start()
    with pytest.raises(MoveInterrupted):
        d.wait_idle(timeout=20)
    assert d.params["0x6081"] == 5000
    assert fast < 20_000 / 5000                      # the move ran at the given speed, not at 6081h


def test_homing_halted_by_another_program_is_interrupted(rig):
    """A homing halted (6040h bit 8) ends reached-not-attained: MoveInterrupted, not a hang."""
    d = rig.drive
    d.params["0x6099:01"] = 500       # a slow search: the halt comes long before the switch
    d.params["0x6099:02"] = 200
    d.home(20, wait=False)            # both: a search away from the home switch window
    time.sleep(0.3)
    d.native.sdo.download(0x6040, 0, (0x011F).to_bytes(2, "little"))   # halt, as another program would
    with pytest.raises(MoveInterrupted) as failed:
        d.wait_idle(timeout=20)
    assert "halt" in failed.value.reason
    assert not d.status.homed and d.status.last_move.state == "interrupted"


def test_homing_into_a_fault_raises_move_faulted_with_the_code(rig):
    if "fault" not in rig.faults:
        pytest.skip("the DMX-CAN has no fault with a code")
    d = rig.drive
    d.params["0x6099:01"] = 500       # slow: the fault comes long before the homing could end
    d.home(20, wait=False)
    time.sleep(0.3)
    rig.inject("fault", code=0x4310)
    with pytest.raises(MoveFaulted) as failed:
        d.wait_idle(timeout=20)
    assert failed.value.code == 0x4310 and "excess temperature drive" in failed.value.reason
    assert d.status.last_move.what == "home" and d.status.last_move.state == "fault"


def test_sim_faults_have_the_standard_names_and_keep_the_old_ones():
    assert {"limit", "fault", "stall", "stop_input", "drive_fault"} <= set(registry.drive_plugin("cia402").sim_faults())
    assert {"limit", "stall", "trip_limit"} <= set(registry.drive_plugin("arcus-canopen").sim_faults())


def test_the_generic_simulator_has_the_identity_object():
    with SimBench(["cia402:7"]) as bench:
        srv = bench.can.servers[0]
        with motorbus.open_drive("cia402", bus=f"socketcand:{srv.host}:{srv.port}/can0", address=7) as d:
            # the docs' example (docs/bench-files.md) used to abort: the object did not exist
            assert [d.console(f"r 0x1018:{sub} u32") for sub in (1, 2, 4)] == ["0", str(0x402), "7"]
            ident = [int.from_bytes(d.native.sdo.upload(0x1018, s), "little") for s in (0, 1, 2, 3, 4)]
            assert ident == [4, 0, 0x402, 0x00010000, 7]


def test_write_only_6060h_is_described_skipped_and_refused_by_name():
    with SimBench(["arcus-canopen:1"]) as bench:
        srv = bench.can.servers[0]
        with motorbus.open_drive("arcus-canopen", bus=f"socketcand:{srv.host}:{srv.port}/can0", address=1) as d:
            d.name = "z"
            info = d.params.describe("0x6060")
            assert info.writable and "write-only" in info.description
            assert "0x6060" not in list(d.params)
            values = {p: d.params[p] for p in d.params}        # what config read --all does
            assert "0x6061" in values and len(values) == len(list(d.params))
            with pytest.raises(motorbus.InvalidArgument, match=r"z: parameter 0x6060 \(Modes of operation\) is "
                                                                r"write-only"):
                d.params["0x6060"]
            d.params["0x6060"] = 3                                # writing it still works
            assert d.params["0x6061"] == 3


def test_config_read_all_works_on_an_arcus_canopen_axis(tmp_path):
    import subprocess
    import sys
    p = tmp_path / "b.toml"
    p.write_text('[bus.can0]\nspec = "virtual:x"\n[axis.z]\nkind = "arcus-canopen"\nbus = "can0"\naddress = 1\n')
    out = subprocess.run([sys.executable, "-m", "motorbus", "config", "read", str(p), "--all", "--sim"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "0x6061" in out.stdout and "0x6060" not in out.stdout


def test_no_simulator_outlives_its_bench(tmp_path):
    """issue 28 item 9: a C++-held bound method kept every cia402 simulator alive (500
    Bench(sim=True) cycles: +80 MB)."""
    from motorbus.drives import cia402

    # The simulator is a C++ object (pybind11 instances are not tracked by the garbage
    # collector, so gc.get_objects() would never list one): weak references say whether
    # each one was freed.
    refs: list = []

    def alive() -> int:
        gc.collect()
        return sum(1 for r in refs if r() is not None)

    def rss_kb() -> int:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4

    before = 0
    bus = motorbus.open_bus("virtual:leak-check")
    try:
        for _ in range(10):                 # warm-up: allocator pools, caches
            cia402.make_sim(5, bus=bus).close()
        gc.collect()
        rss0 = rss_kb()
        for _ in range(100):
            sim = cia402.make_sim(5, bus=bus)
            refs.append(weakref.ref(sim))
            sim.close()
        del sim
        assert len(refs) == 100 and alive() == before
        grown = rss_kb() - rss0
    finally:
        bus.close()
    if "asan" not in os.environ.get("LD_PRELOAD", ""):   # ASan's quarantine keeps freed blocks
        assert grown < 4000, f"{grown} KB for 100 simulators (was ~16 000 KB with the cycle)"

    # The case: whole simulated benches opened and closed.
    p = tmp_path / "b.toml"
    p.write_text('[bus.can0]\nspec = "virtual:x"\n[axis.z]\nkind = "cia402"\nbus = "can0"\naddress = 5\n')
    for _ in range(10):
        motorbus.Bench.load(p, sim=True).close()
    gc.collect()
    rss0 = rss_kb()
    for _ in range(100):
        bench = motorbus.Bench.load(p, sim=True)
        refs.extend(weakref.ref(sim) for sim in bench.sims.values())
        bench.close()
    del bench
    assert len(refs) == 200 and alive() == before
    grown = rss_kb() - rss0
    if "asan" not in os.environ.get("LD_PRELOAD", ""):
        assert grown < 4000, f"{grown} KB for 100 simulated benches"

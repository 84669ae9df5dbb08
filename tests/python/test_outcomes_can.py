"""How a move ends on the CAN kinds UNITEK (REGID protocol) and PMC007 (CANopen CiA 301).

Every test runs the kind's simulator served over socketcand on 127.0.0.1 (motorbus.sim.SimBench)
and opens the drive through ``motorbus.open_drive`` on its own socketcand connection, as a bench
does.  Faults go in through the kind's ``SIM_FAULTS`` (the standard names), a stop from a second
program through python-can on its own socketcand connection.  Each test asserts the typed error,
its reason and code, and where the shaft came to rest (read from the simulator itself).
"""
from __future__ import annotations

import threading
import time

import pytest

import motorbus
from motorbus import LimitReached, MoveFaulted, MoveInterrupted, MoveStalled, MoveTimedOut, registry
from motorbus.drives import pmc007 as pmc
from motorbus.drives import unitek as utk
from motorbus.sim import SimBench

REV = 65536                       # UNITEK num per revolution
# N max 600 rpm (10 rev/s), 200 ms ramps: an 8-rev move takes about 1 s.
UNITEK_SIM = {"calibrated": True, "n_max_rpm": 600, "acc_ramp_ms": 200, "dec_ramp_ms": 200,
              "plus_limit_num": 10 * REV, "minus_limit_num": -10 * REV}
UNITEK_OPEN = {"n_max_rpm": 600}


class Served:
    """One simulated drive served over socketcand, and the drive opened on it."""

    def __init__(self, kind: str, address: str, sim_options: dict, **open_options) -> None:
        self.bench = SimBench([f"{kind}:{address}"], sim_options={kind: sim_options})
        srv = self.bench.can.servers[0]
        self.host, self.port = srv.host, srv.port
        self.spec = f"socketcand:{srv.host}:{srv.port}/can0"
        self.sim = self.bench.sims[(kind, address)]
        self.faults = registry.drive_plugin(kind).sim_faults()
        self.drive = motorbus.open_drive(kind, bus=self.spec, address=address, **open_options)

    def later(self, seconds: float, fn, *args, **kw) -> threading.Timer:
        t = threading.Timer(seconds, fn, args, kw)
        t.start()
        return t

    def close(self) -> None:
        try:
            self.drive.close()
        finally:
            self.bench.close()


@pytest.fixture
def unitek():
    s = Served("unitek", "0x201", UNITEK_SIM, **UNITEK_OPEN)
    s.drive.enable()
    yield s
    s.close()


class SecondProgram:
    """Another program on the bus: python-can on its own socketcand connection."""

    def __init__(self, served: Served) -> None:
        import can

        self._can = can
        self.bus = can.Bus(interface="socketcand", host=served.host, port=served.port, channel="can0")

    def send(self, arbitration_id: int, data: bytes) -> None:
        self.bus.send(self._can.Message(arbitration_id=arbitration_id, data=data, is_extended_id=False))

    def reply(self, arbitration_id: int, starts: bytes, timeout: float = 2.0) -> bool:
        """Whether a frame on ``arbitration_id`` starting with ``starts`` comes within ``timeout``
        (the bus carries this program's traffic too: other frames are skipped)."""
        end = time.monotonic() + timeout
        while (left := end - time.monotonic()) > 0:
            m = self.bus.recv(left)
            if m is not None and m.arbitration_id == arbitration_id and bytes(m.data[:len(starts)]) == starts:
                return True
        return False

    def close(self) -> None:
        time.sleep(0.05)      # let the server take the last frame before the connection closes
        self.bus.shutdown()


# ---- UNITEK ------------------------------------------------------------------------------

def test_unitek_normal_move_returns_at_target_and_records_it(unitek):
    d = unitek.drive
    d.move_to(2 * REV)
    assert abs(unitek.sim.position_num - 2 * REV) <= 64
    last = d.status.last_move
    assert last.ok and last.state == "done" and last.target == 2 * REV
    assert abs(last.position - 2 * REV) <= 64
    assert d.status.at_target


def test_unitek_plus_limit_ends_the_move_with_limit_reached(unitek):
    # The issue: "a unitek move that reaches its +limit never returns".
    d = unitek.drive
    t0 = time.monotonic()
    with pytest.raises(LimitReached) as e:
        d.move_to(20 * REV, timeout=10)
    assert time.monotonic() - t0 < 5
    err = e.value
    assert err.side == 1 and "+limit" in err.reason and "Lim+" in err.reason
    assert err.target == 20 * REV
    # The sim halts at its evaluation time after the switch (every ms; later on a loaded
    # host): at 10 rev/s, 0.1 rev per 10 ms late.
    assert 10 * REV <= unitek.sim.position_num <= 11 * REV
    assert abs(err.position - unitek.sim.position_num) <= 64
    assert err.status & utk.Status.LIM_PLUS
    st = d.status
    assert st.last_move.state == "limit" and st.last_move.error is err and not st.at_target


def test_unitek_limit_injected_mid_move_is_a_minus_limit(unitek):
    d = unitek.drive
    d.move_to(-8 * REV, wait=False)
    time.sleep(0.15)
    unitek.faults["limit"](unitek.sim, direction=-1)
    with pytest.raises(LimitReached) as e:
        d.wait_idle(5)
    assert e.value.side == -1 and "-limit" in e.value.reason
    assert -8 * REV < unitek.sim.position_num < -0.1 * REV
    assert abs(e.value.position - unitek.sim.position_num) <= 64


def test_unitek_a_limit_behind_the_motion_stops_nothing(unitek):
    # Away from an active -limit: the switch is no reason, the move arrives.
    d = unitek.drive
    unitek.sim.force_limit(-1, True)
    d.move_to(1 * REV)
    assert d.status.last_move.ok


def test_unitek_drive_error_mid_move_is_move_faulted_with_its_code(unitek):
    d = unitek.drive
    d.move_to(8 * REV, wait=False)
    time.sleep(0.15)
    unitek.faults["fault"](unitek.sim)                  # ERR_WARN bit 8 OVERVOLTAGE
    with pytest.raises(MoveFaulted) as e:
        d.wait_idle(5)
    err = e.value
    assert err.code == 0x0100
    assert "OVERVOLTAGE" in err.reason and "0x8F" in err.reason
    assert 0 < unitek.sim.position_num < 8 * REV
    assert abs(err.position - unitek.sim.position_num) <= 64
    assert d.status.last_move.state == "fault"
    # A move is refused while the error is there, and goes again after clear_faults.
    with pytest.raises(motorbus.DriveFault, match="OVERVOLTAGE"):
        d.move_to(0)
    d.clear_faults()
    d.move_to(0)
    assert abs(unitek.sim.position_num) <= 64


def test_unitek_hardware_enable_lost_mid_move_is_move_faulted(unitek):
    d = unitek.drive
    d.move_to(8 * REV, wait=False)
    time.sleep(0.15)
    unitek.faults["enable_off"](unitek.sim)
    with pytest.raises(MoveFaulted) as e:
        d.wait_idle(5)
    assert "Ena" in e.value.reason and e.value.code is None
    assert 0 < unitek.sim.position_num < 8 * REV


def test_unitek_stop_from_another_thread_is_move_interrupted(unitek):
    d = unitek.drive
    unitek.later(0.15, d.stop)
    with pytest.raises(MoveInterrupted) as e:
        d.move_to(8 * REV)
    assert "stop() of this program" in e.value.reason
    assert 0 < unitek.sim.position_num < 8 * REV
    assert unitek.sim.speed_num == 0
    assert d.status.last_move.state == "interrupted"


def test_unitek_stop_from_a_second_program_is_move_interrupted(unitek):
    d = unitek.drive
    other = SecondProgram(unitek)
    try:
        # SPEED_CMD 0 (ex 3's frame with 0) from the other program while this one waits.
        unitek.later(0.2, other.send, 0x201, bytes([0x31, 0x00, 0x00]))
        with pytest.raises(MoveInterrupted) as e:
            d.move_to(8 * REV, timeout=10)
    finally:
        time.sleep(0.1)
        other.close()
    assert "another program" in e.value.reason
    assert 0 < unitek.sim.position_num < 8 * REV


def test_unitek_timeout_is_move_timed_out_and_a_timeout_error(unitek):
    d = unitek.drive
    with pytest.raises(MoveTimedOut) as e:
        d.move_to(8 * REV, timeout=0.05)
    assert isinstance(e.value, motorbus.TimeoutError)
    assert "still moving" in str(e.value)
    d.stop()
    d.wait_idle(5)


def test_unitek_velocity_for_one_move_is_refused_by_name():
    # 002 has no REGID for the positioning speed (an NDrive parameter): refused, not ignored.
    s = Served("unitek", "0x201", UNITEK_SIM, **UNITEK_OPEN)
    try:
        s.drive.enable()
        with pytest.raises(motorbus.InvalidArgument, match="positioning speed"):
            s.drive.move_to(REV, velocity=1000)
        assert s.sim.position_num == 0
    finally:
        s.close()


def test_unitek_small_moves_with_cyclic_status_return_only_at_their_target(unitek):
    """Issue 28 item 3: with the status, speed and position transmitted cyclically, a reply
    could be a frame the drive sent before it took the new POS_DEST, and the move returned at
    once at the previous target.  Every move must return at its own target."""
    d = unitek.drive
    native = d.native
    streams = [native.subscribe(r, 1) for r in (utk.Reg.KERN_STATUS, utk.Reg.SPEED_IST, utk.Reg.POS_IST)]
    try:
        target = 0
        for i in range(120):
            target += 3000 if i % 2 == 0 else -1000
            d.move_to(target, timeout=10)
            assert abs(unitek.sim.position_num - target) <= 64, f"move {i} returned away from {target}"
            assert d.status.last_move.ok
    finally:
        for r in (utk.Reg.KERN_STATUS, utk.Reg.SPEED_IST, utk.Reg.POS_IST):
            native.unsubscribe(r)
    assert all(s.count > 0 for s in streams)


def test_unitek_home_into_a_limit_is_limit_reached():
    # home() is a move to 0: short of it (a limit on the way), the homing failed.
    s = Served("unitek", "0x201", dict(UNITEK_SIM, minus_limit_num=-1 * REV), **UNITEK_OPEN)
    try:
        d = s.drive
        d.enable()
        d.move_to(3 * REV)
        s.sim.force_limit(-1, True)          # the -limit closes before 0
        with pytest.raises(LimitReached) as e:
            d.home()
        assert e.value.side == -1 and d.status.last_move.state == "limit"
    finally:
        s.close()


def test_unitek_integer_address_means_that_integer():
    assert utk.check_address(0x201) == "0x201"
    assert utk.check_address("201") == "0x201" and utk.check_address("0x27f") == "0x27F"
    with pytest.raises(motorbus.InvalidArgument, match="0x201..0x27F"):
        utk.check_address(513 + 0x100)
    with pytest.raises(motorbus.InvalidArgument):
        utk.check_address(True)
    s = Served("unitek", "0x201", UNITEK_SIM, **UNITEK_OPEN)
    try:
        with motorbus.open_drive("unitek", bus=s.spec, address=0x201) as d:   # 513, the TOML integer
            assert d.native.rx_id == 0x201
            assert d.position == 0
    finally:
        s.close()


# ---- PMC007 ------------------------------------------------------------------------------

@pytest.fixture
def pmc007():
    s = Served("pmc007", "5", {})
    s.drive.params["maximum_speed"] = 20000        # 6003h, pps
    yield s
    s.close()


def test_pmc007_normal_move_returns_exactly_at_target(pmc007):
    d = pmc007.drive
    d.move_to(6000)
    assert pmc007.sim.position == 6000 and d.position == 6000   # window 0: the step counter
    assert d.status.last_move.ok


def test_pmc007_velocity_is_for_that_move_only(pmc007):
    d = pmc007.drive
    d.move_by(4000, velocity=5000, wait=False)
    assert d.params["maximum_speed"] == 5000                      # the move's own speed...
    d.wait_idle(10)
    assert d.params["maximum_speed"] == 20000                     # ...and the drive's back
    assert pmc007.sim.position == 4000
    d.move_to(0, velocity=8000)
    assert d.params["maximum_speed"] == 20000 and pmc007.sim.position == 0
    # Also when the move ends short.
    d.move_to(20000, velocity=6000, wait=False)
    time.sleep(0.1)
    d.stop()
    with pytest.raises(MoveInterrupted):
        d.wait_idle(5)
    assert d.params["maximum_speed"] == 20000


def test_pmc007_fault_mid_move_is_move_faulted_with_the_6000h_code(pmc007):
    d = pmc007.drive
    d.move_to(12000, wait=False)
    time.sleep(0.15)
    pmc007.faults["fault"](pmc007.sim, bits=0x20)                  # TSD
    with pytest.raises(MoveFaulted) as e:
        d.wait_idle(5)
    err = e.value
    assert err.code == 0x20 and "TSD over-temperature shutdown" in err.reason and "6000h" in err.reason
    assert 0 < pmc007.sim.position < 12000 and err.position == pmc007.sim.position
    assert err.status[0] == 0x20
    d.clear_faults()
    d.move_to(0)
    assert pmc007.sim.position == 0


def test_pmc007_stall_is_move_stalled(pmc007):
    # The issue: "pmc007 stall -> nothing reported".
    d = pmc007.drive
    d.move_to(12000, wait=False)
    time.sleep(0.15)
    pmc007.faults["stall"](pmc007.sim)
    with pytest.raises(MoveStalled) as e:
        d.wait_idle(5)
    assert "STALL" in e.value.reason and e.value.code & pmc.ControllerStatus.STALL
    assert 0 < pmc007.sim.position < 12000
    assert d.status.last_move.state == "stall"


def test_pmc007_stop_input_is_move_interrupted_naming_the_input(pmc007):
    d = pmc007.drive
    d.move_to(20000, wait=False)
    time.sleep(0.1)
    pmc007.faults["stop_input"](pmc007.sim)                        # EXT2, 100 ms debounce
    with pytest.raises(MoveInterrupted) as e:
        d.wait_idle(5)
    assert "EXT2 external stop input" in e.value.reason and "6001h bit 1" in e.value.reason
    assert 0 < pmc007.sim.position < 20000


def test_pmc007_stop_input_declared_a_limit_is_limit_reached():
    s = Served("pmc007", "5", {}, ext_limits={"ext2": 1})
    try:
        d = s.drive
        d.params["maximum_speed"] = 20000
        d.move_to(20000, wait=False)
        time.sleep(0.1)
        s.faults["stop_input"](s.sim)
        with pytest.raises(LimitReached) as e:
            d.wait_idle(5)
        assert e.value.side == 1 and "EXT2" in e.value.reason and "+limit" in e.value.reason
        assert d.status.limit_positive
    finally:
        s.close()
    with pytest.raises(motorbus.InvalidArgument, match="ext_limits"):
        pmc.Pmc007Drive(None, ext_limits={"ext9": 1})


def test_pmc007_stop_from_another_thread_is_move_interrupted(pmc007):
    d = pmc007.drive
    pmc007.later(0.15, d.stop)
    with pytest.raises(MoveInterrupted) as e:
        d.move_to(20000)
    assert "stop() of this program" in e.value.reason
    assert 0 < pmc007.sim.position < 20000 and not pmc007.sim.busy


def test_pmc007_stop_from_a_second_program_is_move_interrupted(pmc007):
    d = pmc007.drive
    other = SecondProgram(pmc007)
    confirmed = []

    def second_program_stops() -> None:
        # Another program writes 6020h (immediate stop) by SDO on the node's COB-IDs while
        # this one polls: the node has one request slot (a colliding request is dropped),
        # so it does what an SDO client does, asks again until the node confirms.
        for _ in range(10):
            other.send(0x605, bytes([0x2F, 0x20, 0x60, 0x00, 0x00, 0x00, 0x00, 0x00]))
            if other.reply(0x585, bytes([0x60, 0x20, 0x60, 0x00]), timeout=0.2):
                confirmed.append(True)
                return

    try:
        pmc007.later(0.15, second_program_stops)
        with pytest.raises(MoveInterrupted) as e:
            d.move_to(20000, timeout=10)
    finally:
        time.sleep(0.3)
        other.close()
    assert confirmed, "the node never confirmed the second program's stop"
    assert "another program" in e.value.reason
    assert 0 < pmc007.sim.position < 20000 and not pmc007.sim.busy


def test_pmc007_timeout_is_move_timed_out(pmc007):
    d = pmc007.drive
    with pytest.raises(MoveTimedOut):
        d.move_to(20000, timeout=0.05)
    d.stop()
    d.wait_idle(5)


def test_pmc007_stall_during_homing_is_move_stalled(pmc007):
    d = pmc007.drive
    d.move_to(3000)
    d.home("ext1", wait=False)
    time.sleep(0.1)
    pmc007.faults["stall"](pmc007.sim)
    with pytest.raises(MoveStalled) as e:
        d.wait_idle(10)
    assert "STALL" in e.value.reason and not d.status.homed


def test_pmc007_homing_puts_its_speed_back(pmc007):
    d = pmc007.drive
    d.home("ext1")            # the sim's switch on EXT1 below -1000 steps
    assert d.status.homed and d.position == 0
    assert d.params["maximum_speed"] == 20000


def test_pmc007_identity_and_console():
    s = Served("pmc007", "5", {"serial": 1234})
    try:
        n = s.drive.native
        assert n.read((0x1018, 2)) == 7 and n.read((0x1018, 3)) == 0x00010000 and n.read((0x1018, 4)) == 1234
        assert n.read((0x1018, 1)) == 0                  # no vendor claimed: the manual names none
        # `terminal` on a pmc007 axis: SDO by index, as on every CANopen kind.
        assert s.drive.console("r 0x1018:2 u32") == "7"
        assert s.drive.console("r 0x1018:4 u32") == "1234"
    finally:
        s.close()


def test_pmc007_integer_address_means_that_integer():
    check = registry.drive_plugin("pmc007").check_address
    assert check(5) == "5" and check("05") == "5" and check("0x7F") == "127"
    for bad in (0, 128, True, "x", "9" * 100):
        with pytest.raises(motorbus.InvalidArgument, match="pmc007 address"):
            check(bad)


def test_bench_file_integer_addresses_mean_those_integers(tmp_path):
    # Issue 22: `address = 0x201` (a TOML integer, 513) was refused as "receive id 0x513".
    p = tmp_path / "bench.toml"
    p.write_text('[bus.can]\nspec = "virtual:outcomes-can-int-address"\n\n'
                 '[axis.z]\nkind = "unitek"\nbus = "can"\naddress = 0x201\n\n'
                 '[axis.p]\nkind = "pmc007"\nbus = "can"\naddress = 5\n')
    with motorbus.Bench.load(p, sim=True) as bench:
        assert bench.config["z"].address == "0x201" and bench.config["p"].address == "5"
        assert bench["z"].native.rx_id == 0x201 and bench["p"].native.node == 5

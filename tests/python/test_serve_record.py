"""motorbus serve's CA face: each axis as an EPICS motor record (docs/epics.md).

The records are driven through their own putters (``await field.write(value)``, what
caproto runs for a client's put) on a simulated bench of four kinds, and every
outcome is checked against the drive and its simulator: where the shaft is, which
DMOV transitions were posted in which order, what the alarm was when DMOV=1 went out
(the moment ophyd judges a move).  One test serves the records over CA on 127.0.0.1.
"""
from __future__ import annotations

import asyncio
import dataclasses
import json
import math
import os
import pathlib
import time
from typing import Any

import pytest
import pytest_asyncio

pytest.importorskip("caproto")

from caproto import AlarmSeverity, AlarmStatus, ChannelType  # noqa: E402

from motorbus import _core, aio, registry  # noqa: E402
from motorbus.drive import LimitReached, MoveFaulted  # noqa: E402
from motorbus.pytest_plugin import default_bench  # noqa: E402
from motorbus.serve import calibration, epics  # noqa: E402
from motorbus.serve.epics_axis import (PUT_NOTIFY, MSTA_COMM_ERR, MSTA_DONE, MSTA_HOMED, MSTA_PLUS_LS, MSTA_PROBLEM,  # noqa: E402
                                       MoveFailedPut, PutRefused, SoftLimitViolation, check_axis_name)

pytestmark = pytest.mark.asyncio(loop_scope="module")

KINDS = ("cia402", "arcus", "pmc007", "unitek")
#: The fields ophyd EpicsMotor, ophyd-async Motor and pyepics Motor connect to, and the CA
#: type each must have (research brief, section 2).
UNION = {
    "RBV": ChannelType.DOUBLE, "DMOV": ChannelType.INT, "MOVN": ChannelType.INT, "STOP": ChannelType.INT,
    "HLM": ChannelType.DOUBLE, "LLM": ChannelType.DOUBLE, "DHLM": ChannelType.DOUBLE, "DLLM": ChannelType.DOUBLE,
    "HLS": ChannelType.INT, "LLS": ChannelType.INT, "TDIR": ChannelType.INT, "OFF": ChannelType.DOUBLE,
    "DIR": ChannelType.ENUM, "FOFF": ChannelType.ENUM, "SET": ChannelType.ENUM, "VELO": ChannelType.DOUBLE,
    "ACCL": ChannelType.DOUBLE, "EGU": ChannelType.STRING, "HOMF": ChannelType.INT, "HOMR": ChannelType.INT,
    "MRES": ChannelType.DOUBLE, "UREV": ChannelType.DOUBLE, "ERES": ChannelType.DOUBLE, "RDBD": ChannelType.DOUBLE,
    "VMAX": ChannelType.DOUBLE, "SREV": ChannelType.LONG, "PREC": ChannelType.INT, "OUT": ChannelType.STRING,
    "DESC": ChannelType.STRING, "RTYP": ChannelType.STRING, "STAT": ChannelType.ENUM, "SPMG": ChannelType.ENUM,
    "LVIO": ChannelType.INT, "TWV": ChannelType.DOUBLE, "TWF": ChannelType.INT, "TWR": ChannelType.INT,
    "DVAL": ChannelType.DOUBLE, "DRBV": ChannelType.DOUBLE, "RVAL": ChannelType.LONG, "RRBV": ChannelType.LONG,
    "MSTA": ChannelType.DOUBLE, "JOGF": ChannelType.INT, "JOGR": ChannelType.INT, "SEVR": ChannelType.ENUM,
    "CNEN": ChannelType.ENUM,
}
ENUMS = {"DIR": ("Pos", "Neg"), "FOFF": ("Variable", "Frozen"), "SET": ("Use", "Set"),
         "SPMG": ("Stop", "Pause", "Move", "Go")}


def bench_dict() -> dict:
    """Four kinds of the plugin's default twin (two CANopen, one serial, one CAN), in mm,
    with fast profiles."""
    data = default_bench()
    data["axis"] = {k: v for k, v in data["axis"].items() if k in KINDS}
    data["line"] = {k: v for k, v in data["line"].items() if k.removesuffix("-link") in KINDS}
    data["bus"] = {k: v for k, v in data["bus"].items() if k.removesuffix("-link") in KINDS}
    mm = {"name": "mm", "scale": 0.01}
    data["axis"]["cia402"].update(units=mm, params={"0x6081": 20000, "0x6083": 400000, "0x6084": 400000})
    data["axis"]["arcus"].update(units=mm, params={"HSPD": 20000, "LSPD": 2000, "ACC": 20})
    data["axis"]["pmc007"].update(units=mm)
    data["axis"]["unitek"].update(units=mm, params={"ACC_RAMP": 20}, sim={"calibrated": True, "dec_ramp_ms": 20})
    return data


@pytest_asyncio.fixture(scope="module", loop_scope="module")
async def bench():
    b = await aio.Bench.from_dict(bench_dict(), sim=True)
    for name in b:
        await b[name].enable()
    yield b
    await b.stop_all()
    await b.aclose()


@pytest_asyncio.fixture(scope="module", loop_scope="module")
async def face(bench, tmp_path_factory):
    f = await epics.build_face(bench, prefix="E26:", calibration_path=str(tmp_path_factory.mktemp("cal") / "b.epics.json"))
    yield f
    await f.close()


class Watch:
    """Records the DMOV values a record posts, with RBV's alarm severity at each."""

    def __init__(self, record: Any) -> None:
        self.record = record
        self.dmov: list[tuple[int, int]] = []
        fld = record.fields["DMOV"]
        self._orig = fld.write

        async def write(value: Any, **kw: Any) -> Any:
            self.dmov.append((int(value), int(record.fields["RBV"].alarm.severity)))
            return await self._orig(value, **kw)

        fld.write = write

    def close(self) -> None:
        self.record.fields["DMOV"].write = self._orig

    @property
    def values(self) -> list[int]:
        return [v for v, _ in self.dmov]


@pytest.fixture
def watch(face):
    watches: list[Watch] = []

    def make(axis: str) -> Watch:
        w = Watch(face.records[axis])
        watches.append(w)
        return w

    yield make
    for w in watches:
        w.close()


async def until(cond: Any, timeout: float = 5.0, what: str = "condition") -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > deadline:
            raise AssertionError(f"{what}: not within {timeout} s")
        await asyncio.sleep(0.005)


async def rest(record: Any) -> None:
    await until(lambda: record.fields["DMOV"].value == 1 and not record.moving, what="rest")


# ---- the record's shape -----------------------------------------------------------------------------
async def test_every_axis_is_a_motor_record_with_the_clients_fields(face, bench):
    assert set(face.records) == set(KINDS)
    for name in ("E26:allstop", "E26:alldone", "E26:moving"):
        assert name in face.pvdb
    for axis, r in face.records.items():
        assert f"E26:{axis}" in face.pvdb and f"E26:{axis}_able" in face.pvdb
        f = r.fields
        assert f["RTYP"].value == "motor"
        for field, ctype in UNION.items():
            assert f[field].data_type == ctype, (axis, field, f[field].data_type)
        for field, strings in ENUMS.items():
            assert tuple(f[field].enum_strings) == strings, field
        assert tuple(r.able.enum_strings) == ("Enable", "Disable") and r.able.value == "Enable"
        assert f["LVIO"].value == 0 and f["DMOV"].value == 1 and f["MOVN"].value == 0
        assert f["EGU"].value == "mm" and f["MRES"].value == pytest.approx(0.01) and f["PREC"].value == 2
        await f["DESC"].read(ChannelType.STRING)          # what a client reads: the getter runs
        assert f["DESC"].value.startswith(bench[axis].kind + " ")
        assert f["VELO"].value > 0 and f["SREV"].value == 200 and f["UREV"].value == pytest.approx(2.0)
        pos = await bench[axis].position()
        assert r.motor.value == pytest.approx(pos) and f["RBV"].value == pytest.approx(pos)
        assert int(f["MSTA"].value) & MSTA_DONE
        if (await bench[axis].travel_limits()) == (-math.inf, math.inf):
            # No travel limits: a 32-bit position register's range (pyepics tests targets against them).
            reach = (2**31 - 1) * 0.01
            assert (f["LLM"].value, f["HLM"].value) == (pytest.approx(-reach), pytest.approx(reach))
            assert (r.motor.lower_ctrl_limit, r.motor.upper_ctrl_limit) == (f["LLM"].value, f["HLM"].value)


async def test_axis_names_that_clash_are_refused():
    for bad in ("allstop", "alldone", "moving", "a.b", "a b", ""):
        with pytest.raises(_core.InvalidArgument):
            check_axis_name(bad, [bad])
    with pytest.raises(_core.InvalidArgument, match="_able record of axis 'x'"):
        check_axis_name("x_able", ["x", "x_able"])
    check_axis_name("x_able", ["x_able"])


# ---- moves ----------------------------------------------------------------------------------------
async def test_a_put_completes_at_rest_on_target(face, bench, watch):
    r, w = face.records["cia402"], watch("cia402")
    await r.motor.write(2.0)
    assert w.values == [0, 1]
    assert await bench["cia402"].position() == pytest.approx(2.0)
    assert bench.sync.sims["cia402"].position == pytest.approx(200)       # native counts on the simulator
    f = r.fields
    assert (f["RBV"].value, f["DVAL"].value, f["RVAL"].value, f["RRBV"].value) == (pytest.approx(2.0),
                                                                                  pytest.approx(2.0), 200, 200)
    assert f["MOVN"].value == 0 and f["DMOV"].value == 1 and f["TDIR"].value == 1


async def test_one_dmov_pulse_per_move_and_none_after(face, bench, watch):
    """Back-to-back moves: exactly one 1->0->1 per put and nothing after the last (a stray
    pulse would end the next ophyd MoveStatus early)."""
    r, w = face.records["unitek"], watch("unitek")
    for i in range(8):
        await r.motor.write(0.5 * (i % 2))
        await asyncio.sleep(0.03)
    await asyncio.sleep(0.25)
    assert w.values == [0, 1] * 8
    # A status kept from mid-move (the readback reads it only every third period at rest)
    # must not make the axis look moving again (cia402: its position stands still at rest).
    c, wc = face.records["cia402"], watch("cia402")
    await c.motor.write(c.motor.value + 0.5)
    await asyncio.sleep(0.05)
    for _ in range(20):               # kept whatever the readback's phase
        c.status = dataclasses.replace(c.status, moving=True)
        await asyncio.sleep(0.02)
    assert wc.values == [0, 1] and c.fields["MOVN"].value == 0


async def test_a_zero_length_move_pulses_dmov(face, bench, watch):
    for axis in ("cia402", "unitek"):
        r, w = face.records[axis], watch(axis)
        await rest(r)
        here = await bench[axis].position()
        await r.motor.write(r.motor.value)
        assert w.values == [0, 1], axis
        assert w.dmov[-1][1] == AlarmSeverity.NO_ALARM
        assert await bench[axis].position() == pytest.approx(here)


async def test_a_second_put_retargets_and_both_complete_at_the_final_rest(face, bench, watch):
    r, w = face.records["cia402"], watch("cia402")
    await r.motor.write(0.0)
    w.dmov.clear()

    async def put(value: float) -> tuple:
        await r.motor.write(value)
        return (r.fields["RBV"].value, r.fields["DMOV"].value, await bench["cia402"].position())

    first = asyncio.create_task(put(30.0))
    await until(lambda: r.fields["MOVN"].value == 1, what="moving")
    second = asyncio.create_task(put(4.0))
    await asyncio.sleep(0.05)
    assert not first.done()
    results = await asyncio.gather(first, second)
    for rbv, dmov, pos in results:
        assert (rbv, dmov, pos) == (pytest.approx(4.0), 1, pytest.approx(4.0))
    assert w.values == [0, 1]                   # one pulse for the whole episode
    assert r.motor.value == pytest.approx(4.0)


async def test_a_target_outside_the_soft_limits_sets_lvio_and_fails_the_put(face, bench, watch):
    r, f = face.records["unitek"], face.records["unitek"].fields
    await r.motor.write(1.0)
    await f["HLM"].write(5.0)
    await f["LLM"].write(-5.0)
    assert (f["DHLM"].value, f["DLLM"].value) == (5.0, -5.0)
    assert (r.motor.lower_ctrl_limit, r.motor.upper_ctrl_limit) == (-5.0, 5.0)
    w = watch("unitek")
    with pytest.raises(SoftLimitViolation, match="outside the soft limits"):
        await r.motor.write(8.0)
    assert f["LVIO"].value == 1 and w.values == [0, 1]
    assert r.motor.value == pytest.approx(1.0) and f["DVAL"].value == pytest.approx(1.0)
    assert await bench["unitek"].position() == pytest.approx(1.0)
    await until(lambda: r.motor.alarm.severity == AlarmSeverity.NO_ALARM, what="VAL's alarm put back")
    # A plain put (no put-callback: ophyd's move) is not answered with an error, as an IOC
    # would not: LVIO says it.
    await f["LVIO"].write(0, verify_value=False)

    async def plain_put() -> None:
        PUT_NOTIFY.set(False)
        await r.motor.write(9.0)

    await asyncio.create_task(plain_put())
    assert f["LVIO"].value == 1 and r.motor.value == pytest.approx(1.0)
    assert r.motor.alarm.severity == AlarmSeverity.NO_ALARM
    await r.motor.write(-2.0)
    assert f["LVIO"].value == 0 and await bench["unitek"].position() == pytest.approx(-2.0)
    await f["HLM"].write(0.0)
    await f["LLM"].write(0.0)
    assert face.counters["failed_puts"] >= 1


async def test_a_plain_put_returns_once_the_move_is_started(face, bench):
    """ophyd's move and `caput` without -c: nobody waits for the answer, and a write in
    flight would hold back every read on the client's circuit."""
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(0.0)

    async def plain_put() -> None:
        PUT_NOTIFY.set(False)
        await r.motor.write(6.0)

    await asyncio.wait_for(asyncio.create_task(plain_put()), 1.0)
    assert f["DMOV"].value == 0 and r.motor.value == 6.0
    await until(lambda: f["DMOV"].value == 1, timeout=10, what="rest")
    assert await bench["cia402"].position() == pytest.approx(6.0)


async def test_stop_resets_and_sets_val_to_rbv(face, bench):
    r, f = face.records["cia402"], face.records["cia402"].fields
    task = asyncio.create_task(r.motor.write(60.0))
    await until(lambda: f["MOVN"].value == 1 and f["RBV"].value > 5.0, what="moving")
    await f["STOP"].write(1)
    assert f["STOP"].value == 0
    # Interrupted by STOP: the put-callback fails with the Drive API's reason (a deliberate
    # difference from the record, which completes it: docs/epics.md) and the record is in
    # STATE/MINOR, which ophyd reads at DMOV=1 as a failed move.
    with pytest.raises(Exception, match=r"STOP of the EPICS record \S+cia402"):
        await asyncio.wait_for(task, 10)
    pos = await bench["cia402"].position()
    assert 5.0 < pos < 60.0
    assert r.motor.value == pytest.approx(pos) and f["RBV"].value == pytest.approx(pos)
    assert f["DMOV"].value == 1 and f["MOVN"].value == 0
    assert (f["RBV"].alarm.status, f["RBV"].alarm.severity) == (AlarmStatus.STATE, AlarmSeverity.MINOR_ALARM)
    await until(lambda: r.motor.alarm.status == AlarmStatus.STATE, what="the record's alarm back on VAL")
    assert (f["SEVR"].value, f["STAT"].value) == ("MINOR", "STATE")
    assert int(f["MSTA"].value) & (1 << 9) == 0           # not a PROBLEM: nothing is wrong with the drive
    await r.motor.write(pos + 1.0)                        # the next good move clears it
    assert f["SEVR"].value == "NO_ALARM"


async def test_spmg_pause_go_stop_move(face, bench):
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(0.0)
    task = asyncio.create_task(r.motor.write(20.0))
    await until(lambda: f["RBV"].value > 2.0, what="moving")
    await f["SPMG"].write("Pause")
    await until(lambda: not r.moving, what="paused")
    await asyncio.sleep(0.1)
    assert not task.done() and f["DMOV"].value == 0
    paused_at = await bench["cia402"].position()
    assert paused_at < 20.0
    await f["SPMG"].write("Go")
    await asyncio.wait_for(task, 10)
    assert await bench["cia402"].position() == pytest.approx(20.0)
    assert f["LSPG"].value == "Pause"
    # Stop: a put completes without motion, VAL := RBV.
    await f["SPMG"].write("Stop")
    await r.motor.write(25.0)
    assert await bench["cia402"].position() == pytest.approx(20.0) and r.motor.value == pytest.approx(20.0)
    # Move: one move, then Pause.
    await f["SPMG"].write("Move")
    await r.motor.write(22.0)
    assert await bench["cia402"].position() == pytest.approx(22.0) and f["SPMG"].value == "Pause"
    await f["SPMG"].write("Go")


async def test_homf_runs_the_kinds_homing(face, bench, watch):
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(3.0)
    w = watch("cia402")
    with pytest.raises(PutRefused, match="takes 1"):
        await f["HOMF"].write(0)
    await f["HOMF"].write(1)
    assert f["HOMF"].value == 0 and w.values == [0, 1]
    st = await bench["cia402"].status()
    assert st.homed and st.last_move.what == "home" and st.last_move.ok
    assert r.motor.value == pytest.approx(f["RBV"].value) == pytest.approx(await bench["cia402"].position())
    assert int(f["MSTA"].value) & MSTA_HOMED


async def test_tweak_and_jog(face, bench):
    r, f = face.records["unitek"], face.records["unitek"].fields
    await r.motor.write(0.0)
    await f["TWV"].write(1.5)
    await f["TWF"].write(1)
    assert f["TWF"].value == 0 and await bench["unitek"].position() == pytest.approx(1.5)
    await f["TWR"].write(1)
    assert await bench["unitek"].position() == pytest.approx(0.0)
    await f["JVEL"].write(20.0)
    await f["JOGF"].write(1)
    await until(lambda: f["MOVN"].value == 1 and f["RBV"].value > 0.5, what="jogging")
    assert f["DMOV"].value == 0
    await f["JOGF"].write(0)
    assert f["JOGF"].value == 0 and f["DMOV"].value == 1
    pos = await bench["unitek"].position()
    assert pos > 0.5 and r.motor.value == pytest.approx(pos)


# ---- calibration ---------------------------------------------------------------------------------------
async def test_dir_neg_swaps_the_limits(face, bench):
    r, f = face.records["unitek"], face.records["unitek"].fields
    await r.motor.write(2.0)
    await f["DHLM"].write(50.0)
    await f["DLLM"].write(-10.0)
    assert (f["LLM"].value, f["HLM"].value) == (-10.0, 50.0)
    await f["DIR"].write("Neg")
    off = f["OFF"].value
    assert off == pytest.approx(4.0)                         # FOFF=Variable: VAL stays at 2
    assert r.motor.value == pytest.approx(2.0) and f["RBV"].value == pytest.approx(2.0)
    assert f["HLM"].value == pytest.approx(off + 10.0) and f["LLM"].value == pytest.approx(off - 50.0)
    assert (r.motor.lower_ctrl_limit, r.motor.upper_ctrl_limit) == (pytest.approx(off - 50), pytest.approx(off + 10))
    await r.motor.write(1.0)                                 # user -1 = dial +1
    assert await bench["unitek"].position() == pytest.approx(3.0)
    with pytest.raises(SoftLimitViolation):
        await r.motor.write(off + 11.0)                      # dial -11 < DLLM
    await f["DIR"].write("Pos")
    await f["OFF"].write(0.0)
    await f["DHLM"].write(0.0)
    await f["DLLM"].write(0.0)
    assert r.motor.value == pytest.approx(3.0)


async def test_set_mode_calibrates_without_moving_and_persists(bench, tmp_path):
    path = str(tmp_path / "cal.epics.json")
    one = await epics.build_face(bench, prefix="C1:", calibration_path=path)
    try:
        r, f = one.records["unitek"], one.records["unitek"].fields
        await r.motor.write(1.0)
        await f["SET"].write("Set")
        await r.motor.write(100.0)
        assert await bench["unitek"].position() == pytest.approx(1.0)        # nothing moved
        assert f["OFF"].value == pytest.approx(99.0) and f["RBV"].value == pytest.approx(100.0)
        await f["FOFF"].write("Frozen")
        with pytest.raises(PutRefused, match="FOFF=Frozen"):
            await r.motor.write(50.0)
        await f["FOFF"].write("Variable")
        await f["SUSE"].write(1)
        assert f["SET"].value == "Use"
        await r.motor.write(101.0)
        assert await bench["unitek"].position() == pytest.approx(2.0)
        await f["HLM"].write(150.0)
        await f["VELO"].write(40.0)
    finally:
        await one.close()
    saved = json.loads(pathlib.Path(path).read_text())["axes"]["unitek"]
    assert saved["off"] == pytest.approx(99.0) and saved["dhlm"] == pytest.approx(51.0) and saved["velo"] == 40.0
    two = await epics.build_face(bench, prefix="C2:", calibration_path=path)
    try:
        r, f = two.records["unitek"], two.records["unitek"].fields
        assert f["OFF"].value == pytest.approx(99.0) and f["HLM"].value == pytest.approx(150.0)
        assert f["RBV"].value == pytest.approx(101.0) and r.motor.value == pytest.approx(101.0)
        assert f["VELO"].value == 40.0
        await f["OFF"].write(0.0)
        await f["HLM"].write(0.0)
        await f["LLM"].write(0.0)
    finally:
        await two.close()


async def test_a_broken_calibration_file_is_refused(tmp_path):
    bad = tmp_path / "bad.epics.json"
    bad.write_text('{"version": 1, "axes": {"x": {"dir": 3}}}')
    with pytest.raises(calibration.CalibrationError, match=r"axes\.x\.dir: 1 or -1"):
        calibration.load(str(bad))
    bad.write_text("{not json")
    with pytest.raises(calibration.CalibrationError, match="not JSON"):
        calibration.load(str(bad))
    assert calibration.load(str(tmp_path / "none.json")) == {}


async def test_velo_and_accl_reach_the_drive(face, bench):
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(0.0)
    await f["VELO"].write(100.0)         # mm/s -> 10000 counts/s
    await f["ACCL"].write(0.05)          # s to VELO -> 200000 counts/s^2
    await r.motor.write(5.0)
    assert await bench["cia402"].params.get("0x6083") == 200000
    assert await bench["cia402"].params.get("0x6084") == 200000
    assert f["S"].value == pytest.approx(100.0 / 2.0)


# ---- status, alarms, other programs ----------------------------------------------------------------------
async def test_motion_from_another_program_shows_as_moving(face, bench):
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(0.0)
    seen: list = []
    orig = f["DMOV"].write

    async def spy(value: Any, **kw: Any) -> Any:
        seen.append((int(value), f["MOVN"].value))
        return await orig(value, **kw)

    f["DMOV"].write = spy
    try:
        # Not through the record (the RPC face, say), slow enough for the 10 Hz rest readback.
        await bench["cia402"].move_to(6.0, velocity=10.0)
        await until(lambda: f["DMOV"].value == 1 and r.motor.value == pytest.approx(6.0), what="synced")
    finally:
        f["DMOV"].write = orig
    assert seen[0] == (0, 1) and seen[-1][0] == 1
    assert f["RBV"].value == pytest.approx(6.0)


async def test_allstop_stops_every_axis(face, bench):
    b = face.bench_records
    for a in ("cia402", "arcus"):
        await face.records[a].fields["VELO"].write(20.0)     # slow: stopped long before the target
    tasks = [asyncio.create_task(face.records[a].motor.write(300.0)) for a in ("cia402", "arcus")]
    await until(lambda: all(face.records[a].fields["MOVN"].value for a in ("cia402", "arcus")), what="moving")
    assert b.alldone.value == "moving" and b.moving.value >= 2
    await b.allstop.write("stop")
    assert b.allstop.value == "release"
    outcomes = await asyncio.wait_for(asyncio.gather(*tasks, return_exceptions=True), 10)
    for a, outcome in zip(("cia402", "arcus"), outcomes):
        # each put-callback fails naming the allstop (docs/epics.md: a stopped move is not a success)
        assert isinstance(outcome, MoveFailedPut) and "allstop of the EPICS record" in str(outcome), outcome
        assert await bench[a].position() < 300.0
        await face.records[a].fields["VELO"].write(100.0)
    await until(lambda: b.alldone.value == "done" and b.moving.value == 0, what="all done")


async def test_a_cancelled_put_leaves_the_motor_moving(face, bench):
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(0.0)
    task = asyncio.create_task(r.motor.write(8.0))
    await until(lambda: f["MOVN"].value == 1, what="moving")
    task.cancel()                     # what caproto does when the client leaves
    await until(lambda: f["DMOV"].value == 1, timeout=10, what="rest")
    assert await bench["cia402"].position() == pytest.approx(8.0)


async def test_limit_switch_shows_in_hls_msta_and_fails_the_move(face, bench):
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(1.0)
    sim = bench.sync.sims["cia402"]
    registry.drive_plugin("cia402").sim_faults()["limit"](sim, direction=1)
    try:
        await until(lambda: f["HLS"].value == 1, what="HLS")
        assert f["RHLS"].value == 1 and f["LLS"].value == 0 and int(f["MSTA"].value) & MSTA_PLUS_LS
        with pytest.raises(MoveFailedPut) as e:
            await r.motor.write(5.0)
        assert isinstance(e.value.error, LimitReached) and e.value.error.side == 1
        assert f["DMOV"].value == 1 and r.motor.value == pytest.approx(f["RBV"].value)
    finally:
        sim.force_limit(1, False)
    await until(lambda: f["HLS"].value == 0, what="HLS released")
    await f["CNEN"].write("Enable")
    await r.motor.write(2.0)
    assert await bench["cia402"].position() == pytest.approx(2.0)


async def test_a_fault_during_a_move_is_a_major_alarm_and_a_failed_put_until_a_good_move(face, bench, watch):
    r, f = face.records["cia402"], face.records["cia402"].fields
    await r.motor.write(0.0)
    w = watch("cia402")
    task = asyncio.create_task(r.motor.write(300.0))
    await until(lambda: f["RBV"].value > 1.0, what="moving")
    registry.drive_plugin("cia402").sim_faults()["fault"](bench.sync.sims["cia402"])
    with pytest.raises(MoveFailedPut) as e:
        await task
    assert isinstance(e.value.error, MoveFaulted) and "0x5441" in str(e.value)
    # RBV's alarm was MAJOR when DMOV=1 went out (ophyd judges the move then).
    assert w.dmov[-1] == (1, AlarmSeverity.MAJOR_ALARM)
    rbv_alarm = f["RBV"].alarm
    assert (rbv_alarm.status, rbv_alarm.severity) == (AlarmStatus.STATE, AlarmSeverity.MAJOR_ALARM)
    assert int(f["MSTA"].value) & MSTA_PROBLEM
    await until(lambda: r.motor.alarm.status == AlarmStatus.STATE, what="the record's alarm back on VAL")
    assert f["SEVR"].value == "MAJOR"
    await f["CNEN"].write("Enable")        # the fault reset
    await r.motor.write(1.0)
    assert rbv_alarm.severity == AlarmSeverity.NO_ALARM and r.motor.alarm.severity == AlarmSeverity.NO_ALARM
    assert not int(f["MSTA"].value) & MSTA_PROBLEM and f["SEVR"].value == "NO_ALARM"


async def test_disabled_record_refuses_puts(face, bench):
    r, f = face.records["unitek"], face.records["unitek"].fields
    await r.able.write("Disable")
    try:
        assert f["DISP"].value == b"\x01" and r.disabled
        with pytest.raises(PutRefused, match="disabled"):
            await r.motor.write(3.0)
        with pytest.raises(PutRefused, match="disabled"):
            await f["VELO"].write(3.0)
    finally:
        await r.able.write("Enable")
    await r.motor.write(3.0)
    assert await bench["unitek"].position() == pytest.approx(3.0)


# ---- served ----------------------------------------------------------------------------------------------
def _port() -> int:
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker.startswith("gw") and worker[2:].isdigit() else 0
    return 20000 + 16 * index + 7


#: The caproto settings exported before this module ran (a user's own value is kept).
ca_user_env = {k for k in os.environ if k.startswith("CAPROTO_SERVER_")}

# ---- the kinds' speed and ramp hooks the record's VELO/VMAX/ACCL go through ----------------------------
@pytest.mark.parametrize("axis, param", [("arcus", "ACC"), ("unitek", "ACC_RAMP")])
async def test_accel_time_in_ms_ramps(bench, axis, param):
    d = bench[axis].sync
    assert await d._set_accel_time(0.05, 1000.0, None) is True
    assert await bench[axis].params.get(param) == 50             # 0.05 s to speed: a 50 ms ramp


async def test_pmc007_accel_time_picks_the_nearest_gear(bench):
    d = bench["pmc007"].sync
    await d._set_accel_time(1e-6, 1000.0, None)                    # as steep as it gets: the fastest gear
    assert await bench["pmc007"].params.get("0x6008") == 1
    await d._set_accel_time(1e3, 1000.0, None)                     # as gentle as it gets: the slowest
    assert await bench["pmc007"].params.get("0x6008") == 8 and await bench["pmc007"].params.get("0x6009") == 8
    await d._set_accel_time(1e-6, 1000.0, None)                    # back to the fastest for what follows


async def test_move_speed_and_per_move_velocity_per_kind(bench):
    for axis in ("cia402", "arcus", "pmc007"):
        now, top = await bench[axis].sync._move_speed()
        # the declared maximum; the speed now (None where the drive holds 0: not set yet)
        assert top and top > 0 and (now is None or 0 < now <= top), (axis, now, top)
        assert bench[axis].sync.per_move_velocity
    assert await bench["unitek"].sync._move_speed() == (None, None)   # its speed is an NDrive setting
    assert not bench["unitek"].sync.per_move_velocity
    assert bench["arcus"].sync.homing_directions == ("H+", "H-")



async def test_served_over_ca_on_loopback_without_broadcast_beacons(bench):
    from caproto import _utils

    port = _port()
    served = await epics.start_ca(bench, prefix="S26:", port=port)
    try:
        assert served.port == port and served.interfaces == ["127.0.0.1"]
        env = served.client_env()
        assert env == {"EPICS_CA_AUTO_ADDR_LIST": "NO", "EPICS_CA_ADDR_LIST": f"127.0.0.1:{port}",
                       "EPICS_CA_SERVER_PORT": str(port)}
        beacons = _utils.get_beacon_address_list()
        assert beacons and all(host == "127.0.0.1" for host, _ in beacons)
        import caproto.server.common as common
        for variable, (name, _default) in epics.LATENCY_SETTINGS.items():   # the exported value, else ours
            assert getattr(common, name) == float(os.environ[variable])
        assert common.MAX_LATENCY <= 0.005 or "CAPROTO_SERVER_MAX_LATENCY_SEC" in ca_user_env
        assert os.environ["EPICS_CAS_INTF_ADDR_LIST"] == "127.0.0.1"

        def client() -> tuple:
            from caproto.sync.client import read, write
            old = {k: os.environ.get(k) for k in env}
            os.environ.update(env)
            try:
                rtyp = read("S26:unitek.RTYP", timeout=5, repeater=False).data[0]
                msta = read("S26:unitek.MSTA", timeout=5, repeater=False).data_type
                write("S26:unitek", 4.0, notify=True, timeout=10, repeater=False)
                return rtyp, msta, read("S26:unitek.RBV", timeout=5, repeater=False).data[0]
            finally:
                for k, v in old.items():
                    if v is None:
                        os.environ.pop(k, None)
                    else:
                        os.environ[k] = v

        rtyp, msta, rbv = await asyncio.to_thread(client)
        assert rtyp == b"motor" and msta == ChannelType.DOUBLE and rbv == pytest.approx(4.0)
        assert await bench["unitek"].position() == pytest.approx(4.0)
    finally:
        await served.close()


async def test_a_second_server_on_the_same_udp_port_is_warned_about(bench, caplog):
    port = _port() + 1
    first = await epics.start_ca(bench, prefix="W1:", port=port)
    try:
        assert "shared_udp_port" not in first.counters
        second = await epics.start_ca(bench, prefix="W2:", port=port)
        await second.close()
        assert second.counters["shared_udp_port"] == 1
        assert f"UDP port {port} on 127.0.0.1 is already taken" in caplog.text
    finally:
        await first.close()


async def test_a_slow_or_silent_drive_does_not_freeze_another_axis(face, bench):
    """Last (it spoils the twin): the pmc007's bus delays every frame by 0.2 s (each of its
    SDO exchanges takes that long) and the arcus line goes silent; the cia402 record moves
    and reads back as before, and the arcus record says COMM_ERR."""
    arcus, pmc, cia = face.records["arcus"], face.records["pmc007"], face.records["cia402"]
    bench.sync.served_buses["pmc007-link"].set_faults(delay=0.2)
    slow = asyncio.create_task(pmc.motor.write(pmc.motor.value + 1.0))
    bench.sync.served_lines["arcus-link"].close()
    silent = asyncio.create_task(arcus.motor.write(arcus.motor.value + 3.0))
    await until(lambda: int(arcus.fields["MSTA"].value) & MSTA_COMM_ERR, timeout=10, what="COMM_ERR")
    await asyncio.sleep(0.3)
    assert not slow.done()
    seen = set()

    async def sample() -> None:
        while True:
            seen.add(round(cia.fields["RBV"].value, 2))
            await asyncio.sleep(0.005)

    await cia.fields["VELO"].write(20.0)             # a 1 s move: RBV is seen along the way
    sampler = asyncio.create_task(sample())
    start = time.monotonic()
    await cia.motor.write(cia.motor.value + 20.0)
    took = time.monotonic() - start
    sampler.cancel()
    assert await bench["cia402"].position() == pytest.approx(cia.motor.value)
    assert len(seen) >= 4, seen                  # RBV posted along the way, not only at the end
    assert took < 5.0
    with pytest.raises((MoveFailedPut, PutRefused)):
        await asyncio.wait_for(silent, 120)
    assert arcus.fields["DMOV"].value == 1
    bench.sync.served_buses["pmc007-link"].set_faults(delay=0.0)
    await asyncio.wait_for(slow, 60)


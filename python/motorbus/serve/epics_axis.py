"""One axis as an EPICS motor record (``motorbus serve``'s CA face; docs/epics.md).

The record's semantics are motorRecord.cc's, over the awaitable Drive API:

* coordinates: ``VAL = DVAL * DIR + OFF``; the dial position is the drive's position in
  the bench's user units; ``RVAL = DVAL / MRES`` (the drive's native units);
* a VAL put (DVAL, RVAL, RLV, TWF, TWR alike) posts DMOV=0 before anything moves and
  completes (put-callback) when the axis is at rest at the end of the *motion episode*:
  a second put while moving retargets (stop, then move on to the new target) and every
  pending put completes at the final rest, with one DMOV pulse 1->0->1;
* the episode's outcome decides the put: done, or interrupted by STOP/SPMG/allstop or
  by another program's stop, completes normally (record semantics, VAL:=RBV after an
  interruption); a limit switch sets HLS/LLS and fails the put; a fault, stall or
  timeout puts RBV (the record) in STATE/MAJOR alarm, sets MSTA PROBLEM (SLIP_STALL
  for a stall) and fails the put; the next successful move clears them.  The alarm
  is posted before DMOV=1, the moment ophyd judges the move;
* a target outside the soft limits sets LVIO=1, moves nothing and fails the put (a
  real IOC completes it: a deliberate difference);
* a readback task per axis posts RBV/DRBV/RRBV/MOVN/HLS/LLS/MSTA/TDIR on change, ~10 Hz
  at rest and ~50 Hz while the axis moves; motion nobody commanded here (the service's
  other face, another program) shows as MOVN=1/DMOV=0 too.

A put task cancelled by caproto (its client left) leaves the motion alone: the episode
is its own task, and puts only await it (shielded).

The calibration and settings fields are ``epics_settings.SettingsFields`` (a mixin of
``AxisRecord``); the caproto types, refusals and constants are in ``epics_types``.
"""
from __future__ import annotations

import asyncio
import logging
import math
from typing import Any, Optional

from caproto import AlarmSeverity, AlarmStatus, ChannelType, SkipWrite
from caproto.server import PVGroup, pvproperty

from .. import _core
from ..drive import Capability, LimitReached, MoveFailed, MoveInterrupted, MoveStalled
from .epics_kinds import DriveSettings
from .epics_settings import SettingsFields
from .epics_types import (JOG_WAIT, MOVING_PERIOD, MSTA_COMM_ERR, MSTA_DIRECTION, MSTA_DONE,  # noqa: F401
                          MSTA_HOMED, MSTA_MINUS_LS, MSTA_MOVING, MSTA_PLUS_LS, MSTA_POSITION, MSTA_PRESENT,
                          MSTA_PROBLEM, MSTA_SLIP_STALL, POSITION_REGISTER, PUT_NOTIFY, RESERVED, REST_PERIOD,
                          STATUS_EVERY,
                          MotorbusMotorFields, MotorVal, MoveFailedPut, PutRefused, SoftLimitViolation,
                          _enum_index, _finite, _told_by_alarm_only, check_axis_name)

log = logging.getLogger("motorbus.serve.epics")


# ---- one axis -----------------------------------------------------------------------------
class AxisRecord(SettingsFields, PVGroup):
    """``<prefix><axis>`` (motor) and ``<prefix><axis>_able`` (bo) over one ``aio.Drive``."""

    motor = pvproperty(name="", value=0.0, dtype=MotorVal, record="motor", precision=3, doc="motorbus axis")
    able = pvproperty(name="_able", value="Enable", dtype=ChannelType.ENUM, enum_strings=("Enable", "Disable"),
                      record="bo", doc="Enable/Disable the motor record's puts")

    def __init__(self, *args: Any, axis: str, drive: Any, face: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.axis = axis
        self.drive = drive
        self.face = face
        self.fields = self.motor.fields
        self.drive_settings = DriveSettings(drive)
        config = getattr(getattr(face.bench, "sync", None), "config", {})
        self.address = str(config[axis].address) if axis in config else self.drive_settings.address()
        u = drive.units
        self.scale = float(u.scale)
        self.mres = abs(self.scale)
        cal = face.calibration.get(axis)
        self.off = float(cal.get("off", 0.0))
        self.dir = int(cal.get("dir", 1))
        self.foff = int(cal.get("foff", 0))
        self._saved_limits = (cal.get("dllm"), cal.get("dhlm"))
        self.velo: Optional[float] = cal.get("velo")
        self.velo_explicit = "velo" in cal
        self.accl = float(cal.get("accl", 0.2))
        self.accl_explicit = "accl" in cal
        self.jvel: Optional[float] = cal.get("jvel")
        self.twv = float(cal.get("twv", 10 * self.mres))
        self.travel = (-math.inf, math.inf)
        self.dllm = self.dhlm = 0.0
        self.set_mode = False
        self.spmg = "Go"
        self.disabled = False
        # Readback state (dial units).
        self.drbv = 0.0
        self.rest_drbv = 0.0            # where the axis last came to rest (uncommanded moves)
        self.native = 0.0
        self.moving = False
        self.tdir = 1
        self.status: Any = None
        self.comm_error = False
        self.problem = False           # MSTA PROBLEM: the last move faulted / timed out
        self.stalled = False           # MSTA SLIP_STALL
        self.alarm_state = (AlarmStatus.NO_ALARM, AlarmSeverity.NO_ALARM)
        # The motion episode: a future every pending put awaits, the task that runs it,
        # what it is asked to do now, and a generation bumped by each new command.
        self.episode: Optional[asyncio.Future] = None
        self.runner: Optional[asyncio.Task] = None
        self.want: tuple = ("move", 0.0)
        self.generation = 0
        self.stop_requested = ""
        self.resume = asyncio.Event()
        self.external = False           # motion nobody commanded through this record
        self._seq = 0                   # bumped at each episode's end (stale readbacks)
        self.accel_applied: Optional[tuple] = None
        self._readback: Optional[asyncio.Task] = None
        self._tasks: set = set()
        f = self.fields
        for name, putter in {
            "STOP": self._put_stop, "SPMG": self._put_spmg, "HOMF": self._put_homf, "HOMR": self._put_homr,
            "JOGF": self._put_jogf, "JOGR": self._put_jogr, "TWF": self._put_twf, "TWR": self._put_twr,
            "TWV": self._put_twv, "RLV": self._put_rlv, "DVAL": self._put_dval, "RVAL": self._put_rval,
            "OFF": self._put_off, "DIR": self._put_dir, "FOFF": self._put_foff, "SET": self._put_set,
            "SSET": self._put_sset, "SUSE": self._put_suse, "HLM": self._put_hlm, "LLM": self._put_llm,
            "DHLM": self._put_dhlm, "DLLM": self._put_dllm, "VELO": self._put_velo, "ACCL": self._put_accl,
            "JVEL": self._put_jvel, "CNEN": self._put_cnen, "MRES": self._read_only, "UREV": self._read_only,
            "SREV": self._read_only, "ERES": self._read_only, "VMAX": self._read_only, "EGU": self._read_only,
            "RDBD": self._read_only, "S": self._put_s, "SYNC": self._put_sync, "DISP": self._put_disp,
        }.items():
            f[name].putter = self._guarded(name, putter)

    # ---- helpers ------------------------------------------------------------------------------
    def _guarded(self, name: str, putter: Any) -> Any:
        """A field's putter: refused while the record is disabled (``_able``), counted."""
        async def put(instance: Any, value: Any) -> Any:
            self.face.counters["puts"] += 1
            try:
                if self.disabled and name != "DISP":
                    raise PutRefused(f"{self.axis}: the record is disabled ({self.able.pvname} = Disable)")
                stored = await putter(instance, value)
                # Committed here rather than by caproto after the putter returns, so that
                # its monitor update is on its way before the put's completion.
                await instance.write(value if stored is None else stored, verify_value=False)
            except SkipWrite:
                pass
            except Exception as e:
                self.face.counters["failed_puts"] += 1
                if not _told_by_alarm_only(e):
                    self._restore_alarms_later(instance)
                    raise
            finally:
                await self.face.flush_monitors()
            raise SkipWrite()
        return put

    async def _set(self, name: str, value: Any, **metadata: Any) -> None:
        """Posts a field the server owns, only when it changed."""
        fld = self.fields[name]
        if fld.value != value or metadata:
            await fld.write(value, verify_value=False, **metadata)

    def user(self, dial: float) -> float:
        return dial * self.dir + self.off

    def dial(self, user: float) -> float:
        return (user - self.off) * self.dir

    def raw(self, dial: float) -> int:
        native = self.drive.units.to_native(dial)
        return int(round(native)) if math.isfinite(native) and abs(native) < 2**31 else 0

    def _spawn(self, coro: Any, name: str) -> asyncio.Task:
        task = asyncio.create_task(coro, name=f"motorbus-ca-{self.axis}-{name}")
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)
        return task

    def _persist(self, **values: Any) -> None:
        try:
            self.face.calibration.update(self.axis, **values)
        except Exception as e:  # noqa: BLE001 - the record goes on; the log says what was not kept
            log.warning("%s: calibration not saved: %s", self.axis, e)

    # ---- start ---------------------------------------------------------------------------------
    async def start(self) -> None:
        """Reads what the drive says (travel limits, position, status, speeds), fills the
        fields and starts the readback task."""
        d = self.drive
        try:
            self.travel = await d.travel_limits()
        except Exception as e:  # noqa: BLE001 - a drive that cannot say has none we know of
            log.info("%s: travel limits unread (%s): none assumed", self.axis, e)
        lo, hi = self.travel
        dllm, dhlm = self._saved_limits
        # Where the drive has no travel limit, the range of a 32-bit position register: a
        # real bound, and clients that test targets against HLM/LLM (pyepics' Motor refuses
        # every target but 0 when both are 0) move out of the box.
        reach = abs(d.units.to_user(float(POSITION_REGISTER)))
        self.dllm = float(dllm) if dllm is not None else (lo if math.isfinite(lo) else -reach)
        self.dhlm = float(dhlm) if dhlm is not None else (hi if math.isfinite(hi) else reach)
        self._clamp_limits()
        speed, vmax = await self.drive_settings.speeds()
        if self.velo is None:
            self.velo = speed if speed else max(self.mres * 1000.0, 1e-9)
        if self.jvel is None:
            self.jvel = self.velo
        self.vmax = vmax or 0.0
        f = self.fields
        egu = d.units.name[:15]
        prec = max(0, min(9, int(math.ceil(-math.log10(self.mres))) if self.mres < 1 else 0))
        for fld in f.values():
            if hasattr(fld, "precision"):
                fld._data["precision"] = prec
        self.motor._data["precision"] = prec
        await f["PREC"].write(prec, verify_value=False)
        for name in ("VAL", "RBV", "DVAL", "DRBV", "HLM", "LLM", "DHLM", "DLLM", "OFF", "TWV", "RLV", "RDBD",
                     "MRES", "ERES", "DIFF", "LVAL", "LDVL"):
            fld = self.motor if name == "VAL" else f[name]
            fld._data["units"] = egu
        for name in ("VELO", "VMAX", "VBAS", "JVEL", "HVEL", "BVEL"):
            f[name]._data["units"] = f"{egu}/sec"
        f["JAR"]._data["units"] = f"{egu}/s/s"
        for name in ("ACCL", "BACC"):
            f[name]._data["units"] = "sec"
        f["UREV"]._data["units"] = f"{egu}/rev"
        await f["EGU"].write(egu, verify_value=False)
        # DESC reads the VAL channel's doc (caproto links them).
        self.motor.__doc__ = f"{d.kind} {self.address}"[:40]
        await f["DESC"].write(self.motor.__doc__, verify_value=False)
        await f["MRES"].write(self.mres, verify_value=False)
        await f["ERES"].write(self.mres, verify_value=False)
        await f["RRES"].write(1.0, verify_value=False)
        await f["SREV"].write(200, verify_value=False)
        await f["UREV"].write(self.mres * 200, verify_value=False)
        await f["RDBD"].write(max(self.mres, await self.drive_settings.deadband()), verify_value=False)
        await f["VMAX"].write(self.vmax, verify_value=False)
        await f["VBAS"].write(0.0, verify_value=False)
        await f["VELO"].write(self.velo, verify_value=False, upper_ctrl_limit=self.vmax, lower_ctrl_limit=0.0)
        await f["S"].write(self.velo / (self.mres * 200), verify_value=False)
        await f["ACCL"].write(self.accl, verify_value=False)
        await f["JVEL"].write(self.jvel, verify_value=False)
        await f["HVEL"].write(self.velo, verify_value=False)
        await f["TWV"].write(self.twv, verify_value=False)
        await f["DIR"].write("Neg" if self.dir < 0 else "Pos", verify_value=False)
        await f["FOFF"].write("Frozen" if self.foff else "Variable", verify_value=False)
        await f["SET"].write("Use", verify_value=False)
        await f["SPMG"].write("Go", verify_value=False)
        await f["LSPG"].write("Go", verify_value=False)
        await f["OFF"].write(self.off, verify_value=False)
        await f["LVIO"].write(0, verify_value=False)      # caproto's default is 1 (gotcha 9)
        await f["DMOV"].write(1, verify_value=False)
        await f["CNEN"].write("Enable", verify_value=False)
        await f["OUT"].write(f"motorbus {d.kind} {self.address}"[:39], verify_value=False)
        await f["DTYP"].write(0, verify_value=False)
        await f["HLSV"].write("NO_ALARM", verify_value=False)
        await self._post_limits()
        await self._read_once(post=True)
        await self._sync_targets()
        await f["UDF"].write(0, verify_value=False)
        await self._alarm(AlarmStatus.NO_ALARM, AlarmSeverity.NO_ALARM)     # SEVR/STAT as enum strings
        self._readback = self._spawn(self._readback_loop(), "readback")

    async def shutdown(self) -> None:
        for task in list(self._tasks):
            task.cancel()
        for task in list(self._tasks):
            try:
                await task
            except (asyncio.CancelledError, Exception):  # noqa: BLE001 - closing
                pass
        if self.episode is not None and not self.episode.done():
            self.episode.set_exception(PutRefused(f"{self.axis}: the CA face closed"))

    # ---- readback ------------------------------------------------------------------------------
    async def _read_once(self, post: bool = True, full: bool = True) -> None:
        """Position and status from the drive (``full=False``: the status only when the
        position moved, or when the last one is too old)."""
        d = self.drive
        seq = self._seq
        try:
            pos = await d.position()
            fresh = full or pos != self.drbv or self.status is None
            st = await d.status() if fresh else None
            if seq != self._seq:
                # The episode ended while this read was on its way: its "moving" is older
                # than the rest the episode saw (it would start a spurious DMOV pulse).
                return
        except Exception as e:  # noqa: BLE001 - a link problem shows as COMM_ERR, the loop goes on
            self.face.counters["readback_errors"] += 1
            if not self.comm_error:
                log.warning("%s: readback failed: %s", self.axis, e)
            self.comm_error = True
            if post:
                await self._set("MSTA", float(self._msta()))
            return
        self.comm_error = False
        native = d.units.to_native(pos)
        if self.moving or (st is not None and st.moving):
            if native > self.native:
                self.tdir = 1
            elif native < self.native:
                self.tdir = 0
        self.drbv, self.native = pos, native
        if st is not None:          # "moving" only from a status read now, never a kept one
            self.moving, self.status = bool(st.moving), st
        if post:
            await self._post_readback()

    def _at_rest(self, pos: float) -> None:
        native = self.drive.units.to_native(pos)
        if native != self.native:
            self.tdir = int(native > self.native)
        self.drbv, self.native, self.moving = pos, native, False

    def _switches(self) -> tuple[int, int]:
        """(RHLS, RLLS): the dial-sense switches (the drive's native + is dial + unless the
        bench's units scale is negative)."""
        st = self.status
        if st is None:
            return (0, 0)
        plus, minus = int(bool(st.limit_positive)), int(bool(st.limit_negative))
        return (plus, minus) if self.scale > 0 else (minus, plus)

    def _msta(self) -> int:
        st = self.status
        rhls, rlls = self._switches()
        bits = 0
        if self.tdir:
            bits |= MSTA_DIRECTION
        if not self.moving:
            bits |= MSTA_DONE
        if rhls:
            bits |= MSTA_PLUS_LS
        if rlls:
            bits |= MSTA_MINUS_LS
        if Capability.ENCODER in self.drive.capabilities:
            bits |= MSTA_POSITION | MSTA_PRESENT
        if self.stalled:
            bits |= MSTA_SLIP_STALL
        if self.problem or (st is not None and st.fault):
            bits |= MSTA_PROBLEM
        if self.moving:
            bits |= MSTA_MOVING
        if self.comm_error:
            bits |= MSTA_COMM_ERR
        if st is not None and st.homed:
            bits |= MSTA_HOMED
        return bits

    async def _post_readback(self) -> None:
        rhls, rlls = self._switches()
        hls, lls = (rhls, rlls) if self.dir > 0 else (rlls, rhls)
        rbv = self.user(self.drbv)
        raw = int(round(self.native)) if math.isfinite(self.native) and abs(self.native) < 2**31 else 0
        await self._set("DRBV", self.drbv)
        await self._set("RRBV", raw)
        await self._set("RMP", raw)
        await self._set("REP", raw)
        await self._set("RHLS", rhls)
        await self._set("RLLS", rlls)
        await self._set("HLS", hls)
        await self._set("LLS", lls)
        await self._set("TDIR", self.tdir)
        await self._set("MOVN", int(self.moving))
        await self._set("MSTA", float(self._msta()))
        await self._set("ATHM", 0)
        if self.status is not None:
            await self._set("CNEN", "Enable" if self.status.enabled else "Disable")
        dval = self.fields["DVAL"].value
        await self._set("DIFF", dval - self.drbv)
        await self._set("RDIF", self.raw(dval) - raw)
        await self._set("RBV", rbv)

    async def _readback_loop(self) -> None:
        n = 0
        while True:
            busy = self.moving or (self.episode is not None and not self.episode.done())
            await asyncio.sleep(MOVING_PERIOD if busy else REST_PERIOD)
            n += 1
            try:
                # At rest the status (several exchanges on most kinds) is read every
                # STATUS_EVERY periods, or at once when the position changed: a bench of
                # many axes on one line leaves room for the commands.
                await self._read_once(full=busy or n % STATUS_EVERY == 0)
                await self._uncommanded()
            except Exception:  # noqa: BLE001 - the readback must go on whatever happened
                log.exception("%s: readback", self.axis)

    async def _uncommanded(self) -> None:
        """Motion nobody commanded through this record (the service's other face, another
        program, a stop input's ramp): MOVN=1/DMOV=0 while it lasts, VAL := RBV at rest."""
        if self.episode is not None and not self.episode.done() or self.comm_error:
            return
        if self.moving and not self.external:
            self.external = True
            await self._dmov(0)
        elif self.external and not self.moving:
            self.external = False
            await self._sync_targets()
            await self._dmov(1)
        elif not self.moving and abs(self.drbv - self.rest_drbv) > max(self.mres, self.fields["RDBD"].value):
            # A move shorter than a readback period: never seen moving, but it moved.
            await self._sync_targets()

    async def _dmov(self, value: int) -> None:
        await self._set("DMOV", value)
        await self._set("MIP", 0 if value else 1)
        await self.face._dmov_changed()

    async def _sync_targets(self) -> None:
        """VAL := RBV, DVAL := DRBV, RVAL := RRBV (and the last-value fields)."""
        self.rest_drbv = self.drbv
        await self._post_targets(self.drbv)

    async def _post_targets(self, dial: float) -> None:
        user, raw = self.user(dial), self.raw(dial)
        if self.motor.value != user:
            await self.motor.write(user, verify_value=False)
        await self._set("DVAL", dial)
        await self._set("RVAL", raw)
        await self._set("LVAL", user)
        await self._set("LDVL", dial)
        await self._set("LRVL", raw)

    # ---- alarms --------------------------------------------------------------------------------
    async def _alarm(self, status: AlarmStatus, severity: AlarmSeverity) -> None:
        """The record's alarm: VAL's (SEVR/STAT follow it) and the fields' (RBV's)."""
        self.alarm_state = (status, severity)
        await self.motor.alarm.write(status=status, severity=severity)
        await self.fields["RBV"].alarm.write(status=status, severity=severity)

    def _restore_alarms_later(self, instance: Any) -> None:
        """caproto sets the alarm of a field whose put failed to WRITE/MAJOR (gotcha 3) --
        VAL's is the record's, every other field's is RBV's: the record's own alarm is put
        back once caproto has written its own."""
        async def restore() -> None:
            for _ in range(50):
                await asyncio.sleep(0.002)
                if instance.alarm.status == AlarmStatus.WRITE:
                    break
            await self._alarm(*self.alarm_state)
        self._spawn(restore(), "alarm")

    # ---- the motion episode ------------------------------------------------------------------
    async def command(self, what: str, arg: Any) -> asyncio.Future:
        """Starts (or retargets) the episode: ``("move", dial)``, ``("home", forward)``,
        ``("jog", +1/-1)``.  Returns the episode's future (resolved at the final rest)."""
        self.generation += 1
        self.want = (what, arg)
        self.stop_requested = ""
        if self.episode is None or self.episode.done():
            loop = asyncio.get_running_loop()
            self.episode = loop.create_future()
            self.episode.add_done_callback(lambda fut: fut.cancelled() or fut.exception())
            self.external = False
            await self._dmov(0)           # before anything moves: ophyd's MoveStatus starts here
            self.runner = self._spawn(self._run(self.episode), "episode")
        else:
            # Retarget while moving: stop, the episode goes on to the new target at rest.
            try:
                await self.drive.stop()
            except Exception as e:  # noqa: BLE001 - the runner reports what the drive says next
                log.info("%s: stop for a retarget failed: %s", self.axis, e)
        return self.episode

    async def _run(self, episode: asyncio.Future) -> None:
        """The episode: one command after another (a put while moving replaces the command
        and stops the drive: the interrupted move is followed by the new one), until the
        axis is at rest with nothing more asked; then the outcome (``_end``)."""
        try:
            while True:
                gen = self.generation
                what, arg = self.want
                error: Optional[BaseException] = None
                try:
                    await self._do(what, arg)
                except Exception as e:  # noqa: BLE001 - every failure is the episode's outcome
                    error = e
                    if not isinstance(e, (MoveFailed, _core.MotorbusError, OSError)):
                        log.exception("%s: %s %r", self.axis, what, arg)
                if self.generation != gen and not self.stop_requested:
                    continue                   # retargeted: on to the new target
                if isinstance(error, MoveInterrupted) and self.stop_requested == "SPMG" and self.spmg != "Stop":
                    await self.resume.wait()   # paused: Go/Move resumes the move to VAL
                    if self.spmg == "Stop":
                        pass                   # Stop while paused: the episode ends here
                    else:
                        self.stop_requested = ""
                        if self.want[0] == "move":   # to VAL as it is now (a put while paused moved it)
                            self.want = ("move", self.dial(self.motor.value))
                        continue
                if await self._end(episode, what, error, gen):
                    return
                # A put arrived while the episode was ending: it goes on.
        except asyncio.CancelledError:
            if not episode.done():
                episode.set_exception(PutRefused(f"{self.axis}: the CA face closed during the move"))
            raise
        except BaseException as e:
            if not episode.done():      # _end failed (a link lost while reading back): still an end
                episode.set_exception(MoveFailedPut(f"{self.axis}: the end of the move: {e}", e))
            raise

    async def _do(self, what: str, arg: Any) -> None:
        d = self.drive
        self.face.counters["moves"] += 1
        if self.status is not None and not self.status.enabled and what != "sync":
            # The motor module's auto power-on: a commanded motion enables the drive first
            # (CNEN=Disable switches it off again).
            await d.enable()
        if what == "move":
            await self._apply_accel()
            velocity = self.velo if (self.velo_explicit and self.drive_settings.velocity) else None
            distance = abs(arg - self.drbv)
            timeout = None
            if self.velo:
                timeout = max(d.sync.default_timeout, 3 * distance / self.velo + 4 * self.accl + 10.0)
            await d.move_to(arg, velocity=velocity, timeout=timeout, stop_on_cancel=False)
        elif what == "home":
            await d.home(self.drive_settings.home_method(forward=arg), stop_on_cancel=False)
        elif what == "jog":
            await d.jog(arg * self.dir * (self.jvel or self.velo or self.mres))
            await d.wait_idle(JOG_WAIT, stop_on_cancel=False)
        elif what == "sync":
            return
        else:  # pragma: no cover
            raise _core.InvalidArgument(f"unknown episode step {what!r}")

    async def _apply_accel(self) -> None:
        """ACCL (seconds to VELO) on the kind's acceleration parameters, when it changed."""
        if not self.accl_explicit:
            return
        key = (self.accl, self.velo)
        if key == self.accel_applied:
            return
        try:
            await self.drive_settings.apply_accel(self.accl, self.velo or 0.0)
            self.accel_applied = key
        except Exception as e:  # noqa: BLE001 - ACCL not honoured: the move goes on at the drive's ramp
            self.face.counters["accel_errors"] += 1
            self.accel_applied = key
            log.warning("%s: ACCL %g s not applied: %s", self.axis, self.accl, e)

    async def _end(self, episode: asyncio.Future, what: str, error: Optional[BaseException], gen: int) -> bool:
        """At the final rest: readbacks, the outcome's alarm and fields, *then* DMOV=1,
        then the pending puts complete.  False (nothing resolved) when a new command
        arrived meanwhile: the episode goes on."""
        self._seq += 1                   # readbacks already on their way are older than this rest
        last = getattr(self.drive.sync, "_last_move", None)
        kept = self.status
        clean = kept is not None and not (kept.fault or kept.limit_positive or kept.limit_negative)
        if error is None and what == "move" and last is not None and last.ok and last.position is not None \
                and clean:
            # The Drive judged the move at rest there a moment ago: no exchange before DMOV=1
            # (the readback task refreshes the status within its period).
            self._at_rest(last.position)
        else:
            await self._read_once(post=False)
        put_error: Optional[BaseException] = None
        interrupted = isinstance(error, MoveInterrupted) or (error is None and self.stop_requested)
        if error is None:
            # A successful move clears what an earlier failure left (the record recomputes
            # its alarm on every process, so it clears with its cause).
            self.problem = self.stalled = False
            if (self.alarm_state[1] != AlarmSeverity.NO_ALARM or self.motor.alarm.severity
                    or self.fields["RBV"].alarm.severity):
                await self._alarm(AlarmStatus.NO_ALARM, AlarmSeverity.NO_ALARM)
        elif isinstance(error, MoveInterrupted):
            # A deliberate difference from motorRecord.cc, which ends a stopped move as a
            # normal completion: a move cut short by STOP, allstop, SPMG Stop or another
            # program's stop did not reach its target, and every client must see that (the
            # project's rule: a move ends at its target or fails saying why).  STATE/MINOR --
            # a stop is not a fault -- is what ophyd judges at DMOV=1, and the put-callback
            # fails with the Drive API's reason; MSTA stays clean; the next good move clears it.
            self.face.counters["interrupted_moves"] += 1
            await self._alarm(AlarmStatus.STATE, AlarmSeverity.MINOR_ALARM)
            put_error = MoveFailedPut(str(error) if str(error).startswith(self.axis) else f"{self.axis}: {error}", error)
        elif isinstance(error, LimitReached):
            self.face.counters["failed_moves"] += 1
            hlsv = self.fields["HLSV"].value
            if hlsv and hlsv != "NO_ALARM":
                side_high = (error.side > 0) == (self.scale > 0) == (self.dir > 0)
                sev = AlarmSeverity(["NO_ALARM", "MINOR", "MAJOR", "INVALID"].index(hlsv))
                await self._alarm(AlarmStatus.HIGH if side_high else AlarmStatus.LOW, sev)
            put_error = MoveFailedPut(str(error) if str(error).startswith(self.axis) else f"{self.axis}: {error}", error)
        else:
            self.face.counters["failed_moves"] += 1
            if isinstance(error, MoveStalled):
                self.stalled = True
                self.problem = True
                await self._alarm(AlarmStatus.STATE, AlarmSeverity.MAJOR_ALARM)
            elif isinstance(error, MoveFailed):      # MoveFaulted, MoveTimedOut, a kind's own
                self.problem = True
                await self._alarm(AlarmStatus.STATE, AlarmSeverity.MAJOR_ALARM)
            else:       # the link: LinkDown, a closed drive, a drive's refusal
                self.problem = True
                status = AlarmStatus.COMM if isinstance(error, (_core.LinkDown, _core.TimeoutError)) \
                    else AlarmStatus.STATE
                await self._alarm(status, AlarmSeverity.MAJOR_ALARM)
            put_error = MoveFailedPut(str(error) if str(error).startswith(self.axis) else f"{self.axis}: {error}", error)
        await self._post_readback()
        if self.generation != gen:
            return False
        if what != "move" or interrupted or put_error is not None:
            await self._sync_targets()       # VAL := RBV (STOP, homing, jog, a failed move)
        if what == "home":
            await self._set("HOMF", 0)
            await self._set("HOMR", 0)
        if what == "jog":
            await self._set("JOGF", 0)
            await self._set("JOGR", 0)
        if self.generation != gen:
            return False
        if self.spmg == "Move":
            self.spmg = "Pause"
            self.resume.clear()
            await self._set("SPMG", "Pause")
        self.rest_drbv = self.drbv
        await self._dmov(1)
        if not episode.done():
            if put_error is None:
                episode.set_result(None)
            else:
                episode.set_exception(put_error)
        return True

    async def _await_episode(self, episode: asyncio.Future) -> None:
        """A put waits for the episode's end; shielded: a put cancelled by caproto (its
        client gone) leaves the motion alone, as a real IOC does.  A plain put (no
        put-callback) does not wait: nobody waits for its answer, and a write in flight
        would hold back every read on its circuit (caproto's write lock)."""
        if PUT_NOTIFY.get() is False:
            return
        await asyncio.shield(episode)

    async def stop_axis(self, by: str = "STOP") -> None:
        """STOP / allstop / SPMG Stop|Pause: the drive's stop at once; the episode ends at
        rest as interrupted (STATE/MINOR and a failed put-callback) with VAL := RBV."""
        self.face.counters["stops"] += 1
        self.stop_requested = by
        try:
            # ``by`` names the record in the outcome every program reads (drive.stopped_by_text)
            await self.drive.sync._co_stop(by=f"{by} of the EPICS record {self.prefix}")
        except Exception as e:  # noqa: BLE001 - nothing more to do from here; the readback shows the rest
            log.warning("%s: stop failed: %s", self.axis, e)
        if self.episode is None or self.episode.done():
            # At rest: the record syncs its targets (cc 1856-1910), with a DMOV pulse.
            await self._read_once()
            await self._sync_targets()

    # ---- VAL and the moves -----------------------------------------------------------------------
    @motor.putter
    async def motor(self, instance: Any, value: Any) -> Any:
        self.face.counters["puts"] += 1
        try:
            if self.disabled:
                raise PutRefused(f"{self.axis}: the record is disabled ({self.able.pvname} = Disable)")
            value = _finite(value, f"{self.axis}.VAL")
            await self._move_user(value)
        except SkipWrite:
            raise
        except Exception as e:
            self.face.counters["failed_puts"] += 1
            if _told_by_alarm_only(e):
                raise SkipWrite() from None
            self._restore_alarms_later(instance)
            raise
        finally:
            await self.face.flush_monitors()
        raise SkipWrite()

    async def _move_user(self, value: float) -> None:
        """A VAL put: calibration in SET mode, else a move (put-completion at the end)."""
        if self.set_mode and not self.fields["IGSET"].value:
            await self._calibrate(value)
            return
        await self._move_dial(self.dial(value))

    async def _move_dial(self, dial: float) -> None:
        if self.spmg == "Stop":
            # Stop mode refuses motion: the put completes, nothing moves, VAL := RBV.
            await self._dmov(0)
            await self._sync_targets()
            await self._dmov(1)
            return
        if self.violates(dial):
            await self._set("LVIO", 1)
            await self._dmov(0)
            await self._dmov(1)
            llm, hlm = self.user_limits()
            raise SoftLimitViolation(f"{self.axis}: target {self.user(dial):g} is outside the soft limits "
                                     f"[{llm:g}, {hlm:g}] (LVIO): nothing moved")
        # Reserved now: an episode ending meanwhile sees a command coming and goes on.
        self.generation += 1
        await self._set("LVIO", 0)
        await self._post_targets(dial)
        if self.spmg == "Pause":
            return                      # stored; Go moves there
        episode = await self.command("move", dial)
        await self._await_episode(episode)

    async def _put_dval(self, instance: Any, value: Any) -> Any:
        dial = _finite(value, f"{self.axis}.DVAL")
        if self.set_mode:
            raise PutRefused(f"{self.axis}: DVAL in SET mode would load the drive's position register, which "
                             "motorbus does not do: calibrate with VAL (the offset absorbs it)")
        await self._move_dial(dial)
        raise SkipWrite()

    async def _put_rval(self, instance: Any, value: Any) -> Any:
        if self.set_mode:
            raise PutRefused(f"{self.axis}: RVAL in SET mode would load the drive's position register, which "
                             "motorbus does not do: calibrate with VAL (the offset absorbs it)")
        await self._move_dial(self.drive.units.to_user(_finite(value, f"{self.axis}.RVAL")))
        raise SkipWrite()

    async def _put_rlv(self, instance: Any, value: Any) -> Any:
        rel = _finite(value, f"{self.axis}.RLV")
        await instance.write(rel, verify_value=False)
        await self._move_user(self.motor.value + rel)
        await instance.write(0.0, verify_value=False)
        raise SkipWrite()

    async def _tweak(self, instance: Any, value: Any, sign: int) -> Any:
        if not value:
            return 0
        await instance.write(0, verify_value=False)     # TWF/TWR read back 0 at once
        await self._move_user(self.motor.value + sign * self.twv)
        raise SkipWrite()

    async def _put_twf(self, instance: Any, value: Any) -> Any:
        return await self._tweak(instance, value, 1)

    async def _put_twr(self, instance: Any, value: Any) -> Any:
        return await self._tweak(instance, value, -1)

    async def _put_twv(self, instance: Any, value: Any) -> Any:
        self.twv = _finite(value, f"{self.axis}.TWV")
        self._persist(twv=self.twv)
        return self.twv

    async def _put_stop(self, instance: Any, value: Any) -> Any:
        if value:
            await self.stop_axis("STOP")
        return 0

    async def _put_spmg(self, instance: Any, value: Any) -> Any:
        strings = ("Stop", "Pause", "Move", "Go")
        mode = strings[_enum_index(value, strings)]
        await self._set("LSPG", self.spmg)
        old, self.spmg = self.spmg, mode
        active = self.episode is not None and not self.episode.done()
        if mode in ("Stop", "Pause"):
            self.resume.clear()
            if active or self.moving:
                await self.stop_axis("SPMG")
            if mode == "Stop" and active:
                self.resume.set()          # a paused episode ends (Stop refuses motion)
        elif old in ("Pause", "Stop") or not active:
            if active:
                self.resume.set()          # the paused move resumes toward VAL
            elif abs(self.dial(self.motor.value) - self.drbv) > self.mres and old == "Pause":
                # A target stored while paused: go there now (no put waits for it).
                self._spawn(self._go_to_val(), "go")
        return mode

    async def _go_to_val(self) -> None:
        try:
            episode = await self.command("move", self.dial(self.motor.value))
            await asyncio.shield(episode)
        except (PutRefused, MoveFailed, _core.MotorbusError):
            pass

    async def _home(self, instance: Any, value: Any, forward: bool) -> Any:
        if value != 1:
            raise PutRefused(f"{self.axis}: {'HOMF' if forward else 'HOMR'} takes 1 (start the homing), "
                             f"not {value!r}")
        if self.episode is not None and not self.episode.done():
            if self.want[0] == "home":
                raise PutRefused(f"{self.axis}: a homing is already running")
            await self.stop_axis("HOME")
        await instance.write(1, verify_value=False)
        episode = await self.command("home", forward)
        await self._set("LVIO", 0)
        await self._await_episode(episode)     # the episode's end reads HOMF/HOMR 0
        raise SkipWrite()

    async def _put_homf(self, instance: Any, value: Any) -> Any:
        return await self._home(instance, value, True)

    async def _put_homr(self, instance: Any, value: Any) -> Any:
        return await self._home(instance, value, False)

    async def _jog(self, instance: Any, value: Any, sign: int) -> Any:
        if value:
            if self.spmg in ("Stop", "Pause"):
                raise PutRefused(f"{self.axis}: SPMG is {self.spmg}: no motion")
            await instance.write(1, verify_value=False)
            await self.command("jog", sign)
            raise SkipWrite()       # the jog runs until 0 (or a stop); this put completes now
        if self.episode is not None and not self.episode.done() and self.want[0] == "jog":
            await self.stop_axis("JOG")
            await asyncio.shield(self.episode)
        return 0

    async def _put_jogf(self, instance: Any, value: Any) -> Any:
        return await self._jog(instance, value, 1)

    async def _put_jogr(self, instance: Any, value: Any) -> Any:
        return await self._jog(instance, value, -1)

    @able.putter
    async def able(self, instance: Any, value: Any) -> Any:
        strings = ("Enable", "Disable")
        idx = _enum_index(value, strings)
        self.disabled = bool(idx)
        await self._set("DISP", idx)
        return strings[idx]


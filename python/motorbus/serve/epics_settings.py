"""The motor record's calibration and settings fields (``motorbus serve``'s CA face):
soft limits (DHLM/DLLM inside the drive's travel limits, HLM/LLM their user images),
OFF/DIR/FOFF/SET calibration (kept in the calibration file), VELO/S/ACCL/JVEL, CNEN,
SYNC, DISP and the read-only fields.  A mixin of ``epics_axis.AxisRecord``, whose state
(``self.off``, ``self.dir``, ``self.dhlm``...) it reads and writes.
"""
from __future__ import annotations

import math
from typing import Any

from caproto import SkipWrite

from .. import _core
from .epics_types import PutRefused, _enum_index, _finite


class SettingsFields:
    """The settings putters and the limit logic of an ``AxisRecord`` (see the module doc)."""

    # ---- limits --------------------------------------------------------------------------------
    def _clamp_limits(self) -> None:
        """DHLM/DLLM inside the drive's travel limits (a side the drive does not limit is
        free; DHLM = DLLM = 0, the record's "no soft limits", stays so)."""
        lo, hi = self.travel
        if self.dhlm == 0.0 and self.dllm == 0.0:
            return
        if math.isfinite(hi):
            self.dhlm, self.dllm = min(self.dhlm, hi), min(self.dllm, hi)
        if math.isfinite(lo):
            self.dllm, self.dhlm = max(self.dllm, lo), max(self.dhlm, lo)

    def user_limits(self) -> tuple[float, float]:
        """(LLM, HLM) from (DLLM, DHLM): DIR=Neg swaps them."""
        a, b = self.user(self.dllm), self.user(self.dhlm)
        return (min(a, b), max(a, b))

    async def _post_limits(self) -> None:
        llm, hlm = self.user_limits()
        f = self.fields
        await self._set("DHLM", self.dhlm)
        await self._set("DLLM", self.dllm)
        await self._set("HLM", hlm)
        await self._set("LLM", llm)
        md = dict(upper_ctrl_limit=hlm, lower_ctrl_limit=llm, upper_disp_limit=hlm, lower_disp_limit=llm)
        await self.motor.write_metadata(**md)
        await f["RBV"].write_metadata(**md)
        dmd = dict(upper_ctrl_limit=self.dhlm, lower_ctrl_limit=self.dllm, upper_disp_limit=self.dhlm,
                   lower_disp_limit=self.dllm)
        await f["DVAL"].write_metadata(**dmd)
        await f["DRBV"].write_metadata(**dmd)
        await self._set("HOPR", hlm)
        await self._set("LOPR", llm)

    def violates(self, dial: float) -> bool:
        """The record's soft-limit test (cc 2396-2445): none when DHLM == DLLM == 0; always
        when DLLM > DHLM; otherwise a target outside, unless it moves back toward the range."""
        if self.dhlm == 0.0 and self.dllm == 0.0:
            return False
        if self.dllm > self.dhlm:
            return True
        if dial > self.dhlm:
            return not (self.drbv > self.dhlm and dial < self.drbv)
        if dial < self.dllm:
            return not (self.drbv < self.dllm and dial > self.drbv)
        return False


    async def _calibrate(self, value: float) -> None:
        """SET mode: the VAL put changes the calibration, nothing moves (a DMOV pulse)."""
        await self._dmov(0)
        try:
            if self.foff:
                raise PutRefused(f"{self.axis}: SET with FOFF=Frozen would load the drive's position register, "
                                 "which motorbus does not do: set FOFF=Variable (the offset absorbs it)")
            await self._read_once(post=False)
            self.off = value - self.drbv * self.dir
            self._persist(off=self.off)
            await self._set("OFF", self.off)
            await self._post_limits()
            await self._post_targets(self.drbv)
            await self._post_readback()
        finally:
            await self._dmov(1)

    # ---- calibration and settings ---------------------------------------------------------------
    async def _recalibrated(self) -> None:
        await self._post_limits()
        await self._post_targets(self.fields["DVAL"].value)
        await self._post_readback()

    async def _put_off(self, instance: Any, value: Any) -> Any:
        self.off = _finite(value, f"{self.axis}.OFF")
        self._persist(off=self.off)
        await instance.write(self.off, verify_value=False)
        await self._recalibrated()
        raise SkipWrite()

    async def _put_dir(self, instance: Any, value: Any) -> Any:
        strings = ("Pos", "Neg")
        new = -1 if _enum_index(value, strings) else 1
        if new != self.dir:
            # motorRecord.cc's DIR special: FOFF=Variable keeps VAL (OFF absorbs the sign
            # change), FOFF=Frozen keeps OFF (VAL and RBV change sign around it).
            self.dir = new
            if not self.foff:
                self.off = self.motor.value - self.fields["DVAL"].value * self.dir
            self._persist(dir=self.dir, off=self.off)
            await self._set("OFF", self.off)
        await instance.write(strings[0 if new > 0 else 1], verify_value=False)
        await self._recalibrated()
        raise SkipWrite()

    async def _put_foff(self, instance: Any, value: Any) -> Any:
        strings = ("Variable", "Frozen")
        self.foff = _enum_index(value, strings)
        self._persist(foff=self.foff)
        return strings[self.foff]

    async def _put_set(self, instance: Any, value: Any) -> Any:
        strings = ("Use", "Set")
        self.set_mode = bool(_enum_index(value, strings))
        return strings[int(self.set_mode)]

    async def _put_sset(self, instance: Any, value: Any) -> Any:
        if value:
            self.set_mode = True
            await self._set("SET", "Set")
        return 0

    async def _put_suse(self, instance: Any, value: Any) -> Any:
        if value:
            self.set_mode = False
            await self._set("SET", "Use")
        return 0

    async def _user_limit(self, value: Any, high: bool) -> None:
        v = self.dial(_finite(value, f"{self.axis}.{'HLM' if high else 'LLM'}"))
        if high == (self.dir > 0):
            self.dhlm = v
        else:
            self.dllm = v
        await self._limits_changed()

    async def _limits_changed(self) -> None:
        self._clamp_limits()
        self._persist(dhlm=self.dhlm, dllm=self.dllm)
        await self._post_limits()
        # VAL outside the new limits sets LVIO (the record's check on a limit change).
        await self._set("LVIO", int(self.violates(self.dial(self.motor.value))))

    async def _put_hlm(self, instance: Any, value: Any) -> Any:
        await self._user_limit(value, True)
        raise SkipWrite()

    async def _put_llm(self, instance: Any, value: Any) -> Any:
        await self._user_limit(value, False)
        raise SkipWrite()

    async def _put_dhlm(self, instance: Any, value: Any) -> Any:
        self.dhlm = _finite(value, f"{self.axis}.DHLM")
        await self._limits_changed()
        raise SkipWrite()

    async def _put_dllm(self, instance: Any, value: Any) -> Any:
        self.dllm = _finite(value, f"{self.axis}.DLLM")
        await self._limits_changed()
        raise SkipWrite()

    async def _put_velo(self, instance: Any, value: Any) -> Any:
        v = _finite(value, f"{self.axis}.VELO")
        if v <= 0:
            raise PutRefused(f"{self.axis}.VELO: a speed > 0 {self.drive.units.name}/s, not {v!r}")
        if self.vmax and v > self.vmax:
            v = self.vmax                # the record clamps VELO to [VBAS, VMAX]
        self.velo, self.velo_explicit = v, True
        self._persist(velo=v)
        await self._set("S", v / (self.mres * 200))
        return v

    async def _put_s(self, instance: Any, value: Any) -> Any:
        s = _finite(value, f"{self.axis}.S")
        await self._put_velo(self.fields["VELO"], s * self.mres * 200)
        await self._set("VELO", self.velo)
        return self.velo / (self.mres * 200)

    async def _put_accl(self, instance: Any, value: Any) -> Any:
        a = _finite(value, f"{self.axis}.ACCL")
        if a <= 0:
            raise PutRefused(f"{self.axis}.ACCL: seconds to VELO > 0, not {a!r}")
        self.accl, self.accl_explicit = a, True
        self._persist(accl=a)
        return a

    async def _put_jvel(self, instance: Any, value: Any) -> Any:
        v = _finite(value, f"{self.axis}.JVEL")
        if v <= 0:
            raise PutRefused(f"{self.axis}.JVEL: a speed > 0, not {v!r}")
        self.jvel = v
        self._persist(jvel=v)
        return v

    async def _put_cnen(self, instance: Any, value: Any) -> Any:
        strings = ("Disable", "Enable")
        on = _enum_index(value, strings)
        try:
            if on:
                # A latched fault keeps most drives from enabling: CNEN=Enable is the
                # record's way to reset one (the motor record has no reset field).
                if self.status is not None and self.status.fault:
                    await self.drive.clear_faults()
                await self.drive.enable()
            else:
                await self.drive.disable()
        except (_core.MotorbusError, OSError) as e:
            raise PutRefused(f"{self.axis}: CNEN={strings[on]}: {e}") from None
        await self._read_once()          # the fault it cleared, the state it set
        return strings[on]

    async def _put_sync(self, instance: Any, value: Any) -> Any:
        if value:
            await self._read_once()
            await self._sync_targets()
        return 0

    async def _put_disp(self, instance: Any, value: Any) -> Any:
        self.disabled = bool(value)
        await self._set_able("Disable" if self.disabled else "Enable")
        return value

    async def _set_able(self, text: str) -> None:
        if self.able.value != text:
            await self.able.write(text, verify_value=False)

    async def _read_only(self, instance: Any, value: Any) -> Any:
        name = instance.pvspec.name
        raise PutRefused(f"{self.axis}.{name}: set by the bench file (units, kind) and the drive, not over CA")

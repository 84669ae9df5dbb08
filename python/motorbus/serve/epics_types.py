"""The caproto types and the small vocabulary of ``motorbus serve``'s CA face
(``epics_axis.AxisRecord`` uses them; docs/epics.md): the motor record's field class
(RTYP "motor", MSTA sent as DOUBLE), VAL's channel class, the put refusals and their
answer to plain puts, the axis-name check, the MSTA bits and the periods.
"""
from __future__ import annotations

import contextvars
import math
from typing import Any

from caproto.server import pvproperty
from caproto.server.records import MotorFields, register_record
from caproto.server.server import PvpropertyDouble, PvpropertyDoubleRO

from .. import _core

#: PV names of the bench-wide records: no axis may take them.
RESERVED = ("allstop", "alldone", "moving")

#: Readback periods (s): at rest, and while a move is in flight.
REST_PERIOD = 0.1
MOVING_PERIOD = 0.02
#: At rest, the status is read every this many periods (and whenever the position moved).
STATUS_EVERY = 3
#: MSTA bits (motorRecord.html, "MSTA": bit = item - 1).
MSTA_DIRECTION, MSTA_DONE, MSTA_PLUS_LS, MSTA_HOMELS = 1 << 0, 1 << 1, 1 << 2, 1 << 3
MSTA_POSITION, MSTA_SLIP_STALL, MSTA_HOME, MSTA_PRESENT = 1 << 5, 1 << 6, 1 << 7, 1 << 8
MSTA_PROBLEM, MSTA_MOVING, MSTA_GAIN_SUPPORT, MSTA_COMM_ERR = 1 << 9, 1 << 10, 1 << 11, 1 << 12
MSTA_MINUS_LS, MSTA_HOMED = 1 << 13, 1 << 14
#: The soft limits of a drive with no travel limit: a 32-bit position register's range (native units).
POSITION_REGISTER = 2**31 - 1
#: A jog runs until JOGF/JOGR=0 (or a stop): its wait for rest has no useful timeout.
JOG_WAIT = 30 * 86400.0


class PutRefused(_core.MotorbusError):
    """A put the record refuses or a move it reports as failed: caproto answers the
    client ECA_PUTFAIL with this message."""


class SoftLimitViolation(PutRefused, _core.InvalidArgument):
    """The target is outside the record's soft limits (LVIO=1, nothing moved)."""


class MoveFailedPut(PutRefused):
    """The move ended in a failure (``error``: the Drive API's MoveFailed or drive error)."""

    def __init__(self, message: str, error: BaseException) -> None:
        super().__init__(message)
        self.error = error


#: Whether the put being served is a put-callback (WriteNotify: True) or a plain put
#: (False); None outside a CA circuit (a test awaiting a putter). Set by the CA face's
#: circuit for each write task.
PUT_NOTIFY: contextvars.ContextVar = contextvars.ContextVar("motorbus_ca_put_notify", default=None)


def _told_by_alarm_only(error: BaseException) -> bool:
    """A refused target or a failed move answered to a *plain* put: nobody waits for that
    put, a real record completes it, and libca would print a warning block for an error
    answer; the record's fields (LVIO, HLS/LLS, the alarm) say what happened."""
    return isinstance(error, (SoftLimitViolation, MoveFailedPut)) and PUT_NOTIFY.get() is False


def check_axis_name(name: str, names: Any = ()) -> None:
    """An axis name usable as a PV name: no clash with the bench-wide records or another
    axis's ``_able``, and only characters a record name may hold."""
    if name in RESERVED:
        raise _core.InvalidArgument(f"CA face: axis {name!r} clashes with the bench-wide record "
                                    f"<prefix>{name} ({', '.join(RESERVED)} are taken)")
    if name.endswith("_able") and name[:-len("_able")] in names:
        raise _core.InvalidArgument(f"CA face: axis {name!r} clashes with the _able record of axis "
                                    f"{name[:-len('_able')]!r}")
    if not name or any(not (c.isalnum() or c in "_-:;<>[]") for c in name):
        raise _core.InvalidArgument(f"CA face: axis {name!r}: a record name holds letters, digits and _-:;<>[] only")


# ---- the record's caproto types ---------------------------------------------------------
@register_record
class MotorbusMotorFields(MotorFields):
    """caproto's motor fields with what the real record sends: RTYP stays "motor" (pyepics
    refuses anything else), MSTA is a ULONG in the record, which CA sends as DOUBLE."""

    _record_type = "motor"
    motor_status = pvproperty(name="MSTA", dtype=PvpropertyDoubleRO, read_only=True, doc="Motor Status")


class MotorVal(PvpropertyDouble):
    """VAL: HLM/LLM are its control limits (as in the record), but caproto would refuse an
    out-of-limit put before the putter runs (gotcha 1): the putter is the judge (LVIO)."""

    async def verify_value(self, value: Any) -> Any:
        if self.putter is not None:
            return await self.putter(self, value)
        return value


def _finite(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise PutRefused(f"{what}: a finite number, not {value!r}")
    return float(value)


def _enum_index(value: Any, strings: tuple) -> int:
    if isinstance(value, str):
        if value in strings:
            return strings.index(value)
        raise PutRefused(f"one of {', '.join(strings)}, not {value!r}")
    return int(value)


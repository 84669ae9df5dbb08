"""Motion profiles: plan, preview and sample moves (the generic planners; each vendor's own
profile model is in its module, ``motorbus.drives.<vendor>``).

Planners return a :class:`Profile`; ``Profile.sample(n)`` gives an ``n x 5`` numpy
array (t, p, v, a, j) ready to plot, and ``Profile.step_times()`` the exact
integer step times (ns) of a stepper following it.

>>> from motorbus import motion
>>> p = motion.plan(1000, max_velocity=100, max_acceleration=1000)
>>> round(p.duration, 6)
10.1
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np

from ._core import InvalidArgument, LimitExceeded  # noqa: F401
from ._core.motion import (  # noqa: F401
    Cia402Homing, Cia402HomingParams, Cia402ProfileParams, Cia402ProfilePosition, Limits, MotionState, MotorConfig,
    MotorEvent, MotorEventKind, MotorModel, Profile, RampShape, SnlActivity, SnlConfig, StepNLoop, SwitchConfig,
    cia402_position_profile, cia402_quick_stop_profile, cia402_velocity_profile, jerk_limited_durations,
    plan_jerk_limited, plan_jerk_limited_velocity, plan_straight_line, plan_synchronized,
    plan_synchronized_jerk_limited, plan_trapezoid, plan_velocity, split_interpolation,
    synchronized_jerk_limited_durations,
)

# Only what every drive can use lives here: planners, profiles, steps, multi-axis,
# the motor model, StepNLoop and the CiA 402 profile/homing (a standard, not a vendor).
# A vendor's own profile model (and anything named after its protocol) is in its
# module, motorbus.drives.<vendor>, which imports it from _core itself.
__all__ = [
    "Cia402Homing", "Cia402HomingParams", "Cia402ProfileParams", "Cia402ProfilePosition", "LimitExceeded",
    "Limits", "MotionState", "MotorConfig", "MotorEvent", "MotorEventKind", "MotorModel", "Profile", "RampShape",
    "SnlActivity", "SnlConfig", "StepNLoop", "SwitchConfig", "cia402_position_profile", "cia402_quick_stop_profile",
    "cia402_velocity_profile", "jerk_limited_durations", "plan", "plan_jerk_limited", "plan_jerk_limited_velocity",
    "plan_straight_line", "plan_synchronized", "plan_synchronized_jerk_limited", "plan_trapezoid", "plan_velocity",
    "sample", "split_interpolation", "step_times", "synchronized_jerk_limited_durations",
]

_SHAPES = {"trapezoid": RampShape.TRAPEZOID, "s_curve": RampShape.SCURVE, "scurve": RampShape.SCURVE,
           "sin2": RampShape.SIN2}


def _shape(shape: str | RampShape) -> RampShape:
    if isinstance(shape, RampShape):
        return shape
    # InvalidArgument (a ValueError too): None or a number is a wrong argument like a wrong name.
    if not isinstance(shape, str) or shape.lower() not in _SHAPES:
        raise InvalidArgument(f"motion.plan shape: one of {sorted(_SHAPES)} or a RampShape, not {shape!r}")
    return _SHAPES[shape.lower()]


def plan(target: float, *, start: float = 0.0, v0: float = 0.0, a0: float = 0.0,
         max_velocity: float, max_acceleration: float, max_deceleration: float = 0.0,
         max_jerk: Optional[float] = None, shape: str | RampShape = "trapezoid") -> Profile:
    """Plan a move to rest at ``target``.

    With ``max_jerk`` the jerk-limited time-optimal (7-phase) planner is used
    (same durations as ruckig); otherwise a trapezoid, or with the same ramp
    times an S-curve (``shape="s_curve"``) or sin^2 ramps (``shape="sin2"``).
    Raises ``LimitExceeded``.
    """
    if max_jerk is not None:
        return plan_jerk_limited(MotionState(start, v0, a0), target,
                                 Limits(max_velocity, max_acceleration, max_deceleration, max_jerk))
    return plan_trapezoid(MotionState(start, v0, 0.0), target,
                          Limits(max_velocity, max_acceleration, max_deceleration), _shape(shape))


def sample(profile: Profile, n: int = 500, t: Optional[Sequence[float]] = None) -> dict[str, np.ndarray]:
    """Sample a profile: a dict of numpy arrays ``t, p, v, a, j`` (n equally spaced points, or at ``t``)."""
    m = profile.sample(n) if t is None else profile.sample_at(np.asarray(t, dtype=float))
    return {k: m[:, i] for i, k in enumerate("tpvaj")}


def step_times(profile: Profile, t0_ns: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Exact step times (int64 ns) and directions (int8, +1/-1) for a profile in steps."""
    return profile.step_times(t0_ns)


// Generic planners: trapezoidal, S-curve and jerk-limited time-optimal
// (7-phase), in position and velocity mode, from any initial velocity (and,
// for the jerk-limited planner, acceleration).
//
// All planners return a Profile starting at t = 0.  Limits are magnitudes and
// symmetric (the same for both directions).  An impossible request throws
// LimitExceeded naming the limit and the excess.
#pragma once
#include <array>
#include <span>
#include <vector>

#include "motorbus/motion/profile.hpp"

namespace motorbus::motion {

struct Limits {
    double max_velocity = 0;      // > 0
    double max_acceleration = 0;  // > 0; also used for deceleration if max_deceleration == 0
    double max_deceleration = 0;  // 0: same as max_acceleration
    double max_jerk = 0;          // jerk-limited planner only, > 0
    double decel() const { return max_deceleration > 0 ? max_deceleration : max_acceleration; }
};

// How acceleration ramps are shaped.
enum class RampShape {
    Trapezoid,  // constant acceleration in each ramp
    SCurve,     // same ramp times and distances as Trapezoid, but the acceleration
                // rises and falls linearly within each ramp (triangular accel, peak = 2x
                // the trapezoid's): how the drives' S-curve settings are read
    Sin2        // same ramp times and distances, acceleration a_peak sin^2(pi t/T)
                // (CiA 402 6086h = 1; callers halve the acceleration to keep the peak)
};

// Position mode: from `start` (p, v; a is ignored: ramps start with a = 0) to
// rest at `target`, time-optimal under max_velocity / max_acceleration /
// max_deceleration.  An initial velocity above max_velocity is first reduced;
// a velocity away from the target, or one too fast to stop in time, reverses
// after stopping.
Profile plan_trapezoid(const State& start, double target, const Limits& lim,
                       RampShape shape = RampShape::Trapezoid);

// Velocity mode: from start.v to `target_velocity` (|.| <= max_velocity), then
// holds it for `hold` seconds (the profile needs a finite end).  Accelerating
// uses max_acceleration, decelerating max_deceleration; a sign change
// decelerates to 0 first.
Profile plan_velocity(const State& start, double target_velocity, const Limits& lim,
                      double hold = 0.0, RampShape shape = RampShape::Trapezoid);

// Jerk-limited, time-optimal (7-phase: +j, 0, -j, cruise, -j, 0, +j and its
// degenerate forms) from `start` (p, v, a) to rest at `target`.  For a start
// with a == 0 the duration equals ruckig's to 1e-9 s (see
// tests/interop/test_motion_ruckig.py); with a != 0 the acceleration is first
// brought to 0 at max_jerk, which is not always time-optimal (documented in
// docs/motion.md).
Profile plan_jerk_limited(const State& start, double target, const Limits& lim);

// Jerk-limited velocity mode: from start.v (start.a is released first, as in
// plan_jerk_limited) to `target_velocity` with a = 0 at the end, time-optimal
// under max_acceleration / max_jerk (|target| <= max_velocity), then holding it
// for `hold` s.  Same duration as ruckig's velocity interface for a = 0 starts.
Profile plan_jerk_limited_velocity(const State& start, double target_velocity, const Limits& lim,
                                   double hold = 0.0);

// Minimum time to change velocity from v0 to v1 (a = 0 at both ends) under
// (amax, jmax), and the distance covered meanwhile.  Closed form.
struct Ramp {
    double t1 = 0, t2 = 0, t3 = 0;  // +j, 0, -j phase durations (signs follow the direction)
    double duration() const { return t1 + t2 + t3; }
    double distance = 0;
};
Ramp jerk_limited_ramp(double v0, double v1, double amax, double jmax);

// ---- multi-axis --------------------------------------------------------------

// Time-synchronised rest-to-rest moves: each axis is planned time-optimally,
// then every faster axis is slowed (its cruise velocity lowered) so that all
// finish at the slowest axis's time.  The returned profiles all have the same
// duration (to 1e-12 s).  Trapezoid/S-curve ramps.
std::vector<Profile> plan_synchronized(const std::vector<double>& start,
                                       const std::vector<double>& target,
                                       const std::vector<Limits>& limits,
                                       RampShape shape = RampShape::Trapezoid);

// Jerk-limited time synchronisation for axes starting at rest (a = 0, v = 0):
// each axis is planned time-optimally (plan_jerk_limited), the slowest sets T,
// and every other axis gets the same 7-phase shape with the lower cruise
// velocity that makes it last exactly T (closed form when the ramps reach
// max_acceleration, Newton otherwise).  Durations equal ruckig's synchronised
// duration for such moves.  Throws InvalidArgument for a moving start.
std::vector<Profile> plan_synchronized_jerk_limited(const std::vector<double>& start,
                                                    const std::vector<double>& target,
                                                    const std::vector<Limits>& limits);

// Batch duration queries (interop tests, benchmarks: no per-call overhead).
// `rows` is row-major: 7 columns (p0, v0, a0, target, vmax, amax, jmax) for
// plan_jerk_limited; 15 = 3 axes x (p0, target, vmax, amax, jmax) for
// plan_synchronized_jerk_limited (the common duration).  InvalidArgument if
// the size is not a multiple of the column count.
std::vector<double> jerk_limited_durations(std::span<const double> rows);
std::vector<double> synchronized_jerk_limited_durations(std::span<const double> rows);

// Straight-line (phase-synchronised) move: one scalar path parameter s in
// [0, 1] is planned under the tightest per-axis limit scaled by each axis's
// share of the move, so every axis starts, accelerates, cruises and stops
// together and the tool moves on the straight line.  Returns one profile per axis.
std::vector<Profile> plan_straight_line(const std::vector<double>& start,
                                        const std::vector<double>& target,
                                        const std::vector<Limits>& limits,
                                        RampShape shape = RampShape::Trapezoid);

// Split a multi-axis path (one profile per axis, positions in increments) into
// interpolation segments, as a drive's interpolated-position stream takes them:
// integer offsets per period of `period_ms` (>= 1; the periods a drive accepts are
// its own check, in its folder).  Offsets are the differences of the rounded
// sampled positions, so their running sums track the path with at most half an
// increment of error and reach every target exactly.  Result: [segment][axis].
std::vector<std::vector<long long>> split_interpolation(const std::vector<Profile>& axes,
                                                        int period_ms);

}  // namespace motorbus::motion

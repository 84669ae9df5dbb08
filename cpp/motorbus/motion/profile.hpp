// A motion profile: a piecewise description of position over time that every
// planner and every drive model in motion/ produces, and that simulators,
// plots and the step generator consume.
//
// Time is in seconds (double) measured from the start of the profile; position
// is in whatever unit the producer documents (steps, encoder counts, 1/10000
// rev...).  Each segment is either a cubic (constant jerk) or the exponential
// approach a closed position loop makes (a servo's last approach to target).  Velocity may
// jump between segments (a stepper's start/stop speed), position never does.
#pragma once
#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

#include "motorbus/errors.hpp"

namespace motorbus::motion {

// Kinematic state at one instant.
struct State {
    double p = 0;  // position
    double v = 0;  // velocity (unit/s)
    double a = 0;  // acceleration (unit/s^2)
    double j = 0;  // jerk (unit/s^3)
};

// A request that no profile can satisfy.  The message names the limit and by
// how much it is exceeded, e.g. "ACC: 0.5 ms is below the minimum 2 ms of
// speed window 1 (by 1.5 ms)".  Python: motorbus.LimitExceeded (a ValueError).
struct LimitExceeded : InvalidArgument {
    LimitExceeded(std::string limit_name, double requested, double limit_value,
                  const std::string& detail = {});
    std::string limit;  // which limit ("max_velocity", "HSPD", "#INTERPOL_TIME", ...)
    double requested;   // the value asked for
    double allowed;     // the bound it violates
    double excess() const { return requested - allowed; }  // signed: >0 above a max, <0 below a min
};

struct Segment {
    enum class Kind : unsigned char {
        Cubic,       // p(t) = p + v t + a t^2/2 + j t^3/6
        ExpApproach, // p(t) = p_end - (p_end - p) e^{-t/tau}: velocity proportional to error
        SinRamp      // a(t) = amp sin^2(pi t / tau): CiA 402 sin^2 ramp (6086h = 1)
    };
    Kind kind = Kind::Cubic;
    double t0 = 0;        // start time within the profile (s)
    double duration = 0;  // s, >= 0
    State start;          // state at t0 (j is the segment's constant jerk for Cubic)
    double tau = 0;       // ExpApproach: time constant (s); SinRamp: full ramp length (s)
    double p_end = 0;     // ExpApproach only: the asymptote (the target)
    double amp = 0;       // SinRamp only: peak acceleration

    State at(double t_in_segment) const;  // t_in_segment in [0, duration]
    State end() const { return at(duration); }
};

// Where a SinRamp segment's velocity crosses zero (-1 if it does not).
double detail_sin_velocity_zero(const Segment& seg);

// An ordered list of segments starting at t = 0, plus the exact final state.
// Query before 0 gives the initial state (at rest at p0 unless v0 was given);
// after duration() the final state.  The last position is stored exactly, so a
// profile to an integer target ends exactly on it whatever the rounding inside.
class Profile {
public:
    Profile() = default;
    // Starts at `initial`; segments are appended with append_*.
    explicit Profile(State initial);

    // Appends a constant-jerk segment from the current end state (final_state():
    // finish() can set it, which is how a velocity jump is made).  Zero-length
    // segments are dropped.  Returns *this for chaining.
    Profile& append_cubic(double duration, double jerk);
    // Appends a segment with a velocity/acceleration jump at its start: it
    // starts at the current end position with (v, a) and constant jerk j.
    Profile& append_jump(double duration, double v, double a, double jerk);
    Profile& append_exp_approach(double duration, double target, double tau);
    // Appends a sin^2 acceleration ramp changing the velocity by dv over
    // `duration` (peak acceleration 2 dv / duration, zero at both ends).
    Profile& append_sin_ramp(double duration, double dv);
    // Sets the velocity/acceleration the profile rests with after its end
    // (normally 0: a stepper stops from LSPD with a jump), and optionally snaps
    // the final position to `exact_end` (the target) to remove rounding.
    Profile& finish(double exact_end_position, double end_velocity = 0.0);
    // Appends another profile (its start position must match, within 1e-6).
    Profile& append(const Profile& tail);
    // Keeps the part before t (the future is replaced by an on-the-fly change).
    Profile truncated(double t) const;
    // The same motion moved by dp in position (a position counter reset).
    Profile shifted_position(double dp) const;

    State initial() const { return initial_; }
    State final_state() const { return final_; }
    double duration() const { return duration_; }
    double start_position() const { return initial_.p; }
    double end_position() const { return final_.p; }
    const std::vector<Segment>& segments() const { return segments_; }
    bool empty() const { return segments_.empty(); }

    State at(double t) const;
    double position(double t) const { return at(t).p; }
    double velocity(double t) const { return at(t).v; }
    double acceleration(double t) const { return at(t).a; }
    double jerk(double t) const { return at(t).j; }
    // Index of the segment containing t (binary search); size() if past the end.
    std::size_t segment_index(double t) const;

    // Sampling: n points equally spaced over [0, duration()] (n >= 2), or at
    // the given times.  Rows: t, p, v, a, j.
    Eigen::Matrix<double, Eigen::Dynamic, 5> sample(std::size_t n) const;
    Eigen::Matrix<double, Eigen::Dynamic, 5> sample_at(const Eigen::VectorXd& t) const;
    // Writes positions at t = t0 + k*dt for k < count into out (fast path for sims).
    void positions(double t0, double dt, std::size_t count, double* out) const;

    // Largest |v|, |a|, |j| over the profile (at segment boundaries and
    // interior extrema), for property tests and limit checks.
    double max_abs_velocity() const;
    double max_abs_acceleration() const;
    double max_abs_jerk() const;
    // First time in [t_from, duration()] where position crosses `level`
    // (either direction); -1 if never.  Exact to ~1e-12 s (closed form for
    // quadratic segments, safeguarded Newton for cubic/exponential).
    double first_crossing(double level, double t_from = 0.0) const;

private:
    State initial_{};
    State final_{};
    double duration_ = 0;
    std::vector<Segment> segments_;
    State end_state_() const;
};

}  // namespace motorbus::motion

#include "motorbus/drives/dmac/profile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "motorbus/motion/planner_detail.hpp"

namespace motorbus::dmac {

namespace {
constexpr double kSpeedHoldSeconds = 1e7;  // MOVE_SPEED runs until the next command
constexpr double kApproachEndIncrements = 1.0;

void check_range(const char* name, double v, double lo, double hi) {
    if (v < lo) throw LimitExceeded(name, v, lo, "below the range");
    if (v > hi) throw LimitExceeded(name, v, hi, "above the range");
}

// Constant-acceleration magnitudes (increments/s^2); infinity for start-stop.
double accel_of(const ProfileParams& p) {
    const double hs = speed_to_inc_per_s(p.high_speed);
    return p.accel_time_ms > 0 ? hs / (p.accel_time_ms / 1000.0) : std::numeric_limits<double>::infinity();
}
double decel_of(const ProfileParams& p) {
    const double hs = speed_to_inc_per_s(p.high_speed);
    return p.decel_time_ms > 0 ? hs / (p.decel_time_ms / 1000.0) : std::numeric_limits<double>::infinity();
}
RampShape shape_of(const ProfileParams& p) { return p.s_curve ? RampShape::SCurve : RampShape::Trapezoid; }

// Appends the closed-loop approach from the current end position to target.
void append_approach(Profile& prof, double target, double low_speed_inc) {
    const double p0 = prof.final_state().p;
    const double err = std::fabs(target - p0);
    if (err == 0) return;
    const double s = target > p0 ? 1.0 : -1.0;
    const double tau = kApproachIncrements / low_speed_inc;
    if (err > kApproachEndIncrements) {
        const double t_exp = tau * std::log(err / kApproachEndIncrements);
        prof.append_exp_approach(t_exp, target, tau);
    }
    // Last increment at the loop's speed for an error of one increment.
    const double rest = std::min(err, kApproachEndIncrements);
    const double v_min = low_speed_inc * kApproachEndIncrements / kApproachIncrements;
    prof.append_jump(rest / v_min, s * v_min, 0, 0);
}
}  // namespace

void ProfileParams::validate() const {
    check_range("#HIGH_SPEED", high_speed, 0, 400000);
    check_range("#LOW_SPEED", low_speed, 0, 400000);
    check_range("#ACCEL_TIME", accel_time_ms, 0, 12000);
    check_range("#DECEL_TIME", decel_time_ms, 0, 12000);
}

double ramp_time(const ProfileParams& p, double v_from, double v_to) {
    if (p.high_speed <= 0) return 0.0;
    const double hs = p.high_speed;
    const double ati = p.accel_time_ms / 1000.0, dti = p.decel_time_ms / 1000.0;
    if (v_from * v_to < 0) return dti * std::fabs(v_from) / hs + ati * std::fabs(v_to) / hs;
    if (std::fabs(v_to) >= std::fabs(v_from)) return ati * std::fabs(v_to - v_from) / hs;
    return dti * std::fabs(v_to - v_from) / hs;
}

Profile speed_profile(const State& start, double speed_001rpm, const ProfileParams& p, double hold) {
    p.validate();
    const double hs = p.high_speed;
    const double target = std::clamp(speed_001rpm, -hs, hs);
    const double vt = speed_to_inc_per_s(target);
    Profile prof(State{start.p, start.v, 0, 0});
    double v = start.v;
    const RampShape shape = shape_of(p);
    const double v_from = inc_per_s_to_speed(v);
    if (v * vt < 0) {
        detail::append_ramp(prof, -v, ramp_time(p, v_from, 0), shape);
        v = 0;
    }
    detail::append_ramp(prof, vt - v, ramp_time(p, inc_per_s_to_speed(v), target), shape);
    if (hold > 0) prof.append_jump(hold, vt, 0, 0);
    prof.finish(prof.final_state().p, vt);
    return prof;
}

Profile position_profile(const State& start, double target, const ProfileParams& p) {
    p.validate();
    if (!std::isfinite(target) || !std::isfinite(start.p) || !std::isfinite(start.v))
        throw InvalidArgument("DMAC move: position and velocity must be finite");
    const double hs = speed_to_inc_per_s(p.high_speed);
    // The loop approaches at most at the cruise speed.
    const double ls = std::min(speed_to_inc_per_s(p.low_speed), hs);
    if (!(ls > 0)) throw LimitExceeded("#LOW_SPEED", p.low_speed, 1, "a position move needs a non-zero approach speed");
    const double a = accel_of(p), d = decel_of(p);
    const RampShape shape = shape_of(p);
    Profile prof(State{start.p, start.v, 0, 0});
    const double x_signed = target - start.p;
    const double s = x_signed >= 0 ? 1.0 : -1.0;
    const double x = std::fabs(x_signed);
    const double u = s * start.v;
    const double stop_to_ls = u > ls ? (u * u - ls * ls) / (2 * d) : 0.0;
    if (start.v != 0 && (u < 0 || x <= kApproachIncrements || stop_to_ls > x - kApproachIncrements)) {
        // Moving the wrong way, or too fast for this target: come to rest first.
        detail::append_ramp(prof, -start.v, std::fabs(start.v) / d, shape);
        const State rest{prof.final_state().p, 0, 0, 0};
        Profile tail = position_profile(rest, target, p);
        prof.append(tail);
        prof.finish(target, 0);
        return prof;
    }
    if (x > kApproachIncrements) {
        const double via = target - s * kApproachIncrements;
        Profile head = detail::stepper_profile(State{start.p, start.v, 0, 0}, via, hs, a, d, 0.0, ls, shape);
        prof = head;
        prof.finish(via, s * ls);
    }
    append_approach(prof, target, ls);
    prof.finish(target, 0);
    return prof;
}

Motion::Motion(ProfileParams params, double position)
    : params_(params), profile_(State{position, 0, 0, 0}), target_(std::llround(position)) {
    params_.validate();
}

void Motion::set_params(const ProfileParams& p) {
    p.validate();
    params_ = p;
}

void Motion::splice(double t, const Profile& tail) {
    if (!(t >= 0) || !std::isfinite(t)) throw InvalidArgument("DMAC command time must be finite and >= 0");
    Profile head = profile_.truncated(t);
    if (head.duration() < t) {
        // Idle since the last move: rest in place until t.
        const State end = head.final_state();
        head.append_jump(t - head.duration(), end.v, 0, 0);
    }
    const State tail_end = tail.final_state();
    const double tail_len = tail.duration();
    head.append(tail);
    head.finish(tail_end.p, tail_end.v);
    profile_ = head;
    motion_end_ = t + tail_len;
    target_reached_ = motion_end_;
}

void Motion::move_to(double t, std::int64_t target) {
    const State st = profile_.at(t);
    splice(t, position_profile(st, static_cast<double>(target), params_));
    speed_mode_ = false;
    target_ = target;
}

void Motion::move_on(double t, std::int64_t offset) {
    // Relative to the current target when one is set, so chained MOVE_ON add up.
    const State st = profile_.at(t);
    const double base = speed_mode_ ? std::round(st.p) : static_cast<double>(target_);
    move_to(t, static_cast<std::int64_t>(base) + offset);
}

void Motion::move_speed(double t, std::int32_t speed_001rpm) {
    const State st = profile_.at(t);
    Profile tail = speed_profile(st, speed_001rpm, params_, kSpeedHoldSeconds);
    splice(t, tail);
    const double vt = tail.final_state().v;
    target_reached_ = t + (tail.duration() - kSpeedHoldSeconds);
    if (vt != 0) motion_end_ = std::numeric_limits<double>::infinity();
    else motion_end_ = target_reached_;
    speed_mode_ = true;
}

void Motion::stop(double t) {
    const State st = profile_.at(t);
    Profile tail = speed_profile(st, 0, params_, 0.0);
    splice(t, tail);
    speed_mode_ = false;
    target_ = static_cast<std::int64_t>(std::llround(tail.final_state().p));
}

bool Motion::moving(double t) const { return t < motion_end_; }

}  // namespace motorbus::dmac

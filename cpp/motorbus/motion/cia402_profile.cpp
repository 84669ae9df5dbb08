#include "motorbus/motion/cia402_profile.hpp"

#include <algorithm>
#include <cmath>

#include "motorbus/motion/planner_detail.hpp"

namespace motorbus::motion {

namespace {
RampShape shape_of(const Cia402ProfileParams& p) { return p.motion_profile_type == 1 ? RampShape::Sin2 : RampShape::Trapezoid; }
// Average accelerations: a sin^2 ramp averages half its peak.
double avg(const Cia402ProfileParams& p, double a) { return p.motion_profile_type == 1 ? a / 2 : a; }
double cruise(const Cia402ProfileParams& p) {
    return p.max_profile_velocity > 0 ? std::min(p.profile_velocity, p.max_profile_velocity) : p.profile_velocity;
}
}  // namespace

void Cia402ProfileParams::validate() const {
    auto pos = [](const char* name, double v) {
        if (!(v > 0) || !std::isfinite(v)) throw LimitExceeded(name, v, 0, "must be positive");
    };
    pos("6081h profile velocity", profile_velocity);
    pos("6083h profile acceleration", profile_acceleration);
    pos("6084h profile deceleration", profile_deceleration);
    pos("6085h quick stop deceleration", quick_stop_deceleration);
    if (motion_profile_type < 0) throw LimitExceeded("6086h motion profile type", motion_profile_type, 0, "0 linear, 1 sin^2");
    if (motion_profile_type > 1) throw LimitExceeded("6086h motion profile type", motion_profile_type, 1, "0 linear, 1 sin^2");
}

Profile cia402_position_profile(const State& start, double target, const Cia402ProfileParams& p) {
    p.validate();
    return detail::stepper_profile(State{start.p, start.v, 0, 0}, target, cruise(p), avg(p, p.profile_acceleration),
                                   avg(p, p.profile_deceleration), 0, 0, shape_of(p));
}

Profile cia402_velocity_profile(const State& start, double vt, const Cia402ProfileParams& p, double hold) {
    p.validate();
    if (p.max_profile_velocity > 0) vt = std::clamp(vt, -p.max_profile_velocity, p.max_profile_velocity);
    Profile prof(State{start.p, start.v, 0, 0});
    double v = start.v;
    const double a = avg(p, p.profile_acceleration), d = avg(p, p.profile_deceleration);
    if (v * vt < 0) {
        detail::append_ramp(prof, -v, std::fabs(v) / d, shape_of(p));
        v = 0;
    }
    const double dv = vt - v;
    detail::append_ramp(prof, dv, std::fabs(dv) / (std::fabs(vt) > std::fabs(v) ? a : d), shape_of(p));
    if (hold > 0) prof.append_jump(hold, vt, 0, 0);
    prof.finish(prof.final_state().p, vt);
    return prof;
}

Profile cia402_quick_stop_profile(const State& start, const Cia402ProfileParams& p) {
    p.validate();
    Profile prof(State{start.p, start.v, 0, 0});
    detail::append_ramp(prof, -start.v, std::fabs(start.v) / p.quick_stop_deceleration, RampShape::Trapezoid);
    prof.finish(prof.final_state().p, 0);
    return prof;
}

Cia402ProfilePosition::Cia402ProfilePosition(Cia402ProfileParams p, double position)
    : p_(p), profile_(State{position, 0, 0, 0}), target_(position) {
    p_.validate();
}

void Cia402ProfilePosition::set_params(const Cia402ProfileParams& p) {
    p.validate();
    p_ = p;
}

void Cia402ProfilePosition::splice(double t, const Profile& tail) {
    Profile head = profile_.truncated(t);
    if (head.duration() < t) {
        const State e = head.final_state();
        head.append_jump(t - head.duration(), 0, 0, 0);
        head.finish(e.p, 0);
    }
    const State end = tail.final_state();
    head.append(tail);
    head.finish(end.p, end.v);
    profile_ = head;
}

void Cia402ProfilePosition::promote(double t_now) {
    if (!pending_ || t_now < profile_.duration()) return;
    const double t = profile_.duration();
    const double tgt = *pending_;
    pending_.reset();
    splice(t, cia402_position_profile(State{profile_.end_position(), 0, 0, 0}, tgt, p_));
    target_ = tgt;
}

bool Cia402ProfilePosition::new_setpoint(double t, double target, bool relative, bool change_immediately,
                                         bool change_on_setpoint) {
    if (!std::isfinite(target) || !(t >= 0)) throw InvalidArgument("CiA 402 set-point: finite target and t >= 0");
    promote(t);
    const bool moving = t < profile_.duration();
    const double base = relative ? (change_immediately || !moving ? (moving ? target_ : profile_.at(t).p) : target_) : 0.0;
    const double abs_target = relative ? base + target : target;
    if (change_immediately || !moving) {
        pending_.reset();
        splice(t, cia402_position_profile(profile_.at(t), abs_target, p_));
        target_ = abs_target;
        return true;
    }
    if (pending_) return false;
    const State now = profile_.at(t);
    const double dir_now = target_ - now.p;
    const bool same_way = (abs_target - target_) * dir_now > 0;
    if (change_on_setpoint && same_way) {
        // Pass through the current target at speed and go on.
        splice(t, cia402_position_profile(now, abs_target, p_));
        target_ = abs_target;
        return true;
    }
    pending_ = abs_target;
    return true;
}

void Cia402ProfilePosition::halt(double t) {
    pending_.reset();
    const State now = profile_.at(t);
    Profile tail(State{now.p, now.v, 0, 0});
    detail::append_ramp(tail, -now.v, std::fabs(now.v) / avg(p_, p_.profile_deceleration), shape_of(p_));
    tail.finish(tail.final_state().p, 0);
    splice(t, tail);
    target_ = tail.final_state().p;
}

const Profile& Cia402ProfilePosition::profile() {
    if (!pending_) return profile_;
    preview_ = profile_;
    preview_.append(cia402_position_profile(State{profile_.end_position(), 0, 0, 0}, *pending_, p_));
    preview_.finish(*pending_, 0);
    return preview_;
}

bool Cia402ProfilePosition::target_reached(double t) {
    promote(t);
    return t >= profile_.duration() && !pending_;
}

}  // namespace motorbus::motion

#include "motorbus/motion/planner.hpp"

#include <algorithm>
#include <cmath>

#include "motorbus/motion/planner_detail.hpp"

namespace motorbus::motion {

namespace detail {

void append_ramp(Profile& prof, double dv, double duration, RampShape shape) {
    if (!(duration > 0)) return;
    const State s = prof.final_state();
    if (shape == RampShape::Trapezoid) {
        prof.append_jump(duration, s.v, dv / duration, 0.0);
    } else if (shape == RampShape::Sin2) {
        prof.append_sin_ramp(duration, dv);
    } else {
        // Triangular acceleration: same Δv and same distance as the linear ramp.
        const double half = duration / 2;
        const double jerk = dv / (half * half);
        prof.append_jump(half, s.v, 0.0, jerk);
        prof.append_cubic(half, -jerk);
    }
}

double sgn(double x) { return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0); }

Profile stepper_profile(const State& start, double target, double vmax, double accel, double decel,
                        double v_start, double v_end, RampShape shape) {
    Profile prof(State{start.p, start.v, 0, 0});
    State cur{start.p, start.v, 0, 0};
    // Divisions dominate this planner's cost: take the two inverses once.
    const double inv_a = 1 / accel, inv_d = 1 / decel;
    for (int pass = 0; pass < 3; ++pass) {
        const double x_signed = target - cur.p;
        double s = sgn(x_signed);
        if (s == 0) s = -sgn(cur.v);  // on target but moving: stop, then come back
        if (s == 0) break;            // at rest on target
        const double x = s * x_signed;
        const double u0 = s * cur.v;
        const double stop_dist = u0 > v_end ? (u0 * u0 - v_end * v_end) * 0.5 * inv_d : 0.0;
        if (u0 < 0 || stop_dist > x || (x == 0 && u0 != 0)) {
            // Moving away, or too fast to stop in time: stop first, then come back.
            const double dir = sgn(cur.v);
            const double w = std::fabs(cur.v);
            if (w > v_end) append_ramp(prof, -dir * (w - v_end), (w - v_end) * inv_d, shape);
            cur = prof.final_state();
            cur.v = 0;  // the stop is a jump from v_end to 0
            cur.a = 0;
            prof.finish(cur.p, 0.0);
            continue;
        }
        double u = u0;
        if (u < v_start) u = v_start;  // a stepper starts at its start speed
        double vp;
        double cruise = 0;
        if (u > vmax) {
            vp = vmax;
        } else {
            const double k = 0.5 * (inv_a + inv_d);
            const double vp2 = (x + 0.5 * (u * u * inv_a + v_end * v_end * inv_d)) / k;
            vp = std::sqrt(std::max(vp2, 0.0));
            if (vp < u) vp = u;
            if (vp < v_end) vp = v_end;
            if (vp > vmax) vp = std::max(vmax, v_end);
        }
        const double d_acc = vp >= u ? (vp * vp - u * u) * 0.5 * inv_a : (u * u - vp * vp) * 0.5 * inv_d;
        const double d_dec = (vp * vp - v_end * v_end) * 0.5 * inv_d;
        if (vp > 0) cruise = std::max(0.0, (x - d_acc - d_dec) / vp);
        // Build: optional jump to u, ramp u->vp, cruise, ramp vp->v_end.
        const double t_acc = vp >= u ? (vp - u) * inv_a : (u - vp) * inv_d;
        const double t_dec = (vp - v_end) * inv_d;
        const std::size_t n_before = prof.segments().size();
        // The start speed is a jump (a stepper starts at it): set the end state, then ramp.
        prof.finish(prof.final_state().p, s * u);
        if (t_acc > 0) {
            if (shape == RampShape::Trapezoid)
                prof.append_jump(t_acc, s * u, vp >= u ? s * accel : -s * decel, 0.0);
            else
                append_ramp(prof, s * (vp - u), t_acc, shape);
        }
        if (cruise > 0) prof.append_jump(cruise, s * vp, 0.0, 0.0);
        if (t_dec > 0) {
            if (shape == RampShape::Trapezoid)
                prof.append_jump(t_dec, s * vp, -s * decel, 0.0);
            else
                append_ramp(prof, -s * (vp - v_end), t_dec, shape);
        }
        if (prof.segments().size() == n_before && vp > 0 && x > 0 && cruise == 0) {
            // Only a start-speed hop remains (x tiny, no ramps): cover it at vp.
            prof.append_jump(x / vp, s * vp, 0.0, 0.0);
        }
        prof.finish(target, 0.0);
        return prof;
    }
    prof.finish(target, 0.0);
    return prof;
}

}  // namespace detail

using detail::append_ramp;
using detail::sgn;

namespace {
void check_limits(const Limits& lim, bool need_jerk) {
    if (!(lim.max_velocity > 0) || !std::isfinite(lim.max_velocity))
        throw LimitExceeded("max_velocity", lim.max_velocity, 0, "must be positive and finite");
    if (!(lim.max_acceleration > 0) || !std::isfinite(lim.max_acceleration))
        throw LimitExceeded("max_acceleration", lim.max_acceleration, 0, "must be positive and finite");
    if (lim.max_deceleration < 0 || !std::isfinite(lim.max_deceleration))
        throw LimitExceeded("max_deceleration", lim.max_deceleration, 0, "must be >= 0 and finite");
    if (need_jerk && (!(lim.max_jerk > 0) || !std::isfinite(lim.max_jerk)))
        throw LimitExceeded("max_jerk", lim.max_jerk, 0, "must be positive and finite");
}
void check_state(const State& s, double target) {
    if (!std::isfinite(s.p) || !std::isfinite(s.v) || !std::isfinite(s.a) || !std::isfinite(target))
        throw InvalidArgument("motion: start state and target must be finite");
}
}  // namespace

Profile plan_trapezoid(const State& start, double target, const Limits& lim, RampShape shape) {
    check_limits(lim, false);
    check_state(start, target);
    return detail::stepper_profile(start, target, lim.max_velocity, lim.max_acceleration, lim.decel(),
                                   0.0, 0.0, shape);
}

Profile plan_velocity(const State& start, double target_velocity, const Limits& lim, double hold,
                      RampShape shape) {
    check_limits(lim, false);
    check_state(start, target_velocity);
    if (std::fabs(target_velocity) > lim.max_velocity)
        throw LimitExceeded("max_velocity", std::fabs(target_velocity), lim.max_velocity,
                            "target velocity");
    if (!(hold >= 0) || !std::isfinite(hold)) throw InvalidArgument("plan_velocity: hold must be >= 0");
    Profile prof(State{start.p, start.v, 0, 0});
    double v = start.v;
    if (v * target_velocity < 0) {
        append_ramp(prof, -v, std::fabs(v) / lim.decel(), shape);
        v = 0;
    }
    const double dv = target_velocity - v;
    const bool speeding_up = std::fabs(target_velocity) > std::fabs(v);
    append_ramp(prof, dv, std::fabs(dv) / (speeding_up ? lim.max_acceleration : lim.decel()), shape);
    if (hold > 0) prof.append_jump(hold, target_velocity, 0.0, 0.0);
    prof.finish(prof.final_state().p, target_velocity);
    return prof;
}

}  // namespace motorbus::motion

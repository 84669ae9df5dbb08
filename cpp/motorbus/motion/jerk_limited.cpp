// Jerk-limited time-optimal planning (a = 0 at the start after an optional
// acceleration release, rest at the target).
//
// Every such profile is ramp(v0 -> vp), cruise at vp, ramp(vp -> 0), where a
// ramp is the time-optimal velocity change with zero acceleration at both ends
// (jerk +-j, possibly a constant-acceleration middle).  A symmetric ramp covers
// (v_from + v_to)/2 x its duration, so the distance as a function of the peak
// velocity vp is known in closed form piecewise; the planner finds every vp
// that covers exactly the distance (bracketed Illinois iteration on each smooth
// piece), adds the cruising candidates at +-vmax, and keeps the fastest.
#include <algorithm>
#include <cmath>
#include <limits>

#include "motorbus/motion/planner.hpp"

namespace motorbus::motion {

Ramp jerk_limited_ramp(double v0, double v1, double amax, double jmax) {
    Ramp r;
    const double dv = std::fabs(v1 - v0);
    if (dv == 0) return r;
    const double dv_full = amax * amax / jmax;  // smallest change that reaches amax
    if (dv >= dv_full) {
        r.t1 = amax / jmax;
        r.t2 = dv / amax - amax / jmax;
        r.t3 = r.t1;
    } else {
        r.t1 = std::sqrt(dv / jmax);
        r.t2 = 0;
        r.t3 = r.t1;
    }
    r.distance = 0.5 * (v0 + v1) * r.duration();
    return r;
}

namespace {

struct Shape {
    double amax, jmax, dv_full;
    double T(double dv) const {  // ramp duration for a change of |dv|
        dv = std::fabs(dv);
        return dv >= dv_full ? dv / amax + amax / jmax : 2 * std::sqrt(dv / jmax);
    }
};

// Distance of ramp(v0 -> vp) + ramp(vp -> 0).
inline double dist(const Shape& s, double v0, double vp) {
    return 0.5 * (v0 + vp) * s.T(vp - v0) + 0.5 * vp * s.T(vp);
}
inline double total_time(const Shape& s, double v0, double vp) { return s.T(vp - v0) + s.T(vp); }

// Root of g(v) = dist(v) - D in [lo, hi] with g(lo), g(hi) of opposite signs.
double solve(const Shape& s, double v0, double D, double lo, double hi, double glo, double ghi) {
    for (int it = 0; it < 200; ++it) {
        double v = (lo * ghi - hi * glo) / (ghi - glo);
        if (!(v > lo && v < hi)) v = 0.5 * (lo + hi);
        const double g = dist(s, v0, v) - D;
        if (g == 0) return v;
        if ((g < 0) == (glo < 0)) {
            lo = v;
            glo = g;
            ghi *= 0.5;  // Illinois: keep the other end moving
        } else {
            hi = v;
            ghi = g;
            glo *= 0.5;
        }
        if (hi - lo <= 1e-15 * std::max({1.0, std::fabs(lo), std::fabs(hi)})) break;
    }
    return 0.5 * (lo + hi);
}

void append_ramp(Profile& prof, double v_from, double v_to, double amax, double jmax) {
    const Ramp r = jerk_limited_ramp(v_from, v_to, amax, jmax);
    const double s = v_to > v_from ? 1.0 : -1.0;
    prof.append_cubic(r.t1, s * jmax);
    prof.append_cubic(r.t2, 0.0);
    prof.append_cubic(r.t3, -s * jmax);
}

}  // namespace

Profile plan_jerk_limited(const State& start, double target, const Limits& lim) {
    for (double x : {lim.max_velocity, lim.max_acceleration, lim.max_jerk})
        if (!(x > 0) || !std::isfinite(x)) {
            const char* name = x == lim.max_velocity ? "max_velocity"
                               : x == lim.max_acceleration ? "max_acceleration" : "max_jerk";
            throw LimitExceeded(name, x, 0, "must be positive and finite");
        }
    if (!std::isfinite(start.p) || !std::isfinite(start.v) || !std::isfinite(start.a) || !std::isfinite(target))
        throw InvalidArgument("plan_jerk_limited: start state and target must be finite");
    if (std::fabs(start.a) > lim.max_acceleration * (1 + 1e-12))
        throw LimitExceeded("max_acceleration", std::fabs(start.a), lim.max_acceleration, "initial acceleration");
    const double amax = lim.max_acceleration, jmax = lim.max_jerk, vmax = lim.max_velocity;
    Profile prof(State{start.p, start.v, start.a, 0});
    // Release any initial acceleration first (not time-optimal when a0 != 0).
    if (start.a != 0) {
        const double t = std::fabs(start.a) / jmax;
        prof.append_jump(t, start.v, start.a, start.a > 0 ? -jmax : jmax);
    }
    const State s0 = prof.final_state();
    const double v0 = s0.v;
    const double D = target - s0.p;
    if (D == 0 && v0 == 0) {
        prof.finish(target, 0);
        return prof;
    }
    const Shape sh{amax, jmax, amax * amax / jmax};
    // Breakpoints of the piecewise distance function in [-vmax, vmax].
    double bp[8] = {-vmax, vmax, 0.0, v0, v0 + sh.dv_full, v0 - sh.dv_full, sh.dv_full, -sh.dv_full};
    std::sort(bp, bp + 8);
    double best_vp = 0, best_time = std::numeric_limits<double>::infinity(), best_cruise = 0;
    auto consider = [&](double vp, double cruise) {
        const double t = total_time(sh, v0, vp) + cruise;
        if (t < best_time) {
            best_time = t;
            best_vp = vp;
            best_cruise = cruise;
        }
    };
    const double f_hi = dist(sh, v0, vmax), f_lo = dist(sh, v0, -vmax);
    if (D >= f_hi) consider(vmax, (D - f_hi) / vmax);
    if (D <= f_lo) consider(-vmax, (D - f_lo) / -vmax);
    double prev = -vmax, gprev = f_lo - D;
    if (gprev == 0) consider(prev, 0);
    for (double b : bp) {
        if (b <= prev) continue;
        if (b > vmax) break;
        const double g = dist(sh, v0, b) - D;
        if (g == 0) {
            consider(b, 0);
        } else if (gprev != 0 && (g < 0) != (gprev < 0)) {
            consider(solve(sh, v0, D, prev, b, gprev, g), 0);
        }
        prev = b;
        gprev = g;
    }
    if (!std::isfinite(best_time)) {
        // Cannot happen for finite inputs (dist spans all reals with cruising), but stay safe.
        throw InvalidArgument("plan_jerk_limited: no profile found");
    }
    append_ramp(prof, v0, best_vp, amax, jmax);
    if (best_cruise > 0) prof.append_cubic(best_cruise, 0.0);
    append_ramp(prof, best_vp, 0.0, amax, jmax);
    prof.finish(target, 0);
    return prof;
}

}  // namespace motorbus::motion

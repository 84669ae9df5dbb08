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

// d dist / d vp: T(d)/2 + (v_from + vp)/2 T'(d) sign, for both ramps.
inline double dist_slope(const Shape& s, double v0, double vp) {
    auto Tp = [&](double d) {  // dT/d|dv|
        d = std::fabs(d);
        return d >= s.dv_full ? 1 / s.amax : 1 / std::sqrt(s.jmax * std::max(d, 1e-300));
    };
    const double d1 = vp - v0;
    return 0.5 * s.T(d1) + 0.5 * (v0 + vp) * Tp(d1) * (d1 >= 0 ? 1 : -1) + 0.5 * s.T(vp) +
           0.5 * vp * Tp(vp) * (vp >= 0 ? 1 : -1);
}

// Root of dist(v) = D on [lo, hi], where dist is increasing and brackets D:
// Newton from the constant-acceleration (quadratic) estimate, kept inside a
// shrinking bracket.
double solve(const Shape& s, double v0, double D, double lo, double hi) {
    // Guess: both ramps reach amax -> dist = vp^2/a + vp a/j + (a v0/2j - v0^2/2a) (for vp >= 0, vp >= v0).
    double v;
    {
        const double a = s.amax, j = s.jmax;
        const double sign = hi > 0 ? 1.0 : -1.0;
        const double c = sign * (a * v0 / (2 * j)) - v0 * v0 / (2 * a) - sign * D;
        const double b = a / j;
        const double disc = b * b - 4 / a * c;
        v = disc >= 0 ? sign * (-b + std::sqrt(disc)) / (2 / a) : 0.5 * (lo + hi);
        if (!(v > lo && v < hi)) v = 0.5 * (lo + hi);
    }
    for (int it = 0; it < 100; ++it) {
        const double g = dist(s, v0, v) - D;
        if (g == 0) return v;
        if (g < 0) lo = v;
        else hi = v;
        const double d = dist_slope(s, v0, v);
        double vn = (d > 0 && std::isfinite(d)) ? v - g / d : 0.5 * (lo + hi);
        if (!(vn > lo && vn < hi)) vn = 0.5 * (lo + hi);
        if (std::fabs(vn - v) <= 1e-15 * std::max(1.0, std::fabs(v)) || hi - lo <= 1e-15 * std::max(1.0, std::fabs(v)))
            return vn;
        v = vn;
    }
    return v;
}

void append_ramp(Profile& prof, double v_from, double v_to, double amax, double jmax) {
    const Ramp r = jerk_limited_ramp(v_from, v_to, amax, jmax);
    const double s = v_to > v_from ? 1.0 : -1.0;
    prof.append_cubic(r.t1, s * jmax);
    prof.append_cubic(r.t2, 0.0);
    prof.append_cubic(r.t3, -s * jmax);
}

// The time-optimal peak velocity (and cruise time) to cover D from v0 and stop.
void peak_for_distance(const Shape& sh, double v0, double D, double vmax, double& vp, double& cruise) {
    cruise = 0;
    // The stopping distance f0 = dist(0) = dist(v0) tells which side the peak is on;
    // dist(vp) increases with vp on [max(v0,0), vmax] and on [-vmax, min(v0,0)].
    const double f0 = 0.5 * v0 * sh.T(v0);
    if (D >= f0) {
        const double f_hi = dist(sh, v0, vmax);
        if (D >= f_hi) {  // far enough to cruise at +vmax: nothing is faster
            vp = vmax;
            cruise = (D - f_hi) / vmax;
        } else {
            vp = solve(sh, v0, D, v0 > vmax ? 0.0 : std::max(v0, 0.0), vmax);  // v0 above the limit: whole side
        }
    } else {
        const double f_lo = dist(sh, v0, -vmax);
        if (D <= f_lo) {
            vp = -vmax;
            cruise = (D - f_lo) / -vmax;
        } else {
            vp = solve(sh, v0, D, -vmax, v0 < -vmax ? 0.0 : std::min(v0, 0.0));
        }
    }
}

void check_jerk_limits(const Limits& lim) {
    for (double x : {lim.max_velocity, lim.max_acceleration, lim.max_jerk})
        if (!(x > 0) || !std::isfinite(x)) {
            const char* name = x == lim.max_velocity ? "max_velocity"
                               : x == lim.max_acceleration ? "max_acceleration" : "max_jerk";
            throw LimitExceeded(name, x, 0, "must be positive and finite");
        }
}

}  // namespace

Profile plan_jerk_limited(const State& start, double target, const Limits& lim) {
    check_jerk_limits(lim);
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
    double best_vp = 0, best_cruise = 0;
    peak_for_distance(sh, v0, D, vmax, best_vp, best_cruise);
    append_ramp(prof, v0, best_vp, amax, jmax);
    if (best_cruise > 0) prof.append_cubic(best_cruise, 0.0);
    append_ramp(prof, best_vp, 0.0, amax, jmax);
    prof.finish(target, 0);
    return prof;
}

Profile plan_jerk_limited_velocity(const State& start, double vt, const Limits& lim, double hold) {
    check_jerk_limits(lim);
    if (!std::isfinite(start.p) || !std::isfinite(start.v) || !std::isfinite(start.a) || !std::isfinite(vt))
        throw InvalidArgument("plan_jerk_limited_velocity: start state and target must be finite");
    if (std::fabs(vt) > lim.max_velocity)
        throw LimitExceeded("max_velocity", std::fabs(vt), lim.max_velocity, "target velocity");
    if (std::fabs(start.a) > lim.max_acceleration * (1 + 1e-12))
        throw LimitExceeded("max_acceleration", std::fabs(start.a), lim.max_acceleration, "initial acceleration");
    if (!(hold >= 0) || !std::isfinite(hold)) throw InvalidArgument("plan_jerk_limited_velocity: hold must be >= 0");
    Profile prof(State{start.p, start.v, start.a, 0});
    if (start.a != 0) {
        const double t = std::fabs(start.a) / lim.max_jerk;
        prof.append_jump(t, start.v, start.a, start.a > 0 ? -lim.max_jerk : lim.max_jerk);
    }
    append_ramp(prof, prof.final_state().v, vt, lim.max_acceleration, lim.max_jerk);
    if (hold > 0) prof.append_cubic(hold, 0.0);
    prof.finish(prof.final_state().p, vt);
    return prof;
}

std::vector<Profile> plan_synchronized_jerk_limited(const std::vector<double>& start,
                                                    const std::vector<double>& target,
                                                    const std::vector<Limits>& limits) {
    if (start.size() != target.size() || start.size() != limits.size() || start.empty())
        throw InvalidArgument("multi-axis: start, target and limits need the same non-zero length");
    // Minimum durations first (no profiles built), then one profile per axis.
    const std::size_t n = start.size();
    std::vector<double> tmin(n);
    double T = 0;
    for (std::size_t i = 0; i < n; ++i) {
        check_jerk_limits(limits[i]);
        if (!std::isfinite(start[i]) || !std::isfinite(target[i]))
            throw InvalidArgument("plan_synchronized_jerk_limited: positions must be finite");
        const Shape sh{limits[i].max_acceleration, limits[i].max_jerk,
                       limits[i].max_acceleration * limits[i].max_acceleration / limits[i].max_jerk};
        const double D = std::fabs(target[i] - start[i]);
        double vp = 0, cruise = 0;
        if (D > 0) peak_for_distance(sh, 0.0, D, limits[i].max_velocity, vp, cruise);
        tmin[i] = D > 0 ? 2 * sh.T(vp) + cruise : 0.0;
        T = std::max(T, tmin[i]);
    }
    std::vector<Profile> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (tmin[i] >= T) out[i] = plan_jerk_limited(State{start[i], 0, 0, 0}, target[i], limits[i]);
    }
    for (std::size_t i = 0; i < start.size(); ++i) {
        const double D = std::fabs(target[i] - start[i]);
        if (tmin[i] >= T) continue;
        const double a = limits[i].max_acceleration, j = limits[i].max_jerk;
        const Shape sh{a, j, a * a / j};
        if (D == 0) {
            Profile p(State{start[i], 0, 0, 0});
            p.append_cubic(T, 0.0);
            p.finish(target[i], 0);
            out[i] = p;
            continue;
        }
        // Rest to rest with peak vp: duration T(vp) + D/vp (two ramps, cruise (D - vp T(vp))/vp).
        // Take the slow root (cruise >= 0), decreasing in vp.
        double vp;
        {
            // Ramps reaching amax: vp^2/a + (a/j - T) vp + D = 0.
            const double b = a / j - T;
            const double disc = b * b - 4 * D / a;
            const double q = disc >= 0 ? (-b - std::sqrt(disc)) * a / 2 : -1;  // smaller root
            if (q >= sh.dv_full) {
                vp = q;
            } else {
                // Ramps below amax: 2 sqrt(vp/j) + D/vp = T, vp < dv_full: Newton from the left.
                double lo = 0, hi = std::min(sh.dv_full, std::max(q, sh.dv_full));
                double v = std::min(D / T, hi * 0.5);
                for (int it = 0; it < 100; ++it) {
                    const double g = sh.T(v) + D / v - T;  // > 0 below the root
                    if (g > 0) lo = v;
                    else hi = v;
                    const double dg = 1 / std::sqrt(j * v) - D / (v * v);
                    double vn = dg < 0 ? v - g / dg : 0.5 * (lo + hi);
                    if (!(vn > lo && vn < hi)) vn = 0.5 * (lo + hi);
                    if (std::fabs(vn - v) <= 1e-15 * v) {
                        v = vn;
                        break;
                    }
                    v = vn;
                }
                vp = v;
            }
        }
        const double s = target[i] >= start[i] ? 1.0 : -1.0;
        Profile p(State{start[i], 0, 0, 0});
        append_ramp(p, 0, s * vp, a, j);
        const double cruise = T - 2 * sh.T(vp);
        if (cruise > 0) p.append_cubic(cruise, 0.0);
        append_ramp(p, s * vp, 0, a, j);
        p.finish(target[i], 0);
        out[i] = p;
    }
    return out;
}

}  // namespace motorbus::motion

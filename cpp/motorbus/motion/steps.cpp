#include "motorbus/motion/steps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace motorbus::motion {

namespace {

// Calls emit(t_in_profile, dir) for every half-integer level crossed by the
// profile, in time order.
template <class Emit>
void for_each_step(const Profile& prof, std::size_t max_steps, Emit&& emit) {
    std::size_t count = 0;
    if (!std::isfinite(prof.start_position()) || !std::isfinite(prof.end_position()))
        throw InvalidArgument("step_times: profile positions must be finite");
    double c = std::floor(prof.start_position() + 0.5);  // steps issued so far, as a position
    for (const Segment& seg : prof.segments()) {
        // Monotone pieces: split cubic segments at velocity zeros.
        double cuts[4];
        int n = 0;
        cuts[n++] = 0;
        if (seg.kind == Segment::Kind::Cubic) {
            const double qa = seg.start.j / 2, qb = seg.start.a, qc = seg.start.v;
            double r[2];
            int nr = 0;
            if (qa == 0) {
                if (qb != 0) r[nr++] = -qc / qb;
            } else {
                const double disc = qb * qb - 4 * qa * qc;
                if (disc > 0) {
                    const double sq = std::sqrt(disc);
                    const double q = -0.5 * (qb + std::copysign(sq, qb));
                    r[nr++] = q / qa;
                    if (q != 0) r[nr++] = qc / q;
                }
            }
            std::sort(r, r + nr);
            for (int k = 0; k < nr; ++k)
                if (r[k] > 0 && r[k] < seg.duration) cuts[n++] = r[k];
        } else if (seg.kind == Segment::Kind::SinRamp) {
            const double tz = detail_sin_velocity_zero(seg);
            if (tz > 0 && tz < seg.duration) cuts[n++] = tz;
        }
        cuts[n++] = seg.duration;
        for (int k = 0; k + 1 < n; ++k) {
            const double ta = cuts[k], tb = cuts[k + 1];
            if (!(tb > ta)) continue;
            const State sa = seg.at(ta);
            const State sb = seg.at(tb);
            const double pa = sa.p, pb = sb.p;
            if (pa == pb) continue;
            const bool up = pb > pa;
            const int dir = up ? 1 : -1;
            // Next half-integer level from the current count c (the count is
            // round(p) as the motor has stepped so far, so reversals stay consistent).
            double h = up ? c + 0.5 : c - 0.5;
            const double n_levels = up ? (pb >= h ? std::floor(pb - h) + 1 : 0.0)
                                       : (pb <= h ? std::floor(h - pb) + 1 : 0.0);
            if (n_levels <= 0) continue;
            if (static_cast<double>(count) + n_levels > static_cast<double>(max_steps))
                throw InvalidArgument("step_times: the profile needs more than max_steps steps");
            c += up ? n_levels : -n_levels;
            const auto levels = static_cast<std::size_t>(n_levels);
            count += levels;
            double t_prev = ta;
            if (seg.kind == Segment::Kind::ExpApproach) {
                const double e0 = seg.p_end - seg.start.p;
                for (std::size_t i = 0; i < levels; ++i, h += dir) {
                    double t = -seg.tau * std::log((seg.p_end - h) / e0);
                    t = std::clamp(t, ta, tb);
                    emit(seg.t0 + t, dir);
                }
            } else if (seg.kind == Segment::Kind::Cubic && seg.start.j == 0) {
                // p = p0 + v t + a t^2/2: closed form, no cancellation.
                const double p0 = seg.start.p, v = seg.start.v, a = seg.start.a;
                const double s = dir;
                for (std::size_t i = 0; i < levels; ++i, h += dir) {
                    const double dh = h - p0;
                    double t;
                    if (a == 0) {
                        t = dh / v;
                    } else {
                        const double disc = std::max(0.0, v * v + 2 * a * dh);
                        const double den = s * std::sqrt(disc) + v;
                        t = den != 0 ? 2 * dh / den : ta;
                    }
                    t = std::clamp(t, ta, tb);
                    emit(seg.t0 + t, dir);
                }
            } else {
                // Cubic or sin^2 ramp: safeguarded Newton from the previous step's time.
                for (std::size_t i = 0; i < levels; ++i, h += dir) {
                    double lo = t_prev, hi = tb;
                    State st = seg.at(lo);
                    double t = st.v != 0 ? lo + (h - st.p) / st.v : 0.5 * (lo + hi);
                    if (!(t > lo && t < hi)) t = 0.5 * (lo + hi);
                    for (int it = 0; it < 60; ++it) {
                        st = seg.at(t);
                        const double f = (st.p - h) * dir;
                        if (f == 0) break;
                        if (f < 0) lo = t;
                        else hi = t;
                        double tn = st.v != 0 ? t - (st.p - h) / st.v : 0.5 * (lo + hi);
                        if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
                        if (std::fabs(tn - t) <= 1e-15 * std::max(1.0, t)) {
                            t = tn;
                            break;
                        }
                        t = tn;
                    }
                    t_prev = t;
                    emit(seg.t0 + t, dir);
                }
            }
        }
    }
}

}  // namespace

StepTimes step_times(const Profile& profile, Nanos t0_ns, std::size_t max_steps) {
    StepTimes out;
    out.t_ns.reserve(static_cast<std::size_t>(std::min(
        static_cast<double>(max_steps), std::fabs(profile.end_position() - profile.start_position()) + 16)));
    out.dir.reserve(out.t_ns.capacity());
    Nanos last = std::numeric_limits<Nanos>::min();
    const double base = static_cast<double>(t0_ns);
    for_each_step(profile, max_steps, [&](double t, int dir) {
        Nanos tn = static_cast<Nanos>(std::llround(base + t * 1e9));
        if (tn <= last) tn = last + 1;
        last = tn;
        out.t_ns.push_back(tn);
        out.dir.push_back(static_cast<std::int8_t>(dir));
    });
    return out;
}

std::vector<double> step_times_seconds(const Profile& profile, std::size_t max_steps) {
    std::vector<double> out;
    for_each_step(profile, max_steps, [&](double t, int) { out.push_back(t); });
    return out;
}

}  // namespace motorbus::motion

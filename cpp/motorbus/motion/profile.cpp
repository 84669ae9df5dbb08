#include "motorbus/motion/profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

namespace motorbus::motion {

namespace {
std::string limit_message(const std::string& name, double requested, double allowed,
                          const std::string& detail) {
    char buf[256];
    const double excess = requested - allowed;
    std::snprintf(buf, sizeof buf, "%s: requested %.9g %s the limit %.9g by %.9g", name.c_str(),
                  requested, excess > 0 ? "exceeds" : "is below", allowed, std::fabs(excess));
    std::string s = buf;
    if (!detail.empty()) s += " (" + detail + ")";
    return s;
}
}  // namespace

LimitExceeded::LimitExceeded(std::string limit_name, double requested_value, double limit_value,
                             const std::string& detail)
    : InvalidArgument(limit_message(limit_name, requested_value, limit_value, detail)),
      limit(std::move(limit_name)),
      requested(requested_value),
      allowed(limit_value) {}

State Segment::at(double t) const {
    if (kind == Kind::ExpApproach) {
        const double e0 = p_end - start.p;
        const double k = std::exp(-t / tau);
        return State{p_end - e0 * k, e0 * k / tau, -e0 * k / (tau * tau), e0 * k / (tau * tau * tau)};
    }
    if (kind == Kind::SinRamp) {
        // a = A sin^2(pi t/T) = A/2 (1 - cos(w t)), w = 2 pi / T
        const double T = tau, A = amp, w = 2 * std::numbers::pi / T;
        const double swt = std::sin(w * t), cwt = std::cos(w * t);
        return State{start.p + start.v * t + A / 2 * (t * t / 2 + (cwt - 1) / (w * w)),
                     start.v + A / 2 * (t - swt / w), A / 2 * (1 - cwt), A / 2 * w * swt};
    }
    // Multiplications by constants: a division here would be the planners' hottest instruction.
    constexpr double kSixth = 1.0 / 6.0;
    const double j = start.j;
    return State{start.p + t * (start.v + t * (start.a * 0.5 + t * j * kSixth)),
                 start.v + t * (start.a + t * j * 0.5), start.a + t * j, j};
}

Profile::Profile(State initial) : initial_(initial), final_(initial) {
    initial_.j = 0;
    final_.j = 0;
    segments_.reserve(8);  // one allocation covers the usual 3-9 segments
}

State Profile::end_state_() const {
    if (segments_.empty()) return final_;
    State s = segments_.back().end();
    return s;
}

Profile& Profile::append_cubic(double duration, double jerk) {
    if (!(duration > 0)) return *this;
    return append_jump(duration, final_.v, final_.a, jerk);
}

Profile& Profile::append_jump(double duration, double v, double a, double jerk) {
    if (!(duration > 0)) return *this;
    Segment& seg = segments_.emplace_back();
    seg.t0 = duration_;
    seg.duration = duration;
    seg.start = State{final_.p, v, a, jerk};
    duration_ += duration;
    // The end state inline (the planners' hot path): the cubic at t = duration.
    constexpr double kSixth = 1.0 / 6.0;
    const double t = duration;
    final_.p = final_.p + t * (v + t * (a * 0.5 + t * jerk * kSixth));
    final_.v = v + t * (a + t * jerk * 0.5);
    final_.a = a + t * jerk;
    final_.j = 0;
    return *this;
}

Profile& Profile::append_exp_approach(double duration, double target, double tau) {
    if (!(duration > 0) || !(tau > 0)) return *this;
    Segment seg;
    seg.kind = Segment::Kind::ExpApproach;
    seg.t0 = duration_;
    seg.duration = duration;
    seg.start = State{final_.p, 0, 0, 0};
    seg.tau = tau;
    seg.p_end = target;
    seg.start = seg.at(0);
    segments_.push_back(seg);
    duration_ += duration;
    final_ = seg.end();
    final_.j = 0;
    return *this;
}

Profile& Profile::append_sin_ramp(double duration, double dv) {
    if (!(duration > 0)) return *this;
    const State e = final_;
    Segment seg;
    seg.kind = Segment::Kind::SinRamp;
    seg.t0 = duration_;
    seg.duration = duration;
    seg.amp = 2 * dv / duration;
    seg.tau = duration;  // the ramp's own length: truncation must not reshape it
    seg.start = State{e.p, e.v, 0, 0};
    segments_.push_back(seg);
    duration_ += duration;
    final_ = seg.end();
    final_.j = 0;
    return *this;
}

Profile& Profile::finish(double exact_end_position, double end_velocity) {
    final_.p = exact_end_position;
    final_.v = end_velocity;
    final_.a = 0;
    final_.j = 0;
    return *this;
}

Profile& Profile::append(const Profile& tail) {
    const double p_here = final_.p;
    for (const Segment& s : tail.segments_) {
        Segment c = s;
        c.t0 = duration_;
        // Keep the joint continuous: the tail was planned from (almost) p_here.
        const double shift = p_here - tail.initial_.p;
        c.start.p += shift;
        if (c.kind == Segment::Kind::ExpApproach) c.p_end += shift;
        segments_.push_back(c);
        duration_ += c.duration;
    }
    final_ = tail.final_;
    final_.p += p_here - tail.initial_.p;
    if (tail.segments_.empty()) final_.v = tail.final_.v;
    return *this;
}

Profile Profile::truncated(double t) const {
    Profile out(initial_);
    if (t <= 0) return out;
    for (const Segment& s : segments_) {
        if (s.t0 >= t) break;
        Segment c = s;
        if (c.t0 + c.duration > t) c.duration = t - c.t0;
        out.segments_.push_back(c);
        out.duration_ = c.t0 + c.duration;
    }
    if (out.segments_.empty()) {
        out.final_ = initial_;
    } else {
        out.final_ = out.segments_.back().end();
        out.final_.j = 0;
        if (t >= duration_) out.final_ = final_;
    }
    return out;
}

Profile Profile::shifted_position(double dp) const {
    Profile out = *this;
    out.initial_.p += dp;
    out.final_.p += dp;
    for (Segment& s : out.segments_) {
        s.start.p += dp;
        s.p_end += dp;
    }
    return out;
}

std::size_t Profile::segment_index(double t) const {
    if (segments_.empty() || t >= duration_) return segments_.size();
    if (segments_.size() <= 16) {
        // Short profiles (every planner's): a branch-free count beats a
        // binary search whose branches a random t mispredicts.
        std::size_t n = 0;
        for (std::size_t i = 1; i < segments_.size(); ++i) n += static_cast<std::size_t>(t >= segments_[i].t0);
        return n;
    }
    auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                               [](double x, const Segment& s) { return x < s.t0; });
    if (it == segments_.begin()) return 0;
    return static_cast<std::size_t>(it - segments_.begin()) - 1;
}

State Profile::at(double t) const {
    if (!(t > 0)) {
        if (segments_.empty()) return initial_;
        State s = initial_;
        return s;
    }
    if (t >= duration_) return final_;
    const Segment& s = segments_[segment_index(t)];
    return s.at(t - s.t0);
}

Eigen::Matrix<double, Eigen::Dynamic, 5> Profile::sample(std::size_t n) const {
    if (n < 2) throw InvalidArgument("sample: n must be >= 2");
    Eigen::VectorXd t(static_cast<Eigen::Index>(n));
    for (std::size_t i = 0; i < n; ++i)
        t[static_cast<Eigen::Index>(i)] = duration_ * static_cast<double>(i) / static_cast<double>(n - 1);
    return sample_at(t);
}

Eigen::Matrix<double, Eigen::Dynamic, 5> Profile::sample_at(const Eigen::VectorXd& t) const {
    Eigen::Matrix<double, Eigen::Dynamic, 5> out(t.size(), 5);
    std::size_t k = 0;
    for (Eigen::Index i = 0; i < t.size(); ++i) {
        const double ti = t[i];
        State s;
        if (!(ti > 0) || ti >= duration_) {
            s = at(ti);
        } else {
            // Monotone times are the common case: walk forward instead of searching.
            if (k >= segments_.size() || ti < segments_[k].t0) k = segment_index(ti);
            while (k + 1 < segments_.size() && ti >= segments_[k + 1].t0) ++k;
            s = segments_[k].at(ti - segments_[k].t0);
        }
        out(i, 0) = ti;
        out(i, 1) = s.p;
        out(i, 2) = s.v;
        out(i, 3) = s.a;
        out(i, 4) = s.j;
    }
    return out;
}

void Profile::positions(double t0, double dt, std::size_t count, double* out) const {
    std::size_t k = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const double ti = t0 + dt * static_cast<double>(i);
        if (!(ti > 0) || ti >= duration_) {
            out[i] = at(ti).p;
            continue;
        }
        if (k >= segments_.size() || ti < segments_[k].t0) k = segment_index(ti);
        while (k + 1 < segments_.size() && ti >= segments_[k + 1].t0) ++k;
        out[i] = segments_[k].at(ti - segments_[k].t0).p;
    }
}

double Profile::max_abs_velocity() const {
    double m = std::max(std::fabs(initial_.v), std::fabs(final_.v));
    for (const Segment& s : segments_) {
        const State e = s.end();
        m = std::max({m, std::fabs(s.start.v), std::fabs(e.v)});
        if (s.kind == Segment::Kind::Cubic && s.start.j != 0) {
            const double tx = -s.start.a / s.start.j;  // where a = 0: velocity extremum
            if (tx > 0 && tx < s.duration) m = std::max(m, std::fabs(s.at(tx).v));
        }
    }
    return m;
}

double Profile::max_abs_acceleration() const {
    double m = 0;
    for (const Segment& s : segments_) {
        m = std::max({m, std::fabs(s.start.a), std::fabs(s.end().a)});
        if (s.kind == Segment::Kind::SinRamp) m = std::max(m, std::fabs(s.amp));
    }
    return m;
}

double Profile::max_abs_jerk() const {
    double m = 0;
    for (const Segment& s : segments_) {
        if (s.kind == Segment::Kind::Cubic)
            m = std::max(m, std::fabs(s.start.j));
        else if (s.kind == Segment::Kind::SinRamp)
            m = std::max(m, std::fabs(s.amp) * std::numbers::pi / s.tau);
        else
            m = std::max({m, std::fabs(s.start.j), std::fabs(s.end().j)});
    }
    return m;
}

// Where a sin^2 ramp's velocity crosses zero (velocity is monotone in it), or -1.
double detail_sin_velocity_zero(const Segment& seg) {
    const double v0 = seg.start.v, v1 = seg.end().v;
    if (v0 == 0 || v1 == 0 || (v0 < 0) == (v1 < 0)) return -1;
    double lo = 0, hi = seg.duration;
    for (int i = 0; i < 80; ++i) {
        const double m = 0.5 * (lo + hi);
        if ((seg.at(m).v < 0) == (v0 < 0)) lo = m;
        else hi = m;
    }
    return 0.5 * (lo + hi);
}

namespace {
// Root of f(t) = seg.at(t).p - level in [lo, hi] where f changes sign (or is 0 at an end).
double refine_root(const Segment& seg, double level, double lo, double hi) {
    double flo = seg.at(lo).p - level;
    if (flo == 0) return lo;
    double t = 0.5 * (lo + hi);
    for (int it = 0; it < 100; ++it) {
        const State s = seg.at(t);
        const double f = s.p - level;
        if (f == 0) return t;
        if ((f < 0) == (flo < 0)) {
            lo = t;
            flo = f;
        } else {
            hi = t;
        }
        double tn = (s.v != 0) ? t - f / s.v : 0.5 * (lo + hi);
        if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
        if (std::fabs(tn - t) < 1e-15 * std::max(1.0, std::fabs(t)) || hi - lo < 1e-15) return tn;
        t = tn;
    }
    return t;
}
}  // namespace

double Profile::first_crossing(double level, double t_from) const {
    if (t_from < 0) t_from = 0;
    std::size_t i = segment_index(t_from);
    for (; i < segments_.size(); ++i) {
        const Segment& seg = segments_[i];
        double lo = std::max(0.0, t_from - seg.t0);
        const double hi = seg.duration;
        // Split at interior velocity zeros so each piece is monotone.
        double cuts[4] = {lo, hi, hi, hi};
        int n = 1;
        if (seg.kind == Segment::Kind::Cubic) {
            const double a = seg.start.j / 2, b = seg.start.a, c = seg.start.v;
            double r[2];
            int nr = 0;
            if (a == 0) {
                if (b != 0) r[nr++] = -c / b;
            } else {
                const double disc = b * b - 4 * a * c;
                if (disc >= 0) {
                    const double sq = std::sqrt(disc);
                    const double q = -0.5 * (b + std::copysign(sq, b));
                    r[nr++] = q / a;
                    if (q != 0) r[nr++] = c / q;
                }
            }
            std::sort(r, r + nr);
            for (int k = 0; k < nr; ++k)
                if (r[k] > lo && r[k] < hi) cuts[n++] = r[k];
        } else if (seg.kind == Segment::Kind::SinRamp) {
            const double tz = detail_sin_velocity_zero(seg);
            if (tz > lo && tz < hi) cuts[n++] = tz;
        }
        cuts[n++] = hi;
        for (int k = 0; k + 1 < n; ++k) {
            const double a0 = cuts[k], a1 = cuts[k + 1];
            if (a1 < a0) continue;
            const double f0 = seg.at(a0).p - level, f1 = seg.at(a1).p - level;
            if (f0 == 0) return seg.t0 + a0;
            if ((f0 < 0) != (f1 < 0) || f1 == 0) return seg.t0 + refine_root(seg, level, a0, a1);
        }
    }
    return -1;
}

}  // namespace motorbus::motion

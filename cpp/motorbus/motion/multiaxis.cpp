// Multi-axis planning: time-synchronised and straight-line moves, and the
// split of a path into interpolation segments (integer offsets per period).
#include <algorithm>
#include <cmath>
#include <limits>

#include "motorbus/motion/planner.hpp"

namespace motorbus::motion {

namespace {
void check_sizes(const std::vector<double>& a, const std::vector<double>& b, const std::vector<Limits>& l) {
    if (a.size() != b.size() || a.size() != l.size() || a.empty())
        throw InvalidArgument("multi-axis: start, target and limits need the same non-zero length");
}

// Extends a profile with rest until `duration` so every axis shares one time line.
Profile pad_to(Profile p, double duration) {
    if (p.duration() < duration) {
        const State e = p.final_state();
        p.append_jump(duration - p.duration(), 0.0, 0.0, 0.0);
        p.finish(e.p, 0.0);
    }
    return p;
}
}  // namespace

std::vector<Profile> plan_synchronized(const std::vector<double>& start, const std::vector<double>& target,
                                       const std::vector<Limits>& limits, RampShape shape) {
    check_sizes(start, target, limits);
    std::vector<Profile> out;
    double T = 0;
    for (std::size_t i = 0; i < start.size(); ++i) {
        out.push_back(plan_trapezoid(State{start[i], 0, 0, 0}, target[i], limits[i], shape));
        T = std::max(T, out.back().duration());
    }
    for (std::size_t i = 0; i < start.size(); ++i) {
        const double x = std::fabs(target[i] - start[i]);
        if (x == 0 || out[i].duration() >= T) {
            out[i] = pad_to(out[i], T);
            continue;
        }
        // Rest-to-rest duration with cruise vc: x/vc + vc k, k = 1/2a + 1/2d.
        const double k = 1 / (2 * limits[i].max_acceleration) + 1 / (2 * limits[i].decel());
        const double disc = std::max(0.0, T * T - 4 * k * x);
        const double vc = 2 * x / (T + std::sqrt(disc));
        Limits slow = limits[i];
        slow.max_velocity = vc;
        out[i] = pad_to(plan_trapezoid(State{start[i], 0, 0, 0}, target[i], slow, shape), T);
    }
    return out;
}

std::vector<Profile> plan_straight_line(const std::vector<double>& start, const std::vector<double>& target,
                                        const std::vector<Limits>& limits, RampShape shape) {
    check_sizes(start, target, limits);
    // Path parameter s in [0, 1]; axis i moves dx_i * s.
    Limits ls{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
              std::numeric_limits<double>::infinity(), 0};
    bool any = false;
    for (std::size_t i = 0; i < start.size(); ++i) {
        const double dx = std::fabs(target[i] - start[i]);
        if (dx == 0) continue;
        any = true;
        ls.max_velocity = std::min(ls.max_velocity, limits[i].max_velocity / dx);
        ls.max_acceleration = std::min(ls.max_acceleration, limits[i].max_acceleration / dx);
        ls.max_deceleration = std::min(ls.max_deceleration, limits[i].decel() / dx);
    }
    std::vector<Profile> out;
    if (!any) {
        for (double s : start) out.emplace_back(State{s, 0, 0, 0});
        return out;
    }
    const Profile path = plan_trapezoid(State{0, 0, 0, 0}, 1.0, ls, shape);
    for (std::size_t i = 0; i < start.size(); ++i) {
        const double dx = target[i] - start[i];
        Profile p(State{start[i], 0, 0, 0});
        for (const Segment& s : path.segments()) p.append_jump(s.duration, s.start.v * dx, s.start.a * dx, s.start.j * dx);
        p.finish(target[i], 0.0);
        out.push_back(std::move(p));
    }
    return out;
}

std::vector<std::vector<long long>> split_interpolation(const std::vector<Profile>& axes, int period_ms) {
    if (period_ms < 1) throw LimitExceeded("period_ms", period_ms, 1, "ms per segment");
    if (axes.empty()) throw InvalidArgument("split_interpolation: no axes");
    double T = 0;
    for (const auto& a : axes) T = std::max(T, a.duration());
    const double dt = period_ms / 1000.0;
    const double n_f = std::ceil(T / dt - 1e-12);
    if (n_f > 1e8) throw LimitExceeded("segments", n_f, 1e8, "path too long for the interpolation FIFO stream");
    const auto n = static_cast<std::size_t>(std::max(0.0, n_f));
    std::vector<std::vector<long long>> out(n, std::vector<long long>(axes.size()));
    for (std::size_t j = 0; j < axes.size(); ++j) {
        long long prev = std::llround(axes[j].start_position());
        for (std::size_t k = 0; k < n; ++k) {
            const double t = (k + 1 == n) ? T : dt * static_cast<double>(k + 1);
            const long long cur = std::llround(axes[j].position(t));
            out[k][j] = cur - prev;
            prev = cur;
        }
    }
    return out;
}

std::vector<double> jerk_limited_durations(std::span<const double> rows) {
    constexpr std::size_t kCols = 7;
    if (rows.size() % kCols != 0) throw InvalidArgument("jerk_limited_durations: rows of 7 values");
    std::vector<double> out;
    out.reserve(rows.size() / kCols);
    for (std::size_t i = 0; i < rows.size(); i += kCols) {
        const double* c = rows.data() + i;
        out.push_back(plan_jerk_limited(State{c[0], c[1], c[2], 0}, c[3], Limits{c[4], c[5], 0, c[6]}).duration());
    }
    return out;
}

std::vector<double> synchronized_jerk_limited_durations(std::span<const double> rows) {
    constexpr std::size_t kCols = 15;
    if (rows.size() % kCols != 0)
        throw InvalidArgument("synchronized_jerk_limited_durations: rows of 15 values (3 axes x 5)");
    std::vector<double> out;
    out.reserve(rows.size() / kCols);
    std::vector<double> s(3), t(3);
    std::vector<Limits> l(3);
    for (std::size_t i = 0; i < rows.size(); i += kCols) {
        const double* c = rows.data() + i;
        for (int k = 0; k < 3; ++k) {
            s[k] = c[5 * k];
            t[k] = c[5 * k + 1];
            l[k] = Limits{c[5 * k + 2], c[5 * k + 3], 0, c[5 * k + 4]};
        }
        out.push_back(plan_synchronized_jerk_limited(s, t, l)[0].duration());
    }
    return out;
}

}  // namespace motorbus::motion

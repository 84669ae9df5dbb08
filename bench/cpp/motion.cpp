// Motion benchmarks: plan time (jerk-limited 1-DoF, trapezoid, 3-axis
// synchronised), sample time and integer step-time generation.
//
// The reference (ruckig) is timed from Python in bench/motion.py in the same
// session; this binary prints the C++-side numbers and the ratio against the
// ruckig anchors measured on this machine (issue text): 0.36 us per 1-DoF
// jerk-limited plan, 0.11 us trapezoidal, 2.37 us 3-DoF synchronised, 6 ns per
// sample; Klipper's step solver ~20 ns per step.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;
#include <time.h>

namespace {
volatile double g_sink;

// Thread CPU time, not wall time: the 2-core machine is shared by ~8 builds, so
// wall time mostly measures the scheduler.  Cache effects of the load remain.
double cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

template <class F>
double ns_per(std::size_t n, F&& f) {
    const double t0 = cpu_ns();
    f();
    return (cpu_ns() - t0) / static_cast<double>(n);
}

struct Case {
    State s;
    double target;
    Limits lim;
};

std::vector<Case> cases(std::size_t n, bool moving, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Case> out;
    for (std::size_t i = 0; i < n; ++i) {
        Limits lim{0.05 + 20 * u(rng), 0.05 + 20 * u(rng), 0, 0.05 + 200 * u(rng)};
        const double p0 = 200 * (u(rng) - 0.5);
        const double v0 = moving ? (2 * u(rng) - 1) * lim.max_velocity : 0.0;
        out.push_back({State{p0, v0, 0, 0}, p0 + (u(rng) < 0.5 ? -1 : 1) * std::pow(10.0, -4 + 6 * u(rng)), lim});
    }
    return out;
}
}  // namespace

int main() {
    const std::size_t N = 200000;
    std::printf("motorbus motion benchmark (C++; ruckig timed from Python in bench/motion.py)\n");
    for (bool moving : {false, true}) {
        auto cs = cases(N, moving, moving ? 2 : 1);
        double best = 1e30;
        for (int rep = 0; rep < 3; ++rep) {
            best = std::min(best, ns_per(N, [&] {
                double acc = 0;
                for (const auto& c : cs) acc += plan_jerk_limited(c.s, c.target, c.lim).duration();
                g_sink = acc;
            }));
        }
        std::printf("jerk-limited 1-DoF plan (%s): %.1f ns/plan; ruckig anchor 360 ns -> %.2fx faster\n",
                    moving ? "v0 != 0" : "from rest", best, 360.0 / best);
    }
    for (bool moving : {false, true}) {
        auto cs = cases(N, moving, moving ? 3 : 6);
        double best = 1e30;
        for (int rep = 0; rep < 3; ++rep)
            best = std::min(best, ns_per(N, [&] {
                double acc = 0;
                for (const auto& c : cs) acc += plan_trapezoid(c.s, c.target, c.lim).duration();
                g_sink = acc;
            }));
        std::printf("trapezoid 1-DoF plan (%s): %.1f ns/plan; ruckig anchor 110 ns -> %.2fx faster\n",
                    moving ? "v0 != 0" : "from rest", best, 110.0 / best);
    }
    {
        auto cs = cases(3 * 20000, false, 4);
        double best = 1e30;
        for (int rep = 0; rep < 3; ++rep)
            best = std::min(best, ns_per(20000, [&] {
                double acc = 0;
                for (std::size_t i = 0; i < 20000; ++i) {
                    std::vector<double> s{cs[3 * i].s.p, cs[3 * i + 1].s.p, cs[3 * i + 2].s.p};
                    std::vector<double> t{cs[3 * i].target, cs[3 * i + 1].target, cs[3 * i + 2].target};
                    std::vector<Limits> l{cs[3 * i].lim, cs[3 * i + 1].lim, cs[3 * i + 2].lim};
                    acc += plan_synchronized(s, t, l)[0].duration();
                }
                g_sink = acc;
            }));
        std::printf("3-axis time-synchronised trapezoid plan: %.1f ns/plan\n", best);
        best = 1e30;
        for (int rep = 0; rep < 3; ++rep)
            best = std::min(best, ns_per(20000, [&] {
                double acc = 0;
                for (std::size_t i = 0; i < 20000; ++i) {
                    std::vector<double> s{cs[3 * i].s.p, cs[3 * i + 1].s.p, cs[3 * i + 2].s.p};
                    std::vector<double> t{cs[3 * i].target, cs[3 * i + 1].target, cs[3 * i + 2].target};
                    std::vector<Limits> l{cs[3 * i].lim, cs[3 * i + 1].lim, cs[3 * i + 2].lim};
                    acc += plan_synchronized_jerk_limited(s, t, l)[0].duration();
                }
                g_sink = acc;
            }));
        std::printf("3-DoF jerk-limited time-synchronised plan (from rest): %.1f ns/plan; ruckig anchor 2370 ns -> %.2fx faster\n",
                    best, 2370.0 / best);
    }
    {
        Profile p = plan_jerk_limited(State{0, 0, 0, 0}, 100, Limits{10, 5, 0, 10});
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<double> u(0, p.duration());
        std::vector<double> ts(1000000);
        for (auto& t : ts) t = u(rng);
        double best = 1e30;
        for (int rep = 0; rep < 3; ++rep)
            best = std::min(best, ns_per(ts.size(), [&] {
                double acc = 0;
                for (double t : ts) acc += p.at(t).p;
                g_sink = acc;
            }));
        std::printf("sample at random t (binary search): %.2f ns/sample; ruckig anchor 6 ns -> %.2fx\n", best, 6.0 / best);
        std::vector<double> out(1000000);
        best = 1e30;
        for (int rep = 0; rep < 3; ++rep)
            best = std::min(best, ns_per(out.size(), [&] {
                p.positions(0, p.duration() / 1e6, out.size(), out.data());
                g_sink = out[12345];
            }));
        std::printf("sample on a uniform grid (positions()): %.2f ns/sample\n", best);
    }
    {
        // 1e6 microsteps: trapezoid (closed-form segments) and jerk-limited (cubic segments).
        Profile trap = plan_trapezoid(State{0, 0, 0, 0}, 1e6, Limits{50000, 200000, 0, 0});
        Profile jerk = plan_jerk_limited(State{0, 0, 0, 0}, 1e6, Limits{50000, 200000, 0, 2e6});
        for (auto item : {std::pair{"trapezoid", &trap}, std::pair{"jerk-limited", &jerk}}) {
            const char* name = item.first;
            const Profile* prof = item.second;
            double best = 1e30;
            std::size_t n = 0;
            for (int rep = 0; rep < 3; ++rep)
                best = std::min(best, ns_per(1000000, [&] {
                    auto st = step_times(*prof);
                    n = st.size();
                    g_sink = static_cast<double>(st.t_ns.back());
                }));
            std::printf("integer step times, %s, %zu steps: %.2f ns/step; Klipper anchor ~20 ns -> %.2fx; target <= 10 ns: %s\n",
                        name, n, best, 20.0 / best, best <= 10 ? "met" : "NOT met");
        }
    }
    return 0;
}

// Jerk-limited planner properties and multi-axis planning.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "motorbus/errors.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;

TEST(JerkLimited, BatchDurationsMatchSinglePlans) {
    const std::vector<double> rows = {0, 0, 0, 100, 50, 200, 1000,  //
                                      10, 5, 0, -40, 30, 100, 500};
    auto d = jerk_limited_durations(rows);
    ASSERT_EQ(d.size(), 2u);
    EXPECT_DOUBLE_EQ(d[0], plan_jerk_limited(State{0, 0, 0, 0}, 100, Limits{50, 200, 0, 1000}).duration());
    EXPECT_DOUBLE_EQ(d[1], plan_jerk_limited(State{10, 5, 0, 0}, -40, Limits{30, 100, 0, 500}).duration());
    EXPECT_TRUE(jerk_limited_durations({}).empty());
    EXPECT_THROW(jerk_limited_durations(std::span(rows.data(), 6)), motorbus::InvalidArgument);

    const std::vector<double> sync = {0, 100, 50, 200, 1000, 0, 10, 50, 200, 1000, 5, -20, 40, 100, 800};
    auto s = synchronized_jerk_limited_durations(sync);
    ASSERT_EQ(s.size(), 1u);
    auto p = plan_synchronized_jerk_limited({0, 0, 5}, {100, 10, -20},
                                            {Limits{50, 200, 0, 1000}, Limits{50, 200, 0, 1000}, Limits{40, 100, 0, 800}});
    EXPECT_DOUBLE_EQ(s[0], p[0].duration());
    EXPECT_THROW(synchronized_jerk_limited_durations(std::span(sync.data(), 14)), motorbus::InvalidArgument);
}

TEST(JerkLimited, RampClosedForm) {
    Ramp r = jerk_limited_ramp(0, 10, 5, 10);  // reaches amax: t1 = 0.5, t2 = 1.5
    EXPECT_DOUBLE_EQ(r.t1, 0.5);
    EXPECT_DOUBLE_EQ(r.t2, 1.5);
    EXPECT_DOUBLE_EQ(r.distance, 5.0 * 2.5);
    r = jerk_limited_ramp(0, 1, 5, 10);  // below amax^2/j = 2.5: t1 = sqrt(0.1)
    EXPECT_DOUBLE_EQ(r.t1, std::sqrt(0.1));
    EXPECT_EQ(r.t2, 0);
}

TEST(JerkLimited, RestToRestKnownDuration) {
    // Long move: ramps of 2.5 s each (t1 0.5, t2 1.5, t3 0.5) cover 12.5 each; cruise 75 at 10.
    Profile p = plan_jerk_limited(State{0, 0, 0, 0}, 100, Limits{10, 5, 0, 10});
    EXPECT_NEAR(p.duration(), 2.5 + 7.5 + 2.5, 1e-12);
    EXPECT_EQ(p.end_position(), 100);
    EXPECT_NEAR(p.max_abs_jerk(), 10, 1e-12);
}

TEST(JerkLimited, RandomProperties) {
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 5000; ++i) {
        Limits lim{0.1 + 10 * u(rng), 0.1 + 10 * u(rng), 0, 0.1 + 100 * u(rng)};
        const double v0 = (i % 2) ? (2 * u(rng) - 1) * lim.max_velocity : 0.0;
        const State s{100 * (u(rng) - 0.5), v0, 0, 0};
        const double target = 100 * (u(rng) - 0.5);
        Profile p = plan_jerk_limited(s, target, lim);
        ASSERT_EQ(p.end_position(), target);
        EXPECT_LE(p.max_abs_velocity(), lim.max_velocity * (1 + 1e-9));
        EXPECT_LE(p.max_abs_acceleration(), lim.max_acceleration * (1 + 1e-9));
        EXPECT_LE(p.max_abs_jerk(), lim.max_jerk * (1 + 1e-12));
        const auto& segs = p.segments();
        for (std::size_t k = 1; k < segs.size(); ++k) {
            const State a = segs[k - 1].end(), b = segs[k].start;
            ASSERT_NEAR(a.p, b.p, 1e-9 * std::max(1.0, std::fabs(a.p)));
            ASSERT_NEAR(a.v, b.v, 1e-9 * std::max(1.0, lim.max_velocity));
            ASSERT_NEAR(a.a, b.a, 1e-9 * std::max(1.0, lim.max_acceleration));
        }
        if (!segs.empty()) {
            const State e = segs.back().end();
            EXPECT_NEAR(e.p, target, 1e-7 * std::max(1.0, std::fabs(target)));
            EXPECT_NEAR(e.v, 0, 1e-9 * std::max(1.0, lim.max_velocity));
            EXPECT_NEAR(e.a, 0, 1e-9 * std::max(1.0, lim.max_acceleration));
        }
    }
}

TEST(JerkLimited, StepsOfJerkLimitedMove) {
    Profile p = plan_jerk_limited(State{0, 0, 0, 0}, 50000, Limits{20000, 100000, 0, 2e6});
    auto st = step_times(p);
    ASSERT_EQ(st.size(), 50000u);
    auto secs = step_times_seconds(p);
    for (std::size_t k : {0ul, 10ul, 25000ul, 49999ul}) EXPECT_NEAR(p.position(secs[k]), k + 0.5, 1e-6);
}

TEST(JerkLimited, InitialAccelerationAndErrors) {
    Profile p = plan_jerk_limited(State{0, 1, 2, 0}, 10, Limits{5, 4, 0, 20});
    EXPECT_EQ(p.end_position(), 10);
    EXPECT_NEAR(p.acceleration(0), 2, 1e-12);
    EXPECT_THROW(plan_jerk_limited(State{0, 0, 5, 0}, 1, Limits{5, 4, 0, 20}), LimitExceeded);
    try {
        plan_jerk_limited(State{}, 1, Limits{5, 4, 0, 0});
        FAIL();
    } catch (const LimitExceeded& e) {
        EXPECT_EQ(e.limit, "max_jerk");
    }
}

TEST(MultiAxis, SynchronizedFinishTogether) {
    std::vector<Limits> lim{{100, 1000, 0, 0}, {100, 1000, 0, 0}, {10, 50, 0, 0}};
    auto ps = plan_synchronized({0, 0, 0}, {1000, 100, -20}, lim);
    ASSERT_EQ(ps.size(), 3u);
    for (auto& p : ps) EXPECT_NEAR(p.duration(), ps[0].duration(), 1e-9);
    EXPECT_EQ(ps[1].end_position(), 100);
    EXPECT_EQ(ps[2].end_position(), -20);
    EXPECT_LE(ps[1].max_abs_velocity(), 100);
    // Axis 1 moves only 100 in 10.1 s: its cruise is the smaller root.
    EXPECT_LT(ps[1].max_abs_velocity(), 11);
}

TEST(MultiAxis, StraightLineStaysOnTheLine) {
    std::vector<Limits> lim{{100, 1000, 0, 0}, {50, 1000, 0, 0}};
    auto ps = plan_straight_line({0, 10}, {1000, 510}, lim);
    for (double t = 0; t < ps[0].duration(); t += 0.37) {
        const double s0 = ps[0].position(t) / 1000.0, s1 = (ps[1].position(t) - 10) / 500.0;
        EXPECT_NEAR(s0, s1, 1e-9);
    }
    EXPECT_LE(ps[1].max_abs_velocity(), 50 * (1 + 1e-12));
    EXPECT_EQ(ps[1].end_position(), 510);
}

TEST(MultiAxis, InterpolationSplitReachesTargetsExactly) {
    std::mt19937_64 rng(5);
    std::uniform_int_distribution<int> tgt(-100000, 100000), per(2, 138);
    for (int i = 0; i < 200; ++i) {
        std::vector<double> start{0, 0, 0}, target{double(tgt(rng)), double(tgt(rng)), double(tgt(rng))};
        std::vector<Limits> lim(3, Limits{50000, 200000, 0, 0});
        auto axes = plan_straight_line(start, target, lim);
        const int period = per(rng);
        auto segs = split_interpolation(axes, period);
        for (int j = 0; j < 3; ++j) {
            long long sum = 0;
            for (auto& s : segs) sum += s[j];
            ASSERT_EQ(sum, static_cast<long long>(target[j]));
        }
        EXPECT_NEAR(segs.size() * period / 1000.0, axes[0].duration(), period / 1000.0);
    }
    std::vector<Profile> one{plan_trapezoid(State{}, 10, Limits{1, 1, 0, 0})};
    EXPECT_THROW(split_interpolation(one, 0), LimitExceeded);
    EXPECT_THROW(split_interpolation(one, -5), LimitExceeded);
    // Any period from 1 ms: the range a drive accepts is that drive's check, not the splitter's.
    for (int period : {1, 139, 1000}) {
        long long sum = 0;
        for (auto& s : split_interpolation(one, period)) sum += s[0];
        EXPECT_EQ(sum, 10) << period;
    }
}

TEST(MultiAxis, JerkLimitedSynchronized) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 500; ++i) {
        std::vector<double> s, t;
        std::vector<Limits> lim;
        for (int k = 0; k < 3; ++k) {
            s.push_back(100 * (u(rng) - 0.5));
            t.push_back(s.back() + (u(rng) < 0.1 ? 0.0 : 100 * (u(rng) - 0.5)));
            lim.push_back(Limits{0.1 + 10 * u(rng), 0.1 + 10 * u(rng), 0, 0.1 + 100 * u(rng)});
        }
        auto ps = plan_synchronized_jerk_limited(s, t, lim);
        double T = 0;
        for (int k = 0; k < 3; ++k) T = std::max(T, plan_jerk_limited(State{s[k], 0, 0, 0}, t[k], lim[k]).duration());
        for (int k = 0; k < 3; ++k) {
            ASSERT_NEAR(ps[k].duration(), T, 1e-9 * std::max(1.0, T)) << i << " axis " << k;
            ASSERT_EQ(ps[k].end_position(), t[k]);
            EXPECT_LE(ps[k].max_abs_velocity(), lim[k].max_velocity * (1 + 1e-9));
            EXPECT_LE(ps[k].max_abs_acceleration(), lim[k].max_acceleration * (1 + 1e-9));
            if (ps[k].segments().empty()) {
                EXPECT_EQ(s[k], t[k]);  // nothing moves at all
                continue;
            }
            const State e = ps[k].segments().back().end();
            EXPECT_NEAR(e.p, t[k], 1e-6 * std::max(1.0, std::fabs(t[k]))) << i << " axis " << k;
            EXPECT_NEAR(e.v, 0, 1e-9 * std::max(1.0, lim[k].max_velocity));
        }
    }
}

TEST(JerkLimited, VelocityMode) {
    Profile p = plan_jerk_limited_velocity(State{0, -2, 0, 0}, 8, Limits{10, 5, 0, 10}, 1.0);
    // dv = 10 >= a^2/j = 2.5: t1 = 0.5, t2 = 1.5, t3 = 0.5; then 1 s hold.
    EXPECT_NEAR(p.duration(), 3.5, 1e-12);
    EXPECT_NEAR(p.velocity(3.0), 8, 1e-12);
    EXPECT_NEAR(p.acceleration(1.0), 5, 1e-12);
    EXPECT_EQ(p.final_state().v, 8);
    EXPECT_THROW(plan_jerk_limited_velocity(State{}, 11, Limits{10, 5, 0, 10}), LimitExceeded);
}

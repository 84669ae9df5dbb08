// Generic planners and step times: closed-form checks and random property tests.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;

namespace {
// Position continuity at every segment joint; velocity continuity unless allowed to jump.
void expect_continuous(const Profile& p, bool velocity_too, double tol = 1e-6) {
    const auto& segs = p.segments();
    for (std::size_t i = 1; i < segs.size(); ++i) {
        const State a = segs[i - 1].end(), b = segs[i].start;
        EXPECT_NEAR(a.p, b.p, tol * std::max(1.0, std::fabs(a.p))) << "segment " << i;
        if (velocity_too) {
            EXPECT_NEAR(a.v, b.v, tol * std::max(1.0, std::fabs(a.v))) << "segment " << i;
        }
    }
    if (!segs.empty()) {
        EXPECT_NEAR(segs.back().end().p, p.end_position(), tol * std::max(1.0, std::fabs(p.end_position())));
    }
}
}  // namespace

TEST(Profile, TrapezoidRestToRestClosedForm) {
    Limits lim{100, 1000, 0, 0};
    Profile p = plan_trapezoid(State{0, 0, 0, 0}, 1000, lim);
    // 0.1 s ramps (5 units each), cruise 990 units at 100 -> 9.9 s; total 10.1 s
    EXPECT_NEAR(p.duration(), 10.1, 1e-12);
    EXPECT_EQ(p.end_position(), 1000);
    EXPECT_NEAR(p.position(0.1), 5.0, 1e-12);
    EXPECT_NEAR(p.velocity(5.0), 100.0, 1e-12);
    EXPECT_NEAR(p.acceleration(0.05), 1000.0, 1e-12);
    EXPECT_NEAR(p.acceleration(10.05), -1000.0, 1e-12);
}

TEST(Profile, TriangularWhenShort) {
    Limits lim{100, 1000, 500, 0};
    // x = vp^2/2a + vp^2/2d = vp^2 (1/2000 + 1/1000) -> vp^2 = 4/0.0015
    Profile p = plan_trapezoid(State{0, 0, 0, 0}, 4, lim);
    const double vp = std::sqrt(4 / 0.0015);
    EXPECT_NEAR(p.duration(), vp / 1000 + vp / 500, 1e-12);
    EXPECT_NEAR(p.max_abs_velocity(), vp, 1e-9);
    EXPECT_EQ(p.end_position(), 4.0);
}

TEST(Profile, SCurveKeepsRampTimes) {
    Limits lim{100, 1000, 0, 0};
    Profile t = plan_trapezoid(State{0, 0, 0, 0}, 1000, lim, RampShape::Trapezoid);
    Profile s = plan_trapezoid(State{0, 0, 0, 0}, 1000, lim, RampShape::SCurve);
    EXPECT_NEAR(s.duration(), t.duration(), 1e-12);
    EXPECT_NEAR(s.position(0.1), t.position(0.1), 1e-9);  // same distance per ramp
    EXPECT_NEAR(s.acceleration(0.05), 2000.0, 1e-9);       // peak = 2x average
    EXPECT_NEAR(s.acceleration(0.0), 0.0, 1e-12);
    expect_continuous(s, true);
}

TEST(Profile, ReversesWhenMovingAway) {
    Limits lim{100, 1000, 0, 0};
    Profile p = plan_trapezoid(State{0, -50, 0, 0}, 10, lim);
    EXPECT_NEAR(p.velocity(0), -50, 1e-12);
    EXPECT_NEAR(p.velocity(0.05), 0, 1e-9);
    EXPECT_EQ(p.end_position(), 10);
    expect_continuous(p, true);
}

TEST(Profile, OvershootStopsAndReturns) {
    Limits lim{100, 1000, 0, 0};
    // Stopping from 100 needs 5 units: a target 1 unit ahead is overshot.
    Profile p = plan_trapezoid(State{0, 100, 0, 0}, 1, lim);
    EXPECT_NEAR(p.position(0.1), 5.0, 1e-9);
    EXPECT_EQ(p.end_position(), 1.0);
    EXPECT_LT(p.velocity(0.15), 0);
}

TEST(Profile, ImpossibleRequestNamesLimit) {
    try {
        plan_velocity(State{}, 150, Limits{100, 1000, 0, 0});
        FAIL() << "expected LimitExceeded";
    } catch (const LimitExceeded& e) {
        EXPECT_EQ(e.limit, "max_velocity");
        EXPECT_DOUBLE_EQ(e.excess(), 50.0);
        EXPECT_NE(std::string(e.what()).find("by 50"), std::string::npos) << e.what();
    }
    EXPECT_THROW(plan_trapezoid(State{}, 1, Limits{0, 1, 0, 0}), LimitExceeded);
    EXPECT_THROW(plan_trapezoid(State{}, NAN, Limits{1, 1, 0, 0}), motorbus::InvalidArgument);
}

TEST(Profile, VelocityModeThroughZero) {
    Limits lim{100, 1000, 500, 0};
    Profile p = plan_velocity(State{0, 50, 0, 0}, -100, lim, 1.0);
    // 50 -> 0 with decel 500 (0.1 s), 0 -> -100 with accel 1000 (0.1 s), hold 1 s.
    EXPECT_NEAR(p.duration(), 1.2, 1e-12);
    EXPECT_NEAR(p.velocity(0.1), 0, 1e-9);
    EXPECT_NEAR(p.velocity(0.5), -100, 1e-9);
    EXPECT_EQ(p.final_state().v, -100);
}

TEST(Profile, SampleMatrix) {
    Profile p = plan_trapezoid(State{0, 0, 0, 0}, 1000, Limits{100, 1000, 0, 0});
    auto m = p.sample(11);
    ASSERT_EQ(m.rows(), 11);
    EXPECT_EQ(m(0, 0), 0.0);
    EXPECT_EQ(m(10, 0), p.duration());
    EXPECT_EQ(m(10, 1), 1000.0);
    EXPECT_NEAR(m(5, 2), 100.0, 1e-9);
    EXPECT_THROW(p.sample(1), motorbus::InvalidArgument);
}

TEST(Profile, FirstCrossing) {
    Profile p = plan_trapezoid(State{0, 0, 0, 0}, 1000, Limits{100, 1000, 0, 0});
    EXPECT_NEAR(p.first_crossing(5.0), 0.1, 1e-12);
    EXPECT_NEAR(p.first_crossing(500.0), 0.1 + 4.95, 1e-12);
    EXPECT_EQ(p.first_crossing(2000.0), -1.0);
}

// Property test: random starts, targets and limits.
TEST(ProfileProperty, RandomTrapezoidsAndSCurves) {
    std::mt19937_64 rng(1234);
    std::uniform_real_distribution<double> pos(-1e4, 1e4), lvel(1, 1e3), lacc(1, 1e4), frac(-1.5, 1.5);
    for (int i = 0; i < 3000; ++i) {
        Limits lim{lvel(rng), lacc(rng), (i % 3 == 0) ? lacc(rng) : 0.0, 0};
        const double v0 = frac(rng) * lim.max_velocity;
        const State s{std::round(pos(rng)), v0, 0, 0};
        const double target = std::round(pos(rng));
        for (RampShape shape : {RampShape::Trapezoid, RampShape::SCurve}) {
            Profile p = plan_trapezoid(s, target, lim, shape);
            ASSERT_EQ(p.end_position(), target);
            ASSERT_EQ(p.final_state().v, 0.0);
            expect_continuous(p, true, 1e-7);
            // The start velocity may exceed the limit; the plan never goes above either.
            EXPECT_LE(p.max_abs_velocity(), std::max(lim.max_velocity, std::fabs(v0)) * (1 + 1e-9));
            const double amax = std::max(lim.max_acceleration, lim.decel()) * (shape == RampShape::SCurve ? 2 : 1);
            EXPECT_LE(p.max_abs_acceleration(), amax * (1 + 1e-9));
            if (v0 == 0) {
                // Integer step sequence: exactly the right count, strictly increasing times.
                StepTimes st = step_times(p);
                long net = 0;
                for (auto d : st.dir) net += d;
                EXPECT_EQ(net, static_cast<long>(target - s.p));
                for (std::size_t k = 1; k < st.size(); ++k) ASSERT_LT(st.t_ns[k - 1], st.t_ns[k]);
            }
        }
    }
}

TEST(Steps, ExactCountAndNoDrift) {
    Profile p = plan_trapezoid(State{0, 0, 0, 0}, 100000, Limits{20000, 100000, 0, 0});
    StepTimes st = step_times(p, 1000);
    ASSERT_EQ(st.size(), 100000u);
    for (auto d : st.dir) ASSERT_EQ(d, 1);
    // Every step fires where the position crosses k + 1/2: check far into the move.
    auto secs = step_times_seconds(p);
    for (std::size_t k : {0ul, 1ul, 999ul, 50000ul, 99999ul}) {
        EXPECT_NEAR(p.position(secs[k]), static_cast<double>(k) + 0.5, 1e-7) << k;
        EXPECT_NEAR(static_cast<double>(st.t_ns[k] - 1000), secs[k] * 1e9, 0.51);
    }
    // Cruise at 20000 steps/s: exactly 50 us apart.
    EXPECT_NEAR(secs[50001] - secs[50000], 50e-6, 1e-12);
}

TEST(Steps, ReversalCountsBothWays) {
    Profile p = plan_trapezoid(State{0, 100, 0, 0}, -3, Limits{100, 1000, 0, 0});
    auto st = step_times(p);
    long net = 0;
    int ups = 0;
    for (auto d : st.dir) {
        net += d;
        ups += d > 0;
    }
    EXPECT_EQ(net, -3);
    EXPECT_EQ(ups, 5);  // overshoots to +5 before coming back
}

TEST(Steps, HostileHugeMoveIsBounded) {
    Profile p = plan_trapezoid(State{0, 0, 0, 0}, 1e12, Limits{1e9, 1e9, 0, 0});
    EXPECT_THROW(step_times(p, 0, 1000), motorbus::InvalidArgument);
}

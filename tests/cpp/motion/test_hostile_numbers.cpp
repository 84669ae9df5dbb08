// Hostile numeric inputs (NaN, inf, negative, huge, tiny) for every planner and
// drive model: a typed error or a valid profile, never a crash, a hang or
// unbounded memory; and the next valid request still works.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "hostile.hpp"
#include "motorbus/motion/cia402_profile.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;

using motorbus::test::kValues;
using motorbus::test::survives;

TEST(HostileNumbers, PlannersRefuseOrPlan) {
    std::mt19937_64 rng(3);
    std::uniform_int_distribution<std::size_t> pick(0, std::size(kValues) - 1);
    auto r = [&] { return kValues[pick(rng)]; };
    for (int i = 0; i < 4000; ++i) {
        const State s{r(), r(), r(), 0};
        const double tgt = r();
        const Limits lim{r(), r(), r(), r()};
        survives([&] { return plan_trapezoid(s, tgt, lim); });
        survives([&] { return plan_trapezoid(s, tgt, lim, RampShape::SCurve); });
        survives([&] { return plan_velocity(s, tgt, lim, std::fabs(r())); });
        survives([&] { return plan_jerk_limited(s, tgt, lim); });
    }
    // The next valid request still works.
    EXPECT_NEAR(plan_jerk_limited(State{}, 100, Limits{10, 5, 0, 10}).duration(), 12.5, 1e-12);
}

TEST(HostileNumbers, Cia402Model) {
    for (double x : kValues) {
        Cia402ProfileParams c;
        c.profile_velocity = x;
        survives([&] { return cia402_position_profile(State{}, 100, c); });
    }
}

TEST(HostileNumbers, StepTimesBoundedAndInterpolationBounded) {
    Profile huge = plan_trapezoid(State{}, 1e15, Limits{1e12, 1e12, 0, 0});
    EXPECT_THROW(step_times(huge, 0, 1'000'000), motorbus::InvalidArgument);
    std::vector<Profile> axes{plan_trapezoid(State{}, 1e6, Limits{1e-3, 1, 0, 0})};  // ~1e9 s long
    EXPECT_THROW(split_interpolation(axes, 2), LimitExceeded);
    Profile ok = plan_trapezoid(State{}, 10, Limits{10, 100, 0, 0});
    EXPECT_EQ(step_times(ok).size(), 10u);
}

#include <gtest/gtest.h>

#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;

TEST(Profile, TrapezoidRestToRest) {
    Limits lim{100, 1000, 0, 0};
    Profile p = plan_trapezoid(State{0, 0, 0, 0}, 1000, lim);
    // 0.1 s ramp (5 units each), cruise 990 units at 100 -> 9.9 s; total 10.1 s
    EXPECT_NEAR(p.duration(), 10.1, 1e-12);
    EXPECT_EQ(p.end_position(), 1000);
    EXPECT_NEAR(p.position(0.1), 5.0, 1e-12);
    EXPECT_NEAR(p.velocity(5.0), 100.0, 1e-12);
}

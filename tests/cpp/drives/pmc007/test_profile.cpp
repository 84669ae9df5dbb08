// CQPUSI PMC007 profile model: gears, microstepping, start/stop speeds.
#include <gtest/gtest.h>

#include <cmath>

#include "../../motion/hostile.hpp"
#include "motorbus/drives/pmc007/profile.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;
using namespace motorbus::pmc007;

TEST(Pmc007, GearTableAndMicrostepping) {
    EXPECT_EQ(gear_acceleration(1), 77440);
    EXPECT_EQ(gear_acceleration(8), 5210);
    EXPECT_TRUE(std::isinf(gear_acceleration(0)));
    try {
        gear_acceleration(9);
        FAIL();
    } catch (const LimitExceeded& e) {
        EXPECT_DOUBLE_EQ(e.excess(), 1);
    }
    EXPECT_EQ(microsteps(0), 1);
    EXPECT_EQ(microsteps(256), 256);
    EXPECT_THROW(microsteps(3), LimitExceeded);
    EXPECT_DOUBLE_EQ(convert_position(1600, 16, 32), 3200);
}
TEST(Pmc007, SCurveWithStartAndStopSpeed) {
    ProfileParams p;
    p.speed = 5610;
    p.start_speed = 400;
    p.stop_speed = 200;
    p.accel_gear = 8;  // 5210 pps^2: 400 -> 5610 in 1 s
    p.decel_gear = 8;
    Profile prof = position_profile(State{}, 20000, p);
    EXPECT_NEAR(prof.velocity(1e-12), 400, 1e-6);
    EXPECT_NEAR(prof.velocity(1.0), 5610, 1e-6);
    EXPECT_NEAR(prof.acceleration(0.5), 2 * 5210, 1e-6);  // S-curve peak
    EXPECT_EQ(prof.end_position(), 20000);
    EXPECT_NEAR(prof.segments().back().end().v, 200, 1e-6);
    EXPECT_EQ(step_times(prof).size(), 20000u);
    Profile sp = speed_profile(State{}, -3000, p, 1.0);
    EXPECT_NEAR(sp.velocity(sp.duration() - 0.5), -3000, 1e-9);
}
TEST(Pmc007, GearZeroIsStartStop) {
    ProfileParams p;
    p.speed = 1000;
    Profile prof = position_profile(State{}, 500, p);
    EXPECT_NEAR(prof.duration(), 0.5, 1e-12);
    EXPECT_EQ(prof.end_position(), 500);
}

TEST(HostileNumbers, Pmc007Model) {
    for (double x : motorbus::test::kValues) {
        ProfileParams pm;
        pm.speed = x;
        motorbus::test::survives([&] { return position_profile(State{}, 100, pm); });
    }
}

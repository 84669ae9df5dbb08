// PMC007, CiA 402 and UNITEK profile models.
#include <gtest/gtest.h>

#include <cmath>

#include "motorbus/motion/cia402_profile.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;




TEST(Cia402, LinearAndSin2) {
    Cia402ProfileParams p;
    p.profile_velocity = 1000;
    p.profile_acceleration = 10000;
    p.profile_deceleration = 10000;
    Profile lin = cia402_position_profile(State{}, 10000, p);
    EXPECT_NEAR(lin.duration(), 10.1, 1e-9);
    p.motion_profile_type = 1;
    Profile sin = cia402_position_profile(State{}, 10000, p);
    EXPECT_NEAR(sin.duration(), 10.2, 1e-9);  // ramps twice as long, peak = 6083h
    EXPECT_NEAR(sin.max_abs_acceleration(), 10000, 1e-6);
    EXPECT_NEAR(sin.acceleration(0.1), 10000, 1e-6);
    EXPECT_NEAR(sin.acceleration(0.0), 0, 1e-9);
    EXPECT_EQ(sin.end_position(), 10000);
    auto st = step_times(sin);
    EXPECT_EQ(st.size(), 10000u);
    for (std::size_t k = 1; k < st.size(); ++k) ASSERT_LT(st.t_ns[k - 1], st.t_ns[k]);
    p.motion_profile_type = 3;
    EXPECT_THROW(cia402_position_profile(State{}, 1, p), LimitExceeded);
}

TEST(Cia402, SetPointHandshake) {
    Cia402ProfileParams p;
    p.profile_velocity = 1000;
    p.profile_acceleration = 10000;
    p.profile_deceleration = 10000;
    Cia402ProfilePosition pp(p);
    EXPECT_TRUE(pp.new_setpoint(0, 5000));
    // Single set-point: the next one waits for the first to finish.
    EXPECT_TRUE(pp.new_setpoint(1.0, 0));
    EXPECT_TRUE(pp.setpoint_pending());
    EXPECT_FALSE(pp.new_setpoint(1.5, 100));  // buffer full: not acknowledged
    EXPECT_FALSE(pp.target_reached(5.0));
    const Profile& prof = pp.profile();
    EXPECT_NEAR(prof.position(5.1), 5000, 1e-9);  // stopped at the first target
    EXPECT_EQ(prof.end_position(), 0);
    EXPECT_NEAR(prof.duration(), 10.2, 1e-9);
    // Change set immediately: replaces the move now.
    Cia402ProfilePosition im(p);
    im.new_setpoint(0, 5000);
    im.new_setpoint(1.0, 2000, false, true);
    EXPECT_EQ(im.profile().end_position(), 2000);
    EXPECT_LT(im.profile().duration(), 5.1);
    // Set of set-points with change on set-point: passes through without stopping.
    Cia402ProfilePosition cs(p);
    cs.new_setpoint(0, 5000);
    cs.new_setpoint(1.0, 8000, false, false, true);
    EXPECT_NEAR(cs.profile().velocity(5.05), 1000, 1e-9);
    EXPECT_EQ(cs.profile().end_position(), 8000);
    EXPECT_NEAR(cs.profile().duration(), 8.1, 1e-9);
    // Relative set-point adds to the current target.
    Cia402ProfilePosition rel(p);
    rel.new_setpoint(0, 100);
    rel.new_setpoint(10, 50, true);
    EXPECT_EQ(rel.profile().end_position(), 150);
}

TEST(Cia402, VelocityAndQuickStop) {
    Cia402ProfileParams p;
    p.profile_acceleration = 1000;
    p.profile_deceleration = 500;
    p.quick_stop_deceleration = 5000;
    Profile v = cia402_velocity_profile(State{0, 100, 0, 0}, -100, p, 1.0);
    EXPECT_NEAR(v.duration(), 0.2 + 0.1 + 1.0, 1e-9);
    Profile q = cia402_quick_stop_profile(State{0, 1000, 0, 0}, p);
    EXPECT_NEAR(q.duration(), 0.2, 1e-12);
    EXPECT_NEAR(q.end_position(), 100, 1e-9);
}


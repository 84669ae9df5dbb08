// PMC007, CiA 402 and UNITEK profile models.
#include <gtest/gtest.h>

#include <cmath>

#include "motorbus/motion/cia402_profile.hpp"
#include "motorbus/motion/pmc007_profile.hpp"
#include "motorbus/motion/steps.hpp"
#include "motorbus/motion/unitek_profile.hpp"

using namespace motorbus::motion;

TEST(Pmc007, GearTableAndMicrostepping) {
    EXPECT_EQ(pmc007_gear_acceleration(1), 77440);
    EXPECT_EQ(pmc007_gear_acceleration(8), 5210);
    EXPECT_TRUE(std::isinf(pmc007_gear_acceleration(0)));
    try {
        pmc007_gear_acceleration(9);
        FAIL();
    } catch (const LimitExceeded& e) {
        EXPECT_DOUBLE_EQ(e.excess(), 1);
    }
    EXPECT_EQ(pmc007_microsteps(0), 1);
    EXPECT_EQ(pmc007_microsteps(256), 256);
    EXPECT_THROW(pmc007_microsteps(3), LimitExceeded);
    EXPECT_DOUBLE_EQ(pmc007_convert_position(1600, 16, 32), 3200);
}

TEST(Pmc007, SCurveWithStartAndStopSpeed) {
    Pmc007ProfileParams p;
    p.speed = 5610;
    p.start_speed = 400;
    p.stop_speed = 200;
    p.accel_gear = 8;  // 5210 pps^2: 400 -> 5610 in 1 s
    p.decel_gear = 8;
    Profile prof = pmc007_position_profile(State{}, 20000, p);
    EXPECT_NEAR(prof.velocity(1e-12), 400, 1e-6);
    EXPECT_NEAR(prof.velocity(1.0), 5610, 1e-6);
    EXPECT_NEAR(prof.acceleration(0.5), 2 * 5210, 1e-6);  // S-curve peak
    EXPECT_EQ(prof.end_position(), 20000);
    EXPECT_NEAR(prof.segments().back().end().v, 200, 1e-6);
    EXPECT_EQ(step_times(prof).size(), 20000u);
    Profile sp = pmc007_speed_profile(State{}, -3000, p, 1.0);
    EXPECT_NEAR(sp.velocity(sp.duration() - 0.5), -3000, 1e-9);
}

TEST(Pmc007, GearZeroIsStartStop) {
    Pmc007ProfileParams p;
    p.speed = 1000;
    Profile prof = pmc007_position_profile(State{}, 500, p);
    EXPECT_NEAR(prof.duration(), 0.5, 1e-12);
    EXPECT_EQ(prof.end_position(), 500);
}

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

TEST(Unitek, RampFromAccRegister) {
    UnitekRampParams p;
    p.n_max_rpm = 3000;
    p.acc_ramp_ms = 1000;  // Example 6: 0x35 = 0x03E8
    p.dec_ramp_ms = 500;
    // 10 % speed (3277 num, Example 3) takes 10 % of the ramp.
    Profile prof = unitek_speed_profile(State{}, 3277, p, 1.0);
    EXPECT_NEAR(prof.duration(), 0.1 * 3277 / 3276.7 + 1.0, 1e-9);
    EXPECT_NEAR(prof.final_state().v, unitek_num_to_counts_per_s(3277, p), 1e-9);
    EXPECT_NEAR(unitek_num_to_counts_per_s(32767, p), 3000.0 / 60 * 65536, 1e-6);
    Profile down = unitek_speed_profile(State{0, unitek_num_to_counts_per_s(32767, p), 0, 0}, 0, p, 0);
    EXPECT_NEAR(down.duration(), 0.5, 1e-12);
    p.acc_ramp_ms = 40000;
    EXPECT_THROW(unitek_speed_profile(State{}, 1, p, 0), LimitExceeded);
}

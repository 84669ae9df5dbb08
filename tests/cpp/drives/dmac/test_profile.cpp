// Midi DMAC profile model: the manual's numbers as tests.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../../motion/hostile.hpp"
#include "motorbus/drives/dmac/profile.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;
using namespace motorbus::dmac;

// ---- DMAC ---------------------------------------------------------------------------

TEST(Dmac, HalfSecondExample) {
    // #ACCEL_TIME 1000 ms, #HIGH_SPEED 60000 (600 rpm): MOVE_SPEED 30000 -> 0.5 s.
    ProfileParams p;
    p.accel_time_ms = 1000;
    p.high_speed = 60000;
    EXPECT_DOUBLE_EQ(ramp_time(p, 0, 30000), 0.5);
    Profile s = speed_profile(State{}, 30000, p, 1.0);
    EXPECT_NEAR(s.duration(), 1.5, 1e-12);
    EXPECT_NEAR(s.velocity(0.5), speed_to_inc_per_s(30000), 1e-9);  // 300 rpm = 50000 inc/s
    EXPECT_NEAR(s.velocity(0.5), 50000, 1e-9);
    // Proportional in the other direction and for partial changes.
    EXPECT_DOUBLE_EQ(ramp_time(p, 60000, 30000), 0.5);
    EXPECT_DOUBLE_EQ(ramp_time(p, 30000, -30000), 1.0);
}

TEST(Dmac, MoveSpeedClampedToHighSpeed) {
    Motion m;
    m.move_speed(0, 400000);
    EXPECT_NEAR(m.profile().velocity(5.0), speed_to_inc_per_s(60000), 1e-9);
    EXPECT_TRUE(m.moving(100.0));
    m.stop(10.0);
    EXPECT_NEAR(m.profile().duration(), 11.0, 1e-9);  // DECEL_TIME 1 s from HIGH_SPEED
    EXPECT_FALSE(m.moving(11.0));
}

TEST(Dmac, PositionMoveLowSpeedAtLastTenthTurn) {
    ProfileParams p;  // factory: HS 60000, LS 6000, 1000 ms ramps
    Profile prof = position_profile(State{}, 100000, p);
    EXPECT_EQ(prof.end_position(), 100000);
    const double t_via = prof.first_crossing(99000);
    ASSERT_GT(t_via, 0);
    EXPECT_NEAR(prof.velocity(t_via), speed_to_inc_per_s(6000), 1e-6);  // 10000 inc/s
    // Velocity proportional to the error inside the last 0.1 turn.
    const double t_half = prof.first_crossing(99500);
    EXPECT_NEAR(prof.velocity(t_half), 5000, 1e-6);
    // Approach time: tau (ln 1000 + 1), tau = 1000 / 10000 s.
    EXPECT_NEAR(prof.duration() - t_via, 0.1 * (std::log(1000.0) + 1), 1e-9);
    EXPECT_LE(prof.max_abs_velocity(), 100000 * (1 + 1e-12));
    auto st = step_times(prof);
    EXPECT_EQ(st.size(), 100000u);
    for (std::size_t k = 1; k < st.size(); ++k) ASSERT_LT(st.t_ns[k - 1], st.t_ns[k]);
}

TEST(Dmac, ShortMoveIsApproachOnly) {
    ProfileParams p;
    Profile prof = position_profile(State{0, 0, 0, 0}, -500, p);
    EXPECT_EQ(prof.end_position(), -500);
    EXPECT_NEAR(prof.velocity(1e-9), -5000, 1e-3);
}

TEST(Dmac, MoveWhileMovingAndLimits) {
    Motion m;
    m.move_to(0, 200000);
    m.move_to(1.0, 0);  // reverse mid-move
    EXPECT_EQ(m.profile().end_position(), 0);
    m.move_on(m.profile().duration() + 1, -5000);  // the manual's MOVE_ON -5000: half a turn CCW
    EXPECT_EQ(m.profile().end_position(), -5000);
    ProfileParams bad;
    bad.high_speed = 400001;
    try {
        bad.validate();
        FAIL();
    } catch (const LimitExceeded& e) {
        EXPECT_EQ(e.limit, "#HIGH_SPEED");
        EXPECT_DOUBLE_EQ(e.excess(), 1.0);
    }
    bad = ProfileParams{};
    bad.accel_time_ms = 12001;
    EXPECT_THROW(bad.validate(), LimitExceeded);
}

TEST(Dmac, SCurveSameTimes) {
    ProfileParams p;
    Profile t = position_profile(State{}, 50000, p);
    p.s_curve = true;
    Profile s = position_profile(State{}, 50000, p);
    EXPECT_NEAR(t.duration(), s.duration(), 1e-9);
    EXPECT_EQ(s.end_position(), 50000);
}

TEST(Dmac, StartStopWithZeroRampTimes) {
    ProfileParams p;
    p.accel_time_ms = 0;
    p.decel_time_ms = 0;
    Profile prof = position_profile(State{}, 20000, p);
    EXPECT_EQ(prof.end_position(), 20000);
    EXPECT_NEAR(prof.velocity(1e-6), 100000, 1e-6);
}

TEST(Dmac, MoveOnFromInitialPosition) {
    Motion m(ProfileParams{}, 500);
    m.move_on(0, 100);
    EXPECT_EQ(m.profile().end_position(), 600);
    EXPECT_EQ(m.target(), 600);
}

TEST(HostileNumbers, DmacModel) {
    for (double x : motorbus::test::kValues) {
        motorbus::test::survives([&] { return position_profile(State{}, x, ProfileParams{}); });
        motorbus::test::survives([&] { return speed_profile(State{}, x, ProfileParams{}, 1.0); });
    }
}

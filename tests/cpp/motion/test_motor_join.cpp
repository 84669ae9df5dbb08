// MotorModel::command_from: a planner that keeps one profile across commands
// hands the model its whole profile and the model plays it from `elapsed` on.
#include <gtest/gtest.h>

#include <cmath>

#include "motorbus/motion/motor_model.hpp"

using namespace motorbus;
using namespace motorbus::motion;

namespace {
// 0..1 s: accelerate at 2000 steps/s^2 to 2000 steps/s (1000 steps), then
// cruise 1 s (2000 steps), end at 3000.
Profile ramp_then_cruise() {
    Profile q(State{0, 0, 0, 0});
    q.append_jump(1.0, 0, 2000, 0).append_jump(1.0, 2000, 0, 0).finish(3000, 0);
    return q;
}
}  // namespace

TEST(MotorModelJoin, PlaysTheProfileFromElapsedWithPositionContinuity) {
    SimClock clock;
    MotorConfig cfg;
    cfg.steps_per_rev = cfg.counts_per_rev = 10000;
    MotorModel m(clock, cfg);
    m.set_pulse_position(500);  // the drive's counter already reads 500
    // Join half-way through the ramp: position 250, velocity 1000 in the profile.
    m.command_from(ramp_then_cruise(), 0.5);
    EXPECT_TRUE(m.moving());
    EXPECT_DOUBLE_EQ(m.commanded_velocity(), 1000.0);
    EXPECT_DOUBLE_EQ(m.pulse_position(), 500.0);  // no jump: the profile is shifted to where the rotor is
    clock.advance(500'000'000);                  // profile t = 1.0 s: end of the ramp
    m.update();
    EXPECT_NEAR(m.pulse_position(), 500.0 + 1000 - 250, 1e-6);
    EXPECT_NEAR(m.velocity(), 2000.0, 1e-9);
    EXPECT_EQ(m.encoder(), 750);  // physical 750 at 1:1, no encoder offset
    Nanos done_at = -1;
    m.add_listener([&](const MotorEvent& e) {
        if (e.kind == MotorEvent::Kind::ProfileDone) done_at = e.t;
    });
    clock.advance(2'000'000'000);
    m.update();
    EXPECT_FALSE(m.moving());
    EXPECT_EQ(done_at, 1'500'000'000);  // 1.5 s after the join (the profile lasts 2 s)
    EXPECT_NEAR(m.pulse_position(), 500.0 + 3000 - 250, 1e-6);
    EXPECT_EQ(m.velocity(), 0.0);
}

TEST(MotorModelJoin, ElapsedPastTheEndIsAtRestAndBadElapsedThrows) {
    SimClock clock;
    MotorModel m(clock, MotorConfig{});
    m.command_from(ramp_then_cruise(), 5.0);
    EXPECT_FALSE(m.moving());
    EXPECT_EQ(m.commanded_position(), 0.0);  // joined at the final state, where the rotor already is
    EXPECT_THROW(m.command_from(ramp_then_cruise(), -1.0), InvalidArgument);
    EXPECT_THROW(m.command_from(ramp_then_cruise(), std::nan("")), InvalidArgument);
    EXPECT_THROW(m.command_from(ramp_then_cruise(), 1e300), InvalidArgument);
}

TEST(MotorModelJoin, LimitSwitchEventsStillExactAfterAJoin) {
    SimClock clock;
    MotorConfig cfg;
    cfg.steps_per_rev = cfg.counts_per_rev = 10000;
    cfg.plus_limit = SwitchConfig{true, 1500, 0, false};
    MotorModel m(clock, cfg);
    Nanos hit = -1;
    m.add_listener([&](const MotorEvent& e) {
        if (e.kind == MotorEvent::Kind::PlusLimitOn) {
            hit = e.t;
            m.halt(e.t);
        }
    });
    m.command_from(ramp_then_cruise(), 1.0);  // cruising at 2000 steps/s from physical 0
    clock.advance(2'000'000'000);
    m.update();
    EXPECT_NEAR(static_cast<double>(hit), 750'000'000.0, 2.0);  // 1500 steps at 2000 steps/s
    EXPECT_NEAR(m.physical_position(), 1500.0, 1e-3);
    EXPECT_FALSE(m.moving());
    EXPECT_TRUE(m.plus_limit_active());
}

// With a units ratio (the Arcus sim's 0.8 steps per count under StepNLoop) the
// join keeps the drive's counter continuous and the rotor moves ratio x units.
TEST(MotorModelJoin, ContinuityIsInTheDrivesUnitsWhenTheyAreNotSteps) {
    SimClock clock;
    MotorModel m(clock, MotorConfig{});
    m.set_steps_per_unit(0.8);
    m.set_pulse_position(1000);
    m.command(ramp_then_cruise());  // 3000 units = 2400 steps: units and steps now differ
    clock.advance(3'000'000'000);
    m.update();
    ASSERT_NEAR(m.pulse_position(), 4000.0, 1e-6);
    ASSERT_NEAR(m.physical_position(), 2400.0, 1e-6);
    m.command_from(ramp_then_cruise(), 1.0);  // join the cruise: 2000 units/s for 1 s
    EXPECT_NEAR(m.pulse_position(), 4000.0, 1e-6);   // no jump in the drive's counter
    EXPECT_NEAR(m.physical_position(), 2400.0, 1e-6);
    clock.advance(1'000'000'000);
    m.update();
    EXPECT_NEAR(m.pulse_position(), 6000.0, 1e-6);
    EXPECT_NEAR(m.physical_position(), 4000.0, 1e-6);  // + 2000 units x 0.8 steps per unit
    EXPECT_FALSE(m.moving());
}

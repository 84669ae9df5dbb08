// canopen::Cia402Axis (the CiA 402 device on a motor model) and Cia402SetPoints
// (the profile-position handshake it shares with the DMX-CAN's front end), on a
// SimClock the tests advance: positions, statusword bits and error codes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "motorbus/canopen/cia402_axis.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::canopen;

namespace {

constexpr std::uint16_t kEnable = 0x000F, kNew = 0x0010, kImmediate = 0x0020, kRelative = 0x0040, kHaltBit = 0x0100;

struct AxisRig : ::testing::Test {
    SimClock clock{1'000'000'000};
    motion::MotorModel motor{clock, config()};
    Cia402Axis axis{motor, clock};

    static motion::MotorConfig config() {
        motion::MotorConfig c;
        c.steps_per_rev = c.counts_per_rev = 3200;
        c.home = motion::SwitchConfig{true, 1000, 1400, false};
        c.minus_limit = motion::SwitchConfig{true, -100000, 0, false};
        c.plus_limit = motion::SwitchConfig{true, 100000, 0, false};
        return c;
    }
    void SetUp() override {
        axis.update_settings([](Cia402AxisSettings& s) {
            s.profile_velocity = 20000;
            s.profile_acceleration = s.profile_deceleration = 100000;
        });
    }
    void enable(OpMode mode) {
        ASSERT_EQ(axis.set_mode(static_cast<std::int8_t>(mode)), 0u);
        axis.write_controlword(0x06);
        axis.write_controlword(0x07);
        axis.write_controlword(kEnable);
        ASSERT_EQ(axis.state(), Cia402State::OperationEnabled);
    }
    void set_target(std::int32_t t) {
        axis.update_settings([t](Cia402AxisSettings& s) { s.target_position = t; });
    }
    // Advances the clock in 10 ms steps until `done` or `seconds` pass.
    template <class F>
    bool run_until(F done, double seconds = 5) {
        for (int i = 0; i < seconds * 100; ++i) {
            if (done()) return true;
            clock.advance(10'000'000);
        }
        return done();
    }
    bool reached() { return (axis.statusword() & sw::kTargetReached) != 0; }
    Cia402State state() { return decode_statusword(axis.statusword()); }  // evaluated now
};

}  // namespace

TEST_F(AxisRig, SetPointHandshakeAcknowledgesUntilBit4FallsAndReachesTheTarget) {
    enable(OpMode::ProfilePosition);
    EXPECT_TRUE(reached());  // at rest: nothing to reach
    set_target(4000);
    axis.write_controlword(kEnable | kNew);
    std::uint16_t s = axis.statusword();
    EXPECT_TRUE(s & sw::kSetPointAck);
    EXPECT_FALSE(s & sw::kTargetReached);
    axis.write_controlword(kEnable);  // bit 4 falls: the acknowledge does too
    s = axis.statusword();
    EXPECT_FALSE(s & sw::kSetPointAck);
    clock.advance(100'000'000);
    const std::int32_t mid = axis.position();
    EXPECT_GT(mid, 0);
    EXPECT_LT(mid, 4000);
    ASSERT_TRUE(run_until([&] { return reached(); }));
    EXPECT_EQ(axis.position(), 4000);
    EXPECT_EQ(axis.velocity(), 0);
    ASSERT_TRUE(axis.last_setpoint_ns().has_value());
    EXPECT_EQ(*axis.last_setpoint_ns(), 1'000'000'000);
}

TEST_F(AxisRig, ASetPointWhileMovingIsBufferedOneDeepAndPlayedAfterTheFirst) {
    enable(OpMode::ProfilePosition);
    set_target(4000);
    axis.write_controlword(kEnable | kNew);
    axis.write_controlword(kEnable);
    clock.advance(50'000'000);
    set_target(8000);
    axis.write_controlword(kEnable | kNew);  // bit 5 = 0: after the running one
    EXPECT_TRUE(axis.statusword() & sw::kSetPointAck);
    axis.write_controlword(kEnable);
    set_target(-5000);
    axis.write_controlword(kEnable | kNew);  // the buffer is full: not acknowledged
    EXPECT_FALSE(axis.statusword() & sw::kSetPointAck);
    axis.write_controlword(kEnable);
    // The first set-point is reached (the axis stops there: no change on set-point), then the second.
    // Passing 4000 at speed would show ~20000 inc/s there; standing there, a sample
    // within 10 ms of the stop shows |v| <= 1000 (100000 inc/s² deceleration).
    bool slow_at_first = false;
    ASSERT_TRUE(run_until([&] {
        if (std::abs(axis.position() - 4000) <= 10 && std::abs(axis.velocity()) <= 1000) slow_at_first = true;
        return reached();
    }));
    EXPECT_TRUE(slow_at_first);
    EXPECT_EQ(axis.position(), 8000);
}

TEST_F(AxisRig, Bit9ChangeOnSetPointGoesThroughTheFirstTargetWithoutStopping) {
    enable(OpMode::ProfilePosition);
    set_target(4000);
    axis.write_controlword(kEnable | kNew);
    axis.write_controlword(kEnable);
    clock.advance(50'000'000);
    set_target(12000);
    axis.write_controlword(kEnable | kNew | 0x0200);  // bit 9: change on set-point
    axis.write_controlword(kEnable | 0x0200);
    double slowest_near_first = 1e9;
    ASSERT_TRUE(run_until([&] {
        if (std::abs(axis.position() - 4000) <= 300) slowest_near_first = std::min<double>(slowest_near_first, std::abs(axis.velocity()));
        return reached();
    }));
    EXPECT_GT(slowest_near_first, 10000);  // at speed through 4000
    EXPECT_EQ(axis.position(), 12000);
}

TEST_F(AxisRig, Bit5ReplacesTheRunningSetPointAndBit6IsRelative) {
    enable(OpMode::ProfilePosition);
    set_target(40000);
    axis.write_controlword(kEnable | kNew);
    axis.write_controlword(kEnable);
    clock.advance(100'000'000);
    set_target(2000);
    axis.write_controlword(kEnable | kNew | kImmediate);  // now, not after
    axis.write_controlword(kEnable);
    ASSERT_TRUE(run_until([&] { return reached(); }));
    EXPECT_EQ(axis.position(), 2000);
    set_target(-500);
    axis.write_controlword(kEnable | kNew | kRelative);
    axis.write_controlword(kEnable);
    ASSERT_TRUE(run_until([&] { return reached(); }));
    EXPECT_EQ(axis.position(), 1500);
}

TEST_F(AxisRig, SoftwareLimitsClipTheTargetAndShowInternalLimit) {
    axis.update_settings([](Cia402AxisSettings& s) { s.max_position = 3000; });
    enable(OpMode::ProfilePosition);
    set_target(9000);
    axis.write_controlword(kEnable | kNew);
    axis.write_controlword(kEnable);
    ASSERT_TRUE(run_until([&] { return reached(); }));
    EXPECT_EQ(axis.position(), 3000);
    EXPECT_TRUE(axis.statusword() & sw::kInternalLimit);
}

TEST_F(AxisRig, ProfileVelocityRunsAtTheTargetAndHaltStopsIt) {
    enable(OpMode::ProfileVelocity);
    axis.set_target_velocity(5000);
    axis.write_controlword(kEnable);  // PV runs at 60FFh
    clock.advance(20'000'000);
    EXPECT_FALSE(reached());  // still accelerating
    ASSERT_TRUE(run_until([&] { return reached(); }, 1));
    EXPECT_EQ(axis.velocity(), 5000);
    axis.set_target_velocity(-2000);  // a running PV follows 60FFh at once
    ASSERT_TRUE(run_until([&] { return axis.velocity() == -2000; }, 1));
    axis.write_controlword(kEnable | kHaltBit);
    ASSERT_TRUE(run_until([&] { return axis.velocity() == 0; }, 1));
    const auto at_rest = axis.position();
    clock.advance(200'000'000);
    EXPECT_EQ(axis.position(), at_rest);
    EXPECT_TRUE(reached());
}

TEST_F(AxisRig, HomingOnTheHomeSwitchAttainsAndSetsTheOffset) {
    axis.update_settings([](Cia402AxisSettings& s) {
        s.homing_speed_switch = 5000;
        s.homing_speed_zero = 1000;
        s.home_offset = 250;
    });
    ASSERT_EQ(axis.set_homing_method(19), 0u);
    enable(OpMode::Homing);
    axis.write_controlword(kEnable | kNew);
    EXPECT_FALSE(axis.statusword() & sw::kSetPointAck);  // bit 12 is "attained" in HM
    ASSERT_TRUE(run_until([&] { return reached(); }));
    const auto s = axis.statusword();
    EXPECT_TRUE(s & sw::kSetPointAck) << std::hex << s;  // attained
    EXPECT_FALSE(s & sw::kFollowingError);               // no homing error
    EXPECT_EQ(axis.position(), 250);
}

TEST_F(AxisRig, Homing35TakesThePositionAsHomeAndUnsupportedMethodsAreRefused) {
    EXPECT_EQ(axis.set_homing_method(99), 0x06090030u);
    EXPECT_EQ(axis.settings().homing_method, 19);
    motor.set_pulse_position(777);
    axis.update_settings([](Cia402AxisSettings& s) { s.home_offset = -10; });
    ASSERT_EQ(axis.set_homing_method(35), 0u);
    enable(OpMode::Homing);
    axis.write_controlword(kEnable | kNew);
    ASSERT_TRUE(run_until([&] { return reached(); }, 1));
    EXPECT_TRUE(axis.statusword() & sw::kSetPointAck);
    EXPECT_EQ(axis.position(), -10);
}

// Every method the axis accepts ends attained at 607Ch, started on the side of the home
// switch (1000..1400) its search direction reaches it from: 7, 19, 20 search in +, from 0;
// 11 in -, from 2000; 17/18 find the -/+ limit, 33/34 the next index, 35 takes the position.
class AxisHomingMethods : public AxisRig, public ::testing::WithParamInterface<int> {};

TEST_P(AxisHomingMethods, EndsAttainedAtTheHomeOffset) {
    if (GetParam() == 11) {
        motor.displace(2000);  // the shaft (the switches see it) ...
        motor.set_pulse_position(2000);  // ... and the counter
    }
    // A search speed whose stopping distance (10 steps) fits in the 400-step switch: method
    // 20 turns back on the switch's edge before it has passed the switch.
    axis.update_settings([](Cia402AxisSettings& s) {
        s.homing_speed_switch = 2000;
        s.homing_speed_zero = 500;
        s.homing_acceleration = 200000;
        s.home_offset = 77;
    });
    ASSERT_EQ(axis.set_homing_method(static_cast<std::int8_t>(GetParam())), 0u);
    enable(OpMode::Homing);
    axis.write_controlword(kEnable | kNew);
    ASSERT_TRUE(run_until([&] { return reached(); }, 120)) << "method " << GetParam();  // 17/18: 100000 steps away
    const auto s = axis.statusword();
    EXPECT_TRUE(s & sw::kSetPointAck) << "method " << GetParam() << " statusword " << std::hex << s;
    EXPECT_FALSE(s & sw::kFollowingError) << "method " << GetParam();
    EXPECT_EQ(axis.position(), 77) << "method " << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Cia402, AxisHomingMethods, ::testing::Values(7, 11, 17, 18, 19, 20, 33, 34, 35));

TEST_F(AxisRig, AJammedRotorFaultsWithAFollowingError) {
    axis.update_settings([](Cia402AxisSettings& s) { s.following_error_window = 200; });
    enable(OpMode::ProfilePosition);
    set_target(20000);
    axis.write_controlword(kEnable | kNew);
    axis.write_controlword(kEnable);
    clock.advance(100'000'000);
    axis.jam(true);
    ASSERT_TRUE(run_until([&] { return state() == Cia402State::Fault; }, 2));
    EXPECT_EQ(axis.error_code(), 0x8611);
    EXPECT_EQ(axis.error_register(), 0x01);
    EXPECT_TRUE(axis.statusword() & sw::kFollowingError);
    EXPECT_LT(axis.position(), 20000);
    // Fault reset (rising bit 7) then the usual enable: the code stays readable.
    axis.write_controlword(0x80);
    EXPECT_EQ(axis.state(), Cia402State::SwitchOnDisabled);
    EXPECT_EQ(axis.error_code(), 0x8611);
}

TEST_F(AxisRig, AForcedLimitStopsAMotionTowardItAtOnce) {
    enable(OpMode::ProfilePosition);
    set_target(50000);
    axis.write_controlword(kEnable | kNew);
    axis.write_controlword(kEnable);
    clock.advance(200'000'000);
    axis.force_limit(1, true);
    const auto where = axis.position();
    clock.advance(100'000'000);
    EXPECT_EQ(axis.position(), where);
    EXPECT_EQ(axis.digital_inputs() & 3u, 2u);
    EXPECT_TRUE(axis.statusword() & sw::kInternalLimit);
    EXPECT_THROW(axis.force_limit(0, true), InvalidArgument);
}

TEST_F(AxisRig, QuickStopRampsThenSwitchOnDisabledAndInjectedFaultsKeepTheirCode) {
    enable(OpMode::ProfileVelocity);
    axis.set_target_velocity(10000);
    axis.write_controlword(kEnable);
    ASSERT_TRUE(run_until([&] { return axis.velocity() == 10000; }, 1));
    axis.write_controlword(0x02);  // quick stop (605Ah = 2: ramp, then Switch on disabled)
    EXPECT_EQ(axis.state(), Cia402State::QuickStopActive);
    ASSERT_TRUE(run_until([&] { return state() == Cia402State::SwitchOnDisabled; }, 1));
    EXPECT_EQ(axis.velocity(), 0);
    axis.inject_fault(0x5441);  // the drive detects a fault in any state
    EXPECT_EQ(axis.state(), Cia402State::Fault);
    EXPECT_EQ(axis.error_code(), 0x5441);
    EXPECT_EQ(decode_statusword(axis.statusword()), Cia402State::Fault);
}

TEST_F(AxisRig, AVendorFaultHookFaultsTheAxis) {
    std::uint16_t code = 0;
    Cia402AxisHooks hooks;
    hooks.vendor_fault = [&] { return code; };
    Cia402Axis vendor(motor, clock, hooks);
    ASSERT_EQ(vendor.set_mode(1), 0u);
    for (std::uint16_t cw : {0x06, 0x07, 0x0F}) vendor.write_controlword(cw);
    EXPECT_EQ(vendor.state(), Cia402State::OperationEnabled);
    code = 0xFF01;  // e.g. the DMX-CAN's latched StepNLoop error
    vendor.statusword();
    EXPECT_EQ(vendor.state(), Cia402State::Fault);
    EXPECT_EQ(vendor.error_code(), 0xFF01);
}

// ---- Cia402SetPoints (the handshake alone) ----------------------------------------------

TEST(Cia402SetPoints, CiA402ReadingBuffersWithBit5ClearAndReplacesWithBit5Set) {
    Cia402SetPoints sp;
    const auto PP = OpMode::ProfilePosition;
    EXPECT_EQ(sp.on_controlword(0x0F, 0x1F, PP, true, true, 1000, 0), SetPointAction::Start);
    EXPECT_TRUE(sp.acknowledged());
    EXPECT_DOUBLE_EQ(sp.target(), 1000);
    EXPECT_EQ(sp.on_controlword(0x1F, 0x1F, PP, false, true, 1000, 0), SetPointAction::None);  // no edge
    EXPECT_EQ(sp.on_controlword(0x1F, 0x0F, PP, false, true, 1000, 0), SetPointAction::None);
    EXPECT_FALSE(sp.acknowledged());
    EXPECT_EQ(sp.on_controlword(0x0F, 0x5F, PP, false, true, 500, 300), SetPointAction::Buffer);  // relative
    EXPECT_DOUBLE_EQ(sp.target(), 1500);  // to the set-point before it, not to the position
    EXPECT_TRUE(sp.buffered());
    EXPECT_EQ(sp.on_controlword(0x0F, 0x1F, PP, false, true, 9, 300), SetPointAction::Refuse);
    EXPECT_FALSE(sp.acknowledged());
    EXPECT_EQ(sp.on_controlword(0x0F, 0x3F, PP, false, true, 7, 300), SetPointAction::Start);  // bit 5: now
    EXPECT_FALSE(sp.buffered());
    EXPECT_EQ(sp.on_controlword(0x0F, 0x1F, PP, true, false, 7, 300), SetPointAction::None);  // not accepted
    EXPECT_FALSE(sp.acknowledged());
}

TEST(Cia402SetPoints, TheDmxCanReadingBuffersOnlyWithBit5AndHaltDropsTheBuffer) {
    Cia402SetPoints sp(Cia402SetPointPolicy{.buffer_on_bit5 = true});
    const auto PP = OpMode::ProfilePosition;
    EXPECT_EQ(sp.on_controlword(0x0F, 0x1F, PP, false, true, 100, 0), SetPointAction::Refuse);
    EXPECT_EQ(sp.on_controlword(0x0F, 0x3F, PP, false, true, 100, 0), SetPointAction::Buffer);
    EXPECT_EQ(sp.take_buffered(), std::optional<double>(100));
    EXPECT_FALSE(sp.take_buffered().has_value());
    EXPECT_EQ(sp.on_controlword(0x0F, 0x3F, PP, false, true, 200, 0), SetPointAction::Buffer);
    EXPECT_EQ(sp.on_controlword(0x3F, 0x13F, PP, false, true, 200, 0), SetPointAction::Halt);
    EXPECT_FALSE(sp.buffered());
    EXPECT_EQ(sp.on_controlword(0x10F, 0x0F, OpMode::ProfileVelocity, true, true, 0, 0), SetPointAction::Resume);
    EXPECT_EQ(sp.on_controlword(0x0F, 0x1F, OpMode::Homing, true, true, 0, 0), SetPointAction::StartHoming);
}

// DMX-CAN homing (Figures 7.2-7.6) and the Arcus profile on the motor model.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../../motion/motor_rig.hpp"
#include "motorbus/drives/arcus/homing.hpp"
#include "motorbus/drives/arcus/profile.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/planner.hpp"

using namespace motorbus::motion;
using namespace motorbus::arcus;
using motorbus::Nanos;
using motorbus::SimClock;
using motorbus::test::bench_cfg;
using motorbus::test::run_until_done;
using motorbus::test::move_profile;

constexpr Nanos kMs = 1'000'000;
constexpr Nanos kSec = 1'000'000'000;

namespace {
ProfileParams homing_params() {
    ProfileParams p;
    p.hspd = 3200;
    p.lspd = 100;
    p.acc_ms = 100;
    return p;
}
}  // namespace

TEST(Homing, HomeOnlyResetsAtSwitchThenDecelerates) {
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    Homing h(m, homing_params());
    h.start(Homing::Method::H, +1);
    EXPECT_EQ(h.snl_status(), 6);
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    // Reset to 0 at the switch edge (physical 5000), then 3200 -> 100 in 0.1 s = 165 steps.
    EXPECT_NEAR(m.pulse_position(), 165, 1e-3);
    EXPECT_NEAR(m.physical_position(), 5165, 1e-3);
}
TEST(Homing, HomeReturnToZero) {
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    HomingOptions o;
    o.rz = true;
    Homing h(m, homing_params(), o);
    h.start(Homing::Method::H, +1);
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    EXPECT_EQ(m.pulse_count(), 0);
    EXPECT_NEAR(m.physical_position(), 5000, 1e-3);
}
TEST(Homing, HighLowFindsSwitchFromSameSide) {
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    HomingOptions o;
    o.hca = 600;  // past the switch (400 wide) by 600 at high speed, back at low speed
    Homing h(m, homing_params(), o);
    h.start(Homing::Method::HL, +1);
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    EXPECT_EQ(m.pulse_count(), 0);
    // Final approach in + at LSPD: stops on the low edge of the window.
    EXPECT_NEAR(m.physical_position(), 5000, 0.01);
}
TEST(Homing, LimitHoming) {
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    Homing h(m, homing_params());  // LCA 1000
    h.start(Homing::Method::L, -1);
    EXPECT_EQ(h.snl_status(), 13);
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    EXPECT_EQ(m.pulse_count(), 0);
    EXPECT_NEAR(m.physical_position(), -20000 + 1000, 0.01);
}
TEST(Homing, ZIndexAndHomeThenZ) {
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    Homing h(m, homing_params());
    h.start(Homing::Method::Z, +1);
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    EXPECT_NEAR(m.physical_position(), 37, 0.01);
    EXPECT_EQ(m.pulse_count(), 0);

    h.start(Homing::Method::ZH, +1);
    EXPECT_EQ(h.snl_status(), 6);  // Homing while it looks for the switch...
    clk.advance(2000 * kMs);       // (the switch at 5000 is passed after ~1.6 s)
    m.update();
    EXPECT_EQ(h.snl_status(), 7);  // ...Z-Homing once it looks for the index
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    // Home at 5000, decel to LSPD by ~5165, next index: 37 + 2*3200 = 6437.
    EXPECT_NEAR(m.physical_position(), 6437, 0.01);
    EXPECT_EQ(m.pulse_count(), 0);
}
TEST(Homing, LimitBeforeHomeIsLimitError) {
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    Homing h(m, homing_params());
    h.start(Homing::Method::H, -1);  // home is the other way
    run_until_done(clk, m, [&] { return h.running(); });
    EXPECT_EQ(h.result(), HomingResult::LimitError);
    EXPECT_NEAR(m.physical_position(), -20000, 0.01);
}
TEST(MotorModel, LongJogOnSimClockIsCheapAndExact) {
    SimClock clk;
    MotorConfig cfg;
    cfg.home = SwitchConfig{true, 1e6, 1e6 + 2, true};  // a 2-step window far away
    MotorModel m(clk, cfg);
    int index = 0, home_on = 0;
    Nanos home_t = 0;
    m.add_listener([&](const MotorEvent& e) {
        index += e.kind == MotorEvent::Kind::IndexPulse;
        if (e.kind == MotorEvent::Kind::HomeOn) {
            ++home_on;
            home_t = e.t;
        }
    });
    Motion a(ProfileParams{3200, 100, 100, 100, false, false, 1.0});
    a.jog(0, 1);
    m.command(a.profile());
    clk.advance(3600 * kSec);  // one simulated hour of jogging
    m.update();
    EXPECT_NEAR(m.pulse_position(), a.profile().position(3600.0), 1e-3);
    EXPECT_EQ(home_on, 1);
    EXPECT_NEAR(static_cast<double>(home_t), a.profile().first_crossing(1e6) * 1e9, 2.0);
    // Index once per rev: floor((p - 0) / 3200) + 1 rising edges from 0 (the first at 0 itself is not crossed).
    EXPECT_EQ(index, static_cast<int>(std::floor(m.physical_position() / 3200.0)));
}
TEST(MotorModel, ReviseKeepsTheTimeOriginAndDisplaceIsSlip) {
    SimClock clk;
    MotorModel m(clk);
    Motion a;
    a.move(0, 2000);
    m.command(a.profile());
    clk.advance(500 * kMs);
    m.update();
    const double before = m.pulse_position();
    a.change_target(m.profile_time(m.time()), 800);
    m.revise(a.profile());
    EXPECT_DOUBLE_EQ(m.pulse_position(), before);  // no jump at the change
    clk.advance(10 * kSec);
    m.update();
    EXPECT_FALSE(m.moving());
    EXPECT_EQ(m.pulse_count(), 800);
    m.displace(40);  // a knock: the rotor moves, the counter does not
    EXPECT_NEAR(m.physical_position(), 840, 1e-9);
    EXPECT_EQ(m.pulse_count(), 800);
    EXPECT_EQ(m.encoder(), 1050);
    EXPECT_NEAR(m.slip(), -40, 1e-9);
}
TEST(Homing, HighLowGoesHcaPastTheSwitchEdge) {
    // Figure 7.4 E: "The motor is now past the home input by the amount defined by
    // the home correction amount (HCA)" -- counted from where it leaves the switch,
    // even when the deceleration stopped inside the switch.
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    HomingOptions o;
    o.hca = 300;
    o.zero_encoder = true;
    Homing h(m, homing_params(), o);
    std::vector<double> stops;
    m.add_listener([&](const MotorEvent& e) {
        if (e.kind == MotorEvent::Kind::ProfileDone) stops.push_back(e.physical);
    });
    h.start(Homing::Method::HL, +1);
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    ASSERT_EQ(stops.size(), 2u);  // the deceleration inside the switch, the HCA move
    EXPECT_GT(stops[0], 5000);
    EXPECT_NEAR(stops[1], 5000 - 300, 1e-3);
    EXPECT_NEAR(m.physical_position(), 5000, 0.01);
    EXPECT_EQ(m.pulse_count(), 0);
    EXPECT_EQ(m.encoder(), 0);  // zero_encoder: EX follows PX
}
TEST(Homing, StartingOnTheSwitchFindsItAtOnce) {
    SimClock clk;
    MotorConfig c = bench_cfg();
    MotorModel m(clk, c);
    m.command(move_profile(0, 5100));
    clk.advance(5 * kSec);
    m.update();
    Homing h(m, homing_params());
    h.start(Homing::Method::H, +1);  // already on the home switch
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    // Zeroed where it started, and stopped there: it was still at LSPD.
    EXPECT_NEAR(m.physical_position(), 5100, 1e-6);
    EXPECT_EQ(m.pulse_count(), 0);
    // On the limit it homes against: backs off by LCA at once.
    m.force_switch(Switch::MinusLimit, true);
    h.start(Homing::Method::L, -1);
    m.force_switch(Switch::MinusLimit, std::nullopt);
    const double from = m.physical_position();
    run_until_done(clk, m, [&] { return h.running(); });
    ASSERT_EQ(h.result(), HomingResult::Done);
    EXPECT_NEAR(m.physical_position(), from + 1000, 0.01);
    EXPECT_EQ(m.pulse_count(), 0);
}

TEST(MotorModel, MoveEndingExactlyOnTheIndexEdgeStillEnds) {
    // The index event and the profile's end fall on the same nanosecond.
    SimClock clk;
    MotorConfig c;
    c.index_position = 1600;
    MotorModel m(clk, c);
    int done = 0, index = 0;
    m.add_listener([&](const MotorEvent& e) {
        done += e.kind == MotorEvent::Kind::ProfileDone;
        index += e.kind == MotorEvent::Kind::IndexPulse;
    });
    Motion a;  // ends with a jump from LSPD to 0: the edge is reached at the very end
    a.move(0, 1600);
    m.command(a.profile());
    clk.advance(5 * kSec);
    m.update();
    EXPECT_FALSE(m.moving());
    EXPECT_EQ(done, 1);
    EXPECT_EQ(index, 1);
    EXPECT_DOUBLE_EQ(m.physical_position(), 1600);
}

// The simulator's axis is a motion::MotorModel: end-stop switches fixed to the
// machine, exact stops inside a tick, units 1:1 with the DMAC's increments.
#include <gtest/gtest.h>

#include <cmath>

#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/drives/dmac/profile.hpp"
#include "sim_rig.hpp"

using namespace motorbus;
using namespace motorbus::dmac;
using motorbus::dmac::testing::Rig;

namespace {

SimOptions with_switches(double neg, double pos, Model model = Model::Dmac34_1, bool active_low = false) {
    SimOptions o;
    o.model = model;
    o.positive_end_switch = motion::SwitchConfig{true, pos, 0, active_low};
    o.negative_end_switch = motion::SwitchConfig{true, neg, 0, active_low};
    return o;
}

}  // namespace

TEST(DmacSimAxis, HardEndSwitchStopsTheAxisOnTheSwitchAndOnlyAllowsReverse) {
    Rig r(with_switches(-3000, 5000));
    r.tx("00HARD_ENDS ALL, #ACCEL_TIME:=0, #DECEL_TIME:=0");
    // 6 rpm = 1000 inc/s: the switch at 5000 closes 5 s in, between nothing special.
    r.tx("00MOVE_SPEED 600");
    EXPECT_EQ(r.run_until_idle(), 5000);
    EXPECT_EQ(r.read(Var::Position), 5000);
    EXPECT_EQ(r.read(Var::Speed), 0);
    std::uint32_t st = r.status();
    EXPECT_TRUE(bit_set(st, status::kHardPosEnd));
    EXPECT_TRUE(bit_set(st, status::kAbnormalStop));
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Input)) & bit_mask(9), bit_mask(9));  // IN9 reads the switch
    r.tx("00MOVE_ON 10");  // further CW is refused
    EXPECT_TRUE(bit_set(static_cast<std::uint32_t>(r.read(Var::Error)), error::kLimit));
    EXPECT_EQ(r.run_until_idle(), 0);
    r.tx("00#ERROR:=0, MOVE_ON -100");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 4900);
    st = r.status();
    EXPECT_FALSE(bit_set(st, status::kHardPosEnd));
    EXPECT_FALSE(bit_set(st, status::kAbnormalStop));
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Input)) & bit_mask(9), 0u);
    EXPECT_EQ(r.sim->state().error, 0u);
}

TEST(DmacSimAxis, SwitchesStayOnTheMachineWhenPositionIsRehomed) {
    Rig r(with_switches(-3000, 5000));
    r.tx("00HARD_ENDS NEG, #POSITION:=10000");  // the counter moves, the machine does not
    r.tx("00MOVE_TO 0");
    r.run_until_idle();
    // The negative switch is 3000 below where the axis was: encoder 7000.
    EXPECT_EQ(r.read(Var::Position), 7000);
    EXPECT_TRUE(bit_set(r.status(), status::kHardNegEnd));
    EXPECT_TRUE(bit_set(r.status(), status::kAbnormalStop));
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Input)) & bit_mask(10), bit_mask(10));
    // Disabled end-stop: the positive switch is read on IN9 but stops nothing.
    r.tx("00MOVE_TO 16000");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 16000);
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Input)) & bit_mask(9), bit_mask(9));
    EXPECT_FALSE(bit_set(r.status(), status::kHardPosEnd));
}

TEST(DmacSimAxis, NormallyClosedSwitchesWithInversePolarity) {
    // DMAC23: IN1 positive, IN2 negative.  Active-low switches read as end-stops
    // only with INVERSE_POLARITY IN.
    Rig r(with_switches(-2000, 2000, Model::Dmac23_1, true));
    r.tx("00INVERSE_POLARITY IN, HARD_ENDS ALL");
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Input)) & 0x3u, 0u);
    r.tx("00MOVE_SPEED -60000");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), -2000);
    EXPECT_TRUE(bit_set(r.status(), status::kHardNegEnd));
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Input)) & 0x3u, 0x2u);
}

TEST(DmacSimAxis, SoftEndStopInsideATickStopsExactlyOnIt) {
    Rig r;
    // 100000 inc/s cruise: 100 increments per ms tick; 12345 is reached mid-tick.
    r.tx("00SOFT_ENDS ON, #POSITIVE_END:=12345, #ACCEL_TIME:=0, MOVE_SPEED 60000");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 12345);
    EXPECT_EQ(r.read(Var::Speed), 0);
    EXPECT_TRUE(bit_set(r.status(), status::kSoftPosEnd));
    // Interpolation segments are stopped the same way.
    r.tx("00#ERROR:=0, #POSITION:=0, #POSITIVE_END:=150");
    for (int i = 0; i < 3; ++i) r.tx("00MOVE_INTERPOL 100");
    r.tx("SYNCHRO INTERPOL");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 150);
    EXPECT_EQ(r.read(Var::InterpolCount), 0);
    EXPECT_TRUE(bit_set(r.status(), status::kAbnormalStop));
}

TEST(DmacSimAxis, ReportedSpeedAndPositionFollowTheProfile) {
    Rig r;
    r.tx("00MOVE_SPEED 12345");
    // ATI 1000 ms for 60000: 12345 is reached after 205.75 ms.
    r.ms(100);
    const double a = speed_to_inc_per_s(60000);  // inc/s^2 with ATI = 1 s
    EXPECT_EQ(r.read(Var::Speed), std::lround(inc_per_s_to_speed(a * 0.1)));
    EXPECT_EQ(r.read(Var::Position), std::lround(a * 0.1 * 0.1 / 2));
    r.ms(200);
    EXPECT_EQ(r.read(Var::Speed), 12345);
    r.tx("00MOVE_TO 100000");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 100000);
    EXPECT_EQ(r.read(Var::Speed), 0);
}

// The simulator against the manual, through the client, on simulated time.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "fixture.hpp"

using namespace motorbus;
using namespace motorbus::arcus;
using arcus_test::Bench;

namespace {
std::string nul(const std::string& s) { return s + std::string(1, '\0'); }
}  // namespace

// ---- the manual's examples, byte for byte (seed vectors arcus_dmx_ascii) ----

TEST(ArcusSim, SeedExamplesRt0) {
    SimClock clock;
    Sim sim(clock);
    EXPECT_EQ(sim.on_line("@01EX"), nul("0"));
    EXPECT_EQ(sim.on_line("@01EX=1000"), nul("OK"));
    EXPECT_EQ(sim.on_line("@01EX"), nul("1000"));
    EXPECT_EQ(sim.on_line("@01EO=1"), nul("OK"));  // powered: a disabled motor does no motion (§6)
    EXPECT_EQ(sim.on_line("@01J+"), nul("OK"));
    EXPECT_EQ(sim.on_line("@01X1000"), nul("?Moving"));
    EXPECT_EQ(sim.on_line("@01ABORT"), nul("OK"));
    EXPECT_EQ(sim.on_line("@00ABORT"), "");
    EXPECT_EQ(sim.on_line("@01FOO"), nul("?FOO"));
    EXPECT_EQ(sim.on_line("@01T500"), nul("?Motor is not moving"));
}

TEST(ArcusSim, SeedExamplesRt1) {
    SimClock clock;
    SimOptions o;
    o.response_type = 1;
    Sim sim(clock, o);
    EXPECT_EQ(sim.on_line("@01EX=1000"), nul("#01OK"));
    EXPECT_EQ(sim.on_line("@01EX"), nul("#011000"));
    EXPECT_EQ(sim.on_line("@01J+"), nul("#01OK"));
    EXPECT_EQ(sim.on_line("@01ABORT"), nul("#01OK"));
}

TEST(ArcusSim, RtChangeTakesEffectAfterStoreAndPowerCycle) {
    Bench b;
    EXPECT_EQ(b.sim.on_line("@01RT=1"), nul("OK"));
    EXPECT_EQ(b.sim.on_line("@01RT"), nul("1"));  // the setting reads back at once...
    EXPECT_EQ(b.sim.on_line("@01EX"), nul("0"));  // ...but replies keep the boot format
    b.sim.power_cycle();                            // not stored: lost
    EXPECT_EQ(b.sim.on_line("@01RT"), nul("0"));
}

TEST(ArcusSim, FactoryDefaultsTable7_11) {
    Bench b;
    EXPECT_EQ(b.c.can_bit_rate_code(), 5);   // 125000 bps
    EXPECT_EQ(b.c.comm_mode(), 0);           // RS-232
    EXPECT_EQ(b.c.idle_current(), 1000);
    EXPECT_EQ(b.c.run_current(), 1600);      // ASCII table, not 8.21's 1500
    EXPECT_EQ(b.c.idle_time(), 500);
    EXPECT_EQ(b.c.baud_code(), 1);           // 9600
    EXPECT_EQ(b.c.device_name(), "DMC01");
    EXPECT_EQ(b.c.outputs_at_boot(), 7u);
    EXPECT_TRUE(b.c.alarm_outputs());
    EXPECT_FALSE(b.c.enabled_at_boot());
    EXPECT_FALSE(b.c.enabled());             // EO follows EOBOOT at boot
    EXPECT_EQ(b.c.limit_correction(), 1000);
    EXPECT_EQ(b.c.node_id(), 1);
    EXPECT_EQ(b.c.polarity(), 0u);
    EXPECT_EQ(b.c.response_type(), 0);
    EXPECT_TRUE(b.c.snl_enabled());
    EXPECT_EQ(b.c.snl_max_attempts(), 10);
    EXPECT_EQ(b.c.snl_error_range(), 1000);
    EXPECT_EQ(b.c.snl_idle_tolerance(), 5);
    EXPECT_EQ(b.c.snl_tolerance(), 20);      // ASCII table, not 8.11's 10
    EXPECT_EQ(b.c.id(), "DriveMax-CAN");
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_EQ(b.c.status().raw, 0u);
}

// ---- moves with the profile model ----

TEST(ArcusSim, TrapezoidMoveTimesAndPositions) {
    Bench b;
    b.open_loop();
    b.c.set_high_speed(1000);
    b.c.set_low_speed(100);
    b.c.set_acceleration(100);
    // Ramp 0.1 s covers (100 + 1000) / 2 * 0.1 = 55 steps each way; cruise 890 steps = 0.89 s.
    b.c.move(1000);
    b.run(0.05);
    EXPECT_TRUE(b.c.status().accelerating());
    EXPECT_EQ(b.c.status().raw, 2u);
    b.run(0.45);  // t = 0.5
    EXPECT_EQ(b.c.status().raw, 1u);
    EXPECT_NEAR(b.c.position(), 55 + 400, 2);
    EXPECT_EQ(b.c.speed(), 1000);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Disabled);
    b.run(0.55);  // t = 1.05: decelerating
    EXPECT_TRUE(b.c.status().decelerating());
    b.run(0.05);  // t = 1.10 > 1.09
    EXPECT_EQ(b.c.status().raw, 0u);
    EXPECT_EQ(b.c.position(), 1000);
    EXPECT_EQ(b.c.encoder(), 1250);  // 4000 counts per 3200 steps
    EXPECT_EQ(b.c.speed(), 0);
}

TEST(ArcusSim, SCurveTakesTheSameTime) {
    Bench b;
    b.open_loop();
    b.c.set_s_curve(true);
    b.c.set_acceleration(100);
    b.c.move(1000);
    b.run(1.08);
    EXPECT_TRUE(b.c.moving());
    b.run(0.02);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.position(), 1000);
}

TEST(ArcusSim, IncrementalAndAbsoluteModes) {
    Bench b;
    b.open_loop();
    b.c.incremental_mode();
    EXPECT_TRUE(b.c.incremental());
    b.c.move(300);
    b.run(2);
    b.c.move(300);
    b.run(2);
    EXPECT_EQ(b.c.position(), 600);
    b.c.absolute_mode();
    EXPECT_FALSE(b.c.incremental());
    b.c.move(-200);
    b.run(3);
    EXPECT_EQ(b.c.position(), -200);
}

TEST(ArcusSim, MoveAbove262143IsRefused) {
    Bench b;
    b.open_loop();
    b.c.set_position(100000);
    // The manual: from 100000 the target must lie within -162143..362143.
    EXPECT_EQ(b.raw("X362144"), "?X362144");
    EXPECT_EQ(b.raw("X-162144"), "?X-162144");
    EXPECT_EQ(b.raw("X362143"), "OK");
    b.c.abort();
    b.c.incremental_mode();
    EXPECT_EQ(b.raw("X262144"), "?X262144");
}

TEST(ArcusSim, MovingErrors) {
    Bench b;
    b.open_loop();
    b.c.move(5000);
    b.run(0.2);
    try {
        b.c.move(10);
        FAIL();
    } catch (const ReplyError& e) {
        EXPECT_EQ(e.code, ErrorCode::Moving);
        EXPECT_EQ(e.reply, "?Moving");
    }
    EXPECT_EQ(b.raw("PX=0"), "?Moving");
    EXPECT_EQ(b.raw("EX=0"), "?Moving");
    EXPECT_EQ(b.raw("J-"), "?Moving");
    EXPECT_EQ(b.raw("H+"), "?Moving");
    EXPECT_EQ(b.raw("HSPD"), "1000");  // queries still answer
}

TEST(ArcusSim, OnTheFlyTargetChange) {
    Bench b;
    b.open_loop();
    b.c.move(10000);
    b.run(1.0);
    b.c.change_target(3000);
    b.run(10);
    EXPECT_EQ(b.c.position(), 3000);
    // Passed already: the motor stops and comes back.
    b.c.move(10000);
    b.run(6.0);
    int64_t there = b.c.position();
    EXPECT_GT(there, 6000);
    b.c.change_target(4000);
    b.run(20);
    EXPECT_EQ(b.c.position(), 4000);
    EXPECT_FALSE(b.c.moving());
    // T while idle or jogging: ?Motor is not moving.
    EXPECT_EQ(b.raw("T100"), "?Motor is not moving");
    b.c.jog(1);
    EXPECT_EQ(b.raw("T100"), "?Motor is not moving");
    b.c.abort();
}

TEST(ArcusSim, OnTheFlySpeedChange) {
    Bench b;
    b.open_loop();
    EXPECT_EQ(b.raw("SSPD2000"), "?Bad SSPD Command");  // not moving
    b.c.jog(1);
    b.run(1);
    EXPECT_EQ(b.c.speed(), 1000);
    b.c.set_s_curve(true);
    try {
        b.c.change_speed(2000);
        FAIL();
    } catch (const ReplyError& e) {
        EXPECT_EQ(e.code, ErrorCode::ScvOn);
    }
    b.c.set_s_curve(false);
    EXPECT_EQ(b.raw("SSPD20000"), "?Speed out of range");  // SSPDM 0 window is 1..16K
    EXPECT_EQ(b.raw("SSPD0"), "?Bad SSPD Command");
    b.c.change_speed(5000);
    b.run(2);
    EXPECT_EQ(b.c.speed(), 5000);
    b.c.set_speed_window(2);
    b.c.change_speed(20000);
    b.run(2);
    EXPECT_EQ(b.c.speed(), 11000);  // the move's ACC slope: 900 pps per 300 ms
    b.run(3);
    EXPECT_EQ(b.c.speed(), 20000);
    b.c.abort();
}

TEST(ArcusSim, JogStopAbort) {
    Bench b;
    b.c.enable(true);
    b.c.jog(1);
    b.run(0.5);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Jogging);
    b.c.stop();
    b.run(0.1);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Stopping);
    EXPECT_TRUE(b.c.status().decelerating());
    b.run(0.3);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    b.c.jog(-1);
    b.run(1);
    int64_t p = b.c.position();
    b.c.abort();
    EXPECT_EQ(b.c.status().raw, 0u);  // immediately
    b.run(1);
    EXPECT_EQ(b.c.position(), p);
}

// ---- StepNLoop ----

TEST(ArcusSim, StepNLoopMovesInEncoderCounts) {
    Bench b;
    b.c.enable(true);
    b.c.move(4000);  // encoder counts: one revolution
    b.run(0.1);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Moving);
    b.run(6);
    EXPECT_EQ(b.c.encoder(), 4000);
    EXPECT_EQ(b.c.position(), 4000);
    EXPECT_EQ(b.c.delta(), 0);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_NEAR(b.sim.physical_position(), 3200, 1e-6);
    EXPECT_TRUE(b.c.digital_output(1));  // in-position output (EDO=1)
}

TEST(ArcusSim, StepNLoopCorrectsADisturbance) {
    Bench b;
    b.c.enable(true);
    b.c.move(2000);
    b.run(5);
    b.sim.disturb(40);  // 50 counts: SLT < 50 < SLE
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Correcting);
    b.run(2);
    EXPECT_EQ(b.c.encoder(), 2000);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    b.sim.disturb(8);  // 10 counts <= SLT: in position, nothing done
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_EQ(b.c.encoder(), 2010);
    b.sim.disturb(1000);  // 1250 counts > SLE while idle: range error
    EXPECT_EQ(b.c.snl_status(), SnlStatus::CorrectionRangeError);
    EXPECT_TRUE(b.c.digital_output(3));  // alarm output
    b.c.clear_snl();
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
}

TEST(ArcusSim, StepNLoopStallAndAttemptErrors) {
    Bench b;
    b.c.enable(true);
    b.sim.set_blocked(true);
    b.c.move(5000);
    b.run(3);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::StallError);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.raw("X0"), "?State Error");
    EXPECT_EQ(b.raw("J+"), "?State Error");
    b.c.abort();  // ABORT clears the StepNLoop error status
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    // A short move that never arrives: corrections until SLA is used up.
    b.c.set_encoder(0);
    b.c.move(100);
    b.run(30);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::CorrectionAttemptError);
    b.c.clear();
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
}

// ---- homing ----

TEST(ArcusSim, HomeInputOnly) {
    Bench b;
    b.open_loop();
    b.c.home(HomeMethod::H, 1);
    b.run(0.5);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Disabled);
    b.run(20);
    EXPECT_FALSE(b.c.moving());
    // Zeroed on the home edge (8000 steps), then decelerated: the position is non-zero.
    int64_t p = b.c.position();
    EXPECT_GT(p, 0);
    EXPECT_NEAR(b.sim.physical_position(), 8000 + p, 1.0);
    // RZ=1: back to zero.
    b.c.set_return_to_zero(true);
    b.c.move(p - 3000);  // off the switch first: it is level-sensitive
    b.run(10);
    b.c.home(HomeMethod::H, 1);
    b.run(20);
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_NEAR(b.sim.physical_position(), 8000, 1.0);
}

TEST(ArcusSim, HomeHighAndLowSpeed) {
    Bench b;
    b.open_loop();
    b.c.set_home_correction(300);
    b.c.home(HomeMethod::HL, 1);
    b.run(30);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.c.encoder(), 0);
    // The last approach is in the homing direction at low speed onto the switch edge.
    EXPECT_NEAR(b.sim.physical_position(), 8000, 0.5);
    EXPECT_TRUE(b.c.status().home());
}

TEST(ArcusSim, HomeThenZIndex) {
    Bench b;
    b.c.enable(true);  // StepNLoop on: shows Homing then Z-Homing
    b.c.home(HomeMethod::ZH, 1);
    b.run(1);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Homing);
    b.run(11);  // home at 8000 steps = 10000 counts, at 1000 counts/s
    EXPECT_EQ(b.c.snl_status(), SnlStatus::ZHoming);
    b.run(60);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.c.encoder(), 0);
    EXPECT_NEAR(b.sim.physical_position(), 11200, 0.01);  // the Z index after the switch
    EXPECT_TRUE(b.c.status().z_index());
}

TEST(ArcusSim, ZIndexOnly) {
    Bench b;
    b.open_loop();
    b.c.set_position(0);
    b.c.move(100);
    b.run(2);
    b.c.home(HomeMethod::Z, -1);
    b.run(0.1);
    EXPECT_EQ(b.c.speed(), 100);  // low speed only
    b.run(20);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_NEAR(b.sim.physical_position(), 1600 - 3200 + 1.0, 1e-6);  // entered from above
}

TEST(ArcusSim, LimitHoming) {
    SimOptions o;
    o.world.minus_limit = -2000;
    Bench b(o);
    b.c.enable(true);
    b.c.home(HomeMethod::L, -1);
    b.run(0.5);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::LimitHoming);
    b.run(20);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.c.encoder(), 0);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    // Backed off by LCA = 1000 (counts under StepNLoop = 800 steps).
    EXPECT_NEAR(b.sim.physical_position(), -2000 + 800, 1.0);
    EXPECT_FALSE(b.c.status().minus_limit_error());
}

TEST(ArcusSim, HighLowGoesHcaPastTheSwitchEdge) {
    // Figure 7.4 E: "The motor is now past the home input by the amount defined by the
    // home correction amount (HCA)" -- from the edge where it leaves the switch (8000),
    // although the first deceleration already stopped inside the switch.
    Bench b;
    b.open_loop();
    b.c.set_home_correction(300);
    b.c.home(HomeMethod::HL, 1);
    double lowest = 1e9, highest = -1e9;
    for (int i = 0; i < 3000 && (i < 10 || b.sim.busy()); ++i) {
        b.run(0.01);
        highest = std::max(highest, b.sim.physical_position());
        if (highest > 8000) lowest = std::min(lowest, b.sim.physical_position());  // after the first find
    }
    EXPECT_FALSE(b.sim.busy());
    EXPECT_GT(highest, 8100);               // decelerated inside the switch (8000..8400)
    EXPECT_NEAR(lowest, 8000 - 300, 2.0);   // HCA past the edge
    EXPECT_NEAR(b.sim.physical_position(), 8000, 0.5);
    EXPECT_EQ(b.c.position(), 0);
}

TEST(ArcusSim, HomingStartedOnTheSwitchFindsItAtOnce) {
    Bench b;
    b.open_loop();
    b.c.move(8100);  // onto the home switch
    b.run(15);
    b.c.home(HomeMethod::H, 1);
    b.run(0.01);
    EXPECT_FALSE(b.c.moving());  // still at LSPD: zeroed and stopped where it was
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.c.encoder(), 0);
    EXPECT_NEAR(b.sim.physical_position(), 8100, 1e-6);
}

TEST(ArcusSim, StopAndSspdDuringHoming) {
    Bench b;
    b.c.enable(true);
    b.c.home(HomeMethod::H, 1);
    b.run(1);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Homing);
    EXPECT_EQ(b.raw("SSPD500"), "?Bad SSPD Command");
    b.c.stop();
    b.run(0.1);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Stopping);
    EXPECT_TRUE(b.c.status().decelerating());
    b.run(0.5);
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_GT(b.c.position(), 0);  // not homed: the counter was never reset
    // ABORT stops a homing at once.
    b.c.home(HomeMethod::H, 1);
    b.run(0.5);
    auto p = b.c.position();
    b.c.abort();
    b.run(1);
    EXPECT_EQ(b.c.position(), p);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
}

// ---- limits ----

TEST(ArcusSim, LimitErrorLatchesUntilClr) {
    SimOptions o;
    o.world.plus_limit = 1500;
    Bench b(o);
    b.open_loop();
    b.c.jog(1);
    b.run(5);
    auto st = b.c.status();
    EXPECT_FALSE(st.moving());
    EXPECT_TRUE(st.plus_limit());
    EXPECT_TRUE(st.plus_limit_error());
    EXPECT_EQ(st.raw, 32u + 128u);
    EXPECT_NEAR(b.sim.physical_position(), 1500, 0.5);  // stopped at once
    EXPECT_EQ(b.raw("J-"), "?State Error");
    EXPECT_EQ(b.raw("X0"), "?State Error");
    b.c.clear();
    EXPECT_EQ(b.c.status().raw, 32u);
    b.c.move(0);
    b.run(5);
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.c.status().raw, 0u);
}

TEST(ArcusSim, MinusLimitErrorIs64) {
    SimOptions o;
    o.world.minus_limit = -500;
    Bench b(o);
    b.open_loop();
    b.c.jog(-1);
    b.run(3);
    EXPECT_EQ(b.c.status().raw, 16u + 64u);
    b.c.clear();
    b.c.set_snl_enabled(true);
    b.c.jog(-1);  // moving into an active limit: error at once
    b.run(0.01);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::LimitError);
}

// ---- latch, sync output, I/O ----

TEST(ArcusSim, LatchOnDi2) {
    Bench b;
    b.open_loop();
    EXPECT_EQ(b.c.latch_status(), LatchStatus::Off);
    b.c.enable_latch(true);
    EXPECT_EQ(b.c.latch_status(), LatchStatus::Waiting);
    b.c.move(2000);
    b.run(1.0);
    int64_t px = b.sim.pulse_position(), ex = b.sim.encoder_position();
    b.sim.set_input(2, true);
    EXPECT_EQ(b.c.latch_status(), LatchStatus::Triggered);
    EXPECT_EQ(b.c.latched_position(), px);
    EXPECT_EQ(b.c.latched_encoder(), ex);
    EXPECT_TRUE(b.c.status().latch_input());
    b.run(5);
    EXPECT_EQ(b.c.latched_position(), px);  // positions are not reset by the latch
    EXPECT_EQ(b.c.position(), 2000);
}

TEST(ArcusSim, SyncOutputOnDo2) {
    Bench b;
    b.open_loop();
    b.c.set_sync_position(500);
    b.c.set_sync_condition(SyncCondition::Equal);
    EXPECT_EQ(b.c.sync_status(), SyncStatus::Off);
    b.c.sync_on();
    EXPECT_EQ(b.c.sync_status(), SyncStatus::Waiting);
    EXPECT_FALSE(b.c.digital_output(2));
    b.c.set_digital_output(2, true);  // DO2 belongs to the sync feature now
    EXPECT_FALSE(b.c.digital_output(2));
    b.c.move(1000);  // encoder passes 500 on the way to 1250
    b.run(3);
    EXPECT_EQ(b.c.sync_status(), SyncStatus::Occurred);
    EXPECT_FALSE(b.c.digital_output(2));  // EQUAL: a pulse while equal only (ArcusAudit)
    b.c.set_sync_condition(SyncCondition::Greater);
    b.c.sync_off();
    b.c.sync_on();
    EXPECT_TRUE(b.c.digital_output(2));   // GREATER stays on
    b.c.sync_off();
    EXPECT_EQ(b.c.sync_status(), SyncStatus::Off);
    EXPECT_FALSE(b.c.digital_output(2));
    b.c.set_sync_condition(SyncCondition::Greater);
    b.c.sync_on();  // 1250 > 500 already
    EXPECT_EQ(b.c.sync_status(), SyncStatus::Occurred);
}

TEST(ArcusSim, DigitalIoIsOneBased) {
    Bench b;
    b.open_loop();  // SL=0: DO1/DO3 are general purpose
    b.sim.set_input(1, true);
    b.sim.set_input(6, true);
    EXPECT_EQ(b.c.digital_inputs(), 33u);
    EXPECT_TRUE(b.c.digital_input(1));
    EXPECT_FALSE(b.c.digital_input(2));
    EXPECT_TRUE(b.c.digital_input(6));
    EXPECT_EQ(b.c.digital_outputs(), 7u);  // DOBOOT=7
    b.c.set_digital_outputs(0);
    b.c.set_digital_output(3, true);
    EXPECT_EQ(b.c.digital_outputs(), 4u);
    EXPECT_EQ(b.raw("DI7"), "?Index out of Range");
    EXPECT_EQ(b.raw("DI0"), "?Index out of Range");
    EXPECT_EQ(b.raw("DO4"), "?Index out of Range");
    EXPECT_EQ(b.raw("DO0=1"), "?Index out of Range");
    EXPECT_EQ(b.raw("DO=8"), "?DO=8");
    EXPECT_THROW(b.c.digital_input(7), InvalidArgument);  // the client checks first
}

// ---- currents, polarity ----

TEST(ArcusSim, RunAndIdleCurrentAfterCurt) {
    Bench b;
    b.open_loop();
    b.run(1);
    EXPECT_EQ(b.c.current(), 1000);
    b.c.move(500);
    b.run(0.1);
    EXPECT_EQ(b.c.current(), 1600);
    b.run(0.8);  // stopped at ~0.75 s
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.c.current(), 1600);  // still within CURT = 500 ms
    b.run(0.5);
    EXPECT_EQ(b.c.current(), 1000);
    b.c.set_idle_current(0);
    EXPECT_EQ(b.c.current(), 0);
    b.c.enable(false);
    b.c.jog(1);
    EXPECT_EQ(b.c.current(), 0);
    b.c.abort();
    EXPECT_EQ(b.raw("CURR=50"), "?CURR=50");
    EXPECT_EQ(b.raw("CURI=99"), "?CURI=99");
}

TEST(ArcusSim, Polarity) {
    Bench b;
    b.open_loop();
    b.c.set_polarity(2);  // direction
    b.c.move(1000);
    b.run(3);
    EXPECT_EQ(b.c.position(), 1000);
    EXPECT_EQ(b.c.encoder(), -1250);
    EXPECT_NEAR(b.sim.physical_position(), -1000, 1e-6);
    b.c.set_polarity(32);  // home input sense inverted: reads active away from the switch
    EXPECT_TRUE(b.c.status().home());
    b.c.set_polarity(16);  // limits inverted: both read active
    EXPECT_EQ(b.c.status().raw & 48u, 48u);
    b.c.set_polarity(64);  // latch input inverted
    EXPECT_TRUE(b.c.status().latch_input());
}

// ---- STORE, power cycle, addressing ----

TEST(ArcusSim, StorePersistsToFile) {
    auto path = std::filesystem::temp_directory_path() / ("arcus_store_" + std::to_string(::getpid()) + ".txt");
    std::filesystem::remove(path);
    {
        SimOptions o;
        o.store_path = path.string();
        Bench b(o);
        b.c.set_run_current(2000);
        b.c.set_device_name(5);
        b.c.set_response_type(1);
        b.c.set_high_speed(5000);  // not a stored item
        b.c.store();
        EXPECT_EQ(b.sim.address(), 1);  // new name only after a power cycle
    }
    SimClock clock;
    SimOptions o;
    o.store_path = path.string();
    Sim sim(clock, o);
    EXPECT_EQ(sim.address(), 5);
    EXPECT_EQ(sim.on_line("@01CURR"), "");
    EXPECT_EQ(sim.on_line("@05CURR"), nul("#052000"));
    EXPECT_EQ(sim.on_line("@05HSPD"), nul("#051000"));
    EXPECT_EQ(sim.on_line("@05DN"), nul("#05DMC05"));
    std::filesystem::remove(path);
}

TEST(ArcusSim, DeviceNameSpellings) {
    Bench b;
    EXPECT_EQ(b.raw("DN=DMK07"), "OK");
    EXPECT_EQ(b.raw("DN"), "DMC07");
    EXPECT_EQ(b.raw("DN=12"), "OK");
    EXPECT_EQ(b.raw("DN"), "DMC12");
    EXPECT_EQ(b.raw("DN=DMC00"), "?DN=DMC00");  // 00 is the broadcast address
    EXPECT_EQ(b.raw("DN=DMC100"), "?DN=DMC100");
}

TEST(ArcusSim, SharedRs485LineAndBroadcast) {
    SimClock clock;
    SimOptions o1, o2;
    o1.address = 1;
    o2.address = 2;
    o1.snl = o2.snl = false;
    o1.eo_boot = o2.eo_boot = true;
    Sim s1(clock, o1), s2(clock, o2);
    auto port = std::make_shared<arcus_test::DevicePort>(std::vector<serial::LineDevice*>{&s1, &s2});
    auto link = std::make_shared<serial::LineLink>(port, Client::line_options(std::chrono::milliseconds(30)));
    Client c1(link, {1, std::nullopt, 1}), c2(link, {2, std::nullopt, 1});
    c1.set_high_speed(2000);
    EXPECT_EQ(c1.high_speed(), 2000);
    EXPECT_EQ(c2.high_speed(), 1000);
    Client::broadcast(*link, "J+");
    clock.advance(1'000'000'000);
    EXPECT_TRUE(c1.moving());
    EXPECT_TRUE(c2.moving());
    c1.abort();
    EXPECT_FALSE(c1.moving());
    EXPECT_TRUE(c2.moving());
    Client::broadcast(*link, "ABORT");
    EXPECT_FALSE(c2.moving());
    EXPECT_EQ(port->written.find("@00ABORT\r") != std::string::npos, true);
    // Nobody answers an address that is not on the line.
    Client c3(link, {3, std::chrono::milliseconds(10), 0});
    EXPECT_THROW(c3.position(), motorbus::TimeoutError);
}

TEST(ArcusSim, AccIsAdjustedIntoTheAppendixAWindow) {
    Bench b;
    b.c.set_high_speed(20000);
    b.c.set_low_speed(100);
    b.c.set_acceleration(50000);
    EXPECT_EQ(b.c.acceleration(), 19900);
    b.c.set_high_speed(900000);
    b.c.set_low_speed(1000);
    b.c.set_acceleration(99999);
    EXPECT_EQ(b.c.acceleration(), 23050);
    b.c.set_high_speed(10000);
    b.c.set_acceleration(1);
    EXPECT_EQ(b.c.acceleration(), 2);  // window 1 minimum
}

// ---- A15 on the simulator: hostile request lines ----

TEST(ArcusSim, A15HostileLinesNeverCrashAndResync) {
    SimClock clock;
    Sim sim(clock);
    EXPECT_EQ(sim.on_line(std::string(5000, 'A')), "");
    EXPECT_EQ(sim.on_line(std::string("\x00\xff\x80\x01", 4)), "");
    EXPECT_EQ(sim.on_line(std::string("@01\xff\xfe", 5)), nul("?"));
    EXPECT_EQ(sim.on_line("@01" + std::string(200, 'X')), nul("?"));  // over-long command
    EXPECT_EQ(sim.on_line("@01ex"), nul("?ex"));                     // case sensitive
    EXPECT_EQ(sim.on_line("@01HSPD=abc"), nul("?HSPD=abc"));
    EXPECT_EQ(sim.on_line("@01HSPD=99999999999"), nul("?HSPD=99999999999"));
    EXPECT_EQ(sim.on_line("@0"), "");
    EXPECT_EQ(sim.on_line("@ab"), "");
    // Noise in front of a request: the parser restarts at '@'.
    EXPECT_EQ(sim.on_line("\xff\xff@01EX"), nul("0"));
    EXPECT_EQ(sim.on_line("@01EX"), nul("0"));
    EXPECT_EQ(sim.max_request(), kMaxRequest + 3);
    EXPECT_EQ(sim.on_overlong(), "");
}

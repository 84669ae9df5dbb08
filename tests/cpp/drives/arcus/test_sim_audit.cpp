// Defects found by a line-by-line audit of the simulator against manual 000.
// Each test failed before its fix (see the commit that added it).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "fixture.hpp"

using namespace motorbus;
using namespace motorbus::arcus;
using arcus_test::Bench;

// Tables 7.2 / 7.11: POL bit 7 inverts the in-position output (DO1), bit 8 the
// alarm output (DO3).  Both outputs are dedicated here (SL=1, EDO=1).
TEST(ArcusAudit, PolarityBits7And8InvertInPositionAndAlarm) {
    Bench b;
    b.c.enable(true);
    b.c.move(1000);
    b.run(3);
    ASSERT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_TRUE(b.c.digital_output(1));   // in position
    EXPECT_FALSE(b.c.digital_output(3));  // no alarm
    b.c.set_polarity(128);
    EXPECT_FALSE(b.c.digital_output(1));  // in position, output inverted
    EXPECT_FALSE(b.c.digital_output(3));
    b.c.set_polarity(256);
    EXPECT_TRUE(b.c.digital_output(1));
    EXPECT_TRUE(b.c.digital_output(3));   // no alarm, output inverted
    b.c.set_polarity(128 | 256);
    EXPECT_EQ(b.c.digital_outputs() & 5u, 4u);
    b.sim.disturb(1000);  // 1250 counts > SLE while idle: range error -> alarm
    ASSERT_EQ(b.c.snl_status(), SnlStatus::CorrectionRangeError);
    EXPECT_TRUE(b.c.digital_output(1));   // not in position, inverted
    EXPECT_FALSE(b.c.digital_output(3));  // alarm, inverted
}

// Table 7.10 lists SLR among the stored StepNLoop parameters; the manual gives
// no syntax.  The reading (docs/drives/arcus.md): SLR reads the ratio of motor
// pulses to encoder counts with three decimals, SLR=<value> sets it
// (0.001..999.999).  The DMX-CAN's own ratio is 3200/4000 = 0.800.
TEST(ArcusAudit, SlrReadsWritesAndIsStored) {
    auto path = std::filesystem::temp_directory_path() / ("arcus_slr_" + std::to_string(::getpid()) + ".txt");
    std::filesystem::remove(path);
    SimOptions o;
    o.store_path = path.string();
    {
        Bench b(o);
        EXPECT_EQ(b.raw("SLR"), "0.800");
        EXPECT_EQ(b.raw("SLR=1"), "OK");
        EXPECT_EQ(b.raw("SLR"), "1.000");
        EXPECT_EQ(b.raw("SLR=0.25"), "OK");
        EXPECT_EQ(b.raw("SLR"), "0.250");
        EXPECT_EQ(b.raw("SLR=0"), "?SLR=0");
        EXPECT_EQ(b.raw("SLR=1000"), "?SLR=1000");
        EXPECT_EQ(b.raw("SLR=-1"), "?SLR=-1");
        EXPECT_EQ(b.raw("SLR=0.0001"), "?SLR=0.0001");
        EXPECT_EQ(b.raw("SLR=abc"), "?SLR=abc");
        EXPECT_EQ(b.raw("SLR=0.8"), "OK");
        EXPECT_DOUBLE_EQ(b.c.snl_ratio(), 0.8);
        b.c.set_snl_ratio(1.5);
        EXPECT_DOUBLE_EQ(b.c.snl_ratio(), 1.5);
        EXPECT_THROW(b.c.set_snl_ratio(0), InvalidArgument);
        b.c.store();
        b.c.set_snl_ratio(2);
        b.sim.power_cycle();
        EXPECT_DOUBLE_EQ(b.c.snl_ratio(), 1.5);  // the stored value, not the later one
    }
    std::filesystem::remove(path);
}

// The ratio is what StepNLoop converts counts to pulses with: a wrong one
// (1 pulse per count on a 0.8 motor) overshoots and StepNLoop corrects it.
TEST(ArcusAudit, SlrIsTheRatioStepNLoopMovesWith) {
    Bench b;
    b.c.enable(true);
    b.c.set_snl_ratio(1.0);
    b.c.move(1000);  // 1000 pulses = 1250 counts: out of position by 250
    b.run(20);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_LE(std::llabs(b.c.encoder() - 1000), 20);  // corrected within SLT
    EXPECT_NEAR(b.sim.physical_position(), b.c.encoder() * 0.8, 1.0);
}

// Table 11.0: "ABORT ... is used for clearing the StepNLoop error status": all
// of it, the limit error (SLS 11) included.  The MST limit error bits stay
// latched until CLR (Table 7.3), so moves are still refused.
TEST(ArcusAudit, AbortClearsTheStepNLoopLimitError) {
    SimOptions o;
    o.world.plus_limit = 1500;
    Bench b(o);
    b.c.enable(true);
    b.c.jog(1);
    b.run(5);
    ASSERT_EQ(b.c.snl_status(), SnlStatus::LimitError);
    ASSERT_EQ(b.c.status().raw, 32u + 128u);
    b.c.abort();
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_EQ(b.c.status().raw, 32u + 128u);  // MST error: CLR only
    EXPECT_EQ(b.raw("X0"), "?State Error");
    b.c.clear();
    EXPECT_EQ(b.c.status().raw, 32u);
}

// Chapter 7, "Sync Output", condition 1: "the sync output pulse will turn on
// only when the encoder position and sync position are equal".  SYNS keeps
// "occurred" (2) after the pulse.
TEST(ArcusAudit, SyncEqualIsAPulseWhilePositionsAreEqual) {
    Bench b;  // StepNLoop: the move stops on the exact encoder count
    b.c.enable(true);
    b.c.set_sync_position(500);
    b.c.set_sync_condition(SyncCondition::Equal);
    b.c.sync_on();
    b.c.move(500);
    b.run(3);
    ASSERT_EQ(b.c.encoder(), 500);
    EXPECT_EQ(b.c.sync_status(), SyncStatus::Occurred);
    EXPECT_TRUE(b.c.digital_output(2));   // equal now
    b.c.move(1000);
    b.run(3);
    ASSERT_EQ(b.c.encoder(), 1000);
    EXPECT_EQ(b.c.sync_status(), SyncStatus::Occurred);
    EXPECT_FALSE(b.c.digital_output(2));  // the pulse is over
    b.c.move(500);
    b.run(3);
    EXPECT_TRUE(b.c.digital_output(2));   // equal again
}

// §6 (Figure 6.6, 3): "When motor is disabled, no motion is done."  With EO=0
// a motion command is accepted and nothing moves: no pulses (PX stays), no
// stall, no homing; EO=0 during a move stops it at once.
TEST(ArcusAudit, DisabledMotorDoesNoMotion) {
    Bench b;  // EO=0 at boot (EOBOOT=0), StepNLoop on
    EXPECT_EQ(b.raw("X3000"), "OK");
    b.run(5);
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.c.encoder(), 0);
    EXPECT_EQ(b.c.status().raw, 0u);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);  // no stall error
    EXPECT_EQ(b.raw("J+"), "OK");
    EXPECT_FALSE(b.c.moving());
    EXPECT_EQ(b.raw("H+"), "OK");
    EXPECT_FALSE(b.c.moving());
    b.run(1);
    EXPECT_EQ(b.c.position(), 0);
    // Powered: moves; EO=0 while moving stops the pulses at once.
    b.c.enable(true);
    b.c.jog(1);
    b.run(0.5);
    ASSERT_TRUE(b.c.moving());
    b.c.enable(false);
    EXPECT_FALSE(b.c.moving());
    const auto p = b.c.position();
    b.run(1);
    EXPECT_EQ(b.c.position(), p);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
}

// Table 7.5, SLM: "an additional correction will be performed using idle
// current instead of run current": CUR reads CURI during that correction.
TEST(ArcusAudit, SlmCorrectionRunsOnIdleCurrent) {
    Bench b;
    b.c.enable(true);
    b.c.move(2000);
    b.run(5);
    ASSERT_EQ(b.c.current(), 1000);  // idle current after CURT
    b.sim.disturb(40);               // 50 counts: first correction, run current
    ASSERT_EQ(b.c.snl_status(), SnlStatus::Correcting);
    EXPECT_EQ(b.c.current(), 1600);
    b.run(0.1);
    b.sim.disturb(8);                // 10 counts more than the correction will make up
    b.run(0.45);                     // the first correction (50 counts at LSPD 100/s) ended
    ASSERT_EQ(b.c.snl_status(), SnlStatus::Correcting);  // the second (SLM) correction
    EXPECT_EQ(b.c.current(), 1000);  // on idle current
    b.run(2);
    EXPECT_EQ(b.c.snl_status(), SnlStatus::Idle);
    EXPECT_EQ(b.c.encoder(), 2000);
}

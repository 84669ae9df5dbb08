// The simulator driven line by line (on_line) on a SimClock.
#include <gtest/gtest.h>

#include <cmath>

#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/drives/dmac/profile.hpp"
#include "sim_rig.hpp"

using namespace motorbus;
using namespace motorbus::dmac;
using motorbus::dmac::testing::Rig;

// ---- the manual's examples, byte for byte (tests/vectors/seed_examples.json) -----
TEST(Sim, SeedExamplesByteForByte) {
    Rig r0(0);
    EXPECT_EQ(r0.tx("00#ACCEL_TIME:=123"), "");
    EXPECT_EQ(r0.tx("00READ #ACCEL_TIME"), "00#ATI=+123\r\n");
    r0.tx("00#ACCEL_TIME:=H100");
    EXPECT_EQ(r0.tx("00READ h#ACCEL_TIME"), "00#ATI=h00000100\r\n");
    r0.tx("00#ACCEL_TIME:=B1100100");
    EXPECT_EQ(r0.tx("00READ b#ACCEL_TIME"), "00#ATI=b00000000 00000000 00000000 01100100\r\n");
    r0.tx("00#V20:=-40");
    EXPECT_EQ(r0.tx("00READ #V20"), "00#V20=-40\r\n");
    r0.tx("00#V20:=HFFFFFFD8");
    EXPECT_EQ(r0.tx("00READ #V20"), "00#V20=-40\r\n");
    r0.tx("00#V10.3:=1");
    EXPECT_EQ(r0.tx("00READ #V10"), "00#V10=+4\r\n");
    r0.tx("#HIGH_SPEED:=10000, MOVE_TO 1234");
    EXPECT_EQ(r0.read(Var::HighSpeed), 10000);
    EXPECT_GE(r0.run_until_idle(), 1);
    EXPECT_EQ(r0.read(Var::Position), 1234);
    r0.tx("00OPEN_SEQ");
    r0.tx("00:3 MOVE_TO 2000");
    r0.tx("00CLOSE_SEQ");
    EXPECT_EQ(r0.tx("00READ_SEQ 3"), "00: 003 MTO +2000\r\n");

    Rig r1(1);
    r1.tx("01#OUTPUT:=7");
    EXPECT_EQ(r1.tx("01READ h#OUTPUT"), "01#OUT=h00000007\r\n");
    r1.sim->inject_error(error::kOvervoltage);
    EXPECT_EQ(r1.tx("01READ b#ERROR"), "01#ERR=b00000000 00000000 00000000 00010000\r\n");

    Rig r2(2);
    r2.sim->set_input(2, true);
    r2.sim->set_input(4, true);
    EXPECT_EQ(r2.tx("02READ b#INPUT"), "02#INP=b00000000 00000000 00000000 00001010\r\n");
    EXPECT_EQ(r2.tx("02READ #SUPPLY_VOLTAGE"), "02#SVO=+32000\r\n");

    Rig r3(3);
    r3.tx("03S_CURVE ON, MOVE_SPEED 20000");
    r3.ms(10);
    EXPECT_EQ(r3.tx("03READ h#STATUS"), "03#STA=h13000800\r\n");

    Rig r4(4);
    r4.tx("04MOVE_SPEED -20000");
    r4.ms(2000);
    EXPECT_EQ(r4.tx("04READ #SPEED"), "04#SPE=-20000\r\n");
    EXPECT_EQ(r4.tx("04REQUEST_VERSION"),
              "04EV v1.7 H142 \"MIDI-INGENIERIE_DMAC34-1_H142-10145_25/01/05_12/04/06\" PHASE:6A BOOT:v1.1\r\n");
}

TEST(Sim, MnemonicsAndFullNamesAreTheSameCommand) {
    Rig r;
    r.tx("00#HSP:=20000");
    EXPECT_EQ(r.tx("00REA #HIGH_SPEED"), "00#HSP=+20000\r\n");
    r.tx("00MTO 500");
    r.run_until_idle();
    EXPECT_EQ(r.val("00READ #POS"), 500);
    r.tx("00MON -200");
    r.run_until_idle();
    EXPECT_EQ(r.val("00READ #POSITION"), 300);
}

TEST(Sim, ReadBitAndWriteBit) {
    Rig r;
    r.tx("00S_CURVE ON");
    EXPECT_EQ(r.tx("00READ #STATUS.12"), "00#STA.12=+1\r\n");
    EXPECT_EQ(r.tx("00READ #STATUS.5"), "00#STA.5=+0\r\n");
    r.tx("00#OUTPUT.4:=1");
    EXPECT_EQ(r.read(Var::Output), 8);
    r.tx("00#V12.1:=#STATUS.12 & #ERROR.2");
    EXPECT_EQ(r.read(v_var(12)), 0);
    r.tx("00#OUTPUT.4:=2");  // a bit is 0 or 1
    EXPECT_TRUE(bit_set(static_cast<std::uint32_t>(r.read(Var::Error)), error::kLimit));
}

// ---- variables: ranges, read-only, stored vs volatile, resets -------------------
TEST(Sim, RangesAndReadOnlyFlagErrors) {
    Rig r;
    r.tx("00#HIGH_SPEED:=400001");
    EXPECT_EQ(r.read(Var::HighSpeed), 60000);
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Error)), bit_mask(error::kLimit));
    r.tx("00#ERROR:=0");
    EXPECT_EQ(r.read(Var::Error), 0);
    r.tx("00#STATUS:=1");
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Error)), bit_mask(error::kSyntax));
    r.tx("00#ERROR:=0, #INTERPOL_TIME:=1");
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Error)), bit_mask(error::kLimit));
    EXPECT_EQ(r.read(Var::InterpolTime), 100);
    EXPECT_EQ(r.tx("00READ #STATUS.31"), "00#STA.31=+1\r\n");  // error summary bit
    r.tx("00#ERROR:=0, #V1:=5 / 0");
    EXPECT_EQ(static_cast<std::uint32_t>(r.read(Var::Error)), bit_mask(error::kComputation));
    EXPECT_EQ(r.read(v_var(1)), 0);
    // DMAC34-only variables do not exist on a DMAC23.
    Rig r23(0, Model::Dmac23_1);
    EXPECT_EQ(r23.tx("00READ #MOTOR_TEMPERATURE"), "");
    EXPECT_EQ(static_cast<std::uint32_t>(r23.read(Var::Error)), bit_mask(error::kSyntax));
    EXPECT_EQ(r.tx("00READ #MOTOR_TEMPERATURE"), "00#MTE=+650\r\n");
    EXPECT_EQ(r.tx("00READ #CPU_TEMPERATURE"), "00#CTE=+520\r\n");
}

TEST(Sim, ModuleResetKeepsStoredVariablesAndClearsVolatileOnes) {
    Rig r;
    r.tx("00#V1:=5, #M1:=7, #HIGH_SPEED:=20000, #OUTPUT:=3, #ACCEL_TIME:=500, #TIMER_1:=100");
    r.tx("00#INTERPOL_TIME:=50, SOFT_ENDS ON, HARD_ENDS ALL, S_CURVE ON, #POSITION:=1234");
    r.tx("00MODULE_RESET");
    EXPECT_EQ(r.read(v_var(1)), 0);
    EXPECT_EQ(r.read(m_var(1)), 7);
    EXPECT_EQ(r.read(Var::HighSpeed), 20000);
    EXPECT_EQ(r.read(Var::AccelTime), 500);
    EXPECT_EQ(r.read(Var::Output), 0);       // outputs forced inactive
    EXPECT_EQ(r.read(timer_var(1)), 0);
    EXPECT_EQ(r.read(Var::InterpolTime), 100);
    EXPECT_EQ(r.read(Var::Position), 1234);  // position is stored
    auto st = static_cast<std::uint32_t>(r.read(Var::Status));
    EXPECT_TRUE(bit_set(st, status::kSoftEndsEnabled));
    EXPECT_TRUE(bit_set(st, status::kSCurve));
    EXPECT_FALSE(bit_set(st, status::kPowerOn));

    r.tx("00SET_ADDRESS 5");
    r.tx("05#LINE_DELAY:=1000");
    r.tx("05MODULE_RESET ALL");
    // The factory table of MODULE_RESET ALL (not the annex's +-100000 end-stops).
    EXPECT_EQ(r.read(Var::HighSpeed), 60000);
    EXPECT_EQ(r.read(Var::LowSpeed), 6000);
    EXPECT_EQ(r.read(Var::TorqueRatio), 50);
    EXPECT_EQ(r.read(Var::AccelTime), 1000);
    EXPECT_EQ(r.read(Var::DecelTime), 1000);
    EXPECT_EQ(r.read(Var::PositiveEnd), 10000);
    EXPECT_EQ(r.read(Var::NegativeEnd), -10000);
    EXPECT_EQ(r.read(Var::Position), 0);
    EXPECT_EQ(r.read(Var::OutputConfig), 3);
    EXPECT_EQ(r.read(Var::OnReset), 0);
    EXPECT_EQ(r.read(m_var(1)), 0);
    st = static_cast<std::uint32_t>(r.read(Var::Status));
    EXPECT_FALSE(bit_set(st, status::kSoftEndsEnabled));
    EXPECT_FALSE(bit_set(st, status::kHardPosEnabled));
    EXPECT_FALSE(bit_set(st, status::kSCurve));
    // Serial line configuration survives.
    EXPECT_EQ(r.sim->address(), 5);
    EXPECT_EQ(r.read(Var::LineDelay), 1000);
}

TEST(Sim, OnResetStartsTheSequencer) {
    Rig r;
    r.tx("00OPEN_SEQ");
    r.tx("00:7 #V1:=#V1 + 1");
    r.tx("00JUMP 0");
    r.tx("00CLOSE_SEQ");
    r.tx("00#ON_RESET:=7");
    r.sim->power_cycle();
    EXPECT_TRUE(r.sim->state().sequencer_running);
    r.ms(5);
    EXPECT_EQ(r.read(v_var(1)), 1);
    EXPECT_FALSE(r.sim->state().sequencer_running);
}

// ---- addressing -------------------------------------------------------------------------
TEST(Sim, GlobalCommandsRunEverywhereButOnlyAddressZeroAnswers) {
    Rig a(0), b(1);
    b.clock = a.clock;
    b.sim = std::make_shared<Sim>(a.clock, SimOptions{.address = 1});
    EXPECT_EQ(a.tx("READ #POSITION"), "00#POS=+0\r\n");
    EXPECT_EQ(b.tx("READ #POSITION"), "");
    a.tx("#V3:=9");
    b.tx("#V3:=9");
    EXPECT_EQ(a.read(v_var(3)), 9);
    EXPECT_EQ(b.read(v_var(3)), 9);
    EXPECT_EQ(b.tx("00READ #V3"), "");       // not addressed
    EXPECT_EQ(b.tx("01READ #V3"), "01#V3=+9\r\n");
    EXPECT_EQ(b.tx("64READ #V3"), "");       // no such address
}

// ---- motion -----------------------------------------------------------------------------
TEST(Sim, MoveToFollowsTheDmacProfileTimes) {
    Rig r;
    r.tx("00MOVE_TO 200000");
    // 0 -> 100 inc/ms in #ACCEL_TIME (1 s): 50000 inc; 100 -> #LOW_SPEED (10 inc/ms)
    // in 0.9 s: 49500 inc; the last 1000 inc closed-loop: tau 100 ms, ends in
    // tau (ln 1000 + 1); the rest cruises at 100 inc/ms.
    const double expected_ms = 1000 + (200000 - 100500) / 100.0 + 900 + 100 * (std::log(1000.0) + 1);
    Motion ref;
    ref.move_to(0, 200000);
    EXPECT_NEAR(ref.profile().duration() * 1000, expected_ms, 1.0);
    r.ms(1000);
    EXPECT_EQ(r.val("00READ #SPEED"), 60000);
    EXPECT_NEAR(r.val("00READ #POSITION"), 50000, 1);
    auto t = r.run_until_idle() + 1000;
    EXPECT_NEAR(static_cast<double>(t), expected_ms, 2.0);
    EXPECT_EQ(r.val("00READ #POSITION"), 200000);
    EXPECT_EQ(r.val("00READ #SPEED"), 0);
    auto st = static_cast<std::uint32_t>(r.read(Var::Status));
    EXPECT_FALSE(bit_set(st, status::kBusy));
    EXPECT_TRUE(bit_set(st, status::kPowerOn));  // moves force power on
}

TEST(Sim, PositionControlBitDuringTheLastTenthOfATurn) {
    Rig r;
    r.tx("00MOVE_TO 20000");
    bool seen_loop = false, seen_before = false;
    for (int i = 0; i < 5000 && bit_set(r.sim->state().status, status::kMovement); ++i) {
        auto s = r.sim->state();
        const bool pc = bit_set(s.status, status::kPositionControl);
        if (pc) {
            seen_loop = true;
            EXPECT_LE(20000 - s.position, 1001);
            EXPECT_LE(std::abs(s.speed), 6000 + 1);
        } else if (!seen_loop) {
            seen_before = true;
        }
        r.ms(1);
    }
    EXPECT_TRUE(seen_before);
    EXPECT_TRUE(seen_loop);
    EXPECT_EQ(r.read(Var::Position), 20000);
}

TEST(Sim, MoveSpeedRampIsProportionalToTheSpeedChange) {
    Rig r;
    r.tx("00MOVE_SPEED 30000");  // manual: ATI 1000, HSP 60000 -> 0.5 s
    r.ms(250);
    EXPECT_NEAR(r.val("00READ #SPEED"), 15000, 100);
    r.ms(250);
    EXPECT_EQ(r.val("00READ #SPEED"), 30000);
    r.tx("00MOVE_SPEED 500000");  // out of range: refused
    EXPECT_TRUE(bit_set(static_cast<std::uint32_t>(r.read(Var::Error)), error::kLimit));
    r.tx("00#ERROR:=0, MOVE_SPEED 400000");  // clamped to #HIGH_SPEED
    r.ms(2000);
    EXPECT_EQ(r.val("00READ #SPEED"), 60000);
    r.tx("00STOP");  // decelerates in #DECEL_TIME from #HIGH_SPEED
    r.ms(500);
    EXPECT_NEAR(r.val("00READ #SPEED"), 30000, 100);
    r.ms(501);
    EXPECT_EQ(r.val("00READ #SPEED"), 0);
}

TEST(Sim, HaltStopsAtOnce) {
    Rig r;
    r.tx("00MOVE_SPEED 60000");
    r.ms(1500);
    auto p = r.read(Var::Position);
    r.tx("00HALT");
    EXPECT_EQ(r.val("00READ #SPEED"), 0);
    r.ms(100);
    EXPECT_EQ(r.read(Var::Position), p);
}

TEST(Sim, SoftEndStopsStopTheAxisAndOnlyAllowReverse) {
    Rig r;
    r.tx("00SOFT_ENDS ON");
    r.tx("00MOVE_TO 20000");  // #POSITIVE_END = 10000
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 10000);
    auto st = static_cast<std::uint32_t>(r.read(Var::Status));
    EXPECT_TRUE(bit_set(st, status::kSoftPosEnd));
    EXPECT_TRUE(bit_set(st, status::kAbnormalStop));
    r.tx("00MOVE_ON 100");  // further CW is refused
    EXPECT_TRUE(bit_set(static_cast<std::uint32_t>(r.read(Var::Error)), error::kLimit));
    EXPECT_EQ(r.run_until_idle(), 0);
    r.tx("00#ERROR:=0, MOVE_TO 0");  // reverse is fine
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 0);
    st = static_cast<std::uint32_t>(r.read(Var::Status));
    EXPECT_FALSE(bit_set(st, status::kSoftPosEnd));
    EXPECT_FALSE(bit_set(st, status::kAbnormalStop));
    r.tx("00#NEGATIVE_END:=-500, MOVE_SPEED -6000");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), -500);
    EXPECT_TRUE(bit_set(static_cast<std::uint32_t>(r.read(Var::Status)), status::kSoftNegEnd));
}

TEST(Sim, HardEndStopsFollowInputsAndPolarity) {
    Rig r(0, Model::Dmac23_1);  // IN1 = positive, IN2 = negative end-stop
    r.tx("00HARD_ENDS POS");
    r.tx("00MOVE_SPEED 6000");
    r.ms(200);
    r.sim->set_input(1, true);
    auto p = r.read(Var::Position);
    EXPECT_EQ(r.val("00READ #SPEED"), 0);
    auto st = static_cast<std::uint32_t>(r.read(Var::Status));
    EXPECT_TRUE(bit_set(st, status::kHardPosEnd));
    EXPECT_TRUE(bit_set(st, status::kHardPosEnabled));
    EXPECT_FALSE(bit_set(st, status::kHardNegEnabled));
    r.tx("00MOVE_ON 10");
    EXPECT_EQ(r.read(Var::Position), p);
    r.tx("00#ERROR:=0, MOVE_ON -100");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), p - 100);
    // Negative end-stop disabled: IN2 does nothing.
    r.sim->set_input(2, true);
    r.tx("00MOVE_ON -100");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), p - 200);
    // With inverted inputs, an inactive physical IN1 reads active.
    r.sim->set_input(1, false);
    r.tx("00INVERSE_POLARITY IN");
    EXPECT_TRUE(bit_set(static_cast<std::uint32_t>(r.read(Var::Status)), status::kHardPosEnd));
    EXPECT_EQ(r.read(Var::Input), 0x3F & ~0x2);
}

TEST(Sim, SynchroOnArmsMovesUntilSynchroTop) {
    auto clock = std::make_shared<SimClock>();
    Sim a(clock, SimOptions{.address = 0}), b(clock, SimOptions{.address = 3});
    a.on_line("00BRAKE OFF");  // factory BRAKE ON (annex 7.1)
    b.on_line("03BRAKE OFF");
    for (auto* s : {&a, &b}) s->on_line("SYNCHRO ON");
    a.on_line("00MOVE_SPEED 4000");
    b.on_line("03MOVE_SPEED -12500");
    clock->advance(100'000'000);
    EXPECT_EQ(a.state().speed, 0);
    EXPECT_TRUE(bit_set(a.state().status, status::kSynchro));
    for (auto* s : {&a, &b}) s->on_line("SYNCHRO TOP");
    for (auto* s : {&a, &b}) s->on_line("SYNCHRO OFF");
    clock->advance(2'000'000'000);
    EXPECT_EQ(a.state().speed, 4000);
    EXPECT_EQ(b.state().speed, -12500);
}

TEST(Sim, PowerAndBrake) {
    Rig r;
    r.tx("00POWER ON");
    EXPECT_TRUE(r.sim->state().power);
    r.tx("00POWER OFF");
    EXPECT_FALSE(r.sim->state().power);
    r.tx("00BRAKE ON");
    EXPECT_TRUE(bit_set(r.sim->state().status, status::kBrake));
    r.tx("00MOVE_TO 100");
    EXPECT_TRUE(bit_set(r.sim->state().error, error::kLimit));
    EXPECT_EQ(r.run_until_idle(), 0);
    Rig r17(0, Model::Dmac17);
    r17.tx("00BRAKE ON");  // DMAC34 only
    EXPECT_TRUE(bit_set(r17.sim->state().error, error::kSyntax));
}

TEST(Sim, CaptureAndReferenceOnIn5) {
    Rig r;
    r.tx("00REFERENCE ON");
    EXPECT_TRUE(bit_set(r.sim->state().status, status::kReference));
    r.tx("00MOVE_SPEED 6000");
    r.ms(1000);
    const auto p = r.read(Var::Position);
    r.sim->set_input(5, true);
    EXPECT_EQ(r.read(Var::Capture), p);
    EXPECT_LE(std::abs(r.read(Var::Position)), 1);
    EXPECT_FALSE(bit_set(r.sim->state().status, status::kReference));
    r.sim->set_input(5, false);
    r.ms(100);
    r.sim->set_input(5, true);  // capture only, no re-home now
    EXPECT_GT(r.read(Var::Position), 900);
    EXPECT_EQ(r.read(Var::Capture), r.read(Var::Position));
}

TEST(Sim, OutputsWithAlternateFunctionsAndPolarity) {
    Rig r(0, Model::Dmac23_1);
    r.tx("00#OUTPUT:=4");
    EXPECT_EQ(r.sim->physical_outputs(), 4u);  // not busy, no fault
    r.tx("00MOVE_SPEED 100");
    EXPECT_EQ(r.sim->physical_outputs(), 5u);  // OUT1 = BUSY
    r.sim->inject_error(error::kUndervoltage);
    // OUT2 = FAULT; the undervoltage also stopped the motor (manual 2.1), so OUT1 is off.
    EXPECT_EQ(r.sim->physical_outputs(), 6u);
    r.tx("00#OUTPUT_CONFIG:=0");
    EXPECT_EQ(r.sim->physical_outputs(), 4u);
    r.tx("00INVERSE_POLARITY OUT");
    EXPECT_EQ(r.sim->physical_outputs(), 0xBu);
}

// ---- sequencer -------------------------------------------------------------------------
TEST(Sim, SequenceOneRevEveryTwoSeconds) {
    Rig r;
    for (auto l : {"OPEN_SEQ", "MOVE_ON 10000", "WAIT 2000", "JUMP 1", "CLOSE_SEQ"}) r.tx(std::string("00") + l);
    EXPECT_EQ(r.sim->sequence_line(1), "MON +10000");
    EXPECT_EQ(r.sim->sequence_line(2), "WAI +2000");
    EXPECT_EQ(r.sim->sequence_line(3), "JUM +1");
    r.tx("00START_SEQ");
    EXPECT_TRUE(bit_set(r.sim->state().status, status::kSeqRun));
    r.ms(1);  // line 1 runs on the first millisecond tick
    EXPECT_TRUE(bit_set(r.sim->state().status, status::kMovement));
    r.ms(2000);  // line 2 at t=2, line 3 at t=2002
    EXPECT_EQ(r.read(Var::Position), 10000);
    EXPECT_EQ(r.read(Var::Line), 2);
    r.ms(2);  // t=2003: line 3 (JUMP 1); t=2004 not yet: line 1 runs at 2004
    r.ms(1);
    EXPECT_TRUE(bit_set(r.sim->state().status, status::kMovement));
    r.ms(2000);
    EXPECT_EQ(r.read(Var::Position), 20000);
    r.tx("00STOP");
    EXPECT_FALSE(r.sim->state().sequencer_running);
    EXPECT_EQ(r.read(Var::Line), 0);
}

TEST(Sim, SequenceOneLinePerMillisecond) {
    Rig r;
    r.tx("00OPEN_SEQ");
    for (int i = 0; i < 10; ++i) r.tx("00#V1:=#V1 + 1");
    r.tx("00CLOSE_SEQ");
    r.tx("00START_SEQ 1");
    r.ms(4);
    EXPECT_EQ(r.read(v_var(1)), 4);
    r.ms(100);
    EXPECT_EQ(r.read(v_var(1)), 10);
    EXPECT_TRUE(r.sim->state().sequencer_running);  // empty lines run as NOP...
    r.ms(400);
    EXPECT_FALSE(r.sim->state().sequencer_running);  // ...until past line 500
}

TEST(Sim, SequenceExample1OutputFollowsSupplyVoltage) {
    Rig r;
    for (auto l : {"OPEN_SEQ", "IF #SUPPLY_VOLTAGE < 15000 JUMP 5", "IF #SUPPLY_VOLTAGE > 20000 JUMP 5",
                   "#OUTPUT.4:=1", "JUMP 1", "#OUTPUT.4:=0", "JUMP 1", "CLOSE_SEQ", "START_SEQ 1"})
        r.tx(std::string("00") + l);
    r.ms(10);
    EXPECT_EQ(r.read(Var::Output), 0);  // 32 V: off
    r.sim->set_supply_voltage(18000);
    r.ms(10);
    EXPECT_EQ(r.read(Var::Output), 8);
    r.sim->set_supply_voltage(12000);
    r.ms(10);
    EXPECT_EQ(r.read(Var::Output), 0);
}

TEST(Sim, SequenceExample2AnalogSpeedLoopWithMnemonics) {
    Rig r(0, Model::Dmac23_1);
    for (auto l : {"OSE", ":50 #V1:=#IAN - 15000", "#V1:=#V1 * 5", "MSP #V1", "JRE -3", "CSE", "SSE 50"})
        r.tx(std::string("00") + l);
    r.sim->set_analog(1, 17000);  // (17000 - 15000) * 5 = 10000
    r.ms(3000);
    EXPECT_EQ(r.val("00READ #SPEED"), 10000);
    EXPECT_EQ(r.sim->sequence_line(53), "JRE -3");
}

TEST(Sim, SequenceExample3InputsTriggerMoves) {
    Rig r;
    for (auto l : {"OPEN_SEQ", "IF #INPUT.2 = 1 JUMP_REL +3", "IF #INPUT.3 = 1 JUMP_REL +4", "JUMP 1",
                   "MOVE_ON 10000", "JUMP_REL 2", "MOVE_ON -10000", "WAIT 0", "JUMP 1", "CLOSE_SEQ",
                   "START_SEQ 1"})
        r.tx(std::string("00") + l);
    r.ms(50);
    EXPECT_EQ(r.read(Var::Position), 0);
    r.sim->set_input(2, true);
    r.ms(5);
    r.sim->set_input(2, false);
    r.ms(3000);
    EXPECT_EQ(r.read(Var::Position), 10000);
    r.sim->set_input(3, true);
    r.ms(5);
    r.sim->set_input(3, false);
    r.ms(3000);
    EXPECT_EQ(r.read(Var::Position), 0);
}

TEST(Sim, SequenceExample4CallAndReturn) {
    Rig r;
    for (auto l : {"OPEN_SEQ", ":150 IF #INPUT.3 = 0 CALL 160", "IF #SUPPLY_VOLTAGE > 30000 CALL 160", "JUMP 0",
                   ":160 #POSITION:=0", "#V5:=#V5 + 1", "RETURN", "CLOSE_SEQ", "#POSITION:=777", "START_SEQ 150"})
        r.tx(std::string("00") + l);
    r.ms(20);
    EXPECT_EQ(r.read(Var::Position), 0);
    EXPECT_EQ(r.read(v_var(5)), 2);  // called twice: input 3 off and 32 V > 30 V
    EXPECT_FALSE(r.sim->state().sequencer_running);
}

TEST(Sim, CallsNestFiveLevelsDeep) {
    Rig r;
    // Line k calls k+10; line 10+k is "CALL 10+k+1"...: a chain of `depth` calls.
    auto build = [&](int depth) {
        r.tx("00OPEN_SEQ");
        r.tx("00:1 CALL 11");
        r.tx("00JUMP 0");
        for (int d = 1; d < depth; ++d) r.tx("00:" + std::to_string(10 + d) + " CALL " + std::to_string(11 + d));
        r.tx("00:" + std::to_string(10 + depth) + " #V1:=" + std::to_string(depth));
        r.tx("00RETURN");
        for (int d = 1; d < depth; ++d) r.tx("00:" + std::to_string(10 + d + 1 + 50) + " NOP");
        r.tx("00CLOSE_SEQ");
    };
    build(5);
    // Each intermediate line's successor must be RETURN for the unwinding.
    for (int d = 1; d < 5; ++d) {
        r.tx("00OPEN_SEQ");
    }
    // Simpler explicit program: 5 nested calls work, the 6th overflows.
    Rig ok;
    for (auto l : {"OPEN_SEQ", "CALL 10", "JUMP 0", ":10 CALL 20", "RETURN", ":20 CALL 30", "RETURN", ":30 CALL 40",
                   "RETURN", ":40 CALL 50", "RETURN", ":50 #V1:=#V1 + 1", "RETURN", "CLOSE_SEQ", "START_SEQ 1"})
        ok.tx(std::string("00") + l);
    ok.ms(50);
    EXPECT_EQ(ok.read(v_var(1)), 1);
    EXPECT_EQ(ok.read(Var::Error), 0);
    EXPECT_FALSE(ok.sim->state().sequencer_running);
    Rig deep;
    for (auto l : {"OPEN_SEQ", "CALL 10", "JUMP 0", ":10 CALL 20", "RETURN", ":20 CALL 30", "RETURN", ":30 CALL 40",
                   "RETURN", ":40 CALL 50", "RETURN", ":50 CALL 60", "RETURN", ":60 #V1:=99", "RETURN", "CLOSE_SEQ",
                   "START_SEQ 1"})
        deep.tx(std::string("00") + l);
    deep.ms(50);
    EXPECT_EQ(deep.read(v_var(1)), 0);
    EXPECT_EQ(static_cast<std::uint32_t>(deep.read(Var::Error)), bit_mask(error::kLimit));
    EXPECT_FALSE(deep.sim->state().sequencer_running);
}

TEST(Sim, WaitPositiveZeroAndNegative) {
    Rig r;
    for (auto l : {"OPEN_SEQ", "MOVE_ON 10000", "WAIT 0", "#V1:=#POSITION", "MOVE_ON 100000", "WAIT -100",
                   "#V2:=#POSITION", "#V3:=#SPEED", "JUMP 0", "CLOSE_SEQ", "START_SEQ"})
        r.tx(std::string("00") + l);
    r.ms(5000);
    EXPECT_EQ(r.read(v_var(1)), 10000);  // WAIT 0: the move was complete
    EXPECT_GT(r.read(v_var(2)), 10000);  // WAIT -100: gave up after 100 ms
    EXPECT_LT(r.read(v_var(2)), 11000);
    EXPECT_GT(r.read(v_var(3)), 0);
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), 110000);
}

TEST(Sim, TimersCountDownEveryMillisecond) {
    Rig r;
    for (auto l : {"OPEN_SEQ", "#TIMER_2:=50", "IF #TIMER_2 != 0 JUMP_REL +0", "#V2:=1", "JUMP 0", "CLOSE_SEQ",
                   "START_SEQ"})
        r.tx(std::string("00") + l);
    r.ms(40);
    EXPECT_EQ(r.read(v_var(2)), 0);
    EXPECT_EQ(r.read(timer_var(2)), 11);
    r.ms(20);
    EXPECT_EQ(r.read(v_var(2)), 1);
    EXPECT_EQ(r.read(timer_var(2)), 0);
    r.tx("00#TIMER_3:=2000");
    r.ms(1500);
    EXPECT_EQ(r.read(timer_var(3)), 500);
}

TEST(Sim, OperatorsEvaluateOnInt32) {
    Rig r;
    r.tx("00#V1:=7");
    r.tx("00#V2:=#V1 * -3");
    r.tx("00#V3:=#V2 / 2");
    r.tx("00#V4:=#V1 & H3");
    r.tx("00#V5:=#V1 | B1000");
    r.tx("00#V6:=#V1 >= 7");
    r.tx("00#V7:=!#V1");
    r.tx("00#V8:=-#V1");
    r.tx("00#V9:=#V1 != 7");
    r.tx("00#V10:=H7FFFFFFF + 1");  // wraps like the 32-bit module
    r.tx("00#V11:=#V1 < 8");
    r.tx("00#V12:=#V1 - 10");
    EXPECT_EQ(r.read(v_var(2)), -21);
    EXPECT_EQ(r.read(v_var(3)), -10);
    EXPECT_EQ(r.read(v_var(4)), 3);
    EXPECT_EQ(r.read(v_var(5)), 15);
    EXPECT_EQ(r.read(v_var(6)), 1);
    EXPECT_EQ(r.read(v_var(7)), ~7);
    EXPECT_EQ(r.read(v_var(8)), -7);
    EXPECT_EQ(r.read(v_var(9)), 0);
    EXPECT_EQ(r.read(v_var(10)), -2147483647 - 1);
    EXPECT_EQ(r.read(v_var(11)), 1);
    EXPECT_EQ(r.read(v_var(12)), -3);
    EXPECT_EQ(r.read(Var::Error), 0);
    r.tx("00MOVE_TO -#V1");
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), -7);
}

TEST(Sim, MemorizedVariablesSurviveResetUserVariablesDoNot) {
    Rig r;
    r.tx("00#M2:=H100, #V13:=1234");
    r.sim->power_cycle();
    EXPECT_EQ(r.read(m_var(2)), 256);
    EXPECT_EQ(r.read(v_var(13)), 0);
}

TEST(Sim, StepExecutesOneLine) {
    Rig r;
    for (auto l : {"OPEN_SEQ", "#V1:=1", "#V1:=2", "#V1:=3", "CLOSE_SEQ"}) r.tx(std::string("00") + l);
    r.tx("00STEP 2");
    EXPECT_EQ(r.read(v_var(1)), 2);
    r.ms(10);
    EXPECT_EQ(r.read(v_var(1)), 2);  // the sequencer did not run on
    r.tx("00STEP");
    EXPECT_EQ(r.read(v_var(1)), 3);
    EXPECT_FALSE(r.sim->state().sequencer_running);
}

TEST(Sim, EditModeStatusBitAndLiveOnlyCommands) {
    Rig r;
    r.tx("00OPEN_SEQ");
    EXPECT_TRUE(bit_set(r.sim->state().status, status::kSeqEdit));
    EXPECT_EQ(r.tx("00READ #V1"), "00#V1=+0\r\n");  // READ still answers while editing
    r.tx("00MOVE_TO 5");  // stored, not executed
    EXPECT_EQ(r.run_until_idle(), 0);
    r.tx("00CLOSE_SEQ");
    EXPECT_FALSE(bit_set(r.sim->state().status, status::kSeqEdit));
    EXPECT_EQ(r.sim->sequence_line(1), "MTO +5");
    r.tx("00JUMP 3");  // sequence-only in live mode
    EXPECT_TRUE(bit_set(r.sim->state().error, error::kSyntax));
    r.tx("00OPEN_SEQ");  // erases the program
    r.tx("00CLOSE_SEQ");
    EXPECT_EQ(r.sim->sequence_line(1), "");
    EXPECT_EQ(r.tx("00READ_SEQ 1"), "00: 001\r\n");
}

// ---- interpolation -----------------------------------------------------------------------
TEST(Sim, InterpolationFifoAndXonError) {
    Rig r;
    r.tx("#INTERPOL_FIFOSIZE:=4");
    r.tx("#INTERPOL_TIME:=100");
    for (int i = 0; i < 4; ++i) EXPECT_EQ(r.tx("00MOVE_INTERPOL 100"), "");
    EXPECT_EQ(r.tx("00MOVE_INTERPOL 100"), std::string(1, '\x17'));
    EXPECT_EQ(r.tx("00MOVE_INTERPOL 100, READ #INTERPOL_COUNT"), "\x17" "00#ICO=+4\r\n");
    r.ms(1000);
    EXPECT_EQ(r.read(Var::Position), 0);  // nothing moves before SYNCHRO INTERPOL
    r.tx("SYNCHRO INTERPOL");
    r.ms(50);
    EXPECT_EQ(r.read(Var::Position), 50);
    EXPECT_EQ(r.val("00READ #SPEED"), 600);  // 100 inc per 100 ms = 1000 inc/s = 6 rpm
    r.ms(50);
    EXPECT_EQ(r.read(Var::Position), 100);
    EXPECT_EQ(r.read(Var::InterpolCount), 3);
    EXPECT_EQ(r.tx("00MOVE_INTERPOL -50, READ #ICO"), "00#ICO=+4\r\n");
    r.ms(400);
    EXPECT_EQ(r.read(Var::Position), 350);
    EXPECT_EQ(r.read(Var::InterpolCount), 0);
    EXPECT_FALSE(bit_set(r.sim->state().status, status::kMovement));
    // An empty FIFO stopped the movement: new segments wait for SYNCHRO INTERPOL.
    r.tx("00MOVE_INTERPOL 10");
    r.ms(200);
    EXPECT_EQ(r.read(Var::Position), 350);
    r.tx("SYNCHRO INTERPOL");
    r.ms(100);
    EXPECT_EQ(r.read(Var::Position), 360);
}

TEST(Sim, StopInInterpolationEmptiesTheFifo) {
    Rig r;
    for (int i = 0; i < 10; ++i) r.tx("00MOVE_INTERPOL 1000");
    r.tx("SYNCHRO INTERPOL");
    r.ms(150);
    r.tx("00STOP");
    EXPECT_EQ(r.read(Var::InterpolCount), 0);
    EXPECT_EQ(r.read(Var::Position), 1500);
    EXPECT_EQ(r.val("00READ #SPEED"), 0);
}

// ---- hostile input (HOSTILE_INPUTS.md 2.9) --------------------------------------------------
TEST(Sim, A15OverlongAndBinaryInputIsSilentAndResyncs) {
    Rig r;
    EXPECT_EQ(r.sim->on_overlong(), "");
    std::string longline = "00READ #POSITION" + std::string(300, 'X');
    EXPECT_EQ(r.tx(longline), "");
    std::string bin;
    for (int i = 0; i < 256; ++i) bin.push_back(static_cast<char>(i));
    EXPECT_EQ(r.tx(bin), "");
    EXPECT_EQ(r.tx(std::string("00\xff\x00\xfe", 5)), "");
    EXPECT_TRUE(bit_set(r.sim->state().error, error::kSyntax));
    EXPECT_EQ(r.tx("00#ERROR:=0, READ #POSITION"), "00#POS=+0\r\n");
    EXPECT_GE(r.sim->lines_rejected(), 3u);
}

TEST(Sim, A7GarbageNumbersInCommandsChangeNothing) {
    Rig r;
    for (const char* bad : {"00MOVE_TO 1e3", "00MOVE_TO +99999999999", "00#V1:=", "00#V1:=1 2", "00MOVE_TO ",
                            "00#V1:=H", "00#V1:=B102", "00MOVE_TO 12,", "00#V1:=5, BOGUS", ",", "00:0 NOP", "00:501 NOP"}) {
        r.tx("00#ERROR:=0");
        EXPECT_EQ(r.tx(bad), "") << bad;
        EXPECT_NE(r.sim->state().error, 0u) << bad;
    }
    EXPECT_EQ(r.read(v_var(1)), 0);
    EXPECT_EQ(r.run_until_idle(), 0);
    EXPECT_EQ(r.tx("00#ERROR:=0, READ #POS"), "00#POS=+0\r\n");
}

TEST(Sim, A10NoiseBetweenFramesDoesNotDisturbTheNext) {
    Rig r;
    EXPECT_EQ(r.tx(std::string(64, '\xff')), "");
    EXPECT_EQ(r.tx(std::string(64, '\0')), "");
    EXPECT_EQ(r.tx("01READ #POS"), "");
    EXPECT_EQ(r.tx("00READ #POS"), "00#POS=+0\r\n");
}

TEST(Sim, RejectsBadAddressBeforeAnything) {
    Rig r(7);
    r.tx("7MOVE_TO 5");   // one digit: a global frame that makes no sense
    EXPECT_TRUE(bit_set(r.sim->state().error, error::kSyntax));
    EXPECT_THROW(Sim(r.clock, SimOptions{.address = 64}), InvalidArgument);
}

// ---- issue 23 items 17, 18 -------------------------------------------------------------------
TEST(Sim, UltraSyncChainedModulesEndEachSegmentTogether) {  // 5.11
    auto clock = std::make_shared<SimClock>();
    SimOptions ox, oy;
    oy.address = 1;
    auto x = std::make_shared<Sim>(clock, ox);
    auto y = std::make_shared<Sim>(clock, oy);
    Sim::chain_ultrasync({x, y});
    EXPECT_THROW(Sim::chain_ultrasync({x, y}), InvalidArgument);  // already chained
    EXPECT_THROW(Sim::chain_ultrasync({x}), InvalidArgument);
    y->set_speed_limit(5000);  // braked: a 1000-increment segment takes 200 ms
    x->on_line("BRAKE OFF");
    y->on_line("BRAKE OFF");
    for (auto* a : {"00", "01"}) {
        x->on_line(std::string(a) + "#INTERPOL_MODE:=-1, #INTERPOL_TIME:=100");
        y->on_line(std::string(a) + "#INTERPOL_MODE:=-1, #INTERPOL_TIME:=100");
        for (int i = 0; i < 2; ++i) {
            x->on_line(std::string(a) + "MOVE_INTERPOL 1000");
            y->on_line(std::string(a) + "MOVE_INTERPOL 1000");
        }
    }
    x->on_line("SYNCHRO INTERPOL");
    y->on_line("SYNCHRO INTERPOL");
    clock->advance(150'000'000);
    EXPECT_EQ(x->read(Var::Position), 1000);  // done, waiting for Y
    EXPECT_EQ(x->read(Var::Speed), 0);
    EXPECT_EQ(x->read(Var::ProfileSpeed), 0);
    EXPECT_EQ(y->read(Var::Position), 750);
    clock->advance(100'000'000);              // Y done at 200: both on segment 2
    EXPECT_EQ(x->read(Var::Position), 1500);
    EXPECT_EQ(y->read(Var::Position), 1250);
    clock->advance(200'000'000);
    EXPECT_EQ(x->read(Var::Position), 2000);
    EXPECT_EQ(y->read(Var::Position), 2000);
    EXPECT_FALSE(x->state().interpolating);
    EXPECT_FALSE(y->state().interpolating);
    EXPECT_THROW(y->set_speed_limit(-1), InvalidArgument);
}

TEST(Sim, UltraSyncWithoutAChainTimesItsOwnSegments) {
    Rig r;
    r.sim->set_speed_limit(5000);
    r.tx("00#INTERPOL_MODE:=-1, #INTERPOL_TIME:=100, MOVE_INTERPOL 1000, MOVE_INTERPOL 1000");
    r.tx("SYNCHRO INTERPOL");
    r.ms(250);
    EXPECT_EQ(r.read(Var::Position), 1250);  // nobody to wait for; the brake still slows it
}

TEST(Sim, ProfileSpeedIsNothingWhileTheRotorRunsDown) {  // 4.8, 5.24
    Rig r;
    r.tx("00#ACCEL_TIME:=100, MOVE_SPEED 60000");
    r.ms(500);
    EXPECT_EQ(r.read(Var::ProfileSpeed), 60000);
    r.tx("00MODULE_RESET");
    r.ms(10);
    const auto s = r.read(Var::Speed);
    EXPECT_NEAR(s, 60000 * std::exp(-0.5), 300);  // 10 ms of a 20 ms time constant
    EXPECT_EQ(r.read(Var::ProfileSpeed), 0);
    EXPECT_TRUE(bit_set(r.status(), status::kMovement));
}

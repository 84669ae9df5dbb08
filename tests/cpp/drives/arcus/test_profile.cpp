// Arcus DMX-CAN profile model: the manual's numbers (Appendix A) as tests.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../../motion/hostile.hpp"
#include "motorbus/drives/arcus/profile.hpp"
#include "motorbus/motion/steps.hpp"

using namespace motorbus::motion;
using namespace motorbus::arcus;

// ---- Arcus Appendix A ------------------------------------------------------------

TEST(ArcusAppendixA, ExampleA_20000_100) {
    // HSPD 20,000 pps, LSPD 100: min ACC 1 ms, max ((20000 - 100) / 1000) x 1000 = 19900 ms.
    const auto& w = arcus_window_for_hspd(20000);
    EXPECT_EQ(w.number, 2);
    EXPECT_EQ(w.min_acc_ms, 1);
    EXPECT_DOUBLE_EQ(arcus_max_acc_ms(20000, 100), 19900.0);
}

TEST(ArcusAppendixA, ExampleB_900000_1000) {
    // HSPD 900,000, LSPD 1000: min 1 ms; max (899000 / 39000) x 1000 = 23051.3 ms.
    // The manual prints 23050 ms (23.05 s): it truncated to 4 significant digits.
    const auto& w = arcus_window_for_hspd(900000);
    EXPECT_EQ(w.number, 7);
    EXPECT_EQ(w.min_acc_ms, 1);
    EXPECT_NEAR(arcus_max_acc_ms(900000, 1000), 23050.0, 2.0);
    EXPECT_NEAR(arcus_max_acc_ms(900000, 1000), 899000.0 / 39000.0 * 1000.0, 1e-9);
}

TEST(ArcusAppendixA, WindowsAndMinimums) {
    struct Row { double hspd; int number; double min_lspd; double min_acc; };
    for (Row r : {Row{1, 1, 10, 2}, Row{16000, 1, 10, 2}, Row{16001, 2, 10, 1}, Row{50000, 3, 15, 1},
                  Row{100000, 4, 25, 1}, Row{200000, 5, 50, 1}, Row{500000, 6, 100, 1}, Row{1e6, 7, 200, 1},
                  Row{2e6, 8, 400, 1}, Row{6e6, 9, 500, 1}}) {
        const auto& w = arcus_window_for_hspd(r.hspd);
        EXPECT_EQ(w.number, r.number) << r.hspd;
        EXPECT_EQ(w.min_lspd, r.min_lspd) << r.hspd;
        EXPECT_EQ(w.min_acc_ms, r.min_acc) << r.hspd;
    }
    try {
        arcus_window_for_hspd(6.5e6);
        FAIL();
    } catch (const LimitExceeded& e) {
        EXPECT_EQ(e.limit, "HSPD");
        EXPECT_DOUBLE_EQ(e.excess(), 0.5e6);
    }
    EXPECT_EQ(arcus_window_for_sspdm(0).number, 1);
    EXPECT_EQ(arcus_window_for_sspdm(1).number, 1);
    EXPECT_EQ(arcus_window_for_sspdm(9).number, 9);
    EXPECT_THROW(arcus_window_for_sspdm(10), LimitExceeded);
}

TEST(ArcusAppendixA, AutomaticAdjustment) {
    ProfileParams p;
    p.hspd = 1000;
    p.lspd = 5;       // below window 1's minimum 10
    p.acc_ms = 0.5;   // below 2 ms
    auto e = arcus_effective(p);
    EXPECT_EQ(e.params.lspd, 10);
    EXPECT_EQ(e.params.acc_ms, 2);
    EXPECT_EQ(e.adjustments.size(), 2u);
    p.lspd = 100;
    p.acc_ms = 5000;  // max = (1000 - 100) / 500 x 1000 = 1800 ms
    e = arcus_effective(p);
    EXPECT_EQ(e.params.acc_ms, 1800);
    // The strict check names the limit and the excess instead.
    try {
        arcus_check_strict(p);
        FAIL();
    } catch (const LimitExceeded& ex) {
        EXPECT_EQ(ex.limit, "ACC");
        EXPECT_DOUBLE_EQ(ex.excess(), 3200.0);
    }
    // StepNLoop on: speeds in encoder counts/s, the window is found in PPS.
    p.acc_ms = 100;
    p.hspd = 18000;      // EPS; x 0.8 = 14400 PPS -> window 1
    p.snl_ratio = 0.8;
    EXPECT_EQ(arcus_effective(p).window->number, 1);
}

// ---- Arcus moves --------------------------------------------------------------------

namespace {
ProfileParams base_params() {
    ProfileParams p;
    p.hspd = 1000;
    p.lspd = 100;
    p.acc_ms = 100;
    return p;
}
}  // namespace

TEST(Motion, TrapezoidFromLspd) {
    Motion m(base_params());
    ASSERT_EQ(m.move(0, 10000), MotionReply::Ok);
    const Profile& p = m.profile();
    // Jump to LSPD, ramp 100 -> 1000 in 0.1 s (55 pulses), cruise, ramp down, jump to 0.
    EXPECT_DOUBLE_EQ(p.velocity(1e-12), 100.0 + 9000.0 * 1e-12);
    EXPECT_NEAR(p.position(0.1), 55.0, 1e-9);
    EXPECT_NEAR(p.velocity(0.1), 1000.0, 1e-9);
    EXPECT_NEAR(p.duration(), 0.1 + (10000 - 110) / 1000.0 + 0.1, 1e-9);
    EXPECT_EQ(p.end_position(), 10000);
    EXPECT_NEAR(p.segments().back().end().v, 100.0, 1e-9);  // ends from LSPD
    EXPECT_EQ(m.phase(0.05), Phase::Accel);
    EXPECT_EQ(m.phase(5.0), Phase::Const);
    EXPECT_EQ(m.phase(p.duration() - 0.05), Phase::Decel);
    EXPECT_EQ(m.phase(p.duration() + 1), Phase::Idle);
    auto st = step_times(p);
    EXPECT_EQ(st.size(), 10000u);
}

TEST(Motion, EdecUsesDec) {
    auto prm = base_params();
    prm.edec = true;
    prm.dec_ms = 200;
    Motion m(prm);
    m.move(0, 10000);
    const Profile& p = m.profile();
    // Decel ramp 1000 -> 100 over 0.2 s covers 110 pulses.
    EXPECT_NEAR(p.duration(), 0.1 + (10000 - 55 - 110) / 1000.0 + 0.2, 1e-9);
}

TEST(Motion, IncrementalLimit262143) {
    Motion m(base_params());
    EXPECT_EQ(m.move(100000, 362143), MotionReply::Ok);
    EXPECT_EQ(m.move(100000, 362144), MotionReply::MoveTooFar);
    EXPECT_EQ(m.move(100000, -162143), MotionReply::Ok);
    EXPECT_EQ(m.move(100000, -162144), MotionReply::MoveTooFar);
}

TEST(Motion, OnTheFlyTargetAhead) {
    Motion m(base_params());
    m.move(0, 10000);
    ASSERT_EQ(m.change_target(2.0, 20000), MotionReply::Ok);
    const Profile& p = m.profile();
    EXPECT_EQ(p.end_position(), 20000);
    EXPECT_NEAR(p.velocity(9.0), 1000, 1e-9);  // still cruising past the old target
    EXPECT_LE(p.max_abs_velocity(), 1000 * (1 + 1e-12));
    EXPECT_EQ(step_times(p).size(), 20000u);
}

TEST(Motion, OnTheFlyTargetAlreadyPassedReverses) {
    Motion m(base_params());
    m.move(0, 10000);
    const double pos_at_5 = m.profile().position(5.0);  // about 4945
    ASSERT_EQ(m.change_target(5.0, 1000), MotionReply::Ok);
    const Profile& p = m.profile();
    EXPECT_EQ(p.end_position(), 1000);
    // Decelerates to LSPD (0.1 s, 55 pulses), stops, then runs back.
    EXPECT_NEAR(p.position(5.1), pos_at_5 + 55, 1e-6);
    bool reversed = false;
    for (double t = 5.1; t < p.duration(); t += 0.01) reversed |= p.velocity(t) < 0;
    EXPECT_TRUE(reversed);
    auto st = step_times(p);
    long net = 0;
    for (auto d : st.dir) net += d;
    EXPECT_EQ(net, 1000);
}

TEST(Motion, OnTheFlyTargetErrors) {
    Motion m(base_params());
    EXPECT_EQ(m.change_target(0, 10), MotionReply::MotorNotMoving);
    m.move(0, 100);
    EXPECT_EQ(m.change_target(100.0, 10), MotionReply::MotorNotMoving);  // finished
    m.jog(0, 1);
    EXPECT_EQ(m.change_target(1.0, 10), MotionReply::MotorNotMoving);    // not a target move
    EXPECT_STREQ(arcus_reply_text(MotionReply::MotorNotMoving), "?Motor is not moving");
}

TEST(Motion, OnTheFlySpeed) {
    Motion m(base_params(), 0);
    m.move(0, 100000);
    EXPECT_EQ(m.change_speed(1.0, 20000), MotionReply::SpeedOutOfRange);  // SSPDM 0: 1..16K
    ASSERT_EQ(m.change_speed(1.0, 2000), MotionReply::Ok);
    const Profile& p = m.profile();
    // Same acceleration (9000 pps/s): 1000 -> 2000 takes 1/9 s.
    EXPECT_NEAR(p.velocity(1.0 + 1.0 / 9.0 + 0.01), 2000, 1e-9);
    EXPECT_EQ(p.end_position(), 100000);
    auto s = base_params();
    s.scv = true;
    Motion sc(s);
    sc.move(0, 10000);
    EXPECT_EQ(sc.change_speed(1.0, 500), MotionReply::ScvOn);
    Motion idle(base_params());
    EXPECT_EQ(idle.change_speed(0, 500), MotionReply::BadSspd);
}

TEST(Motion, JogSpeedChangeAndStop) {
    Motion m(base_params());
    m.jog(0, -1);
    EXPECT_NEAR(m.profile().velocity(1.0), -1000, 1e-9);
    ASSERT_EQ(m.change_speed(1.0, 500), MotionReply::Ok);
    EXPECT_NEAR(m.profile().velocity(2.0), -500, 1e-9);
    m.stop(3.0);
    const Profile& p = m.profile();
    // 500 -> 100 at 9000 pps/s: 0.0444 s, then stop.
    EXPECT_NEAR(p.duration(), 3.0 + 400.0 / 9000.0, 1e-9);
    EXPECT_FALSE(m.moving(3.1));
}

TEST(Motion, SCurveSameDuration) {
    auto s = base_params();
    Motion t(s);
    s.scv = true;
    Motion c(s);
    t.move(0, 5000);
    c.move(0, 5000);
    EXPECT_NEAR(t.profile().duration(), c.profile().duration(), 1e-9);
    EXPECT_NEAR(c.profile().acceleration(0.0), 0.0, 1e-9);
    EXPECT_EQ(c.profile().end_position(), 5000);
}

TEST(Motion, RandomOnTheFlyChangesEndOnTarget) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 500; ++i) {
        ProfileParams p;
        p.hspd = 200 + 15000 * u(rng);
        p.lspd = 10 + 100 * u(rng);
        p.acc_ms = 2 + 500 * u(rng);
        Motion m(p);
        const double target = std::round(-50000 + 100000 * u(rng));
        ASSERT_EQ(m.move(0, target), MotionReply::Ok);
        const double t = m.profile().duration() * u(rng);
        const double t2 = std::round(-50000 + 100000 * u(rng));
        if (m.change_target(t, t2) == MotionReply::Ok) {
            EXPECT_EQ(m.profile().end_position(), t2);
            EXPECT_LE(m.profile().max_abs_velocity(), m.effective().params.hspd * (1 + 1e-9));
            auto st = step_times(m.profile());
            long net = 0;
            for (auto d : st.dir) net += d;
            EXPECT_EQ(net, static_cast<long>(t2));
        }
    }
}

TEST(HostileNumbers, ArcusModel) {
    for (double x : motorbus::test::kValues) {
        ProfileParams a;
        a.hspd = x;
        if (x != 1.0) {  // 1 PPS is the only valid HSPD among these
            EXPECT_THROW(arcus_effective(a), motorbus::InvalidArgument) << x;
        }
        Motion m;
        const MotionReply r = m.move(0, x);
        EXPECT_EQ(r, std::isfinite(x) && std::fabs(x) <= 262143 ? MotionReply::Ok : MotionReply::MoveTooFar) << x;
        EXPECT_TRUE(std::isfinite(m.profile().end_position()));
        m.move(0, 1000);
        const MotionReply rt = m.change_target(0.5, x);
        if (!std::isfinite(x)) {
            EXPECT_EQ(rt, MotionReply::MoveTooFar);
        }
        EXPECT_TRUE(std::isfinite(m.profile().duration()));
    }
    Motion ok;
    EXPECT_EQ(ok.move(0, 1000), MotionReply::Ok);
}

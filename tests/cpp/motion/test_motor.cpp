// StepNLoop (Tables 7.6, 7.7, 8.14), the motor model on a SimClock, and homing.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "motorbus/motion/homing.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motor_rig.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/stepnloop.hpp"

using namespace motorbus::motion;
using motorbus::Nanos;
using motorbus::SimClock;

constexpr Nanos kMs = 1'000'000;
constexpr Nanos kSec = 1'000'000'000;

// ---- StepNLoop -------------------------------------------------------------------

TEST(StepNLoop, ActivityNamesRoundTrip) {
    for (auto a : {SnlActivity::Move, SnlActivity::Jog, SnlActivity::Home, SnlActivity::ZHome,
                   SnlActivity::LimitHome, SnlActivity::Stop, SnlActivity::Abort})
        EXPECT_EQ(snl_activity_from_name(to_string(a)), a);
    EXPECT_EQ(snl_activity_from_name("limit_home"), SnlActivity::LimitHome);
    EXPECT_FALSE(snl_activity_from_name("MOVE"));
    EXPECT_FALSE(snl_activity_from_name(""));
}

TEST(MotorModel, EventKindNames) {
    EXPECT_STREQ(to_string(MotorEvent::Kind::MinusLimitOn), "minus_limit_on");
    EXPECT_STREQ(to_string(MotorEvent::Kind::IndexPulse), "index");
    EXPECT_STREQ(to_string(MotorEvent::Kind::ProfileDone), "profile_done");
}

TEST(StepNLoop, StatusValuesMatchTables) {
    EXPECT_EQ(static_cast<int>(SnlStatus::Idle), 0);
    EXPECT_EQ(static_cast<int>(SnlStatus::StallError), 10);
    EXPECT_EQ(static_cast<int>(SnlStatus::Disabled), 12);
    EXPECT_EQ(static_cast<int>(SnlStatus::LimitHoming), 13);
    EXPECT_STREQ(snl_status_name(SnlStatus::AttemptError), "ERR-ATMPT");
    EXPECT_EQ(SnlConfig::ascii_defaults().tolerance, 20u);   // Table 7.11
    EXPECT_EQ(SnlConfig::canopen_defaults().tolerance, 10u); // Table 8.11
}

TEST(StepNLoop, Table77Moving) {
    StepNLoop s;
    ASSERT_TRUE(s.begin(SnlActivity::Move));
    EXPECT_EQ(s.status(), SnlStatus::Moving);
    EXPECT_EQ(s.monitor(20).action, SnlAction::None);    // <= SLT
    EXPECT_EQ(s.monitor(999).action, SnlAction::None);   // SLT < d < SLE
    EXPECT_EQ(s.monitor(-1001).action, SnlAction::StopNow);  // > SLE
    EXPECT_EQ(s.status(), SnlStatus::StallError);
    EXPECT_FALSE(s.begin(SnlActivity::Move));  // "?State Error" until cleared
    s.clear();
    EXPECT_EQ(s.status(), SnlStatus::Idle);
    EXPECT_TRUE(s.begin(SnlActivity::Jog));
    EXPECT_EQ(s.status(), SnlStatus::Jogging);
}

TEST(StepNLoop, Table77IdleAndCorrections) {
    StepNLoop s;
    s.begin(SnlActivity::Move);
    EXPECT_EQ(s.motion_done(15).action, SnlAction::InPosition);  // <= SLT 20
    EXPECT_EQ(s.status(), SnlStatus::Idle);
    s.begin(SnlActivity::Move);
    SnlDecision d = s.motion_done(300);
    EXPECT_EQ(d.action, SnlAction::Correct);
    EXPECT_EQ(d.correction, 300);
    EXPECT_FALSE(d.idle_current);
    EXPECT_EQ(s.status(), SnlStatus::Correcting);
    // After a correction the idle tolerance SLM = 5 applies, with idle current.
    d = s.motion_done(8);
    EXPECT_EQ(d.action, SnlAction::Correct);
    EXPECT_TRUE(d.idle_current);
    EXPECT_EQ(s.motion_done(4).action, SnlAction::InPosition);
    // Out of range at the end: Correction Range Error (8).
    s.begin(SnlActivity::Move);
    EXPECT_EQ(s.motion_done(5000).action, SnlAction::StopNow);
    EXPECT_EQ(s.status(), SnlStatus::RangeError);
    s.clear();
    // Attempts: SLA = 2 -> the third needed correction is an Attempt Error (9).
    SnlConfig c;
    c.max_attempts = 2;
    s.configure(c);
    s.begin(SnlActivity::Move);
    EXPECT_EQ(s.motion_done(100).action, SnlAction::Correct);
    EXPECT_EQ(s.motion_done(100).action, SnlAction::Correct);
    EXPECT_EQ(s.motion_done(100).action, SnlAction::StopNow);
    EXPECT_EQ(s.status(), SnlStatus::AttemptError);
    EXPECT_EQ(s.attempts(), 2u);
}

TEST(StepNLoop, IdleDisturbanceAndLimitAndDisabled) {
    StepNLoop s;
    EXPECT_EQ(s.idle_check(10).action, SnlAction::None);
    EXPECT_EQ(s.idle_check(50).action, SnlAction::Correct);
    s.clear();
    EXPECT_EQ(s.idle_check(2000).action, SnlAction::StopNow);
    EXPECT_EQ(s.status(), SnlStatus::RangeError);
    s.clear();
    s.begin(SnlActivity::Move);
    s.limit_hit();
    EXPECT_EQ(s.status(), SnlStatus::LimitError);
    SnlConfig off;
    off.enabled = false;
    s.configure(off);
    EXPECT_EQ(s.status(), SnlStatus::Disabled);
    EXPECT_EQ(s.motion_done(1e6).action, SnlAction::InPosition);
    EXPECT_DOUBLE_EQ(s.counts_to_pulses(4000), 3200);
}

// ---- Motor model -----------------------------------------------------------------

using motorbus::test::move_profile;

// Commands p, runs the clock for_ns, returns the events seen.
namespace {
std::vector<MotorEvent> play(MotorModel& m, SimClock& clk, const Profile& p, Nanos for_ns) {
    std::vector<MotorEvent> ev;
    m.add_listener([&](const MotorEvent& e) { ev.push_back(e); });
    m.command(p);
    clk.advance(for_ns);
    m.update();
    return ev;
}
Nanos first(const std::vector<MotorEvent>& ev, MotorEvent::Kind k, int nth = 0) {
    for (const auto& e : ev)
        if (e.kind == k && nth-- == 0) return e.t;
    return -1;
}
}  // namespace

TEST(MotorModel, FollowsProfileAndEncoderRatio) {
    SimClock clk;
    MotorModel m(clk);
    m.command(move_profile(0, 3200));
    EXPECT_TRUE(m.moving());
    clk.advance(2 * kSec);
    m.update();
    EXPECT_FALSE(m.moving());
    EXPECT_EQ(m.pulse_count(), 3200);
    EXPECT_EQ(m.encoder(), 4000);  // 3200 steps = 4000 counts
    m.set_encoder(0);
    m.set_pulse_position(100);
    EXPECT_EQ(m.encoder(), 0);
    EXPECT_EQ(m.pulse_count(), 100);
    EXPECT_DOUBLE_EQ(m.physical_position(), 3200);
}

TEST(MotorModel, IndexOncePerRevAndExactEdgeTimes) {
    // Short ramps (0.1 s), and 10 s ramps with no cruise: a ramp that cannot
    // stall or reverse is taken in one step, and its edges must stay as exact.
    for (const double accel : {32000.0, 320.0}) {
        SCOPED_TRACE(accel);
        SimClock clk;
        MotorConfig cfg;
        cfg.index_position = 100;
        cfg.home = SwitchConfig{true, 1000, 1200, true};
        MotorModel m(clk, cfg);
        const Profile p = move_profile(0, 3 * 3200 + 50, 3200, accel);
        const auto ev = play(m, clk, p, 60 * kSec);
        EXPECT_NEAR(static_cast<double>(first(ev, MotorEvent::Kind::HomeOn)), p.first_crossing(1000) * 1e9, 2.0);
        EXPECT_NEAR(static_cast<double>(first(ev, MotorEvent::Kind::HomeOff)), p.first_crossing(1200) * 1e9, 2.0);
        for (int k = 0; k < 3; ++k)  // 100, 3300, 6500 (9700 is past 9650)
            EXPECT_NEAR(static_cast<double>(first(ev, MotorEvent::Kind::IndexPulse, k)),
                        p.first_crossing(100 + 3200.0 * k) * 1e9, 2.0) << k;
        EXPECT_EQ(first(ev, MotorEvent::Kind::IndexPulse, 3), -1);
        EXPECT_EQ(ev.back().kind, MotorEvent::Kind::ProfileDone);
        EXPECT_EQ(m.pulse_count(), 3 * 3200 + 50);
        EXPECT_TRUE(m.home_input());  // active low: idle high off the switch
    }
}

TEST(MotorModel, StallLosesStepsEncoderShowsIt) {
    SimClock clk;
    MotorConfig cfg;
    cfg.pull_out_speed = 2000;  // the profile asks 3200 steps/s
    MotorModel m(clk, cfg);
    int stalls = 0;
    m.add_listener([&](const MotorEvent& e) { stalls += e.kind == MotorEvent::Kind::Stalled; });
    m.command(move_profile(0, 6400));
    clk.advance(5 * kSec);
    m.update();
    EXPECT_EQ(stalls, 1);
    EXPECT_EQ(m.pulse_count(), 6400);          // the step generator finished
    EXPECT_LT(m.encoder(), m.steps_to_counts(6400) - 100);  // the rotor did not
    EXPECT_GT(m.slip(), 100);
}

TEST(MotorModel, JamAndLatch) {
    SimClock clk;
    MotorModel m(clk);
    m.set_jammed(true);
    m.command(move_profile(0, 1000));
    clk.advance(kSec);
    m.update();
    EXPECT_TRUE(m.stalled());
    EXPECT_EQ(m.encoder(), 0);
    m.set_jammed(false);
    m.arm_latch();
    EXPECT_EQ(m.latch_state(), MotorModel::LatchState::Armed);
    m.command(move_profile(m.pulse_position(), 2000));
    clk.advance(100 * kMs);
    m.trigger_latch();
    EXPECT_EQ(m.latch_state(), MotorModel::LatchState::Triggered);
    EXPECT_NEAR(m.latched_pulse(), m.pulse_position(), 1e-9);
    EXPECT_EQ(m.latched_encoder(), m.encoder());
}

// A cubic piece is taken in one step when it cannot stall or reverse (the
// model's speed-up for long simulated moves); these pin down that nothing is
// lost by it, and that it is not taken whole where it must not be.

namespace {
// One profile piece from rest at 0: velocity v, acceleration a and jerk j at
// its start, held for `duration` s, then finished at `end_p`; the events a
// model with `cfg` reports in the next `for_ns`.
std::vector<MotorEvent> play_piece(const MotorConfig& cfg, double duration, double v, double a, double j,
                                   double end_p, Nanos for_ns) {
    SimClock clk;
    MotorModel m(clk, cfg);
    Profile q(State{0, 0, 0, 0});
    q.append_jump(duration, v, a, j).finish(end_p, 0);
    return play(m, clk, q, for_ns);
}
}  // namespace

TEST(MotorModel, AJammedMoveEndsWhereItDoesTickByTick) {
    // Held by a jam, the rest of a move is taken in one step (only the slip
    // grows); the move must still end on the same tick, with the same slip, as
    // when the clock is walked one tick at a time.
    MotorConfig cfg;
    cfg.tick_ns = kMs;
    const Profile p = move_profile(0, 5000, 3200, 32000);
    struct Run {
        std::vector<MotorEvent> ev;
        double slip, pulse, physical;
    };
    auto run = [&](Nanos step) {
        SimClock clk;
        MotorModel m(clk, cfg);
        Run r;
        m.add_listener([&](const MotorEvent& e) { r.ev.push_back(e); });
        m.set_jammed(true);
        m.command(p);
        for (Nanos t = 0; t < 3 * kSec; t += step) {
            clk.advance(step);
            m.update();
        }
        r.slip = m.slip(), r.pulse = m.pulse_position(), r.physical = m.physical_position();
        return r;
    };
    const Run whole = run(3 * kSec), ticks = run(kMs);
    ASSERT_EQ(whole.ev.size(), 2u);
    EXPECT_EQ(whole.ev[0].kind, MotorEvent::Kind::Stalled);
    EXPECT_EQ(whole.ev[1].kind, MotorEvent::Kind::ProfileDone);
    ASSERT_EQ(ticks.ev.size(), 2u);
    EXPECT_EQ(whole.ev[0].t, ticks.ev[0].t);
    EXPECT_EQ(whole.ev[1].t, ticks.ev[1].t);
    // The first tick at or after the profile's end (not the end itself).
    const Nanos end = static_cast<Nanos>(std::ceil(p.duration() * 1e9));
    EXPECT_GE(whole.ev[1].t, end);
    EXPECT_LT(whole.ev[1].t, end + kMs);
    EXPECT_EQ(whole.ev[1].t % kMs, 0);
    EXPECT_EQ(whole.slip, ticks.slip);
    EXPECT_EQ(whole.pulse, 5000);
    EXPECT_EQ(whole.physical, ticks.physical);
    EXPECT_DOUBLE_EQ(whole.slip, 5000 - whole.physical);
}

TEST(MotorModel, WithoutAnIndexChannelNoIndexPulses) {
    // A drive that reads no Z index (PMC007): the same move reports its switch
    // edges and end at the same instants, with no IndexPulse between them.
    MotorConfig with;
    with.index_position = 100;
    with.home = SwitchConfig{true, 1000, 1200, true};
    MotorConfig without = with;
    without.index_channel = false;
    const Profile p = move_profile(0, 3 * 3200 + 50, 3200, 32000);
    SimClock c1, c2;
    MotorModel m1(c1, with), m2(c2, without);
    const auto e1 = play(m1, c1, p, 10 * kSec), e2 = play(m2, c2, p, 10 * kSec);
    std::vector<MotorEvent> e1_no_index;
    for (const auto& e : e1)
        if (e.kind != MotorEvent::Kind::IndexPulse) e1_no_index.push_back(e);
    EXPECT_EQ(e1.size() - e1_no_index.size(), 3u);
    ASSERT_EQ(e2.size(), e1_no_index.size());
    for (std::size_t i = 0; i < e2.size(); ++i) {
        EXPECT_EQ(e2[i].kind, e1_no_index[i].kind) << i;
        EXPECT_EQ(e2[i].t, e1_no_index[i].t) << i;
    }
    // Both back onto the index position: only the model with the channel sees Z high.
    for (auto [m, c] : {std::pair{&m1, &c1}, std::pair{&m2, &c2}}) {
        m->command(move_profile(m->pulse_position(), 100));
        c->advance(10 * kSec);
        m->update();
        EXPECT_EQ(m->pulse_count(), 100);
    }
    EXPECT_TRUE(m1.index_active());
    EXPECT_FALSE(m2.index_active());
}

TEST(MotorModel, ARampThatReversesFindsTheWayOutAndBack) {
    // v goes 1000 -> -1000 steps/s in one 2 s piece: p(t) = 1000 t - 500 t^2 goes
    // out to 500 and back to 0, through the home window [300, 400] twice.  Its
    // two ends are at the same position, so only stepping finds the four edges.
    MotorConfig cfg;
    cfg.home = SwitchConfig{true, 300, 400, true};
    const auto ev = play_piece(cfg, 2.0, 1000, -1000, 0, 0, 3 * kSec);
    const double r300 = std::sqrt(0.4), r400 = std::sqrt(0.2);  // p = 300, 400 at t = 1 -/+ r
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOn) / 1e9, 1 - r300, 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOff) / 1e9, 1 - r400, 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOn, 1) / 1e9, 1 + r400, 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOff, 1) / 1e9, 1 + r300, 1e-8);
}

TEST(MotorModel, AJerkPieceIsTakenWholeWithExactEdges) {
    // One 2 s jerk piece from rest: p(t) = 1000 t^3 / 6, monotone, so it is
    // taken in one step; the index (at 100) and home window [300, 400] edges
    // must still come out at their exact times.
    MotorConfig cfg;
    cfg.index_position = 100;
    cfg.home = SwitchConfig{true, 300, 400, true};
    const auto ev = play_piece(cfg, 2.0, 0, 0, 1000, 1000.0 * 8 / 6, 3 * kSec);
    const auto at = [](double p) { return std::cbrt(6 * p / 1000); };
    EXPECT_NEAR(first(ev, MotorEvent::Kind::IndexPulse) / 1e9, at(100), 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOn) / 1e9, at(300), 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOff) / 1e9, at(400), 1e-8);
}

TEST(MotorModel, AJerkPieceThatReversesInsideIsStepped) {
    // v(t) = 1000 - 4000 t + 2000 t^2: +1000 at both ends of the 2 s piece but
    // -1000 at t = 1, so p goes out to 138, back to -805 and ends at -667.
    // Both ends (and the middle) are outside the home window [50, 100]: only
    // the velocity's interior extreme says the piece is not monotone, and
    // only stepping it finds the four edges.
    MotorConfig cfg;
    cfg.home = SwitchConfig{true, 50, 100, true};
    const auto ev = play_piece(cfg, 2.0, 1000, -4000, 4000, -2000.0 / 3, 3 * kSec);
    const auto p = [](double t) { return 1000 * t - 2000 * t * t + 4000 * t * t * t / 6; };
    const auto crossing = [&](double level, double lo, double hi) {  // p - level changes sign once in [lo, hi]
        const bool up = p(lo) < level;
        for (int i = 0; i < 100; ++i) {
            const double mid = (lo + hi) / 2;
            ((p(mid) < level) == up ? lo : hi) = mid;
        }
        return lo;
    };
    const double t_out = 1 - std::sqrt(0.5);  // where v = 0 the first time: p = 138
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOn) / 1e9, crossing(50, 0, t_out), 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOff) / 1e9, crossing(100, 0, t_out), 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOn, 1) / 1e9, crossing(100, t_out, 1), 1e-8);
    EXPECT_NEAR(first(ev, MotorEvent::Kind::HomeOff, 1) / 1e9, crossing(50, t_out, 1), 1e-8);
}

TEST(MotorModel, AStallInsideALongRampStartsWithinATickOfThePullOutSpeed) {
    MotorConfig cfg;
    cfg.pull_out_speed = 5000;  // reached 5 s into a 10 s ramp to 10 000 steps/s
    const auto ev = play_piece(cfg, 10.0, 0, 1000, 0, 50'000, 20 * kSec);
    const Nanos stalled = first(ev, MotorEvent::Kind::Stalled);
    EXPECT_GE(stalled, 5 * kSec);
    EXPECT_LE(stalled, 5 * kSec + cfg.tick_ns);
}

// ---- Homing ----------------------------------------------------------------------

namespace {
using motorbus::test::bench_cfg;
using motorbus::test::run_until_done;
}  // namespace







TEST(Cia402Homing, Methods) {
    struct Case { int method; double expect_physical; };
    // Home window [5000, 5400]; index high on [37, 37.8) + k*3200 (its rising edge is
    // at 37.8 when approached from above); limits at -20000 / +20000.
    for (Case c : {Case{17, -20000}, Case{18, 20000}, Case{19, 5000}, Case{20, 5000}, Case{7, 3237.8},
                   Case{11, 6437}, Case{33, 37.8}, Case{34, 3237}, Case{35, 1000}}) {
        SimClock clk;
        MotorModel m(clk, bench_cfg());
        m.command(move_profile(0, 1000));
        clk.advance(2 * kSec);
        m.update();
        if (c.method == 11) {
            m.command(move_profile(1000, 8000));
            clk.advance(5 * kSec);
            m.update();
        }
        Cia402HomingParams p;
        p.method = c.method;
        p.speed_switch = 2000;
        p.speed_zero = 200;
        p.acceleration = 20000;
        p.home_offset = 7;
        Cia402Homing h(m, p);
        h.start();
        run_until_done(clk, m, [&] { return h.result() == HomingResult::Running; });
        ASSERT_TRUE(h.attained()) << c.method;
        EXPECT_NEAR(m.physical_position(), c.expect_physical, 0.05) << c.method;
        EXPECT_EQ(m.pulse_count(), 7) << c.method;
    }
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    Cia402HomingParams p;
    p.method = 1;
    Cia402Homing h(m, p);
    EXPECT_THROW(h.start(), motorbus::InvalidArgument);
}

// A host wrapping an open-loop drive with an encoder in StepNLoop: a jam loses
// steps, verification at the end of the move corrects them (Table 7.7).
TEST(StepNLoop, WrapsOpenLoopMotorAndCorrectsLostSteps) {
    SimClock clk;
    MotorModel m(clk);
    StepNLoop snl;  // SLT 20, SLE 1000 counts, ratio 0.8 steps/count
    const double target_counts = 4000;  // one rev
    ASSERT_TRUE(snl.begin(SnlActivity::Move));
    m.command(move_profile(0, m.counts_to_steps(target_counts)));
    clk.advance(200 * kMs);
    m.update();
    m.set_jammed(true);  // the load blocks the rotor for a while: steps are lost
    clk.advance(100 * kMs);
    m.update();
    m.set_jammed(false);
    for (int i = 0; i < 300 && m.moving(); ++i) {
        clk.advance(10 * kMs);
        m.update();
        // While moving, delta is the real-time target minus the encoder.
        const double delta_now = snl.pulses_to_counts(m.pulse_position()) - static_cast<double>(m.encoder());
        ASSERT_EQ(snl.monitor(delta_now).action, SnlAction::None) << delta_now;  // < SLE
    }
    ASSERT_FALSE(m.moving());
    double delta = target_counts - static_cast<double>(m.encoder());
    ASSERT_GT(delta, 20);  // out of position
    SnlDecision d = snl.motion_done(delta);
    int corrections = 0;
    while (d.action == SnlAction::Correct) {
        ++corrections;
        m.command(move_profile(m.pulse_position(), m.pulse_position() + snl.counts_to_pulses(d.correction)));
        for (int i = 0; i < 300 && m.moving(); ++i) {
            clk.advance(10 * kMs);
            m.update();
        }
        d = snl.motion_done(target_counts - static_cast<double>(m.encoder()));
    }
    EXPECT_EQ(d.action, SnlAction::InPosition);
    EXPECT_GE(corrections, 1);
    EXPECT_LE(std::abs(target_counts - static_cast<double>(m.encoder())), 5);
    EXPECT_EQ(snl.status(), SnlStatus::Idle);
}


// ---- run-time hooks a drive simulator needs ----------------------------------------

TEST(MotorModel, StepsPerUnitBridgesDriveUnitsAndPolarity) {
    SimClock clk;
    MotorModel m(clk);
    m.set_steps_per_unit(0.8);  // the drive counts encoder counts: 0.8 steps each
    m.command(move_profile(0, 4000, 4000, 40000));
    clk.advance(3 * kSec);
    m.update();
    EXPECT_EQ(m.pulse_count(), 4000);
    EXPECT_NEAR(m.physical_position(), 3200, 1e-9);
    EXPECT_EQ(m.encoder(), 4000);
    m.set_steps_per_unit(-1.0);  // direction polarity inverted, pulses again
    m.command(move_profile(4000, 5000));
    clk.advance(100 * kMs);
    m.update();
    EXPECT_GT(m.pulse_velocity(), 0);
    EXPECT_LT(m.commanded_velocity(), 0);
    clk.advance(3 * kSec);
    m.update();
    EXPECT_EQ(m.pulse_count(), 5000);
    EXPECT_NEAR(m.physical_position(), 2200, 1e-9);  // continuous across the change
    EXPECT_THROW(m.set_steps_per_unit(0), motorbus::InvalidArgument);
}


TEST(MotorModel, ForcedAndInvertedSwitchesAreEventsNow) {
    SimClock clk;
    MotorModel m(clk, bench_cfg());
    std::vector<MotorEvent::Kind> seen;
    m.add_listener([&](const MotorEvent& e) {
        if (e.kind != MotorEvent::Kind::IndexPulse && e.kind != MotorEvent::Kind::ProfileDone) seen.push_back(e.kind);
    });
    m.force_switch(Switch::MinusLimit, true);
    EXPECT_TRUE(m.minus_limit_active());
    m.force_switch(Switch::MinusLimit, std::nullopt);
    EXPECT_FALSE(m.minus_limit_active());
    m.set_switch_inverted(Switch::Home, true);  // reads active away from the window
    EXPECT_TRUE(m.home_active());
    ASSERT_EQ(seen.size(), 3u);
    EXPECT_EQ(seen[0], MotorEvent::Kind::MinusLimitOn);
    EXPECT_EQ(seen[1], MotorEvent::Kind::MinusLimitOff);
    EXPECT_EQ(seen[2], MotorEvent::Kind::HomeOn);
    // Inverted, the window is where the input goes inactive.
    seen.clear();
    m.command(move_profile(0, 6000));
    clk.advance(4 * kSec);
    m.update();
    ASSERT_GE(seen.size(), 2u);
    EXPECT_EQ(seen[0], MotorEvent::Kind::HomeOff);
    EXPECT_EQ(seen[1], MotorEvent::Kind::HomeOn);
    // A forced switch has no edges while held.
    m.force_switch(Switch::Home, true);
    seen.clear();
    m.command(move_profile(6000, 0));
    clk.advance(4 * kSec);
    m.update();
    for (auto k : seen) EXPECT_NE(k, MotorEvent::Kind::HomeOff);
}

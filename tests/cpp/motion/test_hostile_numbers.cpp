// Hostile numeric inputs (NaN, inf, negative, huge, tiny) for every planner and
// drive model: a typed error or a valid profile, never a crash, a hang or
// unbounded memory; and the next valid request still works.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "motorbus/motion/arcus_profile.hpp"
#include "motorbus/motion/cia402_profile.hpp"
#include "motorbus/motion/dmac_profile.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/pmc007_profile.hpp"
#include "motorbus/motion/steps.hpp"
#include "motorbus/motion/unitek_profile.hpp"

using namespace motorbus::motion;

namespace {
const double kInf = std::numeric_limits<double>::infinity();
const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kValues[] = {0.0, -0.0, 1e-300, -1e-300, 1e-9, 1.0, -1.0, 1e9, -1e9, 1e300, -1e300, kInf, -kInf, kNan};

template <class F>
void survives(F&& f) {
    try {
        Profile p = f();
        // A profile that is returned must be usable and finite where it was asked to be.
        (void)p.at(p.duration() / 2);
        (void)p.max_abs_velocity();
    } catch (const motorbus::InvalidArgument&) {
        // typed refusal: fine
    }
}
}  // namespace

TEST(HostileNumbers, PlannersRefuseOrPlan) {
    std::mt19937_64 rng(3);
    std::uniform_int_distribution<std::size_t> pick(0, std::size(kValues) - 1);
    auto r = [&] { return kValues[pick(rng)]; };
    for (int i = 0; i < 4000; ++i) {
        const State s{r(), r(), r(), 0};
        const double tgt = r();
        const Limits lim{r(), r(), r(), r()};
        survives([&] { return plan_trapezoid(s, tgt, lim); });
        survives([&] { return plan_trapezoid(s, tgt, lim, RampShape::SCurve); });
        survives([&] { return plan_velocity(s, tgt, lim, std::fabs(r())); });
        survives([&] { return plan_jerk_limited(s, tgt, lim); });
    }
    // The next valid request still works.
    EXPECT_NEAR(plan_jerk_limited(State{}, 100, Limits{10, 5, 0, 10}).duration(), 12.5, 1e-12);
}

TEST(HostileNumbers, DriveModels) {
    for (double x : kValues) {
        ArcusProfileParams a;
        a.hspd = x;
        if (x != 1.0) {  // 1 PPS is the only valid HSPD among these
            EXPECT_THROW(arcus_effective(a), motorbus::InvalidArgument) << x;
        }
        ArcusMotion m;
        const ArcusReply r = m.move(0, x);
        EXPECT_EQ(r, std::isfinite(x) && std::fabs(x) <= 262143 ? ArcusReply::Ok : ArcusReply::MoveTooFar) << x;
        EXPECT_TRUE(std::isfinite(m.profile().end_position()));
        m.move(0, 1000);
        const ArcusReply rt = m.change_target(0.5, x);
        if (!std::isfinite(x)) {
            EXPECT_EQ(rt, ArcusReply::MoveTooFar);
        }
        EXPECT_TRUE(std::isfinite(m.profile().duration()));
        survives([&] { return dmac_position_profile(State{}, x, DmacProfileParams{}); });
        survives([&] { return dmac_speed_profile(State{}, x, DmacProfileParams{}, 1.0); });
        Pmc007ProfileParams pm;
        pm.speed = x;
        survives([&] { return pmc007_position_profile(State{}, 100, pm); });
        Cia402ProfileParams c;
        c.profile_velocity = x;
        survives([&] { return cia402_position_profile(State{}, 100, c); });
        UnitekRampParams u;
        u.acc_ramp_ms = x;
        survives([&] { return unitek_speed_profile(State{}, 1000, u, 0); });
    }
    ArcusMotion ok;
    EXPECT_EQ(ok.move(0, 1000), ArcusReply::Ok);
}

TEST(HostileNumbers, StepTimesBoundedAndInterpolationBounded) {
    Profile huge = plan_trapezoid(State{}, 1e15, Limits{1e12, 1e12, 0, 0});
    EXPECT_THROW(step_times(huge, 0, 1'000'000), motorbus::InvalidArgument);
    std::vector<Profile> axes{plan_trapezoid(State{}, 1e6, Limits{1e-3, 1, 0, 0})};  // ~1e9 s long
    EXPECT_THROW(split_interpolation(axes, 2), LimitExceeded);
    Profile ok = plan_trapezoid(State{}, 10, Limits{10, 100, 0, 0});
    EXPECT_EQ(step_times(ok).size(), 10u);
}

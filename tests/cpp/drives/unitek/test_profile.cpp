// UNITEK ramp model.
#include <gtest/gtest.h>

#include <cmath>

#include "../../motion/hostile.hpp"
#include "motorbus/drives/unitek/profile.hpp"

using namespace motorbus::motion;
using namespace motorbus::unitek;

TEST(Unitek, RampFromAccRegister) {
    RampParams p;
    p.n_max_rpm = 3000;
    p.acc_ramp_ms = 1000;  // Example 6: 0x35 = 0x03E8
    p.dec_ramp_ms = 500;
    // 10 % speed (3277 num, Example 3) takes 10 % of the ramp.
    Profile prof = speed_profile(State{}, 3277, p, 1.0);
    EXPECT_NEAR(prof.duration(), 0.1 * 3277 / 3276.7 + 1.0, 1e-9);
    EXPECT_NEAR(prof.final_state().v, num_to_counts_per_s(3277, p), 1e-9);
    EXPECT_NEAR(num_to_counts_per_s(32767, p), 3000.0 / 60 * 65536, 1e-6);
    Profile down = speed_profile(State{0, num_to_counts_per_s(32767, p), 0, 0}, 0, p, 0);
    EXPECT_NEAR(down.duration(), 0.5, 1e-12);
    p.acc_ramp_ms = 40000;
    EXPECT_THROW(speed_profile(State{}, 1, p, 0), LimitExceeded);
}

TEST(HostileNumbers, UnitekModel) {
    for (double x : motorbus::test::kValues) {
        RampParams u;
        u.acc_ramp_ms = x;
        motorbus::test::survives([&] { return speed_profile(State{}, 1000, u, 0); });
    }
}

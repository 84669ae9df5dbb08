// A motor on a test bench shared by the generic homing tests and the vendors'
// homing tests: home switch [5000, 5400], limits at -20000 / +20000 (all active
// low), index at 37 + k*3200.
#pragma once
#include <functional>

#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::test {
using namespace motorbus::motion;

inline MotorConfig bench_cfg() {
    MotorConfig c;
    c.home = SwitchConfig{true, 5000, 5400, true};
    c.minus_limit = SwitchConfig{true, -20000, 0, true};
    c.plus_limit = SwitchConfig{true, 20000, 0, true};
    c.index_position = 37;
    return c;
}

// A trapezoid move from rest at `from` to `to`.
inline Profile move_profile(double from, double to, double v = 3200, double a = 32000) {
    return plan_trapezoid(State{from, 0, 0, 0}, to, Limits{v, a, 0, 0});
}

// Advances the clock 10 ms at a time until `running` is false (at most 100 s).
inline void run_until_done(SimClock& clk, MotorModel& m, const std::function<bool()>& running) {
    constexpr Nanos kStep = 10'000'000;
    for (int i = 0; i < 10000 && running(); ++i) {
        clk.advance(kStep);
        m.update();
    }
}
}  // namespace motorbus::test

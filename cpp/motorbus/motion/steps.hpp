// Exact integer step times: the instant of every (micro)step a stepper driver
// must emit to follow a Profile, with no cumulative drift.
//
// Convention: the commanded step count is round(p(t)) (ties away from the
// previous count), so a step fires when p(t) crosses k + 1/2.  Each crossing
// time is solved from the segment's own closed form (a square root for
// constant-acceleration segments, a safeguarded Newton iteration for cubic and
// exponential ones), never by accumulating intervals, so step n's time is as
// exact at the millionth step as at the first.  A profile that starts and ends
// on integers emits exactly |end - start| net steps, and a monotone one exactly
// that many steps.
#pragma once
#include <cstdint>
#include <vector>

#include "motorbus/motion/profile.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::motion {

struct StepTimes {
    std::vector<Nanos> t_ns;          // strictly increasing (ties broken by +1 ns)
    std::vector<std::int8_t> dir;     // +1 or -1 per step
    std::size_t size() const { return t_ns.size(); }
};

// Steps of `profile` (positions in steps) at times t0_ns + t*1e9, rounded to
// the nearest nanosecond.  Throws InvalidArgument if the profile would need
// more than max_steps steps (bounded memory on hostile input).
StepTimes step_times(const Profile& profile, Nanos t0_ns = 0,
                     std::size_t max_steps = 100'000'000);

// Same, in seconds (double), no rounding: for accuracy checks.
std::vector<double> step_times_seconds(const Profile& profile,
                                       std::size_t max_steps = 100'000'000);

}  // namespace motorbus::motion

// UNITEK BAMOCAR/BAMOBIL speed ramps (002 manual, Example 6 and section 6).
//
// Speed command values are "num": +-32767 = 100 % of N max (the calibrated
// maximum speed in rpm).  The acceleration ramp register 0x35 holds the time
// in ms to go from 0 to 100 % speed; the deceleration ramp register (NDrive's
// 0xED, not described in this manual) the time from 100 % to 0.  A speed
// change of part of the range takes the same part of the ramp time.
// Positions: 65536 counts per revolution (the manual's resolution).
#pragma once
#include <cstdint>

#include "motorbus/drives/unitek/codec.hpp"
#include "motorbus/motion/profile.hpp"

namespace motorbus::unitek {
// A vendor profile model is built from the generic motion pieces.
using namespace motorbus::motion;

// kRegAccRamp (0x35, documented) is the codec's; DEC_RAMP is NDrive's register list only.
inline constexpr std::uint8_t kRegDecRamp = 0xED;
inline constexpr double kCountsPerRev = 65536.0;
inline constexpr double kFullScale = 32767.0;

struct RampParams {
    double n_max_rpm = 3000;   // N max: the speed of 32767 num
    double acc_ramp_ms = 1000; // register 0x35
    double dec_ramp_ms = 1000; // register 0xED
    void validate() const;     // throws LimitExceeded (0..32767 ms, N max > 0)
};

// num -> counts/s
double num_to_counts_per_s(double num, const RampParams& p);
// The drive's ramp from start.v (counts/s) to the command `speed_num`, held for `hold` s.
// |speed_num| is limited to 32767.
Profile speed_profile(const State& start, double speed_num, const RampParams& p, double hold);

}  // namespace motorbus::unitek

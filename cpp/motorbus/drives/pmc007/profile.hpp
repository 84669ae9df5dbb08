// The CQPUSI PMC007's motion profile (003 manual, 4.5.9-4.5.13): start speed
// 6006h and stop speed 6007h (pps), S-curve ramps whose acceleration is one of
// eight "gears" (6008h/6009h, Figure 4-1's table, pps^2), and microstepping
// 600Ah.  Positions in (micro)steps, speeds in pps.
//
// Reading of the manual: a gear's value is the ramp's average acceleration (the
// ramp time is dv / gear), with the S-curve shape shared by the other models
// (triangular acceleration, same ramp time and distance).  Gear 0 disables
// ramps: start-stop at the set speed.  Microstepping 0 means full steps.
#pragma once
#include <array>
#include <cstdint>

#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/profile.hpp"

namespace motorbus::pmc007 {
// A vendor profile model is built from the generic motion pieces.
using namespace motorbus::motion;

inline constexpr std::array<double, 9> kGearAcceleration = {0,     77440, 48410, 27170, 21510,
                                                                  14080, 10460, 6915,  5210};

// pps^2 of a gear 1..8; infinity for gear 0 (no ramp).  Throws LimitExceeded outside 0..8.
double gear_acceleration(int gear);
// Microsteps per full step for a 600Ah value (0 -> 1); throws LimitExceeded
// for values other than 0, 2, 4, ..., 256.
int microsteps(int setting);
// Position count after changing the microstepping (the manual: read the
// position first, then convert): pos * new / old.
double convert_position(double position, int from_setting, int to_setting);

struct ProfileParams {
    double speed = 1000;           // pps, the running speed (speed mode / position moves)
    double start_speed = 400;      // 6006h, pps (factory 400)
    double stop_speed = 0;         // 6007h, pps (factory 0)
    int accel_gear = 0;            // 6008h, 0..8 (factory 0)
    int decel_gear = 0;            // 6009h, 0..8
    int microstepping = 0;         // 600Ah
    void validate() const;         // throws LimitExceeded naming the object
};

// Step/absolute displacement command: from `start` to `target` (steps).
Profile position_profile(const State& start, double target, const ProfileParams& p);
// Speed mode: ramp to `speed` (signed pps) from the start speed, hold `hold` s.
Profile speed_profile(const State& start, double speed, const ProfileParams& p, double hold);

}  // namespace motorbus::pmc007

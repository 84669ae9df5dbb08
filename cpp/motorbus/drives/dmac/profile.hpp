// The Midi Ingénierie DMAC's motion profile, in the manual's units and rules
// (001 manual: 1.2.2 "Moves", 4.10-4.12 MOVE_ON/MOVE_SPEED/MOVE_TO,
// 5.1 #ACCEL_TIME/#DECEL_TIME, 5.6 #HIGH_SPEED, 5.15 #LOW_SPEED, 4.22 S_CURVE).
//
// Units: positions in increments (1/10000 rev), speeds in 0.01 rpm
// (1 unit = 1/0.6 increments/s), times in ms.  The returned Profile is in
// increments and seconds.
//
// The rules modelled:
//  - #ACCEL_TIME is the time from standstill to #HIGH_SPEED, #DECEL_TIME from
//    #HIGH_SPEED to standstill; a partial speed change takes time in
//    proportion (|Vtarget - Vcurrent| / #HIGH_SPEED), i.e. constant
//    acceleration HS/ATI and deceleration HS/DTI.  A sign change decelerates
//    to 0 with DTI, then accelerates with ATI.  ATI = DTI = 0: start-stop.
//  - A position move: accelerate from the current velocity to #HIGH_SPEED,
//    cruise, decelerate to #LOW_SPEED so that LOW_SPEED is reached 0.1 turn
//    (1000 increments) before the target, then the closed position loop
//    approaches with velocity proportional to the error:
//    v = LOW_SPEED * error / 1000 inc (the manual's figure: from LOW_SPEED at
//    0.1 turn to standstill at the target).  That approach is exponential;
//    the model ends it with one increment at the constant speed
//    LOW_SPEED / 1000 inc, so it finishes exactly on the target in
//    tau * (ln 1000 + 1), tau = 1000 inc / LOW_SPEED.
//  - A move shorter than 0.1 turn is all closed-loop approach.
//  - MOVE_SPEED ramps from the current velocity; |target| is limited to
//    #HIGH_SPEED.
//  - S_CURVE ON: same ramp times and distances, S-shaped acceleration.
#pragma once
#include <cstdint>

#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/profile.hpp"

namespace motorbus::dmac {
// A vendor profile model is built from the generic motion pieces.
using namespace motorbus::motion;

inline constexpr double kIncrementsPerRev = 10000.0;
inline constexpr double kApproachIncrements = 1000.0;  // 0.1 turn
// 0.01 rpm -> increments/s
inline constexpr double speed_to_inc_per_s(double speed_001rpm) {
    return speed_001rpm * kIncrementsPerRev / 6000.0;
}
inline constexpr double inc_per_s_to_speed(double inc_per_s) {
    return inc_per_s * 6000.0 / kIncrementsPerRev;
}

struct ProfileParams {  // factory values (MODULE_RESET ALL)
    std::int32_t high_speed = 60000;  // 0.01 rpm, 0..400000
    std::int32_t low_speed = 6000;    // 0.01 rpm, 0..400000
    std::int32_t accel_time_ms = 1000;  // 0..12000
    std::int32_t decel_time_ms = 1000;  // 0..12000
    bool s_curve = false;
    // Throws LimitExceeded naming the variable (#HIGH_SPEED, ...) out of range.
    void validate() const;
};

// Time (s) the DMAC takes to change speed from v_from to v_to (0.01 rpm):
// #ACCEL_TIME x |dv| / #HIGH_SPEED when the speed magnitude grows, DECEL when
// it shrinks (the manual's 0.5 s example: ATI 1000, HS 60000, 0 -> 30000).
double ramp_time(const ProfileParams& p, double v_from, double v_to);

// The profile of one DMAC axis across commands.  Each command at time t
// (seconds on the profile's own time line, 0 = first command) replaces the
// future with a plan starting from the state at t.
class Motion {
public:
    explicit Motion(ProfileParams params = {}, double position = 0);

    void set_params(const ProfileParams& p);  // validates; applies to next command
    const ProfileParams& params() const { return params_; }

    void move_to(double t, std::int64_t target);
    void move_on(double t, std::int64_t offset);
    // MOVE_SPEED: |speed| clamped to #HIGH_SPEED (0.01 rpm); holds it until the next command.
    void move_speed(double t, std::int32_t speed_001rpm);
    // STOP: decelerate to standstill with #DECEL_TIME (proportional).
    void stop(double t);

    const Profile& profile() const { return profile_; }
    State at(double t) const { return profile_.at(t); }
    bool moving(double t) const;
    // BUSY (manual 3.5.4): until the target is reached, the target velocity in
    // velocity mode (the end of the ramp) or the target position otherwise.
    bool busy(double t) const { return t < target_reached_; }
    bool speed_mode() const { return speed_mode_; }
    std::int64_t target() const { return target_; }

private:
    ProfileParams params_;
    Profile profile_;
    bool speed_mode_ = false;
    std::int64_t target_ = 0;
    double motion_end_ = 0;  // time the motor comes to rest (infinity while a speed holds)
    double target_reached_ = 0;  // time the target velocity / position is reached
    void splice(double t, const Profile& tail);
};

// The core position plan, exposed for reuse: from `start` to `target`
// (increments) with the given parameters.
Profile position_profile(const State& start, double target, const ProfileParams& p);
// Velocity plan from `start` to `speed_001rpm`, then holding it for `hold` s.
Profile speed_profile(const State& start, double speed_001rpm, const ProfileParams& p,
                           double hold);

}  // namespace motorbus::dmac

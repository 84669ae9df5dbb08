// CiA 402 profile position and profile velocity modes: 6081h profile velocity,
// 6082h end velocity, 6083h profile acceleration, 6084h profile deceleration,
// 6085h quick stop deceleration, 6086h motion profile type (0 linear ramp =
// trapezoid, 1 sin^2 ramp), with the set-point handshake: a single set-point,
// a set of set-points (change on set-point, bit 9) and "change set
// immediately" (controlword bit 5).
//
// Units are the drive's (position units, units/s, units/s^2).  With sin^2
// ramps 6083h/6084h are the peak accelerations, so each ramp takes twice as
// long as the linear one (average = half the peak).
#pragma once
#include <cstdint>
#include <optional>

#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/profile.hpp"

namespace motorbus::motion {

struct Cia402ProfileParams {
    double profile_velocity = 1000;      // 6081h
    double end_velocity = 0;             // 6082h (only 0 is modelled; see docs)
    double profile_acceleration = 10000; // 6083h
    double profile_deceleration = 10000; // 6084h
    double quick_stop_deceleration = 100000;  // 6085h
    std::int16_t motion_profile_type = 0;     // 6086h: 0 linear, 1 sin^2
    double max_profile_velocity = 0;     // 607Fh, 0 = no limit
    // Throws LimitExceeded (non-positive values, 6086h other than 0/1).
    void validate() const;
};

Profile cia402_position_profile(const State& start, double target, const Cia402ProfileParams& p);
// Profile velocity mode (60FFh target velocity), holding it for `hold` s.
Profile cia402_velocity_profile(const State& start, double target_velocity, const Cia402ProfileParams& p,
                                double hold);
// Quick stop with 6085h.
Profile cia402_quick_stop_profile(const State& start, const Cia402ProfileParams& p);

// The set-point handshake of profile position mode on one time line (s).
class Cia402ProfilePosition {
public:
    explicit Cia402ProfilePosition(Cia402ProfileParams p = {}, double position = 0);
    void set_params(const Cia402ProfileParams& p);

    // A new set-point (controlword bit 4 rising edge) at time t.  Returns
    // false when it is not accepted (set-point acknowledge stays 0): a
    // buffered set-point is already waiting.
    //  change_immediately (bit 5 = 1): replaces the running move now.
    //  otherwise, idle: starts now; moving: buffered and started when the
    //  current target is reached (from rest), or, with change_on_setpoint
    //  (bit 9) and the new target further along the same direction, the move
    //  continues through the current target without stopping.
    bool new_setpoint(double t, double target, bool relative = false, bool change_immediately = false,
                      bool change_on_setpoint = false);
    void halt(double t);  // controlword bit 8: decelerate with 6084h

    // The planned motion including a buffered set-point (run when the current
    // target is reached).
    const Profile& profile();
    bool target_reached(double t);    // statusword bit 10
    bool setpoint_pending() const { return pending_.has_value(); }
    double target() const { return target_; }

private:
    Cia402ProfileParams p_;
    Profile profile_;
    double target_ = 0;
    std::optional<double> pending_;
    Profile preview_;
    void splice(double t, const Profile& tail);
    void promote(double t);  // starts the buffered set-point if the move ended by t
};

}  // namespace motorbus::motion

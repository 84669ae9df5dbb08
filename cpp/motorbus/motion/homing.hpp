// The homing engine: what every drive's homing shares (the result vocabulary, the
// search ramp) and the CiA 402 methods. Vendor homing lives with its vendor
// (drives/<vendor>/homing.hpp).
//
// CiA 402 (methods 7, 11, 17, 18, 19, 20, 33, 34, 35), with 6099h:01 speed
// during search for switch, 6099h:02 speed during search for zero, 609Ah
// acceleration, 607Ch home offset.  Methods with an index pulse finish on the
// index; 17-20 finish on the switch edge; 33/34 on the next index in the
// negative/positive direction; 35 sets the current position as home.
// At the end the position counter is set to the home offset (the manual's
// 607Ch convention: home position = offset).
#pragma once
#include <cstdint>
#include <string>

#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/planner.hpp"

namespace motorbus::motion {

enum class HomingResult { Running, Done, LimitError, Aborted, Failed };

// From a commanded state (p, v), ramp to `velocity` at `accel` and hold it until an
// event ends the search; a stepper with a start speed jumps to it first.
Profile ramp_and_hold(double p, double v, double velocity, double accel, RampShape shape, double start_speed = 0);

struct Cia402HomingParams {
    int method = 17;               // 6098h
    double speed_switch = 1000;    // 6099h:01, steps/s
    double speed_zero = 100;       // 6099h:02, steps/s
    double acceleration = 10000;   // 609Ah, steps/s^2
    double home_offset = 0;        // 607Ch, steps
};

class Cia402Homing {
public:
    using Params = Cia402HomingParams;
    Cia402Homing(MotorModel& motor, Params p);
    ~Cia402Homing();
    Cia402Homing(const Cia402Homing&) = delete;
    Cia402Homing& operator=(const Cia402Homing&) = delete;

    static bool supported(int method);  // 7, 11, 17, 18, 19, 20, 33, 34, 35
    // Throws InvalidArgument for an unsupported method (the sim answers 0x06090030).
    void start();
    void abort();
    HomingResult result() const { return result_; }
    // Statusword bits of homing mode: bit 12 homing attained, bit 13 homing error.
    bool attained() const { return result_ == HomingResult::Done; }
    bool error() const { return result_ == HomingResult::LimitError || result_ == HomingResult::Failed; }

private:
    MotorModel& motor_;
    Params p_;
    int stage_ = 0;
    HomingResult result_ = HomingResult::Done;
    int listener_ = 0;
    void on_event(const MotorEvent& e);
    void run_at(double velocity);
    void finish(HomingResult r, bool set_home);
};

}  // namespace motorbus::motion

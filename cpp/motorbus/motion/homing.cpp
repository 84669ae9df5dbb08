#include "motorbus/motion/homing.hpp"

#include <cmath>

#include "motorbus/motion/planner_detail.hpp"
#include "motorbus/motion/stepnloop.hpp"

namespace motorbus::motion {

namespace {
constexpr double kHoldSeconds = 1e7;  // a search runs until an event stops it
}  // namespace


// From the motor's current commanded state, ramp to `velocity` at `accel` and hold.
Profile ramp_and_hold(double p, double v, double velocity, double accel, RampShape shape, double start_speed) {
    Profile prof(State{p, v, 0, 0});
    double v0 = v;
    if (v0 * velocity <= 0 && start_speed > 0) v0 = 0;  // a stepper starts at its start speed
    if (v0 == 0 && start_speed > 0) v0 = std::copysign(std::min(start_speed, std::fabs(velocity)), velocity);
    const double dv = velocity - v0;
    if (dv != 0 && std::isfinite(accel) && accel > 0) {
        const double dur = std::fabs(dv) / accel;
        if (shape == RampShape::SCurve) {
            const double half = dur / 2, jerk = dv / (half * half);
            prof.append_jump(half, v0, 0, jerk);
            prof.append_cubic(half, -jerk);
        } else {
            prof.append_jump(dur, v0, dv / dur, 0);
        }
    }
    prof.append_jump(kHoldSeconds, velocity, 0, 0);
    prof.finish(prof.final_state().p, velocity);
    return prof;
}

// ---- CiA 402 -------------------------------------------------------------------

Cia402Homing::Cia402Homing(MotorModel& motor, Params p) : motor_(motor), p_(p) {
    listener_ = motor_.add_listener([this](const MotorEvent& e) { on_event(e); });
}

Cia402Homing::~Cia402Homing() { motor_.remove_listener(listener_); }

bool Cia402Homing::supported(int m) {
    switch (m) {
        case 7: case 11: case 17: case 18: case 19: case 20: case 33: case 34: case 35: return true;
        default: return false;
    }
}

void Cia402Homing::run_at(double velocity) {
    motor_.command(ramp_and_hold(motor_.pulse_position(), motor_.pulse_velocity(), velocity, p_.acceleration,
                                 RampShape::Trapezoid));
}

void Cia402Homing::finish(HomingResult r, bool set_home) {
    motor_.halt();
    if (set_home) motor_.set_pulse_position(p_.home_offset);
    result_ = r;
    stage_ = -1;
}

// Stages: 0 = search the switch at speed_switch, 1 = leave/find the edge at
// speed_zero, 2 = search the index at speed_zero, 3 = (method 20) come back
// to the rising edge.
void Cia402Homing::start() {
    if (!supported(p_.method))
        throw InvalidArgument("CiA 402 homing method " + std::to_string(p_.method) +
                              " is not supported (7, 11, 17, 18, 19, 20, 33, 34, 35)");
    if (!(p_.speed_switch > 0) || !(p_.speed_zero > 0) || !(p_.acceleration > 0))
        throw InvalidArgument("CiA 402 homing: speeds (6099h) and acceleration (609Ah) must be positive");
    motor_.update();
    result_ = HomingResult::Running;
    switch (p_.method) {
        case 35: finish(HomingResult::Done, true); return;
        case 33: stage_ = 2; run_at(-p_.speed_zero); return;
        case 34: stage_ = 2; run_at(p_.speed_zero); return;
        case 17: stage_ = 0; run_at(-p_.speed_switch); return;
        case 18: stage_ = 0; run_at(p_.speed_switch); return;
        default: break;
    }
    // 7, 19, 20: search in + ; 11: search in -.
    const double dir = p_.method == 11 ? -1.0 : 1.0;
    if (motor_.home_active()) {
        // Already on the switch: leave it backwards at zero speed.
        stage_ = 1;
        run_at(-dir * p_.speed_zero);
    } else {
        stage_ = 0;
        run_at(dir * p_.speed_switch);
    }
}

void Cia402Homing::abort() {
    if (result_ != HomingResult::Running) return;
    motor_.halt();
    result_ = HomingResult::Aborted;
}

void Cia402Homing::on_event(const MotorEvent& e) {
    using K = MotorEvent::Kind;
    if (result_ != HomingResult::Running) return;
    const int m = p_.method;
    // A limit switch that is not the homing target is a homing error.
    const bool is_limit = e.kind == K::PlusLimitOn || e.kind == K::MinusLimitOn;
    if (is_limit && !((m == 17 && e.kind == K::MinusLimitOn) || (m == 18 && e.kind == K::PlusLimitOn))) {
        finish(HomingResult::Failed, false);
        return;
    }
    if (m == 17 || m == 18) {
        if (stage_ == 0 && is_limit) {
            stage_ = 1;
            run_at(m == 17 ? p_.speed_zero : -p_.speed_zero);
        } else if (stage_ == 1 && (e.kind == K::MinusLimitOff || e.kind == K::PlusLimitOff)) {
            finish(HomingResult::Done, true);
        }
        return;
    }
    if (m == 33 || m == 34) {
        if (stage_ == 2 && e.kind == K::IndexPulse) finish(HomingResult::Done, true);
        return;
    }
    const double dir = m == 11 ? -1.0 : 1.0;
    if (stage_ == 0 && e.kind == K::HomeOn) {
        if (m == 20) {
            stage_ = 1;
            run_at(-dir * p_.speed_switch);
        } else {
            stage_ = 1;
            run_at(-dir * p_.speed_zero);
        }
    } else if (stage_ == 1 && e.kind == K::HomeOff) {
        if (m == 19) {
            finish(HomingResult::Done, true);
        } else if (m == 20) {
            stage_ = 3;
            run_at(dir * p_.speed_zero);
        } else {  // 7, 11: continue to the next index pulse
            stage_ = 2;
        }
    } else if (stage_ == 2 && e.kind == K::IndexPulse) {
        finish(HomingResult::Done, true);
    } else if (stage_ == 3 && e.kind == K::HomeOn) {
        finish(HomingResult::Done, true);
    }
}

}  // namespace motorbus::motion

#include "motorbus/drives/arcus/homing.hpp"

#include <cmath>

#include "motorbus/motion/planner_detail.hpp"
#include "motorbus/motion/stepnloop.hpp"

namespace motorbus::arcus {

using namespace motorbus::motion;

// ---- DMX-CAN -------------------------------------------------------------------

Homing::Homing(MotorModel& motor, ProfileParams params, Options opt)
    : motor_(motor), params_(arcus_effective(params).params), opt_(opt) {
    listener_ = motor_.add_listener([this](const MotorEvent& e) { on_event(e); });
}

Homing::~Homing() { motor_.remove_listener(listener_); }

int Homing::snl_status() const {
    switch (method_) {
        case Method::Z: return static_cast<int>(SnlStatus::ZHoming);
        // Homing while it looks for the switch, Z-Homing once it looks for the index.
        case Method::ZH: return static_cast<int>(stage_ == 0 ? SnlStatus::Homing : SnlStatus::ZHoming);
        case Method::L: return static_cast<int>(SnlStatus::LimitHoming);
        default: return static_cast<int>(SnlStatus::Homing);
    }
}

namespace {
double arcus_accel(const ProfileParams& p) {
    return std::max(p.hspd - p.lspd, 1e-9) / (p.acc_ms / 1000.0);
}
double arcus_decel(const ProfileParams& p) {
    return std::max(p.hspd - p.lspd, 1e-9) / ((p.edec ? p.dec_ms : p.acc_ms) / 1000.0);
}
}  // namespace

void Homing::jog(int direction, double speed) {
    const RampShape shape = params_.scv ? RampShape::SCurve : RampShape::Trapezoid;
    motor_.command(ramp_and_hold(motor_.pulse_position(), motor_.pulse_velocity(), direction * speed,
                                 arcus_accel(params_), shape, params_.lspd));
}

void Homing::decel_stop(Nanos) {
    // Ramp down to LSPD, then stop (a jump from LSPD to 0).
    const double v = motor_.pulse_velocity();
    Profile tail(State{motor_.pulse_position(), v, 0, 0});
    const double w = std::fabs(v);
    if (w > params_.lspd)
        detail::append_ramp(tail, -detail::sgn(v) * (w - params_.lspd), (w - params_.lspd) / arcus_decel(params_),
                            params_.scv ? RampShape::SCurve : RampShape::Trapezoid);
    tail.finish(tail.final_state().p, 0);
    if (tail.empty()) {
        motor_.halt();
        return;
    }
    motor_.command(tail);
}

void Homing::run(double target, double, bool) {
    const RampShape shape = params_.scv ? RampShape::SCurve : RampShape::Trapezoid;
    Profile p = arcus_stepper_profile(State{motor_.pulse_position(), motor_.pulse_velocity(), 0, 0}, target,
                                      params_.hspd, params_.lspd, arcus_accel(params_), arcus_decel(params_), shape);
    if (p.empty()) {
        motor_.halt();
        return;
    }
    motor_.command(p);
}

void Homing::run_at(double target, double speed) {
    const RampShape shape = params_.scv ? RampShape::SCurve : RampShape::Trapezoid;
    Profile p = arcus_stepper_profile(State{motor_.pulse_position(), motor_.pulse_velocity(), 0, 0}, target, speed,
                                      speed, arcus_accel(params_), arcus_decel(params_), shape);
    if (p.empty()) {
        motor_.halt();
        return;
    }
    motor_.command(p);
}

void Homing::start(Method m, int direction) {
    motor_.update();
    method_ = m;
    dir_ = direction >= 0 ? 1 : -1;
    stage_ = 0;
    result_ = HomingResult::Running;
    if (m == Method::Z) {
        jog(dir_, params_.lspd);
    } else {
        jog(dir_, params_.hspd);
    }
    // The inputs are levels: a switch already active when the search starts
    // is found at once (the event that would announce it never comes).
    using K = MotorEvent::Kind;
    const int phys_dir = motor_.steps_per_unit() > 0 ? dir_ : -dir_;
    auto now_event = [&](K k) {
        on_event(MotorEvent{k, motor_.time(), motor_.physical_position(), motor_.pulse_position(),
                            motor_.encoder(), phys_dir});
    };
    if (phys_dir > 0 && motor_.plus_limit_active()) now_event(K::PlusLimitOn);
    else if (phys_dir < 0 && motor_.minus_limit_active()) now_event(K::MinusLimitOn);
    else if (m != Method::Z && m != Method::L && motor_.home_active()) now_event(K::HomeOn);
}

void Homing::abort() {
    if (result_ != HomingResult::Running) return;
    motor_.halt();
    result_ = HomingResult::Aborted;
}

void Homing::stop() {
    if (result_ != HomingResult::Running) return;
    decel_stop(motor_.time());
    result_ = HomingResult::Aborted;
}

void Homing::set_zero() {
    motor_.set_pulse_position(0);
    if (opt_.zero_encoder) motor_.set_encoder(0);
}

// The home switch was found while searching (H, HL): zero the counter there,
// decelerate to LSPD and stop; stage 1 waits for the end of that ramp.
void Homing::zero_and_decelerate(const MotorEvent& e) {
    set_zero();
    decel_stop(e.t);
    stage_ = 1;
    if (!motor_.moving())
        on_event(MotorEvent{MotorEvent::Kind::ProfileDone, e.t, e.physical, 0, e.encoder, 0});
}

// The routine ends where the motor is now: stop at once, that point is zero.
void Homing::stop_at_zero() {
    motor_.halt();
    set_zero();
    finish(HomingResult::Done);
}

void Homing::finish(HomingResult r) {
    if (r == HomingResult::Done && opt_.final_target && stage_ != kFinalStage) {
        // Zero found: on to the home offset (CANopen 607Ch), then zero there.
        motor_.halt();
        stage_ = kFinalStage;
        if (std::llround(motor_.pulse_position() - *opt_.final_target) != 0) {
            run_at(*opt_.final_target, params_.lspd);
            if (motor_.moving()) return;
        }
        set_zero();
    }
    result_ = r;
    stage_ = -1;
}

void Homing::on_event(const MotorEvent& e) {
    using K = MotorEvent::Kind;
    if (result_ != HomingResult::Running) return;
    const bool limit_ahead = (e.kind == K::PlusLimitOn && e.direction > 0) || (e.kind == K::MinusLimitOn && e.direction < 0);
    if ((method_ != Method::L || stage_ == kFinalStage) && limit_ahead) {
        motor_.halt();
        finish(HomingResult::LimitError);
        return;
    }
    if (stage_ == kFinalStage) {
        if (e.kind == K::ProfileDone) {
            set_zero();
            finish(HomingResult::Done);
        }
        return;
    }
    switch (method_) {
        case Method::H:
            if (stage_ == 0 && e.kind == K::HomeOn) {
                zero_and_decelerate(e);
            } else if (stage_ == 1 && e.kind == K::ProfileDone) {
                if (opt_.rz && std::llround(motor_.pulse_position()) != 0) {
                    run(0, params_.hspd, false);
                    stage_ = 2;
                } else {
                    finish(HomingResult::Done);
                }
            } else if (stage_ == 2 && e.kind == K::ProfileDone) {
                finish(HomingResult::Done);
            }
            break;
        case Method::HL:
            // Stages: 0 search at HSPD, 1 decelerate, 2 back at LSPD to the switch,
            // 3 through the switch at HSPD, 4 HCA past it, 5 forward at LSPD onto it.
            if (stage_ == 0 && e.kind == K::HomeOn) {
                zero_and_decelerate(e);
            } else if (stage_ == 1 && e.kind == K::ProfileDone) {
                if (motor_.home_active()) {
                    // Stopped inside the switch: it is reached already.
                    jog(-dir_, params_.hspd);
                    stage_ = 3;
                } else {
                    jog(-dir_, params_.lspd);
                    stage_ = 2;
                }
            } else if (stage_ == 2 && e.kind == K::HomeOn) {
                jog(-dir_, params_.hspd);
                stage_ = 3;
            } else if (stage_ == 3 && e.kind == K::HomeOff) {
                // The manual (Figure 7.4 E): "past the home input by ... HCA".
                run(motor_.pulse_position() - dir_ * opt_.hca, params_.hspd, true);
                stage_ = 4;
                if (!motor_.moving()) on_event(MotorEvent{K::ProfileDone, e.t, e.physical, 0, e.encoder, 0});
            } else if (stage_ == 4 && e.kind == K::ProfileDone) {
                stage_ = 5;
                if (motor_.home_active()) {
                    stop_at_zero();
                } else {
                    jog(dir_, params_.lspd);
                }
            } else if (stage_ == 5 && e.kind == K::HomeOn) {
                stop_at_zero();
            }
            break;
        case Method::L:
            if (stage_ == 0 && limit_ahead) {
                motor_.halt();
                if (opt_.backoff_at_lspd)
                    run_at(motor_.pulse_position() - dir_ * opt_.lca, params_.lspd);
                else
                    run(motor_.pulse_position() - dir_ * opt_.lca, params_.hspd, true);
                stage_ = 1;
                if (!motor_.moving()) {
                    set_zero();
                    finish(HomingResult::Done);
                }
            } else if (stage_ == 1 && e.kind == K::ProfileDone) {
                set_zero();
                finish(HomingResult::Done);
            }
            break;
        case Method::Z:
            if (stage_ == 0 && e.kind == K::IndexPulse) {
                stop_at_zero();
            }
            break;
        case Method::ZH:
            if (stage_ == 0 && e.kind == K::HomeOn) {
                // Decelerate to LSPD and keep going at LSPD to find Z.
                jog(dir_, params_.lspd);
                stage_ = 1;
            } else if (stage_ == 1 && e.kind == K::IndexPulse &&
                       std::fabs(motor_.pulse_velocity()) <= params_.lspd * (1 + 1e-9)) {
                stop_at_zero();
            }
            break;
    }
}

}  // namespace motorbus::arcus

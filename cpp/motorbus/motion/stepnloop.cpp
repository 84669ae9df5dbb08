#include "motorbus/motion/stepnloop.hpp"

#include <cmath>

namespace motorbus::motion {

namespace {
constexpr SnlActivity kActivities[] = {SnlActivity::Move, SnlActivity::Jog,       SnlActivity::Home,
                                       SnlActivity::ZHome, SnlActivity::LimitHome, SnlActivity::Stop,
                                       SnlActivity::Abort};
}  // namespace

const char* to_string(SnlActivity a) {
    switch (a) {
        case SnlActivity::Move: return "move";
        case SnlActivity::Jog: return "jog";
        case SnlActivity::Home: return "home";
        case SnlActivity::ZHome: return "zhome";
        case SnlActivity::LimitHome: return "limit_home";
        case SnlActivity::Stop: return "stop";
        case SnlActivity::Abort: return "abort";
    }
    return "?";
}

std::optional<SnlActivity> snl_activity_from_name(std::string_view name) {
    for (auto a : kActivities)
        if (name == to_string(a)) return a;
    return std::nullopt;
}

const char* snl_status_name(SnlStatus s) {
    switch (s) {
        case SnlStatus::Idle: return "IDLE";
        case SnlStatus::Moving: return "MOVING";
        case SnlStatus::Correcting: return "CORRECTING";
        case SnlStatus::Stopping: return "STOPPING";
        case SnlStatus::Aborting: return "ABORTING";
        case SnlStatus::Jogging: return "JOGGING";
        case SnlStatus::Homing: return "HOMING";
        case SnlStatus::ZHoming: return "Z-HOMING";
        case SnlStatus::RangeError: return "ERR-RANGE";
        case SnlStatus::AttemptError: return "ERR-ATMPT";
        case SnlStatus::StallError: return "ERR-STALL";
        case SnlStatus::LimitError: return "ERR-LIM";
        case SnlStatus::Disabled: return "NA";
        case SnlStatus::LimitHoming: return "LIMIT-HOMING";
    }
    return "?";
}

StepNLoop::StepNLoop(SnlConfig cfg) { configure(cfg); }

void StepNLoop::configure(const SnlConfig& cfg) {
    cfg_ = cfg;
    if (!(cfg_.ratio > 0) || !std::isfinite(cfg_.ratio)) cfg_.ratio = 0.8;
    if (!cfg_.enabled) {
        status_ = SnlStatus::Disabled;
    } else if (status_ == SnlStatus::Disabled) {
        status_ = SnlStatus::Idle;
    }
    attempts_ = 0;
    after_correction_ = false;
    verifying_ = false;
}

bool StepNLoop::in_error() const {
    return status_ == SnlStatus::RangeError || status_ == SnlStatus::AttemptError ||
           status_ == SnlStatus::StallError || status_ == SnlStatus::LimitError;
}

bool StepNLoop::begin(SnlActivity what) {
    if (!cfg_.enabled) return true;
    if (in_error()) return false;
    attempts_ = 0;
    after_correction_ = false;
    verifying_ = what == SnlActivity::Move;
    switch (what) {
        case SnlActivity::Move: status_ = SnlStatus::Moving; break;
        case SnlActivity::Jog: status_ = SnlStatus::Jogging; break;
        case SnlActivity::Home: status_ = SnlStatus::Homing; break;
        case SnlActivity::ZHome: status_ = SnlStatus::ZHoming; break;
        case SnlActivity::LimitHome: status_ = SnlStatus::LimitHoming; break;
        case SnlActivity::Stop: status_ = SnlStatus::Stopping; break;
        case SnlActivity::Abort: status_ = SnlStatus::Aborting; break;
    }
    return true;
}

SnlDecision StepNLoop::error(SnlStatus s) {
    status_ = s;
    verifying_ = false;
    return SnlDecision{SnlAction::StopNow, 0, false};
}

SnlDecision StepNLoop::monitor(double delta) {
    if (!cfg_.enabled || in_error()) return {};
    if (std::fabs(delta) > static_cast<double>(cfg_.error_range)) return error(SnlStatus::StallError);
    return {};
}

SnlDecision StepNLoop::motion_done(double delta) {
    if (!cfg_.enabled) return SnlDecision{SnlAction::InPosition, 0, false};
    if (in_error()) return {};
    const double err = std::fabs(delta);
    // After a correction the finer idle tolerance decides whether to try again.
    const double tol = after_correction_ ? static_cast<double>(cfg_.idle_tolerance)
                                         : static_cast<double>(cfg_.tolerance);
    if (err <= tol) {
        status_ = SnlStatus::Idle;
        verifying_ = false;
        after_correction_ = false;
        attempts_ = 0;
        return SnlDecision{SnlAction::InPosition, 0, false};
    }
    if (err > static_cast<double>(cfg_.error_range)) return error(SnlStatus::RangeError);
    if (attempts_ >= cfg_.max_attempts) return error(SnlStatus::AttemptError);
    ++attempts_;
    const bool idle_current = after_correction_;
    after_correction_ = true;
    verifying_ = true;
    status_ = SnlStatus::Correcting;
    return SnlDecision{SnlAction::Correct, delta, idle_current};
}

SnlDecision StepNLoop::idle_check(double delta) {
    if (!cfg_.enabled || in_error()) return {};
    if (status_ != SnlStatus::Idle) return {};
    const double err = std::fabs(delta);
    if (err <= static_cast<double>(cfg_.tolerance)) return {};
    attempts_ = 0;
    after_correction_ = false;
    return motion_done(delta);
}

void StepNLoop::limit_hit() {
    if (!cfg_.enabled) return;
    status_ = SnlStatus::LimitError;
    verifying_ = false;
}

void StepNLoop::end_without_verification() {
    if (!cfg_.enabled || in_error()) return;
    status_ = SnlStatus::Idle;
    verifying_ = false;
    after_correction_ = false;
    attempts_ = 0;
}

void StepNLoop::clear() {
    attempts_ = 0;
    after_correction_ = false;
    verifying_ = false;
    status_ = cfg_.enabled ? SnlStatus::Idle : SnlStatus::Disabled;
}

}  // namespace motorbus::motion

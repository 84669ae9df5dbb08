#include "motorbus/drives/arcus/profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "motorbus/motion/planner_detail.hpp"

namespace motorbus::arcus {

namespace {
// A jog has no end; the profile needs one.  Long enough for any test or sim.
constexpr double kJogHoldSeconds = 1e7;

std::string fmt(const char* f, double a, double b) {
    char buf[160];
    std::snprintf(buf, sizeof buf, f, a, b);
    return buf;
}
}  // namespace

const std::array<ArcusSpeedWindow, 9>& arcus_speed_windows() {
    // Table A.0 of the DMX-CAN manual.
    static const std::array<ArcusSpeedWindow, 9> rows{{
        {1, 0, 1, 1, 16e3, 10, 2, 500},
        {2, 2, 2, 16e3, 30e3, 10, 1, 1e3},
        {3, 3, 3, 30e3, 80e3, 15, 1, 2e3},
        {4, 4, 4, 80e3, 160e3, 25, 1, 4e3},
        {5, 5, 5, 160e3, 300e3, 50, 1, 8e3},
        {6, 6, 6, 300e3, 800e3, 100, 1, 18e3},
        {7, 7, 7, 800e3, 1.6e6, 200, 1, 39e3},
        {8, 8, 8, 1.6e6, 3.0e6, 400, 1, 68e3},
        {9, 9, 9, 3.0e6, 6.0e6, 500, 1, 135e3},
    }};
    return rows;
}

const ArcusSpeedWindow& arcus_window_for_hspd(double hspd_pps) {
    const auto& rows = arcus_speed_windows();
    if (!(hspd_pps >= 1)) throw LimitExceeded("HSPD", hspd_pps, 1, "below the lowest speed window");
    if (hspd_pps > rows.back().hspd_high)
        throw LimitExceeded("HSPD", hspd_pps, rows.back().hspd_high, "above the highest speed window");
    for (const auto& w : rows)
        if (hspd_pps <= w.hspd_high) return w;
    return rows.back();
}

const ArcusSpeedWindow& arcus_window_for_sspdm(int sspdm) {
    for (const auto& w : arcus_speed_windows())
        if (sspdm >= w.sspdm_first && sspdm <= w.sspdm_last) return w;
    throw LimitExceeded("SSPDM", sspdm, sspdm < 0 ? 0 : 9, "SSPDM is 0..9");
}

double arcus_max_acc_ms(double hspd_pps, double lspd_pps) {
    const auto& w = arcus_window_for_hspd(hspd_pps);
    return (hspd_pps - lspd_pps) / w.delta * 1000.0;
}

double Effective::accel() const {
    const double dv = std::max(params.hspd - params.lspd, 1e-9);
    return dv / (params.acc_ms / 1000.0);
}
double Effective::decel() const {
    const double dv = std::max(params.hspd - params.lspd, 1e-9);
    return dv / ((params.edec ? params.dec_ms : params.acc_ms) / 1000.0);
}

namespace {
void clamp_time(double& ms, const char* name, const ArcusSpeedWindow& w, double max_ms,
                std::vector<std::string>& notes) {
    const double lo = w.min_acc_ms;
    const double hi = std::max(lo, max_ms);
    if (ms < lo) {
        notes.push_back(std::string(name) + fmt(" raised from %g ms to the window minimum %g ms", ms, lo));
        ms = lo;
    } else if (ms > hi) {
        notes.push_back(std::string(name) + fmt(" lowered from %g ms to the maximum %g ms", ms, hi));
        ms = hi;
    }
}
}  // namespace

Effective arcus_effective(const ProfileParams& req) {
    if (!std::isfinite(req.hspd) || !std::isfinite(req.lspd) || !std::isfinite(req.acc_ms) ||
        !std::isfinite(req.dec_ms) || !std::isfinite(req.snl_ratio))
        throw InvalidArgument("Arcus profile: parameters must be finite");
    if (!(req.snl_ratio > 0)) throw LimitExceeded("SLR", req.snl_ratio, 0, "ratio must be positive");
    if (!(req.acc_ms > 0)) throw LimitExceeded("ACC", req.acc_ms, 0, "must be positive");
    if (req.edec && !(req.dec_ms > 0)) throw LimitExceeded("DEC", req.dec_ms, 0, "must be positive");
    Effective e;
    e.params = req;
    // With StepNLoop on, speeds are in encoder counts/s: the windows are in PPS.
    const double hspd_pps = req.hspd * req.snl_ratio;
    e.window = &arcus_window_for_hspd(hspd_pps);
    const double min_lspd = e.window->min_lspd / req.snl_ratio;
    if (e.params.lspd < min_lspd) {
        e.adjustments.push_back(fmt("LSPD raised from %g to the window minimum %g", e.params.lspd, min_lspd));
        e.params.lspd = min_lspd;
    }
    if (e.params.lspd > e.params.hspd) {
        e.adjustments.push_back(fmt("LSPD lowered from %g to HSPD %g", e.params.lspd, e.params.hspd));
        e.params.lspd = e.params.hspd;
    }
    const double max_ms = (e.params.hspd - e.params.lspd) * req.snl_ratio / e.window->delta * 1000.0;
    clamp_time(e.params.acc_ms, "ACC", *e.window, max_ms, e.adjustments);
    if (e.params.edec) clamp_time(e.params.dec_ms, "DEC", *e.window, max_ms, e.adjustments);
    return e;
}

void arcus_check_strict(const ProfileParams& req) {
    const double hspd_pps = req.hspd * req.snl_ratio;
    const auto& w = arcus_window_for_hspd(hspd_pps);
    const std::string win = "speed window " + std::to_string(w.number);
    if (req.lspd * req.snl_ratio < w.min_lspd)
        throw LimitExceeded("LSPD", req.lspd, w.min_lspd / req.snl_ratio, "minimum LSPD of " + win);
    if (req.lspd > req.hspd) throw LimitExceeded("LSPD", req.lspd, req.hspd, "LSPD above HSPD");
    const double max_ms = (req.hspd - req.lspd) * req.snl_ratio / w.delta * 1000.0;
    auto check = [&](const char* name, double ms) {
        if (ms < w.min_acc_ms) throw LimitExceeded(name, ms, w.min_acc_ms, "minimum ACC of " + win);
        if (ms > max_ms) throw LimitExceeded(name, ms, max_ms, "maximum ACC = ((HSPD - LSPD) / delta) x 1000 ms");
    };
    check("ACC", req.acc_ms);
    if (req.edec) check("DEC", req.dec_ms);
}

const char* arcus_reply_text(MotionReply r) {
    switch (r) {
        case MotionReply::Ok: return "";
        case MotionReply::MotorNotMoving: return "?Motor is not moving";
        case MotionReply::Moving: return "?Moving";
        case MotionReply::ScvOn: return "?SCV ON";
        case MotionReply::SpeedOutOfRange: return "?Speed out of range";
        case MotionReply::BadSspd: return "?Bad SSPD Command";
        case MotionReply::MoveTooFar: return "?Index out of Range";
    }
    return "";
}

Profile arcus_stepper_profile(const State& start, double target, double hspd, double lspd, double accel,
                              double decel, RampShape shape) {
    return detail::stepper_profile(start, target, hspd, accel, decel, lspd, lspd, shape);
}

Motion::Motion(ProfileParams params, int sspdm) {
    set_params(params);
    set_sspdm(sspdm);
}

const Effective& Motion::set_params(const ProfileParams& params) {
    eff_ = arcus_effective(params);
    return eff_;
}

void Motion::set_sspdm(int sspdm) {
    (void)arcus_window_for_sspdm(sspdm);
    sspdm_ = sspdm;
}

static RampShape ArcusMotion_shape(const Effective& e) {
    return e.params.scv ? RampShape::SCurve : RampShape::Trapezoid;
}

MotionReply Motion::move(double position, double target) {
    if (!std::isfinite(position) || !std::isfinite(target)) return MotionReply::MoveTooFar;
    if (std::fabs(target - position) > static_cast<double>(kArcusMaxMoveDistance)) return MotionReply::MoveTooFar;
    hspd_now_ = eff_.params.hspd;
    profile_ = arcus_stepper_profile(State{position, 0, 0, 0}, target, hspd_now_, eff_.params.lspd,
                                     eff_.accel(), eff_.decel(), ArcusMotion_shape(eff_));
    target_move_ = true;
    jogging_ = false;
    target_ = target;
    return MotionReply::Ok;
}

MotionReply Motion::jog(double position, int direction) {
    const double s = direction >= 0 ? 1.0 : -1.0;
    hspd_now_ = eff_.params.hspd;
    Profile p(State{position, 0, 0, 0});
    const double lspd = eff_.params.lspd;
    const double t_acc = (hspd_now_ - lspd) / eff_.accel();
    if (t_acc > 0) {
        if (eff_.params.scv) {
            const double half = t_acc / 2, jerk = s * (hspd_now_ - lspd) / (half * half);
            p.append_jump(half, s * lspd, 0, jerk);
            p.append_cubic(half, -jerk);
        } else {
            p.append_jump(t_acc, s * lspd, s * eff_.accel(), 0);
        }
    }
    p.append_jump(kJogHoldSeconds, s * hspd_now_, 0, 0);
    p.finish(p.final_state().p, s * hspd_now_);
    profile_ = p;
    target_move_ = false;
    jogging_ = true;
    jog_dir_ = static_cast<int>(s);
    return MotionReply::Ok;
}

bool Motion::moving(double t) const { return !profile_.empty() && t >= 0 && t < profile_.duration(); }

MotionReply Motion::change_target(double t, double new_target) {
    if (!target_move_ || !moving(t)) return MotionReply::MotorNotMoving;
    if (!std::isfinite(new_target)) return MotionReply::MoveTooFar;
    const State st = profile_.at(t);
    Profile tail = arcus_stepper_profile(st, new_target, hspd_now_, eff_.params.lspd, eff_.accel(), eff_.decel(),
                                         ArcusMotion_shape(eff_));
    Profile head = profile_.truncated(t);
    head.append(tail);
    head.finish(new_target, 0);
    profile_ = head;
    target_ = new_target;
    return MotionReply::Ok;
}

MotionReply Motion::change_speed(double t, double new_hspd) {
    if (eff_.params.scv) return MotionReply::ScvOn;
    if (!moving(t) || !std::isfinite(new_hspd) || new_hspd <= 0) return MotionReply::BadSspd;
    const auto& w = arcus_window_for_sspdm(sspdm_);
    const double pps = new_hspd * eff_.params.snl_ratio;
    if (pps < w.hspd_low || pps > w.hspd_high) return MotionReply::SpeedOutOfRange;
    const State st = profile_.at(t);
    // The ramp keeps the move's acceleration (PPS/s) fixed.
    const double accel = eff_.accel(), decel = eff_.decel();
    hspd_now_ = std::max(new_hspd, eff_.params.lspd);
    Profile tail;
    if (target_move_) {
        tail = arcus_stepper_profile(st, target_, hspd_now_, eff_.params.lspd, accel, decel, RampShape::Trapezoid);
    } else {
        const double s = jog_dir_ >= 0 ? 1.0 : -1.0;
        tail = Profile(State{st.p, st.v, 0, 0});
        const double dv = s * hspd_now_ - st.v;
        const double rate = std::fabs(s * hspd_now_) > std::fabs(st.v) ? accel : decel;
        detail::append_ramp(tail, dv, std::fabs(dv) / rate, RampShape::Trapezoid);
        tail.append_jump(kJogHoldSeconds, s * hspd_now_, 0, 0);
        tail.finish(tail.final_state().p, s * hspd_now_);
    }
    Profile head = profile_.truncated(t);
    const double end_v = tail.final_state().v;
    const double end_p = tail.final_state().p;
    head.append(tail);
    head.finish(target_move_ ? target_ : end_p, end_v);
    profile_ = head;
    return MotionReply::Ok;
}

void Motion::stop(double t) {
    if (!moving(t)) return;
    const State st = profile_.at(t);
    Profile tail(State{st.p, st.v, 0, 0});
    const double w = std::fabs(st.v), lspd = eff_.params.lspd;
    if (w > lspd)
        detail::append_ramp(tail, -detail::sgn(st.v) * (w - lspd), (w - lspd) / eff_.decel(), ArcusMotion_shape(eff_));
    const double end = tail.final_state().p;
    Profile head = profile_.truncated(t);
    head.append(tail);
    head.finish(end, 0);
    profile_ = head;
    target_move_ = false;
    jogging_ = false;
    target_ = end;
}

void Motion::abort(double t) {
    if (!moving(t)) return;
    const double p = profile_.at(t).p;
    Profile head = profile_.truncated(t);
    head.finish(p, 0);
    profile_ = head;
    target_move_ = false;
    jogging_ = false;
    target_ = p;
}

Phase Motion::phase(double t) const {
    if (!moving(t)) return Phase::Idle;
    const State st = profile_.at(t);
    const double acc = st.a != 0 ? st.a : st.j;
    if (acc == 0 || st.v == 0) return Phase::Const;
    return (acc > 0) == (st.v > 0) ? Phase::Accel : Phase::Decel;
}

}  // namespace motorbus::arcus

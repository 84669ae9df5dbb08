// The simulator's axis: motion::ArcusMotion (the project's DMX profile model:
// LSPD start, ACC/DEC ramps, S-curve, T and SSPD on the fly, STOP/ABORT,
// Appendix A adjustment) stepped on the sim's clock, plus what the sim needs
// on top: a position that counter resets can move, and a "stop here" for
// events found inside a tick.
#pragma once
#include <algorithm>
#include <cmath>

#include "motorbus/motion/arcus_profile.hpp"

namespace motorbus::arcus::detail {

class Axis {
public:
    struct Params {
        double lspd = 100, hspd = 1000;   // units/s (pulses, or counts under StepNLoop)
        double acc_ms = 300, dec_ms = 300;
        bool edec = false;
        bool scurve = false;
        double snl_ratio = 1.0;           // pulses per unit, for the Appendix A windows
        int sspdm = 0;
    };

    bool busy() const { return active_; }
    bool accelerating() const { return active_ && m_.phase(t_) == motion::ArcusPhase::Accel; }
    bool decelerating() const { return active_ && m_.phase(t_) == motion::ArcusPhase::Decel; }
    bool constant() const { return active_ && m_.phase(t_) == motion::ArcusPhase::Const; }
    bool stopping() const { return active_ && stopping_; }
    bool target_move() const { return active_ && m_.target_move(); }

    double position() const { return active_ ? m_.profile().position(t_) + offset_ : idle_pos_; }
    double speed() const { return active_ ? std::fabs(m_.profile().velocity(t_)) : 0.0; }
    // Moves the counter frame (PX=, EX= under StepNLoop, homing zero): the motor stays put.
    void set_position(double p) {
        if (active_) offset_ += p - position();
        else idle_pos_ = p;
    }

    void configure(const Params& p) {
        motion::ArcusProfileParams ap;
        ap.snl_ratio = p.snl_ratio > 0 ? p.snl_ratio : 1.0;
        // arcus_effective refuses speeds outside 1..6 000 000 PPS; the sim
        // validates HSPD/LSPD itself, so only clamp what unit conversion moved.
        const double min_units = 1.0 / ap.snl_ratio;
        const double max_units = 6'000'000.0 / ap.snl_ratio;
        ap.hspd = std::clamp(p.hspd, min_units, max_units);
        ap.lspd = std::clamp(p.lspd, 1e-6, ap.hspd);
        ap.acc_ms = std::max(p.acc_ms, 1e-3);
        ap.dec_ms = std::max(p.dec_ms, 1e-3);
        ap.edec = p.edec;
        ap.scv = p.scurve;
        m_.set_params(ap);
        m_.set_sspdm(std::clamp(p.sspdm, 0, 9));
    }

    // X: returns false when the model refuses the move (above 262143).
    bool move_to(double target) {
        double from = position();
        begin();
        if (m_.move(from, target) != motion::ArcusReply::Ok) {
            idle_pos_ = from;
            return false;
        }
        active_ = m_.moving(0);
        if (!active_) idle_pos_ = target;
        return true;
    }
    // J+/J- (high) or a constant low-speed search (homing).
    void run(int dir, bool high) {
        double from = position();
        begin();
        if (!high) {
            motion::ArcusProfileParams ap = m_.effective().params;
            ap.hspd = ap.lspd;
            m_.set_params(ap);
        }
        m_.jog(from, dir);
        active_ = true;
    }
    void set_sspdm(int sspdm) { m_.set_sspdm(std::clamp(sspdm, 0, 9)); }
    motion::ArcusReply retarget(double target) { return m_.change_target(t_, target - offset_); }
    motion::ArcusReply change_speed(double hspd) { return m_.change_speed(t_, hspd); }
    void decel_stop() {
        if (!active_) return;
        m_.stop(t_);
        stopping_ = true;
        if (!m_.moving(t_)) finish();
    }
    void halt() {
        if (!active_) return;
        m_.abort(t_);
        finish();
    }
    // Advances dt seconds; true when the motion ended in this step.
    bool step(double dt) {
        if (!active_) return false;
        t_ += dt;
        if (m_.moving(t_)) return false;
        finish();
        return true;
    }

private:
    void begin() {
        t_ = 0;
        offset_ = 0;
        stopping_ = false;
        active_ = false;
    }
    void finish() {
        idle_pos_ = m_.profile().final_state().p + offset_;
        active_ = false;
        stopping_ = false;
    }

    motion::ArcusMotion m_;
    double t_ = 0, offset_ = 0, idle_pos_ = 0;
    bool active_ = false, stopping_ = false;
};

}  // namespace motorbus::arcus::detail

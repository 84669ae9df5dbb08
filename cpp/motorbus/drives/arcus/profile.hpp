// Minimal DMX velocity-profile stepper used by the simulator.
//
// ADAPTER: the project's Arcus profile model belongs in motion/ (motion helper);
// it had not been published when this sim was written, so this is the smallest
// thing the sim needs: starting at LSPD, ramping to HSPD in ACC ms (linear or
// S-shaped velocity with the same ramp time, hence the same distance), braking
// from the current speed to LSPD so a target move ends at LSPD, on-the-fly
// target (T) and speed (SSPD) changes.  Replace with motion/ when it exists.
#pragma once
#include <algorithm>
#include <cmath>

namespace motorbus::arcus::detail {

class Axis {
public:
    struct Params {
        double lspd = 100, hspd = 1000;  // units/s
        double acc_s = 0.3, dec_s = 0.3; // full LSPD<->HSPD swing time
        bool scurve = false;
    };
    enum class Mode { Idle, Run, Target };

    double pos = 0;   // units
    double vel = 0;   // magnitude, units/s
    int dir = 1;
    double target = 0;

    Mode mode() const { return mode_; }
    bool busy() const { return mode_ != Mode::Idle; }
    bool accelerating() const { return busy() && ramping_ && v1_ > v0_; }
    bool decelerating() const { return busy() && ramping_ && v1_ < v0_; }
    bool constant() const { return busy() && !ramping_; }
    bool stopping() const { return stop_after_ramp_; }
    const Params& params() const { return p_; }

    void configure(const Params& p) {
        p_ = p;
        double span = std::max(0.0, p_.hspd - p_.lspd);
        acc_rate_ = p_.acc_s > 0 ? span / p_.acc_s : 0;
        dec_rate_ = p_.dec_s > 0 ? span / p_.dec_s : 0;
    }

    void run(int d, bool high) {
        start(d);
        mode_ = Mode::Run;
        if (high) ramp_to(p_.hspd, acc_rate_);
    }
    void move_to(double t) {
        if (t == pos) { halt(); return; }
        start(t > pos ? 1 : -1);
        mode_ = Mode::Target;
        target = t;
        ramp_to(p_.hspd, acc_rate_);
    }
    // On-the-fly target change (T): a target behind us means stop, then go back.
    void retarget(double t) {
        target = t;
        if ((t - pos) * dir < 0) {
            reverse_pending_ = true;
            decel_stop();
        } else {
            reverse_pending_ = false;
            stop_after_ramp_ = false;
        }
    }
    // On-the-fly speed change (SSPD).
    void change_speed(double new_hspd) {
        p_.hspd = new_hspd;
        ramp_to(new_hspd, new_hspd > vel ? acc_rate_ : dec_rate_);
    }
    void decel_stop() {
        if (!busy()) return;
        stop_after_ramp_ = true;
        ramp_to(p_.lspd, dec_rate_);
    }
    void halt() {
        mode_ = Mode::Idle;
        vel = 0;
        ramping_ = false;
        stop_after_ramp_ = false;
        reverse_pending_ = false;
    }

    // Advances dt seconds.  Returns true when the axis went idle in this step.
    bool step(double dt) {
        if (!busy()) return false;
        if (mode_ == Mode::Target && !stop_after_ramp_) {
            double remaining = (target - pos) * dir;
            if (remaining <= 0) return finish_at_target();
            if (!decelerating() && vel > p_.lspd && remaining <= braking_distance() + vel * dt)
                ramp_to(p_.lspd, dec_rate_);
        }
        double v_start = vel;
        if (ramping_) {
            tau_ += dt;
            double u = T_ > 0 ? std::min(1.0, tau_ / T_) : 1.0;
            double shape = p_.scurve ? u * u * (3 - 2 * u) : u;
            vel = v0_ + (v1_ - v0_) * shape;
            if (u >= 1.0) ramping_ = false;
        }
        pos += dir * 0.5 * (v_start + vel) * dt;
        if (mode_ == Mode::Target && !reverse_pending_ && (target - pos) * dir <= 0)
            return finish_at_target();
        if (stop_after_ramp_ && !ramping_) {
            if (reverse_pending_) {
                double t = target;
                halt();
                move_to(t);
                return !busy();
            }
            halt();
            return true;
        }
        return false;
    }

    double braking_distance() const {
        if (vel <= p_.lspd || dec_rate_ <= 0) return 0;
        double t = (vel - p_.lspd) / dec_rate_;
        return 0.5 * (vel + p_.lspd) * t;
    }

private:
    void start(int d) {
        halt();
        dir = d >= 0 ? 1 : -1;
        vel = p_.lspd;
    }
    void ramp_to(double v, double rate) {
        if (rate <= 0 || v == vel) {
            vel = v;
            ramping_ = false;
            return;
        }
        v0_ = vel;
        v1_ = v;
        T_ = std::abs(v1_ - v0_) / rate;
        tau_ = 0;
        ramping_ = true;
    }
    bool finish_at_target() {
        pos = target;
        halt();
        return true;
    }

    Params p_;
    Mode mode_ = Mode::Idle;
    double acc_rate_ = 0, dec_rate_ = 0;
    bool ramping_ = false, stop_after_ramp_ = false, reverse_pending_ = false;
    double v0_ = 0, v1_ = 0, T_ = 0, tau_ = 0;
};

}  // namespace motorbus::arcus::detail

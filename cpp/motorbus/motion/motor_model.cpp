#include "motorbus/motion/motor_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace motorbus::motion {

const char* to_string(MotorEvent::Kind k) {
    using K = MotorEvent::Kind;
    switch (k) {
        case K::HomeOn: return "home_on";
        case K::HomeOff: return "home_off";
        case K::MinusLimitOn: return "minus_limit_on";
        case K::MinusLimitOff: return "minus_limit_off";
        case K::PlusLimitOn: return "plus_limit_on";
        case K::PlusLimitOff: return "plus_limit_off";
        case K::IndexPulse: return "index";
        case K::Stalled: return "stalled";
        case K::Recovered: return "recovered";
        case K::Latched: return "latched";
        case K::ProfileDone: return "profile_done";
    }
    return "?";
}

namespace {
bool home_on(const SwitchConfig& c, double p) { return c.present && p >= c.lo && p <= c.hi; }
bool minus_on(const SwitchConfig& c, double p) { return c.present && p <= c.lo; }
bool plus_on(const SwitchConfig& c, double p) { return c.present && p >= c.lo; }
constexpr int kMaxIndexPerTick = 64;  // bounded work on absurd speeds
int switch_slot(Switch w) { return w == Switch::Home ? 0 : (w == Switch::MinusLimit ? 1 : 2); }
}  // namespace

const SwitchConfig& MotorModel::switch_config(Switch w) const {
    return w == Switch::Home ? cfg_.home : (w == Switch::MinusLimit ? cfg_.minus_limit : cfg_.plus_limit);
}
SwitchConfig& MotorModel::switch_config(Switch w) {
    return w == Switch::Home ? cfg_.home : (w == Switch::MinusLimit ? cfg_.minus_limit : cfg_.plus_limit);
}

bool MotorModel::switch_level(Switch w, double p) const {
    const SwitchConfig& c = switch_config(w);
    const auto& forced = forced_[switch_slot(w)];
    const bool actuated = forced ? *forced
                          : w == Switch::Home ? home_on(c, p)
                          : w == Switch::MinusLimit ? minus_on(c, p)
                                                    : plus_on(c, p);
    return actuated != c.inverted;
}

MotorModel::MotorModel(Clock& clock, MotorConfig cfg) : clock_(clock), cfg_(cfg), profile_(State{0, 0, 0, 0}) {
    if (!(cfg_.steps_per_rev > 0) || !(cfg_.counts_per_rev > 0))
        throw InvalidArgument("MotorModel: steps_per_rev and counts_per_rev must be positive");
    if (cfg_.tick_ns <= 0) throw InvalidArgument("MotorModel: tick_ns must be positive");
    if (!(cfg_.index_width_steps > 0)) cfg_.index_width_steps = cfg_.steps_per_rev / cfg_.counts_per_rev;
    initial_cfg_ = cfg_;
    now_ = clock_.now();
    profile_start_ = now_;
}

void MotorModel::reset() {
    if (in_dispatch_) throw InvalidArgument("MotorModel: reset from a listener");
    cfg_ = initial_cfg_;
    profile_ = Profile(State{0, 0, 0, 0});
    now_ = clock_.now();
    profile_start_ = now_;
    profile_offset_ = 0;
    running_ = false;
    physical_ = 0;
    slip_ = 0;
    stalled_ = false;
    jammed_ = false;
    pulse_offset_ = 0;
    encoder_offset_ = 0;
    steps_per_unit_ = 1;
    anchor_steps_ = 0;
    anchor_units_ = 0;
    for (auto& f : forced_) f.reset();
    latch_ = LatchState::Off;
    latched_pulse_ = 0;
    latched_encoder_ = 0;
}

double MotorModel::profile_time(Nanos t) const { return static_cast<double>(t - profile_start_) * 1e-9; }

State MotorModel::units_state(Nanos t) const {
    State s = profile_.at(profile_time(t));
    s.p -= profile_offset_;
    return s;
}

State MotorModel::command_state(Nanos t) const {
    State s = units_state(t);
    s.p = anchor_steps_ + (s.p - anchor_units_) * steps_per_unit_;
    s.v *= steps_per_unit_;
    s.a *= steps_per_unit_;
    s.j *= steps_per_unit_;
    return s;
}

void MotorModel::revise(const Profile& profile) {
    profile_ = profile;
    running_ = profile_time(now_) < profile.duration();
}

void MotorModel::set_steps_per_unit(double k) {
    if (!std::isfinite(k) || k == 0) throw InvalidArgument("MotorModel: steps_per_unit must be finite and non-zero");
    update();
    anchor_steps_ = command_state(now_).p;
    anchor_units_ = units_state(now_).p;
    steps_per_unit_ = k;
}

void MotorModel::displace(double steps) {
    update();
    physical_ += steps;
    slip_ -= steps;
}

void MotorModel::set_switch_inverted(Switch w, bool inverted) {
    update();
    const bool before = switch_level(w, physical_);
    switch_config(w).inverted = inverted;
    const bool after = switch_level(w, physical_);
    if (before != after) emit_switch(w, after);
}

void MotorModel::force_switch(Switch w, std::optional<bool> active) {
    update();
    const bool before = switch_level(w, physical_);
    forced_[switch_slot(w)] = active;
    const bool after = switch_level(w, physical_);
    if (before != after) emit_switch(w, after);
}

void MotorModel::emit_switch(Switch w, bool on) {
    using K = MotorEvent::Kind;
    const K k = w == Switch::Home ? (on ? K::HomeOn : K::HomeOff)
                : w == Switch::MinusLimit ? (on ? K::MinusLimitOn : K::MinusLimitOff)
                                          : (on ? K::PlusLimitOn : K::PlusLimitOff);
    emit(k, now_);
}

bool MotorModel::moving() const { return running_; }

void MotorModel::command(const Profile& profile, std::optional<Nanos> start) {
    command_from(profile, 0.0, start);
}

void MotorModel::command_from(const Profile& profile, double elapsed, std::optional<Nanos> start) {
    // Bounded so the time line stays inside Nanos.
    if (!(elapsed >= 0) || !(elapsed <= 1e9))
        throw InvalidArgument("MotorModel::command_from: elapsed must be within 0..1e9 s");
    Nanos t = start.value_or(now_);
    if (t < now_) t = now_;
    if (t > now_ && !in_dispatch_) advance_to(t);
    // Continuity in the drive's units: the new profile is shifted so that it
    // passes through the current pulse position at t.
    const double cp = units_state(t).p;
    profile_ = profile;
    profile_start_ = t - static_cast<Nanos>(std::llround(elapsed * 1e9));
    const double pt = profile_time(t);
    profile_offset_ = profile.at(pt).p - cp;
    running_ = pt < profile.duration();
}

void MotorModel::halt(std::optional<Nanos> at) {
    Nanos t = at.value_or(now_);
    if (t < now_) t = now_;
    if (t > now_ && !in_dispatch_) advance_to(t);
    const double pulse = units_state(t).p + pulse_offset_;
    Profile hold(State{pulse, 0, 0, 0});
    command(hold, t);
}

int MotorModel::add_listener(std::function<void(const MotorEvent&)> cb) {
    listeners_.push_back({next_listener_, std::move(cb)});
    return next_listener_++;
}

void MotorModel::remove_listener(int id) {
    for (auto& l : listeners_)
        if (l.id == id) l.cb = nullptr;  // erased later: we may be inside a dispatch
}

double MotorModel::commanded_position() const { return command_state(now_).p; }
double MotorModel::pulse_position() const { return units_state(now_).p + pulse_offset_; }
std::int64_t MotorModel::pulse_count() const { return std::llround(pulse_position()); }
std::int64_t MotorModel::encoder() const {
    return std::llround(steps_to_counts(physical_)) + static_cast<std::int64_t>(encoder_offset_);
}
double MotorModel::commanded_velocity() const { return command_state(now_).v; }
double MotorModel::pulse_velocity() const { return units_state(now_).v; }
double MotorModel::velocity() const { return stalled_ ? 0.0 : commanded_velocity(); }
double MotorModel::commanded_acceleration() const { return command_state(now_).a; }

void MotorModel::set_pulse_position(double pulses) { pulse_offset_ = pulses - units_state(now_).p; }
void MotorModel::set_encoder(std::int64_t counts) {
    encoder_offset_ = static_cast<double>(counts - std::llround(steps_to_counts(physical_)));
}

bool MotorModel::home_active() const { return switch_level(Switch::Home, physical_); }
bool MotorModel::minus_limit_active() const { return switch_level(Switch::MinusLimit, physical_); }
bool MotorModel::plus_limit_active() const { return switch_level(Switch::PlusLimit, physical_); }
bool MotorModel::minus_limit_input() const {
    return cfg_.minus_limit.active_low ? !minus_limit_active() : minus_limit_active();
}
bool MotorModel::plus_limit_input() const {
    return cfg_.plus_limit.active_low ? !plus_limit_active() : plus_limit_active();
}
bool MotorModel::index_active() const {
    if (!cfg_.index_channel) return false;
    const double rel = physical_ - cfg_.index_position;
    const double m = rel - std::floor(rel / cfg_.steps_per_rev) * cfg_.steps_per_rev;
    return m >= 0 && m < cfg_.index_width_steps;
}

void MotorModel::set_jammed(bool jammed) {
    update();
    jammed_ = jammed;
}
void MotorModel::set_pull_out_speed(double s) {
    update();
    cfg_.pull_out_speed = s;
}

void MotorModel::arm_latch() { latch_ = LatchState::Armed; }
void MotorModel::disarm_latch() { latch_ = LatchState::Off; }
void MotorModel::trigger_latch() {
    update();
    if (latch_ != LatchState::Armed) return;
    latch_ = LatchState::Triggered;
    latched_pulse_ = pulse_position();
    latched_encoder_ = encoder();
    emit(MotorEvent::Kind::Latched, now_);
}

MotorEvent MotorModel::make_event(MotorEvent::Kind k, Nanos t) const {
    const State s = command_state(t);
    return MotorEvent{k, t, physical_, units_state(t).p + pulse_offset_, encoder(),
                      s.v > 0 ? 1 : (s.v < 0 ? -1 : 0)};
}

void MotorModel::emit(MotorEvent::Kind k, Nanos t) {
    const MotorEvent e = make_event(k, t);
    const bool nested = in_dispatch_;
    in_dispatch_ = true;
    // A throwing listener must not leave the model believing it is still dispatching.
    struct Restore {
        bool& flag;
        bool value;
        ~Restore() { flag = value; }
    } restore{in_dispatch_, nested};
    for (std::size_t i = 0; i < listeners_.size(); ++i) {
        auto cb = listeners_[i].cb;  // copy: the callback may add listeners
        if (cb) cb(e);
    }
    if (nested) return;
    listeners_.erase(std::remove_if(listeners_.begin(), listeners_.end(), [](const Listener& l) { return !l.cb; }),
                         listeners_.end());
}

void MotorModel::update() { advance_to(clock_.now()); }

// Load: the rotor cannot follow a command faster than the pull-out speed or
// harder than the maximum acceleration (both in steps, a limit of 0 = none).
bool MotorModel::load_exceeded(double v_steps, double a_steps) const {
    return (cfg_.pull_out_speed > 0 && std::fabs(v_steps) > cfg_.pull_out_speed) ||
           (cfg_.max_acceleration > 0 && std::fabs(a_steps) > cfg_.max_acceleration);
}

// True when the rotor follows the command without a stall anywhere in the
// piece [from_s, to_s] (profile times) of the cubic segment `seg`, moving one
// way only.  Velocity is quadratic in time (linear when the jerk is 0), so its
// extremes are at the ends of the piece and where the acceleration crosses
// zero inside it; the acceleration is linear, so its extremes are at the
// ends.  The ends are taken from the segment itself: at its last instant the
// profile may already read the next segment.
bool MotorModel::whole_piece_is_steady(const Segment& seg, double from_s, double to_s) const {
    const State a = seg.at(from_s - seg.t0), b = seg.at(to_s - seg.t0);
    double v_lo = std::min(a.v, b.v), v_hi = std::max(a.v, b.v);
    if (seg.start.j != 0) {
        const double t_flat = -seg.start.a / seg.start.j;  // segment time where a = 0
        if (t_flat > from_s - seg.t0 && t_flat < to_s - seg.t0) {
            const double v = seg.at(t_flat).v;
            v_lo = std::min(v_lo, v);
            v_hi = std::max(v_hi, v);
        }
    }
    if (v_lo < 0 && v_hi > 0) return false;  // reverses inside: not monotone
    const double k = std::fabs(steps_per_unit_);
    return !load_exceeded(std::max(-v_lo, v_hi) * k, std::max(std::fabs(a.a), std::fabs(b.a)) * k);
}

Nanos MotorModel::profile_end() const {
    return profile_start_ + static_cast<Nanos>(std::ceil(profile_.duration() * 1e9));
}

void MotorModel::advance_to(Nanos t) {
    if (in_dispatch_) return;  // a listener's query must not re-enter the integration
    while (now_ < t) {
        Nanos next = std::min<Nanos>(t, now_ + cfg_.tick_ns);
        // At rest, or idle and held by the jam: nothing can change until the next
        // command (step_to skips the interval), so skip it all at once.
        if (!running_ && (!stalled_ || jammed_)) next = t;
        // Stalled by a jam through a move: the rotor stays where it is and only the
        // slip grows, which each step recomputes from its end, so every step before
        // the one that reaches the profile's end changes nothing.  Take them in one:
        // to that step's end, on the same tick grid, so the move ends at the instant
        // it does tick by tick.
        if (running_ && stalled_ && jammed_) {
            const Nanos left = profile_end() - now_;
            const Nanos ticks = left > cfg_.tick_ns ? (left + cfg_.tick_ns - 1) / cfg_.tick_ns : 1;
            next = ticks > (t - now_) / cfg_.tick_ns ? t : now_ + ticks * cfg_.tick_ns;
        }
        // Along a cubic piece of the profile (a cruise, a ramp, an S-curve's
        // jerk phase) whose velocity keeps its sign the motion is monotone, so
        // every switch and index edge is found exactly by bisection over any
        // span; if the load limits hold at the piece's velocity and acceleration
        // extremes no stall can start inside it either.  Take the whole piece in
        // one step: a long move on a simulated clock then costs
        // O(segments + events), not one step per tick.
        if (running_ && !stalled_ && !jammed_) {
            const double pt = profile_time(now_);
            const std::size_t k = profile_.segment_index(pt);
            if (k < profile_.segments().size()) {
                const Segment& seg = profile_.segments()[k];
                if (seg.kind == Segment::Kind::Cubic) {
                    const double end_s = seg.t0 + seg.duration;
                    const double span = std::min(end_s - pt, 1e6);  // stay well inside Nanos
                    const Nanos seg_end = std::min<Nanos>(t, now_ + static_cast<Nanos>(span * 1e9));
                    if (seg_end > next && whole_piece_is_steady(seg, pt, pt + (seg_end - now_) * 1e-9))
                        next = seg_end;
                }
            }
        }
        step_to(next);
    }
}

// Advances from now_ to at most t_end, stopping early at the first event
// (whose listeners then run with now_ at the event's time).
void MotorModel::step_to(Nanos t_end) {
    const Nanos t0 = now_;
    const Nanos profile_end = this->profile_end();
    if (!running_ && !stalled_) {
        // At rest nothing changes: skip the interval.
        now_ = t_end;
        return;
    }
    const State cs = command_state(t_end);
    // Load: does the rotor keep up over this tick?
    const bool overloaded = load_exceeded(cs.v, cs.a);
    const bool commanded_motion = running_ && cs.v != 0;
    if (!stalled_ && commanded_motion && (jammed_ || overloaded)) {
        stalled_ = true;
        slip_ = cs.p - physical_;
        now_ = t_end;
        emit(MotorEvent::Kind::Stalled, t_end);
        return;
    }
    if (stalled_) {
        if (!jammed_ && !overloaded) {
            stalled_ = false;
            slip_ = cs.p - physical_;
            now_ = t_end;
            emit(MotorEvent::Kind::Recovered, t_end);
        } else {
            slip_ = cs.p - physical_;
            now_ = t_end;
            if (running_ && t_end >= profile_end) {
                running_ = false;
                emit(MotorEvent::Kind::ProfileDone, t_end);
            }
        }
        return;
    }
    const double p_prev = physical_;
    const double p_new = cs.p - slip_;
    auto phys_at = [&](Nanos t) { return command_state(t).p - slip_; };
    // Earliest event in (t0, t_end].
    Nanos best_t = std::numeric_limits<Nanos>::max();
    MotorEvent::Kind best_k = MotorEvent::Kind::ProfileDone;
    auto consider_switch = [&](Switch w, MotorEvent::Kind on, MotorEvent::Kind off) {
        if (forced_[switch_slot(w)]) return;  // held: no edges
        const SwitchConfig& c = switch_config(w);
        auto pred = [&](const SwitchConfig&, double p) { return switch_level(w, p); };
        const bool a = pred(c, p_prev), b = pred(c, p_new);
        bool first_edge_seen = false;
        Nanos lo = t0, hi = t_end;
        bool target_state = b;
        if (a == b) {
            // A pass through a narrow home window inside one step.  Over a monotone
            // step the window is crossed iff it lies between the two positions;
            // otherwise sample the middle.
            if (!c.present) return;
            const double p_lo = std::min(p_prev, p_new), p_hi = std::max(p_prev, p_new);
            const bool inside_between = w == Switch::Home && c.lo > p_lo && c.hi < p_hi && pred(c, c.lo) != a;
            Nanos probe;
            if (inside_between) {
                // Bisection to the entering edge: the boundary nearer to p_prev.
                const double edge = p_new > p_prev ? c.lo : c.hi;
                Nanos l = t0, h = t_end;
                while (h - l > 1) {
                    const Nanos m = l + (h - l) / 2;
                    const double pm = phys_at(m);
                    if (p_new > p_prev ? pm >= edge : pm <= edge) h = m;
                    else l = m;
                }
                probe = h;
            } else {
                probe = t0 + (t_end - t0) / 2;
            }
            if (pred(c, phys_at(probe)) == a) return;
            hi = probe;
            target_state = !a;
            first_edge_seen = true;
        }
        (void)first_edge_seen;
        while (hi - lo > 1) {
            const Nanos m = lo + (hi - lo) / 2;
            if (pred(c, phys_at(m)) == target_state) hi = m;
            else lo = m;
        }
        if (hi < best_t) {
            best_t = hi;
            best_k = target_state ? on : off;
        }
    };
    consider_switch(Switch::Home, MotorEvent::Kind::HomeOn, MotorEvent::Kind::HomeOff);
    consider_switch(Switch::MinusLimit, MotorEvent::Kind::MinusLimitOn, MotorEvent::Kind::MinusLimitOff);
    consider_switch(Switch::PlusLimit, MotorEvent::Kind::PlusLimitOn, MotorEvent::Kind::PlusLimitOff);
    // Z index rising edges: entering [idx + k*rev, idx + k*rev + width).
    if (cfg_.index_channel && p_new != p_prev) {
        const double spr = cfg_.steps_per_rev;
        const bool up = p_new > p_prev;
        const double edge0 = cfg_.index_position + (up ? 0.0 : cfg_.index_width_steps);
        // Levels L = edge0 + k*spr strictly after p_prev and reached by p_new.
        const double kf = up ? std::floor((p_prev - edge0) / spr) + 1 : std::ceil((p_prev - edge0) / spr) - 1;
        const double level = edge0 + kf * spr;
        const bool hit = up ? (level > p_prev && level <= p_new) : (level < p_prev && level >= p_new);
        if (hit) {
            Nanos lo = t0, hi = t_end;
            while (hi - lo > 1) {
                const Nanos m = lo + (hi - lo) / 2;
                const double pm = phys_at(m);
                if (up ? pm >= level : pm <= level) hi = m;
                else lo = m;
            }
            if (hi < best_t) {
                best_t = hi;
                best_k = MotorEvent::Kind::IndexPulse;
            }
        }
        (void)kMaxIndexPerTick;
    }
    // An event found exactly at the profile's end comes first; the end is then
    // at t0 of the next step and must still be reported.
    const Nanos done_t = std::max(profile_end, t0);
    if (running_ && done_t <= t_end && done_t < best_t) {
        best_t = done_t;
        best_k = MotorEvent::Kind::ProfileDone;
    }
    if (best_t == std::numeric_limits<Nanos>::max()) {
        physical_ = p_new;
        now_ = t_end;
        return;
    }
    now_ = best_t;
    physical_ = phys_at(best_t);
    if (best_k == MotorEvent::Kind::ProfileDone) running_ = false;
    emit(best_k, best_t);
}

}  // namespace motorbus::motion

// A discrete-time model of an integrated motor: what every drive simulator
// runs on.
//
// Coordinates:
//  - physical position (steps): where the rotor is; switches and the Z index
//    live in this frame, fixed to the machine.
//  - commanded position (steps, physical frame): where the step generator
//    says the rotor should be, following the commanded Profile.
//  - drive units: the commanded Profile and the pulse counter count in the
//    drive's units; the rotor turns steps_per_unit steps per unit (1 by
//    default; a drive that counts encoder counts, or whose direction polarity
//    is inverted, sets it with set_steps_per_unit).
//  - pulse position = commanded units + pulse offset (PX, the drive's counter; set_pulse_position
//    moves the offset, never the rotor).
//  - encoder counts = round(physical * counts_per_rev / steps_per_rev) + encoder offset.
// The rotor follows the command exactly unless the load stalls it; a stalled
// rotor stays put while the command runs on, and recovers (with the lost steps
// as a permanent slip) once the commanded speed is back under the pull-out speed.
//
// Time: Nanos on a motorbus::Clock.  update() advances the model to
// clock.now() in ticks of MotorConfig::tick_ns; edges of switches, index and
// latch found inside a tick are refined to ~1 ns by bisection on the profile,
// and listeners see them in time order with the exact time.  A constant-
// acceleration piece of the profile that cannot stall the rotor (a cruise, a
// ramp keeping its direction, within the load limits) is taken in one step:
// its motion is monotone, so bisection finds its edges as exactly.  A listener may
// command a new profile from inside the callback; it takes effect at the
// event's time, so homing stops happen where a real drive would stop.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "motorbus/motion/profile.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::motion {

// A switch at a physical position.  Home: active for lo <= p <= hi.  Minus
// limit: active for p <= position.  Plus limit: active for p >= position.
// active_low: the electrical input reads 0 when the switch is active (a
// common factory polarity).
struct SwitchConfig {
    bool present = false;
    double lo = 0, hi = 0;  // home window / limit position (use lo for limits)
    bool active_low = true;
    // The controller's polarity setting disagrees with the wiring: it reads the
    // switch as active exactly where it is not actuated, and events follow
    // what the controller reads.
    bool inverted = false;
};

enum class Switch { Home, MinusLimit, PlusLimit };

struct MotorConfig {
    double steps_per_rev = 3200;   // 16 microsteps x 200 full steps
    double counts_per_rev = 4000;  // a 1000-line encoder, quadrature
    double index_position = 0;     // physical steps of one Z index (repeats each rev)
    double index_width_steps = 0.8;  // Z is high within [index, index + width)
    // The motor has a Z index channel.  A drive that reads none says
    // false: no IndexPulse events, whose search would otherwise end a step of the
    // integration at every revolution of a long move.
    bool index_channel = true;
    SwitchConfig home;
    SwitchConfig minus_limit;
    SwitchConfig plus_limit;
    // Load: the rotor stalls when |commanded velocity| > pull_out_speed or
    // |commanded acceleration| > max_acceleration (0 = no such limit), or
    // while the test jams it (set_jammed).
    double pull_out_speed = 0;    // steps/s
    double max_acceleration = 0;  // steps/s^2
    Nanos tick_ns = 100'000;      // integration step (100 us) where the motion may stall or reverse
};

struct MotorEvent {
    enum class Kind {
        HomeOn, HomeOff,
        MinusLimitOn, MinusLimitOff,
        PlusLimitOn, PlusLimitOff,
        IndexPulse,   // rising edge of Z
        Stalled, Recovered,
        Latched,      // latch armed and triggered: latched_* hold the capture
        ProfileDone   // the commanded profile reached its end
    };
    Kind kind;
    Nanos t;            // exact time of the event
    double physical;    // rotor position at t (steps)
    double pulse;       // pulse position at t
    std::int64_t encoder;
    int direction;      // sign of the commanded velocity at t (0 at rest)
};
// "home_on", "home_off", "minus_limit_on", ..., "index", "stalled", "recovered", "latched", "profile_done".
const char* to_string(MotorEvent::Kind k);

class MotorModel {
public:
    MotorModel(Clock& clock, MotorConfig cfg = {});

    const MotorConfig& config() const { return cfg_; }
    Clock& clock() { return clock_; }

    // Commands `profile` (positions in the pulse frame, the drive's counter)
    // starting at time `start` (default: now).  The current motion is replaced
    // from `start` on; a profile whose start position differs from the
    // current pulse position is shifted to start there (the step generator
    // cannot jump).
    void command(const Profile& profile, std::optional<Nanos> start = std::nullopt);
    // Joins `profile` `elapsed` seconds into its own time line at time `start`
    // (default now): for a planner that keeps one profile across commands and
    // splices each command into it.  Position continuity as in command().
    void command_from(const Profile& profile, double elapsed, std::optional<Nanos> start = std::nullopt);
    // Stops the step generator at time t (default now) where it is (ABORT).
    void halt(std::optional<Nanos> at = std::nullopt);
    // An on-the-fly change (new target, new speed, STOP) of the running
    // profile: `profile` must agree with the current one up to now; it keeps
    // the current time origin and position frame.
    void revise(const Profile& profile);
    bool moving() const;                 // a commanded profile is still running
    const Profile& profile() const { return profile_; }
    Nanos profile_start() const { return profile_start_; }
    Nanos profile_end() const;           // when the current profile ends (its start + duration, rounded up)
    // Time within the current profile (s) at time t.
    double profile_time(Nanos t) const;

    // Advance to clock.now() (or to t, never backwards), delivering events.
    void update();
    void advance_to(Nanos t);
    // Back to the state just after construction: the configuration it was built
    // with, at rest at position 0 (pulse, encoder, latch, switches not forced),
    // with clock().now() as its time, which may be earlier than time().  The
    // listeners stay.  For a harness that reuses one model (a fuzz target).
    void reset();
    Nanos time() const { return now_; }

    // Listeners get every event in time order; returns an id for remove_listener.
    int add_listener(std::function<void(const MotorEvent&)> cb);
    void remove_listener(int id);

    // State at the model's current time.
    double commanded_position() const;          // steps, physical frame
    double pulse_position() const;              // PX (continuous)
    std::int64_t pulse_count() const;           // PX as the drive reports it (rounded)
    double physical_position() const { return physical_; }
    std::int64_t encoder() const;               // EX
    double commanded_velocity() const;          // steps/s
    double pulse_velocity() const;              // drive units/s (the commanded profile's frame)
    double velocity() const;                    // rotor velocity, steps/s (0 while stalled)
    double commanded_acceleration() const;
    bool stalled() const { return stalled_; }
    double slip() const { return slip_; }       // commanded - physical, steps

    void set_pulse_position(double pulses);     // PX=...
    void set_encoder(std::int64_t counts);      // EX=...
    // Units bridge (see the top): takes effect now, positions stay continuous.
    void set_steps_per_unit(double steps_per_unit);
    double steps_per_unit() const { return steps_per_unit_; }
    // Moves the rotor by `steps` without pulses (a knock, a hand on the shaft).
    void displace(double steps);

    // Switches: logical (true = switch active) and electrical (after polarity).
    bool home_active() const;
    bool minus_limit_active() const;
    bool plus_limit_active() const;
    bool index_active() const;
    bool home_input() const { return cfg_.home.active_low ? !home_active() : home_active(); }
    bool minus_limit_input() const;
    bool plus_limit_input() const;
    // Run-time changes; a change of what the switch reads is an event now.
    void set_switch_inverted(Switch which, bool inverted);  // polarity setting
    void force_switch(Switch which, std::optional<bool> active);  // override (nullopt = follow position)

    // Load.
    void set_jammed(bool jammed);               // a load that blocks the rotor
    void set_pull_out_speed(double steps_per_s);

    // Latch: arm, then the next trigger (a rising edge of the latch input,
    // or trigger_latch()) captures pulse and encoder positions.
    void arm_latch();
    void disarm_latch();
    void trigger_latch();
    enum class LatchState { Off = 0, Armed = 1, Triggered = 2 };  // LTS values
    LatchState latch_state() const { return latch_; }
    double latched_pulse() const { return latched_pulse_; }
    std::int64_t latched_encoder() const { return latched_encoder_; }

    // Physical position (steps) -> encoder counts without offset.
    double steps_to_counts(double steps) const { return steps * cfg_.counts_per_rev / cfg_.steps_per_rev; }
    double counts_to_steps(double counts) const { return counts * cfg_.steps_per_rev / cfg_.counts_per_rev; }

private:
    Clock& clock_;
    MotorConfig cfg_;
    MotorConfig initial_cfg_;  // cfg_ as built, for reset()
    Profile profile_;
    Nanos profile_start_ = 0;
    double profile_offset_ = 0;  // physical = profile position - profile_offset_
    bool running_ = false;
    Nanos now_ = 0;
    double physical_ = 0;
    double slip_ = 0;
    bool stalled_ = false;
    bool jammed_ = false;
    double pulse_offset_ = 0;  // pulse = commanded + pulse_offset_
    double encoder_offset_ = 0;
    // Units bridge: physical = anchor_steps_ + (units - anchor_units_) * steps_per_unit_.
    double steps_per_unit_ = 1, anchor_steps_ = 0, anchor_units_ = 0;
    std::optional<bool> forced_[3];
    LatchState latch_ = LatchState::Off;
    double latched_pulse_ = 0;
    std::int64_t latched_encoder_ = 0;
    struct Listener { int id; std::function<void(const MotorEvent&)> cb; };
    std::vector<Listener> listeners_;
    int next_listener_ = 1;
    bool in_dispatch_ = false;

    State units_state(Nanos t) const;    // drive units, without the pulse offset
    State command_state(Nanos t) const;  // physical frame
    const SwitchConfig& switch_config(Switch w) const;
    SwitchConfig& switch_config(Switch w);
    bool switch_level(Switch w, double physical) const;  // what the controller reads
    void step_to(Nanos t);
    bool load_exceeded(double v_steps, double a_steps) const;
    bool whole_piece_is_steady(const Segment& seg, double from_s, double to_s) const;
    void emit(MotorEvent::Kind k, Nanos t);
    void emit_switch(Switch w, bool on);
    MotorEvent make_event(MotorEvent::Kind k, Nanos t) const;
};

}  // namespace motorbus::motion

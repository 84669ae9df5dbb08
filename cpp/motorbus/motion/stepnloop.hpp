// StepNLoop: a stepper drive's closed-loop position verification (000 manual,
// "StepNLoop Closed Loop Control", Tables 7.5-7.7, Objects 2001h-2003h,
// Table 8.14) as a reusable state machine.  It holds no clock and moves no
// motor: the owner reports what happens (a move starts, a delta sample, a
// move ends) and carries out the returned decision.  A host can wrap any
// open-loop drive that has an encoder in it the same way.
//
// Delta δ = target - actual, in encoder counts.
// Table 7.7, implemented literally:
//   moving: |δ| <= SLT or SLT < |δ| <= SLE -> keep monitoring;
//           |δ| > SLE -> Stall Error (10), stop now.
//   idle / end of move:
//           |δ| <= SLT (after a correction: <= SLM) -> in position;
//           SLT < |δ| <= SLE -> correction move (attempt += 1);
//           |δ| > SLE -> Correction Range Error (8), stop;
//           a correction needed when attempts == SLA -> Correction Attempt Error (9).
// After a correction the idle tolerance SLM applies ("if the remaining error is
// greater than this value, an additional correction will be performed using
// idle current"), and such corrections are flagged idle_current.
// Limit hit while moving -> Limit Error (11).  Errors stay until clear()
// (CLR/CLRS).  A new move in an error state is refused ("?State Error").
#pragma once
#include <cstdint>
#include <optional>
#include <string_view>

namespace motorbus::motion {

enum class SnlStatus : std::uint16_t {  // Tables 7.6 and 8.14
    Idle = 0,
    Moving = 1,
    Correcting = 2,
    Stopping = 3,
    Aborting = 4,
    Jogging = 5,
    Homing = 6,
    ZHoming = 7,
    RangeError = 8,
    AttemptError = 9,
    StallError = 10,
    LimitError = 11,
    Disabled = 12,
    LimitHoming = 13
};
const char* snl_status_name(SnlStatus s);  // the GUI's words: "IDLE", "ERR-STALL", ...

struct SnlConfig {
    bool enabled = true;            // SL
    std::uint32_t tolerance = 20;   // SLT (ASCII default 20; CANopen 2001h:03 default 10)
    std::uint32_t error_range = 1000;  // SLE
    std::uint32_t max_attempts = 10;   // SLA
    std::uint32_t idle_tolerance = 5;  // SLM
    // Step/encoder ratio (SLR): pulses per encoder count; factory 3200/4000.
    double ratio = 0.8;
    static SnlConfig ascii_defaults() { return {}; }        // Table 7.11
    static SnlConfig canopen_defaults() {                   // Table 8.11
        SnlConfig c;
        c.tolerance = 10;
        return c;
    }
};

// What kind of motion is starting (selects the status shown while it runs).
enum class SnlActivity { Move, Jog, Home, ZHome, LimitHome, Stop, Abort };
// "move", "jog", "home", "zhome", "limit_home", "stop", "abort".
const char* to_string(SnlActivity a);
std::optional<SnlActivity> snl_activity_from_name(std::string_view name);  // nullopt if unknown

enum class SnlAction {
    None,       // keep going
    InPosition, // move complete, no correction needed
    Correct,    // command a correction move of `correction` counts (relative)
    StopNow     // error: stop the motor immediately; status() says which
};
struct SnlDecision {
    SnlAction action = SnlAction::None;
    double correction = 0;     // counts, relative (target - actual)
    bool idle_current = false; // correction performed with idle current (SLM stage)
};

class StepNLoop {
public:
    explicit StepNLoop(SnlConfig cfg = {});
    void configure(const SnlConfig& cfg);  // SL=0 -> status Disabled (12)
    const SnlConfig& config() const { return cfg_; }

    // A move of the given kind starts.  Returns false (and does nothing) in an
    // error state: the drive answers "?State Error".
    bool begin(SnlActivity what);
    // A delta sample while the motor moves (Table 7.7, "motor is moving").
    SnlDecision monitor(double delta_counts);
    // The commanded move (or a correction move) finished with this delta.
    SnlDecision motion_done(double delta_counts);
    // A delta sample while idle (load pushed the motor): Table 7.7 idle column.
    SnlDecision idle_check(double delta_counts);
    // A limit switch stopped the motion.
    void limit_hit();
    // Homing/jog/stop finished without target verification (status -> Idle).
    void end_without_verification();
    // CLR/CLRS: clear an error state, reset attempts.
    void clear();

    SnlStatus status() const { return status_; }
    bool in_error() const;
    std::uint32_t attempts() const { return attempts_; }

    // Unit conversions using the ratio: speeds/positions in EPS <-> PPS.
    double counts_to_pulses(double counts) const { return counts * cfg_.ratio; }
    double pulses_to_counts(double pulses) const { return pulses / cfg_.ratio; }

private:
    SnlConfig cfg_;
    SnlStatus status_ = SnlStatus::Idle;
    std::uint32_t attempts_ = 0;
    bool after_correction_ = false;
    bool verifying_ = false;  // the running motion is a target move that ends in verification
    SnlDecision error(SnlStatus s);
};

}  // namespace motorbus::motion

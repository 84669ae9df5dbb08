// The Arcus DMX-CAN's motion profile, in the manual's units and rules
// (000 manual: "Motion Profile", "On-The-Fly" sections, Appendix A).
//
// Units: positions in pulses (or encoder counts when StepNLoop is on: the
// caller passes whatever the drive counts in), speeds in pulses/s (PPS),
// ACC/DEC in ms (time from LSPD to HSPD).  Every move starts by jumping from
// 0 to LSPD, ramps between LSPD and HSPD, and ends by ramping down to LSPD and
// then stopping with a jump from LSPD to 0, as a stepper does.
//
// Time inside a move is seconds since the move started (double); a simulator
// converts its clock's Nanos.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/profile.hpp"

namespace motorbus::arcus {
// A vendor profile model is built from the generic motion pieces.
using namespace motorbus::motion;

// One row of Table A.0.  HSPD in (hspd_low, hspd_high] belongs to the window
// (the first row also includes HSPD = 1).  The manual prints the bounds in
// "K"; the model reads K as 1000.
struct ArcusSpeedWindow {
    int number;            // 1..9 (row number)
    int sspdm_first;       // SSPDM value(s) that select this window (row 1: 0 and 1)
    int sspdm_last;
    double hspd_low;       // PPS
    double hspd_high;      // PPS
    double min_lspd;       // PPS
    double min_acc_ms;     // ms
    double delta;          // δ of Figure A.0: max ACC = (HSPD - LSPD)/δ * 1000 ms
};
const std::array<ArcusSpeedWindow, 9>& arcus_speed_windows();
// The window an HSPD (PPS) falls in.  With StepNLoop on, pass
// hspd_eps * snl_ratio (the manual: EPS = PPS / ratio).  Throws LimitExceeded
// above 6 000 000 PPS or below 1.
const ArcusSpeedWindow& arcus_window_for_hspd(double hspd_pps);
// The window an SSPDM value (0..9) selects; throws LimitExceeded otherwise.
const ArcusSpeedWindow& arcus_window_for_sspdm(int sspdm);
// Max ACC/DEC (ms) for the given HSPD/LSPD: ((HSPD - LSPD) / δ) x 1000.
double arcus_max_acc_ms(double hspd_pps, double lspd_pps);

// Largest distance a single X move may cover (incremental or absolute).
inline constexpr std::int64_t kArcusMaxMoveDistance = 262143;

struct ProfileParams {
    // The manual gives no factory HSPD/LSPD/ACC; these are the model's defaults.
    double hspd = 1000;     // PPS
    double lspd = 100;      // PPS
    double acc_ms = 300;    // ms, LSPD -> HSPD
    double dec_ms = 300;    // ms, HSPD -> LSPD; used only when edec
    bool edec = false;      // EDEC=1: use DEC for deceleration, else ACC
    bool scv = false;       // SCV=1: S-curve ramps (same ramp times)
    double snl_ratio = 1.0; // pulses per encoder count when speeds are in EPS (StepNLoop on), else 1
};

// The parameters the drive actually uses after Appendix A's automatic
// adjustment, and what was adjusted (one human-readable line per change).
struct Effective {
    ProfileParams params;
    const ArcusSpeedWindow* window = nullptr;
    std::vector<std::string> adjustments;
    double accel() const;  // PPS/s (average over the ramp for S-curve)
    double decel() const;
};
// Applies Table A.0 / Figure A.0: ACC and DEC are clamped into
// [min ACC, max ACC] of HSPD's window (min wins when the window leaves no
// room), LSPD is raised to the window's minimum and lowered to HSPD.  Throws
// LimitExceeded for HSPD outside 1..6 000 000 PPS or non-positive ACC/DEC.
Effective arcus_effective(const ProfileParams& requested);
// Strict variant for tools that want to refuse instead of adjust: throws
// LimitExceeded naming the first parameter outside its window's range.
void arcus_check_strict(const ProfileParams& requested);

// Answers the drive gives to on-the-fly commands (Table 11.1).
enum class MotionReply {
    Ok,
    MotorNotMoving,   // "?Motor is not moving": T while no target move runs
    Moving,           // "?Moving": a move command while outputting pulses
    ScvOn,            // "?SCV ON": SSPD with S-curve enabled
    SpeedOutOfRange,  // "?Speed out of range": SSPD outside the SSPDM window
    BadSspd,          // "?Bad SSPD Command": SSPD not usable (not moving, <= 0)
    MoveTooFar        // a move above 262143 pulses (the drive refuses it)
};
const char* arcus_reply_text(MotionReply r);  // the drive's reply string, "" for Ok

// Motor status bits 0..2 of MST during a move.
enum class Phase { Idle, Accel, Const, Decel };

// The profile of one DMX-CAN axis across moves and on-the-fly changes.
// Position continuity: every command starts from the state at its time.
class Motion {
public:
    explicit Motion(ProfileParams params = {}, int sspdm = 0);

    // Parameters for the next move (the drive ignores changes mid-move except
    // through SSPD).  Returns the effective (adjusted) set.
    const Effective& set_params(const ProfileParams& params);
    void set_sspdm(int sspdm);  // 0..9; throws LimitExceeded otherwise
    const Effective& effective() const { return eff_; }
    int sspdm() const { return sspdm_; }

    // X: a target move from rest at `position`, as a new profile starting at
    // t = 0.  Refuses (MoveTooFar) a distance above 262143.  The simulator
    // answers "?Moving" itself when moving(t) is true.
    MotionReply move(double position, double target);
    // J+/J-: jog from rest at `position`.
    MotionReply jog(double position, int direction);
    // T at time t (seconds since the move started): change the target of the
    // running target move.  If the new target cannot be reached without
    // overshoot, or was already passed, the motor decelerates to LSPD, stops,
    // and moves back (the manual: "it will reverse direction").
    MotionReply change_target(double t, double new_target);
    // SSPD at time t: change the high speed of the running move (target move
    // or jog) to new_hspd using the move's ACC/DEC.  Checks SCV and the SSPDM
    // window.
    MotionReply change_speed(double t, double new_hspd);
    // STOP: decelerate to LSPD, then stop.  ABORT: stop now.
    void stop(double t);
    void abort(double t);

    const Profile& profile() const { return profile_; }
    bool moving(double t) const;  // a move is running at t (t in [0, duration))
    bool target_move() const { return target_move_; }
    double target() const { return target_; }
    Phase phase(double t) const;

private:
    Effective eff_;
    int sspdm_ = 0;
    Profile profile_;
    bool target_move_ = false;
    bool jogging_ = false;
    int jog_dir_ = 0;
    double target_ = 0;
    double hspd_now_ = 0;  // high speed of the running move (after SSPD)
};

// The core of Motion, exposed for reuse: a stepper profile from `start`
// (p, signed v) to `target` with start/stop speed `lspd` (magnitude), cruise
// `hspd`, ramps `accel`/`decel` (PPS/s).  Ends with a jump LSPD -> 0.
Profile arcus_stepper_profile(const State& start, double target, double hspd, double lspd,
                              double accel, double decel, RampShape shape);

}  // namespace motorbus::arcus

// DMX-CAN homing on the MotorModel.
//
// DMX-CAN (000 manual, "Homing", Figures 7.2-7.6):
//   H+/H-   run at HSPD toward home; on the home edge the position counter is
//           reset to 0 and the motor decelerates to LSPD and stops (the final
//           position is not 0).  RZ=1: then return to 0.
//   HL+/HL- as H, then reverse at LSPD to find home again, continue through
//           it at HSPD and on past it by HCA, come back at LSPD, and on the
//           home edge reset to 0 and stop immediately.  RZ=1: return to 0
//           (already there).
//   The inputs are levels: a switch already active at the start is found at once.
//   L+/L-   run toward the limit; stop immediately on it; move back by LCA at
//           HSPD; that point is zero.
//   Z+/Z-   run at LSPD until the Z index; stop, position = 0.
//   ZH+/ZH- run toward home; on home decelerate to LSPD, then search Z at
//           LSPD; on Z stop, position = 0.
//   A limit met in the search direction before the home switch ends homing
//   with a limit error (the DMX-CAN latches a limit error; it does not
//   reverse).
//
#pragma once
#include <optional>

#include "motorbus/drives/arcus/profile.hpp"
#include "motorbus/motion/homing.hpp"
#include "motorbus/motion/motor_model.hpp"

namespace motorbus::arcus {

struct HomingOptions {
    double hca = 0;      // HCA, pulses
    double lca = 1000;   // LCA, pulses (factory 1000)
    bool rz = false;     // RZ: return to zero after H/HL
    // Reset the encoder counter wherever the position counter is reset (a
    // drive that keeps PX and EX aligned, as the DMX-CAN simulator does).
    bool zero_encoder = false;
    // The CANopen front end's home offset (607Ch, manual 000 §8 6098h): once
    // the routine has found its zero, move at LSPD to this position (in the
    // frame just zeroed, units of the motor's position) and make that point
    // zero.  Methods 7/11 "change direction and move by the home offset",
    // 33/34 "continue moving by the home offset amount", 19/20 "move back by
    // the Home Offset amount" from the home edge.  nullopt = the routine's end.
    std::optional<double> final_target{};
    // Limit homing backs off at LSPD (CANopen 17/18: "ramp down to the zero
    // position speed and move away by the home offset"); the ASCII L at HSPD.
    bool backoff_at_lspd = false;
};

class Homing {
public:
    enum class Method { H, HL, L, Z, ZH };
    using Options = HomingOptions;
    Homing(MotorModel& motor, ProfileParams params, Options opt = {});
    ~Homing();
    Homing(const Homing&) = delete;
    Homing& operator=(const Homing&) = delete;

    // Starts homing now (motor.time()); direction +1 or -1.
    void start(Method m, int direction);
    void abort();  // ABORT: stop now
    void stop();   // STOP: decelerate to LSPD, then stop
    HomingResult result() const { return result_; }
    bool running() const { return result_ == HomingResult::Running; }
    Method method() const { return method_; }
    // The StepNLoop status to show while it runs: Homing, Z-Homing or Limit homing.
    int snl_status() const;

private:
    MotorModel& motor_;
    ProfileParams params_;
    Options opt_;
    Method method_ = Method::H;
    int dir_ = 1;
    int stage_ = 0;
    HomingResult result_ = HomingResult::Done;
    int listener_ = 0;
    void on_event(const MotorEvent& e);
    void run(double target_offset, double speed_pps, bool from_current);
    void run_at(double target, double speed);  // start, cruise and stop at one speed
    static constexpr int kFinalStage = 100;    // the move to final_target
    void jog(int direction, double hspd);
    void decel_stop(Nanos t);
    void finish(HomingResult r);
    void set_zero();
    void zero_and_decelerate(const MotorEvent& e);
    void stop_at_zero();
};

}  // namespace motorbus::arcus

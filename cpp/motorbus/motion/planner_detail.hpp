// Internal building blocks shared by the planners and the drive models.
#pragma once
#include "motorbus/motion/planner.hpp"

namespace motorbus::motion::detail {

double sgn(double x);
// Appends a velocity ramp of dv over `duration` (a = 0 at both ends for SCurve).
void append_ramp(Profile& prof, double dv, double duration, RampShape shape);
// Stepper-style trapezoid: jump from rest to v_start, ramp (accel) to at most
// vmax, cruise, ramp (decel) down to v_end, stop with a jump to 0.  With
// v_start = v_end = 0 it is the plain time-optimal trapezoid.  Handles a start
// velocity away from the target or too fast to stop (stop, then come back).
Profile stepper_profile(const State& start, double target, double vmax, double accel, double decel,
                        double v_start, double v_end, RampShape shape);

}  // namespace motorbus::motion::detail

#include "motorbus/drives/pmc007/profile.hpp"

#include <cmath>
#include <limits>

#include "motorbus/motion/planner_detail.hpp"

namespace motorbus::pmc007 {

double gear_acceleration(int gear) {
    if (gear < 0) throw LimitExceeded("acceleration gear (6008h/6009h)", gear, 0, "gears are 0..8");
    if (gear > 8) throw LimitExceeded("acceleration gear (6008h/6009h)", gear, 8, "gears are 0..8");
    return gear == 0 ? std::numeric_limits<double>::infinity() : kGearAcceleration[static_cast<std::size_t>(gear)];
}

int microsteps(int setting) {
    if (setting == 0) return 1;
    for (int m = 2; m <= 256; m *= 2)
        if (setting == m) return m;
    throw LimitExceeded("microstepping (600Ah)", setting, setting > 256 ? 256 : 0, "0, 2, 4, 8, 16, 32, 64, 128 or 256");
}

double convert_position(double position, int from_setting, int to_setting) {
    return position * microsteps(to_setting) / microsteps(from_setting);
}

void ProfileParams::validate() const {
    (void)gear_acceleration(accel_gear);
    (void)gear_acceleration(decel_gear);
    (void)microsteps(microstepping);
    if (start_speed < 0 || start_speed > 65535) throw LimitExceeded("start speed (6006h)", start_speed, start_speed < 0 ? 0 : 65535);
    if (stop_speed < 0 || stop_speed > 65535) throw LimitExceeded("stop speed (6007h)", stop_speed, stop_speed < 0 ? 0 : 65535);
    if (!(speed > 0) || !std::isfinite(speed)) throw LimitExceeded("speed", speed, 0, "must be positive");
}

Profile position_profile(const State& start, double target, const ProfileParams& p) {
    p.validate();
    const double a = gear_acceleration(p.accel_gear), d = gear_acceleration(p.decel_gear);
    // Start/stop speeds above the running speed collapse onto it.
    const double vs = std::min(p.start_speed, p.speed), ve = std::min(p.stop_speed, p.speed);
    return detail::stepper_profile(State{start.p, start.v, 0, 0}, target, p.speed, a, d, vs, ve, RampShape::SCurve);
}

Profile speed_profile(const State& start, double speed, const ProfileParams& p, double hold) {
    p.validate();
    const double a = gear_acceleration(p.accel_gear), d = gear_acceleration(p.decel_gear);
    Profile prof(State{start.p, start.v, 0, 0});
    double v = start.v;
    if (v * speed < 0) {  // reverse: slow down to the stop speed, stop, restart
        const double ve = std::min(p.stop_speed, std::fabs(v));
        if (std::isfinite(d)) detail::append_ramp(prof, -detail::sgn(v) * (std::fabs(v) - ve), (std::fabs(v) - ve) / d, RampShape::SCurve);
        v = 0;
        prof.finish(prof.final_state().p, 0);
    }
    if (v == 0 && speed != 0) {
        v = std::copysign(std::min(p.start_speed, std::fabs(speed)), speed);
        prof.finish(prof.final_state().p, v);
    }
    const double dv = speed - v;
    const bool up = std::fabs(speed) > std::fabs(v);
    const double rate = up ? a : d;
    if (dv != 0 && std::isfinite(rate)) detail::append_ramp(prof, dv, std::fabs(dv) / rate, RampShape::SCurve);
    prof.finish(prof.final_state().p, speed);
    if (hold > 0) prof.append_jump(hold, speed, 0, 0);
    prof.finish(prof.final_state().p, speed);
    return prof;
}

}  // namespace motorbus::pmc007

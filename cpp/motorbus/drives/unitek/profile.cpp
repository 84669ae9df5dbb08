#include "motorbus/drives/unitek/profile.hpp"

#include <algorithm>
#include <cmath>

#include "motorbus/motion/planner_detail.hpp"

namespace motorbus::unitek {

void RampParams::validate() const {
    if (!(n_max_rpm > 0) || !std::isfinite(n_max_rpm)) throw LimitExceeded("N max", n_max_rpm, 0, "must be positive");
    for (auto [name, v] : {std::pair{"ACC ramp (0x35)", acc_ramp_ms}, std::pair{"DEC ramp (0xED)", dec_ramp_ms}}) {
        if (v < 0 || !std::isfinite(v)) throw LimitExceeded(name, v, 0, "ms");
        if (v > 32767) throw LimitExceeded(name, v, 32767, "ms (16-bit register)");
    }
}

double num_to_counts_per_s(double num, const RampParams& p) {
    return num / kFullScale * p.n_max_rpm / 60.0 * kCountsPerRev;
}

Profile speed_profile(const State& start, double speed_num, const RampParams& p, double hold) {
    p.validate();
    if (!std::isfinite(speed_num)) throw InvalidArgument("UNITEK speed command must be finite");
    speed_num = std::clamp(speed_num, -kFullScale, kFullScale);
    const double full = num_to_counts_per_s(kFullScale, p);
    const double vt = num_to_counts_per_s(speed_num, p);
    Profile prof(State{start.p, start.v, 0, 0});
    double v = start.v;
    auto ramp = [&](double from, double to, double ms) {
        const double dur = ms / 1000.0 * std::fabs(to - from) / full;
        if (dur > 0) detail::append_ramp(prof, to - from, dur, RampShape::Trapezoid);
        prof.finish(prof.final_state().p, to);
    };
    if (v * vt < 0) {
        ramp(v, 0, p.dec_ramp_ms);
        v = 0;
    }
    ramp(v, vt, std::fabs(vt) >= std::fabs(v) ? p.acc_ramp_ms : p.dec_ramp_ms);
    if (hold > 0) prof.append_jump(hold, vt, 0, 0);
    prof.finish(prof.final_state().p, vt);
    return prof;
}

}  // namespace motorbus::unitek

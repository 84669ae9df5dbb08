// Hostile numbers for the planners and the drive profile models: every one of
// these must be refused with a typed error or planned into a usable profile.
#pragma once
#include <cmath>
#include <iterator>
#include <limits>

#include "motorbus/errors.hpp"
#include "motorbus/motion/profile.hpp"

namespace motorbus::test {
using motorbus::motion::Profile;
inline const double kInf = std::numeric_limits<double>::infinity();
inline const double kNan = std::numeric_limits<double>::quiet_NaN();
inline const double kValues[] = {0.0, -0.0, 1e-300, -1e-300, 1e-9, 1.0, -1.0, 1e9, -1e9, 1e300, -1e300, kInf, -kInf, kNan};

template <class F>
void survives(F&& f) {
    try {
        Profile p = f();
        // A profile that is returned must be usable and finite where it was asked to be.
        (void)p.at(p.duration() / 2);
        (void)p.max_abs_velocity();
    } catch (const motorbus::InvalidArgument&) {
        // typed refusal: fine
    }
}
}  // namespace motorbus::test

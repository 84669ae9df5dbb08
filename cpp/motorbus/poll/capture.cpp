#include "motorbus/poll/capture.hpp"

#include <limits>

#include "motorbus/errors.hpp"

namespace motorbus::poll {

CaptureSlots::CaptureSlots(std::size_t values, Nanos max_age_ns)
    : value_(values, std::numeric_limits<double>::quiet_NaN()), arrived_(values, -1), v_copy_(values),
      t_copy_(values), max_age_(max_age_ns) {
    if (values == 0) throw InvalidArgument("capture source: at least one value");
    if (max_age_ns <= 0) throw InvalidArgument("capture source: max age must be > 0");
}

void CaptureSlots::set(std::size_t first, const double* v, std::size_t n, Nanos t) {
    std::lock_guard lock(m_);
    for (std::size_t i = 0; i < n && first + i < value_.size(); ++i) {
        value_[first + i] = v[i];
        arrived_[first + i] = t;
    }
}

void CaptureSlots::read(double* out, Nanos now) {
    {
        std::lock_guard lock(m_);  // a copy of a few numbers: the receive thread waits nanoseconds
        for (std::size_t i = 0; i < value_.size(); ++i) {
            v_copy_[i] = value_[i];
            t_copy_[i] = arrived_[i];
        }
    }
    if (fill(t_copy_.data(), v_copy_.data(), value_.size(), now, max_age_, out)) count_stale();
}

bool CaptureSlots::fill(const Nanos* t, const double* v, std::size_t n, Nanos now, Nanos max_age, double* out) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Nanos oldest = std::numeric_limits<Nanos>::max();
    bool missing = false;
    for (std::size_t i = 0; i < n; ++i) {
        if (t[i] < 0) {
            missing = true;
            out[1 + i] = nan;
        } else {
            out[1 + i] = v[i];
            if (t[i] < oldest) oldest = t[i];
        }
    }
    out[0] = missing ? nan : static_cast<double>(oldest);
    return missing || now - oldest > max_age;
}

}  // namespace motorbus::poll

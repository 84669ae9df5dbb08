#include "motorbus/runtime/clock.hpp"

#include "motorbus/runtime/interrupt.hpp"

namespace motorbus {

bool RealClock::sleep_until(Nanos t) {
    std::unique_lock lock(mutex_);
    auto deadline = std::chrono::steady_clock::time_point(std::chrono::nanoseconds(t));
    // Interruptible: a Python caller (sleep_until from the bindings) gets Ctrl-C.
    interruptible_wait_until(cv_, lock, deadline, [&] { return cancelled_; });
    return !cancelled_;
}

void RealClock::cancel() {
    {
        std::lock_guard lock(mutex_);
        cancelled_ = true;
    }
    cv_.notify_all();
}

Nanos SimClock::now() const {
    std::lock_guard lock(mutex_);
    return now_;
}

bool SimClock::sleep_until(Nanos t) {
    std::unique_lock lock(mutex_);
    interruptible_wait_until(cv_, lock, std::chrono::steady_clock::time_point::max(),
                             [&] { return cancelled_ || now_ >= t; });
    return !cancelled_;
}

void SimClock::cancel() {
    {
        std::lock_guard lock(mutex_);
        cancelled_ = true;
    }
    cv_.notify_all();
}

void SimClock::advance(Nanos dt) {
    {
        std::lock_guard lock(mutex_);
        if (dt > 0) now_ += dt;
    }
    cv_.notify_all();
}

void SimClock::set(Nanos t) {
    {
        std::lock_guard lock(mutex_);
        if (t > now_) now_ = t;
    }
    cv_.notify_all();
}

}  // namespace motorbus

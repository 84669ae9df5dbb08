#include "motorbus/runtime/clock.hpp"

namespace motorbus {

bool RealClock::sleep_until(Nanos t) {
    std::unique_lock lock(mutex_);
    auto deadline = std::chrono::steady_clock::time_point(std::chrono::nanoseconds(t));
    cv_.wait_until(lock, deadline, [&] { return cancelled_; });
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
    cv_.wait(lock, [&] { return cancelled_ || now_ >= t; });
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

// Clocks: real time, or simulated time that a test advances by hand.
//
// Simulators and pollers take a Clock& so that a 10 s move can be tested in
// microseconds and deterministically: the test calls SimClock::advance() and
// every sleeper whose deadline has passed wakes up.
#pragma once
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace motorbus {

using Nanos = std::int64_t;  // nanoseconds on some clock's time line

// Monotonic nanoseconds (std::chrono::steady_clock), the timestamp of every Frame.
inline Nanos monotonic_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

class Clock {
public:
    virtual ~Clock() = default;
    virtual Nanos now() const = 0;
    // Blocks until now() >= t.  Returns false if interrupted by cancel().
    virtual bool sleep_until(Nanos t) = 0;
    // Wakes every sleeper (used on shutdown); they return false.
    virtual void cancel() = 0;
    virtual bool simulated() const = 0;
};

class RealClock final : public Clock {
public:
    Nanos now() const override { return monotonic_ns(); }
    bool sleep_until(Nanos t) override;
    void cancel() override;
    bool simulated() const override { return false; }

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    bool cancelled_ = false;
};

// Time stands still until advance()/set() moves it.
class SimClock final : public Clock {
public:
    explicit SimClock(Nanos start = 0) : now_(start) {}
    Nanos now() const override;
    bool sleep_until(Nanos t) override;
    void cancel() override;
    bool simulated() const override { return true; }

    void advance(Nanos dt);
    void set(Nanos t);  // never moves backwards: an earlier t is ignored

private:
    mutable std::mutex mutex_;
    std::condition_variable cv_;
    Nanos now_;
    bool cancelled_ = false;
};

}  // namespace motorbus

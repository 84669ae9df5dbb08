// A stoppable timer thread for periodic services (CANopen heartbeat, EMCY
// inhibit, PDO timers; a simulated drive's cyclic transmissions).  `tick(now)` does the work due at `now` and returns the next
// deadline (-1 = none).  It waits on its own condition variable rather than
// Clock::sleep_until, because cancelling a shared clock would stop everyone.
// On a simulated clock it re-checks every `sim_poll` of real time.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include "motorbus/runtime/clock.hpp"

namespace motorbus {

class TimerThread {
public:
    using Tick = std::function<Nanos(Nanos now)>;
    TimerThread() = default;
    ~TimerThread() { stop(); }
    TimerThread(const TimerThread&) = delete;
    TimerThread& operator=(const TimerThread&) = delete;

    void start(Clock& clock, Tick tick, Nanos idle_period = 10'000'000) {
        stop();
        {
            std::lock_guard l(m_);
            stop_ = false;
        }
        thread_ = std::thread([this, &clock, tick = std::move(tick), idle_period] {
            std::unique_lock l(m_);
            while (!stop_) {
                l.unlock();
                const Nanos now = clock.now();
                Nanos next = -1;
                try {
                    next = tick(now);
                } catch (const std::exception&) {
                    // A closed or saturated bus (or a failing user callback)
                    // must not end the process from a service thread: count
                    // it and try again at the idle period, as a real node
                    // keeps producing through a disconnected cable.
                    failures_.fetch_add(1, std::memory_order_relaxed);
                }
                l.lock();
                if (stop_) break;
                if (next < 0 || next - now > idle_period) next = now + idle_period;
                if (clock.simulated()) {
                    cv_.wait_for(l, std::chrono::milliseconds(1), [&] { return stop_ || poke_; });
                } else {
                    auto until = std::chrono::steady_clock::time_point(
                        std::chrono::nanoseconds(next - now) +
                        std::chrono::steady_clock::now().time_since_epoch());
                    cv_.wait_until(l, until, [&] { return stop_ || poke_; });
                }
                poke_ = false;
            }
        });
    }
    // Makes the thread re-evaluate its deadline now (after a configuration change).
    void poke() {
        {
            std::lock_guard l(m_);
            poke_ = true;
        }
        cv_.notify_all();
    }
    void stop() {
        {
            std::lock_guard l(m_);
            stop_ = true;
        }
        cv_.notify_all();
        if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
    }
    bool running() const { return thread_.joinable(); }
    // Ticks that threw (and were retried at the idle period).
    std::uint64_t failures() const { return failures_.load(std::memory_order_relaxed); }

private:
    std::mutex m_;
    std::condition_variable cv_;
    bool stop_ = false;
    bool poke_ = false;
    std::atomic<std::uint64_t> failures_{0};
    std::thread thread_;
};

}  // namespace motorbus

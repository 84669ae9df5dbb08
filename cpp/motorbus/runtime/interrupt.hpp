// Interruptible waits.  A caller installs a check on its thread with
// InterruptScope (the Python bindings install one that raises KeyboardInterrupt
// for Ctrl-C); while one is installed, the long waits of the core wake at least
// every kInterruptSlice and run it with none of their own locks held.  The check
// throws to abandon the wait: the operation then ends as after a timeout, with
// its partial state dropped.  Without a check installed, waits are unchanged.
#pragma once
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace motorbus {

inline constexpr std::chrono::milliseconds kInterruptSlice{50};
using InterruptCheck = void (*)();

namespace detail {
inline thread_local InterruptCheck interrupt_check = nullptr;
}

class InterruptScope {
public:
    explicit InterruptScope(InterruptCheck check) : prev_(detail::interrupt_check) { detail::interrupt_check = check; }
    ~InterruptScope() { detail::interrupt_check = prev_; }
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;

private:
    InterruptCheck prev_;
};

inline bool interruptible() { return detail::interrupt_check != nullptr; }
inline void interruption_point() {
    if (auto check = detail::interrupt_check) check();
}

// std::this_thread::sleep_for with interruption points.
template <class Rep, class Period>
void interruptible_sleep_for(std::chrono::duration<Rep, Period> d) {
    if (!interruptible()) {
        std::this_thread::sleep_for(d);
        return;
    }
    using SC = std::chrono::steady_clock;
    const auto until = SC::now() + std::chrono::duration_cast<SC::duration>(d);
    for (;;) {
        const auto now = SC::now();
        if (now >= until) return;
        std::this_thread::sleep_for(std::min<SC::duration>(until - now, kInterruptSlice));
        interruption_point();
    }
}

// cv.wait_until(lock, deadline, pred) with interruption points; `lock` is
// released while the check runs.
template <class Clock, class Dur, class Pred>
bool interruptible_wait_until(std::condition_variable& cv, std::unique_lock<std::mutex>& lock,
                              std::chrono::time_point<Clock, Dur> deadline, Pred pred) {
    if (!interruptible()) return cv.wait_until(lock, deadline, pred);
    for (;;) {
        const auto slice_end = Clock::now() + kInterruptSlice;
        if (deadline <= slice_end) return cv.wait_until(lock, deadline, pred);
        if (cv.wait_until(lock, slice_end, pred)) return true;
        lock.unlock();
        try {
            interruption_point();
        } catch (...) {
            lock.lock();
            throw;
        }
        lock.lock();
    }
}

template <class Rep, class Period, class Pred>
bool interruptible_wait_for(std::condition_variable& cv, std::unique_lock<std::mutex>& lock,
                            std::chrono::duration<Rep, Period> timeout, Pred pred) {
    // A poll (timeout 0) only checks: a timed wait that expires at once still costs a syscall.
    if (timeout <= timeout.zero()) return pred();
    if (!interruptible()) return cv.wait_for(lock, timeout, pred);
    return interruptible_wait_until(cv, lock, std::chrono::steady_clock::now() +
                                                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(timeout),
                                    pred);
}

}  // namespace motorbus

#include "motorbus/poll/schedule.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cerrno>

#include "motorbus/errors.hpp"

namespace motorbus::poll {

Schedule::Schedule(Nanos t0, Nanos period) : t0_(t0), period_(period) {
    if (period <= 0) throw InvalidArgument("poll period: must be > 0");
}

Schedule::Next Schedule::after(std::uint64_t k, Nanos now) const {
    const Nanos next = deadline(k + 1);
    if (now < next) return {k + 1, 0, false};
    // The latest deadline already passed: sample it now; the ones before it are gone.
    const auto latest = index_at(now);
    return {latest, latest - (k + 1), true};
}

bool sleep_until(Nanos deadline, Nanos spin_ns, const std::atomic<bool>& stop) {
    constexpr Nanos kSlice = 20'000'000;
    const Nanos wake = deadline - std::max<Nanos>(spin_ns, 0);
    for (;;) {
        if (stop.load(std::memory_order_relaxed)) return false;
        const Nanos now = monotonic_ns();
        if (now >= wake) break;
        const Nanos until = std::min(wake, now + kSlice);
        timespec ts{static_cast<time_t>(until / 1'000'000'000), static_cast<long>(until % 1'000'000'000)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
        }
    }
    while (monotonic_ns() < deadline) {
        if (stop.load(std::memory_order_relaxed)) return false;
    }
    return true;
}

bool try_realtime(int priority) {
    sched_param p{};
    p.sched_priority = priority;
    return pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
}

}  // namespace motorbus::poll

// The poll schedule: absolute deadlines t0 + k * period on CLOCK_MONOTONIC, so
// a slow sample never shifts the ones after it (no drift), and the bookkeeping
// of samples that ran past their period.
//
//   late:   a sample whose reads finished after the next deadline (the next
//           sample then starts at once, behind time);
//   missed: a deadline that passed entirely while a late sample ran, or while
//           the thread woke up late (preempted past a whole period): nothing
//           was read for it (the poll thread writes a NaN row, so it shows).
//
// So a sample of deadline k always starts in [deadline(k), deadline(k + 1)):
// timestamps increase strictly across sampled and missed rows.
#pragma once
#include <atomic>
#include <cstdint>

#include "motorbus/runtime/clock.hpp"

namespace motorbus::poll {

class Schedule {
public:
    Schedule(Nanos t0, Nanos period);  // InvalidArgument if period <= 0

    Nanos t0() const { return t0_; }
    Nanos period() const { return period_; }
    Nanos deadline(std::uint64_t k) const { return t0_ + static_cast<Nanos>(k) * period_; }

    struct Next {
        std::uint64_t index;    // the deadline to sample next
        std::uint64_t skipped;  // deadlines between the finished one and `index`: missed
        bool late;              // the finished sample ran past deadline(k + 1)
    };
    // The latest deadline at or before `now` (0 before t0).
    std::uint64_t index_at(Nanos now) const {
        return now < t0_ ? 0 : static_cast<std::uint64_t>((now - t0_) / period_);
    }
    // Sample k finished at `now`: which deadline comes next.
    Next after(std::uint64_t k, Nanos now) const;

private:
    Nanos t0_, period_;
};

// Sleeps until `deadline` (monotonic ns) with clock_nanosleep(TIMER_ABSTIME),
// waking `spin_ns` early and busy-waiting the rest (tighter wake-up at normal
// priority, at the price of a core for those µs).  Sleeps in slices of at most
// 20 ms so `stop` ends the wait promptly.  Returns false if stopped.
bool sleep_until(Nanos deadline, Nanos spin_ns, const std::atomic<bool>& stop);

// Tries SCHED_FIFO at `priority` for the calling thread; false (and the thread
// unchanged) when not permitted.
bool try_realtime(int priority);

}  // namespace motorbus::poll

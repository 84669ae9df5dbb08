// PollGroup: one thread that reads a list of sources (the drives on one line
// or bus) on an absolute schedule and writes timestamped rows into a
// SampleRing, without the GIL and without allocating per sample.
//
//   PollGroup g({source_a, source_b}, {.period_ns = 1'000'000});
//   g.start();  ...  g.take(...);  g.stats();  g.stop();
//
// Row layout: the deadline's index k, t (monotonic ns at the start of the
// sample's reads), then the columns of each source in order.  A deadline that passed while a late sample
// ran gets a row of NaN with t = the deadline: missed samples show in the data.
// A source that throws (LinkDown, TimeoutError...) ends the thread; stats()
// holds the error's type and text.  stop() waits at most for the read in
// progress (bounded by the transport's timeout) and never throws.
#pragma once
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/poll/ring.hpp"
#include "motorbus/poll/schedule.hpp"
#include "motorbus/poll/source.hpp"
#include "motorbus/poll/stats.hpp"
#include "motorbus/runtime/completions.hpp"

namespace motorbus::poll {

struct PollOptions {
    Nanos period_ns = 1'000'000;       // 1 kHz
    std::size_t capacity = 1 << 16;    // ring rows
    Nanos spin_ns = 0;                 // busy-wait this long before each deadline
    bool realtime = false;             // try SCHED_FIFO
    int priority = 50;                 // its priority when granted
    Nanos start_ns = 0;                // deadline 0 (monotonic ns); 0 = one period after start()
};

class PollGroup {
public:
    PollGroup(std::vector<std::shared_ptr<Source>> sources, PollOptions options = {});
    ~PollGroup();  // stops
    PollGroup(const PollGroup&) = delete;
    PollGroup& operator=(const PollGroup&) = delete;

    void start();  // InvalidArgument if started before
    void stop();   // idempotent

    std::size_t columns() const { return ring_.columns(); }
    const PollOptions& options() const { return options_; }
    SampleRing& ring() { return ring_; }
    PollStats stats() const;
    bool running() const { return running_.load(); }

    // For an event loop (Poller.chunks): returns false and, once the ring holds
    // at least `rows` unread rows or the thread has ended, pushes `token` to
    // `done` with the unread row count (an int64) -- from the poll thread,
    // without the GIL, once per request; returns true (nothing armed) when that
    // is already so.  A new request replaces the previous one.
    bool notify_when(std::size_t rows, std::shared_ptr<Completions> done, std::uint64_t token);
    // Withdraws the request: false when there was none (it already fired).
    bool cancel_notify();

private:
    void run();
    void fail(const char* type, const std::string& what);

    std::vector<std::shared_ptr<Source>> sources_;
    PollOptions options_;
    SampleRing ring_;
    std::atomic<bool> stop_{false};
    std::atomic<bool> running_{false};
    bool started_ = false;
    std::thread thread_;
    mutable std::mutex stats_mutex_;  // guards the fields below (the thread updates them per sample)
    Histogram period_error_, wake_latency_, read_time_;
    std::uint64_t samples_ = 0, missed_ = 0, late_ = 0;
    bool realtime_ = false;
    std::string error_, error_type_;

    void check_notify();
    std::mutex notify_mutex_;
    std::atomic<bool> notify_armed_{false};  // read per sample without the lock
    std::shared_ptr<Completions> notify_done_;
    std::uint64_t notify_token_ = 0;
    std::size_t notify_rows_ = 0;
};

}  // namespace motorbus::poll

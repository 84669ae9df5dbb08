// Timing statistics of one poll group: a histogram of 1 µs bins (fixed
// memory, nothing allocated per sample) for the period error |Δt - period|
// between consecutive samples and for the wake-up latency (sample start -
// its deadline), with exact maxima; percentiles read from the bins.
#pragma once
#include <array>
#include <string>
#include <cstdint>
#include <vector>

#include "motorbus/runtime/clock.hpp"

namespace motorbus::poll {

class Histogram {
public:
    static constexpr Nanos kBin = 1'000;             // 1 µs
    static constexpr std::size_t kBins = 20'000;     // 20 ms; above lands in the last bin

    Histogram() : bins_(kBins + 1, 0) {}
    void add(Nanos value);                           // negative values count as 0
    std::uint64_t count() const { return count_; }
    Nanos max() const { return max_; }
    // The upper edge of the bin holding the q-quantile (0 <= q <= 1); 0 if empty.
    Nanos quantile(double q) const;

private:
    std::vector<std::uint64_t> bins_;
    std::uint64_t count_ = 0;
    Nanos max_ = 0;
};

// A snapshot for readers.
struct PollStats {
    std::uint64_t samples = 0;   // samples read (rows with values)
    std::uint64_t missed = 0;    // deadlines skipped entirely (NaN rows)
    std::uint64_t late = 0;      // samples whose reads ran past the next deadline
    std::uint64_t overflowed = 0;  // rows the reader lost to a full ring
    std::uint64_t stale = 0;     // capture sources' reads that found old or no pushed data (Source::stale)
    Nanos period_ns = 0;
    Nanos period_error_p50 = 0, period_error_p99 = 0, period_error_max = 0;
    Nanos wake_latency_p50 = 0, wake_latency_p99 = 0, wake_latency_max = 0;
    Nanos read_time_p50 = 0, read_time_p99 = 0, read_time_max = 0;  // time the reads of a sample took
    bool running = false;
    bool realtime = false;       // SCHED_FIFO was asked for and granted
    std::string error;           // why the group stopped on its own ("" if it did not)
    std::string error_type;      // "LinkDown", "TimeoutError", ...
};

}  // namespace motorbus::poll

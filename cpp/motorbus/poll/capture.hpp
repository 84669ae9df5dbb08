// What capture sources share (sources whose drive pushes its data: CANopen
// TPDOs, a register protocol's cyclic transmissions): the latest pushed values, written by the
// bus receive thread and taken by the poll thread under a short lock, and the
// row a capture source writes:
//
//   out[0]      when the oldest of the values arrived (monotonic ns; NaN if
//               one never arrived): the Poller shows it as <axis>.t, so users
//               see the data's age, not when the poll thread looked;
//   out[1..n]   the values (NaN for one that never arrived).
//
// A read whose oldest value is older than max_age (or missing) counts as
// stale: a push that stopped is counted in the group's stats, never repeated
// silently.
#pragma once
#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "motorbus/runtime/clock.hpp"

namespace motorbus::poll {

class CaptureSlots {
public:
    CaptureSlots(std::size_t values, Nanos max_age_ns);

    std::size_t values() const { return value_.size(); }
    std::size_t columns() const { return value_.size() + 1; }  // + the arrival time
    Nanos max_age_ns() const { return max_age_; }

    // From the receive thread: values [first, first + n) arrived at t.
    void set(std::size_t first, const double* v, std::size_t n, Nanos t);
    // From the poll thread: writes the row described above; counts a stale read.
    void read(double* out, Nanos now);
    std::uint64_t stale() const { return stale_.load(std::memory_order_relaxed); }

    // The row from values already taken elsewhere (t[i] < 0: never arrived);
    // returns true when it is stale.
    static bool fill(const Nanos* t, const double* v, std::size_t n, Nanos now, Nanos max_age, double* out);
    void count_stale() { stale_.fetch_add(1, std::memory_order_relaxed); }

private:
    std::mutex m_;
    std::vector<double> value_;
    std::vector<Nanos> arrived_;  // -1: never
    std::vector<double> v_copy_;
    std::vector<Nanos> t_copy_;
    Nanos max_age_;
    std::atomic<std::uint64_t> stale_{0};
};

}  // namespace motorbus::poll

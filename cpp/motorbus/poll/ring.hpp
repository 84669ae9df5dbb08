// SampleRing: the preallocated store one poll thread writes and a reader
// (Python, without the GIL) drains.  Each row is one sample: the index k of
// its deadline (t0 + k * period), an int64 timestamp (monotonic ns) and
// `columns` float64 values.
//
// Single writer, single reader, guarded by a mutex held only for a memcpy of
// the rows: the writer never allocates, never waits for Python.  When the
// reader falls more than `capacity` rows behind, the oldest unread rows are
// overwritten and counted in overflowed(): never silently lost.
#pragma once
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

namespace motorbus::poll {

class SampleRing {
public:
    SampleRing(std::size_t capacity, std::size_t columns);  // InvalidArgument if either is 0

    std::size_t capacity() const { return capacity_; }
    std::size_t columns() const { return columns_; }

    // Appends one row (values: columns() doubles).
    void push(std::int64_t index, std::int64_t t_ns, const double* values);

    // Copies the rows written since the last take() into index_out / t_out /
    // v_out (sized by the caller from available()), oldest first; returns how many.
    std::size_t take(std::int64_t* index_out, std::int64_t* t_out, double* v_out, std::size_t max_rows);
    std::size_t available() const;
    std::uint64_t written() const;     // rows pushed since construction
    std::uint64_t overflowed() const;  // rows overwritten before take() saw them

private:
    const std::size_t capacity_, columns_;
    mutable std::mutex mutex_;
    std::vector<std::int64_t> index_, t_;
    std::vector<double> v_;
    std::uint64_t head_ = 0;  // rows ever written
    std::uint64_t tail_ = 0;  // rows ever taken or overwritten
    std::uint64_t overflowed_ = 0;
};

}  // namespace motorbus::poll

#include "motorbus/poll/ring.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "motorbus/errors.hpp"

namespace motorbus::poll {

SampleRing::SampleRing(std::size_t capacity, std::size_t columns) : capacity_(capacity), columns_(columns) {
    if (capacity == 0) throw InvalidArgument("poll ring capacity: at least 1 sample");
    if (columns == 0) throw InvalidArgument("poll ring: at least 1 column");
    index_.resize(capacity);
    t_.resize(capacity);
    v_.resize(capacity * columns);
}

void SampleRing::push(std::int64_t index, std::int64_t t_ns, const double* values) {
    std::lock_guard lock(mutex_);
    const std::size_t slot = static_cast<std::size_t>(head_ % capacity_);
    index_[slot] = index;
    t_[slot] = t_ns;
    std::memcpy(&v_[slot * columns_], values, columns_ * sizeof(double));
    ++head_;
    if (head_ - tail_ > capacity_) {  // the reader is a full ring behind: the oldest row is gone
        ++tail_;
        ++overflowed_;
    }
}

std::size_t SampleRing::take(std::int64_t* index_out, std::int64_t* t_out, double* v_out, std::size_t max_rows) {
    std::lock_guard lock(mutex_);
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(head_ - tail_, max_rows));
    for (std::size_t done = 0; done < n;) {
        // Copy in at most two runs: up to the end of the storage, then from its start.
        const std::size_t slot = static_cast<std::size_t>((tail_ + done) % capacity_);
        const std::size_t run = std::min(n - done, capacity_ - slot);
        std::memcpy(index_out + done, &index_[slot], run * sizeof(std::int64_t));
        std::memcpy(t_out + done, &t_[slot], run * sizeof(std::int64_t));
        std::memcpy(v_out + done * columns_, &v_[slot * columns_], run * columns_ * sizeof(double));
        done += run;
    }
    tail_ += n;
    return n;
}

std::size_t SampleRing::available() const {
    std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(head_ - tail_);
}

std::uint64_t SampleRing::written() const {
    std::lock_guard lock(mutex_);
    return head_;
}

std::uint64_t SampleRing::overflowed() const {
    std::lock_guard lock(mutex_);
    return overflowed_;
}

}  // namespace motorbus::poll

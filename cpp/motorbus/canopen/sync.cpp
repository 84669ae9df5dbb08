#include "motorbus/canopen/sync.hpp"

#include <algorithm>
#include <cmath>

#include <pthread.h>
#include <sched.h>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

can::Frame encode_sync(std::optional<std::uint8_t> counter, std::uint32_t cob_id) {
    if (cob_id > can::kMaxStandardId) throw InvalidArgument("SYNC COB-ID must be 11-bit");
    can::Frame f;
    f.id = cob_id;
    if (counter) {
        if (*counter == 0 || *counter > 240) throw InvalidArgument("SYNC counter must be 1-240");
        f.len = 1;
        f.data[0] = *counter;
    }
    return f;
}

SyncDecode decode_sync(const can::Frame& f, SyncMessage& out, std::uint8_t overflow,
                       std::uint32_t cob_id) {
    out = {};
    if (f.id != cob_id || f.extended || f.rtr || f.is_fd()) return SyncDecode::NotSync;
    if (f.len > 1) return SyncDecode::BadLength;
    if (overflow >= 2 && f.len != 1) return SyncDecode::BadLength;  // a counter was expected
    if (overflow < 2 && f.len != 0) return SyncDecode::BadLength;
    if (f.len == 1) {
        if (f.data[0] == 0 || f.data[0] > overflow) return SyncDecode::BadCounter;
        out.counter = f.data[0];
    }
    return SyncDecode::Ok;
}

SyncProducer::SyncProducer(can::Bus& bus, std::chrono::nanoseconds period, std::uint8_t overflow,
                           std::uint32_t cob_id)
    : bus_(bus), period_(period), overflow_(overflow), cob_id_(cob_id) {
    if (period.count() <= 0) throw InvalidArgument("SYNC period must be > 0");
    if (overflow == 1 || overflow > 240) throw InvalidArgument("SYNC counter overflow must be 0 or 2-240");
    if (cob_id > can::kMaxStandardId) throw InvalidArgument("SYNC COB-ID must be 11-bit");
    errors_ns_.reserve(kWindow);
}

SyncProducer::~SyncProducer() { stop(); }

void SyncProducer::start(bool realtime) {
    if (running_.exchange(true)) return;
    {
        std::lock_guard l(stop_m_);
        stop_ = false;
    }
    reset_stats();
    rt_granted_.store(false);
    thread_ = std::thread([this] { run(); });
    if (realtime) {
        sched_param sp{};
        sp.sched_priority = 50;
        rt_granted_.store(pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &sp) == 0);
    }
}

void SyncProducer::stop() {
    {
        std::lock_guard l(stop_m_);
        stop_ = true;
    }
    stop_cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    running_.store(false);
}

void SyncProducer::run() {
    using clock = std::chrono::steady_clock;
    std::uint8_t counter = 0;
    auto next = clock::now();
    clock::time_point prev{};
    bool have_prev = false;
    while (true) {
        {
            // Sleep most of the way, then spin the last stretch: the condition
            // variable's wake-up latency would otherwise be the jitter floor.
            std::unique_lock l(stop_m_);
            const auto coarse = next - std::chrono::microseconds(200);
            if (stop_cv_.wait_until(l, coarse, [&] { return stop_; })) return;
        }
        while (clock::now() < next) {
        }
        std::optional<std::uint8_t> c;
        if (overflow_ >= 2) {
            counter = counter >= overflow_ ? 1 : static_cast<std::uint8_t>(counter + 1);
            c = counter;
        }
        const auto t = clock::now();
        try {
            bus_.send(encode_sync(c, cob_id_), period_);
            sent_.fetch_add(1, std::memory_order_relaxed);
        } catch (const ClosedError&) {
            return;
        } catch (const Error&) {
            errors_.fetch_add(1, std::memory_order_relaxed);
        }
        if (have_prev) {
            const std::int64_t err = (t - prev - period_).count();
            std::lock_guard l(stats_m_);
            if (errors_ns_.size() < kWindow)
                errors_ns_.push_back(err);
            else
                errors_ns_[ring_pos_] = err;
            ring_pos_ = (ring_pos_ + 1) % kWindow;
            if (count_ == 0 || err < min_) min_ = err;
            if (count_ == 0 || err > max_) max_ = err;
            sum_ += static_cast<double>(err);
            ++count_;
        }
        prev = t;
        have_prev = true;
        next += period_;
        // After a long stall keep the grid but skip the missed slots.
        const auto now = clock::now();
        if (next < now) next += ((now - next) / period_ + 1) * period_;
    }
}

JitterStats SyncProducer::jitter() const {
    std::lock_guard l(stats_m_);
    JitterStats s;
    s.count = count_;
    if (count_ == 0) return s;
    s.min_ns = static_cast<double>(min_);
    s.max_ns = static_cast<double>(max_);
    s.mean_ns = sum_ / static_cast<double>(count_);
    std::vector<std::int64_t> abs(errors_ns_.size());
    std::transform(errors_ns_.begin(), errors_ns_.end(), abs.begin(),
                   [](std::int64_t v) { return v < 0 ? -v : v; });
    auto k = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(abs.size()))) - 1;
    std::nth_element(abs.begin(), abs.begin() + static_cast<std::ptrdiff_t>(k), abs.end());
    s.p99_abs_ns = static_cast<double>(abs[k]);
    s.max_abs_ns = std::max(std::abs(s.min_ns), std::abs(s.max_ns));
    return s;
}

void SyncProducer::reset_stats() {
    std::lock_guard l(stats_m_);
    errors_ns_.clear();
    ring_pos_ = 0;
    count_ = 0;
    sum_ = 0;
    min_ = max_ = 0;
}

}  // namespace motorbus::canopen

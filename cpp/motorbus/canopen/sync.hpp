// SYNC (COB-ID 0x080 by default): codec and a producer running on its own
// C++ thread that measures how far each SYNC was from its ideal time.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"

namespace motorbus::canopen {

constexpr std::uint32_t kSyncCobId = 0x080;

struct SyncMessage {
    std::optional<std::uint8_t> counter;  // present when DLC == 1
};

// counter: nullopt = DLC 0; else 1-240 (0x1019 range).
can::Frame encode_sync(std::optional<std::uint8_t> counter = std::nullopt,
                       std::uint32_t cob_id = kSyncCobId);

enum class SyncDecode { Ok, NotSync, BadLength, BadCounter };
// `overflow` is 0x1019 (0 = no counter expected).  BadLength: DLC not in {0,1}
// (N16, EMCY 0x8240); BadCounter: counter 0 or > overflow (ignored, but the SYNC
// itself still counts).
SyncDecode decode_sync(const can::Frame& f, SyncMessage& out, std::uint8_t overflow = 0,
                       std::uint32_t cob_id = kSyncCobId);

struct JitterStats {
    std::uint64_t count = 0;   // periods measured
    double min_ns = 0, mean_ns = 0, max_ns = 0, p99_abs_ns = 0;  // period error (actual - nominal)
    double max_abs_ns = 0;
};

class SyncProducer {
public:
    // counter_overflow: 0x1019 (0 = no counter byte, else 2-240).
    SyncProducer(can::Bus& bus, std::chrono::nanoseconds period, std::uint8_t counter_overflow = 0,
                 std::uint32_t cob_id = kSyncCobId);
    ~SyncProducer();
    SyncProducer(const SyncProducer&) = delete;
    SyncProducer& operator=(const SyncProducer&) = delete;

    // realtime: ask for SCHED_FIFO (priority 50) for the producer thread; when
    // the process may not (no CAP_SYS_NICE), it runs at normal priority and
    // realtime_granted() says so.
    void start(bool realtime = false);
    void stop();
    bool running() const { return running_.load(); }
    bool realtime_granted() const { return rt_granted_.load(); }
    std::uint64_t sent() const { return sent_.load(); }
    std::uint64_t send_errors() const { return errors_.load(); }
    // Statistics of the period error over the sends since start() (or reset).
    JitterStats jitter() const;
    void reset_stats();

private:
    void run();
    can::Bus& bus_;
    std::chrono::nanoseconds period_;
    std::uint8_t overflow_;
    std::uint32_t cob_id_;
    std::thread thread_;
    std::atomic<bool> running_{false};
    std::mutex stop_m_;
    std::condition_variable stop_cv_;
    bool stop_ = false;
    mutable std::mutex stats_m_;
    std::vector<std::int64_t> errors_ns_;  // ring of the last kWindow errors
    std::size_t ring_pos_ = 0;
    std::uint64_t count_ = 0;
    double sum_ = 0;
    std::int64_t min_ = 0, max_ = 0;
    std::atomic<std::uint64_t> sent_{0}, errors_{0};
    std::atomic<bool> rt_granted_{false};
    static constexpr std::size_t kWindow = 65536;
};

}  // namespace motorbus::canopen

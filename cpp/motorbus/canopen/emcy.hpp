// EMCY (COB-ID 0x080 + node): codec, a consumer keeping a bounded history and
// the active error set per node, and a producer that honours the inhibit time
// (0x1015) with a bounded queue.
#pragma once
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/runtime/timer_thread.hpp"
#include "motorbus/runtime/callback_slot.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::canopen {

constexpr std::uint32_t kEmcyBase = 0x080;

struct EmcyMessage {
    std::uint8_t node_id = 0;
    std::uint16_t code = 0;            // emergency error code (EEC)
    std::uint8_t error_register = 0;   // 0x1001 as sent, passed through (E7)
    std::array<std::uint8_t, 5> manufacturer{};  // MSEF
    bool short_frame = false;          // DLC < 8: missing bytes are zero (E1)
    Nanos timestamp_ns = 0;
    bool is_reset() const { return code == 0x0000; }
};

// Human text for the EEC class (CiA 301 table 21): "current", "voltage", ...
std::string emcy_code_text(std::uint16_t code);

can::Frame encode_emcy(std::uint8_t node_id, std::uint16_t code, std::uint8_t error_register,
                       std::array<std::uint8_t, 5> manufacturer = {});
// nullopt for frames that are not EMCY: id outside 0x081-0x0FF, RTR, extended,
// FD / len > 8 (E2).  DLC < 8 is parsed with zero fill and short_frame (E1);
// DLC 0 carries no code at all and is rejected.
std::optional<EmcyMessage> decode_emcy(const can::Frame& f);

class EmcyConsumer {
public:
    explicit EmcyConsumer(can::Bus& bus, std::size_t history_per_node = 32);
    ~EmcyConsumer();
    EmcyConsumer(const EmcyConsumer&) = delete;
    EmcyConsumer& operator=(const EmcyConsumer&) = delete;

    // Newest last; at most history_per_node entries per node.
    std::vector<EmcyMessage> history(std::uint8_t node) const;
    // Codes currently active (cleared by EEC 0x0000, E3).
    std::vector<std::uint16_t> active(std::uint8_t node) const;
    void clear(std::uint8_t node);
    // The oldest EMCY from `node` (0 = any) not yet returned by wait(), waiting
    // for one up to `timeout`; nullopt on timeout.  Unclaimed messages are kept
    // in a bounded queue (256, oldest dropped), so report-then-wait never races.
    std::optional<EmcyMessage> wait(std::uint8_t node, std::chrono::nanoseconds timeout);

    CallbackSlot<void(const EmcyMessage&)> on_emcy;
    std::uint64_t ignored_frames() const { return ignored_.load(); }
    std::uint64_t received() const { return received_.load(); }

private:
    void on_frame(const can::Frame& f);
    struct NodeLog {
        std::deque<EmcyMessage> history;
        std::vector<std::uint16_t> active;
    };
    can::Bus& bus_;
    std::size_t cap_;
    mutable std::mutex mutex_;
    std::condition_variable cv_;
    std::array<NodeLog, 128> nodes_;
    std::deque<EmcyMessage> unclaimed_;
    std::atomic<std::uint64_t> ignored_{0}, received_{0};
    can::SubscriptionId sub_ = 0;
};

class EmcyProducer {
public:
    // inhibit in units of 100 us (as 0x1015).  The queue holds at most
    // `queue_limit` messages; when full the oldest pending one is dropped and
    // counted (an error storm must not grow memory, E6).
    EmcyProducer(can::Bus& bus, Clock& clock, std::uint8_t node_id, std::uint16_t inhibit_100us = 0,
                 std::size_t queue_limit = 16);
    ~EmcyProducer();
    EmcyProducer(const EmcyProducer&) = delete;
    EmcyProducer& operator=(const EmcyProducer&) = delete;

    // Sends now if the inhibit time has passed, else queues.  Returns true when sent now.
    bool report(std::uint16_t code, std::uint8_t error_register,
                std::array<std::uint8_t, 5> manufacturer = {});
    void set_inhibit(std::uint16_t inhibit_100us);
    // Sends one queued message when the inhibit time allows; returns the next
    // due time (-1 when the queue is empty).
    Nanos process(Nanos now);
    Clock& clock() const { return clock_; }  // the one process(now) is meant to run on
    void start();
    void stop();

    std::size_t pending() const;
    std::uint64_t sent() const { return sent_.load(); }
    std::uint64_t dropped() const { return dropped_.load(); }

private:
    can::Bus& bus_;
    Clock& clock_;
    std::uint8_t node_;
    mutable std::mutex mutex_;
    Nanos inhibit_ns_;
    Nanos last_sent_ = -1;
    std::size_t limit_;
    std::deque<can::Frame> queue_;
    std::atomic<std::uint64_t> sent_{0}, dropped_{0};
    TimerThread timer_;
};

}  // namespace motorbus::canopen

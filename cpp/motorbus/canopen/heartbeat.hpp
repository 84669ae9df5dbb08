// Heartbeat / boot-up (COB-ID 0x700 + node, one state byte): the codec, a
// consumer with per-node timeouts (node lost / back / reset events) and a
// producer.  Timers run on a motorbus::Clock and are advanced by process(now),
// so a test on a SimClock is deterministic; start() runs them on a thread.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/nmt.hpp"
#include "motorbus/runtime/timer_thread.hpp"
#include "motorbus/runtime/callback_slot.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::canopen {

constexpr std::uint32_t kHeartbeatBase = 0x700;

struct HeartbeatMessage {
    std::uint8_t node_id;
    std::uint8_t raw_state;  // as received
    NodeState state;          // Unknown for bytes outside {0, 4, 5, 0x7F} (N7)
    bool is_boot_up() const { return raw_state == 0; }
};

can::Frame encode_heartbeat(std::uint8_t node_id, NodeState state);
// nullopt unless id is 0x701-0x77F, not RTR, DLC == 1 (N6).
std::optional<HeartbeatMessage> decode_heartbeat(const can::Frame& f);

// One entry of 0x1016 (consumer heartbeat time): bits 16-23 node, 0-15 ms.
struct ConsumerEntry {
    std::uint8_t node_id;
    std::uint16_t time_ms;
};
// Decodes a 0x1016 sub-entry; nullopt when the entry is unused: time 0, node 0
// or > 127, or reserved bits 24-31 set (N13: never armed on 0x780-0x7FF).
std::optional<ConsumerEntry> decode_consumer_entry(std::uint32_t v);
// Abort code (0 = accept) for writing `value` to 0x1016:`sub` given the other
// entries (index 0 = sub 1).  A duplicate node with non-zero time gives
// 0x06040043 (N12); reserved bits give 0x06090030 (N13).
std::uint32_t validate_consumer_entry(const std::vector<std::uint32_t>& entries, std::size_t sub,
                                      std::uint32_t value);

enum class HeartbeatEvent {
    Started,       // first heartbeat after monitoring began (or after lost)
    Lost,          // no heartbeat for the consumer time (EMCY 0x8130 territory)
    Back,          // heartbeat again after Lost
    Reset,         // boot-up message: the node restarted
    StateChanged,  // reported state changed
    UnknownState,  // a state byte outside the valid set (N7)
};
const char* to_string(HeartbeatEvent e);

struct NodeHealth {
    std::uint8_t node_id = 0;
    NodeState state = NodeState::Unknown;
    std::uint8_t raw_state = 0xFF;
    bool alive = false;   // heard within the consumer time
    bool lost = false;    // timed out and not heard since
    Nanos last_seen = 0;  // clock time of the last heartbeat
    std::uint64_t heartbeats = 0;
    std::uint64_t boot_ups = 0;
    std::uint64_t timeouts = 0;
};

class HeartbeatConsumer {
public:
    HeartbeatConsumer(can::Bus& bus, Clock& clock);
    ~HeartbeatConsumer();
    HeartbeatConsumer(const HeartbeatConsumer&) = delete;
    HeartbeatConsumer& operator=(const HeartbeatConsumer&) = delete;

    // Monitors `node` (1-127) with `timeout` (> 0).  Monitoring starts at the
    // first heartbeat (CiA 301), so a node never heard is not reported lost.
    void monitor(std::uint8_t node, std::chrono::nanoseconds timeout);
    void forget(std::uint8_t node);
    NodeHealth health(std::uint8_t node) const;

    // Checks deadlines at clock time `now`; fires Lost for overdue nodes.
    // Returns the earliest pending deadline (or -1).
    Nanos process(Nanos now);
    Clock& clock() const { return clock_; }  // the one process(now) is meant to run on
    // Runs process() on a thread until stop()/destruction.
    void start();
    void stop();

    // Called on the bus thread (events from frames) or the timer thread (Lost).
    CallbackSlot<void(std::uint8_t node, HeartbeatEvent ev, NodeState state)> on_event;

    std::uint64_t ignored_frames() const { return ignored_.load(); }

private:
    void on_frame(const can::Frame& f);
    struct Node {
        bool monitored = false;
        Nanos timeout = 0;
        Nanos deadline = -1;  // -1 = not armed
        NodeHealth h;
    };
    can::Bus& bus_;
    Clock& clock_;
    mutable std::mutex mutex_;
    std::array<Node, 128> nodes_{};
    // The monitored node ids, so a deadline check visits those, not all 127.
    std::vector<std::uint8_t> watched_;
    std::atomic<std::uint64_t> ignored_{0};
    can::SubscriptionId sub_ = 0;
    TimerThread timer_;
};

// The shortest heartbeat period a producer accepts (0x1017 counts in ms; a
// shorter one would flood the bus).  0 = off.
inline constexpr std::chrono::nanoseconds kMinHeartbeatPeriod = std::chrono::milliseconds(1);

class HeartbeatProducer {
public:
    // Sends 0x700+node with state() every `period`; a period of 0 disables it.
    // Other periods below kMinHeartbeatPeriod (1 ms) are InvalidArgument.
    HeartbeatProducer(can::Bus& bus, Clock& clock, std::uint8_t node_id,
                      std::chrono::nanoseconds period, std::function<NodeState()> state);
    ~HeartbeatProducer();
    HeartbeatProducer(const HeartbeatProducer&) = delete;
    HeartbeatProducer& operator=(const HeartbeatProducer&) = delete;

    void send_boot_up();
    void set_period(std::chrono::nanoseconds period);
    // Sends when due at `now`; returns the next due time (-1 when disabled).
    Nanos process(Nanos now);
    Clock& clock() const { return clock_; }  // the one process(now) is meant to run on
    void start();
    void stop();
    std::uint64_t sent() const { return sent_.load(); }
    // Heartbeats the bus refused (closed, full, link down) while start()ed.
    std::uint64_t send_failures() const { return timer_.failures(); }

private:
    static void check_period(std::chrono::nanoseconds period);
    can::Bus& bus_;
    Clock& clock_;
    std::uint8_t node_;
    std::mutex mutex_;
    Nanos period_;
    Nanos next_ = -1;
    std::function<NodeState()> state_;
    std::atomic<std::uint64_t> sent_{0};
    TimerThread timer_;
};

}  // namespace motorbus::canopen

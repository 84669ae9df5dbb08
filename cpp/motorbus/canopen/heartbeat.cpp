#include "motorbus/canopen/heartbeat.hpp"

#include <algorithm>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

can::Frame encode_heartbeat(std::uint8_t node_id, NodeState state) {
    if (node_id == 0 || node_id > kMaxNodeId)
        throw InvalidArgument("heartbeat node id " + std::to_string(node_id) + " is outside 1-127");
    if (state == NodeState::Unknown) throw InvalidArgument("heartbeat state: UNKNOWN cannot be sent");
    can::Frame f;
    f.id = kHeartbeatBase + node_id;
    f.len = 1;
    f.data[0] = static_cast<std::uint8_t>(state);
    return f;
}

std::optional<HeartbeatMessage> decode_heartbeat(const can::Frame& f) {
    if (f.extended || f.rtr || f.len != 1) return std::nullopt;  // N6 (RTR = node guarding)
    if (f.id <= kHeartbeatBase || f.id > kHeartbeatBase + kMaxNodeId) return std::nullopt;
    // Bit 7 is only a toggle in node-guarding replies; in a heartbeat it is
    // reserved, so 0x85 is UNKNOWN rather than "operational" (N7).
    const std::uint8_t raw = f.data[0];
    return HeartbeatMessage{static_cast<std::uint8_t>(f.id - kHeartbeatBase), raw,
                            node_state_from_byte(raw)};
}

std::optional<ConsumerEntry> decode_consumer_entry(std::uint32_t v) {
    if (v >> 24) return std::nullopt;
    const auto node = static_cast<std::uint8_t>((v >> 16) & 0xFF);
    const auto ms = static_cast<std::uint16_t>(v & 0xFFFF);
    if (node == 0 || node > kMaxNodeId || ms == 0) return std::nullopt;
    return ConsumerEntry{node, ms};
}

std::uint32_t validate_consumer_entry(const std::vector<std::uint32_t>& entries, std::size_t sub,
                                      std::uint32_t value) {
    if (value >> 24) return 0x06090030;  // N13: reserved bits
    auto e = decode_consumer_entry(value);
    if (!e) return 0;  // unused entries are fine
    for (std::size_t i = 0; i < entries.size(); ++i) {
        if (i + 1 == sub) continue;
        if (auto o = decode_consumer_entry(entries[i]); o && o->node_id == e->node_id)
            return 0x06040043;  // N12
    }
    return 0;
}

const char* to_string(HeartbeatEvent e) {
    switch (e) {
        case HeartbeatEvent::Started: return "started";
        case HeartbeatEvent::Lost: return "lost";
        case HeartbeatEvent::Back: return "back";
        case HeartbeatEvent::Reset: return "reset";
        case HeartbeatEvent::StateChanged: return "state-changed";
        case HeartbeatEvent::UnknownState: return "unknown-state";
    }
    return "?";
}

// ---- consumer ---------------------------------------------------------------

HeartbeatConsumer::HeartbeatConsumer(can::Bus& bus, Clock& clock) : bus_(bus), clock_(clock) {
    for (std::size_t i = 0; i < nodes_.size(); ++i) nodes_[i].h.node_id = static_cast<std::uint8_t>(i);
    sub_ = bus_.subscribe(can::Filter{kHeartbeatBase, 0x780, false, true},
                          [this](const can::Frame& f) { on_frame(f); });
}

HeartbeatConsumer::~HeartbeatConsumer() {
    timer_.stop();
    bus_.unsubscribe(sub_);
}

void HeartbeatConsumer::monitor(std::uint8_t node, std::chrono::nanoseconds timeout) {
    if (node == 0 || node > kMaxNodeId) throw InvalidArgument("heartbeat consumer: node id must be 1-127");
    if (timeout.count() <= 0) throw InvalidArgument("heartbeat consumer: timeout must be > 0");
    std::lock_guard l(mutex_);
    auto& n = nodes_[node];
    if (!n.monitored) watched_.push_back(node);
    n.monitored = true;
    n.timeout = timeout.count();
    if (n.h.alive) n.deadline = n.h.last_seen + n.timeout;
    timer_.poke();
}

void HeartbeatConsumer::forget(std::uint8_t node) {
    if (node == 0 || node > kMaxNodeId) return;
    std::lock_guard l(mutex_);
    if (nodes_[node].monitored) watched_.erase(std::find(watched_.begin(), watched_.end(), node));
    nodes_[node] = Node{};
    nodes_[node].h.node_id = node;
}

NodeHealth HeartbeatConsumer::health(std::uint8_t node) const {
    if (node == 0 || node > kMaxNodeId) throw InvalidArgument("node id must be 1-127");
    std::lock_guard l(mutex_);
    return nodes_[node].h;
}

void HeartbeatConsumer::on_frame(const can::Frame& f) {
    auto hb = decode_heartbeat(f);
    if (!hb) {
        ignored_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    const Nanos now = clock_.now();
    // Collect events under the lock, fire them after (callbacks may call back in).
    HeartbeatEvent evs[4];
    int nev = 0;
    {
        std::lock_guard l(mutex_);
        auto& n = nodes_[hb->node_id];
        const NodeState old = n.h.state;
        const std::uint8_t old_raw = n.h.raw_state;
        const bool was_lost = n.h.lost, was_alive = n.h.alive;
        n.h.last_seen = now;
        ++n.h.heartbeats;
        n.h.state = hb->state;
        n.h.raw_state = hb->raw_state;
        n.h.alive = true;
        n.h.lost = false;
        // N7: an unknown state still refreshes the timer.
        if (n.monitored) n.deadline = now + n.timeout;
        if (hb->is_boot_up()) {
            ++n.h.boot_ups;
            evs[nev++] = HeartbeatEvent::Reset;
        } else if (was_lost) {
            evs[nev++] = HeartbeatEvent::Back;
        } else if (!was_alive) {
            evs[nev++] = HeartbeatEvent::Started;
        }
        if (hb->state == NodeState::Unknown && old_raw != hb->raw_state)
            evs[nev++] = HeartbeatEvent::UnknownState;
        else if (was_alive && old != hb->state && !hb->is_boot_up())
            evs[nev++] = HeartbeatEvent::StateChanged;
    }
    if (on_event)
        for (int i = 0; i < nev; ++i) on_event(hb->node_id, evs[i], hb->state);
}

Nanos HeartbeatConsumer::process(Nanos now) {
    std::vector<std::pair<std::uint8_t, NodeState>> lost;
    Nanos next = -1;
    {
        std::lock_guard l(mutex_);
        for (const std::uint8_t i : watched_) {
            auto& n = nodes_[i];
            if (n.deadline < 0) continue;
            if (now >= n.deadline) {
                n.deadline = -1;  // re-armed by the next heartbeat
                n.h.alive = false;
                n.h.lost = true;
                ++n.h.timeouts;
                lost.emplace_back(i, n.h.state);
            } else if (next < 0 || n.deadline < next) {
                next = n.deadline;
            }
        }
    }
    if (on_event)
        for (auto& [node, st] : lost) on_event(node, HeartbeatEvent::Lost, st);
    return next;
}

void HeartbeatConsumer::start() {
    timer_.start(clock_, [this](Nanos now) { return process(now); });
}
void HeartbeatConsumer::stop() { timer_.stop(); }

// ---- producer ---------------------------------------------------------------

void HeartbeatProducer::check_period(std::chrono::nanoseconds period) {
    if (period.count() != 0 && period < kMinHeartbeatPeriod)
        throw InvalidArgument("heartbeat producer period: " + std::to_string(period.count()) +
                              " ns, must be 0 (off) or >= 1 ms");
}

HeartbeatProducer::HeartbeatProducer(can::Bus& bus, Clock& clock, std::uint8_t node_id,
                                     std::chrono::nanoseconds period, std::function<NodeState()> state)
    : bus_(bus), clock_(clock), node_(node_id), period_(period.count()), state_(std::move(state)) {
    if (node_id == 0 || node_id > kMaxNodeId) throw InvalidArgument("heartbeat producer: node id must be 1-127");
    check_period(period);
    if (!state_) throw InvalidArgument("heartbeat producer: state function required");
}

HeartbeatProducer::~HeartbeatProducer() { timer_.stop(); }

void HeartbeatProducer::send_boot_up() {
    bus_.send(encode_heartbeat(node_, NodeState::Initialising));
    sent_.fetch_add(1);
}

void HeartbeatProducer::set_period(std::chrono::nanoseconds period) {
    check_period(period);
    {
        std::lock_guard l(mutex_);
        period_ = period.count();
        next_ = -1;
    }
    timer_.poke();
}

Nanos HeartbeatProducer::process(Nanos now) {
    bool due = false;
    Nanos next;
    {
        std::lock_guard l(mutex_);
        if (period_ == 0) return -1;
        if (next_ < 0) next_ = now;  // first heartbeat right away
        if (now >= next_) {
            due = true;
            // Keep the grid, but never send a burst to catch up after a stall.
            next_ += period_;
            if (next_ <= now) next_ = now + period_;
        }
        next = next_;
    }
    if (due) {
        NodeState s = state_();
        if (s != NodeState::Unknown) {
            bus_.send(encode_heartbeat(node_, s));
            sent_.fetch_add(1);
        }
    }
    return next;
}

void HeartbeatProducer::start() {
    timer_.start(clock_, [this](Nanos now) { return process(now); });
}
void HeartbeatProducer::stop() { timer_.stop(); }

}  // namespace motorbus::canopen

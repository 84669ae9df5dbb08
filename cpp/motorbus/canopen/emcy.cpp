#include "motorbus/runtime/interrupt.hpp"
#include "motorbus/canopen/emcy.hpp"

#include <algorithm>
#include <cstdio>

#include "motorbus/canopen/nmt.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

std::string emcy_code_text(std::uint16_t code) {
    if (code == 0x0000) return "error reset or no error";
    switch (code) {
        case 0x8110: return "CAN overrun (objects lost)";
        case 0x8120: return "CAN in error passive mode";
        case 0x8130: return "life guard or heartbeat error";
        case 0x8140: return "recovered from bus off";
        case 0x8150: return "CAN-ID collision";
        case 0x8210: return "PDO not processed due to length error";
        case 0x8220: return "PDO length exceeded";
        case 0x8230: return "DAM MPDO not processed, destination object not available";
        case 0x8240: return "unexpected SYNC data length";
        case 0x8250: return "RPDO timeout";
        case 0x6100: return "internal software";
        case 0xFF00: return "device specific";
        default: break;
    }
    switch (code >> 12) {
        case 0x1: return "generic error";
        case 0x2: return "current";
        case 0x3: return "voltage";
        case 0x4: return "temperature";
        case 0x5: return "device hardware";
        case 0x6: return "device software";
        case 0x7: return "additional modules";
        case 0x8: return "monitoring";
        case 0x9: return "external error";
        case 0xF: return (code >> 8) == 0xF0 ? "additional functions" : "device specific";
        default: return "unknown";
    }
}

can::Frame encode_emcy(std::uint8_t node_id, std::uint16_t code, std::uint8_t error_register,
                       std::array<std::uint8_t, 5> manufacturer) {
    if (node_id == 0 || node_id > kMaxNodeId)
        throw InvalidArgument("EMCY node id " + std::to_string(node_id) + " is outside 1-127");
    can::Frame f;
    f.id = kEmcyBase + node_id;
    f.len = 8;
    f.data[0] = static_cast<std::uint8_t>(code & 0xFF);
    f.data[1] = static_cast<std::uint8_t>(code >> 8);
    f.data[2] = error_register;
    std::copy(manufacturer.begin(), manufacturer.end(), f.data.begin() + 3);
    return f;
}

std::optional<EmcyMessage> decode_emcy(const can::Frame& f) {
    if (f.extended || f.rtr || f.is_fd() || f.len > 8) return std::nullopt;  // E2
    if (f.id <= kEmcyBase || f.id > kEmcyBase + kMaxNodeId) return std::nullopt;
    if (f.len == 0) return std::nullopt;
    // Copy only the received bytes into a zeroed buffer: never read stale bytes (E1).
    std::array<std::uint8_t, 8> b{};
    std::copy_n(f.data.begin(), f.len, b.begin());
    EmcyMessage m;
    m.node_id = static_cast<std::uint8_t>(f.id - kEmcyBase);
    m.code = static_cast<std::uint16_t>(b[0] | (b[1] << 8));
    m.error_register = b[2];
    std::copy(b.begin() + 3, b.end(), m.manufacturer.begin());
    m.short_frame = f.len < 8;
    m.timestamp_ns = f.timestamp_ns;
    return m;
}

// ---- consumer ---------------------------------------------------------------

EmcyConsumer::EmcyConsumer(can::Bus& bus, std::size_t history_per_node)
    : bus_(bus), cap_(std::max<std::size_t>(1, history_per_node)) {
    sub_ = bus_.subscribe(can::Filter{kEmcyBase, 0x780, false, true},
                          [this](const can::Frame& f) { on_frame(f); });
}

EmcyConsumer::~EmcyConsumer() { bus_.unsubscribe(sub_); }

void EmcyConsumer::on_frame(const can::Frame& f) {
    auto m = decode_emcy(f);
    if (!m) {
        ignored_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    if (m->timestamp_ns == 0) m->timestamp_ns = monotonic_ns();
    {
        std::lock_guard l(mutex_);
        auto& n = nodes_[m->node_id];
        n.history.push_back(*m);
        while (n.history.size() > cap_) n.history.pop_front();
        if (m->is_reset()) {
            n.active.clear();  // E3
        } else if (std::find(n.active.begin(), n.active.end(), m->code) == n.active.end()) {
            if (n.active.size() < 64) n.active.push_back(m->code);
        }
        unclaimed_.push_back(*m);
        if (unclaimed_.size() > 256) unclaimed_.pop_front();
    }
    received_.fetch_add(1, std::memory_order_relaxed);
    cv_.notify_all();
    if (on_emcy) on_emcy(*m);
}

std::vector<EmcyMessage> EmcyConsumer::history(std::uint8_t node) const {
    if (node == 0 || node > kMaxNodeId) return {};
    std::lock_guard l(mutex_);
    return {nodes_[node].history.begin(), nodes_[node].history.end()};
}

std::vector<std::uint16_t> EmcyConsumer::active(std::uint8_t node) const {
    if (node == 0 || node > kMaxNodeId) return {};
    std::lock_guard l(mutex_);
    return nodes_[node].active;
}

void EmcyConsumer::clear(std::uint8_t node) {
    if (node == 0 || node > kMaxNodeId) return;
    std::lock_guard l(mutex_);
    nodes_[node] = NodeLog{};
}

std::optional<EmcyMessage> EmcyConsumer::wait(std::uint8_t node, std::chrono::nanoseconds timeout) {
    std::unique_lock l(mutex_);
    std::optional<EmcyMessage> found;
    auto take = [&] {
        for (auto it = unclaimed_.begin(); it != unclaimed_.end(); ++it)
            if (node == 0 || it->node_id == node) {
                found = *it;
                unclaimed_.erase(it);
                return true;
            }
        return false;
    };
    interruptible_wait_for(cv_, l, timeout, take);
    return found;
}

// ---- producer ---------------------------------------------------------------

EmcyProducer::EmcyProducer(can::Bus& bus, Clock& clock, std::uint8_t node_id,
                           std::uint16_t inhibit_100us, std::size_t queue_limit)
    : bus_(bus), clock_(clock), node_(node_id), inhibit_ns_(Nanos(inhibit_100us) * 100'000),
      limit_(std::max<std::size_t>(1, queue_limit)) {
    if (node_id == 0 || node_id > kMaxNodeId) throw InvalidArgument("EMCY producer: node id must be 1-127");
}

EmcyProducer::~EmcyProducer() { timer_.stop(); }

void EmcyProducer::set_inhibit(std::uint16_t inhibit_100us) {
    std::lock_guard l(mutex_);
    inhibit_ns_ = Nanos(inhibit_100us) * 100'000;
}

bool EmcyProducer::report(std::uint16_t code, std::uint8_t error_register,
                          std::array<std::uint8_t, 5> manufacturer) {
    can::Frame f = encode_emcy(node_, code, error_register, manufacturer);
    const Nanos now = clock_.now();
    {
        std::lock_guard l(mutex_);
        const bool free = queue_.empty() && (last_sent_ < 0 || now - last_sent_ >= inhibit_ns_);
        if (!free) {
            if (queue_.size() >= limit_) {
                queue_.pop_front();
                dropped_.fetch_add(1);
            }
            queue_.push_back(f);
            timer_.poke();
            return false;
        }
        last_sent_ = now;
    }
    bus_.send(f);
    sent_.fetch_add(1);
    return true;
}

Nanos EmcyProducer::process(Nanos now) {
    can::Frame f;
    Nanos next = -1;
    {
        std::lock_guard l(mutex_);
        if (queue_.empty()) return -1;
        if (last_sent_ >= 0 && now - last_sent_ < inhibit_ns_) return last_sent_ + inhibit_ns_;
        f = queue_.front();
        queue_.pop_front();
        last_sent_ = now;
        if (!queue_.empty()) next = now + inhibit_ns_;
    }
    bus_.send(f);
    sent_.fetch_add(1);
    return next;
}

std::size_t EmcyProducer::pending() const {
    std::lock_guard l(mutex_);
    return queue_.size();
}

void EmcyProducer::start() {
    timer_.start(clock_, [this](Nanos now) { return process(now); });
}
void EmcyProducer::stop() { timer_.stop(); }

}  // namespace motorbus::canopen

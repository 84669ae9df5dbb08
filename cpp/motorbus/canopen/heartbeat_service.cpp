#include "motorbus/canopen/heartbeat_service.hpp"

#include "motorbus/canopen/emcy.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

HeartbeatService::HeartbeatService(LocalNode& node, HeartbeatServiceOptions options)
    : node_(node), options_(options), consumer_(node.bus(), clock_) {}

HeartbeatService::~HeartbeatService() = default;

std::shared_ptr<HeartbeatService> HeartbeatService::attach(LocalNode& node, HeartbeatServiceOptions options) {
    std::shared_ptr<HeartbeatService> s(new HeartbeatService(node, options));
    s->install(s);
    node.add_service(s);
    return s;
}

void HeartbeatService::install(const std::weak_ptr<HeartbeatService>& self) {
    // The dictionary outlives this service (a simulator closes its node and keeps its
    // dictionary, then writes it again at a power cycle): its hooks hold the service
    // weakly and leave the values alone once the service is gone.
    auto& od = node_.od();
    if (!od.find(0x1017, 0))
        od.add_variable({.index = 0x1017, .name = "Producer heartbeat time", .type = DataType::Unsigned16,
                         .access = Access::RW, .default_value = std::uint64_t{options_.producer_ms}});
    if (!od.object(0x1016)) {
        od.add_array(0x1016, "Consumer heartbeat time");
        for (unsigned s = 1; s <= options_.consumer_entries && s <= 127; ++s)
            od.add_member(0x1016, {.subindex = static_cast<std::uint8_t>(s),
                                   .name = "Consumer heartbeat time " + std::to_string(s),
                                   .type = DataType::Unsigned32, .access = Access::RW,
                                   .default_value = std::uint64_t{0}});
    }
    auto producer = od.at(0x1017, 0);
    period_ns_ = Nanos(producer->get_u64()) * 1'000'000;
    producer->set_write_hook([self](const Variable&, std::span<const std::uint8_t> d) -> std::uint32_t {
        auto s = self.lock();
        if (!s) return 0;
        std::lock_guard l(s->m_);
        s->period_ns_ = Nanos(d[0] | (d.size() > 1 ? d[1] << 8 : 0)) * 1'000'000;
        s->next_ = -1;
        return 0;
    });
    auto obj = od.object(0x1016);
    for (auto& [sub, var] : obj->subs) {
        if (sub == 0) continue;
        if (entries_.size() < sub) entries_.resize(sub, 0);
        entries_[sub - 1] = static_cast<std::uint32_t>(var->get_u64());
        var->set_write_hook([self](const Variable& v, std::span<const std::uint8_t> d) -> std::uint32_t {
            auto s = self.lock();
            if (!s) return 0;
            std::uint32_t value = 0;
            for (std::size_t i = 0; i < d.size() && i < 4; ++i) value |= std::uint32_t(d[i]) << (8 * i);
            std::lock_guard l(s->m_);
            if (auto code = validate_consumer_entry(s->entries_, v.subindex(), value)) return code;
            s->entries_[v.subindex() - 1] = value;
            return 0;
        });
        var->add_change_listener([self](const Variable&) {
            if (auto s = self.lock()) s->apply_consumers();
        });
    }
    consumer_.on_event = [this](std::uint8_t n, HeartbeatEvent ev, NodeState st) {
        if (ev == HeartbeatEvent::Lost)
            lost(n);
        else if (ev == HeartbeatEvent::Started || ev == HeartbeatEvent::Back || ev == HeartbeatEvent::Reset)
            node_.wake();  // a deadline was armed: the node's timer must know
        if (on_event) on_event(n, ev, st);
    };
    apply_consumers();
}

void HeartbeatService::apply_consumers() {
    std::vector<std::uint32_t> entries;
    {
        std::lock_guard l(m_);
        entries = entries_;
    }
    for (unsigned n = 1; n <= kMaxNodeId; ++n) consumer_.forget(static_cast<std::uint8_t>(n));
    for (auto v : entries)
        if (auto e = decode_consumer_entry(v))  // N13: unused entries are never armed
            consumer_.monitor(e->node_id, std::chrono::milliseconds(e->time_ms));
    // No node_.wake() here: this runs inside the SDO write (the node's SDO lock
    // held), and wake() takes the node's other lock -- a lock-order inversion.
    // on_timer() re-checks at least every kRecheck instead.
}

void HeartbeatService::lost(std::uint8_t n) {
    (void)n;
    if (on_emcy) {
        on_emcy(0x8130);  // N10, through the device
    } else {
        try {
            node_.send(encode_emcy(node_.node_id(), 0x8130, 0x11));  // N10
        } catch (const Error&) {
        }
    }
    // 0x1029:1 communication error behaviour (CiA 301 default 0: to PRE-OPERATIONAL).
    std::uint64_t behaviour = options_.error_behaviour_without_1029;
    if (auto v = node_.od().find(0x1029, 1)) behaviour = v->get_u64();
    const NmtState s = node_.nmt_state();
    if (s == NmtState::Operational && behaviour == 0) node_.set_nmt_state(NmtState::PreOperational);
    if (behaviour == 2 && s != NmtState::Stopped) node_.set_nmt_state(NmtState::Stopped);
    if (on_lost) on_lost(n);
}

std::uint64_t HeartbeatService::heartbeats_sent() const {
    std::lock_guard l(m_);
    return sent_;
}

void HeartbeatService::on_nmt_state(LocalNode&, NmtState, NmtState) {}

Nanos HeartbeatService::on_timer(LocalNode& node, Nanos now) {
    Nanos next = consumer_.process(now);
    bool send = false;
    {
        std::lock_guard l(m_);
        if (detached_) return kNoDeadline;
        if (period_ns_ > 0) {
            if (next_ < 0) next_ = now + period_ns_;  // the boot-up was the first message
            if (now >= next_) {
                send = true;
                next_ += period_ns_;
                if (next_ <= now) next_ = now + period_ns_;
            }
            if (next < 0 || next_ < next) next = next_;
        }
    }
    const NmtState s = node.nmt_state();
    if (send && s != NmtState::Initialising) {
        try {
            node.send(encode_heartbeat(node.node_id(), static_cast<NodeState>(s)));
            std::lock_guard l(m_);
            ++sent_;
        } catch (const Error&) {
        }
    }
    // Configuration written over SDO is picked up within this time (see apply_consumers).
    constexpr Nanos kRecheck = 50'000'000;
    if (next < 0 || next > now + kRecheck) next = now + kRecheck;
    return next;
}

void HeartbeatService::on_detach(LocalNode&) {
    std::lock_guard l(m_);
    detached_ = true;
}

}  // namespace motorbus::canopen

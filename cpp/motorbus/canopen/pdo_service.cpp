#include "motorbus/canopen/pdo_service.hpp"

#include "motorbus/canopen/emcy.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

// ---- OdPdoObjects -----------------------------------------------------------

std::uint32_t OdPdoObjects::check_mapping(std::uint16_t index, std::uint8_t sub, std::uint8_t bits, bool tpdo) {
    VariablePtr v;
    if (auto code = od_.lookup(index, sub, v)) return code;
    if (!v->pdo_mappable()) return pdo_abort::kNotMappable;
    // A TPDO reads the object, an RPDO writes it.
    if (tpdo ? !readable(v->access()) : !writable(v->access())) return pdo_abort::kNotMappable;
    const std::size_t size = v->size();
    if (size == 0 || size > 8) return pdo_abort::kNotMappable;
    const bool ok = bits == size * 8 || (v->type() == DataType::Boolean && bits == 1);
    return ok ? 0 : pdo_abort::kNotMappable;
}

std::uint64_t OdPdoObjects::read_value(std::uint16_t index, std::uint8_t sub, std::uint8_t) {
    auto v = od_.find(index, sub);
    if (!v) return 0;
    // Through the remote path, as an SDO upload is: a read hook (a simulator's live
    // position, statusword...) is what the TPDO carries, not the last value stored.
    // A hook that refuses leaves the stored value, as before hooks were asked.
    Bytes b;
    if (v->remote_read(b) != 0) b = v->get();
    std::uint64_t raw = 0;
    for (std::size_t i = 0; i < b.size() && i < 8; ++i) raw |= std::uint64_t(b[i]) << (8 * i);
    return raw;
}

void OdPdoObjects::write_value(std::uint16_t index, std::uint8_t sub, std::uint8_t, std::uint64_t raw) {
    auto v = od_.find(index, sub);
    if (!v) return;
    Bytes b(v->size());
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(raw >> (8 * i));
    // Through the remote path: limits and the application's write hook apply to RPDO data too.
    if (v->remote_write(b) != 0) rejected_.fetch_add(1, std::memory_order_relaxed);
}

// ---- PdoService ---------------------------------------------------------------

PdoService::PdoService(LocalNode& node, PdoServiceOptions o)
    : node_(node), options_(o), objects_(node.od()) {
    PdoEngineOptions eo;
    eo.node_id = node.node_id();
    eo.rpdo_count = o.rpdo_count;
    eo.tpdo_count = o.tpdo_count;
    eo.max_mapped = o.max_mapped;
    eo.strict = o.strict;
    eo.sync_window_us = o.sync_window_us;
    eo.rtr = o.rtr;
    eo.allow_restricted_cob_ids = o.allow_restricted_cob_ids;
    engine_ = std::make_unique<PdoEngine>(
        objects_, clock_, eo,
        [this](const can::Frame& f) {
            try {
                node_.send(f);
            } catch (const Error&) {
                // A full or closed bus loses this PDO; the next trigger sends again.
            }
        },
        [this](std::uint16_t code, bool active) {
            if (on_emcy) {
                on_emcy(code, active);
                return;
            }
            try {
                node_.send(encode_emcy(node_.node_id(), active ? code : 0x0000, active ? 0x11 : 0x00));
            } catch (const Error&) {
            }
        });
}

PdoService::~PdoService() {
    std::lock_guard l(detach_m_);
    if (!detached_) {
        node_.bus().unsubscribe(sub_);
        for (auto& [v, h] : listeners_) v->remove_change_listener(h);
    }
}

std::shared_ptr<PdoService> PdoService::attach(LocalNode& node, PdoServiceOptions options) {
    std::shared_ptr<PdoService> s(new PdoService(node, options));
    s->install(s);
    node.add_service(s);
    s->engine_->set_operational(node.nmt_state() == NmtState::Operational);
    return s;
}

void PdoService::install(const std::weak_ptr<PdoService>& self) {
    auto& od = node_.od();
    auto* eng = engine_.get();   // listeners and the subscription below end with the service
    // The dictionary outlives this service (see HeartbeatService::install): the hooks
    // hold it weakly and take the values as plain data once it is gone.
    auto hook = [self](const Variable& var, std::span<const std::uint8_t> data) -> std::uint32_t {
        auto service = self.lock();
        if (!service) return 0;
        const std::uint32_t code = service->engine_->write(var.index(), var.subindex(), data);
        // A PDO (re)configured while OPERATIONAL (CiA 301: invalidate, map,
        // validate) must be scheduled now: the node runs this service's timer
        // only at the deadline it last returned -- none for a PDO that was
        // invalid -- so it used to stay silent until the next NMT change.
        if (code == 0) service->wake_node();
        return code;
    };
    auto ensure = [&](std::uint16_t index, const char* name, bool tpdo, bool map, unsigned n) {
        const bool existed = od.object(index).has_value();
        if (!existed) {
            od.add_record(index, name, map ? ObjectCode::Array : ObjectCode::Record);
            std::vector<std::uint8_t> v;
            if (map) {
                od.add_member(index, {.subindex = 0, .name = "Number of mapped objects",
                                      .type = DataType::Unsigned8, .access = Access::RW,
                                      .default_value = std::uint64_t{0}});
                for (unsigned s = 1; s <= options_.max_mapped; ++s) {
                    od.add_member(index, {.subindex = static_cast<std::uint8_t>(s),
                                          .name = "Mapped object " + std::to_string(s),
                                          .type = DataType::Unsigned32, .access = Access::RW,
                                          .default_value = std::uint64_t{0}});
                }
            } else {
                od.add_member(index, {.subindex = 0, .name = "Highest sub-index supported",
                                      .type = DataType::Unsigned8, .access = Access::Const,
                                      .default_value = std::uint64_t{tpdo ? 6u : 5u}});
                od.add_member(index, {.subindex = 1, .name = "COB-ID", .type = DataType::Unsigned32,
                                      .access = Access::RW,
                                      .default_value = std::uint64_t{engine_->cob_id(tpdo, n)}});
                od.add_member(index, {.subindex = 2, .name = "Transmission type", .type = DataType::Unsigned8,
                                      .access = Access::RW, .default_value = std::uint64_t{255}});
                od.add_member(index, {.subindex = 3, .name = "Inhibit time", .type = DataType::Unsigned16,
                                      .access = Access::RW, .default_value = std::uint64_t{0}});
                od.add_member(index, {.subindex = 4, .name = "Compatibility entry", .type = DataType::Unsigned8,
                                      .access = Access::RW, .default_value = std::uint64_t{0}});
                od.add_member(index, {.subindex = 5, .name = "Event timer", .type = DataType::Unsigned16,
                                      .access = Access::RW, .default_value = std::uint64_t{0}});
                if (tpdo)
                    od.add_member(index, {.subindex = 6, .name = "SYNC start value", .type = DataType::Unsigned8,
                                          .access = Access::RW, .default_value = std::uint64_t{0}});
            }
        }
        auto obj = od.object(index);
        // Adopt existing values (EDS defaults): communication first, then mapping.
        for (auto& [sub, var] : obj->subs) {
            if (sub == 0 && !map) continue;
            if (existed) {
                const Bytes b = var->get();
                eng->load(index, sub, b);
            }
            var->set_write_hook(hook);
        }
    };
    for (unsigned n = 1; n <= 512 && engine_->owns(static_cast<std::uint16_t>(0x1400 + n - 1)); ++n)
        ensure(static_cast<std::uint16_t>(0x1400 + n - 1), "RPDO communication parameter", false, false, n);
    for (unsigned n = 1; n <= 512 && engine_->owns(static_cast<std::uint16_t>(0x1800 + n - 1)); ++n)
        ensure(static_cast<std::uint16_t>(0x1800 + n - 1), "TPDO communication parameter", true, false, n);
    for (unsigned n = 1; n <= 512 && engine_->owns(static_cast<std::uint16_t>(0x1600 + n - 1)); ++n)
        ensure(static_cast<std::uint16_t>(0x1600 + n - 1), "RPDO mapping parameter", false, true, n);
    for (unsigned n = 1; n <= 512 && engine_->owns(static_cast<std::uint16_t>(0x1A00 + n - 1)); ++n)
        ensure(static_cast<std::uint16_t>(0x1A00 + n - 1), "TPDO mapping parameter", true, true, n);

    // Event-driven TPDOs: any change of a mappable object may trigger one.
    for (auto index : od.indices()) {
        auto obj = od.object(index);
        if (!obj) continue;
        for (auto& [sub, var] : obj->subs) {
            if (!var->pdo_mappable()) continue;
            auto h = var->add_change_listener(
                [eng](const Variable& v) { eng->notify_change(v.index(), v.subindex()); });
            listeners_.emplace_back(var, h);
        }
    }
    sub_ = node_.bus().subscribe(can::Filter{}, [eng](const can::Frame& f) {
        if (!(f.flags & can::kFlagLoopback)) eng->on_frame(f);
    });
}

void PdoService::reload() {
    // After a reset the dictionary holds the defaults again: rebuild the engine from it.
    engine_->reset_communication();
    auto& od = node_.od();
    for (std::uint16_t base : {0x1400, 0x1800, 0x1600, 0x1A00})
        for (unsigned n = 0; n < 512 && engine_->owns(static_cast<std::uint16_t>(base + n)); ++n)
            if (auto obj = od.object(static_cast<std::uint16_t>(base + n)))
                for (auto& [sub, var] : obj->subs)
                    if (sub != 0 || base >= 0x1600) engine_->load(obj->index, sub, var->get());
}

void PdoService::reload_from_dictionary() {
    reload();
    wake_node();
}

void PdoService::on_nmt_state(LocalNode&, NmtState previous, NmtState now) {
    if (previous == NmtState::Initialising && now != NmtState::Initialising) reload();
    engine_->set_operational(now == NmtState::Operational);
    node_.wake();
}

Nanos PdoService::on_timer(LocalNode&, Nanos now) {
    const Nanos next = engine_->process(now);
    return next < 0 ? kNoDeadline : next;
}

void PdoService::wake_node() {
    // Under detach_m_: once on_detach() has run, the node may be gone.
    std::lock_guard l(detach_m_);
    if (!detached_) node_.wake();
}

void PdoService::on_detach(LocalNode& node) {
    {
        // Not held while unsubscribing: that waits for a receive thread that
        // may be in wake_node() (an SDO write to a PDO parameter).
        std::lock_guard l(detach_m_);
        if (detached_) return;
        detached_ = true;
    }
    node.bus().unsubscribe(sub_);
    for (auto& [v, h] : listeners_) v->remove_change_listener(h);
    listeners_.clear();
}

}  // namespace motorbus::canopen

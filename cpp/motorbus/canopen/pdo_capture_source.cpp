#include "motorbus/canopen/pdo_capture_source.hpp"

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

PdoCaptureSource::PdoCaptureSource(can::Bus& bus, std::uint8_t node, std::vector<CapturedPdo> pdos,
                                   std::vector<std::pair<std::size_t, std::size_t>> columns, Nanos max_age_ns)
    : bus_(bus), node_(node), pdos_(std::move(pdos)), slots_(columns.size(), max_age_ns) {
    if (pdos_.empty()) throw InvalidArgument("PDO capture source: at least one TPDO");
    for (const auto& p : pdos_) layouts_.emplace_back(p.mapping);  // InvalidArgument past 64 bits
    routes_.resize(pdos_.size());
    for (std::size_t slot = 0; slot < columns.size(); ++slot) {
        const auto [pdo, entry] = columns[slot];
        if (pdo >= pdos_.size() || entry >= layouts_[pdo].size())
            throw InvalidArgument("PDO capture source: column " + std::to_string(slot) + " names TPDO " +
                                  std::to_string(pdo) + " entry " + std::to_string(entry) + ", which is not mapped");
        routes_[pdo].emplace_back(entry, slot);
    }
    for (std::size_t i = 0; i < pdos_.size(); ++i)
        subs_.push_back(bus_.subscribe_id(pdos_[i].cob_id, false, [this, i](const can::Frame& f) { on_frame(i, f); }));
}

PdoCaptureSource::~PdoCaptureSource() { close(); }

void PdoCaptureSource::close() {
    if (closed_.exchange(true)) return;
    for (auto id : subs_) bus_.unsubscribe(id);  // after this no callback runs
}

void PdoCaptureSource::on_frame(std::size_t pdo, const can::Frame& f) {
    if (f.rtr || f.extended || (f.flags & can::kFlagLoopback)) return;
    const PdoLayout& layout = layouts_[pdo];
    std::uint64_t raw[PdoLayout::kMaxEntries];
    if (!layout.unpack(f.data.data(), f.len, raw)) {
        short_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    const Nanos t = f.timestamp_ns ? f.timestamp_ns : monotonic_ns();
    double v[PdoLayout::kMaxEntries];
    const auto& routes = routes_[pdo];
    for (std::size_t j = 0; j < routes.size(); ++j) {
        const auto [entry, slot] = routes[j];
        v[j] = layout.entry(entry).is_signed ? static_cast<double>(layout.to_signed(entry, raw[entry]))
                                             : static_cast<double>(raw[entry]);
    }
    // Every value of the frame gets the frame's arrival time.
    for (std::size_t j = 0; j < routes.size(); ++j) slots_.set(routes[j].second, &v[j], 1, t);
    received_.fetch_add(1, std::memory_order_relaxed);
}

void PdoCaptureSource::read(double* out) {
    switch (bus_.state()) {
        // A lost link (adapter unplugged, server gone) turns the bus bus-off, as a real bus-off
        // does: either way nothing more arrives, and Bus::send() would refuse with LinkDown.
        case can::BusState::BusOff:
        case can::BusState::LinkDown:
            throw LinkDown("PDO capture node " + std::to_string(node_) + ": bus " + bus_.channel() +
                           " is down (link lost or bus-off)");
        case can::BusState::Closed: throw ClosedError("PDO capture node " + std::to_string(node_) + ": the bus is closed");
        default: break;
    }
    slots_.read(out, monotonic_ns());
}

std::string PdoCaptureSource::describe() const {
    return "TPDO capture node " + std::to_string(node_) + " (" + std::to_string(pdos_.size()) + " TPDO)";
}

}  // namespace motorbus::canopen

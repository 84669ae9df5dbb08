#include "motorbus/runtime/interrupt.hpp"
#include "motorbus/canopen/pdo.hpp"

#include "motorbus/canopen/nmt.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

PdoLayout::PdoLayout(std::span<const PdoMapEntry> entries) {
    if (entries.size() > kMaxEntries)
        throw InvalidArgument("PDO mapping: at most 64 entries, got " + std::to_string(entries.size()));
    unsigned off = 0;
    for (const auto& e : entries) {
        if (e.bits == 0 || e.bits > 64)
            throw InvalidArgument("PDO mapping: entry " + std::to_string(n_ + 1) + " has " +
                                  std::to_string(e.bits) + " bits (1-64 allowed)");
        if (off + e.bits > 64)
            throw InvalidArgument("PDO mapping: " + std::to_string(off + e.bits) +
                                  " bits exceed the 64 of a CAN frame");
        entries_[n_] = e;
        offset_[n_] = static_cast<std::uint8_t>(off);
        mask_[n_] = e.bits == 64 ? ~std::uint64_t(0) : ((std::uint64_t(1) << e.bits) - 1);
        off += e.bits;
        ++n_;
    }
    total_bits_ = off;
}

std::vector<std::uint8_t> PdoLayout::pack(std::span<const std::uint64_t> values) const {
    if (values.size() != n_)
        throw InvalidArgument("PDO pack: " + std::to_string(values.size()) + " values for " +
                              std::to_string(n_) + " mapped entries");
    std::uint8_t buf[8];
    unsigned len = pack(values.data(), buf);
    return {buf, buf + len};
}

std::vector<std::uint64_t> PdoLayout::unpack(std::span<const std::uint8_t> data) const {
    std::vector<std::uint64_t> v(n_);
    if (!unpack(data.data(), data.size(), v.data()))
        throw ProtocolError("PDO unpack: " + std::to_string(data.size()) + " bytes, mapping needs " +
                                std::to_string(byte_length()),
                            {data.begin(), data.end()});
    return v;
}

std::uint16_t pdo_comm_index(bool tpdo, unsigned number) {
    if (number < 1 || number > 512) throw InvalidArgument("PDO number must be 1-512");
    return static_cast<std::uint16_t>((tpdo ? 0x1800 : 0x1400) + number - 1);
}

std::uint16_t pdo_map_index(bool tpdo, unsigned number) {
    if (number < 1 || number > 512) throw InvalidArgument("PDO number must be 1-512");
    return static_cast<std::uint16_t>((tpdo ? 0x1A00 : 0x1600) + number - 1);
}

std::uint32_t default_pdo_cob_id(bool tpdo, unsigned number, std::uint8_t node) {
    if (number < 1 || number > 4) throw InvalidArgument("predefined PDO COB-IDs exist for PDO 1-4");
    if (node == 0 || node > kMaxNodeId) throw InvalidArgument("node id must be 1-127");
    return (tpdo ? 0x180u : 0x200u) + 0x100u * (number - 1) + node;
}

const char* to_string(PdoProcedure p) {
    switch (p) {
        case PdoProcedure::Cia301: return "cia301";
        case PdoProcedure::Direct: return "direct";
    }
    return "?";
}

std::optional<PdoProcedure> pdo_procedure_from_name(std::string_view name) {
    for (auto p : {PdoProcedure::Cia301, PdoProcedure::Direct})
        if (name == to_string(p)) return p;
    return std::nullopt;
}

void write_pdo(SdoAccess& sdo, std::uint8_t node, const PdoConfig& cfg, PdoProcedure procedure) {
    const std::uint16_t comm = pdo_comm_index(cfg.tpdo, cfg.number);
    const std::uint16_t map = pdo_map_index(cfg.tpdo, cfg.number);
    if (cfg.mapping) PdoLayout check(*cfg.mapping);  // refuse an impossible mapping before any write

    auto write_params = [&] {
        if (cfg.transmission_type) sdo.write_u8(node, comm, 2, *cfg.transmission_type);
        if (cfg.inhibit_100us) sdo.write_u16(node, comm, 3, *cfg.inhibit_100us);
        if (cfg.event_timer_ms) sdo.write_u16(node, comm, 5, *cfg.event_timer_ms);
        if (cfg.sync_start && cfg.tpdo) sdo.write_u8(node, comm, 6, *cfg.sync_start);
    };

    if (procedure == PdoProcedure::Direct) {
        if (cfg.cob_id)
            sdo.write_u32(node, comm, 1, (*cfg.cob_id & ~kPdoInvalid) | (cfg.enabled ? 0 : kPdoInvalid));
        write_params();
        if (cfg.mapping) {
            sdo.write_u8(node, map, 0, static_cast<std::uint8_t>(cfg.mapping->size()));
            for (std::size_t i = 0; i < cfg.mapping->size(); ++i)
                sdo.write_u32(node, map, static_cast<std::uint8_t>(i + 1), (*cfg.mapping)[i].mapping_word());
        }
        return;
    }

    // CiA 301 procedure: the PDO must be invalid while its parameters change.
    std::uint32_t cob = cfg.cob_id ? *cfg.cob_id
                                   : static_cast<std::uint32_t>(sdo.read_uint(node, comm, 1));
    cob &= ~kPdoInvalid;
    sdo.write_u32(node, comm, 1, cob | kPdoInvalid);
    write_params();
    if (cfg.mapping) {
        sdo.write_u8(node, map, 0, 0);
        for (std::size_t i = 0; i < cfg.mapping->size(); ++i)
            sdo.write_u32(node, map, static_cast<std::uint8_t>(i + 1), (*cfg.mapping)[i].mapping_word());
        sdo.write_u8(node, map, 0, static_cast<std::uint8_t>(cfg.mapping->size()));
    }
    if (cfg.enabled) sdo.write_u32(node, comm, 1, cob);
}

PdoConfig read_pdo(SdoAccess& sdo, std::uint8_t node, bool tpdo, unsigned number) {
    PdoConfig c;
    c.tpdo = tpdo;
    c.number = number;
    const std::uint16_t comm = pdo_comm_index(tpdo, number);
    const std::uint16_t map = pdo_map_index(tpdo, number);
    const auto cob = static_cast<std::uint32_t>(sdo.read_uint(node, comm, 1));
    c.cob_id = cob & ~kPdoInvalid;
    c.enabled = !(cob & kPdoInvalid);
    c.transmission_type = static_cast<std::uint8_t>(sdo.read_uint(node, comm, 2));
    // Highest supported sub tells which optional entries exist.
    const auto highest = static_cast<std::uint8_t>(sdo.read_uint(node, comm, 0));
    if (highest >= 3) c.inhibit_100us = static_cast<std::uint16_t>(sdo.read_uint(node, comm, 3));
    if (highest >= 5) c.event_timer_ms = static_cast<std::uint16_t>(sdo.read_uint(node, comm, 5));
    if (tpdo && highest >= 6) c.sync_start = static_cast<std::uint8_t>(sdo.read_uint(node, comm, 6));
    const auto n = static_cast<std::uint8_t>(sdo.read_uint(node, map, 0));
    if (n > PdoLayout::kMaxEntries)
        throw ProtocolError("PDO mapping count " + std::to_string(n) + " exceeds 64", {n});
    std::vector<PdoMapEntry> entries;
    for (std::uint8_t i = 1; i <= n; ++i)
        entries.push_back(PdoMapEntry::from_mapping_word(static_cast<std::uint32_t>(sdo.read_uint(node, map, i))));
    c.mapping = std::move(entries);
    return c;
}

// ---- host-side receiver / sender ----------------------------------------------

namespace {
void check_cob(std::uint32_t cob_id) {
    if ((cob_id & ~kPdoExtended) > ((cob_id & kPdoExtended) ? can::kMaxExtendedId : can::kMaxStandardId))
        throw InvalidArgument("PDO COB-ID out of range");
}
}  // namespace

PdoReceiver::PdoReceiver(can::Bus& bus, std::uint32_t cob_id, std::vector<PdoMapEntry> mapping)
    : bus_(bus), cob_id_(cob_id & ~(kPdoInvalid | kPdoNoRtr)), layout_(mapping) {
    check_cob(cob_id_);
    const bool ext = cob_id_ & kPdoExtended;
    sub_ = bus_.subscribe_id(cob_id_ & can::kMaxExtendedId, ext,
                             [this](const can::Frame& f) { on_frame(f); });
}

PdoReceiver::~PdoReceiver() { bus_.unsubscribe(sub_); }

void PdoReceiver::on_frame(const can::Frame& f) {
    if (f.rtr) return;
    std::vector<std::uint64_t> v(layout_.size());
    if (!layout_.unpack(f.data.data(), f.len, v.data())) {
        short_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    {
        std::lock_guard l(m_);
        values_ = v;
        ++count_;
    }
    cv_.notify_all();
    if (on_receive) on_receive(v, f.timestamp_ns);
}

std::vector<std::uint64_t> PdoReceiver::values() const {
    std::lock_guard l(m_);
    return values_;
}

std::optional<std::uint64_t> PdoReceiver::value(std::uint16_t index, std::uint8_t sub) const {
    std::lock_guard l(m_);
    if (values_.empty()) return std::nullopt;
    for (std::size_t i = 0; i < layout_.size(); ++i)
        if (layout_.entry(i).index == index && layout_.entry(i).sub == sub) return values_[i];
    return std::nullopt;
}

std::uint64_t PdoReceiver::received() const {
    std::lock_guard l(m_);
    return count_;
}

std::optional<std::uint64_t> PdoReceiver::wait_newer(std::uint64_t after, std::chrono::nanoseconds timeout) {
    std::unique_lock l(m_);
    if (!interruptible_wait_for(cv_, l, timeout, [&] { return count_ > after; })) return std::nullopt;
    return count_;
}

void PdoReceiver::request() {
    can::Frame f;
    f.id = cob_id_ & can::kMaxExtendedId;
    f.extended = cob_id_ & kPdoExtended;
    f.rtr = true;
    f.len = static_cast<std::uint8_t>(layout_.byte_length());
    bus_.send(f);
}

PdoSender::PdoSender(can::Bus& bus, std::uint32_t cob_id, std::vector<PdoMapEntry> mapping)
    : bus_(bus), cob_id_(cob_id & ~(kPdoInvalid | kPdoNoRtr)), layout_(mapping) {
    check_cob(cob_id_);
}

void PdoSender::send(std::span<const std::uint64_t> values, std::chrono::nanoseconds timeout) {
    if (values.size() != layout_.size())
        throw InvalidArgument("PDO send: " + std::to_string(values.size()) + " values for " +
                              std::to_string(layout_.size()) + " mapped entries");
    can::Frame f;
    f.id = cob_id_ & can::kMaxExtendedId;
    f.extended = cob_id_ & kPdoExtended;
    f.len = static_cast<std::uint8_t>(layout_.pack(values.data(), f.data.data()));
    bus_.send(f, timeout);
}

}  // namespace motorbus::canopen

#include "motorbus/canopen/pdo_engine.hpp"

#include <algorithm>

#include "motorbus/canopen/nmt.hpp"
#include "motorbus/canopen/sync.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

using namespace pdo_abort;

// ---- PdoObjectTable -------------------------------------------------------

std::uint64_t PdoObjectTable::get(std::uint16_t index, std::uint8_t sub) const {
    std::lock_guard l(m_);
    auto it = objs_.find(key(index, sub));
    if (it == objs_.end()) throw InvalidArgument("no object in table");
    return it->second.value;
}

void PdoObjectTable::set(std::uint16_t index, std::uint8_t sub, std::uint64_t v) {
    std::lock_guard l(m_);
    auto it = objs_.find(key(index, sub));
    if (it == objs_.end()) throw InvalidArgument("no object in table");
    it->second.value = v;
}

std::uint32_t PdoObjectTable::check_mapping(std::uint16_t index, std::uint8_t sub, std::uint8_t bits,
                                            bool tpdo) {
    std::lock_guard l(m_);
    auto it = objs_.find(key(index, sub));
    if (it == objs_.end()) {
        for (auto& [k, o] : objs_)
            if ((k >> 8) == index) return kNoSubIndex;
        return kNoObject;
    }
    const auto& o = it->second;
    if (!(tpdo ? o.tpdo_mappable : o.rpdo_mappable)) return kNotMappable;
    if (bits != o.bits) return kNotMappable;
    return 0;
}

std::uint64_t PdoObjectTable::read_value(std::uint16_t index, std::uint8_t sub, std::uint8_t) {
    std::lock_guard l(m_);
    auto it = objs_.find(key(index, sub));
    return it == objs_.end() ? 0 : it->second.value;
}

void PdoObjectTable::write_value(std::uint16_t index, std::uint8_t sub, std::uint8_t, std::uint64_t raw) {
    {
        std::lock_guard l(m_);
        auto it = objs_.find(key(index, sub));
        if (it == objs_.end()) return;
        it->second.value = raw;
    }
    if (on_write) on_write(index, sub, raw);
}

// ---- helpers --------------------------------------------------------------

namespace {

bool restricted_id(std::uint32_t id) {
    return id <= 0x07F || (id >= 0x101 && id <= 0x180) || (id >= 0x581 && id <= 0x5FF) ||
           (id >= 0x601 && id <= 0x67F) || (id >= 0x6E0 && id <= 0x6FF) || id >= 0x701;
}

// Dummy-mapping objects and their sizes (CiA 301 7.4.7.1).
int dummy_bits(std::uint16_t index) {
    switch (index) {
        case 0x0001: return 1;
        case 0x0002: case 0x0005: return 8;
        case 0x0003: case 0x0006: return 16;
        case 0x0004: case 0x0007: return 32;
        default: return -1;
    }
}

std::uint32_t le(std::span<const std::uint8_t> d) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < d.size() && i < 4; ++i) v |= std::uint32_t(d[i]) << (8 * i);
    return v;
}

std::uint32_t size_check(std::span<const std::uint8_t> d, std::size_t want) {
    if (d.size() > want) return kLengthTooHigh;
    if (d.size() < want) return kLengthTooLow;
    return 0;
}

void put(std::vector<std::uint8_t>& out, std::uint32_t v, std::size_t n) {
    out.clear();
    for (std::size_t i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

}  // namespace

// ---- engine ---------------------------------------------------------------

PdoEngine::PdoEngine(PdoObjectAccess& objects, Clock& clock, PdoEngineOptions options, SendFn send,
                     EmcyFn emcy)
    : objects_(objects), clock_(clock), opt_(options), send_(std::move(send)), emcy_(std::move(emcy)) {
    if (opt_.node_id == 0 || opt_.node_id > kMaxNodeId) throw InvalidArgument("PDO engine: node id must be 1-127");
    if (opt_.max_mapped == 0 || opt_.max_mapped > 64) throw InvalidArgument("PDO engine: max_mapped must be 1-64");
    if (opt_.rpdo_count > 512 || opt_.tpdo_count > 512) throw InvalidArgument("PDO engine: at most 512 PDOs");
    if (!send_) throw InvalidArgument("PDO engine: a send function is required");
    rpdos_.resize(opt_.rpdo_count);
    tpdos_.resize(opt_.tpdo_count);
    for (unsigned i = 0; i < rpdos_.size(); ++i) rpdos_[i].number = i + 1;
    for (unsigned i = 0; i < tpdos_.size(); ++i) {
        tpdos_[i].number = i + 1;
        tpdos_[i].tpdo = true;
    }
    reset_communication();
}

void PdoEngine::defaults(Pdo& p) {
    const unsigned n = p.number;
    const bool t = p.tpdo;
    p = Pdo{};
    p.tpdo = t;
    p.number = n;
    p.cob = n <= 4 ? default_pdo_cob_id(t, n, opt_.node_id) : kPdoInvalid;
    p.type = 255;
}

void PdoEngine::reset_communication() {
    std::lock_guard l(m_);
    for (auto& p : rpdos_) defaults(p);
    for (auto& p : tpdos_) defaults(p);
    last_sync_ = -1;
    sync_error_ = false;
}

bool PdoEngine::owns(std::uint16_t index) const {
    bool is_map;
    return find(index, is_map) != nullptr;
}

const PdoEngine::Pdo* PdoEngine::find(std::uint16_t index, bool& is_map) const {
    return const_cast<PdoEngine*>(this)->find(index, is_map);
}

PdoEngine::Pdo* PdoEngine::find(std::uint16_t index, bool& is_map) {
    auto pick = [&](std::vector<Pdo>& v, std::uint16_t base, bool map) -> Pdo* {
        if (index >= base && index < base + v.size()) {
            is_map = map;
            return &v[index - base];
        }
        return nullptr;
    };
    if (auto p = pick(rpdos_, 0x1400, false)) return p;
    if (auto p = pick(rpdos_, 0x1600, true)) return p;
    if (auto p = pick(tpdos_, 0x1800, false)) return p;
    if (auto p = pick(tpdos_, 0x1A00, true)) return p;
    return nullptr;
}

void PdoEngine::rebuild(Pdo& p) {
    p.complete = false;
    p.layout = PdoLayout{};
    if (p.count == 0) return;
    std::vector<PdoMapEntry> entries;
    for (unsigned i = 0; i < p.count; ++i) {
        auto e = PdoMapEntry::from_mapping_word(p.words[i]);
        if (e.bits == 0) return;  // an entry not written yet: nothing to send
        entries.push_back(e);
    }
    try {
        p.layout = PdoLayout(entries);
        p.complete = true;
    } catch (const InvalidArgument&) {
    }
}

std::uint32_t PdoEngine::validate_map_count(const Pdo& p, unsigned n, bool strict) const {
    if (n > opt_.max_mapped) return kMappingTooLong;  // P7: sub0 > max
    unsigned bits = 0;
    for (unsigned i = 0; i < n; ++i) {
        const auto e = PdoMapEntry::from_mapping_word(p.words[i]);
        if (e.bits == 0) {
            if (strict) return kNotMappable;
            continue;  // lenient: entries may follow sub0
        }
        bits += e.bits;
    }
    if (bits > 64) return kMappingTooLong;
    return 0;
}

std::uint32_t PdoEngine::write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data) {
    std::lock_guard l(m_);
    return write_locked(index, sub, data, opt_.strict);
}

std::uint32_t PdoEngine::load(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data) {
    std::lock_guard l(m_);
    return write_locked(index, sub, data, false);
}

std::uint32_t PdoEngine::write_locked(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                                      bool strict) {
    bool is_map = false;
    Pdo* pp = find(index, is_map);
    if (!pp) return kNoObject;
    Pdo& p = *pp;

    if (is_map) {
        if (sub > opt_.max_mapped) return kNoSubIndex;
        if (sub == 0) {
            if (auto e = size_check(data, 1)) return e;
            const unsigned n = data[0];
            if (strict && p.valid()) return kUnsupportedAccess;  // P8
            if (auto e = validate_map_count(p, n, strict)) return e;
            p.count = static_cast<std::uint8_t>(n);
            rebuild(p);
            return 0;
        }
        if (auto e = size_check(data, 4)) return e;
        if (strict && (p.valid() || p.count != 0)) return kUnsupportedAccess;  // P8
        const std::uint32_t w = le(data);
        const auto e = PdoMapEntry::from_mapping_word(w);
        if (e.bits == 0 || e.bits > 64) return kMappingTooLong;
        if (const int db = dummy_bits(e.index); db > 0) {
            if (p.tpdo || e.sub != 0 || e.bits != db) return kNotMappable;
        } else if (const auto code = objects_.check_mapping(e.index, e.sub, e.bits, p.tpdo)) {
            return code;  // P7: unmappable object
        }
        const std::uint32_t old = p.words[sub - 1];
        p.words[sub - 1] = w;
        if (sub <= p.count) {
            if (auto c = validate_map_count(p, p.count, strict)) {
                p.words[sub - 1] = old;
                return c;
            }
        }
        rebuild(p);
        return 0;
    }

    // communication parameter
    switch (sub) {
        case 0: return kReadOnly;
        case 1: {
            if (auto e = size_check(data, 4)) return e;
            const std::uint32_t v = le(data);
            const bool valid = !(v & kPdoInvalid);
            const bool ext = v & kPdoExtended;
            const std::uint32_t id = v & can::kMaxExtendedId;
            if (!ext && id > can::kMaxStandardId) return kInvalidValue;   // P9: reserved bits
            if (!opt_.allow_restricted_cob_ids) {
                if (valid && !ext && restricted_id(id)) return kInvalidValue;  // P9: restricted
                if (valid && id == 0) return kInvalidValue;
            }
            if (strict && valid && p.valid() &&
                (id != p.can_id() || ext != p.extended() ||
                 (p.tpdo && ((v ^ p.cob) & kPdoNoRtr))))
                return kInvalidValue;  // P9: change while valid
            const bool becomes_valid = valid && !p.valid();
            p.cob = v;
            if (becomes_valid) {
                p.pending = is_event_type(p.type);
                p.sync_count = 0;
                p.sync_started = false;
                p.len_error = false;
                p.have_buffer = false;
                p.rx_deadline = -1;
                p.timer_due = -1;
            }
            return 0;
        }
        case 2: {
            if (auto e = size_check(data, 1)) return e;
            if (data[0] > kPdoSyncCyclicMax && data[0] < kPdoEventManufacturer) return kInvalidValue;  // P10
            p.type = data[0];
            p.sync_count = 0;
            return 0;
        }
        case 3: {
            if (auto e = size_check(data, 2)) return e;
            if (strict && p.tpdo && p.valid()) return kInvalidValue;
            p.inhibit = static_cast<std::uint16_t>(le(data));
            return 0;
        }
        case 4: {
            if (auto e = size_check(data, 1)) return e;
            p.compat = data[0];
            return 0;
        }
        case 5: {
            if (auto e = size_check(data, 2)) return e;
            p.event_timer = static_cast<std::uint16_t>(le(data));
            p.timer_due = -1;  // re-armed from now by process()
            return 0;
        }
        case 6: {
            if (!p.tpdo) return kNoSubIndex;
            if (auto e = size_check(data, 1)) return e;
            if (strict && p.valid()) return kInvalidValue;
            if (data[0] > 240) return kInvalidValue;
            p.sync_start = data[0];
            return 0;
        }
        default: return kNoSubIndex;
    }
}

std::uint32_t PdoEngine::read(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& out) const {
    std::lock_guard l(m_);
    bool is_map = false;
    const Pdo* pp = find(index, is_map);
    if (!pp) return kNoObject;
    const Pdo& p = *pp;
    if (is_map) {
        if (sub > opt_.max_mapped) return kNoSubIndex;
        if (sub == 0)
            put(out, p.count, 1);
        else
            put(out, p.words[sub - 1], 4);
        return 0;
    }
    switch (sub) {
        case 0: put(out, p.tpdo ? 6 : 5, 1); return 0;
        case 1: put(out, p.cob, 4); return 0;
        case 2: put(out, p.type, 1); return 0;
        case 3: put(out, p.inhibit, 2); return 0;
        case 4: put(out, p.compat, 1); return 0;
        case 5: put(out, p.event_timer, 2); return 0;
        case 6:
            if (!p.tpdo) return kNoSubIndex;
            put(out, p.sync_start, 1);
            return 0;
        default: return kNoSubIndex;
    }
}

void PdoEngine::set_operational(bool operational) {
    {
        std::lock_guard l(m_);
        if (operational == operational_) return;
        operational_ = operational;
        for (auto& p : tpdos_) {
            // Event-driven TPDOs go out once on entering OPERATIONAL.
            p.pending = operational && is_event_type(p.type);
            p.timer_due = -1;
            p.sync_count = 0;
            p.sync_started = false;
        }
        for (auto& p : rpdos_) {
            p.have_buffer = false;
            p.rx_deadline = -1;
        }
    }
    process(clock_.now());
}

void PdoEngine::set_sync_cob_id(std::uint32_t cob_id) {
    std::lock_guard l(m_);
    opt_.sync_cob_id = cob_id & can::kMaxStandardId;
}

bool PdoEngine::operational() const {
    std::lock_guard l(m_);
    return operational_;
}

void PdoEngine::send_tpdo(Pdo& p, Nanos now, Out& out) {
    if (!p.valid() || !p.complete) return;
    // The mapped objects are read later, outside the lock (flush): reading one may
    // run its read hook (a simulator's live position), and a hook that sets an
    // object notifies this engine (notify_change) — under the lock that would
    // deadlock on the engine's own mutex.
    can::Frame f;
    f.id = p.can_id();
    f.extended = p.extended();
    out.tpdos.push_back({p.layout, f});
    p.pending = false;
    p.last_sent = now;
    p.timer_due = p.event_timer ? now + Nanos(p.event_timer) * 1'000'000 : -1;
    ++counters_.tpdo_sent;
}

void PdoEngine::apply_rpdo(Pdo& p, const can::Frame& f, Out& out) {
    std::uint64_t v[PdoLayout::kMaxEntries];
    if (!p.layout.unpack(f.data.data(), f.len, v)) return;
    for (std::size_t i = 0; i < p.layout.size(); ++i) {
        const auto& e = p.layout.entry(i);
        if (!e.is_dummy()) out.writes.push_back({e.index, e.sub, e.bits, v[i]});
    }
    ++counters_.rpdo_applied;
    out.rpdo_applied.push_back(p.number);
}

void PdoEngine::handle_sync(const can::Frame& f, Nanos now, Out& out) {
    SyncMessage msg;
    const auto r = decode_sync(f, msg, opt_.sync_overflow, opt_.sync_cob_id);
    if (r == SyncDecode::BadLength) {  // N16
        ++counters_.sync_errors;
        if (!sync_error_) out.emcy.emplace_back(pdo_emcy::kUnexpectedSync, true);
        sync_error_ = true;
        return;
    }
    if (sync_error_) {
        sync_error_ = false;
        out.emcy.emplace_back(pdo_emcy::kUnexpectedSync, false);
    }
    ++counters_.sync_received;
    last_sync_ = now;
    if (!operational_) return;
    // Synchronous RPDOs received in the previous cycle take effect now.
    for (auto& p : rpdos_) {
        if (p.have_buffer && p.valid() && p.complete && is_sync_type(p.type)) apply_rpdo(p, p.buffer, out);
        p.have_buffer = false;
    }
    for (auto& p : tpdos_) {
        if (!p.valid() || !p.complete || !is_sync_type(p.type)) continue;
        if (p.type == kPdoSyncAcyclic) {
            if (p.pending) send_tpdo(p, now, out);
            continue;
        }
        if (!p.sync_started) {
            // Sync start value: begin counting when the SYNC counter equals it.
            if (p.sync_start && (!msg.counter || *msg.counter != p.sync_start)) continue;
            p.sync_started = true;
            p.sync_count = 0;
        }
        if (++p.sync_count >= p.type) {
            p.sync_count = 0;
            send_tpdo(p, now, out);
        }
    }
}

bool PdoEngine::on_frame(const can::Frame& f) {
    Out out;
    bool used = false;
    {
        std::lock_guard l(m_);
        const Nanos now = clock_.now();
        if (!f.extended && f.id == opt_.sync_cob_id && !f.rtr) {
            handle_sync(f, now, out);
            used = true;
        } else {
            for (auto& p : rpdos_) {
                if (!p.valid() || p.can_id() != f.id || p.extended() != f.extended) continue;
                used = true;
                if (f.rtr) {  // P6
                    ++counters_.rtr_ignored;
                    break;
                }
                if (!operational_ || !p.complete || f.is_fd()) {  // P3
                    ++counters_.rpdo_ignored;
                    break;
                }
                const unsigned need = p.layout.byte_length();
                if (f.len < need) {  // P1: never apply, EMCY once
                    ++counters_.rpdo_length_errors;
                    if (!p.len_error) out.emcy.emplace_back(pdo_emcy::kLengthError, true);
                    p.len_error = true;
                    break;
                }
                if (f.len > need) {  // P2: apply the first bytes, report
                    ++counters_.rpdo_length_errors;
                    if (!p.len_error) out.emcy.emplace_back(pdo_emcy::kLengthExceeded, true);
                    p.len_error = true;
                } else if (p.len_error) {
                    p.len_error = false;
                    out.emcy.emplace_back(pdo_emcy::kLengthError, false);
                }
                if (p.event_timer) p.rx_deadline = now + Nanos(p.event_timer) * 1'000'000;
                if (is_sync_type(p.type)) {
                    // P5: outside the synchronous window after the last SYNC: discard.
                    if (opt_.sync_window_us && last_sync_ >= 0 &&
                        now - last_sync_ > Nanos(opt_.sync_window_us) * 1000) {
                        ++counters_.rpdo_ignored;
                        break;
                    }
                    p.buffer = f;
                    p.have_buffer = true;
                } else {
                    apply_rpdo(p, f, out);
                }
                break;
            }
            if (!used) {
                for (auto& p : tpdos_) {
                    if (!p.valid() || p.can_id() != f.id || p.extended() != f.extended) continue;
                    used = true;
                    if (!f.rtr) {  // N15: someone else transmits on our COB-ID
                        ++counters_.collisions;
                        if (!collision_) out.emcy.emplace_back(pdo_emcy::kCollision, true);
                        collision_ = true;
                        break;
                    }
                    if (!operational_ || opt_.rtr == PdoRtrPolicy::Never || (p.cob & kPdoNoRtr)) {
                        ++counters_.rtr_ignored;
                        break;
                    }
                    send_tpdo(p, now, out);
                    break;
                }
            }
        }
    }
    flush(out);
    return used;
}

namespace {
// The engine whose TPDO objects this thread is reading (flush), if any.
thread_local const PdoEngine* reading_tpdo_objects = nullptr;
}  // namespace

void PdoEngine::notify_change(std::uint16_t index, std::uint8_t sub) {
    // A read hook may set the object it answers for (a simulator publishing its
    // state as it is read): that is what the TPDO being built carries, not a new
    // event — sending again would read again, for ever.
    if (reading_tpdo_objects == this) return;
    {
        std::lock_guard l(m_);
        for (auto& p : tpdos_) {
            if (!p.complete || !(is_event_type(p.type) || p.type == kPdoSyncAcyclic)) continue;
            for (std::size_t i = 0; i < p.layout.size(); ++i)
                if (p.layout.entry(i).index == index && p.layout.entry(i).sub == sub) p.pending = true;
        }
    }
    process(clock_.now());
}

void PdoEngine::trigger_tpdo(unsigned n) {
    {
        std::lock_guard l(m_);
        if (n == 0 || n > tpdos_.size()) throw InvalidArgument("no such TPDO");
        tpdos_[n - 1].pending = true;
    }
    process(clock_.now());
}

Nanos PdoEngine::process(Nanos now) {
    Out out;
    Nanos next = -1;
    auto consider = [&](Nanos t) {
        if (t >= 0 && (next < 0 || t < next)) next = t;
    };
    {
        std::lock_guard l(m_);
        if (operational_) {
            for (auto& p : tpdos_) {
                if (!p.valid() || !p.complete || !is_event_type(p.type)) continue;
                if (p.event_timer && p.timer_due < 0)
                    p.timer_due = (p.last_sent >= 0 ? p.last_sent : now) + Nanos(p.event_timer) * 1'000'000;
                if (p.timer_due >= 0 && now >= p.timer_due) p.pending = true;
                if (p.pending) {
                    const Nanos free_at = p.last_sent < 0 ? now : p.last_sent + Nanos(p.inhibit) * 100'000;
                    if (now >= free_at)
                        send_tpdo(p, now, out);  // P12: never faster than the inhibit time
                    else
                        consider(free_at);
                }
                consider(p.timer_due);
            }
            for (auto& p : rpdos_) {
                if (p.rx_deadline < 0) continue;
                if (now >= p.rx_deadline) {  // P11
                    p.rx_deadline = -1;
                    out.emcy.emplace_back(pdo_emcy::kRpdoTimeout, true);
                    out.rpdo_timeout.push_back(p.number);
                } else {
                    consider(p.rx_deadline);
                }
            }
        }
    }
    flush(out);
    return next;
}

void PdoEngine::flush(Out& out) {
    // Outside the lock: writing or reading an object may run hooks that call back in.
    for (auto& w : out.writes) objects_.write_value(w.index, w.sub, w.bits, w.raw);
    for (auto& t : out.tpdos) {
        struct ReadingGuard {  // marks this thread as reading this engine's TPDO objects
            const PdoEngine* outer = reading_tpdo_objects;
            explicit ReadingGuard(const PdoEngine* e) { reading_tpdo_objects = e; }
            ~ReadingGuard() { reading_tpdo_objects = outer; }
        } guard(this);
        std::uint64_t values[PdoLayout::kMaxEntries];
        for (std::size_t i = 0; i < t.layout.size(); ++i) {
            const auto& e = t.layout.entry(i);
            values[i] = objects_.read_value(e.index, e.sub, e.bits);
        }
        t.frame.len = static_cast<std::uint8_t>(t.layout.pack(values, t.frame.data.data()));
        send_(t.frame);
    }
    if (emcy_)
        for (auto& [code, active] : out.emcy) emcy_(code, active);
    if (on_rpdo)
        for (auto n : out.rpdo_applied) on_rpdo(n);
    if (on_rpdo_timeout)
        for (auto n : out.rpdo_timeout) on_rpdo_timeout(n);
}

PdoEngine::Counters PdoEngine::counters() const {
    std::lock_guard l(m_);
    return counters_;
}

std::vector<PdoMapEntry> PdoEngine::mapping(bool tpdo, unsigned n) const {
    std::lock_guard l(m_);
    const auto& v = tpdo ? tpdos_ : rpdos_;
    if (n == 0 || n > v.size()) throw InvalidArgument("no such PDO");
    return v[n - 1].complete ? v[n - 1].layout.entries() : std::vector<PdoMapEntry>{};
}

std::uint32_t PdoEngine::cob_id(bool tpdo, unsigned n) const {
    std::lock_guard l(m_);
    const auto& v = tpdo ? tpdos_ : rpdos_;
    if (n == 0 || n > v.size()) throw InvalidArgument("no such PDO");
    return v[n - 1].cob;
}

}  // namespace motorbus::canopen

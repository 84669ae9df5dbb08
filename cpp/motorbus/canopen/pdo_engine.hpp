// The PDO engine of a served node (simulators, LocalNode): owns the PDO
// communication and mapping parameters (0x1400-0x1BFF), validates writes to
// them with the CiA 301 abort codes, transmits TPDOs on SYNC, on events (with
// inhibit time) and on the event timer, answers RTRs, and applies RPDOs to
// the application objects.
//
// It reads and writes application objects only through PdoObjectAccess, and
// sends through a callback, so it works with any object dictionary and any
// bus.  Frames it should see are routed to on_frame() by its owner.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "motorbus/can/frame.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/runtime/callback_slot.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::canopen {

// SDO abort codes the engine answers with.
namespace pdo_abort {
constexpr std::uint32_t kUnsupportedAccess = 0x06010000;  // P8
constexpr std::uint32_t kReadOnly = 0x06010002;
constexpr std::uint32_t kNoObject = 0x06020000;
constexpr std::uint32_t kNotMappable = 0x06040041;        // P7
constexpr std::uint32_t kMappingTooLong = 0x06040042;     // P7
constexpr std::uint32_t kLengthMismatch = 0x06070010;
constexpr std::uint32_t kLengthTooHigh = 0x06070012;
constexpr std::uint32_t kLengthTooLow = 0x06070013;
constexpr std::uint32_t kNoSubIndex = 0x06090011;
constexpr std::uint32_t kInvalidValue = 0x06090030;       // P9, P10
}  // namespace pdo_abort

// EMCY codes the engine raises.
namespace pdo_emcy {
constexpr std::uint16_t kLengthError = 0x8210;     // P1
constexpr std::uint16_t kLengthExceeded = 0x8220;  // P2
constexpr std::uint16_t kUnexpectedSync = 0x8240;  // N16
constexpr std::uint16_t kRpdoTimeout = 0x8250;     // P11
constexpr std::uint16_t kCollision = 0x8150;       // N15
}  // namespace pdo_emcy

class PdoObjectAccess {
public:
    virtual ~PdoObjectAccess() = default;
    // 0 when index:sub with `bits` may be mapped into a TPDO (tpdo) / RPDO,
    // else the abort code (0x06040041 not mappable, 0x06020000, 0x06090011, ...).
    virtual std::uint32_t check_mapping(std::uint16_t index, std::uint8_t sub, std::uint8_t bits,
                                        bool tpdo) = 0;
    // The object's value as little-endian raw bits (low `bits` used).
    virtual std::uint64_t read_value(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) = 0;
    virtual void write_value(std::uint16_t index, std::uint8_t sub, std::uint8_t bits,
                             std::uint64_t raw) = 0;
};

// A lookup table implementation, handy for simulators and tests.
class PdoObjectTable : public PdoObjectAccess {
public:
    struct Object {
        std::uint8_t bits;
        bool tpdo_mappable = true;
        bool rpdo_mappable = true;
        std::uint64_t value = 0;
    };
    void add(std::uint16_t index, std::uint8_t sub, Object o) { objs_[key(index, sub)] = o; }
    std::uint64_t get(std::uint16_t index, std::uint8_t sub) const;
    void set(std::uint16_t index, std::uint8_t sub, std::uint64_t v);
    std::uint32_t check_mapping(std::uint16_t index, std::uint8_t sub, std::uint8_t bits,
                                bool tpdo) override;
    std::uint64_t read_value(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) override;
    void write_value(std::uint16_t index, std::uint8_t sub, std::uint8_t bits, std::uint64_t raw) override;
    std::function<void(std::uint16_t, std::uint8_t, std::uint64_t)> on_write;

private:
    static std::uint32_t key(std::uint16_t i, std::uint8_t s) { return (std::uint32_t(i) << 8) | s; }
    mutable std::mutex m_;
    std::unordered_map<std::uint32_t, Object> objs_;
};

// Whether a remote frame (RTR) on a TPDO's COB-ID is answered with that TPDO.
enum class PdoRtrPolicy : std::uint8_t {
    ByCobId,  // CiA 301: answered while COB-ID bit 30 ("no RTR allowed") is 0
    Never,    // never answered, whatever bit 30 says (a device without RTR support)
};

struct PdoEngineOptions {
    std::uint8_t node_id = 1;
    unsigned rpdo_count = 4;
    unsigned tpdo_count = 4;
    unsigned max_mapped = 8;  // highest mapping sub-index (<= 64)
    // true: the CiA 301 procedure is enforced (P8/P9: no change while valid).
    // false: changes while valid are accepted and take effect at once, as a
    // device whose manual documents the direct configuration sequence does.
    bool strict = true;
    std::uint32_t sync_cob_id = 0x080;
    std::uint8_t sync_overflow = 0;   // 0x1019
    std::uint32_t sync_window_us = 0; // 0x1007, 0 = no window (P5)
    PdoRtrPolicy rtr = PdoRtrPolicy::ByCobId;
    // false: a valid standard COB-ID in CiA 301's restricted ranges (NMT, SYNC/EMCY
    // low ids, SDO, LSS, NMT error control) is refused 06090030 (P9).  true: any
    // 11-bit COB-ID is accepted, for a device whose manual allows any.
    bool allow_restricted_cob_ids = false;
};

class PdoEngine {
public:
    using SendFn = std::function<void(const can::Frame&)>;
    // emcy(code, active): active = an error occurred, false = it went away.
    using EmcyFn = std::function<void(std::uint16_t code, bool active)>;

    PdoEngine(PdoObjectAccess& objects, Clock& clock, PdoEngineOptions options, SendFn send,
              EmcyFn emcy = {});

    // ---- object dictionary side ------------------------------------------
    bool owns(std::uint16_t index) const;
    // SDO write to a PDO parameter: 0 or the abort code.
    std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data);
    std::uint32_t read(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t>& out) const;
    // Loads a stored value (EDS default, saved parameters) without the
    // "no change while valid" procedure checks; value checks still apply.
    std::uint32_t load(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data);
    // Restores the predefined connection set (reset communication).
    void reset_communication();

    // ---- runtime ---------------------------------------------------------
    void set_operational(bool operational);
    // The COB-ID SYNC is consumed on (0x1005 bits 0-10, standard frame); takes effect at once.
    void set_sync_cob_id(std::uint32_t cob_id);
    bool operational() const;
    // Routes a frame (RPDO data, RTR on a TPDO, SYNC); returns true when used.
    // A data frame on one of our own TPDO COB-IDs is a node-id collision (N15).
    bool on_frame(const can::Frame& f);
    // The application changed index:sub: event-driven TPDOs mapping it are sent
    // (subject to the inhibit time), acyclic synchronous ones at the next SYNC.
    void notify_change(std::uint16_t index, std::uint8_t sub);
    // Requests TPDO n (1-based) as an event.
    void trigger_tpdo(unsigned n);
    // Runs timers (inhibit, event timer, RPDO timeouts) at `now`; returns the
    // next deadline or -1.
    Nanos process(Nanos now);

    // RPDO n applied / timed out (P11: the simulator's loss-of-command reaction).
    std::function<void(unsigned n)> on_rpdo;
    CallbackSlot<void(unsigned n)> on_rpdo_timeout;

    struct Counters {
        std::uint64_t tpdo_sent = 0, rpdo_applied = 0, rpdo_ignored = 0, rpdo_length_errors = 0,
                      sync_received = 0, sync_errors = 0, rtr_ignored = 0, collisions = 0;
    };
    Counters counters() const;
    // The compiled mapping of a PDO (empty when not complete).
    std::vector<PdoMapEntry> mapping(bool tpdo, unsigned n) const;
    std::uint32_t cob_id(bool tpdo, unsigned n) const;

private:
    struct Pdo {
        bool tpdo = false;
        unsigned number = 0;
        std::uint32_t cob = kPdoInvalid;
        std::uint8_t type = 255;
        std::uint16_t inhibit = 0;
        std::uint8_t compat = 0;
        std::uint16_t event_timer = 0;
        std::uint8_t sync_start = 0;
        std::uint8_t count = 0;  // mapping sub0
        std::array<std::uint32_t, 64> words{};
        PdoLayout layout;
        bool complete = false;  // layout usable
        // runtime
        bool pending = false;
        Nanos last_sent = -1;
        Nanos timer_due = -1;
        unsigned sync_count = 0;
        bool sync_started = false;
        bool have_buffer = false;
        can::Frame buffer;
        bool len_error = false;
        Nanos rx_deadline = -1;
        bool valid() const { return !(cob & kPdoInvalid); }
        std::uint32_t can_id() const { return cob & can::kMaxExtendedId; }
        bool extended() const { return cob & kPdoExtended; }
    };
    struct Write {
        std::uint16_t index;
        std::uint8_t sub;
        std::uint8_t bits;
        std::uint64_t raw;
    };
    struct Out {
        std::vector<Write> writes;
        // TPDOs due: their mapping as it was when they fell due, and the frame's
        // id; the objects are read (and the frames packed and sent) in flush().
        struct Tpdo {
            PdoLayout layout;
            can::Frame frame;
        };
        std::vector<Tpdo> tpdos;
        std::vector<std::pair<std::uint16_t, bool>> emcy;
        std::vector<unsigned> rpdo_applied, rpdo_timeout;
    };
    std::uint32_t write_locked(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                               bool strict);
    Pdo* find(std::uint16_t index, bool& is_map);
    const Pdo* find(std::uint16_t index, bool& is_map) const;
    void rebuild(Pdo& p);
    std::uint32_t validate_map_count(const Pdo& p, unsigned n, bool strict) const;
    void send_tpdo(Pdo& p, Nanos now, Out& out);
    void apply_rpdo(Pdo& p, const can::Frame& f, Out& out);
    void handle_sync(const can::Frame& f, Nanos now, Out& out);
    void flush(Out& out);
    void defaults(Pdo& p);

    PdoObjectAccess& objects_;
    Clock& clock_;
    PdoEngineOptions opt_;
    SendFn send_;
    EmcyFn emcy_;
    mutable std::mutex m_;
    std::vector<Pdo> rpdos_, tpdos_;
    bool operational_ = false;
    Nanos last_sync_ = -1;
    bool sync_error_ = false;
    bool collision_ = false;
    Counters counters_;
};

}  // namespace motorbus::canopen

// PDO: bit-exact pack/unpack of mapped values (CiA 301: entries follow each
// other LSB first, any bit offset, little-endian), the mapping/communication
// parameter encodings, reading and writing a remote node's PDO configuration
// over SDO, and host-side PDO senders/receivers.
#pragma once
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/sdo_access.hpp"
#include "motorbus/runtime/callback_slot.hpp"

namespace motorbus::canopen {

struct PdoMapEntry {
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    std::uint8_t bits = 0;  // 1..64
    bool is_signed = false;  // only affects unpack_signed; not on the wire

    std::uint32_t mapping_word() const {
        return (std::uint32_t(index) << 16) | (std::uint32_t(sub) << 8) | bits;
    }
    static PdoMapEntry from_mapping_word(std::uint32_t w) {
        return {static_cast<std::uint16_t>(w >> 16), static_cast<std::uint8_t>(w >> 8),
                static_cast<std::uint8_t>(w), false};
    }
    // Dummy entries (index 0x0001-0x0007) reserve space in an RPDO.
    bool is_dummy() const { return index >= 0x0001 && index <= 0x0007; }
    bool operator==(const PdoMapEntry& o) const {
        return index == o.index && sub == o.sub && bits == o.bits;
    }
};

// A mapping compiled for speed: offsets and masks precomputed, so pack and
// unpack are a handful of shifts on one 64-bit word.
class PdoLayout {
public:
    static constexpr std::size_t kMaxEntries = 64;
    PdoLayout() = default;
    // Throws InvalidArgument when an entry has 0 or > 64 bits, or the total
    // exceeds 64 bits (one classic CAN frame).
    explicit PdoLayout(std::span<const PdoMapEntry> entries);

    std::size_t size() const { return n_; }
    const PdoMapEntry& entry(std::size_t i) const { return entries_[i]; }
    std::vector<PdoMapEntry> entries() const { return {entries_.begin(), entries_.begin() + n_}; }
    unsigned total_bits() const { return total_bits_; }
    unsigned byte_length() const { return (total_bits_ + 7) / 8; }
    unsigned offset(std::size_t i) const { return offset_[i]; }

    // Packs values[0..size) (only the low `bits` of each are used) into out;
    // returns the frame length.  out must hold 8 bytes.
    unsigned pack(const std::uint64_t* values, std::uint8_t* out) const {
        std::uint64_t acc = 0;
        for (std::size_t i = 0; i < n_; ++i) acc |= (values[i] & mask_[i]) << offset_[i];
        store_le(acc, out);
        return byte_length();
    }
    // Unpacks; returns false (values untouched) when len < byte_length().
    bool unpack(const std::uint8_t* data, std::size_t len, std::uint64_t* values) const {
        if (len < byte_length()) return false;
        const std::uint64_t acc = load_le(data, byte_length());
        for (std::size_t i = 0; i < n_; ++i) values[i] = (acc >> offset_[i]) & mask_[i];
        return true;
    }
    // Sign-extends a raw value of entry i when it is signed.
    std::int64_t to_signed(std::size_t i, std::uint64_t raw) const {
        const unsigned b = entries_[i].bits;
        if (b >= 64) return static_cast<std::int64_t>(raw);
        const std::uint64_t sign = std::uint64_t(1) << (b - 1);
        return static_cast<std::int64_t>((raw ^ sign) - sign);
    }

    std::vector<std::uint8_t> pack(std::span<const std::uint64_t> values) const;
    std::vector<std::uint64_t> unpack(std::span<const std::uint8_t> data) const;

private:
    static void store_le(std::uint64_t v, std::uint8_t* out) {
        for (int i = 0; i < 8; ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * i));
    }
    static std::uint64_t load_le(const std::uint8_t* p, unsigned n) {
        std::uint64_t v = 0;
        for (unsigned i = 0; i < n; ++i) v |= std::uint64_t(p[i]) << (8 * i);
        return v;
    }
    std::array<PdoMapEntry, kMaxEntries> entries_{};
    std::array<std::uint64_t, kMaxEntries> mask_{};
    std::array<std::uint8_t, kMaxEntries> offset_{};
    std::size_t n_ = 0;
    unsigned total_bits_ = 0;
};

// Bits of the COB-ID entry (sub 1).
constexpr std::uint32_t kPdoInvalid = 0x80000000u;   // bit 31: PDO does not exist / disabled
constexpr std::uint32_t kPdoNoRtr = 0x40000000u;     // bit 30: RTR not allowed
constexpr std::uint32_t kPdoExtended = 0x20000000u;  // bit 29: 29-bit id

// Transmission types (sub 2).
constexpr std::uint8_t kPdoSyncAcyclic = 0;
constexpr std::uint8_t kPdoSyncCyclicMax = 240;
constexpr std::uint8_t kPdoRtrSync = 252;
constexpr std::uint8_t kPdoRtrEvent = 253;
constexpr std::uint8_t kPdoEventManufacturer = 254;
constexpr std::uint8_t kPdoEventProfile = 255;
inline bool is_sync_type(std::uint8_t t) { return t <= kPdoSyncCyclicMax; }
inline bool is_event_type(std::uint8_t t) { return t >= kPdoEventManufacturer; }

// Index of the communication / mapping parameter of PDO `number` (1-512).
std::uint16_t pdo_comm_index(bool tpdo, unsigned number);
std::uint16_t pdo_map_index(bool tpdo, unsigned number);
// The predefined connection set's COB-ID for PDO 1-4 of `node`.
std::uint32_t default_pdo_cob_id(bool tpdo, unsigned number, std::uint8_t node);

// A PDO's full configuration as a host writes or reads it.  Fields left empty
// are not written (and read back as they are on the device).
struct PdoConfig {
    bool tpdo = true;       // transmit PDO of the device (0x18xx/0x1Axx)
    unsigned number = 1;    // 1-512
    std::optional<std::uint32_t> cob_id;         // bits 0-28 + 29 (ext); 30 no-RTR
    bool enabled = true;                          // bit 31 cleared at the end
    std::optional<std::uint8_t> transmission_type;
    std::optional<std::uint16_t> inhibit_100us;   // sub 3
    std::optional<std::uint16_t> event_timer_ms;  // sub 5
    std::optional<std::uint8_t> sync_start;       // sub 6 (TPDO only)
    std::optional<std::vector<PdoMapEntry>> mapping;
};

enum class PdoProcedure {
    // CiA 301: disable (COB-ID bit 31), parameters, clear sub0, entries,
    // set sub0, enable.  Works on every conforming device.
    Cia301,
    // Writes in the order COB-ID, parameters, sub0 = n, entries, without the
    // disable/enable steps: some devices' manuals document exactly this
    // sequence, and those devices accept it.
    Direct,
};
const char* to_string(PdoProcedure p);                                 // "cia301", "direct"
std::optional<PdoProcedure> pdo_procedure_from_name(std::string_view name);  // nullopt if unknown

// Writes `cfg` to `node` over `sdo`; SDO errors propagate (SdoAbortError etc.).
void write_pdo(SdoAccess& sdo, std::uint8_t node, const PdoConfig& cfg,
               PdoProcedure procedure = PdoProcedure::Cia301);
// Reads COB-ID, transmission type, inhibit, event timer and the mapping.
// Optional subs the device lacks (3, 5, 6) are left empty.
PdoConfig read_pdo(SdoAccess& sdo, std::uint8_t node, bool tpdo, unsigned number);

// Host side: receives a device's TPDO, unpacks it and keeps the latest values.
class PdoReceiver {
public:
    PdoReceiver(can::Bus& bus, std::uint32_t cob_id, std::vector<PdoMapEntry> mapping);
    ~PdoReceiver();
    PdoReceiver(const PdoReceiver&) = delete;
    PdoReceiver& operator=(const PdoReceiver&) = delete;

    const PdoLayout& layout() const { return layout_; }
    std::uint32_t cob_id() const { return cob_id_; }
    // Latest raw values (empty before the first valid frame).
    std::vector<std::uint64_t> values() const;
    // Raw value of the first entry mapping index:sub.
    std::optional<std::uint64_t> value(std::uint16_t index, std::uint8_t sub) const;
    std::uint64_t received() const;
    std::uint64_t short_frames() const { return short_.load(); }
    // Waits until a frame newer than `after_count` arrives; returns the count.
    std::optional<std::uint64_t> wait_newer(std::uint64_t after_count, std::chrono::nanoseconds timeout);
    // Asks the device for the PDO with an RTR frame.
    void request();

    CallbackSlot<void(const std::vector<std::uint64_t>&, Nanos timestamp)> on_receive;

private:
    void on_frame(const can::Frame& f);
    can::Bus& bus_;
    std::uint32_t cob_id_;
    PdoLayout layout_;
    mutable std::mutex m_;
    std::condition_variable cv_;
    std::vector<std::uint64_t> values_;
    std::uint64_t count_ = 0;
    std::atomic<std::uint64_t> short_{0};
    can::SubscriptionId sub_ = 0;
};

// Host side: packs values and sends them as a device's RPDO.
class PdoSender {
public:
    PdoSender(can::Bus& bus, std::uint32_t cob_id, std::vector<PdoMapEntry> mapping);
    const PdoLayout& layout() const { return layout_; }
    // Throws InvalidArgument when the count of values differs from the mapping.
    void send(std::span<const std::uint64_t> values,
              std::chrono::nanoseconds timeout = std::chrono::seconds(1));

private:
    can::Bus& bus_;
    std::uint32_t cob_id_;
    PdoLayout layout_;
};

}  // namespace motorbus::canopen

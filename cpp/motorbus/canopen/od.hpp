// The object dictionary (CiA 301 §7.4): the variables a node exposes over SDO
// and PDO, addressed by 16-bit index and 8-bit sub-index (or by name).
//
//   ObjectDictionary od;
//   od.add_variable({.index = 0x6001, .name = "Controller status",
//                    .type = DataType::Unsigned8, .access = Access::RO,
//                    .pdo_mappable = true, .default_value = std::uint64_t{0}});
//   auto rec = od.add_record(0x1018, "Identity object");
//   od.add_member(0x1018, {.subindex = 1, .name = "Vendor-ID", .type = DataType::Unsigned32});
//   od.at(0x6001, 0)->set_u64(8);            // the device updates its own value
//   std::uint32_t code = od.at(0x2003, 0)->remote_write(bytes);  // what the SDO server does
//
// Threading: every Variable guards its value with its own mutex, so the SDO
// server, PDO services and the application may read and write concurrently.
// Variables are shared_ptr-owned and never move, so a pointer obtained once
// (e.g. by a PDO mapping) stays valid while the dictionary lives.  Adding
// objects while the dictionary is being served is allowed (guarded by a
// shared mutex) but removing them is not offered.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/datatypes.hpp"

namespace motorbus::canopen {

// CiA 306 access types.  rwr/rww are rw with a PDO direction hint.
enum class Access : std::uint8_t { RO, WO, RW, RWR, RWW, Const };
bool readable(Access a);
bool writable(Access a);
const char* access_name(Access a);                       // "ro", "wo", "rw", "rwr", "rww", "const"
std::optional<Access> access_from_name(std::string_view);  // case-insensitive

enum class ObjectCode : std::uint8_t {
    Null = 0,
    Domain = 2,
    DefType = 5,
    DefStruct = 6,
    Var = 7,
    Array = 8,
    Record = 9,
};

class Variable;

// Called on a remote (SDO) read before the value is returned.  May replace
// `value` (e.g. fetch a live reading).  Return 0, or an abort code to refuse.
using ReadHook = std::function<std::uint32_t(const Variable& var, Bytes& value)>;
// Called on a remote (SDO/PDO) write before the value is committed, with the
// size and range already checked.  Return 0 to accept, or an abort code (the
// value is then left unchanged).  E.g. 0x08000022 "present device state".
using WriteHook = std::function<std::uint32_t(const Variable& var, std::span<const std::uint8_t> data)>;
// Streams a large domain on upload without materialising it: fill `chunk`
// with up to `max` bytes starting at `offset`, set `last` on the final chunk.
// Return 0, or an abort code (which aborts the transfer mid-stream).
using ChunkReadHook = std::function<std::uint32_t(const Variable& var, std::size_t offset,
                                                  std::size_t max, Bytes& chunk, bool& last)>;
// Told after a value changed (remote write or local set); runs on the writer's thread.
using ChangeListener = std::function<void(const Variable& var)>;

// What a variable is; aggregate so callers can use designated initializers.
struct VariableSpec {
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    std::string name{};
    DataType type = DataType::Unsigned32;
    Access access = Access::RW;
    bool pdo_mappable = false;
    std::optional<Scalar> low_limit{};   // numeric types only; inclusive
    std::optional<Scalar> high_limit{};  // numeric types only; inclusive
    // Initial value: a number for numeric types, bytes (or text) for strings/domains.
    std::variant<std::monostate, std::int64_t, std::uint64_t, double, Bytes> default_value{};
    // For strings and domains: the largest accepted value (0 = the dictionary's
    // max_variable_size).  Ignored for fixed-size types.
    std::size_t max_size = 0;
    // EDS: the DefaultValue string was "$NODEID+0x180" etc.; kept so the EDS
    // round-trips.  Empty when the default is a plain literal.
    std::string default_expr{};
    // A second size a remote write may carry (0 = none), for a device whose manual
    // lists an object with two sizes (one manual gives an object UNSIGNED8 in one
    // table and UNSIGNED32 in another).  Such a write is narrowed or widened to the type's
    // size first (bytes beyond it must be zero: 0x06090031 otherwise).
    std::size_t alt_size = 0;
};

class Variable : public std::enable_shared_from_this<Variable> {
public:
    explicit Variable(VariableSpec spec, std::size_t dictionary_max_size);

    const VariableSpec& spec() const { return spec_; }
    std::uint16_t index() const { return spec_.index; }
    std::uint8_t subindex() const { return spec_.subindex; }
    const std::string& name() const { return spec_.name; }
    DataType type() const { return spec_.type; }
    Access access() const { return spec_.access; }
    bool pdo_mappable() const { return spec_.pdo_mappable; }
    // Fixed size in bytes, or 0 for strings and domains.
    std::size_t size() const { return type_size(spec_.type); }
    // The largest value a write may carry (fixed size, or max_size for strings/domains).
    std::size_t max_size() const { return max_size_; }
    const Bytes& default_bytes() const { return default_; }

    // --- local access (the device/application itself; no access check, no hooks) ---
    Bytes get() const;
    // True when the stored value is exactly `data` (compared in place, no copy).
    bool holds(std::span<const std::uint8_t> data) const;
    // Replaces the value after checking size and limits; throws InvalidArgument
    // with the CiA reason otherwise.  Tells the change listeners.
    void set(std::span<const std::uint8_t> data);
    // As set() but returns the abort code instead of throwing (0 = stored).
    std::uint32_t try_set(std::span<const std::uint8_t> data);
    // Numeric convenience; throws InvalidArgument if the type is not numeric or
    // the number does not fit / is outside the limits.
    Scalar get_scalar() const;
    std::int64_t get_i64() const;
    std::uint64_t get_u64() const;
    double get_f64() const;
    void set_scalar(const Scalar& v);
    void set_i64(std::int64_t v) { set_scalar(v); }
    void set_u64(std::uint64_t v) { set_scalar(v); }
    void set_f64(double v) { set_scalar(v); }
    std::string get_string() const;  // raw bytes as text (strings/domains)
    void reset_to_default();

    // --- remote access (SDO server, RPDO/TPDO): access check, size, limits, hooks ---
    // Returns 0 and the value, or the CiA 301 abort code.
    std::uint32_t remote_read(Bytes& out) const;
    // Checks writable, size (0x06070012/13 or 0x06070010), limits (0x06090031/32),
    // then the write hook, then commits and tells listeners.  Returns 0 or the code.
    std::uint32_t remote_write(std::span<const std::uint8_t> data);
    // Only the checks of remote_write (no hook, no commit): used by the SDO server
    // to refuse a segmented/block download at initiate time, before buffering.
    std::uint32_t check_size_for_write(std::size_t size) const;
    // The values a write may carry: the limits where set, else the whole range of an
    // integer type (BOOLEAN 0..1); nullopt for reals, strings and domains.  What a
    // host shows as an object's range without a table of type sizes of its own.
    std::optional<std::pair<Scalar, Scalar>> value_range() const;

    // --- hooks (may be set at any time; calls use a snapshot) ---
    void set_read_hook(ReadHook h);
    void set_write_hook(WriteHook h);
    void set_chunk_read_hook(ChunkReadHook h);
    ChunkReadHook chunk_read_hook() const;
    // True when any read/write/chunk hook or change listener is set, i.e. a
    // remote access may run application code.
    bool has_hooks() const;
    // Returns a handle for remove_change_listener().
    std::uint64_t add_change_listener(ChangeListener cb);
    void remove_change_listener(std::uint64_t handle);

private:
    friend class ObjectDictionary;
    std::uint32_t validate(std::span<const std::uint8_t> data) const;
    void commit(std::span<const std::uint8_t> data);
    void notify() const;

    VariableSpec spec_;
    std::size_t max_size_;
    Bytes default_;
    mutable std::mutex mutex_;
    Bytes value_;
    ReadHook read_hook_;
    WriteHook write_hook_;
    ChunkReadHook chunk_hook_;
    std::vector<std::pair<std::uint64_t, ChangeListener>> listeners_;
    std::uint64_t next_listener_ = 1;
};

using VariablePtr = std::shared_ptr<Variable>;

// One index of the dictionary: a VAR (only sub-index 0), an ARRAY or a RECORD.
struct Object {
    std::uint16_t index = 0;
    std::string name;
    ObjectCode code = ObjectCode::Var;
    std::map<std::uint8_t, VariablePtr> subs;
    VariablePtr sub(std::uint8_t s) const {
        auto it = subs.find(s);
        return it == subs.end() ? nullptr : it->second;
    }
};

// Information for the EDS [FileInfo]/[DeviceInfo] sections.
struct DeviceInfo {
    std::string file_name;
    std::string description;
    std::string vendor_name;
    std::uint32_t vendor_number = 0;
    std::string product_name;
    std::uint32_t product_number = 0;
    std::uint32_t revision_number = 0;
    std::string order_code;
    std::vector<unsigned> baud_rates_kbit{125, 250, 500, 1000};
    bool simple_boot_up_slave = true;
    unsigned granularity = 8;
    unsigned nr_rx_pdo = 0;
    unsigned nr_tx_pdo = 0;
    bool lss_supported = false;
};

class ObjectDictionary {
public:
    ObjectDictionary() = default;
    ObjectDictionary(const ObjectDictionary&) = delete;
    ObjectDictionary& operator=(const ObjectDictionary&) = delete;

    // Adds a VAR object at spec.index (sub-index forced to 0).  Throws
    // InvalidArgument when the index exists, the limits do not fit the type,
    // low > high, or the default is outside the limits.
    VariablePtr add_variable(VariableSpec spec);
    // Adds an ARRAY or RECORD (members added with add_member).  A RECORD/ARRAY
    // gets its sub-index 0 "Highest sub-index supported" (UNSIGNED8, ro)
    // automatically, kept equal to the largest member.
    Object& add_record(std::uint16_t index, std::string name, ObjectCode code = ObjectCode::Record);
    Object& add_array(std::uint16_t index, std::string name) {
        return add_record(index, std::move(name), ObjectCode::Array);
    }
    // Adds a member to an ARRAY/RECORD (spec.index is overwritten by `index`).
    // Adding sub-index 0 explicitly replaces the automatic one.
    VariablePtr add_member(std::uint16_t index, VariableSpec spec);

    // nullptr when absent.
    VariablePtr find(std::uint16_t index, std::uint8_t subindex) const;
    // Throws InvalidArgument naming the missing object.
    VariablePtr at(std::uint16_t index, std::uint8_t subindex) const;
    // "Name" for a VAR, "Record name.Member name" for a member, or "0x6001",
    // "0x1018:1", "1018sub1", all case-sensitive.  nullptr when absent.
    VariablePtr find(std::string_view name) const;
    VariablePtr at(std::string_view name) const;
    // 0 when (index, sub) exists, else 0x06020000 or 0x06090011 (the SDO answer).
    std::uint32_t lookup(std::uint16_t index, std::uint8_t subindex, VariablePtr& out) const;

    // A copy of one object's description (nullopt when absent).
    std::optional<Object> object(std::uint16_t index) const;
    std::vector<std::uint16_t> indices() const;
    std::size_t size() const;  // number of objects

    // Largest string/domain value accepted by default (bounded buffers).
    std::size_t max_variable_size() const { return max_variable_size_; }
    void set_max_variable_size(std::size_t n) { max_variable_size_ = n; }

    DeviceInfo& device_info() { return info_; }
    const DeviceInfo& device_info() const { return info_; }
    // The node-id $NODEID expressions were (or will be) evaluated with (0 = none).
    std::uint8_t node_id() const { return node_id_; }
    void set_node_id(std::uint8_t id) { node_id_ = id; }

private:
    mutable std::shared_mutex mutex_;
    std::map<std::uint16_t, Object> objects_;
    std::map<std::string, VariablePtr, std::less<>> by_name_;
    std::size_t max_variable_size_ = 1 << 20;
    DeviceInfo info_;
    std::uint8_t node_id_ = 0;
};

}  // namespace motorbus::canopen

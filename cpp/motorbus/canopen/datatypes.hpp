// CiA 301 basic data types: codes, sizes and little-endian encoding.
//
// Values live in the object dictionary as raw little-endian bytes, exactly as
// they travel in SDO and PDO frames, so a transfer never converts twice.  The
// helpers here turn those bytes into numbers (and back) for typed access.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace motorbus::canopen {

using Bytes = std::vector<std::uint8_t>;

// Codes as in CiA 301 table 44 (they are also the EDS "DataType" values).
enum class DataType : std::uint16_t {
    Boolean = 0x01,
    Integer8 = 0x02,
    Integer16 = 0x03,
    Integer32 = 0x04,
    Unsigned8 = 0x05,
    Unsigned16 = 0x06,
    Unsigned32 = 0x07,
    Real32 = 0x08,
    VisibleString = 0x09,
    OctetString = 0x0A,
    UnicodeString = 0x0B,
    TimeOfDay = 0x0C,
    TimeDifference = 0x0D,
    Domain = 0x0F,
    Integer24 = 0x10,
    Real64 = 0x11,
    Integer40 = 0x12,
    Integer48 = 0x13,
    Integer56 = 0x14,
    Integer64 = 0x15,
    Unsigned24 = 0x16,
    Unsigned40 = 0x18,
    Unsigned48 = 0x19,
    Unsigned56 = 0x1A,
    Unsigned64 = 0x1B,
};

// Bytes a value of `t` occupies; 0 for the variable-length types (strings, domain).
std::size_t type_size(DataType t);
bool is_known_type(std::uint16_t code);
bool is_signed(DataType t);    // Integer*
bool is_unsigned(DataType t);  // Boolean, Unsigned*
bool is_real(DataType t);      // Real32, Real64
bool is_variable_length(DataType t);
bool is_numeric(DataType t);   // signed, unsigned or real
const char* type_name(DataType t);  // "UNSIGNED32", "VISIBLE_STRING", ...
// A type from its CiA name ("UNSIGNED32") or the short forms the Python API
// documents ("u32", "i8", "f64", "str", "bytes", "bool"); case-insensitive.
std::optional<DataType> data_type_from_name(std::string_view name);

// A number as the dictionary understands it: signed types decode to int64,
// unsigned (and Boolean) to uint64, reals to double.
using Scalar = std::variant<std::int64_t, std::uint64_t, double>;

// Decodes `raw` (exactly type_size(t) bytes) as a number; nullopt when the
// type is not numeric or the size is wrong.
std::optional<Scalar> decode_scalar(DataType t, std::span<const std::uint8_t> raw);

// Encodes `v` as type `t`.  Returns nullopt when `v` does not fit (e.g. -1 as
// Unsigned8, 300 as Unsigned8) or `t` is not numeric.
std::optional<Bytes> encode_scalar(DataType t, const Scalar& v);

// -1 / 0 / +1, comparing numerically across the three representations.
int compare_scalars(const Scalar& a, const Scalar& b);
std::string scalar_to_string(const Scalar& v);

// Little-endian helpers for codecs.
inline std::uint16_t get_le16(const std::uint8_t* p) {
    return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get_le32(const std::uint8_t* p) {
    return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
           (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
inline void put_le16(std::uint8_t* p, std::uint16_t v) {
    p[0] = static_cast<std::uint8_t>(v);
    p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_le32(std::uint8_t* p, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace motorbus::canopen

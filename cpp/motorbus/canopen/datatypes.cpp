#include "motorbus/canopen/datatypes.hpp"

#include <cctype>
#include <utility>

#include <cmath>
#include <cstring>
#include <limits>

namespace motorbus::canopen {

std::size_t type_size(DataType t) {
    switch (t) {
        case DataType::Boolean:
        case DataType::Integer8:
        case DataType::Unsigned8: return 1;
        case DataType::Integer16:
        case DataType::Unsigned16: return 2;
        case DataType::Integer24:
        case DataType::Unsigned24: return 3;
        case DataType::Integer32:
        case DataType::Unsigned32:
        case DataType::Real32: return 4;
        case DataType::Integer40:
        case DataType::Unsigned40: return 5;
        case DataType::Integer48:
        case DataType::Unsigned48:
        case DataType::TimeOfDay:
        case DataType::TimeDifference: return 6;
        case DataType::Integer56:
        case DataType::Unsigned56: return 7;
        case DataType::Integer64:
        case DataType::Unsigned64:
        case DataType::Real64: return 8;
        case DataType::VisibleString:
        case DataType::OctetString:
        case DataType::UnicodeString:
        case DataType::Domain: return 0;
    }
    return 0;
}

bool is_known_type(std::uint16_t code) {
    switch (code) {
        case 0x01: case 0x02: case 0x03: case 0x04: case 0x05: case 0x06: case 0x07: case 0x08:
        case 0x09: case 0x0A: case 0x0B: case 0x0C: case 0x0D: case 0x0F: case 0x10: case 0x11:
        case 0x12: case 0x13: case 0x14: case 0x15: case 0x16: case 0x18: case 0x19: case 0x1A:
        case 0x1B: return true;
        default: return false;
    }
}

bool is_signed(DataType t) {
    switch (t) {
        case DataType::Integer8: case DataType::Integer16: case DataType::Integer24:
        case DataType::Integer32: case DataType::Integer40: case DataType::Integer48:
        case DataType::Integer56: case DataType::Integer64: return true;
        default: return false;
    }
}

bool is_unsigned(DataType t) {
    switch (t) {
        case DataType::Boolean: case DataType::Unsigned8: case DataType::Unsigned16:
        case DataType::Unsigned24: case DataType::Unsigned32: case DataType::Unsigned40:
        case DataType::Unsigned48: case DataType::Unsigned56: case DataType::Unsigned64: return true;
        default: return false;
    }
}

bool is_real(DataType t) { return t == DataType::Real32 || t == DataType::Real64; }
bool is_variable_length(DataType t) { return type_size(t) == 0; }
bool is_numeric(DataType t) { return is_signed(t) || is_unsigned(t) || is_real(t); }

const char* type_name(DataType t) {
    switch (t) {
        case DataType::Boolean: return "BOOLEAN";
        case DataType::Integer8: return "INTEGER8";
        case DataType::Integer16: return "INTEGER16";
        case DataType::Integer32: return "INTEGER32";
        case DataType::Unsigned8: return "UNSIGNED8";
        case DataType::Unsigned16: return "UNSIGNED16";
        case DataType::Unsigned32: return "UNSIGNED32";
        case DataType::Real32: return "REAL32";
        case DataType::VisibleString: return "VISIBLE_STRING";
        case DataType::OctetString: return "OCTET_STRING";
        case DataType::UnicodeString: return "UNICODE_STRING";
        case DataType::TimeOfDay: return "TIME_OF_DAY";
        case DataType::TimeDifference: return "TIME_DIFFERENCE";
        case DataType::Domain: return "DOMAIN";
        case DataType::Integer24: return "INTEGER24";
        case DataType::Real64: return "REAL64";
        case DataType::Integer40: return "INTEGER40";
        case DataType::Integer48: return "INTEGER48";
        case DataType::Integer56: return "INTEGER56";
        case DataType::Integer64: return "INTEGER64";
        case DataType::Unsigned24: return "UNSIGNED24";
        case DataType::Unsigned40: return "UNSIGNED40";
        case DataType::Unsigned48: return "UNSIGNED48";
        case DataType::Unsigned56: return "UNSIGNED56";
        case DataType::Unsigned64: return "UNSIGNED64";
    }
    return "UNKNOWN";
}

std::optional<Scalar> decode_scalar(DataType t, std::span<const std::uint8_t> raw) {
    const std::size_t n = type_size(t);
    if (n == 0 || raw.size() != n || !is_numeric(t)) return std::nullopt;
    std::uint64_t u = 0;
    for (std::size_t i = 0; i < n; ++i) u |= static_cast<std::uint64_t>(raw[i]) << (8 * i);
    if (t == DataType::Real32) {
        float f;
        auto u32 = static_cast<std::uint32_t>(u);
        std::memcpy(&f, &u32, 4);
        return Scalar{static_cast<double>(f)};
    }
    if (t == DataType::Real64) {
        double d;
        std::memcpy(&d, &u, 8);
        return Scalar{d};
    }
    if (is_signed(t)) {
        if (n < 8 && (u >> (8 * n - 1)) & 1) u |= ~std::uint64_t{0} << (8 * n);  // sign-extend
        return Scalar{static_cast<std::int64_t>(u)};
    }
    return Scalar{u};
}

std::optional<Bytes> encode_scalar(DataType t, const Scalar& v) {
    const std::size_t n = type_size(t);
    if (n == 0 || !is_numeric(t)) return std::nullopt;
    std::uint64_t u = 0;
    if (is_real(t)) {
        double d;
        if (auto p = std::get_if<double>(&v)) d = *p;
        else if (auto p = std::get_if<std::int64_t>(&v)) d = static_cast<double>(*p);
        else d = static_cast<double>(std::get<std::uint64_t>(v));
        if (t == DataType::Real32) {
            float f = static_cast<float>(d);
            if (std::isfinite(d) && !std::isfinite(f)) return std::nullopt;
            std::uint32_t u32;
            std::memcpy(&u32, &f, 4);
            u = u32;
        } else {
            std::memcpy(&u, &d, 8);
        }
    } else {
        const unsigned bits = static_cast<unsigned>(8 * n);
        if (auto p = std::get_if<double>(&v)) {
            if (!std::isfinite(*p) || std::trunc(*p) != *p) return std::nullopt;
            if (is_signed(t)) {
                if (*p < -9.2233720368547758e18 || *p >= 9.2233720368547758e18) return std::nullopt;
                return encode_scalar(t, Scalar{static_cast<std::int64_t>(*p)});
            }
            if (*p < 0 || *p >= 1.8446744073709552e19) return std::nullopt;
            return encode_scalar(t, Scalar{static_cast<std::uint64_t>(*p)});
        }
        if (is_signed(t)) {
            std::int64_t s;
            if (auto p = std::get_if<std::int64_t>(&v)) s = *p;
            else {
                auto x = std::get<std::uint64_t>(v);
                if (x > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
                    return std::nullopt;
                s = static_cast<std::int64_t>(x);
            }
            if (bits < 64) {
                const std::int64_t lo = -(std::int64_t{1} << (bits - 1));
                const std::int64_t hi = (std::int64_t{1} << (bits - 1)) - 1;
                if (s < lo || s > hi) return std::nullopt;
            }
            u = static_cast<std::uint64_t>(s);
        } else {
            if (auto p = std::get_if<std::int64_t>(&v)) {
                if (*p < 0) return std::nullopt;
                u = static_cast<std::uint64_t>(*p);
            } else {
                u = std::get<std::uint64_t>(v);
            }
            const std::uint64_t max = t == DataType::Boolean ? 1
                                      : bits < 64 ? (std::uint64_t{1} << bits) - 1
                                                  : ~std::uint64_t{0};
            if (u > max) return std::nullopt;
        }
    }
    Bytes out(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<std::uint8_t>(u >> (8 * i));
    return out;
}

int compare_scalars(const Scalar& a, const Scalar& b) {
    auto cmp = [](auto x, auto y) { return x < y ? -1 : (y < x ? 1 : 0); };
    if (std::holds_alternative<double>(a) || std::holds_alternative<double>(b)) {
        auto as_d = [](const Scalar& s) {
            return std::visit([](auto v) { return static_cast<double>(v); }, s);
        };
        return cmp(as_d(a), as_d(b));
    }
    if (auto ai = std::get_if<std::int64_t>(&a)) {
        if (auto bi = std::get_if<std::int64_t>(&b)) return cmp(*ai, *bi);
        if (*ai < 0) return -1;
        return cmp(static_cast<std::uint64_t>(*ai), std::get<std::uint64_t>(b));
    }
    auto au = std::get<std::uint64_t>(a);
    if (auto bu = std::get_if<std::uint64_t>(&b)) return cmp(au, *bu);
    auto bi = std::get<std::int64_t>(b);
    if (bi < 0) return 1;
    return cmp(au, static_cast<std::uint64_t>(bi));
}

std::string scalar_to_string(const Scalar& v) {
    return std::visit(
        [](auto x) -> std::string {
            if constexpr (std::is_same_v<decltype(x), double>) {
                char buf[40];
                std::snprintf(buf, sizeof buf, "%.17g", x);
                return buf;
            } else {
                return std::to_string(x);
            }
        },
        v);
}

std::optional<DataType> data_type_from_name(std::string_view name) {
    std::string u;
    for (char c : name) u.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    static const std::pair<const char*, DataType> aliases[] = {
        {"BOOL", DataType::Boolean},       {"I8", DataType::Integer8},     {"I16", DataType::Integer16},
        {"I32", DataType::Integer32},      {"I64", DataType::Integer64},   {"U8", DataType::Unsigned8},
        {"U16", DataType::Unsigned16},     {"U32", DataType::Unsigned32},  {"U64", DataType::Unsigned64},
        {"F32", DataType::Real32},         {"F64", DataType::Real64},      {"STR", DataType::VisibleString},
        {"BYTES", DataType::OctetString},
    };
    for (auto& [a, t] : aliases)
        if (u == a) return t;
    for (unsigned c = 1; c <= 0x1B; ++c)
        if (is_known_type(static_cast<std::uint16_t>(c)) && u == type_name(static_cast<DataType>(c)))
            return static_cast<DataType>(c);
    return std::nullopt;
}

}  // namespace motorbus::canopen

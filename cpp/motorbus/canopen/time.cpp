#include "motorbus/canopen/time.hpp"

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

TimeOfDay TimeOfDay::from_unix_ms(std::int64_t unix_ms) {
    const std::int64_t rel = unix_ms - kCanopenEpochUnixMs;
    if (rel < 0) throw InvalidArgument("TIME: before 1984-01-01 cannot be encoded");
    const std::int64_t days = rel / 86'400'000;
    if (days > 0xFFFF) throw InvalidArgument("TIME: beyond the 16-bit day range (year 2163)");
    return {static_cast<std::uint32_t>(rel % 86'400'000), static_cast<std::uint16_t>(days)};
}

can::Frame encode_time(const TimeOfDay& t, std::uint32_t cob_id) {
    if (t.ms_after_midnight >= 86'400'000) throw InvalidArgument("TIME: ms after midnight must be < 86400000");
    can::Frame f;
    f.id = cob_id;
    f.len = 6;
    const std::uint32_t ms = t.ms_after_midnight;
    for (int i = 0; i < 4; ++i) f.data[i] = static_cast<std::uint8_t>(ms >> (8 * i));
    f.data[4] = static_cast<std::uint8_t>(t.days_since_1984);
    f.data[5] = static_cast<std::uint8_t>(t.days_since_1984 >> 8);
    return f;
}

std::optional<TimeOfDay> decode_time(const can::Frame& f, std::uint32_t cob_id) {
    if (f.id != cob_id || f.extended || f.rtr || f.len != 6) return std::nullopt;
    std::uint32_t raw = 0;
    for (int i = 0; i < 4; ++i) raw |= std::uint32_t(f.data[i]) << (8 * i);
    if (raw >> 28) return std::nullopt;
    if (raw >= 86'400'000) return std::nullopt;
    return TimeOfDay{raw, static_cast<std::uint16_t>(f.data[4] | (f.data[5] << 8))};
}

}  // namespace motorbus::canopen

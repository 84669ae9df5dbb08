// TIME (COB-ID 0x100): TIME_OF_DAY = 28-bit milliseconds after midnight and
// 16-bit days since 1984-01-01, little-endian, 6 bytes (CiA 301).
#pragma once
#include <cstdint>
#include <optional>

#include "motorbus/can/frame.hpp"

namespace motorbus::canopen {

constexpr std::uint32_t kTimeCobId = 0x100;
constexpr std::int64_t kCanopenEpochUnixMs = 441'763'200'000;  // 1984-01-01T00:00:00Z

struct TimeOfDay {
    std::uint32_t ms_after_midnight = 0;  // 0 .. 86'399'999
    std::uint16_t days_since_1984 = 0;
    std::int64_t to_unix_ms() const {
        return kCanopenEpochUnixMs + std::int64_t(days_since_1984) * 86'400'000 + ms_after_midnight;
    }
    // Throws InvalidArgument before 1984-01-01 or after the 16-bit day range.
    static TimeOfDay from_unix_ms(std::int64_t unix_ms);
};

can::Frame encode_time(const TimeOfDay& t, std::uint32_t cob_id = kTimeCobId);
// nullopt unless DLC == 6 on `cob_id`, not RTR; ms >= 86'400'000 or the 4
// reserved bits set also give nullopt (never a time that does not exist).
std::optional<TimeOfDay> decode_time(const can::Frame& f, std::uint32_t cob_id = kTimeCobId);

}  // namespace motorbus::canopen

// Fuzzes the candump and ASC log parsers (untrusted files from other tools).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "motorbus/can/log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view text(reinterpret_cast<const char*>(data), size);
    if (auto e = motorbus::can::parse_candump_line(text)) {
        // Whatever parses must be a valid frame and survive a format/parse round trip.
        if (!e->frame.valid()) __builtin_trap();
        auto again = motorbus::can::parse_candump_line(motorbus::can::format_candump_line(*e));
        if (!again || !again->frame.same_content(e->frame)) __builtin_trap();
    }
    std::size_t bad = 0;
    for (const auto& e : motorbus::can::parse_asc(text, &bad))
        if (!e.frame.valid()) __builtin_trap();
    return 0;
}

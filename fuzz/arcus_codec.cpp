// Fuzz target: the Arcus ASCII codec on arbitrary bytes (reply parsing, request
// line parsing, command parsing, the strict integer grammar).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "motorbus/drives/arcus/codec.hpp"

using namespace motorbus::arcus;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view in(reinterpret_cast<const char*>(data), size);
    try {
        Reply r = parse_reply(in);
        if (r.body.empty()) __builtin_trap();  // parse_reply never returns an empty body
        (void)classify_error(r.body);
        try {
            (void)reply_int(r.body);
        } catch (const motorbus::ProtocolError&) {
        }
    } catch (const motorbus::ProtocolError&) {
    }
    if (auto req = parse_request_line(in)) {
        if (req->address < 0 || req->address > 99) __builtin_trap();
        if (auto pc = parse_command(req->command)) {
            if (!pc->info) __builtin_trap();
            if (pc->value && (*pc->value < INT32_MIN || *pc->value > INT32_MAX)) __builtin_trap();
        }
    }
    (void)parse_int(in);
    try {
        std::string built = build_request(static_cast<int>(size % 101), in);
        // Whatever we agree to send must parse back to the same command.
        auto back = parse_request_line(std::string_view(built).substr(0, built.size() - 1));
        if (!back || back->command != in) __builtin_trap();
    } catch (const motorbus::InvalidArgument&) {
    }
    return 0;
}

// libFuzzer target for the DMAC codec: request frames, replies, version and
// READ_SEQ lines, numbers.  Properties: no crash/UB, and every parsed command
// formats to text that parses back to the same canonical form.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "motorbus/drives/dmac/codec.hpp"

using namespace motorbus::dmac;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view in(reinterpret_cast<const char*>(data), size);
    Request r = parse_request(in);
    for (const Command& c : r.commands) {
        if (c.cmd == Cmd::Invalid) continue;
        const std::string text = format_command(c);
        Request again = parse_request(text);
        if (again.commands.size() != 1 || format_command(again.commands[0]) != text) std::abort();
    }
    if (auto rr = parse_read_reply(in)) {
        if (rr->address < 0 || rr->address > kMaxAddress || rr->bit < 0 || rr->bit > 32) std::abort();
        (void)format_value(rr->value, rr->radix);
    }
    (void)parse_seq_reply(in);
    (void)parse_version(in);
    if (auto n = parse_number(in)) {
        // A decimal value formats and parses back to itself.
        if (parse_number(format_value(*n, Radix::Dec)) != n) std::abort();
    }
    return 0;
}

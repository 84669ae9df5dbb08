// Fuzzes LineFramer (the reassembly behind LineLink and PtyLineServer).
// Input: [config byte][max_line byte][split seed byte][stream...].
// Oracle: framing must not depend on how the stream is split into reads, lines
// respect max_line, and consumption accounting adds up.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "motorbus/serial/line_framer.hpp"

using motorbus::serial::FramedLine;
using motorbus::serial::LineFramer;

namespace {
struct Event {
    int kind;
    std::string text;
    std::size_t length;
    std::string term;
    bool operator==(const Event&) const = default;
};

std::vector<Event> run(LineFramer& f, const std::uint8_t* data, std::size_t size, std::uint8_t seed) {
    std::vector<Event> out;
    std::size_t pos = 0;
    unsigned step = seed;
    while (pos < size) {
        step = step * 1103515245u + 12345u;
        std::size_t chunk = seed == 0 ? size : 1 + (step >> 16) % 17;
        if (chunk > size - pos) chunk = size - pos;
        std::span<const std::uint8_t> in(data + pos, chunk);
        std::size_t total = 0;
        while (!in.empty()) {
            std::size_t used = 0;
            auto line = f.push(in, used);
            if (used > in.size()) std::abort();
            if (line) {
                if (used == 0) std::abort();  // an event always consumes its terminator
                if (line->kind == FramedLine::Kind::Line && line->text.size() > f.max_line()) std::abort();
                if (line->kind == FramedLine::Kind::Overlong &&
                    (line->length <= f.max_line() || line->text.size() > LineFramer::kOverlongPrefix))
                    std::abort();
                out.push_back({line->kind == FramedLine::Kind::Line ? 0 : 1, line->text, line->length,
                               line->terminator});
            } else if (used != in.size()) {
                std::abort();  // no event means everything was consumed
            }
            total += used;
            in = in.subspan(used);
        }
        if (total != chunk) std::abort();
        pos += chunk;
    }
    return out;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 3) return 0;
    static const std::vector<std::vector<std::string>> sets = {
        {"\r"},
        {"\r\n"},
        {std::string("\0", 1)},
        {"\r", "\r\n"},
        {"\n", "\r\n"},
        {"\r", "\r\n", std::string("\0", 1)},
        {">", "\r\n"},
        {"ab", "abc", "b"},
    };
    const auto& terms = sets[data[0] % sets.size()];
    std::size_t max_line = 1 + data[1] % 64;
    std::uint8_t seed = data[2];
    data += 3;
    size -= 3;
    LineFramer whole(terms, max_line);
    LineFramer split(terms, max_line);
    auto a = run(whole, data, size, 0);
    auto b = run(split, data, size, seed | 1);
    if (a != b) std::abort();
    if (whole.partial_bytes() != split.partial_bytes()) std::abort();
    return 0;
}

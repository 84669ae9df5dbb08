// Fuzzes the Telnet parser behind rfc2217:// lines (serial/telnet.hpp).
// Input: [split seed byte][stream...], as a server could send it.
// Oracles: the result does not depend on how the stream is split into reads;
// data never grows beyond the input; subnegotiation payloads respect the cap;
// negotiation answers are whole IAC verb option triples about options we were
// asked for; a stream of plain data escaped with escape() parses back to itself.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "motorbus/serial/telnet.hpp"

using namespace motorbus::serial::telnet;

namespace {
Parser make() { return Parser({OPT_BINARY, OPT_SGA, OPT_COM_PORT}, {OPT_BINARY, OPT_SGA, OPT_COM_PORT}); }

Output run(const std::uint8_t* data, std::size_t size, std::uint8_t seed) {
    Parser p = make();
    // Our own requests first, as Rfc2217Port makes them.
    p.request(Side::Local, OPT_COM_PORT);
    p.request(Side::Remote, OPT_BINARY);
    Output out;
    std::size_t pos = 0;
    unsigned step = seed;
    while (pos < size) {
        step = step * 1103515245u + 12345u;
        std::size_t chunk = seed == 0 ? size : 1 + (step >> 16) % 13;
        if (chunk > size - pos) chunk = size - pos;
        p.feed({data + pos, chunk}, out);
        pos += chunk;
    }
    return out;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    const std::uint8_t seed = data[0];
    ++data;
    --size;
    auto whole = run(data, size, 0);
    auto split = run(data, size, seed | 1);
    if (whole.data != split.data || whole.events != split.events || whole.answer != split.answer) std::abort();
    if (whole.data.size() > size) std::abort();
    if (whole.answer.size() % 3 != 0) std::abort();
    for (std::size_t i = 0; i < whole.answer.size(); i += 3)
        if (whole.answer[i] != IAC || whole.answer[i + 1] < WILL) std::abort();
    for (const auto& e : whole.events)
        if (e.payload.size() > Parser::kMaxSubnegotiation) std::abort();
    // Round trip: any bytes, escaped, are data and nothing else.
    Parser p = make();
    Output back;
    p.feed(escape({data, size}), back);
    if (back.data != std::vector<std::uint8_t>(data, data + size) || !back.events.empty() || !back.answer.empty())
        std::abort();
    return 0;
}

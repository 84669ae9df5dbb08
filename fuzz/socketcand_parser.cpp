// Fuzz the socketcand element parser: any byte stream, fed in arbitrary chunks,
// must never crash, never grow the buffer past its cap, and every element it
// accepts must re-encode to something it accepts again.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "motorbus/can/socketcand_codec.hpp"

using namespace motorbus::can;
using namespace motorbus::can::socketcand;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    // First byte picks the chunk size, so element boundaries land everywhere.
    const std::size_t chunk = 1 + data[0] % 64;
    ElementParser parser(64 + data[0]);
    const char* p = reinterpret_cast<const char*>(data + 1);
    std::size_t left = size - 1;
    while (left) {
        std::size_t n = left < chunk ? left : chunk;
        parser.feed(
            std::span<const char>(p, n),
            [](const Element& e) {
                const bool is_frame = e.kind == ElementKind::Frame || e.kind == ElementKind::FdFrame ||
                                      e.kind == ElementKind::Rtr || e.kind == ElementKind::Send ||
                                      e.kind == ElementKind::SendRtr || e.kind == ElementKind::FdSend;
                if (!is_frame) return;
                if (e.frame.problem()) std::abort();  // the parser let an invalid frame through
                std::string wire;
                encode_send(e.frame, wire);
                Element back;
                if (parse_element(wire, back) || !back.frame.same_content(e.frame)) std::abort();
            },
            [](const ParseError& err) {
                if (err.element.empty() || err.element.front() != '<') std::abort();
            });
        p += n;
        left -= n;
    }
    return 0;
}

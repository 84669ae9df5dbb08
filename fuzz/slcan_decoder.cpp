// libFuzzer: the SLCAN adapter->host stream decoder on arbitrary bytes.
// Checks the invariants the bus relies on: the held line never exceeds the
// MTU, every decoded frame is valid, and a valid line after the input decodes.
#include <cstdint>
#include <cstdlib>
#include <span>

#include "motorbus/can/slcan_codec.hpp"

using namespace motorbus::can;
using namespace motorbus::can::slcan;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    StreamDecoder d;
    // Split the input at a data-dependent point so chunking is exercised too.
    const std::size_t cut = size ? data[0] % (size + 1) : 0;
    auto check = [&](const Event& e) {
        if (e.kind == EventKind::Frame) {
            if (!e.frame.valid()) std::abort();
            // What we decode we can encode again, and it decodes the same.
            StreamDecoder again;
            std::string line = encode_frame(e.frame, e.timestamp_ms);
            bool same = false;
            again.feed(std::span(reinterpret_cast<const std::uint8_t*>(line.data()), line.size()),
                       [&](const Event& e2) { same = e2.kind == EventKind::Frame && e2.frame.same_content(e.frame); });
            if (!same) std::abort();
        }
        if (e.text.size() > kMtu) std::abort();
    };
    d.feed(std::span(data, cut), check);
    if (d.pending() > kMtu) std::abort();
    d.feed(std::span(data + cut, size - cut), check);
    if (d.pending() > kMtu) std::abort();
    static const std::uint8_t tail[] = {'\r', 't', '1', '2', '3', '1', 'A', 'B', '\r'};
    bool got = false;
    d.feed(std::span(tail), [&](const Event& e) {
        if (e.kind == EventKind::Frame && e.frame.id == 0x123 && e.frame.len == 1 && e.frame.data[0] == 0xAB) got = true;
    });
    if (!got) std::abort();
    return 0;
}

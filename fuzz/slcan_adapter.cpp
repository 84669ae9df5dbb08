// libFuzzer: the SLCAN adapter role (command parser + AdapterSession) on
// arbitrary host bytes.  Every reply must be a well-formed SLCAN reply and every
// frame handed to the bus must be valid.
#include <cstdint>
#include <cstdlib>
#include <span>

#include "motorbus/can/slcan_codec.hpp"

using namespace motorbus::can;
using namespace motorbus::can::slcan;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    CommandDecoder d;
    AdapterSession s;
    const std::uint8_t flags = size ? data[size - 1] : 0;
    d.feed(std::span(data, size), [&](const Command& c) {
        AdapterReply r = s.handle(c, flags);
        if (r.bytes.empty() || r.bytes.size() > kMtu) std::abort();
        const char last = r.bytes.back();
        if (last != '\r' && last != '\a') std::abort();
        if (r.transmit) {
            if (!r.transmit->valid()) std::abort();
            if (!s.is_open() || s.listen_only()) std::abort();
        }
        // What the host reads back must decode as exactly one reply event.
        StreamDecoder back;
        int events = 0;
        back.feed(std::span(reinterpret_cast<const std::uint8_t*>(r.bytes.data()), r.bytes.size()),
                  [&](const Event& e) {
                      ++events;
                      if (e.kind == EventKind::Malformed || e.kind == EventKind::Overflow) std::abort();
                  });
        if (events != 1) std::abort();
    });
    return 0;
}

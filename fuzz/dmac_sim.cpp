// libFuzzer target for the DMAC simulator's line handler.  The input is split
// into lines at CR; between lines the simulated clock advances by an amount
// taken from the input, so the sequencer, the FIFO and motion run too.
// Properties: on_line never throws, never answers a frame for another address,
// and a valid READ afterwards still answers.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

#include "motorbus/drives/dmac/sim.hpp"

using namespace motorbus;
using namespace motorbus::dmac;

namespace {
// Lines looked at per input: a longer input adds run time (up to 255 ms of
// 1 ms cycles per line), not new states.
constexpr std::size_t kMaxLines = 64;
// Either switch polarity, chosen by the input.
bool data_len_odd(std::size_t size) { return (size & 1u) != 0; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    auto clock = std::make_shared<SimClock>();
    SimOptions options{.address = 1};
    options.line_delay_in_real_time = false;  // no wire: 3 ms per reply would be the whole run
    // End-stop switches on the axis, so HARD_ENDS stops at switch edges get fuzzed too.
    options.positive_end_switch = motion::SwitchConfig{true, 20000, 0, false};
    options.negative_end_switch = motion::SwitchConfig{true, -20000, 0, data_len_odd(size)};
    Sim sim(clock, options);
    std::string_view in(reinterpret_cast<const char*>(data), size);
    std::size_t start = 0;
    std::size_t lines = 0;
    while (start <= in.size() && lines++ < kMaxLines) {
        std::size_t cr = in.find('\r', start);
        std::size_t end = cr == std::string_view::npos ? in.size() : cr;
        std::string_view line = in.substr(start, end - start);
        if (line.size() > sim.max_request()) {
            (void)sim.on_overlong();
        } else {
            const std::string before = address_prefix(sim.address());
            std::string reply = sim.on_line(line);
            const std::string after = address_prefix(sim.address());
            // Replies carry the module's own address (SET_ADDRESS may change it mid-frame).
            if (!reply.empty() && reply[0] != kXonError && reply.compare(0, 2, before) != 0 &&
                reply.compare(0, 2, after) != 0)
                std::abort();
        }
        // Advance 0..255 ms, from the first byte of the line.
        if (!line.empty()) clock->advance(static_cast<Nanos>(static_cast<std::uint8_t>(line[0])) * 1'000'000);
        if (cr == std::string_view::npos) break;
        start = cr + 1;
    }
    const std::string a = address_prefix(sim.address());
    // Leave sequence edition first, or the assignment would be stored, not run.
    (void)sim.on_line(a + "CLOSE_SEQ");
    std::string r = sim.on_line(a + "#ERROR:=0, READ #ERROR");
    if (r != a + "#ERR=+0\r\n") std::abort();
    return 0;
}

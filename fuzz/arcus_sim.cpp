// Fuzz target: the Arcus simulator fed arbitrary request lines, with simulated
// time advancing between them.  The device must never throw, crash or hang,
// and every reply ends with exactly one NUL.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "motorbus/drives/arcus/sim.hpp"

using namespace motorbus;

namespace {
// Time between two lines: 0-255 units.  While a StepNLoop or sync move is
// armed the simulator samples every 1 ms tick, so this bounds one line's cost
// (0-1.275 s: long enough for moves to end and limits to be hit).
constexpr Nanos kTimeUnit = 5'000'000;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    SimClock clock;
    arcus::SimOptions o;
    o.world.plus_limit = 20000;
    o.world.minus_limit = -20000;
    o.tick_ns = 1'000'000;  // coarse steps keep long moves cheap
    arcus::Sim sim(clock, o);
    std::string_view in(reinterpret_cast<const char*>(data), size);
    // Lines are separated by CR; the byte after each CR picks how far time moves.
    std::size_t start = 0;
    while (start <= in.size()) {
        std::size_t cr = in.find('\r', start);
        std::string_view line = in.substr(start, cr == std::string_view::npos ? std::string_view::npos : cr - start);
        if (line.size() > sim.max_request()) line = line.substr(0, sim.max_request());
        std::string reply = sim.on_line(line);
        if (!reply.empty() && (reply.back() != '\0' || reply.find('\0') != reply.size() - 1)) __builtin_trap();
        if (cr == std::string_view::npos) break;
        start = cr + 1;
        if (start < in.size()) clock.advance(static_cast<Nanos>(static_cast<std::uint8_t>(in[start])) * kTimeUnit);
    }
    (void)sim.motor_status();
    (void)sim.snl_status();
    return 0;
}

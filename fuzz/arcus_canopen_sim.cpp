// Fuzz target: the Arcus simulator's CANopen front end fed arbitrary CAN frames
// (SDO requests on 0x601, NMT, other ids), with simulated time advancing between
// them.  The device must never throw, crash or hang; every SDO reply is 8 bytes
// on 0x581 (or, after an NMT reset, on the node-ID the store file chose) and a
// boot-up is one byte on 0x700 + n.
#include <cstddef>
#include <cstdint>
#include <span>

#include "motorbus/drives/arcus/sim.hpp"

using namespace motorbus;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    SimClock clock;
    arcus::SimOptions o;
    o.comm_type = 2;
    o.world.plus_limit = 20000;
    o.world.minus_limit = -20000;
    o.tick_ns = 1'000'000;  // coarse steps keep long moves cheap
    arcus::Sim sim(clock, o);
    // Records: [kind, dlc, 8 data bytes, time step]; kind picks the id.
    std::size_t i = 0;
    while (i + 11 <= size) {
        const std::uint8_t kind = data[i];
        const std::uint8_t dlc = data[i + 1] % 9;
        const std::uint32_t id = kind < 200 ? 0x601 : kind < 230 ? 0x000 : 0x600u + (kind & 0x7F);
        can::Frame f = can::Frame::make(id, std::span<const std::uint8_t>(data + i + 2, dlc));
        for (const auto& r : sim.on_can_frame(f)) {
            const bool sdo = (r.id & 0x780) == 0x580 && r.len == 8;
            const bool boot = (r.id & 0x780) == 0x700 && r.len == 1 && r.data[0] == 0;
            if (!sdo && !boot) __builtin_trap();
        }
        clock.advance(static_cast<Nanos>(data[i + 10]) * 5'000'000);
        i += 11;
    }
    (void)sim.motor_status();
    (void)sim.snl_status();
    return 0;
}

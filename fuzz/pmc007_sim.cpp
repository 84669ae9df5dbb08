// Fuzz target: the PMC007 simulator's request handling.  Each 8-byte record is
// one SDO-level access to its dictionary (index, sub, up to 4 data bytes, and an
// operation byte: read, write of 1/2/4 bytes, input edge, jam, error, time step),
// applied through the same remote_read/remote_write path the SDO server and the
// RPDOs use, with simulated time advancing between records.  The device must
// never throw, crash or hang, and its invariants hold (busy only while moving,
// 6001h bit 3 = busy, 6011h:01 bits 7-10 read 0).
#include <cstddef>
#include <cstdint>
#include <span>

#include "motorbus/drives/pmc007/sim.hpp"

using namespace motorbus;
using namespace motorbus::pmc007;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    SimClock clock(1'000'000'000);
    Pmc007SimOptions o;
    o.ext1_switch = std::make_pair(-1e6, -1000.0);
    Pmc007Sim sim(5, clock, o);
    auto& od = sim.od();
    for (std::size_t i = 0; i + 8 <= size; i += 8) {
        const std::uint8_t* r = data + i;
        const std::uint16_t index = static_cast<std::uint16_t>(r[0] | r[1] << 8);
        const std::uint8_t sub = r[2];
        const std::uint8_t op = r[3];
        switch (op % 8) {
            case 0: {
                canopen::VariablePtr v;
                if (od.lookup(index, sub, v) == 0) {
                    canopen::Bytes out;
                    (void)v->remote_read(out);
                }
                break;
            }
            case 1:
            case 2:
            case 3: {
                const std::size_t n = op % 8 == 1 ? 1 : op % 8 == 2 ? 2 : 4;
                canopen::VariablePtr v;
                if (od.lookup(index, sub, v) == 0) (void)v->remote_write(std::span<const std::uint8_t>(r + 4, n));
                break;
            }
            case 4: sim.set_input(r[4] % 11, r[5] & 1); break;
            case 5: sim.set_jammed(r[4] & 1); break;
            case 6: sim.inject_error(r[4]); break;
            case 7: break;
        }
        clock.advance(static_cast<Nanos>(r[7]) * 5'000'000);
        sim.poll();
        const bool busy = sim.busy();
        if (((sim.controller_status() & st::kBusy) != 0) != busy) __builtin_trap();
        if (od.at(0x6011, 1)->get_u64() & 0x780) __builtin_trap();
    }
    sim.power_cycle();
    return 0;
}

// 07: a simulated CQPUSI PMC007 on a virtual bus, driven by the generic SdoClient:
// a step command on a simulated clock, then an offline program assembled,
// uploaded word by word (6019h:01/02), saved and run.
#include <cstdio>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/drives/pmc007/program.hpp"
#include "motorbus/drives/pmc007/sim.hpp"

using namespace motorbus;

int main() {
    SimClock clock(0);
    auto device_bus = can::open_virtual("pmc007-example"), host_bus = can::open_virtual("pmc007-example");
    pmc007::Sim sim(5, clock);
    sim.attach(device_bus);
    canopen::SdoClient sdo(*host_bus, 5);

    sdo.write_i32(0x6003, 0, 1600);   // speed first: + sets direction 1
    sdo.write_u32(0x6004, 0, 3200);   // then the step command
    std::printf("6001h=0x%02X\n", sdo.read_u8(0x6001, 0));
    clock.advance(2'100'000'000);
    sim.poll();
    std::printf("position %d busy %d\n", sdo.read_i32(0x600C, 0), sdo.read_u8(0x6001, 0) >> 3);

    const auto words = pmc007::assemble("VSET 0,1000\nDIR 0,0\nROT 0,500\nWAIT 1,0\nCNTI\nCMP 1,3\nJNE 0,2\n");
    for (std::size_t i = 0; i < words.size(); ++i) {
        sdo.write_u8(0x6019, 1, static_cast<std::uint8_t>(i));
        sdo.write_u32(0x6019, 2, words[i]);
    }
    sdo.write_u8(0x6018, 1, static_cast<std::uint8_t>(words.size()));
    sdo.write_u8(0x6019, 3, 1);       // write to flash
    sdo.write_u8(0x6018, 2, 1);       // offline exec
    clock.advance(1'600'000'000);
    sim.poll();
    std::printf("after the program: position %d counter %u\n", sdo.read_i32(0x600C, 0), sim.program_counter_value());
    sim.close();
    return 0;
}

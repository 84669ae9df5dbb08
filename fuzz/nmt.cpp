// Fuzz: NMT decode and the NMT slave state machine on arbitrary frames.
#include <cstddef>
#include <cstdint>

#include "motorbus/canopen/nmt.hpp"

using namespace motorbus;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    canopen::NmtSlave slave(5);
    slave.boot();
    std::size_t i = 0;
    while (i + 2 <= size) {
        can::Frame f;
        f.id = data[i] & 0x03 ? 0 : data[i];  // mostly COB-ID 0
        f.rtr = data[i] & 0x80;
        f.len = static_cast<std::uint8_t>(data[i + 1] % 9);
        i += 2;
        for (std::size_t k = 0; k < f.len && i < size; ++k) f.data[k] = data[i++];
        (void)canopen::decode_nmt(f);
        slave.on_frame(f);
        if (slave.state() == canopen::NodeState::Initialising) slave.boot();
    }
    return 0;
}

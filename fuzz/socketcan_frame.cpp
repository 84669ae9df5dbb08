// Fuzz the SocketCAN struct conversion: whatever bytes a raw socket returns
// (any length, any flags), from_kernel() must not crash, must only produce
// valid frames, and those frames must convert back to the same kernel frame.
#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "motorbus/can/socketcan_bus.hpp"

using namespace motorbus::can;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    auto f = socketcan::from_kernel(data, size, 0);
    if (!f) return 0;
    if (f->problem()) std::abort();
    if (f->flags & kFlagError) return 0;  // error frames are received, never sent
    struct canfd_frame in;
    std::memset(&in, 0, sizeof in);
    std::memcpy(&in, data, size);
    // Bits above the id's width carry nothing (the kernel never sets them); compare the rest.
    const canid_t id_mask = f->extended ? CAN_EFF_MASK : CAN_SFF_MASK;
    if (size == CAN_MTU) {
        struct can_frame back = socketcan::to_can_frame(*f);
        const canid_t mask = CAN_EFF_FLAG | CAN_RTR_FLAG | id_mask;
        if ((back.can_id & mask) != (in.can_id & mask) || back.len != in.len) std::abort();
        if (!f->rtr && std::memcmp(back.data, in.data, in.len) != 0) std::abort();
    } else {
        struct canfd_frame back = socketcan::to_canfd_frame(*f);
        const canid_t mask = CAN_EFF_FLAG | id_mask;
        if ((back.can_id & mask) != (in.can_id & mask) || back.len != in.len) std::abort();
        if (std::memcmp(back.data, in.data, in.len) != 0) std::abort();
    }
    return 0;
}

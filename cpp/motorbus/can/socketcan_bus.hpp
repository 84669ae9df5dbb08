// SocketCAN: Linux AF_CAN raw sockets (can0, vcan0, slcan0, ...).
//
//   auto bus = open_socketcan("can0");
//
// Kernel acceptance filters (CAN_RAW_FILTER) drop unwanted ids before they
// cost a system call; error frames (CAN_RAW_ERR_FILTER) update the bus state
// and counters; receive timestamps come from the kernel (SO_TIMESTAMPNS) and
// are moved onto the monotonic time line every Frame uses.
//
// The conversions below are pure and testable on a kernel without CAN
// (CONFIG_CAN unset), where socket(PF_CAN, ...) fails with EAFNOSUPPORT.
#pragma once
#include <linux/can.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/socketcand_net.hpp"

namespace motorbus::can {

struct SocketCanOptions : BusOptions {
    std::vector<Filter> kernel_filters;  // CAN_RAW_FILTER; empty = every frame
    bool error_frames = true;            // receive error frames (CAN_RAW_ERR_FILTER = all classes)
    bool fd = false;                     // CAN_RAW_FD_FRAMES (the interface must have MTU 72)
};

namespace socketcan {

struct can_frame to_can_frame(const Frame& f);      // classic (InvalidArgument for an FD frame)
struct canfd_frame to_canfd_frame(const Frame& f);  // FD (or classic data in the FD layout)
// A kernel frame of `size` bytes (CAN_MTU or CANFD_MTU) -> Frame; nullopt when
// the size or the length field is not one the kernel could have produced.
std::optional<Frame> from_kernel(const void* data, std::size_t size, Nanos timestamp_ns);
// Our acceptance filters in the kernel's terms (same matching rule).
std::vector<struct can_filter> to_kernel_filters(const std::vector<Filter>& filters);
// Bus state after an error frame (id = CAN_ERR_* class bits, data = details).
BusState state_after_error(const Frame& error_frame, BusState current);
// nullopt when AF_CAN raw sockets work here, else why not (e.g. a kernel
// without CONFIG_CAN: "... socket(PF_CAN) failed with EAFNOSUPPORT ...").
std::optional<std::string> unavailable_reason();

}  // namespace socketcan

class SocketCanBus final : public Bus {
public:
    // Throws LinkDown when the kernel has no CAN or the interface does not
    // exist / is down, InvalidArgument for a bad interface name.
    SocketCanBus(const std::string& iface, const SocketCanOptions& options = {});
    ~SocketCanBus() override;

protected:
    void do_send(const Frame& frame, Deadline deadline) override;
    void do_close() override;

private:
    void rx_loop();

    const SocketCanOptions opts_;
    net::Fd sock_;
    net::Wakeup wake_;
    std::atomic<bool> stop_{false};
    std::thread rx_thread_;
};

std::shared_ptr<SocketCanBus> open_socketcan(const std::string& iface,
                                             const SocketCanOptions& options = {});

}  // namespace motorbus::can

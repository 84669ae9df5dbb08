// 01: two endpoints on a virtual CAN bus, a subscriber, and recv().
#include <cstdio>
#include <vector>

#include "motorbus/can/virtual_bus.hpp"

using namespace motorbus::can;
using namespace std::chrono_literals;

int main() {
    auto a = open_virtual("example"), b = open_virtual("example");
    b->subscribe_id(0x181, false, [](const Frame& f) {
        std::printf("callback: %s\n", f.to_string().c_str());  // on b's receive thread
    });
    a->send(Frame::make(0x181, std::vector<std::uint8_t>{1, 2, 3}));
    a->send(Frame::make(0x1ABCDEF0, std::vector<std::uint8_t>{0xFF}, /*extended=*/true));
    for (int i = 0; i < 2; ++i)
        if (auto f = b->recv(1s)) std::printf("recv: %s\n", f->to_string().c_str());
    std::printf("rx_frames=%llu\n", static_cast<unsigned long long>(b->counters().rx_frames));
}

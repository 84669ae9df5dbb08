// Issue 23 #4: a stored 200Bh takes effect at the power cycle, and a node whose
// bit rate differs from the wire's neither hears nor is heard (can::BitRateGate),
// on virtual hubs with wire time.  Threads: the hub's delivery and the sim's
// receive callbacks (run under tsan by the sanitizer stage).
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>

#include "motorbus/can/bit_rate_gate.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/runtime/clock.hpp"

namespace {

using namespace std::chrono_literals;
using motorbus::can::Frame;

std::shared_ptr<motorbus::can::VirtualBus> hub(const std::string& name, double rate) {
    motorbus::can::VirtualOptions o;
    o.bitrate = rate;
    return motorbus::can::open_virtual(name, o);
}

// The first frame with `id` within `wait`, or nothing.
std::optional<Frame> expect_id(motorbus::can::Bus& bus, std::uint32_t id, std::chrono::milliseconds wait) {
    const auto end = std::chrono::steady_clock::now() + wait;
    while (std::chrono::steady_clock::now() < end) {
        auto f = bus.recv(std::chrono::duration_cast<motorbus::can::Duration>(end - std::chrono::steady_clock::now()));
        if (f && f->id == id) return f;
    }
    return std::nullopt;
}

Frame sdo(std::uint8_t cs, std::uint16_t index, std::uint8_t value = 0) {
    const std::uint8_t b[8] = {cs, std::uint8_t(index), std::uint8_t(index >> 8), 0, value, 0, 0, 0};
    return Frame::make(0x601, b);
}

TEST(ArcusBitRate, CodesAreTable836) {
    EXPECT_EQ(motorbus::arcus::canopen_bit_rate_bps(1), 10e3);
    EXPECT_EQ(motorbus::arcus::canopen_bit_rate_bps(5), 125e3);
    EXPECT_EQ(motorbus::arcus::canopen_bit_rate_bps(9), 1e6);
    EXPECT_EQ(motorbus::arcus::canopen_bit_rate_bps(0), 0.0);
    EXPECT_EQ(motorbus::arcus::canopen_bit_rate_bps(10), 0.0);
}

TEST(ArcusBitRate, StoredRateTakesEffectAtThePowerCycleAndTheNodeMovesBuses) {
    motorbus::RealClock clock;
    motorbus::arcus::SimOptions o;
    o.comm_type = 2;
    motorbus::arcus::Sim sim(clock, o);
    auto node_side = hub("arcus-br-125", 125e3);
    auto host = hub("arcus-br-125", 125e3);
    sim.attach(node_side);
    ASSERT_TRUE(expect_id(*host, 0x701, 500ms));                       // boot-up at the factory 125k
    host->send(sdo(0x2F, 0x200B, 7));                                   // 500 kbit/s
    ASSERT_TRUE(expect_id(*host, 0x581, 500ms));
    host->send(sdo(0x2F, 0x200E, 1));                                   // store
    ASSERT_TRUE(expect_id(*host, 0x581, 500ms));
    const std::uint8_t reset[2] = {0x81, 1};
    host->send(Frame::make(0, reset));                                  // power cycle
    EXPECT_FALSE(expect_id(*host, 0x701, 300ms));                       // its boot-up is off this wire
    host->send(sdo(0x40, 0x200B));
    EXPECT_FALSE(expect_id(*host, 0x581, 300ms));
    EXPECT_EQ(sim.can_bit_rate(), 7);

    sim.close();
    auto fast_node = hub("arcus-br-500", 500e3);
    auto fast_host = hub("arcus-br-500", 500e3);
    sim.attach(fast_node);
    ASSERT_TRUE(expect_id(*fast_host, 0x701, 500ms));
    fast_host->send(sdo(0x40, 0x200B));
    auto r = expect_id(*fast_host, 0x581, 500ms);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->data[0], 0x4F);
    EXPECT_EQ(r->data[4], 7);
    sim.close();
}

TEST(ArcusBitRate, AGateOnABusWithoutWireTimePassesEverything) {
    auto a = hub("arcus-br-none", 0), b = hub("arcus-br-none", 0);
    motorbus::can::BitRateGate gate(*a, [] { return 42.0; });
    EXPECT_TRUE(gate.in_step());
    EXPECT_EQ(motorbus::can::medium_bit_rate(gate), 0.0);
    auto c = hub("arcus-br-wire", 250e3);
    motorbus::can::BitRateGate off(*c, [] { return 125e3; }), on(*c, [] { return 250e3; });
    EXPECT_FALSE(off.in_step());
    EXPECT_TRUE(on.in_step());
    EXPECT_EQ(motorbus::can::medium_bit_rate(on), 250e3);
}

}  // namespace

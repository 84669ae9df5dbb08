// Hardening (defect 11, CANopen side): SDO block size, a second LocalNode with
// the same node-ID on one bus or one virtual hub, a heartbeat period below
// 1 ms -- each refused with InvalidArgument naming the option and its range.
#include <gtest/gtest.h>

#include <string>

#include "../invalid_message.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;

namespace {

using motorbus::test::invalid_message;

std::shared_ptr<ObjectDictionary> small_od() {
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x2000, .name = "U8", .type = DataType::Unsigned8});
    return od;
}

}  // namespace

TEST(HardeningOptions, SdoBlockSizeOutside1To127Refused) {
    auto bus = can::open_virtual("hardening-sdo-blk");
    for (unsigned b : {0u, 128u, 200u, 255u}) {
        SdoClientOptions o;
        o.block_size = static_cast<std::uint8_t>(b);
        auto m = invalid_message([&] { SdoClient c(*bus, 5, o); });
        EXPECT_NE(m.find("block_size"), std::string::npos) << b << ": " << m;
        EXPECT_NE(m.find("1-127"), std::string::npos) << m;
    }
    SdoClientOptions o;
    o.max_transfer = 0;
    EXPECT_NE(invalid_message([&] { SdoClient c(*bus, 5, o); }).find("max_transfer"), std::string::npos);
    o = {};
    o.block_size = 127;
    EXPECT_NO_THROW(SdoClient(*bus, 5, o));
    o.block_size = 1;
    EXPECT_NO_THROW(SdoClient(*bus, 5, o));
}

TEST(HardeningOptions, DuplicateLocalNodeOnOneBusRefused) {
    auto bus = can::open_virtual("hardening-dup-a");
    LocalNode first(*bus, 5, small_od());
    auto m = invalid_message([&] { LocalNode second(*bus, 5, small_od()); });
    EXPECT_NE(m.find("node_id"), std::string::npos) << m;
    EXPECT_NE(m.find("5"), std::string::npos) << m;
    EXPECT_NO_THROW(LocalNode other(*bus, 6, small_od()));
    first.close();
    EXPECT_NO_THROW(LocalNode again(*bus, 5, small_od()));  // the id is free once closed
}

TEST(HardeningOptions, DuplicateLocalNodeOnOneVirtualHubRefused) {
    auto a = can::open_virtual("hardening-dup-hub");
    auto b = can::open_virtual("hardening-dup-hub");
    auto elsewhere = can::open_virtual("hardening-dup-other");
    auto first = std::make_unique<LocalNode>(*a, 7, small_od());
    auto m = invalid_message([&] { LocalNode second(*b, 7, small_od()); });
    EXPECT_NE(m.find("node_id"), std::string::npos) << m;
    EXPECT_NE(m.find("hardening-dup-hub"), std::string::npos) << m;
    EXPECT_NO_THROW(LocalNode other_hub(*elsewhere, 7, small_od()));
    first.reset();
    EXPECT_NO_THROW(LocalNode again(*b, 7, small_od()));
}

TEST(HardeningOptions, HeartbeatPeriodBelowOneMillisecondRefused) {
    auto bus = can::open_virtual("hardening-hb");
    RealClock clock;
    auto state = [] { return NodeState::Operational; };
    for (auto p : {1ns, 999'999ns}) {
        auto m = invalid_message([&] { HeartbeatProducer hb(*bus, clock, 5, p, state); });
        EXPECT_NE(m.find("period"), std::string::npos) << m;
        EXPECT_NE(m.find("1 ms"), std::string::npos) << m;
    }
    HeartbeatProducer hb(*bus, clock, 5, 0ns, state);  // 0 = off
    EXPECT_NE(invalid_message([&] { hb.set_period(1ns); }).find("1 ms"), std::string::npos);
    EXPECT_NO_THROW(hb.set_period(1ms));
}

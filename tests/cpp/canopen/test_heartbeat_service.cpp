// Heartbeat producer/consumer of a served LocalNode over the virtual bus.
#include <gtest/gtest.h>

#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/heartbeat_service.hpp"
#include "motorbus/canopen/nmt.hpp"
#include "motorbus/canopen/sdo_client_access.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;

namespace {
template <class F>
bool eventually(F f, std::chrono::milliseconds t = 2000ms) {
    const auto deadline = std::chrono::steady_clock::now() + t;
    while (!f()) {
        if (std::chrono::steady_clock::now() > deadline) return false;
        std::this_thread::sleep_for(1ms);
    }
    return true;
}
}  // namespace

TEST(HeartbeatService, ProducesConsumesAndReactsToLoss_N10_N12_N13) {
    auto dev_bus = can::open_virtual("svc-hbs");
    auto host_bus = can::open_virtual("svc-hbs");
    auto sniff = can::open_virtual("svc-hbs");
    sniff->set_filters({can::Filter{0x85, 0x7FF, false, true}});
    auto od = std::make_shared<ObjectDictionary>();
    LocalNode node(*dev_bus, 5, od);
    auto hb = HeartbeatService::attach(node);
    std::atomic<int> lost{0};
    hb->on_lost = [&](std::uint8_t n) { lost += n == 1; };
    BusSdoAccess sdo(*host_bus);
    NmtMaster master(*host_bus);

    // Producer: 0x1017 = 20 ms; the master sees the node's state.
    sdo.write_u16(5, 0x1017, 0, 20);
    master.start(5);
    EXPECT_TRUE(master.wait_for_state(5, NodeState::Operational, 2s));
    EXPECT_TRUE(eventually([&] { return hb->heartbeats_sent() >= 2; }));

    // Consumer: node 1 (the master) with 50 ms.  N12: a duplicate is refused.
    sdo.write_u32(5, 0x1016, 1, 0x00010032);
    try {
        sdo.write_u32(5, 0x1016, 2, 0x00010064);
        FAIL();
    } catch (const SdoAbortError& e) {
        EXPECT_EQ(e.code, 0x06040043u);
    }
    try {  // N13: reserved bits
        sdo.write_u32(5, 0x1016, 2, 0x01020064);
        FAIL();
    } catch (const SdoAbortError& e) {
        EXPECT_EQ(e.code, 0x06090030u);
    }
    sdo.write_u32(5, 0x1016, 2, 0x00FF0064);  // node 255: accepted, never armed (N13)
    // Node 1 beats once, then goes silent: lost, EMCY 0x8130, PRE-OPERATIONAL (0x1029 default).
    host_bus->send(encode_heartbeat(1, NodeState::Operational));
    EXPECT_TRUE(eventually([&] { return lost.load() == 1; }));
    EXPECT_TRUE(eventually([&] { return node.nmt_state() == NmtState::PreOperational; }));
    EXPECT_TRUE(hb->health(1).lost);
    auto e = sniff->recv(1s);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->len, 8);
    EXPECT_EQ(e->data[0], 0x30);
    EXPECT_EQ(e->data[1], 0x81);
    node.close();
}

// error_behaviour_without_1029 = 1: a lost heartbeat sends EMCY 0x8130 and the
// node stays OPERATIONAL (a device whose manual documents no reaction).
TEST(HeartbeatService, NoStateChangeWhenAskedAndNo1029) {
    auto dev_bus = can::open_virtual("svc-hbs-1");
    auto host_bus = can::open_virtual("svc-hbs-1");
    auto od = std::make_shared<ObjectDictionary>();
    LocalNode node(*dev_bus, 5, od);
    auto hb = HeartbeatService::attach(node, {.consumer_entries = 3, .error_behaviour_without_1029 = 1});
    std::atomic<int> lost{0};
    hb->on_lost = [&](std::uint8_t n) { lost += n == 1; };
    BusSdoAccess sdo(*host_bus);
    NmtMaster master(*host_bus);
    master.start(5);
    sdo.write_u32(5, 0x1016, 1, 0x00010032);
    host_bus->send(encode_heartbeat(1, NodeState::Operational));
    EXPECT_TRUE(eventually([&] { return lost.load() == 1; }));
    std::this_thread::sleep_for(20ms);
    EXPECT_EQ(node.nmt_state(), NmtState::Operational);
    node.close();
}

#include <gtest/gtest.h>

#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/canopen/scanner.hpp"
#include "test_nmt_support.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using svc_test::frame;
using namespace std::chrono_literals;

namespace {
// A minimal responder for expedited uploads of 0x1000 / 0x1018.
struct FakeNode {
    std::shared_ptr<svc_test::HubBus> bus;
    std::uint8_t id;
    std::map<std::uint32_t, std::uint32_t> objs;
    bool abort_device_type = false;
    FakeNode(svc_test::Hub& hub, std::uint8_t node, std::uint32_t type) : bus(hub.open("n")), id(node) {
        objs[0x100000] = type;
        objs[0x101801] = 0x0000012E;
        objs[0x101802] = 0x0000DEAD;
        objs[0x101803] = 0x00010002;
        objs[0x101804] = 0x12345678u + node;
        bus->subscribe_id(0x600u + node, false, [this](const can::Frame& f) {
            if (f.len != 8 || f.data[0] != 0x40) return;
            const std::uint32_t key = (std::uint32_t(f.data[1] | (f.data[2] << 8)) << 8) | f.data[3];
            can::Frame r = f;
            r.id = 0x580u + id;
            auto it = objs.find(key);
            if (it == objs.end() || (abort_device_type && key == 0x100000)) {
                r.data[0] = 0x80;
                r.data[4] = 0x00, r.data[5] = 0x00, r.data[6] = 0x02, r.data[7] = 0x06;
            } else {
                r.data[0] = 0x43;
                for (int i = 0; i < 4; ++i) r.data[4 + i] = static_cast<std::uint8_t>(it->second >> (8 * i));
            }
            bus->send(r);
        });
    }
};
}  // namespace

TEST(Scanner, FindsNodesByProbeAndHeartbeat) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    FakeNode a(hub, 5, 0x00040192);   // CiA 402 drive
    FakeNode b(hub, 32, 0x00000191);
    b.abort_device_type = true;
    auto silent = hub.open("hb-only");
    // A node that only sends heartbeats (SDO disabled, e.g. stopped).
    silent->subscribe_id(0x600 + 77, false, [&](const can::Frame&) {
        silent->send(encode_heartbeat(77, NodeState::Stopped));
    });
    // Garbage on the SDO response range must not confuse the scan.
    auto noise = hub.open("noise");
    noise->subscribe_id(0x600 + 9, false, [&](const can::Frame&) {
        noise->send(frame(0x589, {0x43, 0x00}));                            // short
        noise->send(frame(0x589, {0x43, 0x99, 0x99, 0x00, 1, 2, 3, 4}));    // wrong index
    });
    ScanOptions o;
    o.sdo_timeout = 30ms;
    auto res = scan_network(*host, o);
    ASSERT_EQ(res.size(), 3u);
    EXPECT_EQ(res[0].node_id, 5);
    EXPECT_EQ(res[0].device_type, 0x00040192u);
    EXPECT_EQ(res[0].profile(), 0x0192);
    EXPECT_EQ(res[0].vendor_id, 0x12Eu);
    EXPECT_EQ(res[0].product_code, 0xDEADu);
    EXPECT_EQ(res[0].revision, 0x00010002u);
    EXPECT_EQ(res[0].serial_number, 0x1234567Du);
    EXPECT_EQ(res[1].node_id, 32);
    EXPECT_FALSE(res[1].device_type);
    EXPECT_EQ(res[1].device_type_abort, 0x06020000u);
    EXPECT_EQ(res[1].vendor_id, 0x12Eu);
    EXPECT_EQ(res[2].node_id, 77);
    EXPECT_TRUE(res[2].heard_heartbeat);
    EXPECT_FALSE(res[2].sdo_answered);
    EXPECT_EQ(res[2].state, NodeState::Stopped);
    // Every node id was probed once for 0x1000: 127 requests.
    int probes = 0;
    for (auto& f : hub.log)
        if (f.id >= 0x601 && f.id <= 0x67F && f.data[1] == 0x00 && f.data[2] == 0x10) ++probes;
    EXPECT_EQ(probes, 127);
}

TEST(Scanner, RangeAndNoProbe) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    FakeNode a(hub, 5, 0x00040192);
    ScanOptions o;
    o.first = 6;
    o.last = 10;
    o.sdo_timeout = 5ms;
    EXPECT_TRUE(scan_network(*host, o).empty());
    o.first = 0;
    EXPECT_THROW(scan_network(*host, o), InvalidArgument);
    o.first = 1;
    o.probe_sdo = false;
    o.listen = 5ms;
    EXPECT_TRUE(scan_network(*host, o).empty());
}

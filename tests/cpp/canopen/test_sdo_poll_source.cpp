// SdoPollSource: the poller's CANopen source reads each object by SDO upload
// through the node's SdoClient and decodes it by its type; a PollGroup over it
// samples a LocalNode's values; an object the node lacks ends the group with
// the abort as its error.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/canopen/sdo_poll_source.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/poll/poll_group.hpp"
#include "test_sdo_bus.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;
using motorbus::test::LoopHub;

namespace {

struct PollNode : ::testing::Test {
    std::shared_ptr<LoopHub> hub = std::make_shared<LoopHub>();
    std::shared_ptr<test::LoopBus> host = hub->open("host");
    std::shared_ptr<test::LoopBus> dev = hub->open("dev");
    std::shared_ptr<ObjectDictionary> od = std::make_shared<ObjectDictionary>();
    std::unique_ptr<LocalNode> node;
    std::unique_ptr<SdoClient> sdo;

    void SetUp() override {
        od->add_variable({.index = 0x6064, .name = "Position", .type = DataType::Integer32});
        od->add_variable({.index = 0x6041, .name = "Statusword", .type = DataType::Unsigned16});
        od->add_variable({.index = 0x2011, .name = "Gain", .type = DataType::Real32});
        od->add_variable({.index = 0x2013, .name = "Offset", .type = DataType::Integer16});
        node = std::make_unique<LocalNode>(*dev, 5, od);
        SdoClientOptions o;
        o.timeout = 500ms;
        sdo = std::make_unique<SdoClient>(*host, 5, o);
    }
    void TearDown() override {
        sdo.reset();
        node.reset();
    }
};

}  // namespace

TEST_F(PollNode, ReadsEachObjectByItsType) {
    sdo->write_i32(0x6064, 0, -123456);
    sdo->write_u16(0x6041, 0, 0xBEEF);
    sdo->write_f32(0x2011, 0, 1.5f);
    sdo->write_i16(0x2013, 0, -7);
    SdoPollSource src(*sdo, {{0x6064, 0, "i32"}, {0x6041, 0, "U16"}, {0x2011, 0, "f32"}, {0x2013, 0, "i16"}});
    ASSERT_EQ(src.columns(), 4u);
    double out[4] = {};
    src.read(out);
    EXPECT_EQ(out[0], -123456.0);
    EXPECT_EQ(out[1], 0xBEEF);
    EXPECT_EQ(out[2], 1.5);
    EXPECT_EQ(out[3], -7.0);
    EXPECT_EQ(src.describe(), "SDO node 5");
}

TEST_F(PollNode, RefusesAnUnknownTypeOrNoObjects) {
    EXPECT_THROW(SdoPollSource(*sdo, {{0x6064, 0, "int32"}}), InvalidArgument);
    EXPECT_THROW(SdoPollSource(*sdo, {}), InvalidArgument);
}

TEST_F(PollNode, APollGroupSamplesTheNodeAndAMissingObjectEndsIt) {
    sdo->write_i32(0x6064, 0, 42);
    auto good = std::make_shared<SdoPollSource>(*sdo, std::vector<SdoPollObject>{{0x6064, 0, "i32"}});
    poll::PollOptions o;
    o.period_ns = 2'000'000;
    {
        poll::PollGroup g({good}, o);
        g.start();
        std::this_thread::sleep_for(50ms);
        g.stop();
        const std::size_t n = g.ring().available();
        ASSERT_GT(n, 5u);
        std::vector<std::int64_t> k(n), t(n);
        std::vector<double> v(n);
        ASSERT_EQ(g.ring().take(k.data(), t.data(), v.data(), n), n);
        for (double x : v) {
            if (!std::isnan(x)) {
                EXPECT_EQ(x, 42.0);
            }
        }
        EXPECT_EQ(g.stats().error, "");
    }
    auto missing = std::make_shared<SdoPollSource>(*sdo, std::vector<SdoPollObject>{{0x6099, 0, "i32"}});
    poll::PollGroup g({missing}, o);
    g.start();
    for (int i = 0; i < 500 && g.running(); ++i) std::this_thread::sleep_for(2ms);
    EXPECT_FALSE(g.running());
    EXPECT_EQ(g.stats().samples, 0u);
    EXPECT_NE(g.stats().error.find("6099"), std::string::npos) << g.stats().error;
}

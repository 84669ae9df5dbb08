// SdoClient against LocalNode over an in-process bus: all transfer types in
// both directions, NMT (S17), request floods (S18), lossy links (B13),
// many threads and many nodes at once.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "test_sdo_bus.hpp"
#include "test_sdo_util.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;
using motorbus::test::H;
using motorbus::test::hex;
using motorbus::test::LoopHub;

using motorbus::test::pattern;

namespace {

std::shared_ptr<ObjectDictionary> make_od() {
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x6001, .name = "Controller status", .type = DataType::Unsigned8,
                      .access = Access::RO, .default_value = std::uint64_t{8}});
    od->add_variable({.index = 0x2003, .name = "Baud index", .type = DataType::Unsigned8,
                      .low_limit = std::uint64_t{0}, .high_limit = std::uint64_t{8},
                      .default_value = std::uint64_t{4}});
    od->add_variable({.index = 0x6003, .name = "Position", .type = DataType::Integer32});
    od->add_variable({.index = 0x2010, .name = "Wide", .type = DataType::Unsigned64});
    od->add_variable({.index = 0x2011, .name = "Gain", .type = DataType::Real32});
    od->add_variable({.index = 0x2012, .name = "Gain64", .type = DataType::Real64});
    od->add_variable({.index = 0x2013, .name = "Offset", .type = DataType::Integer16});
    od->add_variable({.index = 0x1008, .name = "Device name", .type = DataType::VisibleString,
                      .access = Access::RW, .default_value = Bytes{'m', 'o', 't', 'o', 'r'}});
    od->add_variable({.index = 0x2201, .name = "Blob", .type = DataType::Domain, .access = Access::RW,
                      .max_size = 1 << 20});
    return od;
}

struct NodeFixture : ::testing::Test {
    std::shared_ptr<LoopHub> hub = std::make_shared<LoopHub>();
    std::shared_ptr<test::LoopBus> host = hub->open("host");
    std::shared_ptr<test::LoopBus> dev = hub->open("dev");
    std::shared_ptr<ObjectDictionary> od = make_od();
    std::unique_ptr<LocalNode> node;
    std::unique_ptr<SdoClient> sdo;

    void SetUp() override { start(); }
    void start(LocalNodeOptions o = {}, SdoClientOptions co = {}) {
        sdo.reset();
        node.reset();
        node = std::make_unique<LocalNode>(*dev, 5, od, o);
        co.timeout = co.timeout == std::chrono::seconds(1) ? 500ms : co.timeout;
        sdo = std::make_unique<SdoClient>(*host, 5, co);
    }
    void TearDown() override {
        sdo.reset();
        node.reset();
    }
    void nmt(std::uint8_t cs, std::uint8_t target = 5) {
        std::uint8_t d[2] = {cs, target};
        host->send(can::Frame::make(0, std::span(d, 2)));
    }
    template <class Pred>
    bool eventually(Pred p) {
        for (int i = 0; i < 2000; ++i) {
            if (p()) return true;
            std::this_thread::sleep_for(1ms);
        }
        return false;
    }
};

}  // namespace

TEST_F(NodeFixture, BootUpAndPreOperational) {
    ASSERT_TRUE(eventually([&] { return !hub->frames().empty(); }));
    auto f = hub->frames().front();
    EXPECT_EQ(f.id, 0x705u);
    EXPECT_EQ(hex(f.payload()), "00");
    EXPECT_EQ(node->nmt_state(), NmtState::PreOperational);
}

TEST_F(NodeFixture, ExpeditedRoundTripBytesOnTheWire) {
    hub->clear();
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 8);
    sdo->write_u8(0x2003, 0, 7);
    auto fr = hub->frames();
    ASSERT_EQ(fr.size(), 4u);
    EXPECT_EQ(fr[0].id, 0x605u);
    EXPECT_EQ(hex(fr[0].payload()), "40 01 60 00 00 00 00 00");
    EXPECT_EQ(fr[1].id, 0x585u);
    EXPECT_EQ(hex(fr[1].payload()), "4F 01 60 00 08 00 00 00");
    EXPECT_EQ(hex(fr[2].payload()), "2F 03 20 00 07 00 00 00");
    EXPECT_EQ(hex(fr[3].payload()), "60 03 20 00 00 00 00 00");
    EXPECT_EQ(od->at(0x2003, 0)->get_u64(), 7u);
}

TEST_F(NodeFixture, TypedHelpers) {
    sdo->write_i32(0x6003, 0, -123456);
    EXPECT_EQ(sdo->read_i32(0x6003, 0), -123456);
    sdo->write_u64(0x2010, 0, 0x0123456789ABCDEFull);
    EXPECT_EQ(sdo->read_u64(0x2010, 0), 0x0123456789ABCDEFull);
    sdo->write_f32(0x2011, 0, 1.5f);
    EXPECT_EQ(sdo->read_f32(0x2011, 0), 1.5f);
    sdo->write_f64(0x2012, 0, -2.25);
    EXPECT_EQ(sdo->read_f64(0x2012, 0), -2.25);
    sdo->write_i16(0x2013, 0, -2);
    EXPECT_EQ(sdo->read_i16(0x2013, 0), -2);
    EXPECT_EQ(sdo->read_string(0x1008, 0), "motor");
    sdo->write_string(0x1008, 0, "a longer device name");
    EXPECT_EQ(sdo->read_string(0x1008, 0), "a longer device name");
    // C14: a 1-byte value read as u32 is a type error, not a silent widening.
    EXPECT_THROW(sdo->read_u32(0x6001, 0), InvalidArgument);
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 8);
}

TEST_F(NodeFixture, AbortsSurfaceAsTypedErrors) {
    try {
        sdo->write_u8(0x2003, 0, 9);
        FAIL();
    } catch (const SdoAbortError& e) {
        EXPECT_EQ(e.code, 0x06090031u);
        EXPECT_EQ(e.index, 0x2003);
        EXPECT_NE(std::string(e.what()).find("written too high"), std::string::npos);
    }
    try {
        sdo->upload(0x5555, 0);
        FAIL();
    } catch (const SdoAbortError& e) {
        EXPECT_EQ(e.code, 0x06020000u);
    }
}

TEST_F(NodeFixture, SegmentedAndBlockBothWays) {
    for (std::size_t n : {0u, 1u, 5u, 7u, 8u, 13u, 14u, 889u, 890u, 1024u, 65536u}) {
        Bytes v = pattern(n);
        for (auto mode : {TransferMode::Segmented, TransferMode::Block}) {
            if (n > 4096 && mode == TransferMode::Segmented) continue;
            sdo->download(0x2201, 0, v, mode);
            EXPECT_EQ(od->at(0x2201, 0)->get(), v) << n;
            EXPECT_EQ(sdo->upload(0x2201, 0, mode), v) << n;
        }
    }
    EXPECT_EQ(sdo->upload(0x2201, 0, TransferMode::Auto).size(), 65536u);
}

TEST_F(NodeFixture, C1_NoServerTimesOutWithAbort) {
    SdoClientOptions co;
    co.timeout = 50ms;
    SdoClient lonely(*host, 9, co);
    hub->clear();
    EXPECT_THROW(lonely.read_u8(0x6001, 0), SdoTimeout);
    auto fr = hub->frames();
    ASSERT_EQ(fr.size(), 2u);
    EXPECT_EQ(hex(fr[1].payload()), "80 01 60 00 00 00 04 05");
    EXPECT_EQ(fr[1].id, 0x609u);
    // Bounded retries for reads only.
    SdoClientOptions co2 = co;
    co2.read_retries = 2;
    SdoClient retry(*host, 9, co2);
    hub->clear();
    EXPECT_THROW(retry.upload(0x6001, 0), motorbus::TimeoutError);
    EXPECT_EQ(hub->frames().size(), 6u);
    hub->clear();
    EXPECT_THROW(retry.write_u8(0x2003, 0, 1), SdoTimeout);
    EXPECT_EQ(hub->frames().size(), 2u);
}

TEST_F(NodeFixture, S17_SdoSilentWhileStopped) {
    nmt(0x02);
    ASSERT_TRUE(eventually([&] { return node->nmt_state() == NmtState::Stopped; }));
    SdoClientOptions co;
    co.timeout = 50ms;
    SdoClient quick(*host, 5, co);
    hub->clear();
    EXPECT_THROW(quick.read_u8(0x6001, 0), SdoTimeout);
    for (auto& f : hub->frames()) EXPECT_NE(f.id, 0x585u);
    EXPECT_GE(node->counters().sdo_while_stopped, 1u);
    nmt(0x80);
    ASSERT_TRUE(eventually([&] { return node->nmt_state() == NmtState::PreOperational; }));
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 8);
}

TEST_F(NodeFixture, NmtCommandsAndListeners) {
    std::vector<std::pair<NmtState, NmtState>> seen;
    std::mutex m;
    node->add_state_listener([&](NmtState a, NmtState b) {
        std::lock_guard l(m);
        seen.emplace_back(a, b);
    });
    nmt(0x01, 0);  // broadcast (N3)
    ASSERT_TRUE(eventually([&] { return node->nmt_state() == NmtState::Operational; }));
    nmt(0x02, 6);  // another node (N2)
    nmt(0x03, 5);  // unknown command (N4)
    std::uint8_t bad[3] = {0x02, 5, 0};
    host->send(can::Frame::make(0, std::span(bad, 3)));  // DLC 3 (N1)
    nmt(0x02, 200);
    sdo->read_u8(0x6001, 0);  // a round trip so the NMT frames were handled
    EXPECT_EQ(node->nmt_state(), NmtState::Operational);
    EXPECT_EQ(node->counters().nmt_ignored, 4u);
    od->at(0x2003, 0)->set_u64(7);
    hub->clear();
    nmt(0x81);  // reset node: defaults back, boot-up again
    ASSERT_TRUE(eventually([&] { return node->nmt_state() == NmtState::PreOperational; }));
    EXPECT_EQ(od->at(0x2003, 0)->get_u64(), 4u);
    ASSERT_TRUE(eventually([&] {
        for (auto& f : hub->frames())
            if (f.id == 0x705) return true;
        return false;
    }));
    std::lock_guard l(m);
    ASSERT_GE(seen.size(), 3u);
    EXPECT_EQ(seen[0], std::make_pair(NmtState::PreOperational, NmtState::Operational));
    EXPECT_EQ(seen[1], std::make_pair(NmtState::Operational, NmtState::Initialising));
    EXPECT_EQ(seen[2], std::make_pair(NmtState::Initialising, NmtState::PreOperational));
}

TEST_F(NodeFixture, S18_FloodIsBoundedOneResponsePerProcessedRequest) {
    // A hooked object: its requests go through the single-slot mailbox.
    od->at(0x6001, 0)->set_read_hook([](const Variable&, Bytes&) { return 0u; });
    hub->clear();
    const int n = 10000;
    auto req = H("40 01 60 00 00 00 00 00");
    for (int i = 0; i < n; ++i) host->send(can::Frame::make(0x605, req));
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 8);  // still serving after the flood
    ASSERT_TRUE(eventually([&] {
        auto c = node->counters();
        return c.sdo.requests + c.sdo.dropped >= static_cast<std::uint64_t>(n + 1);
    }));
    auto c = node->counters();
    EXPECT_EQ(c.sdo.requests + c.sdo.dropped, static_cast<std::uint64_t>(n + 1));
    std::size_t responses = 0;
    for (auto& f : hub->frames()) responses += f.id == 0x585;
    EXPECT_EQ(responses, c.sdo.requests);  // at most one response per processed request
    EXPECT_LE(responses, static_cast<std::size_t>(n + 1));
}

TEST_F(NodeFixture, ManyThreadsShareOneClient) {
    std::atomic<int> ok{0};
    std::vector<std::thread> ts;
    for (int t = 0; t < 4; ++t)
        ts.emplace_back([&, t] {
            for (int i = 0; i < 50; ++i) {
                const std::int32_t v = t * 1000 + i;
                if (i % 10 == 0) {
                    Bytes b = pattern(100 + static_cast<std::size_t>(t));
                    sdo->download(0x2201, 0, b, TransferMode::Block);
                    sdo->upload(0x2201, 0);
                }
                sdo->write_i32(0x6003, 0, v);
                (void)sdo->read_i32(0x6003, 0);
                ++ok;
            }
        });
    for (auto& t : ts) t.join();
    EXPECT_EQ(ok.load(), 200);
    EXPECT_EQ(sdo->counters().aborts_sent, 0u);
}

TEST_F(NodeFixture, ManyNodesInFlight) {
    std::vector<std::unique_ptr<LocalNode>> nodes;
    std::vector<std::unique_ptr<SdoClient>> clients;
    for (std::uint8_t id = 10; id < 20; ++id) {
        auto d = make_od();
        d->at(0x6001, 0)->set_u64(id);
        nodes.push_back(std::make_unique<LocalNode>(*dev, id, d));
        clients.push_back(std::make_unique<SdoClient>(*host, id));
    }
    std::vector<std::thread> ts;
    std::atomic<int> good{0};
    for (std::size_t k = 0; k < clients.size(); ++k)
        ts.emplace_back([&, k] {
            for (int i = 0; i < 20; ++i) good += clients[k]->read_u8(0x6001, 0) == 10 + k;
            Bytes b = pattern(2000 + k);
            clients[k]->download(0x2201, 0, b, TransferMode::Block);
            good += clients[k]->upload(0x2201, 0, TransferMode::Block) == b;
        });
    for (auto& t : ts) t.join();
    EXPECT_EQ(good.load(), 210);
}

TEST_F(NodeFixture, B13_LossyLinkStillCorrect) {
    // Drop every 50th SDO segment frame in either direction of a block transfer.
    std::atomic<int> count{0};
    hub->drop = [&](const can::Frame& f) {
        if (f.id != 0x605 && f.id != 0x585) return false;
        const std::uint8_t b0 = f.data[0];
        const bool segment = (b0 & 0x7F) != 0 && (b0 & 0x7F) < 0x60 && f.len == 8;
        return segment && ++count % 50 == 0;
    };
    SdoClientOptions co;
    co.timeout = 200ms;
    start({}, co);
    Bytes v = pattern(20000);
    for (int i = 0; i < 3; ++i) {
        try {
            sdo->download(0x2201, 0, v, TransferMode::Block);
            EXPECT_EQ(od->at(0x2201, 0)->get(), v);
            EXPECT_EQ(sdo->upload(0x2201, 0, TransferMode::Block), v);
        } catch (const SdoTimeout&) {
            // A dropped control frame (ack/end) ends in a timeout: allowed, never corrupt.
        } catch (const SdoAbortError&) {
        }
    }
    EXPECT_GT(sdo->counters().retransmit_requests + node->counters().sdo.ignored, 0u);
}

TEST_F(NodeFixture, ServicesGetTimersAndStateChanges) {
    struct Counter : NodeService {
        std::atomic<int> ticks{0}, changes{0};
        Nanos on_timer(LocalNode&, Nanos now) override {
            ++ticks;
            return ticks < 3 ? now + 1'000'000 : kNoDeadline;
        }
        void on_nmt_state(LocalNode&, NmtState, NmtState) override { ++changes; }
    };
    auto svc = std::make_shared<Counter>();
    node->add_service(svc);
    ASSERT_TRUE(eventually([&] { return svc->ticks >= 3; }));
    nmt(0x01);
    ASSERT_TRUE(eventually([&] { return svc->changes >= 1; }));
    EXPECT_EQ(&node->od(), od.get());
    EXPECT_EQ(node->node_id(), 5);
}

TEST(LocalNodeArgs, N14_InvalidNodeIdRefused) {
    auto hub = std::make_shared<LoopHub>();
    auto bus = hub->open();
    auto od = make_od();
    EXPECT_THROW(LocalNode(*bus, 0, od), InvalidArgument);
    EXPECT_THROW(LocalNode(*bus, 128, od), InvalidArgument);
}

// A second node on a node-ID already served on the medium is refused with its own
// type (a restarting device tells "taken" from other failures by it, not by text);
// a range error is not that type; once the first closes, the ID is free again.
TEST(LocalNodeArgs, ASecondNodeOnAServedIdIsNodeIdTaken) {
    auto hub = std::make_shared<LoopHub>();
    auto bus = hub->open();
    auto first = std::make_unique<LocalNode>(*bus, 9, make_od());
    EXPECT_THROW(LocalNode(*bus, 9, make_od()), NodeIdTaken);
    try {
        LocalNode(*bus, 0, make_od());
        ADD_FAILURE() << "node-ID 0 accepted";
    } catch (const NodeIdTaken&) {
        ADD_FAILURE() << "a range error reported as a taken ID";
    } catch (const InvalidArgument&) {
    }
    first->close();
    EXPECT_NO_THROW(LocalNode(*bus, 9, make_od()));
}

// LocalNodeOptions::on_reset is told which reset it was, after the defaults
// were restored and before the boot-up; sdo_require_dlc8 drops short requests.
TEST_F(NodeFixture, OnResetHookAndStrictDlc) {
    std::atomic<int> last{0};
    std::atomic<std::uint64_t> value_at_hook{0};
    LocalNodeOptions o;
    o.on_reset = [&](NmtCommand c) {
        last = static_cast<int>(c);
        value_at_hook = od->at(0x2003, 0)->get_u64();
    };
    o.sdo_require_dlc8 = true;
    start(o);
    sdo->write_u8(0x2003, 0, 7);
    nmt(0x82);
    ASSERT_TRUE(eventually([&] { return last == 0x82; }));
    EXPECT_EQ(value_at_hook, 7u);  // reset communication leaves 0x2000+ alone
    nmt(0x81);
    ASSERT_TRUE(eventually([&] { return last == 0x81; }));
    EXPECT_EQ(value_at_hook, 4u);  // reset node restored the default first
    ASSERT_TRUE(eventually([&] { return node->nmt_state() == NmtState::PreOperational; }));
    hub->clear();
    std::uint8_t shortreq[4] = {0x40, 0x01, 0x60, 0x00};
    host->send(can::Frame::make(0x605, std::span(shortreq, 4)));
    ASSERT_TRUE(eventually([&] { return node->counters().sdo_bad_dlc == 1; }));
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 8);
    for (const auto& f : hub->frames()) EXPECT_NE(f.id == 0x585u && f.payload()[0] == 0x80, true);
}

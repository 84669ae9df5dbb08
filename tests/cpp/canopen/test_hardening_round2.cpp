// Issue 28 ("Hardening, second round"), the CANopen core:
//  item 4 -- an SDO transfer in flight wakes with LinkDown when the link dies and
//            with ClosedError when the bus is closed from another thread, instead
//            of waiting for its timeout (forever with an infinite one);
//  item 6 (issue 22) -- two clients on one node's COB-IDs each get their own
//            answers (the other's are ignored and counted);
//  item 8 -- a TPDO re-configured while OPERATIONAL (disable, map, enable) is
//            sent again without an NMT change.
// Threads are involved: tools/sanitize.sh runs this suite under ASan and TSan.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <string>
#include <thread>

#include "motorbus/can/socketcand_bus.hpp"
#include "motorbus/can/socketcand_server.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/nmt.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/pdo_service.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/canopen/sdo_client_access.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

namespace {

// Runs `f` on another thread; the outcome as text and how long it took.
struct Outcome {
    std::string what;
    double seconds = 0;
};
template <class F>
std::future<Outcome> start(F f) {
    return std::async(std::launch::async, [f]() -> Outcome {
        const auto t0 = SteadyClock::now();
        std::string what = "returned";
        try {
            f();
        } catch (const LinkDown& e) {
            what = std::string("LinkDown: ") + e.what();
        } catch (const ClosedError& e) {
            what = std::string("ClosedError: ") + e.what();
        } catch (const std::exception& e) {
            what = std::string("other: ") + e.what();
        }
        return {what, std::chrono::duration<double>(SteadyClock::now() - t0).count()};
    });
}

SdoClientOptions patient() {
    SdoClientOptions o;
    // Long against the wake-up the tests expect (< 5 s), short enough that a
    // client that does not wake fails the test at its timeout instead of hanging it.
    o.timeout = 20s;
    return o;
}

}  // namespace

// Nobody answers node 9; the bus is closed from another thread mid-transfer.
TEST(SdoLinkLoss, CloseFromAnotherThreadEndsTheTransferWithClosedError) {
    auto bus = can::open_virtual("r2-close");
    SdoClient sdo(*bus, 9, patient());
    auto up = start([&] { sdo.upload(0x1000, 0); });
    std::this_thread::sleep_for(100ms);
    ASSERT_EQ(up.wait_for(0s), std::future_status::timeout) << "the upload ended before the close";
    bus->close();
    ASSERT_EQ(up.wait_for(25s), std::future_status::ready);
    const auto r = up.get();
    EXPECT_EQ(r.what.rfind("ClosedError: SDO 0x1000:00", 0), 0u) << r.what;
    // Generous: the point is "not at its timeout (20 s)", and sanitizers are slow.
    EXPECT_LT(r.seconds, 5.0);
}

// The socketcand server is killed while a client waits for a response
// (a download, then a block upload): LinkDown at once, naming the link.
TEST(SdoLinkLoss, KilledSocketcandServerEndsTheTransferWithLinkDown) {
    for (auto mode : {TransferMode::Auto, TransferMode::Block}) {
        auto served = can::open_virtual("r2-scd");
        can::SocketcandServerOptions so;
        so.host = "127.0.0.1";
        so.port = 0;
        auto server = std::make_unique<can::SocketcandServer>(served, so);
        can::SocketcandOptions co;
        co.keepalive_period = 0ms;  // EOF ends the link here, not silence
        auto client = can::open_socketcand("127.0.0.1", server->port(), "can0", co);
        SdoClient sdo(*client, 9, patient());
        auto t = start([&] {
            if (mode == TransferMode::Block)
                sdo.upload(0x2000, 0, TransferMode::Block);
            else
                sdo.write_u32(0x2000, 0, 7);
        });
        std::this_thread::sleep_for(100ms);
        ASSERT_EQ(t.wait_for(0s), std::future_status::timeout);
        server.reset();  // closes every client connection: EOF at the client
        ASSERT_EQ(t.wait_for(25s), std::future_status::ready);
        const auto r = t.get();
        EXPECT_EQ(r.what.rfind("LinkDown: SDO 0x2000:00", 0), 0u) << r.what;
        EXPECT_NE(r.what.find("lost during the transfer"), std::string::npos) << r.what;
        EXPECT_LT(r.seconds, 5.0);
        EXPECT_GE(client->link_losses(), 1u);
        // The next transfer does not wait either: the bus refuses at once.
        EXPECT_THROW(sdo.read_u32(0x2000, 0), LinkDown);
        client->close();
        served->close();
    }
}

// Issue 22: two processes (here two endpoints, as two socketcand clients would
// be) read different objects of one node on the same COB-IDs, concurrently.
// Each gets its own values; the other's responses are counted, not errors.
TEST(SdoTwoClients, EachGetsItsOwnAnswerOnSharedCobIds) {
    auto dev = can::open_virtual("r2-two");
    auto a_bus = can::open_virtual("r2-two");
    auto b_bus = can::open_virtual("r2-two");
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x6064, .name = "Position actual value", .type = DataType::Integer32,
                      .access = Access::RW, .default_value = std::int64_t{123456}});
    od->add_variable({.index = 0x606C, .name = "Velocity actual value", .type = DataType::Integer32,
                      .access = Access::RW, .default_value = std::int64_t{-777}});
    LocalNode node(*dev, 5, od);
    SdoClientOptions o;
    o.timeout = 2s;
    SdoClient a(*a_bus, 5, o), b(*b_bus, 5, o);
    constexpr int kReads = 400;
    std::atomic<int> a_bad{0}, b_bad{0};
    std::string a_err, b_err;
    auto run = [&](SdoClient& c, std::uint16_t index, std::int32_t expect, std::atomic<int>& bad, std::string& err) {
        for (int i = 0; i < kReads; ++i) {
            try {
                if (c.read_i32(index, 0) != expect) ++bad;
            } catch (const std::exception& e) {
                ++bad;
                err = e.what();
            }
        }
    };
    std::thread ta([&] { run(a, 0x6064, 123456, a_bad, a_err); });
    std::thread tb([&] { run(b, 0x606C, -777, b_bad, b_err); });
    ta.join();
    tb.join();
    EXPECT_EQ(a_bad.load(), 0) << a_err;
    EXPECT_EQ(b_bad.load(), 0) << b_err;
    // Every response reaches both clients: each saw the other's.
    EXPECT_GT(a.counters().foreign_responses + b.counters().foreign_responses, 0u);
    node.close();
}

// Item 8: TPDO 1 with an event timer runs; it is disabled long enough for the
// node to forget its timer, then re-configured by the CiA 301 procedure while
// the node stays OPERATIONAL.  It must be sent again, with the new mapping.
TEST(PdoReconfigure, TpdoReArmedWhileOperational) {
    auto dev = can::open_virtual("r2-tpdo");
    auto host = can::open_virtual("r2-tpdo");
    auto sniff = can::open_virtual("r2-tpdo");
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x6041, .name = "Statusword", .type = DataType::Unsigned16,
                      .access = Access::RO, .pdo_mappable = true, .default_value = std::uint64_t{0x0237}});
    od->add_variable({.index = 0x6064, .name = "Position actual value", .type = DataType::Integer32,
                      .access = Access::RO, .pdo_mappable = true, .default_value = std::int64_t{0x11223344}});
    LocalNode node(*dev, 5, od);
    auto pdo = PdoService::attach(node);
    BusSdoAccess sdo(*host);
    PdoConfig c;
    c.cob_id = 0x185;
    c.transmission_type = 255;
    c.event_timer_ms = 10;
    c.mapping = std::vector<PdoMapEntry>{{0x6041, 0, 16}};
    write_pdo(sdo, 5, c, PdoProcedure::Cia301);
    NmtMaster nmt(*host);
    nmt.start(5);
    auto count = [&](std::chrono::milliseconds window, std::size_t len) {
        // Frames of TPDO 1 with `len` data bytes seen in `window`.
        std::size_t n = 0;
        const auto until = SteadyClock::now() + window;
        while (SteadyClock::now() < until)
            if (auto f = sniff->recv(5ms); f && f->id == 0x185 && f->len == len) ++n;
        return n;
    };
    EXPECT_GE(count(300ms, 2), 3u) << "the first configuration is not sent";
    // A Poller stopping: TPDO 1 invalid (COB-ID bit 31).  Long enough for the
    // node's timer for this service to run and find nothing to schedule.
    sdo.write_u32(5, 0x1800, 1, 0x80000185u);
    std::this_thread::sleep_for(100ms);
    while (sniff->recv(0ms)) {
    }
    EXPECT_EQ(count(100ms, 2), 0u) << "a disabled TPDO is still sent";
    // The next Poller: disable, map (now 6041h + 6064h), enable, node still OPERATIONAL.
    c.mapping = std::vector<PdoMapEntry>{{0x6041, 0, 16}, {0x6064, 0, 32}};
    write_pdo(sdo, 5, c, PdoProcedure::Cia301);
    EXPECT_EQ(node.nmt_state(), NmtState::Operational);
    EXPECT_GE(count(500ms, 6), 3u) << "TPDO 1 re-configured while operational is not sent";
    node.close();
}

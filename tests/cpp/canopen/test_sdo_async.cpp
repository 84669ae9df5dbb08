// Completion-based SDO transfers (SdoClient::upload_async / download_async)
// against LocalNode on an in-process bus: every transfer type both ways,
// queued transfers in order, aborts, timeouts driven by check_deadline(),
// cancel, close with transfers pending, blocking and async on one client,
// and 127 nodes at once on the virtual bus.
#include <gtest/gtest.h>
#include <poll.h>

#include <dirent.h>

#include <atomic>
#include <map>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/runtime/completions.hpp"
#include "test_sdo_bus.hpp"
#include "test_sdo_util.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;
using motorbus::test::hex;
using motorbus::test::LoopHub;

using motorbus::test::pattern;

namespace {

std::shared_ptr<ObjectDictionary> make_od(std::uint32_t device_type = 0x00020192) {
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x1000, .name = "Device type", .type = DataType::Unsigned32, .access = Access::RO,
                      .default_value = std::uint64_t{device_type}});
    od->add_variable({.index = 0x6003, .name = "Position", .type = DataType::Integer32});
    od->add_variable({.index = 0x1008, .name = "Device name", .type = DataType::VisibleString,
                      .access = Access::RW, .default_value = Bytes{'m', 'o', 't', 'o', 'r'}});
    od->add_variable({.index = 0x2201, .name = "Blob", .type = DataType::Domain, .access = Access::RW,
                      .max_size = 1 << 20});
    return od;
}

Bytes le32(std::uint32_t v) { return {std::uint8_t(v), std::uint8_t(v >> 8), std::uint8_t(v >> 16), std::uint8_t(v >> 24)}; }

int threads_alive() {
    int n = 0;
    if (DIR* d = opendir("/proc/self/task")) {
        while (auto* e = readdir(d))
            if (e->d_name[0] != '.') ++n;
        closedir(d);
    }
    return n;
}

// What an event loop does: wait on the eventfd, drain, and call the clients'
// check_deadline() when their deadline is due.  Collects completions by token.
struct Waiter {
    std::shared_ptr<Completions> done = std::make_shared<Completions>();
    std::map<std::uint64_t, Completion> got;
    std::vector<std::uint64_t> order;  // tokens in completion order

    bool wait_for(std::size_t n, std::vector<SdoClient*> clients = {}, std::chrono::milliseconds limit = 5000ms) {
        const auto end = std::chrono::steady_clock::now() + limit;
        while (got.size() < n) {
            if (std::chrono::steady_clock::now() > end) return false;
            Nanos next = kNoDeadline;
            for (auto* c : clients) next = std::min(next, c->check_deadline());
            int ms = 20;
            if (next != kNoDeadline) ms = static_cast<int>(std::clamp<Nanos>((next - monotonic_ns()) / 1'000'000 + 1, 0, 20));
            pollfd p{done->fd(), POLLIN, 0};
            ::poll(&p, 1, ms);
            for (auto& c : done->drain()) {
                order.push_back(c.token);
                got[c.token] = std::move(c);
            }
        }
        return true;
    }
    Bytes bytes(std::uint64_t token) {
        auto& c = got.at(token);
        if (c.error) std::rethrow_exception(c.error);
        return std::any_cast<Bytes>(c.value);
    }
    template <class E>
    E error(std::uint64_t token) {
        auto& c = got.at(token);
        EXPECT_TRUE(c.error) << "token " << token << " succeeded";
        try {
            std::rethrow_exception(c.error);
        } catch (const E& e) {
            return e;
        } catch (const std::exception& e) {
            ADD_FAILURE() << "token " << token << ": unexpected error " << e.what();
        }
        throw std::runtime_error("no error");
    }
};

struct AsyncFixture : ::testing::Test {
    std::shared_ptr<LoopHub> hub = std::make_shared<LoopHub>();
    std::shared_ptr<test::LoopBus> host = hub->open("host");
    std::shared_ptr<test::LoopBus> dev = hub->open("dev");
    std::shared_ptr<ObjectDictionary> od = make_od();
    std::unique_ptr<LocalNode> node = std::make_unique<LocalNode>(*dev, 5, od);
    std::unique_ptr<SdoClient> sdo = std::make_unique<SdoClient>(*host, 5, SdoClientOptions{.timeout = 500ms});
    Waiter w;

    void TearDown() override {
        sdo.reset();
        node.reset();
    }
    // The frames the client sent (requests on 0x605), as hex payloads.
    std::vector<std::string> requests(std::uint32_t id = 0x605) {
        std::vector<std::string> r;
        for (const auto& f : hub->frames())
            if (f.id == id) r.push_back(hex(f.payload()));
        return r;
    }
};

TEST_F(AsyncFixture, ExpeditedUpAndDown) {
    sdo->download_async(0x6003, 0, le32(0xFFFFFF85), TransferMode::Auto, w.done, 1);
    sdo->upload_async(0x6003, 0, TransferMode::Auto, w.done, 2);
    ASSERT_TRUE(w.wait_for(2, {sdo.get()}));
    EXPECT_FALSE(w.got.at(1).error);
    EXPECT_FALSE(w.got.at(1).value.has_value());  // a download completes with no value
    EXPECT_EQ(w.bytes(2), le32(0xFFFFFF85));
    EXPECT_EQ(od->at(0x6003, 0)->get_i64(), -123);
    // The wire: one expedited download, then one expedited upload request.
    auto r = requests();
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(r[0], "23 03 60 00 85 FF FF FF");
    EXPECT_EQ(r[1], "40 03 60 00 00 00 00 00");
}

TEST_F(AsyncFixture, SegmentedUpAndDown) {
    const Bytes data = pattern(1000);
    sdo->download_async(0x2201, 0, data, TransferMode::Segmented, w.done, 1);
    sdo->upload_async(0x2201, 0, TransferMode::Auto, w.done, 2);
    sdo->upload_async(0x1008, 0, TransferMode::Auto, w.done, 3);
    ASSERT_TRUE(w.wait_for(3, {sdo.get()}));
    EXPECT_FALSE(w.got.at(1).error);
    EXPECT_EQ(w.bytes(2), data);
    EXPECT_EQ(w.bytes(3), (Bytes{'m', 'o', 't', 'o', 'r'}));
    EXPECT_EQ(requests()[0], "21 01 22 00 E8 03 00 00");  // segmented initiate, size 1000
}

TEST_F(AsyncFixture, BlockUpAndDown) {
    const Bytes data = pattern(20000);
    sdo->download_async(0x2201, 0, data, TransferMode::Block, w.done, 1);
    sdo->upload_async(0x2201, 0, TransferMode::Block, w.done, 2);
    ASSERT_TRUE(w.wait_for(2, {sdo.get()}));
    EXPECT_FALSE(w.got.at(1).error);
    EXPECT_EQ(w.bytes(2), data);
    auto r = requests();
    EXPECT_EQ(r[0].substr(0, 2), "C6");  // block download initiate, CRC, size indicated
    EXPECT_EQ(sdo->counters().transfers, 2u);
}

TEST_F(AsyncFixture, QueuedTransfersRunInOrderOneAtATime) {
    constexpr int n = 40;
    for (int i = 0; i < n; ++i) {
        sdo->download_async(0x6003, 0, le32(static_cast<std::uint32_t>(i * 1000)), TransferMode::Auto, w.done,
                            2 * i + 1);
        sdo->upload_async(0x6003, 0, TransferMode::Auto, w.done, 2 * i + 2);
    }
    ASSERT_TRUE(w.wait_for(2 * n, {sdo.get()}));
    for (int i = 0; i < 2 * n; ++i) EXPECT_EQ(w.order[i], static_cast<std::uint64_t>(i + 1));
    // Each read sees the write queued just before it: no two transfers overlapped.
    for (int i = 0; i < n; ++i) EXPECT_EQ(w.bytes(2 * i + 2), le32(static_cast<std::uint32_t>(i * 1000)));
    // On the wire strictly alternating request / response: never two requests in a row.
    std::uint32_t last = 0;
    for (const auto& f : hub->frames()) {
        if (f.id != 0x605 && f.id != 0x585) continue;
        EXPECT_NE(f.id, last) << "two frames of one direction in a row";
        last = f.id;
    }
    EXPECT_EQ(sdo->async_pending(), 0u);
}

TEST_F(AsyncFixture, AbortIsTheBlockingCallsError) {
    sdo->upload_async(0x7777, 0, TransferMode::Auto, w.done, 1);
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 2);  // the next one is unaffected
    ASSERT_TRUE(w.wait_for(2, {sdo.get()}));
    auto e = w.error<SdoAbortError>(1);
    EXPECT_EQ(e.code, 0x06020000u);
    EXPECT_EQ(w.bytes(2), le32(0x00020192));
}

TEST_F(AsyncFixture, TimeoutSendsTheAbortAndTheNextTransferRuns) {
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 60ms});  // nobody serves node 9
    const auto t0 = std::chrono::steady_clock::now();
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 1);
    sdo->download_async(0x6003, 0, le32(1), TransferMode::Auto, w.done, 2);
    // Nothing fires without check_deadline(): no timer thread.
    std::this_thread::sleep_for(100ms);
    EXPECT_EQ(w.done->pending(), 0u);
    ASSERT_TRUE(w.wait_for(2, {sdo.get()}));
    EXPECT_GE(std::chrono::steady_clock::now() - t0, 160ms);  // 100 ms idle + the second's 60 ms
    w.error<SdoTimeout>(1);
    w.error<SdoTimeout>(2);
    auto r = requests(0x609);
    ASSERT_EQ(r.size(), 4u);
    EXPECT_EQ(r[1], "80 00 10 00 00 00 04 05");  // abort 0x05040000 with the multiplexer
    EXPECT_EQ(r[2].substr(0, 11), "23 03 60 00");
    EXPECT_EQ(r[3], "80 03 60 00 00 00 04 05");
    EXPECT_EQ(sdo->counters().timeouts, 2u);
}

TEST_F(AsyncFixture, ReadRetriesApplyToAsyncUploads) {
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 30ms, .read_retries = 2});
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 1);
    ASSERT_TRUE(w.wait_for(1, {sdo.get()}));
    w.error<SdoTimeout>(1);
    EXPECT_EQ(sdo->counters().transfers, 3u);
}

TEST_F(AsyncFixture, BlockingCallerEnforcesAnOrphanedAsyncDeadline) {
    // An async transfer whose waiter never calls check_deadline() (its loop is
    // gone) cannot hold the channel: a blocking call behind it times it out.
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 50ms});
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 1);
    EXPECT_THROW(sdo->read_u32(0x1000, 0), SdoTimeout);
    ASSERT_TRUE(w.wait_for(1));
    w.error<SdoTimeout>(1);
}

TEST_F(AsyncFixture, CancelAbortsTheRunningTransferAndDropsQueuedOnes) {
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 2s});
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 1);
    sdo->upload_async(0x1000, 1, TransferMode::Auto, w.done, 2);
    sdo->upload_async(0x1000, 2, TransferMode::Auto, w.done, 3);
    EXPECT_TRUE(sdo->cancel(w.done, 2));   // queued: dropped
    EXPECT_TRUE(sdo->cancel(w.done, 1));   // running: aborted, 3 starts
    EXPECT_FALSE(sdo->cancel(w.done, 1));  // not pending any more
    EXPECT_EQ(sdo->async_pending(), 1u);
    auto r = requests(0x609);
    ASSERT_EQ(r.size(), 3u);
    EXPECT_EQ(r[0], "40 00 10 00 00 00 00 00");
    EXPECT_EQ(r[1], "80 00 10 00 00 00 00 08");  // abort 0x08000000 (general error)
    EXPECT_EQ(r[2], "40 00 10 02 00 00 00 00");
    sdo->close();
    ASSERT_TRUE(w.wait_for(1));
    EXPECT_EQ(w.got.size(), 1u);  // no completion for the cancelled ones
    w.error<ClosedError>(3);
}

TEST_F(AsyncFixture, CancelledTransferLeavesTheChannelUsable) {
    const Bytes data = pattern(50000);
    od->at(0x2201, 0)->set(data);
    sdo->upload_async(0x2201, 0, TransferMode::Segmented, w.done, 1);
    std::this_thread::sleep_for(2ms);  // mid-transfer
    sdo->cancel(w.done, 1);
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 2);
    ASSERT_TRUE(w.wait_for(1, {sdo.get()}));
    EXPECT_EQ(w.bytes(2), le32(0x00020192));
    EXPECT_EQ(sdo->read_u32(0x1000, 0), 0x00020192u);
    EXPECT_FALSE(w.got.count(1));
}

TEST_F(AsyncFixture, AfterACancelTheAbandonedTransfersLastAnswerIsIgnored) {
    // A hand-played server on node 9: the answer to the cancelled transfer's
    // segment request arrives after the next transfer's initiate went out.
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 2s});
    auto answer = [&](const std::string& h) {
        auto b = test::H(h);
        dev->send(can::Frame::make(0x589, std::span<const std::uint8_t>(b)));
    };
    auto sent = [&](std::size_t n) {
        for (int i = 0; i < 2000 && requests(0x609).size() < n; ++i) std::this_thread::sleep_for(1ms);
        return requests(0x609);
    };
    sdo->upload_async(0x2201, 0, TransferMode::Auto, w.done, 1);
    sent(1);
    answer("41 01 22 00 20 00 00 00");  // segmented, 32 bytes
    EXPECT_EQ(sent(2)[1], "60 00 00 00 00 00 00 00");
    EXPECT_TRUE(sdo->cancel(w.done, 1));
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 2);
    auto r = sent(4);
    EXPECT_EQ(r[2], "80 01 22 00 00 00 00 08");
    EXPECT_EQ(r[3], "40 00 10 00 00 00 00 00");
    answer("00 41 42 43 44 45 46 47");  // the stale segment
    answer("43 00 10 00 92 01 02 00");
    ASSERT_TRUE(w.wait_for(1, {sdo.get()}));
    EXPECT_EQ(w.bytes(2), le32(0x00020192));
    EXPECT_EQ(sdo->counters().ignored_frames, 1u);
    // Strict again afterwards: a segment answering an initiate is a protocol error.
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 3);
    sent(5);
    answer("00 41 42 43 44 45 46 47");
    ASSERT_TRUE(w.wait_for(2, {sdo.get()}));
    w.error<SdoProtocolError>(3);
}

TEST_F(AsyncFixture, CloseFailsEveryPendingTransferWithClosedError) {
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 5s});
    for (std::uint64_t t = 1; t <= 5; ++t) sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, t);
    sdo->close();
    ASSERT_TRUE(w.wait_for(5));
    for (std::uint64_t t = 1; t <= 5; ++t) w.error<ClosedError>(t);
    // Later transfers fail the same way, async and blocking.
    sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, 6);
    ASSERT_TRUE(w.wait_for(6));
    w.error<ClosedError>(6);
    EXPECT_THROW(sdo->read_u32(0x1000, 0), ClosedError);
}

TEST_F(AsyncFixture, DestroyingTheClientCompletesItsTransfers) {
    auto done = w.done;
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 5s});
    sdo->upload_async(0x1000, 0, TransferMode::Auto, done, 1);
    sdo.reset();
    ASSERT_TRUE(w.wait_for(1));
    w.error<ClosedError>(1);
}

TEST_F(AsyncFixture, BusCloseFailsTheRunningAndQueuedTransfers) {
    sdo = std::make_unique<SdoClient>(*host, 9, SdoClientOptions{.timeout = 5s});
    for (std::uint64_t t = 1; t <= 3; ++t) sdo->upload_async(0x1000, 0, TransferMode::Auto, w.done, t);
    host->close();
    ASSERT_TRUE(w.wait_for(3));  // at once: no check_deadline() needed
    for (std::uint64_t t = 1; t <= 3; ++t) w.error<ClosedError>(t);
}

TEST_F(AsyncFixture, BlockingAndAsyncTransfersDoNotInterleave) {
    const Bytes data = pattern(8000);
    od->at(0x2201, 0)->set(data);
    std::atomic<int> blocking_ok{0};
    for (std::uint64_t t = 1; t <= 10; ++t) sdo->upload_async(0x2201, 0, TransferMode::Segmented, w.done, t);
    std::thread other([&] {
        for (int i = 0; i < 5; ++i)
            if (sdo->upload(0x2201, 0) == data) ++blocking_ok;
    });
    ASSERT_TRUE(w.wait_for(10, {sdo.get()}, 20000ms));
    other.join();
    for (std::uint64_t t = 1; t <= 10; ++t) EXPECT_EQ(w.bytes(t), data);
    EXPECT_EQ(blocking_ok.load(), 5);
    EXPECT_EQ(sdo->counters().aborts_sent, 0u);
    EXPECT_EQ(sdo->counters().aborts_received, 0u);
}

TEST(SdoAsyncMany, OneHundredTwentySevenNodesAtOnceWithoutAThread) {
    auto host = can::open_virtual("sdo-async-127");
    auto dev = can::open_virtual("sdo-async-127");
    std::vector<std::unique_ptr<LocalNode>> nodes;
    std::vector<std::unique_ptr<SdoClient>> clients;
    for (int id = 1; id <= 127; ++id) {
        nodes.push_back(std::make_unique<LocalNode>(*dev, static_cast<std::uint8_t>(id),
                                                    make_od(0x00020000u + static_cast<std::uint32_t>(id))));
        clients.push_back(std::make_unique<SdoClient>(*host, static_cast<std::uint8_t>(id)));
    }
    Waiter w;
    std::vector<SdoClient*> all;
    for (auto& c : clients) all.push_back(c.get());
    for (int round = 0; round < 3; ++round) {
        w.got.clear();
        const int before = threads_alive();
        for (int id = 1; id <= 127; ++id)
            clients[id - 1]->upload_async(0x1000, 0, TransferMode::Auto, w.done, static_cast<std::uint64_t>(id));
        EXPECT_EQ(threads_alive(), before);  // 127 transfers in flight, not one thread more
        ASSERT_TRUE(w.wait_for(127, all));
        for (int id = 1; id <= 127; ++id)
            EXPECT_EQ(w.bytes(static_cast<std::uint64_t>(id)), le32(0x00020000u + static_cast<std::uint32_t>(id)));
    }
    // Completions arrive in bursts: fewer wake-ups than completions.
    EXPECT_EQ(w.done->pushed(), 3u * 127u);
    EXPECT_LT(w.done->wakeups(), w.done->pushed());
    clients.clear();
    nodes.clear();
}

}  // namespace

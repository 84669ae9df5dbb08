// AsyncReceiver and Bus::recv_or_wait: a bus's frames handed to an event loop
// through a Completions (one wake-up per burst, bounded queue, counted
// overflow, the end of the stream as an error).
#include <gtest/gtest.h>
#include <poll.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/can/async_receiver.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/runtime/completions.hpp"

using namespace motorbus;
using namespace motorbus::can;
using namespace std::chrono_literals;

namespace {

// A bus whose receive "thread" is the test: burst() delivers frames as one read.
class TestBus final : public Bus {
public:
    TestBus() : Bus("test") {}
    ~TestBus() override { close(); }
    void burst(const std::vector<Frame>& frames) { dispatch_batch(frames); }
    void one(const Frame& f) { dispatch(f); }
    void lose(const std::string& why) { link_lost(why); }

protected:
    void do_send(const Frame&, Deadline) override {}
    void do_close() override {}
};

Frame fr(std::uint32_t id, std::uint8_t b) { return Frame::make(id, std::vector<std::uint8_t>{b}); }

bool readable(int fd, int timeout_ms = 0) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) == 1 && (p.revents & POLLIN);
}

std::vector<Frame> batch_of(const Completion& c) { return std::any_cast<const std::vector<Frame>&>(c.value); }

}  // namespace

TEST(AsyncReceiver, ABurstWakesTheLoopOnceAndKeepsItsOrder) {
    auto bus = std::make_shared<TestBus>();
    auto done = std::make_shared<Completions>();
    AsyncReceiver rx(bus, {}, 1024);
    EXPECT_TRUE(rx.take_or_arm(64, done, 7).empty());  // nothing yet: armed
    for (int i = 0; i < 100; ++i) bus->one(fr(0x100 + i, static_cast<std::uint8_t>(i)));
    EXPECT_EQ(done->wakeups(), 1u);                     // 100 frames, one wake-up
    ASSERT_TRUE(readable(done->fd()));
    auto got = done->drain();
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].token, 7u);
    auto first = batch_of(got[0]);
    ASSERT_EQ(first.size(), 1u);
    EXPECT_EQ(first[0].id, 0x100u);
    // The rest of the burst is taken without another wake-up, in order, at most max at a time.
    auto rest = rx.take_or_arm(64, done, 8);
    ASSERT_EQ(rest.size(), 64u);
    auto tail = rx.take_or_arm(64, done, 9);
    ASSERT_EQ(tail.size(), 35u);
    rest.insert(rest.end(), tail.begin(), tail.end());
    for (int i = 0; i < 99; ++i) {
        EXPECT_EQ(rest[i].id, static_cast<std::uint32_t>(0x101 + i));
        EXPECT_EQ(rest[i].payload()[0], static_cast<std::uint8_t>(i + 1));
    }
    EXPECT_EQ(done->wakeups(), 1u);
    EXPECT_EQ(rx.counters().received, 100u);
    EXPECT_EQ(rx.counters().overflows, 0u);
}

TEST(AsyncReceiver, AFullQueueDropsTheNewestAndCountsIt) {
    auto bus = std::make_shared<TestBus>();
    auto done = std::make_shared<Completions>();
    AsyncReceiver rx(bus, {}, 4);
    std::vector<Frame> burst;
    for (int i = 0; i < 10; ++i) burst.push_back(fr(0x200, static_cast<std::uint8_t>(i)));
    bus->burst(burst);                                  // not armed: everything queues, 4 fit
    EXPECT_EQ(rx.queued(), 4u);
    EXPECT_EQ(rx.counters().overflows, 6u);
    EXPECT_EQ(rx.counters().received, 10u);
    auto got = rx.take(100);
    ASSERT_EQ(got.size(), 4u);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(got[i].payload()[0], i);  // the oldest kept
    EXPECT_EQ(done->wakeups(), 0u);
}

TEST(AsyncReceiver, FiltersChooseTheFramesAndTheBusQueueIsUntouched) {
    auto bus = std::make_shared<TestBus>();
    auto done = std::make_shared<Completions>();
    AsyncReceiver rx(bus, {Filter{0x180, 0x780, false, false}}, 16);  // TPDO1 of any node
    bus->burst({fr(0x181, 1), fr(0x701, 2), fr(0x18A, 3)});
    auto got = rx.take(16);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_EQ(got[0].id, 0x181u);
    EXPECT_EQ(got[1].id, 0x18Au);
    // recv() still sees all three: the stream is a subscription of its own.
    EXPECT_EQ(bus->recv_many(16, 0ms).size(), 3u);
}

TEST(AsyncReceiver, CloseEndsTheStreamAfterItsQueuedFrames) {
    auto bus = std::make_shared<TestBus>();
    auto done = std::make_shared<Completions>();
    AsyncReceiver rx(bus, {}, 16);
    bus->one(fr(0x300, 1));
    bus->close();
    EXPECT_TRUE(rx.ended());
    auto got = rx.take_or_arm(16, done, 1);             // queued before the close: still handed out
    ASSERT_EQ(got.size(), 1u);
    EXPECT_THROW(rx.take_or_arm(16, done, 2), ClosedError);

    // An armed waiter gets the error as its completion.
    auto bus2 = std::make_shared<TestBus>();
    AsyncReceiver rx2(bus2, {}, 16);
    EXPECT_TRUE(rx2.take_or_arm(16, done, 3).empty());
    bus2->lose("peer reset");
    auto c = done->drain();
    ASSERT_EQ(c.size(), 1u);
    EXPECT_EQ(c[0].token, 3u);
    EXPECT_THROW(std::rethrow_exception(c[0].error), LinkDown);

    // Closing the receiver itself: unsubscribed, nothing more is counted.
    AsyncReceiver rx3(bus2, {}, 16);
    rx3.close();
    rx3.close();  // idempotent
    EXPECT_THROW(rx3.take(1), ClosedError);
}

TEST(AsyncReceiver, DisarmDropsTheWaiter) {
    auto bus = std::make_shared<TestBus>();
    auto done = std::make_shared<Completions>();
    AsyncReceiver rx(bus, {}, 16);
    EXPECT_TRUE(rx.take_or_arm(16, done, 5).empty());
    EXPECT_TRUE(rx.disarm());
    EXPECT_FALSE(rx.disarm());
    bus->one(fr(0x400, 9));
    EXPECT_EQ(done->pending(), 0u);                     // queued for the next take, not pushed
    EXPECT_EQ(rx.take(16).size(), 1u);
    EXPECT_THROW(rx.take_or_arm(0, done, 6), InvalidArgument);
    EXPECT_THROW(AsyncReceiver(bus, {}, 0), InvalidArgument);
}

TEST(AsyncReceiver, FramesFromAVirtualBusThreadArriveInOrder) {
    auto tx = open_virtual("t-async-rx"), rxbus = open_virtual("t-async-rx");
    auto done = std::make_shared<Completions>();
    AsyncReceiver rx(rxbus, {}, 4096);
    std::vector<Frame> got;
    std::uint64_t token = 1;
    std::thread sender([&] {
        for (int i = 0; i < 500; ++i) tx->send(fr(0x123, static_cast<std::uint8_t>(i & 0xFF)));
    });
    // The loop: take what is there, else arm and wait for the descriptor.
    while (got.size() < 500) {
        auto now = rx.take_or_arm(128, done, token++);
        if (!now.empty()) {
            got.insert(got.end(), now.begin(), now.end());
            continue;
        }
        ASSERT_TRUE(readable(done->fd(), 5000)) << "no completion after " << got.size() << " frames";
        for (auto& c : done->drain()) {
            auto b = batch_of(c);
            got.insert(got.end(), b.begin(), b.end());
        }
    }
    sender.join();
    for (int i = 0; i < 500; ++i) ASSERT_EQ(got[i].payload()[0], static_cast<std::uint8_t>(i & 0xFF)) << i;
    EXPECT_LE(done->wakeups(), rx.counters().received);  // never more than one per frame
    EXPECT_EQ(rx.counters().overflows, 0u);
}

TEST(BusRecvOrWait, ServesTheRecvQueueThenWaitsWithACompletion) {
    auto bus = std::make_shared<TestBus>();
    auto done = std::make_shared<Completions>();
    bus->one(fr(0x10, 1));
    auto now = bus->recv_or_wait(8, done, 1);            // queued: returned at once
    ASSERT_EQ(now.size(), 1u);
    EXPECT_TRUE(bus->recv_or_wait(8, done, 2).empty());  // empty: a waiter
    bus->burst({fr(0x11, 2), fr(0x12, 3), fr(0x13, 4)});
    auto c = done->drain();
    ASSERT_EQ(c.size(), 1u);                              // the burst in one completion
    EXPECT_EQ(c[0].token, 2u);
    auto b = batch_of(c[0]);
    ASSERT_EQ(b.size(), 3u);
    EXPECT_EQ(b[2].id, 0x13u);
    EXPECT_EQ(bus->recv_many(8, 0ms).size(), 0u);        // taken from the recv() queue

    // A cancelled waiter is withdrawn; a later one gets the close as ClosedError.
    EXPECT_TRUE(bus->recv_or_wait(8, done, 3).empty());
    EXPECT_TRUE(bus->cancel_wait(done.get(), 3));
    EXPECT_FALSE(bus->cancel_wait(done.get(), 3));
    EXPECT_TRUE(bus->recv_or_wait(8, done, 4).empty());
    bus->close();
    c = done->drain();
    ASSERT_EQ(c.size(), 1u);
    EXPECT_EQ(c[0].token, 4u);
    EXPECT_THROW(std::rethrow_exception(c[0].error), ClosedError);
    EXPECT_THROW(bus->recv_or_wait(8, done, 5), ClosedError);
    EXPECT_THROW(bus->recv_or_wait(0, done, 6), InvalidArgument);
}

#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <memory>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/emcy.hpp"
#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/runtime/callback_slot.hpp"
#include "test_nmt_support.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using svc_test::bytes;
using svc_test::frame;
using namespace std::chrono_literals;

TEST(HeartbeatCodec, EncodeDecode) {
    auto f = encode_heartbeat(5, NodeState::Operational);
    EXPECT_EQ(f.id, 0x705u);
    EXPECT_EQ(bytes(f), std::vector<std::uint8_t>{0x05});
    auto m = decode_heartbeat(f);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->node_id, 5);
    EXPECT_EQ(m->state, NodeState::Operational);
    EXPECT_TRUE(decode_heartbeat(frame(0x77F, {0x00}))->is_boot_up());
    EXPECT_FALSE(decode_heartbeat(frame(0x700, {0x05})));  // node 0
    EXPECT_FALSE(decode_heartbeat(frame(0x705, {}, true)));  // node-guarding RTR
}

TEST(HeartbeatCodec, N6_DlcNotOneIgnored) {
    EXPECT_FALSE(decode_heartbeat(frame(0x705, {})));
    EXPECT_FALSE(decode_heartbeat(frame(0x705, {0x05, 0x00})));
    EXPECT_FALSE(decode_heartbeat(frame(0x705, {0x05, 0, 0, 0, 0, 0, 0, 0})));
}

TEST(HeartbeatCodec, N7_UnknownStatesAreUnknown) {
    for (std::uint8_t b : {0x42, 0x01, 0x85, 0xFF, 0x7E}) {
        auto m = decode_heartbeat(frame(0x705, {b}));
        ASSERT_TRUE(m);
        EXPECT_EQ(m->state, NodeState::Unknown) << int(b);
        EXPECT_EQ(m->raw_state, b);
    }
}

TEST(HeartbeatConsumerEntry, N12_DuplicateNodeAborts) {
    std::vector<std::uint32_t> entries{0x000503E8, 0, 0};  // node 5, 1000 ms at sub 1
    EXPECT_EQ(validate_consumer_entry(entries, 2, 0x000501F4), 0x06040043u);
    EXPECT_EQ(validate_consumer_entry(entries, 1, 0x000501F4), 0u);  // rewriting the same sub
    EXPECT_EQ(validate_consumer_entry(entries, 2, 0x00050000), 0u);  // time 0 = unused
    EXPECT_EQ(validate_consumer_entry(entries, 2, 0x000601F4), 0u);
}

TEST(HeartbeatConsumerEntry, N13_InvalidEntriesNeverArmed) {
    EXPECT_FALSE(decode_consumer_entry(0x000003E8));  // node 0
    EXPECT_FALSE(decode_consumer_entry(0x008003E8));  // node 128
    EXPECT_FALSE(decode_consumer_entry(0x00FF03E8));  // node 255 -> would be 0x7FF
    EXPECT_FALSE(decode_consumer_entry(0x010503E8));  // reserved bits
    EXPECT_EQ(validate_consumer_entry({}, 1, 0x010503E8), 0x06090030u);
    auto e = decode_consumer_entry(0x007F0064);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->node_id, 127);
    EXPECT_EQ(e->time_ms, 100);
}

struct ConsumerFixture : ::testing::Test {
    svc_test::Hub hub;
    std::shared_ptr<svc_test::HubBus> host = hub.open("host"), dev = hub.open("dev");
    SimClock clock{0};
    HeartbeatConsumer hc{*host, clock};
    std::vector<std::pair<int, HeartbeatEvent>> events;
    void SetUp() override {
        hc.on_event = [this](std::uint8_t n, HeartbeatEvent e, NodeState) { events.emplace_back(n, e); };
    }
    void beat(std::uint8_t node, std::uint8_t state) { dev->send(frame(0x700u + node, {state})); }
};

TEST_F(ConsumerFixture, N10_LostWithinConsumerTimePlusOneTick_ThenBack) {
    EmcyProducer emcy(*host, clock, 1);
    hc.on_event = [&](std::uint8_t n, HeartbeatEvent e, NodeState) {
        events.emplace_back(n, e);
        if (e == HeartbeatEvent::Lost) emcy.report(0x8130, 0x11);
    };
    hc.monitor(5, 100ms);
    clock.advance(1'000'000'000);
    EXPECT_EQ(hc.process(clock.now()), -1);  // never heard: not monitored yet
    EXPECT_TRUE(events.empty());
    beat(5, 0x05);
    const Nanos t0 = clock.now();
    EXPECT_EQ(hc.process(t0), t0 + 100'000'000);
    clock.advance(99'000'000);
    hc.process(clock.now());
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].second, HeartbeatEvent::Started);
    clock.advance(1'000'000);  // exactly the consumer time: lost on this tick
    hc.process(clock.now());
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[1], std::make_pair(5, HeartbeatEvent::Lost));
    EXPECT_TRUE(hc.health(5).lost);
    EXPECT_EQ(hc.health(5).timeouts, 1u);
    // EMCY 0x8130 went out.
    EXPECT_EQ(bytes(hub.log.back()), (std::vector<std::uint8_t>{0x30, 0x81, 0x11, 0, 0, 0, 0, 0}));
    EXPECT_EQ(hub.log.back().id, 0x81u);
    // Lost fires once, not on every tick.
    clock.advance(500'000'000);
    hc.process(clock.now());
    EXPECT_EQ(events.size(), 2u);
    beat(5, 0x05);
    EXPECT_EQ(events.back(), std::make_pair(5, HeartbeatEvent::Back));
    beat(5, 0x00);
    EXPECT_EQ(events.back(), std::make_pair(5, HeartbeatEvent::Reset));
    EXPECT_EQ(hc.health(5).boot_ups, 1u);
}

TEST_F(ConsumerFixture, OnlyMonitoredNodesAreCheckedAndForgetStopsIt) {
    // Three nodes beat; 5 and 127 are monitored (twice: a second monitor() only
    // changes the time), then 5 is forgotten and monitored again.
    hc.monitor(5, 100ms);
    hc.monitor(127, 300ms);
    hc.monitor(127, 200ms);
    for (std::uint8_t n : {5, 9, 127}) beat(n, 0x05);
    const Nanos t0 = clock.now();
    EXPECT_EQ(hc.process(t0), t0 + 100'000'000);  // the earliest deadline: node 5's
    hc.forget(5);
    EXPECT_EQ(hc.process(t0), t0 + 200'000'000);  // only 127 left
    clock.advance(250'000'000);
    events.clear();
    EXPECT_EQ(hc.process(clock.now()), -1);
    ASSERT_EQ(events.size(), 1u);  // 127 lost; 9 never monitored, 5 forgotten
    EXPECT_EQ(events[0], std::make_pair(127, HeartbeatEvent::Lost));
    hc.monitor(5, 100ms);
    beat(5, 0x05);
    EXPECT_EQ(hc.process(clock.now()), clock.now() + 100'000'000);
    hc.forget(127);
    hc.forget(9);  // not monitored: nothing to stop
    clock.advance(100'000'000);
    events.clear();
    EXPECT_EQ(hc.process(clock.now()), -1);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0], std::make_pair(5, HeartbeatEvent::Lost));
}

// Python's set_callback(None) on a running consumer replaced on_event while
// the consumer's threads called it (an abort under ASan in the sanitizer
// suite, a data race under TSan).  Replacing it while events fire is now safe.
TEST_F(ConsumerFixture, CallbackReplacedWhileEventsFire) {
    hc.monitor(5, 100ms);
    std::atomic<bool> stop{false};
    std::atomic<int> calls{0};
    std::thread beats([&] {
        for (int i = 0; !stop; ++i) beat(5, i % 2 ? 0x05 : 0x7F);  // every beat is a state change
    });
    // Until events have fired into many replaced callables (bounded: a broken feed fails below).
    for (int i = 0; (i < 3000 || calls.load() < 200) && i < 10'000'000; ++i) {
        auto token = std::make_shared<int>(i);  // heap state a destroyed callable would free
        if (i % 3 == 0)
            hc.on_event = nullptr;
        else
            hc.on_event = [token, &calls](std::uint8_t, HeartbeatEvent, NodeState) { calls += *token >= 0; };
    }
    stop = true;
    beats.join();
    EXPECT_GE(calls.load(), 200);
}

TEST(CallbackSlot, AReplacedCallableLivesUntilItsCallReturns) {
    CallbackSlot<void(int)> slot;
    auto held = std::make_shared<int>(1);
    const std::weak_ptr<int> watch = held;
    std::promise<void> entered, release;
    auto entered_f = entered.get_future();
    auto release_f = release.get_future().share();
    slot = [held = std::move(held), &entered, release_f](int) {
        entered.set_value();
        release_f.wait();
    };
    std::thread caller([&] { slot(1); });
    entered_f.wait();
    slot = nullptr;  // replaced while its call runs
    EXPECT_FALSE(static_cast<bool>(slot));
    EXPECT_FALSE(watch.expired());  // the call in progress still holds it
    release.set_value();
    caller.join();
    EXPECT_TRUE(watch.expired());  // released when that call returned
    slot(2);                       // cleared: nothing to call
}

TEST_F(ConsumerFixture, N6_BadDlcCountedAndNextValidWorks) {
    hc.monitor(5, 100ms);
    dev->send(frame(0x705, {}));
    dev->send(frame(0x705, {5, 5}));
    EXPECT_EQ(hc.ignored_frames(), 2u);
    EXPECT_EQ(hc.health(5).heartbeats, 0u);
    beat(5, 0x7F);
    EXPECT_EQ(hc.health(5).state, NodeState::PreOperational);
}

TEST_F(ConsumerFixture, N7_UnknownStateEventAndTimerRefreshed) {
    hc.monitor(5, 100ms);
    beat(5, 0x05);
    clock.advance(90'000'000);
    beat(5, 0x42);
    EXPECT_EQ(events.back(), std::make_pair(5, HeartbeatEvent::UnknownState));
    EXPECT_EQ(hc.health(5).state, NodeState::Unknown);
    EXPECT_EQ(hc.health(5).raw_state, 0x42);
    clock.advance(90'000'000);  // 180 ms after the first beat but 90 after the odd one
    hc.process(clock.now());
    EXPECT_FALSE(hc.health(5).lost);
}

TEST_F(ConsumerFixture, N11_FloodIsOnlyReportedOnChange) {
    hc.monitor(7, 1000ms);
    for (int i = 0; i < 1000; ++i) beat(7, 0x05);
    EXPECT_EQ(events.size(), 1u);  // Started only
    beat(7, 0x04);
    EXPECT_EQ(events.size(), 2u);
    EXPECT_EQ(events.back().second, HeartbeatEvent::StateChanged);
    EXPECT_EQ(hc.health(7).heartbeats, 1001u);
}

TEST(HeartbeatProducer, SendsOnGridWithState) {
    svc_test::Hub hub;
    auto dev = hub.open("dev");
    auto host = hub.open("host");
    SimClock clock{0};
    NodeState st = NodeState::PreOperational;
    HeartbeatProducer p(*dev, clock, 9, 100ms, [&] { return st; });
    p.send_boot_up();
    EXPECT_EQ(p.process(0), 100'000'000);
    clock.advance(50'000'000);
    EXPECT_EQ(p.process(clock.now()), 100'000'000);
    st = NodeState::Operational;
    clock.advance(50'000'000);
    p.process(clock.now());
    ASSERT_EQ(hub.log.size(), 3u);
    EXPECT_EQ(hub.log[0].id, 0x709u);
    EXPECT_EQ(bytes(hub.log[0]), std::vector<std::uint8_t>{0x00});
    EXPECT_EQ(bytes(hub.log[1]), std::vector<std::uint8_t>{0x7F});
    EXPECT_EQ(bytes(hub.log[2]), std::vector<std::uint8_t>{0x05});
    // After a stall it does not burst to catch up.
    clock.advance(1'000'000'000);
    p.process(clock.now());
    p.process(clock.now());
    EXPECT_EQ(hub.log.size(), 4u);
    p.set_period(0ns);
    clock.advance(1'000'000'000);
    EXPECT_EQ(p.process(clock.now()), -1);
    EXPECT_EQ(hub.log.size(), 4u);
}

// The producer's thread outlives its bus: a pulled cable (here: the bus
// closed under it) is counted, never a crash, and it produces again when it can.
TEST(HeartbeatProducer, ThreadSurvivesAClosedBusAndCountsTheFailures) {
    auto dev = can::open_virtual("hb-closed");
    RealClock clock;
    HeartbeatProducer p(*dev, clock, 9, 5ms, [] { return NodeState::Operational; });
    p.start();
    for (int i = 0; i < 2000 && p.sent() < 2; ++i) std::this_thread::sleep_for(1ms);
    EXPECT_GE(p.sent(), 2u);
    dev->close();
    // The idle period of the service thread is 10 ms: a few retries within 2 s.
    for (int i = 0; i < 2000 && p.send_failures() < 2; ++i) std::this_thread::sleep_for(1ms);
    EXPECT_GE(p.send_failures(), 2u);
    p.stop();
}

TEST(HeartbeatConsumerThread, DetectsLossOnRealClock) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    auto dev = hub.open("dev");
    RealClock clock;
    HeartbeatConsumer hc(*host, clock);
    std::mutex m;
    std::condition_variable cv;
    bool lost = false;
    hc.on_event = [&](std::uint8_t, HeartbeatEvent e, NodeState) {
        if (e == HeartbeatEvent::Lost) {
            std::lock_guard l(m);
            lost = true;
            cv.notify_all();
        }
    };
    hc.monitor(3, 20ms);
    hc.start();
    dev->send(frame(0x703, {0x05}));
    std::unique_lock l(m);
    EXPECT_TRUE(cv.wait_for(l, 2s, [&] { return lost; }));
    l.unlock();
    hc.stop();
}

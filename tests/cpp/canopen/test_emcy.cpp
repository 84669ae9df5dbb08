#include <gtest/gtest.h>

#include "motorbus/canopen/emcy.hpp"
#include "motorbus/errors.hpp"
#include "test_nmt_support.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using svc_test::bytes;
using svc_test::frame;
using namespace std::chrono_literals;

TEST(EmcyCodec, RoundTrip) {
    auto f = encode_emcy(5, 0x8130, 0x11, {1, 2, 3, 4, 5});
    EXPECT_EQ(f.id, 0x85u);
    EXPECT_EQ(bytes(f), (std::vector<std::uint8_t>{0x30, 0x81, 0x11, 1, 2, 3, 4, 5}));
    auto m = decode_emcy(f);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->node_id, 5);
    EXPECT_EQ(m->code, 0x8130);
    EXPECT_EQ(m->error_register, 0x11);
    EXPECT_EQ(m->manufacturer, (std::array<std::uint8_t, 5>{1, 2, 3, 4, 5}));
    EXPECT_FALSE(m->short_frame);
    EXPECT_EQ(emcy_code_text(0x8130), "life guard or heartbeat error");
    EXPECT_EQ(emcy_code_text(0x2310), "current");
    EXPECT_FALSE(decode_emcy(frame(0x080, {0, 0})));  // that is SYNC, not EMCY
    EXPECT_FALSE(decode_emcy(frame(0x100, {0, 0})));
}

TEST(EmcyCodec, E1_ShortFrameZeroFilledNoStaleBytes) {
    auto f = frame(0x85, {0x10, 0x23, 0x04});
    // Stale bytes beyond DLC must never show up in the result.
    for (std::size_t i = 3; i < 8; ++i) f.data[i] = 0xEE;
    auto m = decode_emcy(f);
    ASSERT_TRUE(m);
    EXPECT_TRUE(m->short_frame);
    EXPECT_EQ(m->code, 0x2310);
    EXPECT_EQ(m->error_register, 0x04);
    EXPECT_EQ(m->manufacturer, (std::array<std::uint8_t, 5>{0, 0, 0, 0, 0}));
    auto one = frame(0x85, {0x10});
    one.data[1] = 0xEE;
    auto m1 = decode_emcy(one);
    ASSERT_TRUE(m1);
    EXPECT_EQ(m1->code, 0x0010);
    EXPECT_FALSE(decode_emcy(frame(0x85, {})));  // DLC 0 carries no code
}

TEST(EmcyCodec, E2_FdFrameIgnored) {
    auto f = frame(0x85, {0x10, 0x23, 0x04, 0, 0, 0, 0, 0});
    f.flags = can::kFlagFd;
    f.len = 12;
    EXPECT_FALSE(decode_emcy(f));
    f.flags = 0;
    EXPECT_FALSE(decode_emcy(f));  // len > 8 without the flag too
}

TEST(EmcyCodec, E7_InconsistentErrorRegisterPassedThrough) {
    // A current error (0x2310) with error register "temperature" (bit 3): kept as sent.
    auto m = decode_emcy(frame(0x85, {0x10, 0x23, 0x08, 0, 0, 0, 0, 0}));
    ASSERT_TRUE(m);
    EXPECT_EQ(m->error_register, 0x08);
    auto r = decode_emcy(frame(0x85, {0x00, 0x00, 0xFF, 0, 0, 0, 0, 0}));
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->is_reset());
    EXPECT_EQ(r->error_register, 0xFF);
}

TEST(EmcyConsumer, HistoryBoundedActiveSetAndE3Reset) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    auto dev = hub.open("dev");
    EmcyConsumer c(*host, 4);
    std::vector<std::uint16_t> seen;
    c.on_emcy = [&](const EmcyMessage& m) { seen.push_back(m.code); };
    for (std::uint16_t i = 0; i < 10; ++i) dev->send(encode_emcy(5, static_cast<std::uint16_t>(0x1000 + i), 1));
    dev->send(encode_emcy(6, 0x3210, 4));
    auto h = c.history(5);
    ASSERT_EQ(h.size(), 4u);
    EXPECT_EQ(h.front().code, 0x1006);
    EXPECT_EQ(h.back().code, 0x1009);
    EXPECT_EQ(c.active(5).size(), 10u);
    EXPECT_EQ(seen.size(), 11u);
    dev->send(encode_emcy(5, 0x0000, 0));  // E3
    EXPECT_TRUE(c.active(5).empty());
    EXPECT_EQ(c.active(6), std::vector<std::uint16_t>{0x3210});  // other nodes untouched
    // Garbage is counted, and the next valid EMCY still works.
    dev->send(frame(0x85, {}));
    EXPECT_EQ(c.ignored_frames(), 1u);
    dev->send(encode_emcy(5, 0x4210, 8));
    EXPECT_EQ(c.active(5), std::vector<std::uint16_t>{0x4210});
    // wait() hands out unclaimed messages in order, each once.
    auto first = c.wait(6, 1ms);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->code, 0x3210);
    EXPECT_FALSE(c.wait(6, 1ms));
    EXPECT_EQ(c.wait(5, 1ms)->code, 0x1000);
    EXPECT_EQ(c.wait(0, 1ms)->code, 0x1001);
}

TEST(EmcyProducer, E6_InhibitEnforcedQueueBounded) {
    svc_test::Hub hub;
    auto dev = hub.open("dev");
    auto host = hub.open("host");
    SimClock clock{1'000'000'000};
    EmcyProducer p(*dev, clock, 5, 100 /* 10 ms */, 3);
    EXPECT_TRUE(p.report(0x2310, 1));
    for (std::uint16_t i = 0; i < 100; ++i) EXPECT_FALSE(p.report(static_cast<std::uint16_t>(0x3000 + i), 4));
    EXPECT_EQ(p.pending(), 3u);
    EXPECT_EQ(p.dropped(), 97u);
    EXPECT_EQ(hub.log.size(), 1u);
    EXPECT_EQ(p.process(clock.now()), 1'010'000'000);  // not before the inhibit time
    EXPECT_EQ(hub.log.size(), 1u);
    clock.advance(10'000'000);
    p.process(clock.now());
    EXPECT_EQ(hub.log.size(), 2u);
    EXPECT_EQ(bytes(hub.log[1])[0], 0x61);  // the newest three survive: 0x3061..0x3063
    clock.advance(5'000'000);
    p.process(clock.now());
    EXPECT_EQ(hub.log.size(), 2u);
    clock.advance(5'000'000);
    p.process(clock.now());
    clock.advance(10'000'000);
    EXPECT_EQ(p.process(clock.now()), -1);
    EXPECT_EQ(hub.log.size(), 4u);
    for (std::size_t i = 1; i < hub.log.size(); ++i) EXPECT_EQ(hub.log[i].id, 0x85u);
    EXPECT_EQ(p.sent(), 4u);
}

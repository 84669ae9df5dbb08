#include <gtest/gtest.h>

#include <thread>

#include "motorbus/canopen/sync.hpp"
#include "motorbus/canopen/time.hpp"
#include "motorbus/errors.hpp"
#include "test_nmt_support.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using svc_test::bytes;
using svc_test::frame;
using namespace std::chrono_literals;

TEST(SyncCodec, EncodeDecode) {
    EXPECT_EQ(encode_sync().len, 0);
    EXPECT_EQ(encode_sync().id, 0x80u);
    EXPECT_EQ(bytes(encode_sync(7)), std::vector<std::uint8_t>{7});
    EXPECT_THROW(encode_sync(0), InvalidArgument);
    EXPECT_THROW(encode_sync(241), InvalidArgument);
    SyncMessage m;
    EXPECT_EQ(decode_sync(frame(0x80, {}), m), SyncDecode::Ok);
    EXPECT_FALSE(m.counter);
    EXPECT_EQ(decode_sync(frame(0x80, {5}), m, 10), SyncDecode::Ok);
    EXPECT_EQ(m.counter, 5);
    EXPECT_EQ(decode_sync(frame(0x81, {}), m), SyncDecode::NotSync);
}

TEST(SyncCodec, N16_BadLengthOrCounter) {
    SyncMessage m;
    EXPECT_EQ(decode_sync(frame(0x80, {1, 2}), m), SyncDecode::BadLength);
    EXPECT_EQ(decode_sync(frame(0x80, {1, 2, 3, 4, 5, 6, 7, 8}), m), SyncDecode::BadLength);
    EXPECT_EQ(decode_sync(frame(0x80, {1}), m, 0), SyncDecode::BadLength);  // no counter configured
    EXPECT_EQ(decode_sync(frame(0x80, {}), m, 10), SyncDecode::BadLength);  // counter expected
    EXPECT_EQ(decode_sync(frame(0x80, {11}), m, 10), SyncDecode::BadCounter);
    EXPECT_EQ(decode_sync(frame(0x80, {0}), m, 10), SyncDecode::BadCounter);
    EXPECT_FALSE(m.counter);
    EXPECT_EQ(decode_sync(frame(0x80, {10}), m, 10), SyncDecode::Ok);  // next valid works
}

TEST(SyncProducer, SendsWithWrappingCounterAndMeasuresJitter) {
    svc_test::Hub hub;
    auto bus = hub.open("m");
    SyncProducer p(*bus, 1ms, 3);
    EXPECT_THROW(SyncProducer(*bus, 0ms), InvalidArgument);
    EXPECT_THROW(SyncProducer(*bus, 1ms, 1), InvalidArgument);
    p.start();
    while (p.sent() < 8) std::this_thread::sleep_for(1ms);
    p.stop();
    const auto n = p.sent();
    ASSERT_GE(hub.log.size(), 8u);
    EXPECT_EQ(hub.log.size(), n);
    for (std::size_t i = 0; i < hub.log.size(); ++i) {
        EXPECT_EQ(hub.log[i].id, 0x80u);
        EXPECT_EQ(bytes(hub.log[i]), std::vector<std::uint8_t>{static_cast<std::uint8_t>(i % 3 + 1)});
    }
    auto j = p.jitter();
    EXPECT_EQ(j.count, n - 1);
    EXPECT_LE(j.min_ns, j.mean_ns);
    EXPECT_LE(j.mean_ns, j.max_ns);
    EXPECT_GE(j.p99_abs_ns, 0.0);
    EXPECT_FALSE(p.running());
}

TEST(TimeCodec, RoundTripAndEpoch) {
    // 2026-11-21T13:54:12.345Z
    const std::int64_t unix_ms = 1'795'269'252'345;
    auto t = TimeOfDay::from_unix_ms(unix_ms);
    EXPECT_EQ(t.to_unix_ms(), unix_ms);
    EXPECT_EQ(t.ms_after_midnight, ((13 * 60 + 54) * 60 + 12) * 1000u + 345u);
    auto f = encode_time(t);
    EXPECT_EQ(f.id, 0x100u);
    EXPECT_EQ(f.len, 6);
    auto d = decode_time(f);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->days_since_1984, t.days_since_1984);
    EXPECT_EQ(TimeOfDay::from_unix_ms(kCanopenEpochUnixMs).days_since_1984, 0);
    EXPECT_THROW(TimeOfDay::from_unix_ms(0), InvalidArgument);
    // 1 day + 1 ms: 01 00 00 00 01 00
    EXPECT_EQ(bytes(encode_time({1, 1})), (std::vector<std::uint8_t>{1, 0, 0, 0, 1, 0}));
}

TEST(TimeCodec, RejectsMalformed) {
    EXPECT_FALSE(decode_time(frame(0x100, {1, 0, 0, 0, 1})));
    EXPECT_FALSE(decode_time(frame(0x100, {1, 0, 0, 0, 1, 0, 0})));
    EXPECT_FALSE(decode_time(frame(0x100, {0, 0, 0, 0x10, 1, 0})));  // reserved bits
    EXPECT_FALSE(decode_time(frame(0x100, {0x00, 0x5C, 0x26, 0x05, 1, 0})));  // 86 400 000 ms
    EXPECT_TRUE(decode_time(frame(0x100, {0xFF, 0x5B, 0x26, 0x05, 1, 0})));   // 86 399 999 ms
}

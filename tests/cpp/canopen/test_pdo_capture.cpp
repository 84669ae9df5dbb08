// PdoCaptureSource on a virtual bus: TPDO frames sent by a "drive" endpoint are
// unpacked (signed entries sign-extended) into the row, with the arrival time of
// the oldest TPDO; short frames are counted, not used; missing data is NaN and
// stale; a closed bus makes read() throw.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/pdo_capture_source.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;

namespace {
void wait_for(const std::function<bool()>& done) {
    for (int i = 0; i < 200 && !done(); ++i) std::this_thread::sleep_for(1ms);
}
}  // namespace

TEST(PdoCaptureSource, UnpacksTheTpdosIntoTheRow) {
    auto drive = can::open_virtual("pdo-capture-1");
    auto host = can::open_virtual("pdo-capture-1");
    // TPDO1: position (i32) + status (u16); TPDO2: velocity (i32).  Row: status, position, velocity.
    std::vector<CapturedPdo> pdos = {{0x185, {{0x6064, 0, 32, true}, {0x6041, 0, 16, false}}},
                                     {0x285, {{0x606C, 0, 32, true}}}};
    PdoCaptureSource src(*host, 5, pdos, {{0, 1}, {0, 0}, {1, 0}}, 50'000'000);
    ASSERT_EQ(src.columns(), 4u);
    double row[4];
    src.read(row);
    EXPECT_TRUE(std::isnan(row[0]) && std::isnan(row[1]));
    EXPECT_EQ(src.stale(), 1u);

    const std::uint8_t t1[6] = {0xFE, 0xFF, 0xFF, 0xFF, 0x37, 0x12};  // -2, 0x1237
    drive->send(can::Frame::make(0x185, t1));
    wait_for([&] { return src.received() == 1; });
    src.read(row);
    EXPECT_TRUE(std::isnan(row[0]));   // TPDO2 not yet: no arrival time, its value NaN
    EXPECT_EQ(row[1], 0x1237);
    EXPECT_EQ(row[2], -2.0);
    EXPECT_TRUE(std::isnan(row[3]));

    const std::uint8_t t2[4] = {0x10, 0x27, 0x00, 0x00};  // 10000
    const Nanos sent = monotonic_ns();
    drive->send(can::Frame::make(0x285, t2));
    wait_for([&] { return src.received() == 2; });
    src.read(row);
    EXPECT_EQ(row[3], 10000.0);
    ASSERT_FALSE(std::isnan(row[0]));
    EXPECT_LT(row[0], static_cast<double>(sent));  // the oldest: TPDO1's arrival
    EXPECT_EQ(src.stale(), 2u);                    // fresh now: no new stale read

    const std::uint8_t short_frame[3] = {1, 2, 3};
    drive->send(can::Frame::make(0x185, short_frame));
    wait_for([&] { return src.short_frames() == 1; });
    src.read(row);
    EXPECT_EQ(row[2], -2.0);  // unchanged

    host->close();
    EXPECT_THROW(src.read(row), ClosedError);
}

TEST(PdoCaptureSource, RefusesWhatCannotBeCaptured) {
    auto host = can::open_virtual("pdo-capture-2");
    EXPECT_THROW(PdoCaptureSource(*host, 5, {}, {}, 1'000'000), InvalidArgument);
    std::vector<CapturedPdo> one = {{0x185, {{0x6064, 0, 32, true}}}};
    EXPECT_THROW(PdoCaptureSource(*host, 5, one, {{0, 1}}, 1'000'000), InvalidArgument);   // no entry 1
    EXPECT_THROW(PdoCaptureSource(*host, 5, one, {{1, 0}}, 1'000'000), InvalidArgument);   // no TPDO 1
    std::vector<CapturedPdo> wide = {{0x185, {{0x6064, 0, 64, true}, {0x6041, 0, 16, false}}}};
    EXPECT_THROW(PdoCaptureSource(*host, 5, wide, {{0, 0}}, 1'000'000), InvalidArgument);  // > 64 bits
}

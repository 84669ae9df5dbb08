#include <gtest/gtest.h>

#include <vector>

#include "motorbus/can/frame.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::can;

TEST(Frame, ValidStandardAndExtended) {
    std::vector<std::uint8_t> d{1, 2, 3};
    auto f = Frame::make(0x7FF, d);
    EXPECT_EQ(f.len, 3);
    EXPECT_EQ(f.to_string(), "7FF#010203");
    auto e = Frame::make(0x1FFFFFFF, {}, true);
    EXPECT_EQ(e.to_string(), "1FFFFFFF#");
    auto r = Frame::make(0x123, {}, false, true, 4);
    EXPECT_EQ(r.to_string(), "123#R4");
    EXPECT_EQ(r.payload().size(), 0u);
}

TEST(Frame, RefusesInvalidFieldsNamingThem) {
    std::vector<std::uint8_t> nine(9, 0);
    try {
        Frame::make(0x800, {});
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("frame id"), std::string::npos);
    }
    try {
        Frame::make(0x1, nine);
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("frame data"), std::string::npos);
    }
    EXPECT_THROW(Frame::make(0x20000000, {}, true), InvalidArgument);
    EXPECT_THROW(Frame::make(0x1, {}, false, true, 9), InvalidArgument);
}

TEST(Frame, WorstCaseWireBits) {
    std::vector<std::uint8_t> eight(8, 0);
    EXPECT_EQ(wire_bits_worst_case(Frame::make(0x1, eight)), 135u);
    EXPECT_EQ(wire_bits_worst_case(Frame::make(0x1, eight, true)), 160u);
    EXPECT_EQ(wire_bits_worst_case(Frame::make(0x1, {})), 55u);  // 34+13+8
}

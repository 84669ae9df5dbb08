#include <gtest/gtest.h>

#include "motorbus/drives/dmac/codec.hpp"

using namespace motorbus::dmac;

TEST(DmacCodec, FormatsValuesInTheThreeRadixes) {
    EXPECT_EQ(format_value(123, Radix::Dec), "+123");
    EXPECT_EQ(format_value(-20000, Radix::Dec), "-20000");
    EXPECT_EQ(format_value(0, Radix::Dec), "+0");
    EXPECT_EQ(format_value(256, Radix::Hex), "h00000100");
    EXPECT_EQ(format_value(-10, Radix::Hex), "hFFFFFFF6");
    EXPECT_EQ(format_value(100, Radix::Bin), "b00000000 00000000 00000000 01100100");
}

TEST(DmacCodec, ParsesNumbersStrictly) {
    EXPECT_EQ(parse_number("H100"), 256);
    EXPECT_EQ(parse_number("hFFFFFFD8"), -40);
    EXPECT_EQ(parse_number("B1100100"), 100);
    EXPECT_EQ(parse_number("-40"), -40);
    EXPECT_EQ(parse_number("+2147483647"), 2147483647);
    EXPECT_EQ(parse_number("-2147483648"), -2147483647 - 1);
    EXPECT_FALSE(parse_number("2147483648"));
    EXPECT_FALSE(parse_number("+99999999999"));
    EXPECT_FALSE(parse_number("1e3"));
    EXPECT_FALSE(parse_number(""));
    EXPECT_FALSE(parse_number("+"));
    EXPECT_FALSE(parse_number("H123456789"));
    EXPECT_FALSE(parse_number("B2"));
}

// LineFramer: the pure reassembler behind LineLink and PtyLineServer.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "motorbus/errors.hpp"
#include "motorbus/serial/line_framer.hpp"

using namespace motorbus;
using namespace motorbus::serial;

namespace {
// Feeds `in` in chunks of `chunk` bytes; returns "L:<text>" / "O:<len>" per event.
std::vector<std::string> frame(LineFramer& f, const std::string& in, std::size_t chunk = 1000) {
    std::vector<std::string> out;
    for (std::size_t pos = 0; pos < in.size(); pos += chunk) {
        std::string part = in.substr(pos, chunk);
        std::span<const std::uint8_t> s(reinterpret_cast<const std::uint8_t*>(part.data()), part.size());
        while (!s.empty()) {
            std::size_t used = 0;
            auto line = f.push(s, used);
            EXPECT_LE(used, s.size());
            s = s.subspan(used);
            if (line)
                out.push_back(line->kind == FramedLine::Kind::Line ? "L:" + line->text
                                                                   : "O:" + std::to_string(line->length));
        }
    }
    return out;
}
using V = std::vector<std::string>;
}  // namespace

TEST(LineFramer, SplitAcrossEveryByteBoundary) {
    for (std::size_t chunk = 1; chunk <= 8; ++chunk) {
        LineFramer f({"\r\n"}, 64);
        EXPECT_EQ(frame(f, "123\r\n-45\r\n\r\n", chunk), (V{"L:123", "L:-45", "L:"})) << chunk;
    }
}

TEST(LineFramer, A11_OnlyConfiguredTerminatorsEndALine) {
    LineFramer nul({std::string("\0", 1)}, 64);
    EXPECT_EQ(frame(nul, std::string("12\r\n\0", 5)), (V{"L:12\r\n"}));
    LineFramer cr({"\r"}, 64);
    EXPECT_EQ(frame(cr, "5\n6\r"), (V{"L:5\n6"}));
    LineFramer crlf({"\r\n"}, 64);
    EXPECT_EQ(frame(crlf, "a\rb\n\r\n"), (V{"L:a\rb\n"}));
}

TEST(LineFramer, A11_PrefixTerminatorsDoNotMakeEmptyLines) {
    LineFramer f({"\r", "\r\n"}, 64);
    EXPECT_EQ(frame(f, "a\r\nb\rc\r\n", 1), (V{"L:a", "L:b", "L:c"}));
    // A lone LF that is not the continuation of CR is data.
    EXPECT_EQ(frame(f, "\nd\r"), (V{"L:\nd"}));
}

TEST(LineFramer, LongestTerminatorWinsAtTheSameByte) {
    LineFramer f({"\n", "\r\n"}, 64);
    EXPECT_EQ(frame(f, "x\r\ny\n"), (V{"L:x", "L:y"}));
}

TEST(LineFramer, A3_OverlongIsBoundedAndResyncs) {
    LineFramer f({"\r\n"}, 8);
    EXPECT_EQ(frame(f, "12345678\r\n"), (V{"L:12345678"}));      // exactly max_line
    EXPECT_EQ(frame(f, "123456789\r\n"), (V{"O:9"}));            // one over
    std::string huge(100000, 'Z');
    EXPECT_EQ(frame(f, huge + "\r\nok\r\n", 777), (V{"O:100000", "L:ok"}));
    EXPECT_LE(f.partial_bytes(), 0u);
}

TEST(LineFramer, OverlongPrefixKept) {
    LineFramer f({"\r"}, 4);
    std::string in = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789abcdef\r";
    std::span<const std::uint8_t> s(reinterpret_cast<const std::uint8_t*>(in.data()), in.size());
    std::size_t used = 0;
    auto line = f.push(s, used);
    ASSERT_TRUE(line);
    EXPECT_EQ(line->kind, FramedLine::Kind::Overlong);
    EXPECT_EQ(line->text, in.substr(0, LineFramer::kOverlongPrefix));
    EXPECT_EQ(line->length, in.size() - 1);
    EXPECT_EQ(used, in.size());
}

TEST(LineFramer, OverlongPrefixNeverIncludesTheTerminator) {
    LineFramer f({"\r\n"}, 4);
    std::string in = "toolongreply\r\n";
    std::span<const std::uint8_t> s(reinterpret_cast<const std::uint8_t*>(in.data()), in.size());
    std::size_t used = 0;
    auto line = f.push(s, used);
    ASSERT_TRUE(line);
    EXPECT_EQ(line->text, "toolongreply");
    EXPECT_EQ(line->length, 12u);
}

TEST(LineFramer, A10_NoiseBurstsThenValidLine) {
    LineFramer f({"\r\n"}, 16);
    std::string noise(200, '\xff');
    noise += std::string(200, '\0');
    EXPECT_EQ(frame(f, noise + "\r\n42\r\n", 3), (V{"O:400", "L:42"}));
}

TEST(LineFramer, StopsAtFirstLineAndReportsConsumed) {
    LineFramer f({"\r"}, 16);
    std::string in = "a\rb\r";
    std::span<const std::uint8_t> s(reinterpret_cast<const std::uint8_t*>(in.data()), in.size());
    std::size_t used = 0;
    auto l = f.push(s, used);
    ASSERT_TRUE(l);
    EXPECT_EQ(l->text, "a");
    EXPECT_EQ(used, 2u);
}

TEST(LineFramer, RejectsBadOptions) {
    EXPECT_THROW(LineFramer({}, 16), InvalidArgument);
    EXPECT_THROW(LineFramer({""}, 16), InvalidArgument);
    EXPECT_THROW(LineFramer({"123456789"}, 16), InvalidArgument);
    EXPECT_THROW(LineFramer({"\r"}, 0), InvalidArgument);
    EXPECT_THROW(LineFramer({"\r"}, (1u << 20) + 1), InvalidArgument);
}

TEST(LineFramer, ResetDropsPartial) {
    LineFramer f({"\r"}, 16);
    EXPECT_EQ(frame(f, "abc"), V{});
    EXPECT_EQ(f.partial_bytes(), 3u);
    f.reset();
    EXPECT_EQ(frame(f, "d\r"), (V{"L:d"}));
}

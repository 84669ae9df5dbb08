// socketcand codec: element parser (HOSTILE_INPUTS 2.8 rows K1-K7, K10) and encoders.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "motorbus/can/socketcand_codec.hpp"

using namespace motorbus;
using namespace motorbus::can;
using namespace motorbus::can::socketcand;

namespace {

struct Collected {
    std::vector<Element> elements;
    std::vector<std::string> errors;  // reason | element
};

Collected feed(ElementParser& p, std::string_view bytes) {
    Collected c;
    p.feed(std::span<const char>(bytes.data(), bytes.size()),
           [&](const Element& e) { c.elements.push_back(e); },
           [&](const ParseError& e) { c.errors.push_back(std::string(e.reason) + "|" + std::string(e.element)); });
    return c;
}

Element one(std::string_view text) {
    ElementParser p;
    auto c = feed(p, text);
    EXPECT_EQ(c.errors.size(), 0u) << (c.errors.empty() ? "" : c.errors[0]);
    EXPECT_EQ(c.elements.size(), 1u) << text;
    return c.elements.empty() ? Element{} : c.elements[0];
}

std::string refused(std::string_view text) {
    Element e;
    const char* why = parse_element(text, e);
    return why ? why : "";
}

std::vector<std::uint8_t> bytes_of(const Frame& f) {
    auto p = f.payload();
    return {p.begin(), p.end()};
}

}  // namespace

TEST(SocketcandCodec, ParsesFrameContiguousAndSpacedData) {
    auto e = one("< frame 123 23.424242 11223344 >");
    EXPECT_EQ(e.kind, ElementKind::Frame);
    EXPECT_EQ(e.frame.id, 0x123u);
    EXPECT_FALSE(e.frame.extended);
    EXPECT_EQ(bytes_of(e.frame), (std::vector<std::uint8_t>{0x11, 0x22, 0x33, 0x44}));
    EXPECT_EQ(e.remote_time_ns, 23'424'242'000LL);
    // protocol.md shows the bytes space-separated
    auto s = one("< frame 1AAAAAAA 1.5 11 22 33 44 >");
    EXPECT_TRUE(s.frame.extended);
    EXPECT_EQ(s.frame.id, 0x1AAAAAAAu);
    EXPECT_EQ(s.remote_time_ns, 1'500'000'000LL);
    EXPECT_EQ(bytes_of(s.frame), (std::vector<std::uint8_t>{0x11, 0x22, 0x33, 0x44}));
    auto empty = one("< frame 7FF 0.000001  >");
    EXPECT_EQ(empty.frame.len, 0);
    EXPECT_EQ(empty.remote_time_ns, 1000);
    auto lower = one("< frame 0ab 1.0 deadbeef >");
    EXPECT_EQ(lower.frame.id, 0xABu);
    EXPECT_EQ(bytes_of(lower.frame), (std::vector<std::uint8_t>{0xDE, 0xAD, 0xBE, 0xEF}));
}

TEST(SocketcandCodec, ParsesControlElements) {
    EXPECT_EQ(one("< hi >").kind, ElementKind::Hi);
    EXPECT_EQ(one("< ok >").kind, ElementKind::Ok);
    EXPECT_EQ(one("< echo >").kind, ElementKind::Echo);
    EXPECT_EQ(one("< rawmode >").kind, ElementKind::RawMode);
    EXPECT_EQ(one("< bcmmode >").kind, ElementKind::BcmMode);
    EXPECT_EQ(one("<hi>").kind, ElementKind::Hi);
    auto o = one("< open vcan0 >");
    EXPECT_EQ(o.kind, ElementKind::Open);
    EXPECT_EQ(o.text, "vcan0");
    auto et = one("< error unknown command >");
    EXPECT_EQ(et.kind, ElementKind::ErrorText);
    EXPECT_EQ(et.text, "unknown command");
    auto ef = one("< error 004 12.000100 >");
    EXPECT_EQ(ef.kind, ElementKind::ErrorFrame);
    EXPECT_EQ(ef.frame.id, 0x004u);
    EXPECT_TRUE(ef.frame.flags & kFlagError);
    EXPECT_EQ(ef.remote_time_ns, 12'000'100'000LL);
    auto r = one("< rtr 123 23.424242 4 >");
    EXPECT_EQ(r.kind, ElementKind::Rtr);
    EXPECT_TRUE(r.frame.rtr);
    EXPECT_EQ(r.frame.len, 4);
    auto u = one("< subscribe 0 0 123 >");
    EXPECT_EQ(u.kind, ElementKind::Unknown);
    EXPECT_EQ(u.text, "subscribe");
}

TEST(SocketcandCodec, ParsesSendAsPythonCanWritesIt) {
    // python-can writes bytes with "{x:x}": single digits for values below 0x10.
    auto e = one("< send 123 3 1 a ff >");
    EXPECT_EQ(e.kind, ElementKind::Send);
    EXPECT_EQ(e.frame.id, 0x123u);
    EXPECT_EQ(bytes_of(e.frame), (std::vector<std::uint8_t>{0x01, 0x0A, 0xFF}));
    auto x = one("< send 1AAAAAAA 2 1 F1 >");
    EXPECT_TRUE(x.frame.extended);
    EXPECT_EQ(bytes_of(x.frame), (std::vector<std::uint8_t>{0x01, 0xF1}));
    auto z = one("< send 123 0 >");
    EXPECT_EQ(z.frame.len, 0);
    auto rtr = one("< sendrtr 1AAAAAAA 2 >");
    EXPECT_EQ(rtr.kind, ElementKind::SendRtr);
    EXPECT_TRUE(rtr.frame.rtr && rtr.frame.extended);
    EXPECT_EQ(rtr.frame.len, 2);
    auto fd = one("< fdsend 123 01 12 0 1 2 3 4 5 6 7 8 9 a b >");
    EXPECT_EQ(fd.kind, ElementKind::FdSend);
    EXPECT_TRUE(fd.frame.is_fd());
    EXPECT_TRUE(fd.frame.flags & kFlagBrs);
    EXPECT_EQ(fd.frame.len, 12);
    EXPECT_EQ(fd.frame.data[11], 0x0B);
}

TEST(SocketcandCodec, K1_BytesBeforeFirstElementAreDiscarded) {
    ElementParser p;
    auto c = feed(p, "garbage\x01\xff< hi >");
    ASSERT_EQ(c.elements.size(), 1u);
    EXPECT_EQ(c.elements[0].kind, ElementKind::Hi);
    EXPECT_EQ(p.stats().discarded_bytes, 9u);
    EXPECT_TRUE(c.errors.empty());
}

TEST(SocketcandCodec, K2_UnterminatedElementIsCappedThenResyncs) {
    ElementParser p(64);
    std::string flood = "< frame 123 1.0 " + std::string(500, 'A');  // never closed
    auto c = feed(p, flood);
    EXPECT_TRUE(c.elements.empty());
    EXPECT_EQ(p.stats().overlong, 1u);
    EXPECT_FALSE(p.mid_element());
    // The rest of the flood, its stray '>' and the next good element.
    c = feed(p, std::string(300, 'B') + " > < frame 321 2.0 AA >");
    ASSERT_EQ(c.elements.size(), 1u);
    EXPECT_EQ(c.elements[0].frame.id, 0x321u);
    EXPECT_EQ(p.stats().overlong, 1u);
    // Waiting: a partial element is held (bounded) until its '>' arrives.
    c = feed(p, "< frame 456 3.0 ");
    EXPECT_TRUE(c.elements.empty());
    EXPECT_TRUE(p.mid_element());
    c = feed(p, "BB >");
    ASSERT_EQ(c.elements.size(), 1u);
    EXPECT_EQ(c.elements[0].frame.id, 0x456u);
}

TEST(SocketcandCodec, K2_NewOpeningBracketAbandonsThePartialElement) {
    ElementParser p;
    auto c = feed(p, "< frame 123 1.0 AA < frame 124 1.0 BB >");
    ASSERT_EQ(c.elements.size(), 1u);
    EXPECT_EQ(c.elements[0].frame.id, 0x124u);
    EXPECT_EQ(p.stats().interrupted, 1u);
}

TEST(SocketcandCodec, K2_ElementExactlyAtTheCapIsAccepted) {
    std::string e = "< frame 123 1.0 1122 >";
    ElementParser exact(e.size());
    EXPECT_EQ(feed(exact, e).elements.size(), 1u);
    ElementParser shorter(e.size() - 1);
    EXPECT_EQ(feed(shorter, e).elements.size(), 0u);
    EXPECT_EQ(shorter.stats().overlong, 1u);
}

TEST(SocketcandCodec, K3_ClosingBracketBeforeOpeningIsDiscarded) {
    ElementParser p;
    auto c = feed(p, "> >>x< ok >");
    ASSERT_EQ(c.elements.size(), 1u);
    EXPECT_EQ(c.elements[0].kind, ElementKind::Ok);
    EXPECT_EQ(p.stats().discarded_bytes, 4u);
}

TEST(SocketcandCodec, K5_BadElementIsDroppedCountedAndParsingContinues) {
    ElementParser p;
    auto c = feed(p,
                  "< frame XYZ 1.0 AA >"          // bad hex id
                  "< frame 123 1.0.0 AA >"        // bad timestamp
                  "< frame 123 abc AA >"          // bad timestamp
                  "< frame 123 -1.0 AA >"         // negative timestamp
                  "< frame 123 1. AA >"           // empty fraction
                  "< frame 123 1.0 ABC >"         // odd data hex
                  "< frame 123 1.0 A B >"         // odd data hex per token
                  "< frame 123 1.0 GG >"          // non-hex data
                  "< frame 123 >"                 // no timestamp
                  "< frame 125 9.000001 0102 >");  // the next valid one still works
    EXPECT_EQ(c.errors.size(), 9u);
    EXPECT_EQ(p.stats().bad_elements, 9u);
    ASSERT_EQ(c.elements.size(), 1u);
    EXPECT_EQ(c.elements[0].frame.id, 0x125u);
    EXPECT_EQ(bytes_of(c.elements[0].frame), (std::vector<std::uint8_t>{1, 2}));
    EXPECT_NE(c.errors[0].find("id"), std::string::npos);
    EXPECT_NE(c.errors[1].find("timestamp"), std::string::npos);
    EXPECT_NE(c.errors[5].find("odd"), std::string::npos);
    // and again: no poison pill left behind
    c = feed(p, "< frame 126 1.0 03 >");
    ASSERT_EQ(c.elements.size(), 1u);
    EXPECT_EQ(c.elements[0].frame.id, 0x126u);
}

TEST(SocketcandCodec, K6_DataLongerThanTheFrameIsRefused) {
    EXPECT_EQ(refused("< frame 123 1.0 112233445566778899 >"), "data: too many bytes");
    std::string big = "< frame 123 1.0 " + std::string(600, 'A') + " >";  // python-can: 300-byte frame
    EXPECT_EQ(refused(big), "data: too many bytes");
    EXPECT_EQ(refused("< frame 123 1.0 1122334455667788 >"), "");  // exactly 8 is fine
    std::string fd64 = "< fdframe 123 00 1.0 " + std::string(128, '5') + " >";
    EXPECT_EQ(refused(fd64), "");
    std::string fd65 = "< fdframe 123 00 1.0 " + std::string(130, '5') + " >";
    EXPECT_EQ(refused(fd65), "data: too many bytes");
    EXPECT_NE(refused("< fdframe 123 00 1.0 112233445566778899 >"), "");  // 9: not an FD length
}

TEST(SocketcandCodec, K7_IdOutOfRangeForItsWidthIsRefused) {
    EXPECT_EQ(refused("< frame 800 1.0 >"), "id: above 7FF");
    EXPECT_EQ(refused("< frame 7FF 1.0 >"), "");
    EXPECT_EQ(refused("< frame FFFFFFFF 1.0 >"), "id: above 1FFFFFFF");
    EXPECT_EQ(refused("< frame 20000000 1.0 >"), "id: above 1FFFFFFF");
    EXPECT_EQ(refused("< frame 1FFFFFFF 1.0 >"), "");
    EXPECT_EQ(refused("< frame 123456789 1.0 >"), "id: needs 1-8 hex digits");
    EXPECT_EQ(refused("< send 800 0 >"), "id: above 7FF");
    EXPECT_EQ(refused("< send FFFFFFFF 0 >"), "id: above 1FFFFFFF");
}

TEST(SocketcandCodec, K10_SendWithBadDlcOrItemCountIsRefused) {
    EXPECT_EQ(refused("< send 123 9 1 2 3 4 5 6 7 8 9 >"), "dlc: above 8");
    EXPECT_EQ(refused("< send 123 3 1 2 >"), "send: byte count differs from dlc");
    EXPECT_EQ(refused("< send 123 1 1 2 >"), "send: byte count differs from dlc");
    EXPECT_EQ(refused("< send 123 2 1 123 >"), "data: each byte needs 1-2 hex digits");
    EXPECT_EQ(refused("< send 123 1 zz >"), "data: not hex");
    EXPECT_EQ(refused("< send 123 >"), "send: needs id and dlc");
    EXPECT_EQ(refused("< send 123 x >"), "dlc: not decimal");
    EXPECT_EQ(refused("< sendrtr 123 9 >"), "dlc: above 8");
}

TEST(SocketcandCodec, RefusesArgumentsOnBareCommandsAndLongChannelNames) {
    EXPECT_NE(refused("< hi there >"), "");
    EXPECT_NE(refused("< >"), "");
    EXPECT_NE(refused("< open >"), "");
    EXPECT_NE(refused("< open abcdefghijklmnopq >"), "");  // 17 chars
    EXPECT_EQ(refused("< open abcdefghijklmnop >"), "");   // 16 chars
}

TEST(SocketcandCodec, ElementsSplitAcrossFeedsOneByteAtATime) {
    ElementParser p;
    std::string s = "< hi >< frame 1ABCDEF0 5.000007 0102030405060708 >< ok >";
    std::vector<Element> got;
    for (char c : s)
        p.feed(std::span<const char>(&c, 1), [&](const Element& e) { got.push_back(e); },
               [](const ParseError&) { FAIL(); });
    ASSERT_EQ(got.size(), 3u);
    EXPECT_EQ(got[1].frame.id, 0x1ABCDEF0u);
    EXPECT_EQ(got[1].frame.len, 8);
    EXPECT_EQ(got[2].kind, ElementKind::Ok);
}

TEST(SocketcandCodec, EncodesFramesLikeSocketcand) {
    std::string out;
    std::vector<std::uint8_t> d{0x11, 0x22, 0x33, 0x44};
    encode_frame(Frame::make(0x123, d), 23'424'242'000LL, out);
    EXPECT_EQ(out, "< frame 123 23.424242 11223344 >");
    out.clear();
    encode_frame(Frame::make(0x1AAAAAAA, {}, true), 1'000'000'000LL, out);
    EXPECT_EQ(out, "< frame 1AAAAAAA 1.000000  >");  // two blanks: empty data field
    out.clear();
    encode_frame(Frame::make(0x12, {}, false, true, 4), 0, out);
    EXPECT_EQ(out, "< rtr 012 0.000000 4 >");
    out.clear();
    Frame err;
    err.id = 0x4;
    err.extended = true;
    err.flags = kFlagError;
    encode_frame(err, 5'000'001'000LL, out);
    EXPECT_EQ(out, "< error 004 5.000001 >");
    out.clear();
    encode_error_text("bad <thing>", out);
    EXPECT_EQ(out, "< error bad ?thing? >");
}

TEST(SocketcandCodec, EncodesSendAndCommands) {
    std::string out;
    std::vector<std::uint8_t> d{0x01, 0xF1};
    encode_send(Frame::make(0x1AAAAAAA, d, true), out);
    EXPECT_EQ(out, "< send 1AAAAAAA 2 01 F1 >");
    out.clear();
    encode_send(Frame::make(0x123, {}), out);
    EXPECT_EQ(out, "< send 123 0 >");
    out.clear();
    encode_send(Frame::make(0x7FF, {}, false, true, 8), out);
    EXPECT_EQ(out, "< sendrtr 7FF 8 >");
    out.clear();
    encode_command(ElementKind::RawMode, out);
    encode_open("vcan0", out);
    EXPECT_EQ(out, "< rawmode >< open vcan0 >");
}

TEST(SocketcandCodec, RoundTripEveryIdWidthAndDlc) {
    for (bool ext : {false, true}) {
        for (std::uint32_t id : {0u, 1u, 0x7FFu, 0x1FFFFFFFu}) {
            if (!ext && id > 0x7FF) continue;
            for (std::size_t len = 0; len <= 8; ++len) {
                static constexpr std::uint8_t kBytes[8] = {0xF0, 0xF1, 0xF2, 0xF3,
                                                           0xF4, 0xF5, 0xF6, 0xF7};
                Frame f = Frame::make(id, std::span(kBytes, len), ext);
                std::string wire, sent;
                encode_frame(f, 42'000'001'000LL, wire);
                encode_send(f, sent);
                Element a = one(wire), b = one(sent);
                EXPECT_TRUE(a.frame.same_content(f)) << wire;
                EXPECT_TRUE(b.frame.same_content(f)) << sent;
                EXPECT_EQ(a.remote_time_ns, 42'000'001'000LL);
            }
        }
    }
}

// parse_element has a fast path for the canonical `< frame ... >` and
// `< send ... >` shapes; near-misses must still go the general way, with the
// same result or the same reason.
TEST(SocketcandCodec, FastPathAndGeneralPathAgreeOnNearMisses) {
    // Accepted by both paths: canonical shape vs. a variant only the general path takes.
    struct Pair {
        const char* canonical;
        const char* variant;
    };
    const Pair same[] = {
        {"< frame 123 5.000000 1122 >", "< frame 123 5 11 22 >"},
        {"< frame 1234 5.1 >", "<  frame 00001234  5.100 >"},  // empty data, 29-bit by width
        {"< frame 7FF 0.000001  >", "< frame 7ff 0.000001 >"},
        {"< send 123 2 a bc >", "< send 123 02 0a bc >"},
        {"< send 1FFFFFFF 0 >", "< send  1fffffff  0  >"},
    };
    for (const Pair& p : same) {
        const Element a = one(p.canonical), b = one(p.variant);
        EXPECT_EQ(a.kind, b.kind) << p.canonical;
        EXPECT_EQ(a.remote_time_ns, b.remote_time_ns) << p.canonical;
        EXPECT_EQ(a.frame.id, b.frame.id) << p.canonical;
        EXPECT_EQ(a.frame.extended, b.frame.extended) << p.canonical;
        EXPECT_EQ(a.frame.len, b.frame.len) << p.canonical;
        EXPECT_EQ(a.frame.data, b.frame.data) << p.canonical;
    }
    const Element f = one("< frame 12345678 1700000000.123456789 0011223344556677 >");
    EXPECT_EQ(f.kind, ElementKind::Frame);
    EXPECT_EQ(f.frame.id, 0x12345678u);
    EXPECT_TRUE(f.frame.extended);
    EXPECT_EQ(f.remote_time_ns, 1'700'000'000'123'456'789LL);
    EXPECT_EQ(f.frame.len, 8);
    EXPECT_EQ(f.frame.data[7], 0x77);
    // Near misses of the fast shapes keep the general path's reasons (K5, K6, K7, K10).
    EXPECT_EQ(refused("< frame 800 1.0 11 >"), "id: above 7FF");
    EXPECT_EQ(refused("< frame 123 1.0 112 >"), "data: odd number of hex digits");
    EXPECT_EQ(refused("< frame 123 1.0 001122334455667788 >"), "data: too many bytes");
    EXPECT_EQ(refused("< frame 123 1.0123456789 11 >"), "timestamp: bad fraction");
    EXPECT_EQ(refused("< frame 123 99999999999.0 11 >"), "timestamp: bad seconds");
    EXPECT_EQ(refused("< send 123 3 1 2 >"), "send: byte count differs from dlc");
    EXPECT_EQ(refused("< send 123 2 1 2 3 >"), "send: byte count differs from dlc");
    EXPECT_EQ(refused("< send 123 9 1 2 3 4 5 6 7 8 9 >"), "dlc: above 8");
    EXPECT_EQ(refused("< send 123 1 123 >"), "data: each byte needs 1-2 hex digits");
    EXPECT_EQ(refused("< send 123 1 1g >"), "data: not hex");
}

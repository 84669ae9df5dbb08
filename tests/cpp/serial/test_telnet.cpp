// The Telnet parser and RFC 2217 codec behind rfc2217:// lines, as pure code.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "motorbus/serial/telnet.hpp"

using namespace motorbus::serial;
using namespace motorbus::serial::telnet;
using Bytes = std::vector<std::uint8_t>;

namespace {
Parser client() { return Parser({OPT_BINARY, OPT_SGA, OPT_COM_PORT}, {OPT_BINARY, OPT_SGA, OPT_COM_PORT}); }

Output feed(Parser& p, const Bytes& in) {
    Output out;
    p.feed(in, out);
    return out;
}

Bytes str(const std::string& s) { return {s.begin(), s.end()}; }
}  // namespace

TEST(TelnetParser, PlainDataPassesUnchanged) {
    auto p = client();
    Bytes all;
    for (int i = 0; i < 255; ++i) all.push_back(static_cast<std::uint8_t>(i));  // every byte but IAC
    auto out = feed(p, all);
    EXPECT_EQ(out.data, all);
    EXPECT_TRUE(out.events.empty());
    EXPECT_TRUE(out.answer.empty());
}

TEST(TelnetParser, IacIacIsOneDataByte) {
    auto p = client();
    auto out = feed(p, {'a', IAC, IAC, 'b', IAC, IAC});
    EXPECT_EQ(out.data, (Bytes{'a', 0xFF, 'b', 0xFF}));
}

TEST(TelnetParser, AnyPartitionGivesTheSameResult) {
    Bytes stream = {'x', IAC, WILL, OPT_BINARY, 'y', IAC, IAC, IAC, SB, OPT_COM_PORT, 101, 0, 0, 0x25, 0x80,
                    IAC, SE, 'z', IAC, NOP, IAC, DO, 24, '!'};
    auto whole_p = client();
    auto whole = feed(whole_p, stream);
    auto split_p = client();
    Output split;
    for (auto b : stream) split_p.feed(std::span(&b, 1), split);
    EXPECT_EQ(whole.data, split.data);
    EXPECT_EQ(whole.events, split.events);
    EXPECT_EQ(whole.answer, split.answer);
    EXPECT_EQ(whole.data, str("xy\xffz!"));
}

TEST(TelnetParser, AcceptsWantedOptionsOnceAndRefusesOthers) {
    auto p = client();
    auto out = feed(p, {IAC, DO, OPT_BINARY, IAC, WILL, OPT_SGA});
    EXPECT_EQ(out.answer, (Bytes{IAC, WILL, OPT_BINARY, IAC, DO, OPT_SGA}));
    EXPECT_TRUE(p.enabled(Side::Local, OPT_BINARY));
    EXPECT_TRUE(p.enabled(Side::Remote, OPT_SGA));
    ASSERT_EQ(out.events.size(), 2u);
    EXPECT_EQ(out.events[0].kind, Event::Kind::OptionOn);
    // Asked again while on: no answer, or two peers would loop (RFC 854).
    out = feed(p, {IAC, DO, OPT_BINARY, IAC, WILL, OPT_SGA});
    EXPECT_TRUE(out.answer.empty());
    EXPECT_TRUE(out.events.empty());
    // ECHO (1) and TERMINAL-TYPE (24) are not ours to take: refused.
    out = feed(p, {IAC, WILL, 1, IAC, DO, 24});
    EXPECT_EQ(out.answer, (Bytes{IAC, DONT, 1, IAC, WONT, 24}));
    EXPECT_FALSE(p.enabled(Side::Remote, 1));
    // A refusal of something already off needs no answer.
    out = feed(p, {IAC, WONT, 1, IAC, DONT, 24});
    EXPECT_TRUE(out.answer.empty());
}

TEST(TelnetParser, OurRequestsAreNotAnsweredTwice) {
    auto p = client();
    EXPECT_EQ(p.request(Side::Local, OPT_COM_PORT), (Bytes{IAC, WILL, OPT_COM_PORT}));
    EXPECT_TRUE(p.request(Side::Local, OPT_COM_PORT).empty());  // already asked
    EXPECT_TRUE(p.pending(Side::Local, OPT_COM_PORT));
    auto out = feed(p, {IAC, DO, OPT_COM_PORT});
    EXPECT_TRUE(out.answer.empty());  // the server's DO is the answer, not a new request
    EXPECT_TRUE(p.enabled(Side::Local, OPT_COM_PORT));
    EXPECT_FALSE(p.pending(Side::Local, OPT_COM_PORT));

    EXPECT_EQ(p.request(Side::Remote, OPT_BINARY), (Bytes{IAC, DO, OPT_BINARY}));
    out = feed(p, {IAC, WONT, OPT_BINARY});
    EXPECT_TRUE(out.answer.empty());
    EXPECT_FALSE(p.enabled(Side::Remote, OPT_BINARY));
    EXPECT_FALSE(p.pending(Side::Remote, OPT_BINARY));
    ASSERT_EQ(out.events.size(), 1u);
    EXPECT_EQ(out.events[0].kind, Event::Kind::OptionOff);
}

TEST(TelnetParser, TurningAnOptionOffIsConfirmed) {
    auto p = client();
    feed(p, {IAC, DO, OPT_SGA});
    auto out = feed(p, {IAC, DONT, OPT_SGA});
    EXPECT_EQ(out.answer, (Bytes{IAC, WONT, OPT_SGA}));
    EXPECT_FALSE(p.enabled(Side::Local, OPT_SGA));
}

TEST(TelnetParser, SubnegotiationIsConsumedAndUnescaped) {
    auto p = client();
    auto out = feed(p, {'a', IAC, SB, OPT_COM_PORT, 101, 0, 0, IAC, IAC, IAC, IAC, IAC, SE, 'b'});
    EXPECT_EQ(out.data, str("ab"));
    ASSERT_EQ(out.events.size(), 1u);
    EXPECT_EQ(out.events[0].kind, Event::Kind::Subnegotiation);
    EXPECT_EQ(out.events[0].option, OPT_COM_PORT);
    EXPECT_EQ(out.events[0].payload, (Bytes{101, 0, 0, 0xFF, 0xFF}));
    EXPECT_FALSE(out.events[0].truncated);
}

TEST(TelnetParser, OverlongSubnegotiationIsCut) {
    auto p = client();
    Bytes in = {IAC, SB, 99};
    in.insert(in.end(), Parser::kMaxSubnegotiation + 10, 'x');
    in.insert(in.end(), {IAC, SE, 'd'});
    auto out = feed(p, in);
    ASSERT_EQ(out.events.size(), 1u);
    EXPECT_TRUE(out.events[0].truncated);
    EXPECT_EQ(out.events[0].payload.size(), Parser::kMaxSubnegotiation);
    EXPECT_EQ(out.data, str("d"));
}

TEST(TelnetParser, UnterminatedSubnegotiationDoesNotSwallowData) {
    auto p = client();
    // IAC NOP inside a subnegotiation: the peer forgot IAC SE.
    auto out = feed(p, {IAC, SB, OPT_COM_PORT, 101, 1, IAC, NOP, 'o', 'k'});
    EXPECT_EQ(out.data, str("ok"));
    EXPECT_EQ(p.malformed(), 1u);
    ASSERT_EQ(out.events.size(), 1u);
    EXPECT_EQ(out.events[0].kind, Event::Kind::Command);
    EXPECT_EQ(out.events[0].option, NOP);
}

TEST(TelnetParser, OtherCommandsAreReportedAndStripped) {
    auto p = client();
    auto out = feed(p, {'1', IAC, NOP, '2', IAC, 249 /* GA */, '3'});
    EXPECT_EQ(out.data, str("123"));
    ASSERT_EQ(out.events.size(), 2u);
    EXPECT_EQ(out.events[1].option, 249);
}

TEST(Telnet, EscapeDoublesIac) {
    EXPECT_EQ(escape(Bytes{1, 0xFF, 2, 0xFF, 0xFF}), (Bytes{1, 0xFF, 0xFF, 2, 0xFF, 0xFF, 0xFF, 0xFF}));
    EXPECT_TRUE(escape(Bytes{}).empty());
}

TEST(Rfc2217, SetBaudrateIsNetworkOrderAndEscaped) {
    EXPECT_EQ(rfc2217::set_baudrate(9600), (Bytes{IAC, SB, 44, 1, 0, 0, 0x25, 0x80, IAC, SE}));
    // 65535 = 00 00 FF FF: each FF doubled so it cannot end the subnegotiation.
    EXPECT_EQ(rfc2217::set_baudrate(65535), (Bytes{IAC, SB, 44, 1, 0, 0, IAC, IAC, IAC, IAC, IAC, SE}));
    EXPECT_EQ(rfc2217::set_byte(rfc2217::SET_PARITY, rfc2217::PARITY_NONE), (Bytes{IAC, SB, 44, 3, 1, IAC, SE}));
}

TEST(Rfc2217, ServerRepliesDecode) {
    auto r = rfc2217::parse_reply(Bytes{101, 0, 1, 0xC2, 0x00});
    ASSERT_TRUE(r);
    EXPECT_EQ(r->command, rfc2217::SET_BAUDRATE);
    EXPECT_EQ(r->baud(), 115200u);
    EXPECT_FALSE(rfc2217::parse_reply(Bytes{}));
    EXPECT_FALSE(rfc2217::parse_reply(Bytes{1, 0, 0, 0, 0}));  // a client command, not an answer
    auto size = rfc2217::parse_reply(Bytes{102, 8});
    ASSERT_TRUE(size);
    EXPECT_EQ(size->command, rfc2217::SET_DATASIZE);
    EXPECT_FALSE(size->baud());
    EXPECT_FALSE((rfc2217::Reply{rfc2217::SET_BAUDRATE, {1, 2}}.baud()));  // short value
}

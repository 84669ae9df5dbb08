// SLCAN codec: encoding, the adapter->host stream decoder (hostile rows L1-L12
// of HOSTILE_INPUTS 2.7), the host->adapter command parser and AdapterSession.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "motorbus/can/slcan_codec.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::can;
using namespace motorbus::can::slcan;

namespace {

struct Seen {
    EventKind kind;
    Frame frame;
    std::optional<std::uint16_t> ts;
    std::uint8_t status;
    bool extended;
    std::uint16_t error_bits;
    BusState state;
    std::uint16_t rxe, txe;
    std::string text;
};

std::vector<Seen> feed(StreamDecoder& d, std::string_view bytes) {
    std::vector<Seen> out;
    d.feed(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
           [&](const Event& e) {
               out.push_back(Seen{e.kind, e.frame, e.timestamp_ms, e.status, e.extended,
                                  e.error_bits, e.state, e.rx_errors, e.tx_errors,
                                  std::string(e.text)});
           });
    return out;
}

std::vector<Seen> feed_bytewise(StreamDecoder& d, std::string_view bytes) {
    std::vector<Seen> out;
    for (char c : bytes) {
        auto v = feed(d, std::string_view(&c, 1));
        out.insert(out.end(), v.begin(), v.end());
    }
    return out;
}

Frame frame(std::uint32_t id, std::vector<std::uint8_t> data, bool ext = false) {
    return Frame::make(id, data, ext);
}

// After any bad input, this valid line must still decode.
void expect_next_valid_frame(StreamDecoder& d) {
    auto v = feed(d, "t7FF2CAFE\r");
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].kind, EventKind::Frame);
    EXPECT_EQ(v[0].frame.id, 0x7FFu);
    EXPECT_EQ(v[0].frame.len, 2);
    EXPECT_EQ(v[0].frame.data[0], 0xCA);
    EXPECT_EQ(v[0].frame.data[1], 0xFE);
}

}  // namespace

// ---------------------------------------------------------------- encoding --

TEST(SlcanEncode, StandardExtendedRtrAndTimestamp) {
    EXPECT_EQ(encode_frame(frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF})), "t1234DEADBEEF\r");
    EXPECT_EQ(encode_frame(frame(0, {})), "t0000\r");
    EXPECT_EQ(encode_frame(frame(0x7FF, {1, 2, 3, 4, 5, 6, 7, 8})), "t7FF80102030405060708\r");
    EXPECT_EQ(encode_frame(frame(0x1FFFFFFF, {0xAB}, true)), "T1FFFFFFF1AB\r");
    EXPECT_EQ(encode_frame(frame(0x1, {}, true)), "T000000010\r");
    EXPECT_EQ(encode_frame(Frame::make(0x456, {}, false, true, 3)), "r4563\r");
    EXPECT_EQ(encode_frame(Frame::make(0x12345, {}, true, true, 8)), "R000123458\r");
    EXPECT_EQ(encode_frame(frame(0x10, {0x01}), 0xEA5F), "t010101EA5F\r");
    EXPECT_EQ(encode_frame(frame(0x10, {}), 0), "t01000000\r");
    // The longest line fits the MTU with its CR.
    auto longest = encode_frame(frame(0x11112222, {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88}, true), 0xEA5F);
    EXPECT_EQ(longest, "T1111222281122334455667788EA5F\r");
    EXPECT_LT(longest.size(), kMtu);
}

TEST(SlcanEncode, RefusesWhatSlcanCannotCarry) {
    Frame fd = frame(0x1, {});
    fd.flags |= kFlagFd;
    EXPECT_THROW(encode_frame(fd), InvalidArgument);
    Frame bad = frame(0x1, {});
    bad.id = 0x800;
    EXPECT_THROW(encode_frame(bad), InvalidArgument);
    EXPECT_THROW(encode_frame(frame(0x1, {}), 0xEA60), InvalidArgument);
}

TEST(SlcanEncode, RoundTripEveryDlcAndWidth) {
    for (bool ext : {false, true}) {
        for (std::uint32_t id : {0u, 1u, ext ? kMaxExtendedId : kMaxStandardId}) {
            for (int dlc = 0; dlc <= 8; ++dlc) {
                for (bool rtr : {false, true}) {
                    std::vector<std::uint8_t> data;
                    for (int i = 0; i < dlc; ++i) data.push_back(static_cast<std::uint8_t>(0xF0 + i));
                    Frame f = rtr ? Frame::make(id, {}, ext, true, dlc) : Frame::make(id, data, ext);
                    StreamDecoder d;
                    auto v = feed(d, encode_frame(f));
                    ASSERT_EQ(v.size(), 1u);
                    ASSERT_EQ(v[0].kind, EventKind::Frame);
                    EXPECT_TRUE(v[0].frame.same_content(f)) << f.to_string();
                    EXPECT_FALSE(v[0].ts.has_value());
                }
            }
        }
    }
}

TEST(SlcanEncode, BitrateCodes) {
    EXPECT_EQ(bitrate_code(500000), '6');
    EXPECT_EQ(bitrate_code(10000), '0');
    EXPECT_EQ(bitrate_code(1000000), '8');
    EXPECT_EQ(bitrate_code(750000), '7');
    EXPECT_EQ(bitrate_code(800000), '7');
    EXPECT_FALSE(bitrate_code(83300).has_value());
    EXPECT_EQ(bitrate_from_code('4'), 125000u);
    EXPECT_EQ(bitrate_from_code('9'), 0u);
}

// --------------------------------------------------------- stream decoding --

TEST(SlcanDecode, FramesWithAndWithoutTimestamp) {
    StreamDecoder d;
    auto v = feed(d, "t1232AABB\rT1FFFFFFF0\rr7FF8\rR000000013\rt0010EA5F\r");
    ASSERT_EQ(v.size(), 5u);
    EXPECT_EQ(v[0].frame.id, 0x123u);
    EXPECT_EQ(v[0].frame.len, 2);
    EXPECT_EQ(v[0].frame.data[0], 0xAA);
    EXPECT_EQ(v[0].frame.data[1], 0xBB);
    EXPECT_TRUE(v[1].frame.extended);
    EXPECT_EQ(v[1].frame.id, 0x1FFFFFFFu);
    EXPECT_TRUE(v[2].frame.rtr);
    EXPECT_EQ(v[2].frame.len, 8);
    EXPECT_TRUE(v[3].frame.rtr && v[3].frame.extended);
    EXPECT_EQ(v[3].frame.len, 3);
    ASSERT_TRUE(v[4].ts.has_value());
    EXPECT_EQ(*v[4].ts, 0xEA5F);
    EXPECT_EQ(d.counters().frames, 5u);
}

TEST(SlcanDecode, AnyChunkingGivesTheSameEvents) {
    const std::string stream = "t1232AABB\r\rz\rF04\r\aT00000001180\r";
    StreamDecoder a, b;
    auto whole = feed(a, stream);
    auto bytewise = feed_bytewise(b, stream);
    ASSERT_EQ(whole.size(), 6u);
    ASSERT_EQ(bytewise.size(), whole.size());
    for (std::size_t i = 0; i < whole.size(); ++i) {
        EXPECT_EQ(whole[i].kind, bytewise[i].kind);
        EXPECT_TRUE(whole[i].frame.same_content(bytewise[i].frame));
    }
    EXPECT_EQ(whole[1].kind, EventKind::Ok);
    EXPECT_EQ(whole[2].kind, EventKind::TxAck);
    EXPECT_EQ(whole[3].kind, EventKind::Status);
    EXPECT_EQ(whole[4].kind, EventKind::Nack);
    EXPECT_EQ(whole[5].frame.data[0], 0x80);
}

TEST(SlcanDecode, L1_LineLongerThanMtuEntersErrorStateUntilCr) {
    StreamDecoder d;
    std::string junk(200, 'A');  // no CR for far longer than the MTU
    auto v = feed(d, junk);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].kind, EventKind::Overflow);
    EXPECT_EQ(d.counters().rx_over_errors, 1u);  // counted once per line
    EXPECT_TRUE(d.in_overflow());
    EXPECT_LE(d.pending(), kMtu);
    // A valid-looking tail inside the bad line is discarded with it.
    v = feed(d, "t1230\r");
    EXPECT_TRUE(v.empty());
    EXPECT_FALSE(d.in_overflow());
    expect_next_valid_frame(d);
    // Exactly kMtu body bytes is still held; one more overflows.
    StreamDecoder e;
    EXPECT_TRUE(feed(e, std::string(kMtu, 'x')).empty());
    EXPECT_EQ(e.pending(), kMtu);
    EXPECT_EQ(feed(e, "x").at(0).kind, EventKind::Overflow);
    // BEL also ends the error state (and is still a NACK).
    v = feed(e, "\a");
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].kind, EventKind::Nack);
    expect_next_valid_frame(e);
}

TEST(SlcanDecode, L2_StreamEndsWithoutCrHoldsAtMostMtuAndDropsOnDiscard) {
    StreamDecoder d;
    EXPECT_TRUE(feed(d, "t1232AA").empty());
    EXPECT_EQ(d.pending(), 7u);
    EXPECT_TRUE(d.discard_partial());
    EXPECT_EQ(d.pending(), 0u);
    EXPECT_EQ(d.counters().dropped_partial, 1u);
    EXPECT_FALSE(d.discard_partial());
    // The dropped head must not prefix the next line.
    expect_next_valid_frame(d);
}

TEST(SlcanDecode, L3_NonHexInIdOrDataDropsTheLineAndContinues) {
    StreamDecoder d;
    using namespace std::string_view_literals;
    for (std::string_view bad : {"t12G0\r"sv, "t1232AAGG\r"sv, "T1234567Z0\r"sv, "t1 30\r"sv,
                                 "t1232+1AA\r"sv, "t-120\r"sv, "t1231\xff\xff\r"sv,
                                 "t1232AA\x00\x00\r"sv}) {
        auto v = feed(d, bad);
        ASSERT_EQ(v.size(), 1u) << bad;
        EXPECT_EQ(v[0].kind, EventKind::Malformed) << bad;
        expect_next_valid_frame(d);
    }
    EXPECT_EQ(d.counters().rx_errors, 8u);
    EXPECT_EQ(d.counters().frames, 8u);
}

TEST(SlcanDecode, L5_DlcOutsideZeroToEightIsRejected) {
    StreamDecoder d;
    for (const char* bad : {"t1239001122334455667788\r", "t123A\r", "T000000019001122334455667788\r",
                            "r1239\r", "t123F\r", "t123:\r"}) {
        auto v = feed(d, bad);
        ASSERT_EQ(v.size(), 1u) << bad;
        EXPECT_EQ(v[0].kind, EventKind::Malformed) << bad;
        expect_next_valid_frame(d);
    }
    auto ok = feed(d, "t12380011223344556677\r");
    ASSERT_EQ(ok.at(0).kind, EventKind::Frame);
    EXPECT_EQ(ok[0].frame.len, 8);
    EXPECT_EQ(ok[0].frame.data[7], 0x77);
}

TEST(SlcanDecode, L7_OnlyZeroOrFourTrailingHexCharsAndTimestampAtMostEA5F) {
    StreamDecoder d;
    // 0 and 4 trailing chars are accepted
    auto v = feed(d, "t1231111112\r");
    ASSERT_EQ(v.at(0).kind, EventKind::Frame);
    EXPECT_EQ(*v[0].ts, 0x1112);
    EXPECT_EQ(v[0].frame.data[0], 0x11);
    v = feed(d, "t1230ea5f\r");  // lowercase timestamp too
    ASSERT_EQ(v.at(0).kind, EventKind::Frame);
    EXPECT_EQ(*v[0].ts, 0xEA5F);
    v = feed(d, "r12320000\r");
    ASSERT_EQ(v.at(0).kind, EventKind::Frame);
    EXPECT_EQ(*v[0].ts, 0);
    // 1, 2, 3, 5, 6 trailing chars are rejected; so is a missing data byte
    for (const char* bad : {"t1231111\r", "t12311111\r", "t123111111\r", "t12311111111\r", "t123111111111\r", "t12311\r",
                            "t1232AA\r", "t1230EA60\r", "t1230FFFF\r", "t1230EAG0\r", "r12320\r"}) {
        v = feed(d, bad);
        ASSERT_EQ(v.size(), 1u) << bad;
        EXPECT_EQ(v[0].kind, EventKind::Malformed) << bad;
        expect_next_valid_frame(d);
    }
}

TEST(SlcanDecode, L8_IdsOutOfRangeAreRejected) {
    StreamDecoder d;
    for (const char* bad : {"t8000\r", "tFFF0\r", "T200000000\r", "TFFFFFFFF0\r", "r8000\r",
                            "R200000000\r"}) {
        auto v = feed(d, bad);
        ASSERT_EQ(v.size(), 1u) << bad;
        EXPECT_EQ(v[0].kind, EventKind::Malformed) << bad;
        expect_next_valid_frame(d);
    }
    auto v = feed(d, "T1FFFFFFF0\rt7FF0\r");
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].frame.id, 0x1FFFFFFFu);
    EXPECT_EQ(v[1].frame.id, 0x7FFu);
}

TEST(SlcanDecode, L9_LowercaseHexIsAccepted) {
    StreamDecoder d;
    auto v = feed(d, "t7ff2abcd\rT1fffffff1ef\rF0a\r");
    ASSERT_EQ(v.size(), 3u);
    EXPECT_EQ(v[0].frame.id, 0x7FFu);
    EXPECT_EQ(v[0].frame.data[0], 0xAB);
    EXPECT_EQ(v[0].frame.data[1], 0xCD);
    EXPECT_EQ(v[1].frame.id, 0x1FFFFFFFu);
    EXPECT_EQ(v[1].frame.data[0], 0xEF);
    EXPECT_EQ(v[2].status, 0x0A);
}

TEST(SlcanDecode, L10_LoneBelIsANackNotAFrame) {
    StreamDecoder d;
    auto v = feed(d, "\a");
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].kind, EventKind::Nack);
    EXPECT_EQ(d.counters().frames, 0u);
    // A BEL after a partial line: the partial is noise (malformed), then the NACK.
    v = feed(d, "t12\a");
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].kind, EventKind::Malformed);
    EXPECT_EQ(v[1].kind, EventKind::Nack);
    // A complete-looking frame terminated by BEL is not delivered.
    v = feed(d, "t1230\a");
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].kind, EventKind::Malformed);
    EXPECT_EQ(v[1].kind, EventKind::Nack);
    expect_next_valid_frame(d);
}

TEST(SlcanDecode, L11_KnownNonFrameLinesAreParsedTheRestIgnoredAndCounted) {
    StreamDecoder d;
    auto v = feed(d, "z\rZ\rV1013\rNA1B2\re2ac\rsp128096\rsb256256\rX123\rd1230\r?\r");
    ASSERT_EQ(v.size(), 10u);
    EXPECT_EQ(v[0].kind, EventKind::TxAck);
    EXPECT_FALSE(v[0].extended);
    EXPECT_EQ(v[1].kind, EventKind::TxAck);
    EXPECT_TRUE(v[1].extended);
    EXPECT_EQ(v[2].kind, EventKind::Version);
    EXPECT_EQ(v[2].text, "V1013");
    EXPECT_EQ(v[3].kind, EventKind::Serial);
    EXPECT_EQ(v[3].text, "NA1B2");
    EXPECT_EQ(v[4].kind, EventKind::ErrorReport);
    EXPECT_EQ(v[4].error_bits, kErrAck | kErrCrc);
    EXPECT_EQ(v[5].kind, EventKind::StateReport);
    EXPECT_EQ(v[5].state, BusState::ErrorPassive);
    EXPECT_EQ(v[5].rxe, 128);
    EXPECT_EQ(v[5].txe, 96);
    EXPECT_EQ(v[6].state, BusState::BusOff);
    EXPECT_EQ(v[6].rxe, 256);
    EXPECT_EQ(v[7].kind, EventKind::Unknown);
    EXPECT_EQ(v[8].kind, EventKind::Unknown);  // CAN FD lines: not supported, ignored
    EXPECT_EQ(v[9].kind, EventKind::Unknown);
    EXPECT_EQ(d.counters().ignored, 3u);
    // Broken extension lines are malformed, never half-applied.
    for (const char* bad : {"zz\r", "e9abcdefghi\r", "e2a\r", "e1x\r", "sx000000\r", "sa00000\r",
                            "sa00a000\r", "F\r", "F123\r", "FGG\r"}) {
        v = feed(d, bad);
        ASSERT_EQ(v.size(), 1u) << bad;
        EXPECT_EQ(v[0].kind, EventKind::Malformed) << bad;
        expect_next_valid_frame(d);
    }
}

TEST(SlcanDecode, L12_StatusFlagsMapToBusStatePerLawicelBitLayout) {
    // bit0 RX FIFO full, bit1 TX FIFO full, bit2 EI, bit3 DOI, bit5 EPI, bit6 ALI, bit7 BEI
    EXPECT_EQ(status_to_state(0x00), BusState::Active);
    EXPECT_EQ(status_to_state(0x04), BusState::ErrorWarning);
    EXPECT_EQ(status_to_state(0x20), BusState::ErrorPassive);
    EXPECT_EQ(status_to_state(0x24), BusState::ErrorPassive);
    EXPECT_EQ(status_to_state(0x08), BusState::Active);  // overrun alone is no error state
    EXPECT_EQ(status_to_state(0x80), BusState::Active);
    EXPECT_EQ(status_to_state(0x13), BusState::Active);
    StreamDecoder d;
    auto v = feed(d, "F24\rF08\r");
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].status, kStatusErrorWarning | kStatusErrorPassive);
    EXPECT_EQ(v[0].state, BusState::ErrorPassive);
    EXPECT_EQ(v[1].status, kStatusDataOverrun);
    EXPECT_EQ(state_to_status(BusState::ErrorWarning), kStatusErrorWarning);
    EXPECT_EQ(status_to_state(state_to_status(BusState::ErrorPassive)), BusState::ErrorPassive);
}

TEST(SlcanDecode, NextValidFrameArrivesAfterEveryKindOfBadInput) {
    // string_view literals: the first input starts with NUL, which a C string would end at once.
    using namespace std::string_view_literals;
    const std::string_view bad_inputs[] = {
        "\x00\x01\x02\xff\r"sv, "tttttttttttttttttttttttttttttttttttttttttttttttttttt"sv,
        "\r\r\r"sv, "\a\a"sv, "t"sv, "T\r"sv, "t123"sv, "\xfe\r"sv, "F\r"sv, "e\r"sv, "s\r"sv, "V\r"sv,
    };
    for (std::string_view bad : bad_inputs) {
        ASSERT_FALSE(bad.empty());
        StreamDecoder d;
        feed(d, bad);
        feed(d, "\r");  // whatever the bad input left, one CR ends it
        expect_next_valid_frame(d);
    }
}

// ----------------------------------------------------------- command side --

TEST(SlcanCommand, ParsesEveryAdapterCommand) {
    EXPECT_EQ(parse_command("O").kind, CommandKind::Open);
    EXPECT_EQ(parse_command("L").kind, CommandKind::ListenOnly);
    EXPECT_EQ(parse_command("C").kind, CommandKind::Close);
    EXPECT_EQ(parse_command("V").kind, CommandKind::Version);
    EXPECT_EQ(parse_command("N").kind, CommandKind::Serial);
    EXPECT_EQ(parse_command("F").kind, CommandKind::Status);
    EXPECT_EQ(parse_command("").kind, CommandKind::Empty);
    auto s = parse_command("S6");
    EXPECT_EQ(s.kind, CommandKind::SetBitrate);
    EXPECT_EQ(s.arg, 6u);
    EXPECT_EQ(parse_command("S9").kind, CommandKind::Invalid);
    auto b = parse_command("s031C");
    EXPECT_EQ(b.kind, CommandKind::SetBtr);
    EXPECT_EQ(b.arg, 0x031Cu);
    EXPECT_EQ(parse_command("s03").kind, CommandKind::Invalid);
    auto z = parse_command("Z1");
    EXPECT_EQ(z.kind, CommandKind::Timestamps);
    EXPECT_EQ(z.arg, 1u);
    EXPECT_EQ(parse_command("Z2").kind, CommandKind::Invalid);
    EXPECT_EQ(parse_command("M00000000").kind, CommandKind::AcceptCode);
    EXPECT_EQ(parse_command("mFFFFFFFF").arg, 0xFFFFFFFFu);
    auto t = parse_command("T1FFFFFFF2BEEF");
    ASSERT_EQ(t.kind, CommandKind::Transmit);
    EXPECT_EQ(t.frame.id, 0x1FFFFFFFu);
    EXPECT_EQ(t.frame.data[1], 0xEF);
    EXPECT_EQ(parse_command("r1238").frame.len, 8);
    // commands carry no timestamps, and every L row applies
    for (const char* bad : {"t1230EA5F", "t8000", "t1239", "t12G0", "OX", "CC", "Q1", "x"})
        EXPECT_EQ(parse_command(bad).kind, CommandKind::Invalid) << bad;
}

TEST(SlcanCommand, DecoderBoundsLinesAndIgnoresBel) {
    CommandDecoder d;
    std::vector<CommandKind> kinds;
    auto feed_cmd = [&](std::string_view s) {
        d.feed(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()),
               [&](const Command& c) { kinds.push_back(c.kind); });
    };
    feed_cmd(std::string(100, 't') + "\rO\r");
    ASSERT_EQ(kinds.size(), 2u);
    EXPECT_EQ(kinds[0], CommandKind::Invalid);
    EXPECT_EQ(kinds[1], CommandKind::Open);
    EXPECT_EQ(d.over_errors(), 1u);
    kinds.clear();
    feed_cmd("t12\at1230\r");
    ASSERT_EQ(kinds.size(), 1u);
    EXPECT_EQ(kinds[0], CommandKind::Transmit);
}

TEST(SlcanAdapter, AnswersLikeACanusb) {
    AdapterSession s;
    auto run = [&](std::string_view line, std::uint8_t flags = 0) {
        return s.handle(parse_command(line), flags);
    };
    EXPECT_EQ(run("C").bytes, "\a");        // closing a closed channel
    EXPECT_EQ(run("t1230").bytes, "\a");    // transmit while closed
    EXPECT_EQ(run("F").bytes, "\a");        // status while closed
    EXPECT_EQ(run("S4").bytes, "\r");
    EXPECT_EQ(s.bitrate(), 125000u);
    EXPECT_EQ(run("Z1").bytes, "\r");
    EXPECT_TRUE(s.timestamps());
    EXPECT_EQ(run("V").bytes, "V1013\r");
    EXPECT_EQ(run("N").bytes, "NMB01\r");
    EXPECT_EQ(run("O").bytes, "\r");
    EXPECT_TRUE(s.is_open());
    EXPECT_EQ(run("O").bytes, "\a");   // already open
    EXPECT_EQ(run("S6").bytes, "\a");  // no reconfiguration while open
    EXPECT_EQ(run("Z0").bytes, "\a");
    auto r = run("t1232BEEF");
    EXPECT_EQ(r.bytes, "z\r");
    ASSERT_TRUE(r.transmit.has_value());
    EXPECT_EQ(r.transmit->id, 0x123u);
    EXPECT_EQ(r.transmit->data[1], 0xEF);
    r = run("R1FFFFFFF8");
    EXPECT_EQ(r.bytes, "Z\r");
    EXPECT_TRUE(r.transmit->rtr);
    EXPECT_EQ(run("F", 0x24).bytes, "F24\r");
    EXPECT_EQ(run("t8000").bytes, "\a");
    EXPECT_EQ(run("?").bytes, "\a");
    EXPECT_EQ(run("").bytes, "\a");
    EXPECT_EQ(run("C").bytes, "\r");
    EXPECT_FALSE(s.is_open());
    EXPECT_EQ(run("s031C").bytes, "\r");
    EXPECT_EQ(*s.btr(), 0x031C);
    EXPECT_EQ(run("L").bytes, "\r");
    EXPECT_TRUE(s.listen_only());
    EXPECT_EQ(run("t1230").bytes, "\a");  // listen-only never transmits
    EXPECT_FALSE(run("t1230").transmit.has_value());
}

// ------------------------------------------------ line endings: LF and NUL --
// LF and NUL are separators, never frame bytes (docs/slcan.md "Line endings").

TEST(SlcanDecode, CrLfLinesDecodeWithoutErrorsInAnyChunking) {
    const std::string_view stream = "t1232AABB\r\nz\r\n\r\nT1FFFFFFF1EE\r\nF04\r\n";
    for (bool bytewise : {false, true}) {
        StreamDecoder d;
        auto v = bytewise ? feed_bytewise(d, stream) : feed(d, stream);
        ASSERT_EQ(v.size(), 5u) << bytewise;
        EXPECT_EQ(v[0].kind, EventKind::Frame);
        EXPECT_EQ(v[0].frame.id, 0x123u);
        EXPECT_EQ(v[0].frame.len, 2);
        EXPECT_EQ(v[0].frame.data[0], 0xAA);
        EXPECT_EQ(v[0].frame.data[1], 0xBB);
        EXPECT_EQ(v[1].kind, EventKind::TxAck);
        EXPECT_EQ(v[2].kind, EventKind::Ok);  // the lone CR, its LF adds nothing
        EXPECT_EQ(v[3].kind, EventKind::Frame);
        EXPECT_EQ(v[3].frame.id, 0x1FFFFFFFu);
        EXPECT_EQ(v[3].frame.data[0], 0xEE);
        EXPECT_EQ(v[4].kind, EventKind::Status);
        EXPECT_EQ(v[4].status, 0x04);
        EXPECT_EQ(d.counters().frames, 2u);
        EXPECT_EQ(d.counters().rx_errors, 0u);
        EXPECT_EQ(d.counters().ignored, 0u);
        EXPECT_EQ(d.pending(), 0u);
    }
}

TEST(SlcanDecode, LfAloneEndsALineAndStrayLfsAreSkipped) {
    StreamDecoder d;
    auto v = feed(d, "\n\nt1231AB\nz\n\n\nt4560\n");
    ASSERT_EQ(v.size(), 3u);
    EXPECT_EQ(v[0].kind, EventKind::Frame);
    EXPECT_EQ(v[0].frame.id, 0x123u);
    EXPECT_EQ(v[0].frame.data[0], 0xAB);
    EXPECT_EQ(v[1].kind, EventKind::TxAck);
    EXPECT_EQ(v[2].kind, EventKind::Frame);
    EXPECT_EQ(v[2].frame.id, 0x456u);
    EXPECT_EQ(v[2].frame.len, 0);
    EXPECT_EQ(d.counters().rx_errors, 0u);
}

TEST(SlcanDecode, NulPadsBetweenLinesAreSkippedAndANulInsideALineBreaksIt) {
    using namespace std::string_view_literals;
    StreamDecoder d;
    auto v = feed(d, "\0\0\0t1231AB\r\0\0\0\0z\r\0"sv);
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].kind, EventKind::Frame);
    EXPECT_EQ(v[0].frame.data[0], 0xAB);
    EXPECT_EQ(v[1].kind, EventKind::TxAck);
    EXPECT_EQ(d.counters().rx_errors, 0u);
    EXPECT_EQ(d.pending(), 0u);
    // A NUL inside a line is corruption: the whole line is one malformed
    // event (never "t1231A" + "B", never a frame with a hole in it).
    v = feed(d, "t12\x00" "31AB\r"sv);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].kind, EventKind::Malformed);
    EXPECT_EQ(d.counters().rx_errors, 1u);
    expect_next_valid_frame(d);
    // ... also when the line then ends with LF, and a partial broken line is
    // dropped like any other partial line.
    v = feed(d, "t1231A\x00\n"sv);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].kind, EventKind::Malformed);
    feed(d, "t12\x00"sv);
    EXPECT_TRUE(d.discard_partial());
    expect_next_valid_frame(d);
}

namespace {
std::vector<Command> feed_commands(CommandDecoder& d, std::string_view s, bool bytewise = false) {
    std::vector<Command> out;
    auto on = [&](const Command& c) { out.push_back(c); };
    if (bytewise) {
        for (char c : s) d.feed(std::span(reinterpret_cast<const std::uint8_t*>(&c), 1), on);
    } else {
        d.feed(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()), on);
    }
    return out;
}
}  // namespace

TEST(SlcanCommand, CrLfHostLosesNoCommandAndGetsNoBel) {
    // Before LF was a separator, every command after the first arrived as
    // "\nt..." and was answered with BEL: every second frame of a CR LF host.
    for (bool bytewise : {false, true}) {
        CommandDecoder d;
        AdapterSession s;
        std::string replies;
        std::vector<Frame> sent;
        for (const Command& c : feed_commands(d, "C\r\nS6\r\nO\r\nt1232AABB\r\nt4560\r\nT1FFFFFFF1EE\r\nr7FF8\r\n", bytewise)) {
            auto r = s.handle(c);
            replies += r.bytes;
            if (r.transmit) sent.push_back(*r.transmit);
        }
        EXPECT_EQ(replies, "\a\r\rz\rz\rZ\rz\r") << bytewise;  // C while closed is the only BEL
        ASSERT_EQ(sent.size(), 4u);
        EXPECT_EQ(sent[0].id, 0x123u);
        EXPECT_EQ(sent[0].data[1], 0xBB);
        EXPECT_EQ(sent[1].id, 0x456u);
        EXPECT_EQ(sent[2].id, 0x1FFFFFFFu);
        EXPECT_TRUE(sent[3].rtr);
        EXPECT_EQ(sent[3].len, 8);
    }
}

TEST(SlcanCommand, LfOnlyHostAndNulPadsAreAccepted) {
    using namespace std::string_view_literals;
    CommandDecoder d;
    auto v = feed_commands(d, "O\nt1231AB\n\n\0\0t4560\r\0\n\0"sv);
    ASSERT_EQ(v.size(), 3u);
    EXPECT_EQ(v[0].kind, CommandKind::Open);
    EXPECT_EQ(v[1].kind, CommandKind::Transmit);
    EXPECT_EQ(v[1].frame.data[0], 0xAB);
    EXPECT_EQ(v[2].kind, CommandKind::Transmit);
    EXPECT_EQ(v[2].frame.id, 0x456u);
    // A NUL inside a command makes that one command invalid (answered BEL),
    // never a shorter or a joined command; the next one is intact.
    v = feed_commands(d, "t123\x00" "1AB\rt7FF0\r"sv);
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].kind, CommandKind::Invalid);
    EXPECT_EQ(v[1].kind, CommandKind::Transmit);
    EXPECT_EQ(v[1].frame.id, 0x7FFu);
    // An over-long line ended by LF is one overflow, as with CR.
    v = feed_commands(d, std::string(100, 't') + "\nO\r");
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].kind, CommandKind::Invalid);
    EXPECT_EQ(v[1].kind, CommandKind::Open);
    EXPECT_EQ(d.over_errors(), 1u);
}

// SDO client state machine: PMC007 request bytes and every client-side row of
// HOSTILE_INPUTS 2.2 (C*) and 2.3 (B*), driven without a bus.
#include <gtest/gtest.h>

#include "motorbus/canopen/sdo_client.hpp"
#include "test_sdo_util.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using motorbus::test::H;
using motorbus::test::hex;
using motorbus::test::hexes;
using Strs = std::vector<std::string>;

namespace {

constexpr Nanos kSec = 1'000'000'000;

struct ClientFixture : ::testing::Test {
    SdoClientMachine cli;
    Nanos now = 5000;

    Strs up(std::uint16_t i, std::uint8_t s, TransferMode m = TransferMode::Auto) {
        SdoClientMachine::Outbox out;
        cli.start_upload(i, s, m, now, out);
        return hexes(out);
    }
    Strs down(std::uint16_t i, std::uint8_t s, const Bytes& d, TransferMode m = TransferMode::Auto) {
        SdoClientMachine::Outbox out;
        cli.start_download(i, s, d, m, now, out);
        return hexes(out);
    }
    Strs rx(const std::string& h) {
        SdoClientMachine::Outbox out;
        auto b = H(h);
        cli.on_frame(b, now, out);
        return hexes(out);
    }
    Strs tick(Nanos at) {
        SdoClientMachine::Outbox out;
        now = at;
        cli.on_timer(at, out);
        return hexes(out);
    }
    template <class E>
    E error() {
        EXPECT_EQ(cli.status(), SdoClientMachine::Status::Failed);
        try {
            std::rethrow_exception(cli.error());
        } catch (const E& e) {
            return e;
        } catch (const std::exception& e) {
            ADD_FAILURE() << "unexpected error " << e.what();
        }
        throw std::runtime_error("no error");
    }
    std::string abort_of(std::uint16_t i, std::uint8_t s, std::uint32_t code) {
        return hex(sdo::abort_transfer({i, s}, code));
    }
};

}  // namespace

TEST_F(ClientFixture, Pmc007RequestBytes) {
    EXPECT_EQ(up(0x6001, 0), Strs{"40 01 60 00 00 00 00 00"});
    EXPECT_EQ(rx("4F 01 60 00 08 00 00 00"), Strs{});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Done);
    EXPECT_EQ(hex(cli.result()), "08");
    EXPECT_EQ(down(0x2003, 0, {7}), Strs{"2F 03 20 00 07 00 00 00"});
    EXPECT_EQ(rx("60 03 20 00 00 00 00 00"), Strs{});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Done);
    EXPECT_EQ(down(0x6004, 0, H("80 0C 00 00")), Strs{"23 04 60 00 80 0C 00 00"});
    EXPECT_EQ(rx("80 04 60 00 22 00 00 08"), Strs{});
    auto e = error<SdoAbortError>();
    EXPECT_EQ(e.code, 0x08000022u);
    EXPECT_EQ(e.index, 0x6004);
    EXPECT_EQ(e.text(), "Data cannot be transferred or stored to the application because of the "
                        "present device state");
    // Write command bytes by size (sdo_write_request_command_bytes).
    EXPECT_EQ(down(0x1800, 2, {0xFF})[0].substr(0, 2), "2F");
    EXPECT_EQ(down(0x1800, 3, {0x32, 0})[0].substr(0, 2), "2B");
    EXPECT_EQ(down(0x1800, 3, {1, 2, 3})[0].substr(0, 2), "27");
    EXPECT_EQ(down(0x1800, 1, H("87 01 00 00")), Strs{"23 00 18 01 87 01 00 00"});
}

TEST_F(ClientFixture, SegmentedUpload) {
    up(0x1008, 0);
    EXPECT_EQ(rx("41 08 10 00 0A 00 00 00"), Strs{"60 00 00 00 00 00 00 00"});
    EXPECT_EQ(rx("00 41 42 43 44 45 46 47"), Strs{"70 00 00 00 00 00 00 00"});
    EXPECT_EQ(rx("19 48 49 4A 00 00 00 00"), Strs{});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Done);
    EXPECT_EQ(std::string(cli.result().begin(), cli.result().end()), "ABCDEFGHIJ");
}

TEST_F(ClientFixture, SegmentedDownload) {
    EXPECT_EQ(down(0x2100, 0, H("01 02 03 04 05 06 07 08 09")), Strs{"21 00 21 00 09 00 00 00"});
    EXPECT_EQ(rx("60 00 21 00 00 00 00 00"), Strs{"00 01 02 03 04 05 06 07"});
    EXPECT_EQ(rx("20 00 00 00 00 00 00 00"), Strs{"1B 08 09 00 00 00 00 00"});
    EXPECT_EQ(rx("30 00 00 00 00 00 00 00"), Strs{});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Done);
    // Forced segmented for a small value.
    EXPECT_EQ(down(0x2100, 0, {5}, TransferMode::Segmented), Strs{"21 00 21 00 01 00 00 00"});
    EXPECT_EQ(rx("60 00 21 00 00 00 00 00"), Strs{"0D 05 00 00 00 00 00 00"});
}

TEST_F(ClientFixture, C1_TimeoutSendsAbortWithMultiplexer) {
    up(0x6001, 0);
    EXPECT_EQ(cli.next_deadline(), now + kSec);
    EXPECT_EQ(tick(now + kSec - 1), Strs{});
    EXPECT_EQ(tick(now + 1), Strs{"80 01 60 00 00 00 04 05"});
    auto e = error<SdoTimeout>();
    EXPECT_EQ(e.index, 0x6001);
    static_assert(std::is_base_of_v<motorbus::TimeoutError, SdoTimeout>);
}

// C2, revised (issue 22): two processes asking one node share its COB-IDs, so
// an initiate response or an abort naming another multiplexer is the other
// client's.  It is ignored (counted, no abort sent, no timeout restart) and the
// transfer waits on for its own; it used to fail with "response names 0x606C:00".
TEST_F(ClientFixture, C2_ResponseForAnotherMultiplexerIsAnotherClients) {
    up(0x6064, 0);
    now += kSec / 2;
    EXPECT_EQ(rx("43 6C 60 00 10 27 00 00"), Strs{});  // the other client's 606Ch answer
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Running);
    EXPECT_EQ(cli.counters().foreign_responses, 1u);
    EXPECT_EQ(cli.counters().aborts_sent, 0u);
    EXPECT_EQ(cli.next_deadline(), 5000 + kSec);  // the foreign frame did not restart our timeout
    EXPECT_EQ(rx("80 6C 60 00 00 00 02 06"), Strs{});  // the server aborting the other's request
    EXPECT_EQ(rx("60 40 60 00 00 00 00 00"), Strs{});  // the other's download confirmation
    EXPECT_EQ(rx("C6 6C 60 00 04 00 00 00"), Strs{});  // the other's block initiate response
    EXPECT_EQ(cli.counters().foreign_responses, 4u);
    EXPECT_EQ(rx("43 64 60 00 78 56 34 12"), Strs{});  // ours
    ASSERT_EQ(cli.status(), SdoClientMachine::Status::Done);
    EXPECT_EQ(hex(cli.result()), "78 56 34 12");
    down(0x2003, 0, {1});
    EXPECT_EQ(rx("60 03 20 01 00 00 00 00"), Strs{});  // sub 1: not ours
    EXPECT_EQ(rx("60 03 20 00 00 00 00 00"), Strs{});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Done);
    EXPECT_EQ(cli.counters().foreign_responses, 5u);
}

// Everything else stays strict: an abort for OUR multiplexer raises, a frame
// too short to name one is a protocol error, so is a wrong toggle bit.
TEST_F(ClientFixture, C2_StrictForOurOwnMultiplexer) {
    up(0x6064, 0);
    rx("80 64 60 00 00 00 02 06");
    EXPECT_EQ(error<SdoAbortError>().code, 0x06020000u);
    up(0x6064, 0);
    EXPECT_EQ(rx("43 64"), Strs{abort_of(0x6064, 0, 0x05040001)});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Failed);
    up(0x1008, 0);
    EXPECT_EQ(rx("41 08 10 00 0A 00 00 00"), Strs{"60 00 00 00 00 00 00 00"});
    // Between our segments: the other client's expedited answer is still not ours...
    EXPECT_EQ(rx("43 6C 60 00 10 27 00 00"), Strs{});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Running);
    // ...but an initiate response naming our object is a protocol error there.
    EXPECT_EQ(rx("41 08 10 00 0A 00 00 00"), Strs{abort_of(0x1008, 0, 0x05040001)});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Failed);
    up(0x1008, 0);
    rx("41 08 10 00 0A 00 00 00");
    EXPECT_EQ(rx("10 41 42 43 44 45 46 47"), Strs{abort_of(0x1008, 0, 0x05030000)});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Failed);
}

TEST_F(ClientFixture, C3_ServerAbortMidTransfer) {
    up(0x1008, 0);
    rx("41 08 10 00 0A 00 00 00");
    EXPECT_EQ(rx("80 08 10 00 00 00 06 06"), Strs{});  // no reply
    EXPECT_EQ(error<SdoAbortError>().code, 0x06060000u);
    EXPECT_TRUE(cli.result().empty());
    up(0x2201, 0, TransferMode::Block);
    rx("C6 01 22 00 20 00 00 00");
    rx("01 00 00 00 00 00 00 00");
    EXPECT_EQ(rx("80 01 22 00 20 00 00 08"), Strs{});
    EXPECT_EQ(error<SdoAbortError>().code, 0x08000020u);
}

TEST_F(ClientFixture, C4_ShortAbortIsGeneralError) {
    up(0x6001, 0);
    EXPECT_EQ(rx("80 01 60 00 11"), Strs{});
    EXPECT_EQ(error<SdoAbortError>().code, 0x08000000u);
    up(0x6001, 0);
    rx("80");
    EXPECT_EQ(error<SdoAbortError>().code, 0x08000000u);
}

TEST_F(ClientFixture, C5_ZeroAbortCodeIsGeneralError) {
    up(0x6001, 0);
    rx("80 01 60 00 00 00 00 00");
    EXPECT_EQ(error<SdoAbortError>().code, 0x08000000u);
}

TEST_F(ClientFixture, C6_UnknownScs) {
    up(0x6001, 0);
    EXPECT_EQ(rx("E0 01 60 00 00 00 00 00"), Strs{abort_of(0x6001, 0, 0x05040001)});
    EXPECT_EQ(error<SdoProtocolError>().code, 0x05040001u);
}

TEST_F(ClientFixture, C7_WrongToggleInUploadSegment) {
    up(0x1008, 0);
    rx("41 08 10 00 0E 00 00 00");
    EXPECT_EQ(rx("10 41 42 43 44 45 46 47"), Strs{abort_of(0x1008, 0, 0x05030000)});
    EXPECT_EQ(error<SdoProtocolError>().code, 0x05030000u);
}

TEST_F(ClientFixture, C8_UnsolicitedWhileIdleIgnored) {
    EXPECT_EQ(rx("4F 01 60 00 08 00 00 00"), Strs{});
    EXPECT_EQ(rx("80 01 60 00 00 00 04 05"), Strs{});
    EXPECT_EQ(cli.counters().ignored_frames, 2u);
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Idle);
    EXPECT_EQ(up(0x6001, 0), Strs{"40 01 60 00 00 00 00 00"});  // nothing was queued for later
    rx("4F 01 60 00 09 00 00 00");
    EXPECT_EQ(hex(cli.result()), "09");
}

TEST_F(ClientFixture, C10_HugeIndicatedSizeRefusedBeforeAllocating) {
    up(0x2201, 0);
    EXPECT_EQ(rx("41 01 22 00 FF FF FF FF"), Strs{abort_of(0x2201, 0, 0x05040005)});
    EXPECT_EQ(error<SdoProtocolError>().code, 0x05040005u);
    EXPECT_EQ(cli.result().capacity(), 0u);
    up(0x2201, 0, TransferMode::Block);
    EXPECT_EQ(rx("C6 01 22 00 FF FF FF FF"), Strs{abort_of(0x2201, 0, 0x05040005)});
}

TEST_F(ClientFixture, C11_MoreDataThanIndicated) {
    up(0x2201, 0);
    rx("41 01 22 00 03 00 00 00");
    EXPECT_EQ(rx("01 01 02 03 04 05 06 07"), Strs{abort_of(0x2201, 0, 0x06070012)});
}

TEST_F(ClientFixture, C12_LessDataThanIndicated) {
    up(0x2201, 0);
    rx("41 01 22 00 0A 00 00 00");
    EXPECT_EQ(rx("0B 01 02 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x06070013)});
}

TEST_F(ClientFixture, C13_EndlessSegmentsCapped) {
    SdoClientConfig c;
    c.max_transfer = 100;
    cli.set_config(c);
    up(0x2201, 0);
    EXPECT_EQ(rx("40 01 22 00 00 00 00 00"), Strs{"60 00 00 00 00 00 00 00"});  // no size
    bool t = false;
    Strs last;
    for (int i = 0; i < 20 && cli.busy(); ++i) {
        last = rx(t ? "10 AA AA AA AA AA AA AA" : "00 AA AA AA AA AA AA AA");
        t = !t;
    }
    EXPECT_EQ(last, Strs{abort_of(0x2201, 0, 0x05040005)});
    EXPECT_EQ(error<SdoProtocolError>().code, 0x05040005u);
}

TEST_F(ClientFixture, C14_ExpeditedSizeDecodedAsIndicated) {
    up(0x6001, 0);
    rx("4B 01 60 00 34 12 00 00");  // 2 bytes although the object may be U8
    EXPECT_EQ(hex(cli.result()), "34 12");
    up(0x6001, 0);
    rx("42 01 60 00 01 02 03 04");  // e=1, s=0: unspecified, take the 4 bytes
    EXPECT_EQ(hex(cli.result()), "01 02 03 04");
}

TEST_F(ClientFixture, C15_ShortButSufficientAndInsufficientFrames) {
    up(0x6001, 0);
    EXPECT_EQ(rx("4F 01 60 00 08"), Strs{});  // DLC 5 carries the one byte
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Done);
    EXPECT_EQ(hex(cli.result()), "08");
    up(0x6001, 0);
    EXPECT_EQ(rx("4F 01 60"), Strs{abort_of(0x6001, 0, 0x05040001)});
    EXPECT_EQ(error<SdoProtocolError>().code, 0x05040001u);
    up(0x6001, 0);
    EXPECT_EQ(rx("43 01 60 00 08"), Strs{abort_of(0x6001, 0, 0x05040001)});  // 4 bytes claimed
    up(0x6001, 0);
    EXPECT_EQ(rx(""), Strs{abort_of(0x6001, 0, 0x05040001)});
}

// ---- block transfers, client side -----------------------------------------------

TEST_F(ClientFixture, BlockUploadWithCrc) {
    Bytes v(20);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint8_t>(i + 1);
    EXPECT_EQ(up(0x2201, 0, TransferMode::Block), Strs{"A4 01 22 00 7F 00 00 00"});
    EXPECT_EQ(rx("C6 01 22 00 14 00 00 00"), Strs{"A3 00 00 00 00 00 00 00"});
    EXPECT_EQ(rx(hex(sdo::block_segment(1, std::span(v).subspan(0, 7), false))), Strs{});
    EXPECT_EQ(rx(hex(sdo::block_segment(2, std::span(v).subspan(7, 7), false))), Strs{});
    EXPECT_EQ(rx(hex(sdo::block_segment(3, std::span(v).subspan(14, 6), true))), Strs{"A2 03 7F 00 00 00 00 00"});
    EXPECT_EQ(rx(hex(sdo::block_upload_end(1, sdo::crc16(v)))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(cli.result(), v);
}

TEST_F(ClientFixture, BlockDownloadWithCrc) {
    Bytes v(20, 0x42);
    EXPECT_EQ(down(0x2201, 0, v, TransferMode::Block), Strs{"C6 01 22 00 14 00 00 00"});
    EXPECT_EQ(rx("A4 01 22 00 02 00 00 00"),
              (Strs{"01 42 42 42 42 42 42 42", "02 42 42 42 42 42 42 42"}));
    EXPECT_EQ(rx("A2 02 02 00 00 00 00 00"), Strs{"81 42 42 42 42 42 42 00"});
    EXPECT_EQ(rx("A2 01 02 00 00 00 00 00"), Strs{hex(sdo::block_download_end(1, sdo::crc16(v)))});
    EXPECT_EQ(rx("A1 00 00 00 00 00 00 00"), Strs{});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Done);
}

TEST_F(ClientFixture, BlockDownloadRetransmitsFromAckseq) {
    Bytes v(21);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint8_t>(i);
    down(0x2201, 0, v, TransferMode::Block);
    EXPECT_EQ(rx("A4 01 22 00 03 00 00 00").size(), 3u);
    EXPECT_EQ(rx("A2 01 03 00 00 00 00 00"),
              (Strs{"01 07 08 09 0A 0B 0C 0D", "82 0E 0F 10 11 12 13 14"}));
    EXPECT_EQ(cli.counters().retransmit_requests, 1u);
    EXPECT_EQ(rx("A2 02 03 00 00 00 00 00"), Strs{hex(sdo::block_download_end(0, sdo::crc16(v)))});
}

TEST_F(ClientFixture, B8_ServerBlksizeInvalid) {
    down(0x2201, 0, Bytes(20), TransferMode::Block);
    EXPECT_EQ(rx("A4 01 22 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040002)});
    down(0x2201, 0, Bytes(20), TransferMode::Block);
    EXPECT_EQ(rx("A4 01 22 00 80 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040002)});
    down(0x2201, 0, Bytes(20), TransferMode::Block);
    rx("A4 01 22 00 02 00 00 00");
    EXPECT_EQ(rx("A2 02 00 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040002)});  // in a sub-block ack
}

TEST_F(ClientFixture, B3_ServerAckseqBeyondSubblock) {
    down(0x2201, 0, Bytes(20), TransferMode::Block);
    rx("A4 01 22 00 02 00 00 00");
    EXPECT_EQ(rx("A2 80 02 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040003)});
}

TEST_F(ClientFixture, B9_CrcMismatchOnUpload) {
    up(0x2201, 0, TransferMode::Block);
    rx("C6 01 22 00 03 00 00 00");
    rx("81 01 02 03 00 00 00 00");
    EXPECT_EQ(rx("D1 00 00 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040004)});
    EXPECT_EQ(error<SdoProtocolError>().code, 0x05040004u);
}

TEST_F(ClientFixture, B10_B11_EndFrameInconsistent) {
    up(0x2201, 0, TransferMode::Block);
    rx("C6 01 22 00 03 00 00 00");
    rx("81 01 02 03 00 00 00 00");
    EXPECT_EQ(rx("C1 00 00 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x06070012)});  // 7 != 3
    up(0x2201, 0, TransferMode::Block);
    rx("C6 01 22 00 0A 00 00 00");
    rx("81 01 02 03 00 00 00 00");
    EXPECT_EQ(rx("D1 00 00 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x06070013)});  // 3 != 10
}

TEST_F(ClientFixture, B12_ServerStallsMidSubblock) {
    up(0x2201, 0, TransferMode::Block);
    rx("C6 01 22 00 40 00 00 00");
    rx("01 00 00 00 00 00 00 00");
    EXPECT_EQ(tick(now + kSec * 7 / 10), Strs{"A2 01 7F 00 00 00 00 00"});
    EXPECT_EQ(tick(now + kSec * 3 / 10), Strs{abort_of(0x2201, 0, 0x05040000)});
    EXPECT_NO_THROW(error<SdoTimeout>());
}

TEST_F(ClientFixture, B13_LostSegmentRequestedAgain) {
    SdoClientConfig c;
    c.block_size = 4;
    cli.set_config(c);
    Bytes v(28);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint8_t>(i);
    auto seg = [&](std::uint8_t seq, std::size_t k, bool last = false) {
        return hex(sdo::block_segment(seq, std::span(v).subspan(k * 7, 7), last));
    };
    EXPECT_EQ(up(0x2201, 0, TransferMode::Block), Strs{"A4 01 22 00 04 00 00 00"});
    rx("C6 01 22 00 1C 00 00 00");
    rx(seg(1, 0));
    // 2 lost
    EXPECT_EQ(rx(seg(3, 2)), Strs{});
    EXPECT_EQ(rx(seg(4, 3, true)), Strs{"A2 01 04 00 00 00 00 00"});
    EXPECT_EQ(cli.counters().retransmit_requests, 1u);
    rx(seg(1, 1));
    EXPECT_EQ(rx(seg(1, 1)), Strs{});  // B6 duplicate ignored
    rx(seg(2, 2));
    EXPECT_EQ(rx(seg(3, 3, true)), Strs{"A2 03 04 00 00 00 00 00"});
    EXPECT_EQ(rx(hex(sdo::block_upload_end(0, sdo::crc16(v)))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(cli.result(), v);
}

TEST_F(ClientFixture, B16_FallBackToSegmented) {
    SdoClientConfig opt_in;
    opt_in.fallback_to_segmented = true;  // not the default (Hardening defect 4)
    cli.set_config(opt_in);
    EXPECT_EQ(up(0x1008, 0, TransferMode::Block), Strs{"A4 08 10 00 7F 00 00 00"});
    EXPECT_EQ(rx("80 08 10 00 01 00 04 05"), Strs{"40 08 10 00 00 00 00 00"});
    EXPECT_EQ(rx("43 08 10 00 41 42 43 44"), Strs{});
    EXPECT_EQ(hex(cli.result()), "41 42 43 44");
    EXPECT_EQ(cli.counters().fallbacks, 1u);
    down(0x2100, 0, H("01 02 03 04 05 06 07 08"), TransferMode::Block);
    EXPECT_EQ(rx("80 00 21 00 01 00 04 05"), Strs{"21 00 21 00 08 00 00 00"});
    // Without fall-back the abort is reported.
    SdoClientConfig c;
    c.fallback_to_segmented = false;
    cli.set_config(c);
    up(0x1008, 0, TransferMode::Block);
    EXPECT_EQ(rx("80 08 10 00 01 00 04 05"), Strs{});
    EXPECT_EQ(error<SdoAbortError>().code, 0x05040001u);
}

// Issue 28 item 5: the client sends pst 0 ("no switch"), so a non-block answer
// is refused -- the plain protocol has no CRC, and under bit errors a block
// initiate response (C6 .. size) read as expedited (46 ..) delivered its size as
// the value.  With a threshold the switch is taken.
TEST_F(ClientFixture, BlockUploadProtocolSwitchRefusedUnlessAllowed) {
    EXPECT_EQ(SdoClientConfig{}.protocol_switch, 0u);
    up(0x6001, 0, TransferMode::Block);
    EXPECT_EQ(rx("4F 01 60 00 08 00 00 00"), Strs{abort_of(0x6001, 0, 0x05040001)});
    EXPECT_NE(std::string(error<SdoProtocolError>().what()).find("did not allow"), std::string::npos);
    up(0x2201, 0, TransferMode::Block);
    EXPECT_EQ(rx("46 01 22 00 14 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040001)});  // C6 with bit 7 flipped
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Failed);
    auto c = cli.config();
    c.protocol_switch = 4;
    cli.set_config(c);
    EXPECT_EQ(up(0x6001, 0, TransferMode::Block), Strs{"A4 01 60 00 7F 04 00 00"});
    EXPECT_EQ(rx("4F 01 60 00 08 00 00 00"), Strs{});
    EXPECT_EQ(hex(cli.result()), "08");
    // block_fallback: the caller accepts CRC-less answers from a server without
    // block upload (the `canopen` package answers plainly); counted as a fallback.
    c.protocol_switch = 0;
    c.fallback_to_segmented = true;
    cli.set_config(c);
    up(0x6001, 0, TransferMode::Block);
    EXPECT_EQ(rx("4F 01 60 00 09 00 00 00"), Strs{});
    EXPECT_EQ(hex(cli.result()), "09");
    EXPECT_EQ(cli.counters().fallbacks, 1u);
}

// A block transfer delivers CRC-checked data or fails: a server answering
// without CRC (or a request whose cc bit was lost) is refused with 0x05040004,
// unless the caller turned CRC off.
TEST_F(ClientFixture, BlockTransferWithoutCrcRefused) {
    up(0x2201, 0, TransferMode::Block);
    EXPECT_EQ(rx("C2 01 22 00 03 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040004)});
    EXPECT_EQ(error<SdoProtocolError>().code, 0x05040004u);
    down(0x2201, 0, Bytes(20, 0x42), TransferMode::Block);
    EXPECT_EQ(rx("A0 01 22 00 02 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040004)});
    EXPECT_EQ(cli.status(), SdoClientMachine::Status::Failed);
    auto c = cli.config();
    c.block_crc = false;
    cli.set_config(c);
    EXPECT_EQ(up(0x2201, 0, TransferMode::Block), Strs{"A0 01 22 00 7F 00 00 00"});
    EXPECT_EQ(rx("C2 01 22 00 03 00 00 00"), Strs{"A3 00 00 00 00 00 00 00"});
    rx("81 01 02 03 00 00 00 00");
    EXPECT_EQ(rx("D1 00 00 00 00 00 00 00"), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(hex(cli.result()), "01 02 03");
}

// Hardening (defect 4): a caller who asked for block gets block or an error.
// By default a server that refuses block mode (0x05040001) is reported as
// SdoAbortError 0x05040001; nothing is retried segmented behind its back.
TEST_F(ClientFixture, BlockRefusedIsAnErrorByDefault) {
    EXPECT_FALSE(SdoClientConfig{}.fallback_to_segmented);
    EXPECT_FALSE(SdoClientOptions{}.fallback_to_segmented);
    up(0x1008, 0, TransferMode::Block);
    EXPECT_EQ(rx("80 08 10 00 01 00 04 05"), Strs{});  // no segmented initiate
    ASSERT_EQ(cli.status(), SdoClientMachine::Status::Failed);
    EXPECT_EQ(error<SdoAbortError>().code, 0x05040001u);
    EXPECT_EQ(cli.counters().fallbacks, 0u);
    down(0x2100, 0, H("01 02 03 04 05 06 07 08"), TransferMode::Block);
    EXPECT_EQ(rx("80 00 21 00 01 00 04 05"), Strs{});
    ASSERT_EQ(cli.status(), SdoClientMachine::Status::Failed);
    EXPECT_EQ(error<SdoAbortError>().code, 0x05040001u);
    EXPECT_EQ(cli.counters().fallbacks, 0u);
}

// Hardening (defect 7): the acknowledgement of a complete sub-block is lost.
// The server still waits for it; the client's sub-block timer must repeat the
// same acknowledgement (ackseq = the sub-block's last segment), never ackseq 0,
// which makes the server resend the old sub-block as if it were new data.
TEST_F(ClientFixture, LostSubblockAckIsRepeatedNotZeroed) {
    SdoClientConfig c;
    c.block_size = 2;
    cli.set_config(c);
    Bytes v(28);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint8_t>(i);
    auto seg = [&](std::uint8_t seq, std::size_t k, bool last = false) {
        return hex(sdo::block_segment(seq, std::span(v).subspan(k * 7, 7), last));
    };
    up(0x2201, 0, TransferMode::Block);
    rx("C6 01 22 00 1C 00 00 00");
    rx(seg(1, 0));
    EXPECT_EQ(rx(seg(2, 1)), Strs{"A2 02 02 00 00 00 00 00"});  // this ack is lost
    EXPECT_EQ(tick(now + kSec * 7 / 10), Strs{"A2 02 02 00 00 00 00 00"});
    // The server got the repeat and sends the second sub-block.
    rx(seg(1, 2));
    EXPECT_EQ(rx(seg(2, 3, true)), Strs{"A2 02 02 00 00 00 00 00"});
    EXPECT_EQ(rx(hex(sdo::block_upload_end(0, sdo::crc16(v)))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(cli.result(), v);
}

// The acknowledgement of the last sub-block is lost: the client waits for the
// end frame, the server for the ack.  The timer repeats the ack.
TEST_F(ClientFixture, LostFinalAckIsRepeated) {
    Bytes v(10, 0x33);
    up(0x2201, 0, TransferMode::Block);
    rx("C6 01 22 00 0A 00 00 00");
    rx(hex(sdo::block_segment(1, std::span(v).subspan(0, 7), false)));
    EXPECT_EQ(rx(hex(sdo::block_segment(2, std::span(v).subspan(7, 3), true))), Strs{"A2 02 7F 00 00 00 00 00"});
    EXPECT_EQ(tick(now + kSec * 7 / 10), Strs{"A2 02 7F 00 00 00 00 00"});
    EXPECT_EQ(rx(hex(sdo::block_upload_end(4, sdo::crc16(v)))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(cli.result(), v);
}

// The start command (0xA3) is lost: nothing arrives, the server still waits
// for it.  The timer repeats the start command (an ack would be refused).
TEST_F(ClientFixture, LostStartCommandIsRepeated) {
    up(0x2201, 0, TransferMode::Block);
    EXPECT_EQ(rx("C6 01 22 00 03 00 00 00"), Strs{"A3 00 00 00 00 00 00 00"});
    EXPECT_EQ(tick(now + kSec * 7 / 10), Strs{"A3 00 00 00 00 00 00 00"});
    EXPECT_EQ(rx("81 01 02 03 00 00 00 00"), Strs{"A2 01 7F 00 00 00 00 00"});
    EXPECT_EQ(rx(hex(sdo::block_upload_end(4, sdo::crc16(H("01 02 03"))))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(hex(cli.result()), "01 02 03");
}

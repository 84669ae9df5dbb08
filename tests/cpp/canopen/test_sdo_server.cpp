// SDO server state machine: the PMC007 exchanges byte for byte, and every
// server-side row of HOSTILE_INPUTS 2.1 (S*) and 2.3 (B*), driven without a bus.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "motorbus/canopen/sdo_server.hpp"
#include "test_sdo_util.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using motorbus::test::H;
using motorbus::test::hex;
using motorbus::test::hexes;
using Strs = std::vector<std::string>;

namespace {

constexpr Nanos kSec = 1'000'000'000;

struct ServerFixture : ::testing::Test {
    std::shared_ptr<ObjectDictionary> od = std::make_shared<ObjectDictionary>();
    bool external_stop = false;
    std::unique_ptr<SdoServerMachine> srv;
    Nanos now = 1000;

    void SetUp() override {
        od->add_variable({.index = 0x6001, .name = "Controller status", .type = DataType::Unsigned8,
                          .access = Access::RO, .pdo_mappable = true, .default_value = std::uint64_t{8}});
        od->add_variable({.index = 0x2003, .name = "Baud index", .type = DataType::Unsigned8,
                          .access = Access::RW, .low_limit = std::uint64_t{0},
                          .high_limit = std::uint64_t{8}, .default_value = std::uint64_t{4}});
        auto step = od->add_variable({.index = 0x6004, .name = "Step command",
                                      .type = DataType::Integer32, .access = Access::RW});
        step->set_write_hook([this](const Variable&, std::span<const std::uint8_t>) {
            return external_stop ? abort_code::kDeviceState : 0u;
        });
        od->add_variable({.index = 0x1008, .name = "Device name", .type = DataType::VisibleString,
                          .access = Access::Const, .default_value = Bytes{'P', 'M', 'C', '0', '0', '7'}});
        od->add_variable({.index = 0x2100, .name = "Small domain", .type = DataType::Domain,
                          .access = Access::RW, .max_size = 64});
        od->add_variable({.index = 0x2101, .name = "Password", .type = DataType::Unsigned16,
                          .access = Access::WO});
        od->add_variable({.index = 0x2102, .name = "Limited", .type = DataType::Unsigned16,
                          .access = Access::RW, .low_limit = std::uint64_t{10},
                          .high_limit = std::uint64_t{1000}, .default_value = std::uint64_t{100}});
        auto stream = od->add_variable({.index = 0x2200, .name = "Stream", .type = DataType::Domain,
                                        .access = Access::RO});
        stream->set_chunk_read_hook([](const Variable&, std::size_t off, std::size_t max, Bytes& chunk,
                                       bool& last) -> std::uint32_t {
            if (off >= 14) return abort_code::kCannotStore;  // fails mid-stream (S22)
            chunk.assign(std::min<std::size_t>(max, 7), static_cast<std::uint8_t>(0xA0 + off));
            last = false;
            return 0;
        });
        od->add_variable({.index = 0x2201, .name = "Big", .type = DataType::Domain,
                          .access = Access::RW, .max_size = 65536});
        od->add_record(0x1018, "Identity object");
        for (std::uint8_t s = 1; s <= 4; ++s)
            od->add_member(0x1018, {.subindex = s, .name = "Field" + std::to_string(s),
                                    .type = DataType::Unsigned32, .access = Access::RO,
                                    .default_value = std::uint64_t{0x100u + s}});
        od->add_record(0x1800, "TPDO1 communication parameter");
        od->add_member(0x1800, {.subindex = 1, .name = "COB-ID", .type = DataType::Unsigned32,
                                .default_value = std::uint64_t{0x185}});
        od->add_member(0x1800, {.subindex = 2, .name = "Transmission type", .type = DataType::Unsigned8});
        od->add_member(0x1800, {.subindex = 3, .name = "Inhibit time", .type = DataType::Unsigned16});
        od->add_member(0x1800, {.subindex = 5, .name = "Event timer", .type = DataType::Unsigned16});
        od->add_record(0x1A00, "TPDO1 mapping parameter");
        od->add_member(0x1A00, {.subindex = 0, .name = "Number of mapped objects",
                                .type = DataType::Unsigned8});
        od->add_member(0x1A00, {.subindex = 1, .name = "Mapping 1", .type = DataType::Unsigned32});
        srv = std::make_unique<SdoServerMachine>(*od);
    }

    Strs req(const std::string& h) {
        SdoServerMachine::Outbox out;
        auto b = H(h);
        srv->on_request(b, now, out);
        return hexes(out);
    }
    Strs tick(Nanos at) {
        SdoServerMachine::Outbox out;
        now = at;
        srv->on_timer(at, out);
        return hexes(out);
    }
    std::string abort_of(std::uint16_t i, std::uint8_t s, std::uint32_t code) {
        return hex(sdo::abort_transfer({i, s}, code));
    }
};

std::vector<std::string> pmc007_data_strings() {
    std::ifstream f(std::string(MOTORBUS_TEST_DATA) + "/vectors/seed_examples.json");
    std::stringstream ss;
    ss << f.rdbuf();
    std::string all = ss.str();
    auto start = all.find("\"pmc007_canopen\"");
    auto end = all.find("\"sdo_read_reply_command_bytes\"", start);
    std::string section = all.substr(start, end - start);
    // Every "data": "<hex>" value in order (std::regex trips GCC 12 warnings under sanitizers).
    std::vector<std::string> out;
    const std::string key = "\"data\": \"";
    for (auto p = section.find(key); p != std::string::npos; p = section.find(key, p + 1)) {
        auto b = p + key.size();
        out.push_back(section.substr(b, section.find('"', b) - b));
    }
    return out;
}

}  // namespace

// ---- PMC007 worked examples (tests/vectors/seed_examples.json) -------------

TEST_F(ServerFixture, Pmc007ExchangesByteForByte) {
    auto d = pmc007_data_strings();
    ASSERT_EQ(d.size(), 6u);  // three request/reply pairs
    EXPECT_EQ(req(d[0]), Strs{d[1]});  // read 0x6001 -> 8
    EXPECT_EQ(req(d[2]), Strs{d[3]});  // write 0x2003 = 7
    EXPECT_EQ(od->at(0x2003, 0)->get_u64(), 7u);
    external_stop = true;
    EXPECT_EQ(req(d[4]), Strs{d[5]});  // write 0x6004 refused: 0x08000022
    EXPECT_EQ(od->at(0x6004, 0)->get_i64(), 0);
    external_stop = false;
    EXPECT_EQ(req(d[4]), Strs{"60 04 60 00 00 00 00 00"});
    EXPECT_EQ(od->at(0x6004, 0)->get_i64(), 3200);
}

TEST_F(ServerFixture, Pmc007PdoConfigSequence) {
    const Strs requests = {"23 00 18 01 87 01 00 00", "2F 00 18 02 FF 00 00 00",
                           "2B 00 18 03 32 00 00 00", "2B 00 18 05 E8 03 00 00",
                           "2F 00 1A 00 01 00 00 00", "23 00 1A 01 10 00 12 60"};
    for (auto& r : requests) {
        auto b = H(r);
        EXPECT_EQ(req(r), Strs{hex(sdo::initiate_download_response({get_le16(&b[1]), b[3]}))}) << r;
    }
    EXPECT_EQ(od->at(0x1800, 1)->get_u64(), 0x187u);  // any COB-ID may be configured
    EXPECT_EQ(od->at(0x1800, 3)->get_u64(), 50u);
    EXPECT_EQ(od->at(0x1A00, 1)->get_u64(), 0x60120010u);
}

TEST_F(ServerFixture, Pmc007ReadReplyCommandBytesBySize) {
    od->add_variable({.index = 0x3001, .type = DataType::Unsigned8, .default_value = std::uint64_t{1}});
    od->add_variable({.index = 0x3002, .type = DataType::Unsigned16, .default_value = std::uint64_t{2}});
    od->add_variable({.index = 0x3003, .type = DataType::Unsigned24, .default_value = std::uint64_t{3}});
    od->add_variable({.index = 0x3004, .type = DataType::Unsigned32, .default_value = std::uint64_t{4}});
    EXPECT_EQ(req("40 01 30 00 00 00 00 00"), Strs{"4F 01 30 00 01 00 00 00"});
    EXPECT_EQ(req("40 02 30 00 00 00 00 00"), Strs{"4B 02 30 00 02 00 00 00"});
    EXPECT_EQ(req("40 03 30 00 00 00 00 00"), Strs{"47 03 30 00 03 00 00 00"});
    EXPECT_EQ(req("40 04 30 00 00 00 00 00"), Strs{"43 04 30 00 04 00 00 00"});
}

// ---- 2.1 server side ---------------------------------------------------------

TEST_F(ServerFixture, S1_UnknownCcsAbortsWithMultiplexer) {
    EXPECT_EQ(req("E0 34 12 56 00 00 00 00"), Strs{"80 34 12 56 01 00 04 05"});
    EXPECT_EQ(req("40 01 60 00 00 00 00 00"), Strs{"4F 01 60 00 08 00 00 00"});  // still serving
}

TEST_F(ServerFixture, S2_AbortWhileIdleIsSilent) {
    EXPECT_EQ(req("80 00 10 00 00 00 04 05"), Strs{});
    EXPECT_TRUE(srv->idle());
    EXPECT_EQ(srv->counters().aborts_received, 1u);
    EXPECT_EQ(req("40 01 60 00 00 00 00 00"), Strs{"4F 01 60 00 08 00 00 00"});
}

TEST_F(ServerFixture, S3_AbortMidDownloadDiscardsPartialData) {
    od->at(0x2100, 0)->set(H("01 02 03"));
    EXPECT_EQ(req("21 00 21 00 0E 00 00 00"), Strs{"60 00 21 00 00 00 00 00"});
    EXPECT_EQ(req("00 11 11 11 11 11 11 11"), Strs{"20 00 00 00 00 00 00 00"});
    for (const char* a : {"80 00 21 00 00 00 04 05", "80", "80 00 21"}) {  // any DLC
        EXPECT_EQ(req(a), Strs{});
        EXPECT_TRUE(srv->idle());
        EXPECT_EQ(hex(od->at(0x2100, 0)->get()), "01 02 03");  // nothing committed
        EXPECT_EQ(srv->buffered(), 0u);
        req("21 00 21 00 0E 00 00 00");
        req("00 11 11 11 11 11 11 11");
    }
}

TEST_F(ServerFixture, S4_InitiateWithoutMultiplexerAborts) {
    for (const char* r : {"40", "40 01", "40 01 60", "23 04", "A4 01", "C6 01 20"})
        EXPECT_EQ(req(r), Strs{"80 00 00 00 01 00 04 05"}) << r;
    EXPECT_EQ(req("40 01 60 00"), Strs{"4F 01 60 00 08 00 00 00"});  // DLC 4 is enough for upload
}

TEST_F(ServerFixture, S5_EmptyFrameIgnoredAndCounted) {
    EXPECT_EQ(req(""), Strs{});
    EXPECT_EQ(srv->counters().ignored, 1u);
    EXPECT_EQ(req("40 01 60 00 00 00 00 00"), Strs{"4F 01 60 00 08 00 00 00"});
}

TEST_F(ServerFixture, S6_NonExistentObject) {
    EXPECT_EQ(req("40 55 55 00 00 00 00 00"), Strs{abort_of(0x5555, 0, 0x06020000)});
    EXPECT_EQ(req("2F 55 55 00 01 00 00 00"), Strs{abort_of(0x5555, 0, 0x06020000)});
    EXPECT_EQ(req("A4 55 55 00 7F 00 00 00"), Strs{abort_of(0x5555, 0, 0x06020000)});
}

TEST_F(ServerFixture, S7_NonExistentSubIndex) {
    EXPECT_EQ(req("40 01 60 01 00 00 00 00"), Strs{abort_of(0x6001, 1, 0x06090011)});  // VAR sub != 0
    EXPECT_EQ(req("40 18 10 09 00 00 00 00"), Strs{abort_of(0x1018, 9, 0x06090011)});
    EXPECT_EQ(req("40 18 10 00 00 00 00 00"), Strs{"4F 18 10 00 04 00 00 00"});
}

TEST_F(ServerFixture, S8_WriteReadOnlyAndReadWriteOnly) {
    EXPECT_EQ(req("2F 01 60 00 01 00 00 00"), Strs{abort_of(0x6001, 0, 0x06010002)});
    EXPECT_EQ(req("21 08 10 00 03 00 00 00"), Strs{abort_of(0x1008, 0, 0x06010002)});  // const, segmented
    EXPECT_EQ(req("40 01 21 00 00 00 00 00"), Strs{abort_of(0x2101, 0, 0x06010001)});
    EXPECT_EQ(req("A4 01 21 00 10 00 00 00"), Strs{abort_of(0x2101, 0, 0x06010001)});
    EXPECT_EQ(req("2B 01 21 00 34 12 00 00"), Strs{"60 01 21 00 00 00 00 00"});
    EXPECT_EQ(od->at(0x2101, 0)->get_u64(), 0x1234u);
}

TEST_F(ServerFixture, S9_ExpeditedSizeMismatch) {
    EXPECT_EQ(req("23 02 21 00 20 00 00 00"), Strs{abort_of(0x2102, 0, 0x06070012)});
    EXPECT_EQ(req("2F 02 21 00 20 00 00 00"), Strs{abort_of(0x2102, 0, 0x06070013)});
    EXPECT_EQ(od->at(0x2102, 0)->get_u64(), 100u);
    EXPECT_EQ(req("2B 02 21 00 20 00 00 00"), Strs{"60 02 21 00 00 00 00 00"});
}

TEST_F(ServerFixture, S10_ValueOutOfRange) {
    EXPECT_EQ(req("2B 02 21 00 05 00 00 00"), Strs{abort_of(0x2102, 0, 0x06090032)});
    EXPECT_EQ(req("2B 02 21 00 D0 07 00 00"), Strs{abort_of(0x2102, 0, 0x06090031)});
    EXPECT_EQ(req("2F 03 20 00 09 00 00 00"), Strs{abort_of(0x2003, 0, 0x06090031)});
    EXPECT_EQ(od->at(0x2102, 0)->get_u64(), 100u);
    EXPECT_EQ(req("2B 02 21 00 E8 03 00 00"), Strs{"60 02 21 00 00 00 00 00"});  // 1000: the limit itself
}

TEST_F(ServerFixture, S11_SegmentedInitiateSizeMismatchFailsEarly) {
    EXPECT_EQ(req("21 02 21 00 07 00 00 00"), Strs{abort_of(0x2102, 0, 0x06070012)});
    EXPECT_EQ(req("21 02 21 00 01 00 00 00"), Strs{abort_of(0x2102, 0, 0x06070013)});
    EXPECT_EQ(srv->buffered(), 0u);
    EXPECT_EQ(req("21 00 21 00 41 00 00 00"), Strs{abort_of(0x2100, 0, 0x06070012)});  // 65 > max 64
    EXPECT_EQ(req("21 02 21 00 02 00 00 00"), Strs{"60 02 21 00 00 00 00 00"});
}

TEST_F(ServerFixture, S12_SegmentsPastIndicatedOrObjectSize) {
    // Size indicated (8): the second full segment brings byte 9..14 -> abort at once.
    EXPECT_EQ(req("21 00 21 00 08 00 00 00"), Strs{"60 00 21 00 00 00 00 00"});
    EXPECT_EQ(req("00 01 02 03 04 05 06 07"), Strs{"20 00 00 00 00 00 00 00"});
    EXPECT_EQ(req("10 08 09 0A 0B 0C 0D 0E"), Strs{abort_of(0x2100, 0, 0x06070012)});
    EXPECT_EQ(srv->buffered(), 0u);
    // No size: the buffer stops at the object's max size (64).
    EXPECT_EQ(req("20 00 21 00 00 00 00 00"), Strs{"60 00 21 00 00 00 00 00"});
    bool t = false;
    for (int i = 0; i < 9; ++i, t = !t) {
        std::string seg = t ? "10 AA AA AA AA AA AA AA" : "00 AA AA AA AA AA AA AA";
        EXPECT_EQ(req(seg), Strs{t ? "30 00 00 00 00 00 00 00" : "20 00 00 00 00 00 00 00"});
        EXPECT_LE(srv->buffered(), 4096u);
    }
    EXPECT_EQ(req(t ? "10 AA AA AA AA AA AA AA" : "00 AA AA AA AA AA AA AA"),
              Strs{abort_of(0x2100, 0, 0x06070012)});  // 63 + 7 > 64
    EXPECT_TRUE(od->at(0x2100, 0)->get().empty());
}

TEST_F(ServerFixture, S13_ToggleNotAlternated) {
    req("21 00 21 00 0E 00 00 00");
    EXPECT_EQ(req("00 01 02 03 04 05 06 07"), Strs{"20 00 00 00 00 00 00 00"});
    EXPECT_EQ(req("00 01 02 03 04 05 06 07"), Strs{abort_of(0x2100, 0, 0x05030000)});
    // Upload side: the client's segment request repeats the toggle.
    EXPECT_EQ(req("40 08 10 00 00 00 00 00"), Strs{"41 08 10 00 06 00 00 00"});
    EXPECT_EQ(req("70 00 00 00 00 00 00 00"), Strs{abort_of(0x1008, 0, 0x05030000)});
}

TEST_F(ServerFixture, S14_SegmentWithoutTransfer) {
    EXPECT_EQ(req("00 01 02 03 04 05 06 07"), Strs{"80 01 02 03 01 00 04 05"});
    EXPECT_EQ(req("60 00 00 00 00 00 00 00"), Strs{"80 00 00 00 01 00 04 05"});
    EXPECT_EQ(req("40 01 60 00 00 00 00 00"), Strs{"4F 01 60 00 08 00 00 00"});
}

TEST_F(ServerFixture, S16_SilentClientTimesOutAndReleases) {
    EXPECT_EQ(req("21 01 22 00 00 04 00 00"), Strs{"60 01 22 00 00 00 00 00"});
    EXPECT_EQ(req("00 01 02 03 04 05 06 07"), Strs{"20 00 00 00 00 00 00 00"});
    EXPECT_GT(srv->buffered(), 0u);
    EXPECT_EQ(srv->next_deadline(), now + kSec);
    EXPECT_EQ(tick(now + kSec - 1), Strs{});
    EXPECT_EQ(tick(now + 1), Strs{abort_of(0x2201, 0, 0x05040000)});
    EXPECT_TRUE(srv->idle());
    EXPECT_EQ(srv->buffered(), 0u);
    EXPECT_EQ(srv->counters().timeouts, 1u);
    EXPECT_TRUE(od->at(0x2201, 0)->get().empty());
}

TEST_F(ServerFixture, S19_SegmentClaimsMoreThanDlc) {
    req("21 00 21 00 0E 00 00 00");
    EXPECT_EQ(req("00 01 02"), Strs{abort_of(0x2100, 0, 0x05040001)});  // n=0 claims 7 bytes
    req("21 00 21 00 02 00 00 00");
    EXPECT_EQ(req("0B 01 02"), Strs{"20 00 00 00 00 00 00 00"});  // n=5: 2 bytes, DLC 3 is enough
    EXPECT_EQ(hex(od->at(0x2100, 0)->get()), "01 02");
}

TEST_F(ServerFixture, S22_HookErrorMidStreamAborts) {
    EXPECT_EQ(req("40 00 22 00 00 00 00 00"), Strs{"40 00 22 00 00 00 00 00"});  // size not indicated
    EXPECT_EQ(req("60 00 00 00 00 00 00 00"), Strs{"00 A0 A0 A0 A0 A0 A0 A0"});
    EXPECT_EQ(req("70 00 00 00 00 00 00 00"), Strs{"10 A7 A7 A7 A7 A7 A7 A7"});
    EXPECT_EQ(req("60 00 00 00 00 00 00 00"), Strs{abort_of(0x2200, 0, 0x08000020)});
    EXPECT_TRUE(srv->idle());
    // Block upload of the same stream: the hook fails while filling the sub-block.
    EXPECT_EQ(req("A4 00 22 00 7F 00 00 00"), Strs{"C4 00 22 00 00 00 00 00"});
    EXPECT_EQ(req("A3 00 00 00 00 00 00 00"), Strs{abort_of(0x2200, 0, 0x08000020)});
}

TEST_F(ServerFixture, SegmentedUploadAndDownloadRoundTrip) {
    EXPECT_EQ(req("40 08 10 00 00 00 00 00"), Strs{"41 08 10 00 06 00 00 00"});
    EXPECT_EQ(req("60 00 00 00 00 00 00 00"), Strs{"03 50 4D 43 30 30 37 00"});  // n=1, c=1
    EXPECT_TRUE(srv->idle());
    EXPECT_EQ(req("21 00 21 00 09 00 00 00"), Strs{"60 00 21 00 00 00 00 00"});
    EXPECT_EQ(req("00 01 02 03 04 05 06 07"), Strs{"20 00 00 00 00 00 00 00"});
    EXPECT_EQ(req("1B 08 09 00 00 00 00 00"), Strs{"30 00 00 00 00 00 00 00"});
    EXPECT_EQ(hex(od->at(0x2100, 0)->get()), "01 02 03 04 05 06 07 08 09");
}

// ---- 2.3 block transfer, server side -------------------------------------------

TEST_F(ServerFixture, BlockUploadWithCrc) {
    EXPECT_EQ(req("A4 08 10 00 7F 00 00 00"), Strs{"C6 08 10 00 06 00 00 00"});
    EXPECT_EQ(req("A3 00 00 00 00 00 00 00"), Strs{"81 50 4D 43 30 30 37 00"});
    const auto crc = sdo::crc16(H("50 4D 43 30 30 37"));
    EXPECT_EQ(req("A2 01 7F 00 00 00 00 00"), Strs{hex(sdo::block_upload_end(1, crc))});
    EXPECT_EQ(req("A1 00 00 00 00 00 00 00"), Strs{});
    EXPECT_TRUE(srv->idle());
}

TEST_F(ServerFixture, BlockUploadProtocolSwitch) {
    EXPECT_EQ(req("A4 01 60 00 7F 04 00 00"), Strs{"4F 01 60 00 08 00 00 00"});  // pst 4 >= 1 byte
}

TEST_F(ServerFixture, B1_BlockUploadBlksizeZero) {
    EXPECT_EQ(req("A4 08 10 00 00 00 00 00"), Strs{abort_of(0x1008, 0, 0x05040002)});
}

TEST_F(ServerFixture, B2_BlockUploadBlksizeTooLarge) {
    EXPECT_EQ(req("A4 08 10 00 80 00 00 00"), Strs{abort_of(0x1008, 0, 0x05040002)});
    EXPECT_EQ(req("A4 08 10 00 FF 00 00 00"), Strs{abort_of(0x1008, 0, 0x05040002)});
    EXPECT_EQ(req("A4 08 10 00 7F 00 00 00"), Strs{"C6 08 10 00 06 00 00 00"});
}

TEST_F(ServerFixture, B3_AckseqBeyondSubblock) {
    od->at(0x2201, 0)->set(Bytes(30, 0x55));
    req("A4 01 22 00 02 00 00 00");
    EXPECT_EQ(req("A3 00 00 00 00 00 00 00").size(), 2u);
    EXPECT_EQ(req("A2 80 7F 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040003)});
    req("A4 01 22 00 02 00 00 00");
    req("A3 00 00 00 00 00 00 00");
    EXPECT_EQ(req("A2 03 7F 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040003)});  // sent only 2
}

TEST_F(ServerFixture, B8_ClientAckWithInvalidBlksize) {
    od->at(0x2201, 0)->set(Bytes(30, 0x55));
    req("A4 01 22 00 02 00 00 00");
    req("A3 00 00 00 00 00 00 00");
    EXPECT_EQ(req("A2 02 00 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040002)});
    req("A4 01 22 00 02 00 00 00");
    req("A3 00 00 00 00 00 00 00");
    EXPECT_EQ(req("A2 02 80 00 00 00 00 00"), Strs{abort_of(0x2201, 0, 0x05040002)});
}

TEST_F(ServerFixture, BlockUploadRetransmitsFromAckseq) {
    Bytes v(30);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint8_t>(i);
    od->at(0x2201, 0)->set(v);
    EXPECT_EQ(req("A4 01 22 00 03 00 00 00"), Strs{"C6 01 22 00 1E 00 00 00"});
    EXPECT_EQ(req("A3 00 00 00 00 00 00 00"),
              (Strs{"01 00 01 02 03 04 05 06", "02 07 08 09 0A 0B 0C 0D", "03 0E 0F 10 11 12 13 14"}));
    // Only seq 1 arrived: 2 and 3 come again as 1 and 2, topped up with new data.
    EXPECT_EQ(req("A2 01 03 00 00 00 00 00"),
              (Strs{"01 07 08 09 0A 0B 0C 0D", "02 0E 0F 10 11 12 13 14", "03 15 16 17 18 19 1A 1B"}));
    EXPECT_EQ(req("A2 03 03 00 00 00 00 00"), Strs{"81 1C 1D 00 00 00 00 00"});
    EXPECT_EQ(req("A2 01 03 00 00 00 00 00"), Strs{hex(sdo::block_upload_end(5, sdo::crc16(v)))});
    EXPECT_EQ(req("A1 00 00 00 00 00 00 00"), Strs{});
    EXPECT_EQ(srv->counters().transfers_completed, 1u);
}

struct BlockDownload : ServerFixture {
    Bytes data;
    void begin(std::size_t n, bool crc = true) {
        data.resize(n);
        for (std::size_t i = 0; i < n; ++i) data[i] = static_cast<std::uint8_t>(i * 7 + 1);
        auto p = sdo::block_download_initiate({0x2201, 0}, crc, static_cast<std::uint32_t>(n));
        EXPECT_EQ(req(hex(p)), Strs{"A4 01 22 00 7F 00 00 00"});
    }
    std::string seg(std::uint8_t seq, std::size_t k, bool last = false) {
        auto off = k * 7;
        std::span<const std::uint8_t> d(data.data() + off, std::min<std::size_t>(7, data.size() - off));
        return hex(sdo::block_segment(seq, d, last));
    }
};

TEST_F(BlockDownload, CompletesWithCrc) {
    begin(20);
    EXPECT_EQ(req(seg(1, 0)), Strs{});
    EXPECT_EQ(req(seg(2, 1)), Strs{});
    EXPECT_EQ(req(seg(3, 2, true)), Strs{"A2 03 7F 00 00 00 00 00"});
    EXPECT_EQ(req(hex(sdo::block_download_end(1, sdo::crc16(data)))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(od->at(0x2201, 0)->get(), data);
}

TEST_F(BlockDownload, B4_SeqnoZero) {
    begin(20);
    EXPECT_EQ(req("00 01 02 03 04 05 06 07"), Strs{abort_of(0x2201, 0, 0x05040003)});
    EXPECT_TRUE(srv->idle());
}

TEST_F(BlockDownload, B6_DuplicateSeqnoIgnored) {
    begin(20);
    req(seg(1, 0));
    req(seg(2, 1));
    EXPECT_EQ(req(seg(2, 1)), Strs{});
    EXPECT_EQ(req(seg(1, 0)), Strs{});
    EXPECT_EQ(req(seg(3, 2, true)), Strs{"A2 03 7F 00 00 00 00 00"});
    EXPECT_EQ(req(hex(sdo::block_download_end(1, sdo::crc16(data)))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(od->at(0x2201, 0)->get(), data);
}

TEST_F(BlockDownload, B9_CrcMismatch) {
    begin(20);
    req(seg(1, 0));
    req(seg(2, 1));
    req(seg(3, 2, true));
    EXPECT_EQ(req(hex(sdo::block_download_end(1, sdo::crc16(data) ^ 1))),
              Strs{abort_of(0x2201, 0, 0x05040004)});
    EXPECT_TRUE(od->at(0x2201, 0)->get().empty());
}

TEST_F(BlockDownload, B10_EndNInconsistent) {
    begin(20);
    req(seg(1, 0));
    req(seg(2, 1));
    req(seg(3, 2, true));
    EXPECT_EQ(req(hex(sdo::block_download_end(7, 0))), Strs{abort_of(0x2201, 0, 0x05040001)});
}

TEST_F(BlockDownload, B11_TotalDiffersFromIndicated) {
    begin(20);
    req(seg(1, 0));
    req(seg(2, 1));
    req(seg(3, 2, true));
    EXPECT_EQ(req(hex(sdo::block_download_end(3, 0))), Strs{abort_of(0x2201, 0, 0x06070013)});
    begin(13);
    req(seg(1, 0));
    EXPECT_EQ(req(hex(sdo::block_segment(2, H("01 02 03 04 05 06 07"), true))), Strs{"A2 02 7F 00 00 00 00 00"});
    EXPECT_EQ(req(hex(sdo::block_download_end(0, 0))), Strs{abort_of(0x2201, 0, 0x06070012)});
}

TEST_F(BlockDownload, B12_StalledSubblockAckedThenTimeout) {
    begin(2000);
    req(seg(1, 0));
    req(seg(2, 1));
    EXPECT_EQ(tick(now + kSec * 7 / 10), Strs{"A2 02 7F 00 00 00 00 00"});  // acks what arrived
    // The client resends from 3 as 1..: accepted in order.
    EXPECT_EQ(req(seg(1, 2)), Strs{});
    EXPECT_EQ(tick(now + kSec), Strs{abort_of(0x2201, 0, 0x05040000)});
    EXPECT_TRUE(srv->idle());
    EXPECT_EQ(srv->buffered(), 0u);
}

TEST_F(BlockDownload, B13_LostFrameRecoveredByRetransmission) {
    SdoServerConfig cfg;
    cfg.block_size = 4;
    srv = std::make_unique<SdoServerMachine>(*od, cfg);
    data.resize(40);
    for (std::size_t i = 0; i < 40; ++i) data[i] = static_cast<std::uint8_t>(i);
    EXPECT_EQ(req(hex(sdo::block_download_initiate({0x2201, 0}, true, 40))), Strs{"A4 01 22 00 04 00 00 00"});
    req(seg(1, 0));
    // seq 2 lost
    EXPECT_EQ(req(seg(3, 2)), Strs{});
    EXPECT_EQ(req(seg(4, 3)), Strs{"A2 01 04 00 00 00 00 00"});
    // retransmit from segment 1 (data block 1) renumbered
    req(seg(1, 1));
    req(seg(2, 2));
    req(seg(3, 3));
    EXPECT_EQ(req(seg(4, 4)), Strs{"A2 04 04 00 00 00 00 00"});
    EXPECT_EQ(req(seg(1, 5, true)), Strs{"A2 01 04 00 00 00 00 00"});
    EXPECT_EQ(req(hex(sdo::block_download_end(2, sdo::crc16(data)))), Strs{"A1 00 00 00 00 00 00 00"});
    EXPECT_EQ(od->at(0x2201, 0)->get(), data);
}

TEST_F(ServerFixture, B15_BlockDownloadLargerThanObject) {
    EXPECT_EQ(req(hex(sdo::block_download_initiate({0x2102, 0}, true, 10))),
              Strs{abort_of(0x2102, 0, 0x06070012)});
    EXPECT_EQ(req(hex(sdo::block_download_initiate({0x2100, 0}, true, 65))),
              Strs{abort_of(0x2100, 0, 0x06070012)});
}

TEST_F(ServerFixture, B16_BlockRefusedWhenDisabled) {
    SdoServerConfig cfg;
    cfg.block_transfer = false;
    srv = std::make_unique<SdoServerMachine>(*od, cfg);
    EXPECT_EQ(req("A4 08 10 00 7F 00 00 00"), Strs{abort_of(0x1008, 0, 0x05040001)});
    EXPECT_EQ(req("C6 00 21 00 02 00 00 00"), Strs{abort_of(0x2100, 0, 0x05040001)});
    EXPECT_EQ(req("40 08 10 00 00 00 00 00"), Strs{"41 08 10 00 06 00 00 00"});
}

TEST_F(ServerFixture, WrongCommandMidTransferAborts) {
    req("21 00 21 00 0E 00 00 00");
    EXPECT_EQ(req("60 00 00 00 00 00 00 00"), Strs{abort_of(0x2100, 0, 0x05040001)});
    EXPECT_TRUE(srv->idle());
}

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "motorbus/canopen/emcy.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/pdo_engine.hpp"
#include "motorbus/errors.hpp"
#include "test_nmt_support.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using svc_test::bytes;
using svc_test::frame;
using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

// ---- codec ------------------------------------------------------------------

TEST(PdoConfigure, ProcedureNames) {
    EXPECT_EQ(pdo_procedure_from_name("cia301"), PdoProcedure::Cia301);
    EXPECT_EQ(pdo_procedure_from_name("direct"), PdoProcedure::Direct);
    EXPECT_STREQ(to_string(PdoProcedure::Direct), "direct");
    EXPECT_FALSE(pdo_procedure_from_name("CiA301"));
}

TEST(PdoLayout, ByteAlignedLittleEndian) {
    PdoMapEntry m[] = {{0x6041, 0, 16}, {0x6064, 0, 32}, {0x6061, 0, 8}};
    PdoLayout l(m);
    EXPECT_EQ(l.total_bits(), 56u);
    EXPECT_EQ(l.byte_length(), 7u);
    std::uint64_t v[] = {0x0637, 0xFFFFFF9C /* -100 */, 0x01};
    EXPECT_EQ(l.pack(std::span<const std::uint64_t>(v)), (Bytes{0x37, 0x06, 0x9C, 0xFF, 0xFF, 0xFF, 0x01}));
    auto u = l.unpack(Bytes{0x37, 0x06, 0x9C, 0xFF, 0xFF, 0xFF, 0x01});
    EXPECT_EQ(u, (std::vector<std::uint64_t>{0x0637, 0xFFFFFF9C, 1}));
    EXPECT_EQ(l.to_signed(1, u[1]), -100);  // only meaningful for signed objects
}

TEST(PdoLayout, ArbitraryBitOffsets) {
    // 1 + 3 + 12 + 7 + 1 bits: entries straddle byte boundaries.
    PdoMapEntry m[] = {{0x2000, 1, 1}, {0x2000, 2, 3}, {0x2000, 3, 12}, {0x2000, 4, 7}, {0x2000, 5, 1}};
    PdoLayout l(m);
    EXPECT_EQ(l.total_bits(), 24u);
    EXPECT_EQ(l.offset(3), 16u);
    std::uint64_t v[] = {1, 0b101, 0xABC, 0x55, 1};
    // bit layout: b0=1, b1-3=101, b4-15=ABC, b16-22=1010101, b23=1
    // byte0 = 1 | 101<<1 | (C<<4) = 0xCB, byte1 = 0xAB, byte2 = 0x55 | 0x80 = 0xD5
    auto packed = l.pack(std::span<const std::uint64_t>(v));
    EXPECT_EQ(packed, (Bytes{0xCB, 0xAB, 0xD5}));
    EXPECT_EQ(l.unpack(packed), (std::vector<std::uint64_t>{1, 5, 0xABC, 0x55, 1}));
    // Values wider than their entry are truncated, never bleed into neighbours.
    std::uint64_t wide[] = {0xFF, 0xFF, 0xFFFFF, 0xFF, 0xFF};
    EXPECT_EQ(l.pack(std::span<const std::uint64_t>(wide)), (Bytes{0xFF, 0xFF, 0xFF}));
}

TEST(PdoLayout, SixtyFourBitsAndLimits) {
    PdoMapEntry m64[] = {{0x2001, 0, 64}};
    PdoLayout l(m64);
    std::uint64_t v[] = {0x0123456789ABCDEFull};
    EXPECT_EQ(l.pack(std::span<const std::uint64_t>(v)), (Bytes{0xEF, 0xCD, 0xAB, 0x89, 0x67, 0x45, 0x23, 0x01}));
    PdoMapEntry over[] = {{0x2001, 0, 64}, {0x2002, 0, 1}};
    EXPECT_THROW(PdoLayout{over}, InvalidArgument);
    PdoMapEntry zero[] = {{0x2001, 0, 0}};
    EXPECT_THROW(PdoLayout{zero}, InvalidArgument);
    std::vector<PdoMapEntry> bits64(64, PdoMapEntry{0x2000, 1, 1});
    PdoLayout ones(bits64);
    std::vector<std::uint64_t> alt(64);
    for (int i = 0; i < 64; ++i) alt[i] = i & 1;
    EXPECT_EQ(ones.pack(alt), Bytes(8, 0xAA));
    // Too short for the mapping: no values, a ProtocolError with the bytes.
    EXPECT_THROW(l.unpack(Bytes{1, 2, 3}), ProtocolError);
}

TEST(PdoLayout, MappingWord) {
    PdoMapEntry e{0x6012, 0, 16};
    EXPECT_EQ(e.mapping_word(), 0x60120010u);
    EXPECT_EQ(PdoMapEntry::from_mapping_word(0x60410010u), (PdoMapEntry{0x6041, 0, 16}));
    EXPECT_EQ(pdo_comm_index(true, 1), 0x1800);
    EXPECT_EQ(pdo_map_index(false, 4), 0x1603);
    EXPECT_EQ(default_pdo_cob_id(true, 1, 5), 0x185u);
    EXPECT_EQ(default_pdo_cob_id(false, 4, 5), 0x505u);
}

// ---- configuration over SDO -------------------------------------------------

namespace {

// Turns SdoAccess calls into the expedited download frames an SDO client
// sends (command byte by size), and answers uploads from a map.
struct RecordingSdo : SdoAccess {
    std::vector<can::Frame> frames;
    std::map<std::uint32_t, std::uint64_t> values;
    std::function<std::uint32_t(std::uint16_t, std::uint8_t, std::span<const std::uint8_t>)> sink;
    void download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                  std::span<const std::uint8_t> data) override {
        can::Frame f;
        f.id = 0x600u + node;
        f.len = 8;
        f.data[0] = static_cast<std::uint8_t>(0x23 | ((4 - data.size()) << 2));
        f.data[1] = static_cast<std::uint8_t>(index);
        f.data[2] = static_cast<std::uint8_t>(index >> 8);
        f.data[3] = sub;
        std::copy(data.begin(), data.end(), f.data.begin() + 4);
        frames.push_back(f);
        if (sink)
            if (auto code = sink(index, sub, data)) throw ProtocolError("abort " + std::to_string(code));
    }
    std::vector<std::uint8_t> upload(std::uint8_t, std::uint16_t index, std::uint8_t sub) override {
        auto v = values.at((std::uint32_t(index) << 8) | sub);
        return {std::uint8_t(v), std::uint8_t(v >> 8), std::uint8_t(v >> 16), std::uint8_t(v >> 24)};
    }
};

Bytes hex(const std::string& s) {
    Bytes b;
    std::istringstream in(s);
    std::string tok;
    while (in >> tok) b.push_back(static_cast<std::uint8_t>(std::stoul(tok, nullptr, 16)));
    return b;
}

struct Vector {
    std::vector<std::pair<std::uint32_t, Bytes>> requests;
    std::pair<std::uint32_t, Bytes> result;
};

Vector pmc007_vector() {
    std::ifstream in(std::string(MOTORBUS_TEST_DATA) + "/vectors/seed_examples.json");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string s = ss.str();
    auto start = s.find("\"pdo_config_sequence\"");
    EXPECT_NE(start, std::string::npos);
    auto end = s.find("\"accel_gears_pps2\"", start);
    std::string part = s.substr(start, end - start);
    // Every "id": "..", "data": ".." pair in order (no std::regex: GCC 12 warns under sanitizers).
    Vector v;
    std::vector<std::pair<std::uint32_t, Bytes>> all;
    const std::string idk = "\"id\": \"", datak = "\"data\": \"";
    for (auto p = part.find(idk); p != std::string::npos; p = part.find(idk, p + 1)) {
        const auto ib = p + idk.size();
        const auto d = part.find(datak, ib);
        if (d == std::string::npos) break;
        const auto db = d + datak.size();
        all.emplace_back(std::stoul(part.substr(ib, part.find('"', ib) - ib), nullptr, 16),
                         hex(part.substr(db, part.find('"', db) - db)));
    }
    EXPECT_EQ(all.size(), 7u);
    v.requests.assign(all.begin(), all.end() - 1);
    v.result = all.back();
    return v;
}

PdoConfig pmc007_config() {
    PdoConfig c;
    c.tpdo = true;
    c.number = 1;
    c.cob_id = 0x187;
    c.transmission_type = 255;
    c.inhibit_100us = 50;
    c.event_timer_ms = 1000;
    c.mapping = std::vector<PdoMapEntry>{{0x6012, 0, 16}};
    return c;
}

}  // namespace

TEST(PdoConfigure, Pmc007SequenceByteForByte) {
    const auto vec = pmc007_vector();
    RecordingSdo sdo;
    write_pdo(sdo, 5, pmc007_config(), PdoProcedure::Direct);
    ASSERT_EQ(sdo.frames.size(), vec.requests.size());
    for (std::size_t i = 0; i < vec.requests.size(); ++i) {
        EXPECT_EQ(sdo.frames[i].id, vec.requests[i].first) << i;
        EXPECT_EQ(bytes(sdo.frames[i]), vec.requests[i].second) << i;
    }
}

TEST(PdoConfigure, Cia301ProcedureDisablesClearsMapsEnables) {
    RecordingSdo sdo;
    write_pdo(sdo, 5, pmc007_config(), PdoProcedure::Cia301);
    std::vector<Bytes> want = {
        {0x23, 0x00, 0x18, 0x01, 0x87, 0x01, 0x00, 0x80},  // disable (bit 31)
        {0x2F, 0x00, 0x18, 0x02, 0xFF, 0, 0, 0},
        {0x2B, 0x00, 0x18, 0x03, 0x32, 0x00, 0, 0},
        {0x2B, 0x00, 0x18, 0x05, 0xE8, 0x03, 0, 0},
        {0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0},  // clear sub0
        {0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x12, 0x60},
        {0x2F, 0x00, 0x1A, 0x00, 0x01, 0, 0, 0},  // set sub0
        {0x23, 0x00, 0x18, 0x01, 0x87, 0x01, 0x00, 0x00},  // enable
    };
    ASSERT_EQ(sdo.frames.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(bytes(sdo.frames[i]), want[i]) << i;
}

TEST(PdoConfigure, ReadBack) {
    RecordingSdo sdo;
    auto k = [](std::uint16_t i, std::uint8_t s) { return (std::uint32_t(i) << 8) | s; };
    sdo.values = {{k(0x1801, 0), 5},          {k(0x1801, 1), 0x80000285}, {k(0x1801, 2), 1},
                  {k(0x1801, 3), 0},          {k(0x1801, 5), 0},          {k(0x1A01, 0), 2},
                  {k(0x1A01, 1), 0x60410010}, {k(0x1A01, 2), 0x60640020}};
    auto c = read_pdo(sdo, 5, true, 2);
    EXPECT_EQ(*c.cob_id, 0x285u);
    EXPECT_FALSE(c.enabled);
    EXPECT_EQ(*c.transmission_type, 1);
    EXPECT_EQ(*c.event_timer_ms, 0);
    EXPECT_FALSE(c.sync_start);
    ASSERT_EQ(c.mapping->size(), 2u);
    EXPECT_EQ((*c.mapping)[1], (PdoMapEntry{0x6064, 0, 32}));
}

// ---- engine -------------------------------------------------------------------

namespace {

struct EngineFixture : ::testing::Test {
    SimClock clock{0};
    PdoObjectTable od;
    std::vector<can::Frame> out;
    std::vector<std::pair<std::uint16_t, bool>> emcy;
    std::unique_ptr<PdoEngine> eng;

    void make(bool strict = true, std::uint32_t window_us = 0) {
        od.add(0x6012, 0, {16, true, false, 0x0003});        // PMC007 GPIO value
        od.add(0x6041, 0, {16, true, false, 0x0237});
        od.add(0x6064, 0, {32, true, false, 0});
        od.add(0x6040, 0, {16, false, true, 0});
        od.add(0x607A, 0, {32, false, true, 0});
        od.add(0x6060, 0, {8, false, true, 0});
        od.add(0x1000, 0, {32, false, false, 0x00040192});  // not mappable
        PdoEngineOptions o;
        o.node_id = 5;
        o.strict = strict;
        o.sync_window_us = window_us;
        eng = std::make_unique<PdoEngine>(
            od, clock, o, [this](const can::Frame& f) { out.push_back(f); },
            [this](std::uint16_t c, bool a) { emcy.emplace_back(c, a); });
    }
    std::uint32_t w32(std::uint16_t i, std::uint8_t s, std::uint32_t v) {
        Bytes b{std::uint8_t(v), std::uint8_t(v >> 8), std::uint8_t(v >> 16), std::uint8_t(v >> 24)};
        return eng->write(i, s, b);
    }
    std::uint32_t w16(std::uint16_t i, std::uint8_t s, std::uint16_t v) {
        Bytes b{std::uint8_t(v), std::uint8_t(v >> 8)};
        return eng->write(i, s, b);
    }
    std::uint32_t w8(std::uint16_t i, std::uint8_t s, std::uint8_t v) { return eng->write(i, s, Bytes{v}); }
    // RPDO1: controlword + target position, async.
    void map_rpdo1(std::uint8_t type = 255) {
        ASSERT_EQ(w32(0x1400, 1, 0x80000205), 0u);
        ASSERT_EQ(w8(0x1400, 2, type), 0u);
        ASSERT_EQ(w8(0x1600, 0, 0), 0u);
        ASSERT_EQ(w32(0x1600, 1, 0x60400010), 0u);
        ASSERT_EQ(w32(0x1600, 2, 0x607A0020), 0u);
        ASSERT_EQ(w8(0x1600, 0, 2), 0u);
        ASSERT_EQ(w32(0x1400, 1, 0x205), 0u);
    }
    void map_tpdo1(std::uint8_t type, std::uint16_t inhibit = 0, std::uint16_t timer = 0) {
        ASSERT_EQ(w32(0x1800, 1, 0x80000185), 0u);
        ASSERT_EQ(w8(0x1800, 2, type), 0u);
        ASSERT_EQ(w16(0x1800, 3, inhibit), 0u);
        ASSERT_EQ(w16(0x1800, 5, timer), 0u);
        ASSERT_EQ(w8(0x1A00, 0, 0), 0u);
        ASSERT_EQ(w32(0x1A00, 1, 0x60410010), 0u);
        ASSERT_EQ(w8(0x1A00, 0, 1), 0u);
        ASSERT_EQ(w32(0x1800, 1, 0x185), 0u);
    }
};

}  // namespace

TEST_F(EngineFixture, Pmc007SequenceProducesTpdo187) {
    make(/*strict=*/false);
    const auto vec = pmc007_vector();
    // Feed the manual's six SDO writes (expedited download frames) to the engine.
    for (auto& [id, d] : vec.requests) {
        ASSERT_EQ(id, 0x605u);
        const std::uint16_t index = static_cast<std::uint16_t>(d[1] | (d[2] << 8));
        const std::size_t n = 4 - ((d[0] >> 2) & 3);
        EXPECT_EQ(eng->write(index, d[3], std::span<const std::uint8_t>(d.data() + 4, n)), 0u)
            << std::hex << index << ":" << int(d[3]);
    }
    eng->set_operational(true);  // event-driven TPDO goes out on entering OPERATIONAL
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].id, vec.result.first);
    EXPECT_EQ(bytes(out[0]), vec.result.second);
    // Then every 1000 ms by the event timer.
    clock.advance(999'000'000);
    eng->process(clock.now());
    EXPECT_EQ(out.size(), 1u);
    clock.advance(1'000'000);
    eng->process(clock.now());
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(bytes(out[1]), (Bytes{0x03, 0x00}));
    // A GPIO change goes out at once... but not within 5 ms of the last one (inhibit).
    od.set(0x6012, 0, 0x0001);
    clock.advance(2'000'000);
    eng->notify_change(0x6012, 0);
    EXPECT_EQ(out.size(), 2u);
    clock.advance(3'000'000);
    eng->process(clock.now());
    ASSERT_EQ(out.size(), 3u);
    EXPECT_EQ(bytes(out[2]), (Bytes{0x01, 0x00}));
}

TEST_F(EngineFixture, Pmc007SequenceRejectedByStrictEngine) {
    make(/*strict=*/true);
    // TPDO1 is valid at 0x185 by default: CiA 301 forbids changing it while valid.
    EXPECT_EQ(w32(0x1800, 1, 0x187), pdo_abort::kInvalidValue);
}

TEST_F(EngineFixture, P7_MappingTooLongUnmappableSub0TooHigh) {
    make();
    ASSERT_EQ(w32(0x1800, 1, 0x80000185), 0u);
    ASSERT_EQ(w8(0x1A00, 0, 0), 0u);
    EXPECT_EQ(w32(0x1A00, 1, 0x10000020), pdo_abort::kNotMappable);   // 0x1000 not mappable
    EXPECT_EQ(w32(0x1A00, 1, 0x60400010), pdo_abort::kNotMappable);   // RPDO-only object in a TPDO
    EXPECT_EQ(w32(0x1A00, 1, 0x60410020), pdo_abort::kNotMappable);   // wrong length
    EXPECT_EQ(w32(0x1A00, 1, 0x00020008), pdo_abort::kNotMappable);   // dummy in a TPDO
    EXPECT_EQ(w32(0x1A00, 1, 0x99990010), pdo_abort::kNoObject);
    EXPECT_EQ(w8(0x1A00, 0, 9), pdo_abort::kMappingTooLong);           // sub0 > max (8)
    for (std::uint8_t i = 1; i <= 3; ++i) ASSERT_EQ(w32(0x1A00, i, 0x60640020), 0u);
    EXPECT_EQ(w8(0x1A00, 0, 3), pdo_abort::kMappingTooLong);           // 96 bits
    EXPECT_EQ(w8(0x1A00, 0, 2), 0u);                                   // 64 bits is fine
    Bytes r;
    ASSERT_EQ(eng->read(0x1A00, 0, r), 0u);
    EXPECT_EQ(r, Bytes{2});
    EXPECT_EQ(eng->write(0x1A00, 1, Bytes{1, 2}), pdo_abort::kLengthTooLow);
    EXPECT_EQ(eng->write(0x1A00, 9, Bytes{0, 0, 0, 0}), pdo_abort::kNoSubIndex);
}

TEST_F(EngineFixture, P8_MappingChangeWhileValid) {
    make();
    map_tpdo1(255);
    EXPECT_EQ(w8(0x1A00, 0, 0), pdo_abort::kUnsupportedAccess);
    EXPECT_EQ(w32(0x1A00, 1, 0x60640020), pdo_abort::kUnsupportedAccess);
    // Disabled but sub0 != 0: entries still locked.
    ASSERT_EQ(w32(0x1800, 1, 0x80000185), 0u);
    EXPECT_EQ(w32(0x1A00, 1, 0x60640020), pdo_abort::kUnsupportedAccess);
    ASSERT_EQ(w8(0x1A00, 0, 0), 0u);
    EXPECT_EQ(w32(0x1A00, 1, 0x60640020), 0u);
    EXPECT_EQ(w8(0x1A00, 0, 1), 0u);
    EXPECT_EQ(eng->mapping(true, 1), (std::vector<PdoMapEntry>{{0x6064, 0, 32}}));
}

TEST_F(EngineFixture, P9_CobIdRestrictedReservedOrChangedWhileValid) {
    make();
    ASSERT_EQ(w32(0x1800, 1, 0x80000185), 0u);
    for (std::uint32_t id : {0x000u, 0x07Fu, 0x101u, 0x180u, 0x581u, 0x5FFu, 0x601u, 0x67Fu, 0x6E0u, 0x6FFu,
                             0x701u, 0x7FFu})
        EXPECT_EQ(w32(0x1800, 1, id), pdo_abort::kInvalidValue) << std::hex << id;
    EXPECT_EQ(w32(0x1800, 1, 0x00000985), pdo_abort::kInvalidValue);  // bits 11-28 without bit 29
    EXPECT_EQ(w32(0x1800, 1, 0x80000701), 0u);  // restricted but invalid: allowed
    EXPECT_EQ(w32(0x1800, 1, 0x80000185), 0u);
    EXPECT_EQ(w32(0x1800, 1, 0x185), 0u);
    EXPECT_EQ(w32(0x1800, 1, 0x186), pdo_abort::kInvalidValue);  // change while valid
    EXPECT_EQ(w32(0x1800, 1, 0x185), 0u);                         // same value: fine
    EXPECT_EQ(w32(0x1800, 1, 0x20012345), pdo_abort::kInvalidValue);  // 29-bit change while valid
    EXPECT_EQ(eng->cob_id(true, 1), 0x185u);
}

TEST_F(EngineFixture, P10_TransmissionType241To253) {
    make();
    for (int t = 241; t <= 253; ++t) {
        EXPECT_EQ(w8(0x1800, 2, static_cast<std::uint8_t>(t)), pdo_abort::kInvalidValue) << t;
        EXPECT_EQ(w8(0x1400, 2, static_cast<std::uint8_t>(t)), pdo_abort::kInvalidValue) << t;
    }
    for (int t : {0, 1, 240, 254, 255}) EXPECT_EQ(w8(0x1800, 2, static_cast<std::uint8_t>(t)), 0u) << t;
}

TEST_F(EngineFixture, P1_ShortRpdoNotAppliedEmcyOnceClearedByGoodFrame) {
    make();
    map_rpdo1();
    eng->set_operational(true);
    EXPECT_TRUE(eng->on_frame(frame(0x205, {0x0F, 0x00, 0x10})));
    EXPECT_TRUE(eng->on_frame(frame(0x205, {})));
    EXPECT_EQ(od.get(0x6040, 0), 0u);
    ASSERT_EQ(emcy.size(), 1u);
    EXPECT_EQ(emcy[0], std::make_pair(std::uint16_t(0x8210), true));
    eng->on_frame(frame(0x205, {0x0F, 0x00, 0x10, 0x27, 0x00, 0x00}));
    EXPECT_EQ(od.get(0x6040, 0), 0x000Fu);
    EXPECT_EQ(od.get(0x607A, 0), 10000u);
    ASSERT_EQ(emcy.size(), 2u);
    EXPECT_EQ(emcy[1], std::make_pair(std::uint16_t(0x8210), false));
    EXPECT_EQ(eng->counters().rpdo_length_errors, 2u);
}

TEST_F(EngineFixture, P2_LongRpdoAppliedWithEmcy) {
    make();
    map_rpdo1();
    eng->set_operational(true);
    eng->on_frame(frame(0x205, {0x06, 0x00, 0x01, 0x00, 0x00, 0x00, 0xEE, 0xEE}));
    EXPECT_EQ(od.get(0x6040, 0), 6u);
    EXPECT_EQ(od.get(0x607A, 0), 1u);
    ASSERT_EQ(emcy.size(), 1u);
    EXPECT_EQ(emcy[0].first, 0x8220);
}

TEST_F(EngineFixture, P3_RpdoIgnoredWhenNotOperational) {
    make();
    map_rpdo1();
    eng->on_frame(frame(0x205, {0x0F, 0x00, 0x10, 0x27, 0x00, 0x00}));
    EXPECT_EQ(od.get(0x6040, 0), 0u);
    EXPECT_EQ(eng->counters().rpdo_ignored, 1u);
    eng->set_operational(true);
    eng->on_frame(frame(0x205, {0x0F, 0x00, 0x10, 0x27, 0x00, 0x00}));
    EXPECT_EQ(od.get(0x6040, 0), 0x0Fu);
}

TEST_F(EngineFixture, P5_SyncRpdoOutsideWindowDiscarded) {
    make(true, 1000 /* us */);
    map_rpdo1(1);
    eng->set_operational(true);
    eng->on_frame(frame(0x080, {}));
    clock.advance(500'000);  // inside the window
    eng->on_frame(frame(0x205, {0x06, 0x00, 0x01, 0x00, 0x00, 0x00}));
    EXPECT_EQ(od.get(0x6040, 0), 0u);  // synchronous: applied at the next SYNC
    clock.advance(9'500'000);
    eng->on_frame(frame(0x080, {}));
    EXPECT_EQ(od.get(0x6040, 0), 6u);
    clock.advance(2'000'000);  // 2 ms after SYNC: outside the 1 ms window
    eng->on_frame(frame(0x205, {0x07, 0x00, 0x02, 0x00, 0x00, 0x00}));
    clock.advance(8'000'000);
    eng->on_frame(frame(0x080, {}));
    EXPECT_EQ(od.get(0x6040, 0), 6u);
    EXPECT_EQ(eng->counters().rpdo_ignored, 1u);
}

TEST_F(EngineFixture, P6_RtrOnRpdoIgnored) {
    make();
    map_rpdo1();
    eng->set_operational(true);
    EXPECT_TRUE(eng->on_frame(frame(0x205, {}, true)));
    EXPECT_EQ(eng->counters().rtr_ignored, 1u);
    EXPECT_TRUE(out.empty());
    EXPECT_TRUE(emcy.empty());
}

TEST_F(EngineFixture, P11_RpdoEventTimerExpiry) {
    make();
    map_rpdo1();
    ASSERT_EQ(w16(0x1400, 5, 100), 0u);
    std::vector<unsigned> timeouts;
    eng->on_rpdo_timeout = [&](unsigned n) { timeouts.push_back(n); };
    eng->set_operational(true);
    eng->process(clock.now());
    clock.advance(1'000'000'000);
    eng->process(clock.now());
    EXPECT_TRUE(timeouts.empty());  // the timer starts with the first RPDO
    eng->on_frame(frame(0x205, {0x0F, 0x00, 0x10, 0x27, 0x00, 0x00}));
    clock.advance(99'000'000);
    eng->process(clock.now());
    EXPECT_TRUE(timeouts.empty());
    clock.advance(1'000'000);
    eng->process(clock.now());
    ASSERT_EQ(timeouts, std::vector<unsigned>{1});
    ASSERT_EQ(emcy.size(), 1u);
    EXPECT_EQ(emcy[0], std::make_pair(std::uint16_t(0x8250), true));
    clock.advance(1'000'000'000);
    eng->process(clock.now());
    EXPECT_EQ(timeouts.size(), 1u);  // once per loss
}

TEST_F(EngineFixture, P12_TpdoEventStormRespectsInhibit) {
    make();
    map_tpdo1(255, 100 /* 10 ms */);
    eng->set_operational(true);
    ASSERT_EQ(out.size(), 1u);
    for (int i = 0; i < 1000; ++i) {
        clock.advance(100'000);  // 0.1 ms
        od.set(0x6041, 0, static_cast<std::uint64_t>(i));
        eng->notify_change(0x6041, 0);
    }
    // 100 ms of changes at 10 kHz: at most one frame per 10 ms.
    EXPECT_EQ(out.size(), 11u);
    for (std::size_t i = 2; i < out.size(); ++i) EXPECT_EQ(out[i].id, 0x185u);
    EXPECT_EQ(eng->counters().tpdo_sent, 11u);
}

TEST_F(EngineFixture, SyncTypesCyclicAcyclicAndRtr) {
    make();
    map_tpdo1(3);
    eng->set_operational(true);
    EXPECT_TRUE(out.empty());
    for (int i = 0; i < 7; ++i) eng->on_frame(frame(0x080, {}));
    EXPECT_EQ(out.size(), 2u);  // every 3rd SYNC
    // RTR on the TPDO: answered.
    eng->on_frame(frame(0x185, {}, true));
    EXPECT_EQ(out.size(), 3u);
    EXPECT_EQ(bytes(out.back()), (Bytes{0x37, 0x02}));
    // With bit 30 (no RTR) set, RTRs are ignored.
    ASSERT_EQ(w32(0x1800, 1, 0xC0000185), 0u);
    ASSERT_EQ(w32(0x1800, 1, 0x40000185), 0u);
    eng->on_frame(frame(0x185, {}, true));
    EXPECT_EQ(out.size(), 3u);
    // Acyclic synchronous: only after a change, at the SYNC.
    ASSERT_EQ(w32(0x1800, 1, 0xC0000185), 0u);
    ASSERT_EQ(w8(0x1800, 2, 0), 0u);
    ASSERT_EQ(w32(0x1800, 1, 0x40000185), 0u);
    eng->on_frame(frame(0x080, {}));
    EXPECT_EQ(out.size(), 3u);
    eng->notify_change(0x6041, 0);
    EXPECT_EQ(out.size(), 3u);
    eng->on_frame(frame(0x080, {}));
    EXPECT_EQ(out.size(), 4u);
}

TEST_F(EngineFixture, N15_FrameOnOwnTpdoIdIsCollision) {
    make();
    map_tpdo1(255);
    eng->set_operational(true);
    eng->on_frame(frame(0x185, {0x01, 0x02}));
    eng->on_frame(frame(0x185, {0x01, 0x02}));
    ASSERT_EQ(emcy.size(), 1u);
    EXPECT_EQ(emcy[0], std::make_pair(std::uint16_t(0x8150), true));
    EXPECT_EQ(eng->counters().collisions, 2u);
}

TEST_F(EngineFixture, N16_BadSyncLengthEmcyAndCounterIgnored) {
    make();
    map_tpdo1(1);
    eng->set_operational(true);
    eng->on_frame(frame(0x080, {1, 2}));
    eng->on_frame(frame(0x080, {1, 2, 3}));
    ASSERT_EQ(emcy.size(), 1u);
    EXPECT_EQ(emcy[0], std::make_pair(std::uint16_t(0x8240), true));
    EXPECT_TRUE(out.empty());
    eng->on_frame(frame(0x080, {}));  // a good SYNC clears it and triggers the TPDO
    EXPECT_EQ(out.size(), 1u);
    EXPECT_EQ(emcy.back(), std::make_pair(std::uint16_t(0x8240), false));
}

TEST(PdoHost, ReceiverAndSenderOverBus) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    auto dev = hub.open("dev");
    PdoReceiver rx(*host, 0x185, {{0x6041, 0, 16}, {0x6064, 0, 32}});
    std::vector<std::uint64_t> got;
    rx.on_receive = [&](const std::vector<std::uint64_t>& v, Nanos) { got = v; };
    dev->send(frame(0x185, {0x37, 0x06, 0x10}));  // short: counted, not delivered
    EXPECT_EQ(rx.short_frames(), 1u);
    EXPECT_FALSE(rx.value(0x6041, 0));
    dev->send(frame(0x185, {0x37, 0x06, 0x10, 0x27, 0x00, 0x00}));
    EXPECT_EQ(got, (std::vector<std::uint64_t>{0x0637, 10000}));
    EXPECT_EQ(rx.value(0x6064, 0), 10000u);
    EXPECT_EQ(rx.received(), 1u);
    rx.request();
    EXPECT_TRUE(hub.log.back().rtr);
    EXPECT_EQ(hub.log.back().len, 6);
    PdoSender tx(*host, 0x205, {{0x6040, 0, 16}, {0x607A, 0, 32}});
    std::uint64_t v[] = {0x0F, 0xFFFFFFFF};
    tx.send(v);
    EXPECT_EQ(bytes(hub.log.back()), (Bytes{0x0F, 0x00, 0xFF, 0xFF, 0xFF, 0xFF}));
    EXPECT_THROW(tx.send(std::span<const std::uint64_t>(v, 1)), InvalidArgument);
}

#include "motorbus/canopen/cia402.hpp"

TEST_F(EngineFixture, P11_D5_RpdoTimeoutAppliesLossOfMasterReaction) {
    make();
    map_rpdo1();
    ASSERT_EQ(w16(0x1400, 5, 50), 0u);
    Cia402Device drive;
    ASSERT_EQ(drive.set_abort_connection_option(2), 0u);  // 0x6007 = 2: disable voltage
    drive.on_controlword(0x06);
    drive.on_controlword(0x0F);
    eng->on_rpdo_timeout = [&](unsigned) { drive.loss_of_master(); };
    eng->set_operational(true);
    eng->on_frame(frame(0x205, {0x0F, 0x00, 0x00, 0x00, 0x00, 0x00}));
    clock.advance(49'000'000);
    eng->process(clock.now());
    EXPECT_EQ(drive.state(), Cia402State::OperationEnabled);
    clock.advance(1'000'000);
    eng->process(clock.now());
    EXPECT_EQ(drive.state(), Cia402State::SwitchOnDisabled);
    EXPECT_EQ(emcy.back(), std::make_pair(std::uint16_t(0x8250), true));
}

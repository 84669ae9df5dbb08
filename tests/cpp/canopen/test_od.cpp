// Object dictionary, data types and the abort code table.
#include <gtest/gtest.h>

#include <thread>

#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/od.hpp"
#include "motorbus/canopen/sdo_codec.hpp"
#include "test_sdo_util.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using motorbus::test::H;
using motorbus::test::hex;

TEST(DataTypes, EncodeDecodeRanges) {
    EXPECT_EQ(hex(*encode_scalar(DataType::Integer16, std::int64_t{-2})), "FE FF");
    EXPECT_EQ(std::get<std::int64_t>(*decode_scalar(DataType::Integer24, H("FF FF FF"))), -1);
    EXPECT_EQ(std::get<std::uint64_t>(*decode_scalar(DataType::Unsigned24, H("FF FF FF"))), 0xFFFFFFu);
    EXPECT_FALSE(encode_scalar(DataType::Unsigned8, std::int64_t{256}));
    EXPECT_FALSE(encode_scalar(DataType::Unsigned8, std::int64_t{-1}));
    EXPECT_FALSE(encode_scalar(DataType::Integer8, std::int64_t{128}));
    EXPECT_TRUE(encode_scalar(DataType::Integer8, std::int64_t{-128}));
    EXPECT_FALSE(encode_scalar(DataType::Boolean, std::uint64_t{2}));
    EXPECT_EQ(hex(*encode_scalar(DataType::Real32, 1.5)), "00 00 C0 3F");
    EXPECT_EQ(std::get<double>(*decode_scalar(DataType::Real64, *encode_scalar(DataType::Real64, -0.25))), -0.25);
    EXPECT_FALSE(decode_scalar(DataType::Unsigned32, H("01 02")));  // wrong size
    EXPECT_EQ(hex(*encode_scalar(DataType::Unsigned64, std::uint64_t{~0ull})), "FF FF FF FF FF FF FF FF");
    EXPECT_EQ(compare_scalars(std::int64_t{-1}, std::uint64_t{0}), -1);
    EXPECT_EQ(compare_scalars(std::uint64_t{~0ull}, std::int64_t{5}), 1);
    EXPECT_EQ(type_size(DataType::VisibleString), 0u);
    EXPECT_STREQ(type_name(DataType::Unsigned32), "UNSIGNED32");
}

TEST(AbortCodes, CiaTableWithPmc007Corrections) {
    EXPECT_STREQ(abort_text(0x05040004), "CRC error (block mode only)");
    EXPECT_STREQ(abort_text(0x05030004), "CRC error (block mode only)");  // PMC007 misprint
    EXPECT_STREQ(abort_text(0x05030005), "Out of memory");
    EXPECT_STREQ(abort_text(0x06060012), abort_text(0x06070012));        // 0606001x family
    EXPECT_STREQ(abort_text(0x05040000), "SDO protocol timed out");
    EXPECT_EQ(abort_text(0x12345678), nullptr);
    EXPECT_EQ(describe_abort(0x06020000), "0x06020000 Object does not exist in the object dictionary");
    // The table is sorted (binary search) and holds every code of the seed list.
    const auto& t = abort_table();
    for (std::size_t i = 1; i < t.size(); ++i) EXPECT_LT(t[i - 1].code, t[i].code);
    for (std::uint32_t c : {0x05030000u, 0x05040001u, 0x05040002u, 0x05040003u, 0x06010000u,
                            0x06010001u, 0x06010002u, 0x06040041u, 0x06040042u, 0x06040043u,
                            0x06040047u, 0x06060000u, 0x06070010u, 0x06070013u, 0x06090011u,
                            0x06090030u, 0x06090031u, 0x06090032u, 0x06090036u, 0x08000000u,
                            0x08000020u, 0x08000021u, 0x08000022u, 0x08000023u})
        EXPECT_NE(abort_text(c), nullptr) << std::hex << c;
    SdoAbortError e(0x08000022, 0x6004, 0);
    EXPECT_NE(std::string(e.what()).find("0x6004:00"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("present device state"), std::string::npos);
}

TEST(Codec, Crc16Xmodem) {
    const std::string s = "123456789";
    EXPECT_EQ(sdo::crc16(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size())), 0x31C3);
    EXPECT_EQ(sdo::crc16({}), 0);
}

TEST(Codec, EncodersMatchCia301Layouts) {
    EXPECT_EQ(hex(sdo::initiate_download_expedited({0x6004, 0}, H("80 0C 00 00"))), "23 04 60 00 80 0C 00 00");
    EXPECT_EQ(hex(sdo::initiate_download_segmented({0x1008, 0}, 10)), "21 08 10 00 0A 00 00 00");
    EXPECT_EQ(hex(sdo::initiate_download_segmented({0x1008, 0}, std::nullopt)), "20 08 10 00 00 00 00 00");
    EXPECT_EQ(hex(sdo::download_segment(true, H("01 02 03"), true)), "19 01 02 03 00 00 00 00");
    EXPECT_EQ(hex(sdo::upload_segment(true)), "70 00 00 00 00 00 00 00");
    EXPECT_EQ(hex(sdo::abort_transfer({0x1234, 0x56}, 0x05040000)), "80 34 12 56 00 00 04 05");
    EXPECT_EQ(hex(sdo::block_upload_initiate({0x1008, 0}, true, 127, 0)), "A4 08 10 00 7F 00 00 00");
    EXPECT_EQ(hex(sdo::block_download_initiate({0x1008, 0}, true, 20)), "C6 08 10 00 14 00 00 00");
    EXPECT_EQ(hex(sdo::block_download_end(3, 0xBEEF)), "CD EF BE 00 00 00 00 00");
    EXPECT_EQ(hex(sdo::block_upload_ack(5, 127)), "A2 05 7F 00 00 00 00 00");
    EXPECT_EQ(sdo::abort_code_of(H("80 00 00 00")), 0x08000000u);
    EXPECT_EQ(sdo::describe_request(H("40 01 60 00")), "initiate upload 0x6001:00");
}

TEST(ObjectDictionary, VariablesRecordsAndNames) {
    ObjectDictionary od;
    auto v = od.add_variable({.index = 0x6040, .name = "Controlword", .type = DataType::Unsigned16,
                              .access = Access::RW, .pdo_mappable = true});
    od.add_record(0x1018, "Identity object");
    od.add_member(0x1018, {.subindex = 1, .name = "Vendor-ID", .type = DataType::Unsigned32,
                           .access = Access::RO, .default_value = std::uint64_t{0x1234}});
    od.add_member(0x1018, {.subindex = 3, .name = "Revision", .type = DataType::Unsigned32});
    EXPECT_EQ(od.at(0x1018, 0)->get_u64(), 3u);  // highest sub-index follows the members
    EXPECT_EQ(od.find("Identity object.Vendor-ID")->get_u64(), 0x1234u);
    EXPECT_EQ(od.find("Controlword"), v);
    EXPECT_EQ(od.find("0x6040"), v);
    EXPECT_EQ(od.find("0x1018:1")->name(), "Vendor-ID");
    EXPECT_EQ(od.find("1018sub3")->name(), "Revision");
    EXPECT_EQ(od.find("nope"), nullptr);
    EXPECT_EQ(od.find("0x1018:300"), nullptr);
    EXPECT_THROW(od.at("nope"), InvalidArgument);
    VariablePtr out;
    EXPECT_EQ(od.lookup(0x1018, 2, out), abort_code::kNoSubindex);
    EXPECT_EQ(od.lookup(0x1019, 0, out), abort_code::kNoObject);
    EXPECT_EQ(od.lookup(0x1018, 3, out), 0u);
    EXPECT_THROW(od.add_variable({.index = 0x6040}), InvalidArgument);
    EXPECT_THROW(od.add_member(0x6040, {.subindex = 1}), InvalidArgument);
    EXPECT_EQ(od.indices(), (std::vector<std::uint16_t>{0x1018, 0x6040}));
    EXPECT_TRUE(v->pdo_mappable());
}

TEST(ObjectDictionary, LimitsDefaultsAndValidation) {
    ObjectDictionary od;
    EXPECT_THROW(od.add_variable({.index = 0x2000, .type = DataType::Unsigned8,
                                  .low_limit = std::uint64_t{10}, .high_limit = std::uint64_t{5}}),
                 InvalidArgument);
    EXPECT_THROW(od.add_variable({.index = 0x2001, .type = DataType::Unsigned8,
                                  .default_value = std::int64_t{300}}),
                 InvalidArgument);
    EXPECT_THROW(od.add_variable({.index = 0x2002, .type = DataType::VisibleString,
                                  .low_limit = std::uint64_t{1}}),
                 InvalidArgument);
    auto v = od.add_variable({.index = 0x2003, .type = DataType::Integer16, .low_limit = std::int64_t{-100},
                              .high_limit = std::int64_t{100}, .default_value = std::int64_t{-5}});
    EXPECT_EQ(v->get_i64(), -5);
    EXPECT_THROW(v->set_i64(101), InvalidArgument);
    EXPECT_EQ(v->try_set(H("9B FF")), abort_code::kValueTooLow);  // -101
    EXPECT_EQ(v->try_set(H("01")), abort_code::kTooShort);
    v->set_i64(-100);
    EXPECT_EQ(hex(v->get()), "9C FF");
    v->reset_to_default();
    EXPECT_EQ(v->get_i64(), -5);
    auto b = od.add_variable({.index = 0x2004, .type = DataType::Boolean});
    EXPECT_EQ(b->remote_write(H("02")), abort_code::kInvalidValue);
    auto s = od.add_variable({.index = 0x2005, .type = DataType::VisibleString, .max_size = 4});
    EXPECT_EQ(s->remote_write(H("41 42 43 44 45")), abort_code::kTooLong);
    EXPECT_EQ(s->remote_write(H("41 42")), 0u);
    EXPECT_EQ(s->get_string(), "AB");
}

TEST(ObjectDictionary, HooksAndListeners) {
    ObjectDictionary od;
    auto v = od.add_variable({.index = 0x2000, .type = DataType::Unsigned32});
    int changes = 0;
    auto h = v->add_change_listener([&](const Variable&) { ++changes; });
    v->set_write_hook([](const Variable&, std::span<const std::uint8_t> d) {
        return d[0] == 0xEE ? abort_code::kLocalControl : 0u;
    });
    v->set_read_hook([](const Variable&, Bytes& out) {
        out = {1, 2, 3, 4};
        return 0u;
    });
    EXPECT_EQ(v->remote_write(H("EE 00 00 00")), abort_code::kLocalControl);
    EXPECT_EQ(changes, 0);
    EXPECT_EQ(v->remote_write(H("11 00 00 00")), 0u);
    EXPECT_EQ(changes, 1);
    Bytes out;
    EXPECT_EQ(v->remote_read(out), 0u);
    EXPECT_EQ(hex(out), "01 02 03 04");
    EXPECT_EQ(v->get_u64(), 0x11u);  // the hook changed only what was reported
    v->set_u64(5);  // local writes bypass the hook but tell listeners
    EXPECT_EQ(changes, 2);
    v->remove_change_listener(h);
    v->set_u64(6);
    EXPECT_EQ(changes, 2);
}

TEST(ObjectDictionary, ConcurrentAccessIsSafe) {
    ObjectDictionary od;
    auto v = od.add_variable({.index = 0x2000, .type = DataType::Unsigned64});
    std::vector<std::thread> ts;
    for (int t = 0; t < 4; ++t)
        ts.emplace_back([&, t] {
            for (int i = 0; i < 10000; ++i) {
                if (t % 2) v->set_u64(0x0101010101010101ull * static_cast<std::uint64_t>(i & 0xFF));
                else {
                    auto b = v->get();
                    ASSERT_EQ(b.size(), 8u);
                    for (auto x : b) ASSERT_EQ(x, b[0]);  // never torn
                }
            }
        });
    for (auto& t : ts) t.join();
}

// VariableSpec::alt_size: a second size a remote write may carry, narrowed to the type.
TEST(ObjectDictionary, AltSizeRemoteWrite) {
    ObjectDictionary od;
    auto v = od.add_variable({.index = 0x6020, .name = "Stop", .type = DataType::Unsigned8,
                              .default_value = std::uint64_t{0}, .alt_size = 4});
    std::uint8_t four[4] = {0x02, 0, 0, 0};
    EXPECT_EQ(v->remote_write(std::span(four, 4)), 0u);
    EXPECT_EQ(v->get(), (Bytes{0x02}));
    std::uint8_t big[4] = {0x02, 0, 1, 0};
    EXPECT_EQ(v->remote_write(std::span(big, 4)), abort_code::kValueTooHigh);
    std::uint8_t two[2] = {1, 0};
    EXPECT_EQ(v->remote_write(std::span(two, 2)), abort_code::kTooLong);  // only the one extra size
    EXPECT_EQ(v->check_size_for_write(4), 0u);
}

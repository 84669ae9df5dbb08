// UNITEK codec and register table against the 002 manual (worked examples, §4-§6).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "motorbus/drives/unitek/codec.hpp"

using namespace motorbus;
using namespace motorbus::unitek;
using Bytes = std::vector<std::uint8_t>;

TEST(UnitekCodec, WorkedExamplesToTheDrive) {
    const auto t = RegisterTable::builtin();
    EXPECT_EQ(encode_write(t.at(kRegRxId), 0x210), (Bytes{0x68, 0x10, 0x02}));          // ex 1
    EXPECT_EQ(encode_write(t.at(kRegMode), 0x0004), (Bytes{0x51, 0x04, 0x00}));         // ex 2
    EXPECT_EQ(encode_write(t.at(kRegSpeedCmd), 3277), (Bytes{0x31, 0xCD, 0x0C}));       // ex 3
    EXPECT_EQ(encode_write(t.at(kRegPosDest), 3000000), (Bytes{0x6E, 0xC0, 0xC6, 0x2D, 0x00}));  // ex 4, DLC 5
    EXPECT_EQ(encode_write(t.at(kRegPosDest), 300010000), (Bytes{0x6E, 0x10, 0xCA, 0xE1, 0x11}));  // §4.8
    EXPECT_EQ(encode_write(t.at(kRegTorqueCmd), 16380), (Bytes{0x90, 0xFC, 0x3F}));     // ex 5
    EXPECT_EQ(encode_write(t.at(kRegAccRamp), 1000), (Bytes{0x35, 0xE8, 0x03}));        // ex 6 corrected
    EXPECT_EQ(encode_write(t.at(kRegEeprom), 0), (Bytes{0x84, 0x00, 0x00}));            // ex 7
    EXPECT_EQ(encode_write(t.at(kRegEeprom), 1), (Bytes{0x84, 0x01, 0x00}));
    EXPECT_EQ(encode_write(t.at(kRegMode), 0x0010), (Bytes{0x51, 0x10, 0x00}));         // ex 10
    EXPECT_EQ(encode_write(t.at(kRegEventMask), 0x0012), (Bytes{0x52, 0x12, 0x00}));    // ex 10-1
    EXPECT_EQ(encode_request(kRegStatus, kIntervalOnce), (Bytes{0x3D, 0x40, 0x00}));    // ex 8
    EXPECT_EQ(encode_cyclic(kRegSpeedActual, 100), (Bytes{0x3D, 0x30, 0x64}));          // ex 9
    EXPECT_EQ(encode_request(kRegSpeedActual, kIntervalStop), (Bytes{0x3D, 0x30, 0xFF}));
    EXPECT_EQ(encode_request(kRegA8, 0), (Bytes{0x3D, 0xA8, 0x00}));                    // §5.2 item 1
    EXPECT_EQ(encode_cyclic(kRegA8, 10), (Bytes{0x3D, 0xA8, 0x0A}));                    // §5.2 item 2
}

TEST(UnitekCodec, FramesFromTheDrive) {
    auto f = decode_from_drive(Bytes{0x40, 0x81, 0x01, 0x5A});  // ex 8: dummy ignored
    EXPECT_EQ(f.regid, 0x40);
    EXPECT_EQ(f.value, 0x0181u);
    EXPECT_EQ(f.value_bits, 16);
    f = decode_from_drive(Bytes{0x40, 0x85, 0x31, 0x00, 0x00, 0xEE});  // ex 10-1
    EXPECT_EQ(f.value, 0x3185u);
    EXPECT_EQ(f.value_bits, 32);
    const auto t = RegisterTable::builtin();
    EXPECT_EQ(t.at(kRegSpeedActual).from_raw(0x7FFF, 16), 32767);  // ex 9
    EXPECT_EQ(t.at(kRegSpeedActual).from_raw(0x8001, 16), -32767);  // B-U14 sign extension
    EXPECT_EQ(t.at(kRegPosDest).from_raw(0xFFFFFFFF, 32), -1);
    EXPECT_EQ(t.at(kRegPosDest).from_raw(0xFFFF, 16), -1);          // B-U03: DLC 3 into a 32-bit signed register
    EXPECT_EQ(encode_reply(0x40, 0x0181, 16), (Bytes{0x40, 0x81, 0x01, 0x00}));
    EXPECT_EQ(encode_reply(0x40, 0x3181, 32), (Bytes{0x40, 0x81, 0x31, 0x00, 0x00, 0x00}));
}

TEST(UnitekCodec, WrongDlcFromTheDriveNamesTheByte) {  // R1, client side
    for (std::size_t n : {0u, 1u, 2u, 3u, 5u, 7u, 8u}) {
        Bytes b(n, 0x30);
        try {
            decode_from_drive(b);
            FAIL() << "DLC " << n << " accepted";
        } catch (const FrameError& e) {
            EXPECT_EQ(e.bytes, b);
            EXPECT_EQ(e.byte, n < 4 ? static_cast<int>(n) : (n == 5 ? 5 : 6)) << n;
            EXPECT_NE(std::string(e.what()).find("byte"), std::string::npos);
        }
    }
}

TEST(UnitekCodec, DlcRulesToTheDrive) {  // R1, drive side: B-U02, B-U03
    for (std::size_t n : {0u, 1u, 2u}) {
        try {
            decode_to_drive(Bytes(n, 0x31));
            FAIL();
        } catch (const FrameError& e) {
            EXPECT_EQ(e.byte, static_cast<int>(n));
        }
    }
    auto t = decode_to_drive(Bytes{0x31, 0xCD, 0x0C, 0x77});  // DLC 4 = DLC 3
    EXPECT_EQ(t.value, 0x0CCDu);
    EXPECT_EQ(t.value_bits, 16);
    t = decode_to_drive(Bytes{0x6E, 0xC0, 0xC6, 0x2D, 0x00, 0x11, 0x22, 0x33});  // DLC 8 = DLC 5
    EXPECT_EQ(t.value, 3000000u);
    EXPECT_EQ(t.value_bits, 32);
    t = decode_to_drive(Bytes{0x3D, 0x30, 0x64});
    EXPECT_TRUE(t.is_request());
    EXPECT_EQ(t.request_regid(), 0x30);
    EXPECT_EQ(t.request_interval(), 100);
    EXPECT_THROW(decode_to_drive(Bytes(9, 0)), FrameError);
}

TEST(UnitekCodec, ChecksBeforeSending) {  // R2, R3
    const auto t = RegisterTable::builtin();
    EXPECT_THROW(t.at(0x99), UnknownRegister);
    EXPECT_THROW(encode_write(t.at(kRegSpeedActual), 1), InvalidArgument);     // read-only
    EXPECT_THROW(encode_write(t.at(kRegStatus), 1), InvalidArgument);
    EXPECT_THROW(encode_write(t.at(kRegSpeedCmd), 32768), InvalidArgument);    // range
    EXPECT_THROW(encode_write(t.at(kRegSpeedCmd), -32768), InvalidArgument);
    EXPECT_THROW(encode_write(t.at(kRegRxId), 0x280), InvalidArgument);
    EXPECT_THROW(encode_write(t.at(kRegEeprom), 2), InvalidArgument);
    EXPECT_THROW(encode_write(0x31, 70000, 16), InvalidArgument);
    EXPECT_THROW(encode_cyclic(0x30, 0), InvalidArgument);
    EXPECT_THROW(encode_cyclic(0x30, 255), InvalidArgument);
    EXPECT_EQ(encode_write(0x31, -1, 16), (Bytes{0x31, 0xFF, 0xFF}));
}

TEST(UnitekCodec, TableIsDataAndExtendable) {
    auto t = RegisterTable::builtin();
    EXPECT_EQ(t.size(), 11u);  // the 12 REGIDs less 0x3D, which is the request itself
    EXPECT_EQ(t.at("pos_dest").regid, kRegPosDest);
    Register r;
    r.regid = 0x34;
    r.name = "SPEED_LIM";
    r.bits = 16;
    r.is_signed = true;
    r.quantity = Quantity::Speed;
    t.add(r);
    EXPECT_EQ(t.at(0x34).name, "SPEED_LIM");
    r.regid = kRegRead;
    EXPECT_THROW(t.add(r), InvalidArgument);
    r.regid = 0x35;
    r.bits = 24;
    EXPECT_THROW(t.add(r), InvalidArgument);
}

TEST(UnitekCodec, Scalings) {  // §6.1, B-U15..B-U18
    Scalings s;
    s.n_max_rpm = 2000;
    const auto t = RegisterTable::builtin();
    EXPECT_EQ(s.to_num(t.at(kRegSpeedCmd), 1500), 24575);  // E-U18
    EXPECT_EQ(s.to_num(t.at(kRegSpeedCmd), 2000), 32767);
    EXPECT_EQ(s.to_num(t.at(kRegPosDest), 200), 13107200);  // E-U20: 1000 mm at 5 mm/rev
    EXPECT_DOUBLE_EQ(s.to_physical(t.at(kRegPosDest), 65536), 1.0);
    EXPECT_EQ(s.to_num(t.at(kRegTorqueCmd), 50), 16384);  // ex 5's 16380 is "about 50 %"
    EXPECT_NEAR(s.to_physical(t.at(kRegTorqueCmd), 16380), 49.99, 0.01);
    EXPECT_EQ(continuous_current_num(device_currents()[0], 2), 44);  // E-U19
    // 10 V analog = 90 % of 32767 (B-U18).
    EXPECT_EQ(static_cast<int>(32767 * 0.9), 29490);
    EXPECT_EQ(65536 / 4096, 16);      // 12-bit resolver resolution
    EXPECT_EQ(65536 / (4 * 2048), 8);  // 2048-line encoder
}

TEST(UnitekCodec, EventMaskTable) {  // C-U01
    EXPECT_EQ(event_status_mask(0x0030), kStatusCal | kStatusTol);
    EXPECT_EQ(event_status_mask(0x0012), kStatusLimPlus | kStatusLimMinus);
    EXPECT_EQ(event_status_mask(0x0020), kStatusIcns);
    EXPECT_EQ(event_status_mask(0x0101), 0x0101u);
}

TEST(UnitekCodec, BitTimingTable) {  // §3.1, C-U08
    const auto t = bit_timings();
    ASSERT_EQ(t.size(), 5u);
    EXPECT_EQ(bit_timing_for_btr(0x4002).kbit_s, 1000);
    EXPECT_EQ(bit_timing_for_btr(0x4025).max_line_m, 70);
    EXPECT_EQ(bit_timing_for_btr(0x4014).kbit_s, 625);
    EXPECT_EQ(bit_timing_for_bit_rate(250000).btr, 0x405C);
    EXPECT_EQ(bit_timing_for_bit_rate(100000).max_line_m, 500);
    EXPECT_EQ(kDefaultBtr, 0x4025);
    EXPECT_THROW(bit_timing_for_btr(0x4026), InvalidArgument);
    EXPECT_THROW(bit_timing_for_bit_rate(615000), InvalidArgument);  // "Labod 615 kB/s": not a row
}

TEST(UnitekCodec, SmallerOfMotorAndDeviceCurrentLimit) {  // §6.1
    const auto& ds205 = device_current("DS 205/405");
    EXPECT_EQ(effective_current_limit_num(ds205, 500), 160);
    EXPECT_EQ(effective_current_limit_num(ds205, 44), 44);
    EXPECT_EQ(effective_current_limit_num(device_current("DS 420"), 511), 200);
    EXPECT_THROW(effective_current_limit_num(ds205, -1), InvalidArgument);
    EXPECT_THROW(device_current("DS 999"), InvalidArgument);
    EXPECT_EQ(kCurrentCommandMax, 511);
}

TEST(UnitekCodec, AnalogCommandTenVoltsIs29490) {  // §6.1, B-U18
    EXPECT_EQ(analog_command_num(10.0), 29490);
    EXPECT_EQ(analog_command_num(-10.0), -29490);
    EXPECT_EQ(analog_command_num(1.0), 2949);
    EXPECT_THROW(analog_command_num(10.01), InvalidArgument);
    EXPECT_THROW(analog_command_num(std::nan("")), InvalidArgument);
}

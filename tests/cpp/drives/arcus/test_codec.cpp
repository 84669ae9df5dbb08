#include <gtest/gtest.h>

#include "motorbus/drives/arcus/codec.hpp"

using namespace motorbus;
using namespace motorbus::arcus;

TEST(ArcusCodec, BuildsRequestsByteForByte) {
    EXPECT_EQ(build_query(1, "EX"), "@01EX\r");
    EXPECT_EQ(build_action(1, "J+"), "@01J+\r");
    EXPECT_EQ(build_action(0, "ABORT"), "@00ABORT\r");
    EXPECT_EQ(build_set(12, "HSPD", 20000), "@12HSPD=20000\r");
    EXPECT_EQ(build_argument(99, "X", -1000), "@99X-1000\r");
    EXPECT_EQ(build_argument(1, "SSPD", 5000), "@01SSPD5000\r");
    EXPECT_EQ(format_command(7, "MST"), "@07MST");
}

TEST(ArcusCodec, RefusesBadRequests) {
    EXPECT_THROW(build_query(100, "EX"), InvalidArgument);
    EXPECT_THROW(build_query(-1, "EX"), InvalidArgument);
    EXPECT_THROW(build_query(1, ""), InvalidArgument);
    EXPECT_THROW(build_query(1, "EX\r@02ABORT"), InvalidArgument);  // no smuggled second command
    EXPECT_THROW(build_query(1, std::string(65, 'A')), InvalidArgument);
    EXPECT_THROW(build_query(1, std::string("E\0X", 3)), InvalidArgument);
}

TEST(ArcusCodec, TableHasEveryCommandOfTable11AndTheSections) {
    for (auto name : {"ABORT", "ABS", "ACC", "BR", "CLR", "CM", "CUR", "CURI", "CURR", "CURT", "DB", "DEC", "DI",
                      "DN", "DO", "DOBOOT", "DX", "EDEC", "EDO", "EO", "EOBOOT", "EX", "H+", "H-", "HL+", "HL-",
                      "HSPD", "ID", "INC", "J+", "J-", "L+", "L-", "LCA", "LSPD", "LT", "LTE", "LTP", "LTS", "MM",
                      "MST", "NID", "POL", "PS", "PX", "RT", "SCV", "SL", "SLA", "SLE", "SLS", "SLT", "STORE",
                      "SSPD", "SSPDM", "STOP", "VER", "X", "Z+", "Z-", "ZH+", "ZH-",
                      // described outside Table 11.0
                      "T", "SYNO", "SYNF", "SYNP", "SYNC", "SYNS", "HCA", "RZ", "CLRS", "SLM"}) {
        EXPECT_NE(find_command(name), nullptr) << name;
    }
    EXPECT_EQ(find_command("FOO"), nullptr);
    EXPECT_EQ(find_command("ex"), nullptr);  // case sensitive
}

TEST(ArcusCodec, ParsesCommandForms) {
    auto q = parse_command("HSPD");
    ASSERT_TRUE(q);
    EXPECT_EQ(q->info->name, "HSPD");
    EXPECT_EQ(q->op, ParsedCommand::Op::Query);

    auto s = parse_command("HSPD=20000");
    ASSERT_TRUE(s);
    EXPECT_EQ(s->op, ParsedCommand::Op::Set);
    EXPECT_EQ(*s->value, 20000);

    auto x = parse_command("X-500");
    ASSERT_TRUE(x);
    EXPECT_EQ(x->info->name, "X");
    EXPECT_EQ(x->op, ParsedCommand::Op::Argument);
    EXPECT_EQ(*x->value, -500);

    auto sspd = parse_command("SSPD5000");
    ASSERT_TRUE(sspd);
    EXPECT_EQ(sspd->info->name, "SSPD");
    EXPECT_EQ(*sspd->value, 5000);
    EXPECT_EQ(parse_command("SSPDM")->info->name, "SSPDM");

    auto di = parse_command("DI3");
    ASSERT_TRUE(di);
    EXPECT_EQ(di->info->name, "DI");
    EXPECT_EQ(di->index, 3);
    EXPECT_TRUE(di->index_valid);
    EXPECT_FALSE(parse_command("DI7")->index_valid);
    EXPECT_FALSE(parse_command("DO0")->index_valid);
    auto do2 = parse_command("DO2=1");
    ASSERT_TRUE(do2);
    EXPECT_EQ(do2->op, ParsedCommand::Op::Set);
    EXPECT_EQ(do2->index, 2);
    EXPECT_EQ(parse_command("DOBOOT")->info->name, "DOBOOT");
    EXPECT_EQ(parse_command("ZH+")->info->name, "ZH+");
    EXPECT_EQ(parse_command("HL-")->info->name, "HL-");
    EXPECT_EQ(parse_command("SLS")->info->name, "SLS");

    EXPECT_FALSE(parse_command("FOO"));
    EXPECT_FALSE(parse_command("X"));       // needs a value
    EXPECT_FALSE(parse_command("MST=5"));   // read only
    EXPECT_FALSE(parse_command("DI1=1"));   // inputs are read only
    EXPECT_FALSE(parse_command("ex"));
    // A value that is not a number is parsed but carries no value: the sim answers "?".
    EXPECT_FALSE(parse_command("HSPD=1e3")->value);
}

TEST(ArcusCodec, ParsesBothReplyFormats) {
    auto r0 = parse_reply("1000");
    EXPECT_FALSE(r0.address);
    EXPECT_EQ(r0.body, "1000");
    auto r1 = parse_reply("#011000");
    ASSERT_TRUE(r1.address);
    EXPECT_EQ(*r1.address, 1);
    EXPECT_EQ(r1.body, "1000");
    EXPECT_EQ(parse_reply("#99OK").body, "OK");
    EXPECT_THROW(parse_reply(""), ProtocolError);
    EXPECT_THROW(parse_reply("#0"), ProtocolError);
    EXPECT_THROW(parse_reply("#AB12"), ProtocolError);
    EXPECT_THROW(parse_reply("10\xff"), ProtocolError);
    EXPECT_THROW(parse_reply(std::string(kMaxReply + 1, '1')), ProtocolError);
    EXPECT_EQ(format_reply(1, "1000", 0), std::string("1000\0", 5));
    EXPECT_EQ(format_reply(1, "1000", 1), std::string("#011000\0", 8));
}

TEST(ArcusCodec, ClassifiesEveryErrorOfTable11_1) {
    EXPECT_EQ(classify_error("?FOO"), ErrorCode::UnknownCommand);
    EXPECT_EQ(classify_error("?"), ErrorCode::UnknownCommand);
    EXPECT_EQ(classify_error("?Bad SSPD Command"), ErrorCode::BadSspd);
    EXPECT_EQ(classify_error("?Enable RS-485 Mode"), ErrorCode::EnableRs485);
    EXPECT_EQ(classify_error("?Index out of Range"), ErrorCode::IndexOutOfRange);
    EXPECT_EQ(classify_error("?Motor is not moving"), ErrorCode::MotorNotMoving);
    EXPECT_EQ(classify_error("?Moving"), ErrorCode::Moving);
    EXPECT_EQ(classify_error("?SCV ON"), ErrorCode::ScvOn);
    EXPECT_EQ(classify_error("?Speed out of range"), ErrorCode::SpeedOutOfRange);
    EXPECT_EQ(classify_error("?State Error"), ErrorCode::StateError);
    EXPECT_FALSE(classify_error("OK"));
    EXPECT_FALSE(classify_error("1000"));
}

// A7: strict numeric grammar.
TEST(ArcusCodec, A7StrictIntegers) {
    EXPECT_EQ(reply_int("1000"), 1000);
    EXPECT_EQ(reply_int("-2147483648"), INT32_MIN);
    EXPECT_EQ(reply_int("2147483647"), INT32_MAX);
    for (const char* bad : {"", "-", "+99999999999", "1e3", "10 00", " 10", "10 ", "0x10", "2147483648", "1.5",
                            "+5", "OK"}) {
        EXPECT_THROW(reply_int(bad), ProtocolError) << bad;
    }
}

TEST(ArcusCodec, AppendixAExamples) {
    // a) HSPD 20000, LSPD 100: 1 ms .. 19900 ms.  b) 900000/1000: 1 .. 23050 ms.
    EXPECT_EQ(min_acc_ms(20000), 1);
    EXPECT_EQ(max_acc_ms(20000, 100), 19900);
    EXPECT_EQ(min_acc_ms(900000), 1);
    EXPECT_EQ(max_acc_ms(900000, 1000), 23050);
    EXPECT_EQ(min_acc_ms(10000), 2);
    EXPECT_EQ(clamp_acc_ms(50000, 20000, 100), 19900);
    EXPECT_EQ(clamp_acc_ms(0, 10000, 100), 2);
    EXPECT_EQ(window_for_speed(16000)->sspdm, 1);
    EXPECT_EQ(window_for_speed(16001)->sspdm, 2);
    EXPECT_EQ(window_for_speed(6000000)->sspdm, 9);
    EXPECT_FALSE(window_for_speed(6000001));
    EXPECT_EQ(window_for_sspdm(0)->hspd_max, 16000);
    EXPECT_EQ(window_for_sspdm(7)->delta, 39000);
    EXPECT_FALSE(window_for_sspdm(10));
}

TEST(ArcusCodec, DecodesStatusRegisters) {
    // The manual's MST examples: 0 idle, 2 accelerating, 9 constant speed + home, 64 minus limit error.
    EXPECT_FALSE(MotorStatus{0}.moving());
    EXPECT_TRUE(MotorStatus{2}.accelerating());
    EXPECT_TRUE(MotorStatus{9}.constant_speed());
    EXPECT_TRUE(MotorStatus{9}.home());
    EXPECT_TRUE(MotorStatus{64}.minus_limit_error());
    EXPECT_FALSE(MotorStatus{64}.moving());
    EXPECT_TRUE(MotorStatus{512}.z_index());
    EXPECT_EQ(snl_status_from(12), SnlStatus::Disabled);
    EXPECT_EQ(snl_status_from(13), SnlStatus::LimitHoming);
    EXPECT_FALSE(snl_status_from(14));
    EXPECT_TRUE(snl_error(SnlStatus::StallError));
    EXPECT_EQ(snl_status_name(SnlStatus::CorrectionAttemptError), "CorrectionAttemptError");
}

TEST(ArcusCodec, ParsesRequestLines) {
    auto r = parse_request_line("@01EX");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->address, 1);
    EXPECT_EQ(r->command, "EX");
    EXPECT_FALSE(parse_request_line("@1EX"));
    EXPECT_FALSE(parse_request_line("01EX"));
    EXPECT_FALSE(parse_request_line("@01"));
    EXPECT_FALSE(parse_request_line(""));
}

#include <gtest/gtest.h>

#include "motorbus/drives/dmac/codec.hpp"

using namespace motorbus::dmac;

TEST(DmacCodec, FormatsValuesInTheThreeRadixes) {
    EXPECT_EQ(format_value(123, Radix::Dec), "+123");
    EXPECT_EQ(format_value(-20000, Radix::Dec), "-20000");
    EXPECT_EQ(format_value(0, Radix::Dec), "+0");
    EXPECT_EQ(format_value(256, Radix::Hex), "h00000100");
    EXPECT_EQ(format_value(-10, Radix::Hex), "hFFFFFFF6");
    EXPECT_EQ(format_value(100, Radix::Bin), "b00000000 00000000 00000000 01100100");
}

TEST(DmacCodec, ParsesNumbersStrictly) {
    EXPECT_EQ(parse_number("H100"), 256);
    EXPECT_EQ(parse_number("hFFFFFFD8"), -40);
    EXPECT_EQ(parse_number("B1100100"), 100);
    EXPECT_EQ(parse_number("-40"), -40);
    EXPECT_EQ(parse_number("+2147483647"), 2147483647);
    EXPECT_EQ(parse_number("-2147483648"), -2147483647 - 1);
    EXPECT_FALSE(parse_number("2147483648"));
    EXPECT_FALSE(parse_number("+99999999999"));
    EXPECT_FALSE(parse_number("1e3"));
    EXPECT_FALSE(parse_number(""));
    EXPECT_FALSE(parse_number("+"));
    EXPECT_FALSE(parse_number("H123456789"));
    EXPECT_FALSE(parse_number("B2"));
}

TEST(DmacCodec, ParsesAddressGlobalAndSeveralCommands) {
    auto r = parse_request("#HIGH_SPEED:=10000, MOVE_TO 1234");
    EXPECT_EQ(r.address, kGlobal);
    ASSERT_EQ(r.commands.size(), 2u);
    EXPECT_EQ(r.commands[0].cmd, Cmd::Assign);
    EXPECT_EQ(r.commands[0].var, Var::HighSpeed);
    EXPECT_EQ(r.commands[0].expr.lhs.value, 10000);
    EXPECT_EQ(r.commands[1].cmd, Cmd::MoveTo);
    EXPECT_EQ(r.commands[1].expr.lhs.value, 1234);

    auto m = parse_request("63MTO -5000");
    EXPECT_EQ(m.address, 63);
    EXPECT_EQ(m.commands[0].cmd, Cmd::MoveTo);
    EXPECT_EQ(m.commands[0].expr.lhs.value, -5000);
    EXPECT_TRUE(parse_request("64MOVE_TO 1").address_error);
    auto sp = parse_request("04 REQUEST_VERSION");
    EXPECT_EQ(sp.address, 4);
    EXPECT_EQ(sp.commands[0].cmd, Cmd::RequestVersion);
    EXPECT_EQ(parse_request("04RVE").commands[0].cmd, Cmd::RequestVersion);
    EXPECT_EQ(parse_request("04RV").commands[0].cmd, Cmd::RequestVersion);
    auto seq = parse_request("00:120 MOVE_TO 15000");
    EXPECT_EQ(seq.seq_line, 120);
    EXPECT_EQ(seq.commands[0].cmd, Cmd::MoveTo);
}

TEST(DmacCodec, FrameLongerThan256IsInvalid) {
    std::string f = "00MOVE_TO 1" + std::string(250, ' ');
    ASSERT_GT(f.size(), kMaxFrame);
    auto r = parse_request(f);
    EXPECT_EQ(r.address, 0);
    ASSERT_EQ(r.commands.size(), 1u);
    EXPECT_EQ(r.commands[0].cmd, Cmd::Invalid);
    std::string ok = "00MOVE_TO 1" + std::string(256 - 11, ' ');
    EXPECT_EQ(parse_request(ok).commands[0].cmd, Cmd::MoveTo);
}

TEST(DmacCodec, ReadForms) {
    auto d = parse_request("00READ #ACCEL_TIME").commands[0];
    EXPECT_EQ(d.cmd, Cmd::Read);
    EXPECT_EQ(d.var, Var::AccelTime);
    EXPECT_EQ(d.radix, Radix::Dec);
    EXPECT_EQ(parse_request("01READ h#OUTPUT").commands[0].radix, Radix::Hex);
    EXPECT_EQ(parse_request("01READ H#OUT").commands[0].radix, Radix::Hex);
    EXPECT_EQ(parse_request("02READ b#INPUT").commands[0].radix, Radix::Bin);
    auto bit = parse_request("00READ #STATUS.5").commands[0];
    EXPECT_EQ(bit.var, Var::Status);
    EXPECT_EQ(bit.bit, 5);
    EXPECT_EQ(parse_request("00READ #STATUS.33").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("00READ #STATUS.0").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("00READ #NOPE").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("00READ #V33").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("00READ #TIMER_3").commands[0].var, timer_var(3));
    EXPECT_EQ(parse_request("00READ #T2").commands[0].var, timer_var(2));
}

TEST(DmacCodec, WritesWithOperandsAndOperators) {
    auto w = parse_request("00#V10.3:=1").commands[0];
    EXPECT_EQ(w.var, v_var(10));
    EXPECT_EQ(w.bit, 3);
    auto h = parse_request("00#V20:= HFFFFFFD8").commands[0];
    EXPECT_EQ(h.expr.lhs.value, -40);
    auto neg = parse_request("00#V21:=-#V1").commands[0];
    EXPECT_TRUE(neg.expr.lhs.is_var);
    EXPECT_TRUE(neg.expr.lhs.negate);
    auto cpl = parse_request("00#V23:=!#V15 & !#STATUS").commands[0];
    EXPECT_EQ(cpl.expr.op, Op::And);
    EXPECT_TRUE(cpl.expr.lhs.complement);
    EXPECT_TRUE(cpl.expr.rhs.complement);
    auto mul = parse_request("#V2:=3 * -#SUPPLY_VOLTAGE").commands[0];
    EXPECT_EQ(mul.expr.op, Op::Mul);
    EXPECT_TRUE(mul.expr.rhs.negate);
    for (auto [text, op] : {std::pair{"#V1:=#POSITION + 12000", Op::Add}, {"#V1:=#HSP - #V3", Op::Sub},
                            {"#M3:=#POSITION / 10000", Op::Div}, {"#M1:=!#V4 | H00000240", Op::Or},
                            {"#V1:=#POSITION > 123", Op::Gt}, {"#V1:=#POSITION < 123", Op::Lt},
                            {"#V1:=#POSITION >= 123", Op::Ge}, {"#V1:=#POSITION <= 123", Op::Le},
                            {"#V2:=#POSITION != 0", Op::Ne}}) {
        auto c = parse_request(text).commands[0];
        EXPECT_EQ(c.cmd, Cmd::Assign) << text;
        EXPECT_EQ(c.expr.op, op) << text;
    }
    // Operators need spaces around them; three operands are not a DMAC expression.
    EXPECT_EQ(parse_request("#V1:=#V2+3").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("#V1:=1 + 2 + 3").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("MOVE_TO -#POSITION").commands[0].expr.lhs.negate, true);
}

TEST(DmacCodec, IfAndFormatRoundTrip) {
    auto c = parse_request("IF #INPUT.3 = 1 JUMP_REL +4").commands[0];
    EXPECT_EQ(c.cmd, Cmd::If);
    EXPECT_EQ(c.jump, Cmd::JumpRel);
    EXPECT_EQ(c.expr.op, Op::Eq);
    EXPECT_EQ(format_command(c), "IF #INP.3 = +1 JRE +4");
    EXPECT_EQ(format_command(parse_request("MOVE_TO 2000").commands[0]), "MTO +2000");
    EXPECT_EQ(format_command(parse_request("IF #SUPPLY_VOLTAGE > 30000 CALL 160").commands[0]),
              "IF #SVO > +30000 CAL +160");
    for (const char* t : {"#V1:=#IAN - 15000", "HALT MOUV", "SYNCHRO INTERPOL", "WAIT -2000", "START_SEQ",
                          "#OUTPUT.4:=0", "JRE -3", "MSP #V1"}) {
        auto a = parse_request(t).commands[0];
        ASSERT_NE(a.cmd, Cmd::Invalid) << t;
        auto b = parse_request(format_command(a)).commands[0];
        EXPECT_EQ(format_command(a), format_command(b)) << t;
    }
    EXPECT_EQ(parse_request("IF #V1 JUMP").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("POWER MAYBE").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("MOVE_TO").commands[0].cmd, Cmd::Invalid);
    EXPECT_EQ(parse_request("CLOSE_SEQ 3").commands[0].cmd, Cmd::Invalid);
}

TEST(DmacCodec, ParsesRepliesStrictly) {
    auto r = parse_read_reply("00#ATI=+123");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->address, 0);
    EXPECT_EQ(r->mnemonic, "#ATI");
    EXPECT_EQ(r->value, 123);
    EXPECT_EQ(parse_read_reply("00#POS=12345")->value, 12345);  // sign omitted in the manual
    EXPECT_EQ(parse_read_reply("03#STA=h13000800")->value, 0x13000800);
    EXPECT_EQ(parse_read_reply("05#INP=h13")->value, 19);
    EXPECT_EQ(parse_read_reply("02#INP=b00000000 00000000 00000000 00001010")->value, 10);
    EXPECT_EQ(parse_read_reply("05#INP=b00000000000000000000000000010011")->value, 19);
    EXPECT_EQ(parse_read_reply("00#STA.5=1")->bit, 5);
    EXPECT_EQ(parse_read_reply("04#SPE=-20000")->value, -20000);
    // A7: numeric garbage
    for (const char* bad : {"00#POS=", "00#POS=+99999999999", "00#POS=1e3", "00#POS=+1 2", "00#POS= 12",
                            "00#POS=+", "0#POS=1", "00POS=1", "00#POS:=1", "00#INP=b0000000 00000000",
                            "00#POS=hXYZ", "99#POS=1"}) {
        EXPECT_FALSE(parse_read_reply(bad)) << bad;
    }
    // A2: a NUL inside a reply is an invalid character
    EXPECT_FALSE(parse_read_reply(std::string("00#POS=+1\0" "23", 12)));
}

TEST(DmacCodec, VersionAndSequenceReplies) {
    auto v = parse_version(
        "04EV v1.7 H142 \"MIDI-INGENIERIE_DMAC34-1_H142-10145_25/01/05_12/04/06\" PHASE:6A BOOT:v1.1");
    ASSERT_TRUE(v);
    EXPECT_EQ(v->address, 4);
    EXPECT_EQ(v->version, 1);
    EXPECT_EQ(v->release, 7);
    EXPECT_EQ(v->code, "H142");
    EXPECT_EQ(v->model, "DMAC34 standard");
    EXPECT_EQ(v->product, "DMAC34-1");
    EXPECT_EQ(v->serial, "H142-10145");
    EXPECT_EQ(v->manufacturing_date, "25/01/05");
    EXPECT_EQ(v->revision_date, "12/04/06");
    EXPECT_EQ(v->phase, "6A");
    EXPECT_EQ(v->boot, "v1.1");
    EXPECT_FALSE(parse_version("04EV v1.7 H142 \"unterminated"));
    auto s = parse_seq_reply("00: 003 MTO +2000");
    ASSERT_TRUE(s);
    EXPECT_EQ(s->line, 3);
    EXPECT_EQ(s->text, "MTO +2000");
    EXPECT_EQ(format_seq_reply(0, 3, "MTO +2000"), "00: 003 MTO +2000");
    EXPECT_FALSE(parse_seq_reply("00: 501 NOP"));
}

TEST(DmacCodec, StatusAndErrorBitsAreOneBasedFromTheLsb) {
    // 03#STA=h13000800: busy (29), movement (26), power on (25), S-curve (12)
    auto names = status_names(0x13000800u);
    EXPECT_EQ(names, (std::vector<std::string>{"s_curve", "power_on", "movement", "busy"}));
    EXPECT_TRUE(bit_set(0x10u, error::kOvervoltage));  // 01#ERR=b...00010000
    EXPECT_EQ(error_names(0x10u), std::vector<std::string>{"overvoltage"});
    EXPECT_EQ(bit_mask(1), 1u);
    EXPECT_EQ(bit_mask(32), 0x80000000u);
    EXPECT_FALSE(bit_set(0xFFFFFFFFu, 0));
    EXPECT_FALSE(bit_set(0xFFFFFFFFu, 33));
}

TEST(DmacCodec, VariableTableCoversTheManual) {
    EXPECT_EQ(find_variable("#ACCEL_TIME"), Var::AccelTime);
    EXPECT_EQ(find_variable("#ati"), Var::AccelTime);
    EXPECT_EQ(find_variable("HSP"), Var::HighSpeed);
    EXPECT_EQ(var_info(Var::NegativeEnd).factory, -10000);  // MODULE_RESET ALL, not the annex
    EXPECT_EQ(var_info(Var::PositiveEnd).factory, 10000);
    EXPECT_TRUE(var_info(Var::HighSpeed).stored);
    EXPECT_FALSE(var_info(v_var(1)).stored);
    EXPECT_TRUE(var_info(m_var(8)).stored);
    EXPECT_TRUE(var_info(Var::Status).read_only);
    EXPECT_EQ(encode_read(0, Var::AccelTime), "00READ #ACCEL_TIME");
    EXPECT_EQ(encode_read(1, Var::Output, Radix::Hex), "01READ h#OUTPUT");
    EXPECT_EQ(encode_write(0, v_var(10), 1, 3), "00#V10.3:=1");
    EXPECT_EQ(encode_write(kGlobal, Var::HighSpeed, 10000), "#HIGH_SPEED:=10000");
}

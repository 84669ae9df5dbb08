// HOSTILE_INPUTS.md section 2.9, protocol A rows, against the client (and the
// simulator behind it).  Each test names its row.
#include <gtest/gtest.h>

#include "fixture.hpp"

using namespace std::string_literals;

using namespace motorbus;
using namespace motorbus::arcus;
using arcus_test::Bench;

namespace {
std::size_t count(const std::string& hay, const std::string& needle) {
    std::size_t n = 0;
    for (auto p = hay.find(needle); p != std::string::npos; p = hay.find(needle, p + 1)) ++n;
    return n;
}
}  // namespace

TEST(ArcusHostile, A1NoTerminatorTimesOutAndTheNextCommandWorks) {
    Bench b;
    b.port->mangle = [](const std::string& r) { return r.substr(0, r.size() - 1); };  // drop the NUL
    EXPECT_THROW(b.c.position(), motorbus::TimeoutError);
    b.port->mangle = nullptr;
    // The partial "0" must not prefix the next reply.
    b.c.set_position(1234);
    EXPECT_EQ(b.c.position(), 1234);
    EXPECT_GE(b.c.counters().timeouts, 1u);
}

TEST(ArcusHostile, A2BytesAfterTheNulAreStrayAndFlushed) {
    Bench b;
    b.port->mangle = [](const std::string& r) { return r + "999\0"s; };
    b.c.set_position(42);
    EXPECT_EQ(b.c.position(), 42);  // the stray "999\0" after each reply never answers a request
    EXPECT_EQ(b.c.position(), 42);
    b.port->mangle = nullptr;
    EXPECT_EQ(b.c.high_speed(), 1000);
}

TEST(ArcusHostile, A3OverlongReplyIsRefusedBounded) {
    Bench b;
    b.port->mangle = [](const std::string&) { return std::string(500, '7') + '\0'; };
    EXPECT_THROW(b.c.position(), ProtocolError);  // ReplyTooLong
    b.port->mangle = nullptr;
    EXPECT_EQ(b.c.position(), 0);
}

TEST(ArcusHostile, A5UnknownCommandIsTypedAndNotRetried) {
    Bench b;
    auto before = b.c.counters().requests;
    try {
        b.c.command("FOO", /*idempotent=*/true);
        FAIL();
    } catch (const ReplyError& e) {
        EXPECT_EQ(e.code, ErrorCode::UnknownCommand);
        EXPECT_EQ(e.reply, "?FOO");
        EXPECT_EQ(e.command, "FOO");
    }
    EXPECT_EQ(b.c.counters().requests, before + 1);
    EXPECT_EQ(count(b.port->written, "@01FOO\r"), 1u);
    // A bare "?" is the same error.
    b.port->mangle = [](const std::string&) { return "?\0"s; };
    try {
        b.c.position();
        FAIL();
    } catch (const ReplyError& e) {
        EXPECT_EQ(e.code, ErrorCode::UnknownCommand);
    }
}

TEST(ArcusHostile, A6ReplyFromAnotherAddressIsRejected) {
    Bench b;
    b.port->mangle = [](const std::string& r) { return "#02" + r; };
    EXPECT_THROW(b.c.position(), ProtocolError);
    b.port->mangle = [](const std::string& r) { return "#01" + r; };
    EXPECT_EQ(b.c.position(), 0);  // RT=1 format from the right device is fine
    b.port->mangle = nullptr;
}

TEST(ArcusHostile, A7NumericGarbage) {
    Bench b;
    for (std::string bad : {"", "-", "+99999999999", "1e3", "10 00", "+5", "OK", "12a"}) {
        b.port->mangle = [bad](const std::string&) { return bad + '\0'; };
        EXPECT_ANY_THROW(b.c.position()) << bad;
        try {
            b.c.position();
        } catch (const ProtocolError&) {
        } catch (const motorbus::TimeoutError&) {
            EXPECT_EQ(bad, "");  // an empty line is skipped like noise, then nothing comes
        }
    }
    // A set command must be answered "OK".
    b.port->mangle = [](const std::string&) { return "1000\0"s; };
    EXPECT_THROW(b.c.set_high_speed(5), ProtocolError);
    b.port->mangle = nullptr;
    EXPECT_EQ(b.c.position(), 0);
}

TEST(ArcusHostile, A8LateReplyAfterATimeoutIsDiscarded) {
    Bench b;
    b.port->silent = true;
    EXPECT_THROW(b.c.position(), motorbus::TimeoutError);
    b.port->silent = false;
    b.port->inject("777\0"s);  // the late answer to the PX that timed out
    b.c.set_high_speed(2000);
    EXPECT_EQ(b.c.high_speed(), 2000);
    b.port->inject("#017\0"s);
    EXPECT_EQ(b.c.position(), 0);
}

TEST(ArcusHostile, A10NoiseIsSkippedCountedAndResynced) {
    Bench b;
    b.port->mangle = [](const std::string& r) { return "\xff\xff\x00\x01\x80\x00"s + r; };
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.c.counters().noise_lines, 2u);
    b.port->mangle = [](const std::string& r) { return "\x00\x00\x00"s + r; };
    EXPECT_EQ(b.c.high_speed(), 1000);
    b.port->mangle = nullptr;
    EXPECT_EQ(b.c.position(), 0);
}

TEST(ArcusHostile, A11OnlyNulEndsAReply) {
    Bench b;
    b.port->mangle = [](const std::string& r) { return r.substr(0, r.size() - 1) + "\r\n"; };
    EXPECT_THROW(b.c.position(), motorbus::TimeoutError);
    b.port->mangle = [](const std::string& r) { return r.substr(0, r.size() - 1) + "\r"; };
    EXPECT_THROW(b.c.position(), motorbus::TimeoutError);
    b.port->mangle = nullptr;
    EXPECT_EQ(b.c.position(), 0);
}

// A13: the DMX-CAN sends no boot banner (the manual documents none and the sim
// sends none).  What remains is stray output around a power cycle: it is
// flushed before the next request, and the device answers with boot values.
TEST(ArcusHostile, A13PowerCycleOutputIsDroppedAndStateIsBootState) {
    Bench b;
    b.c.set_high_speed(3000);
    b.sim.power_cycle();
    b.port->inject("DMX-CAN\0"s);
    EXPECT_EQ(b.c.high_speed(), 1000);
    EXPECT_FALSE(b.c.enabled());
}

TEST(ArcusHostile, A14MotionCommandsAreNotRetriedQueriesAre) {
    Bench b;
    b.c.enable(true);  // a disabled motor does no motion (§6)
    b.port->silent = true;
    EXPECT_THROW(b.c.move(1000), motorbus::TimeoutError);
    EXPECT_EQ(count(b.port->written, "@01X1000\r"), 1u);
    EXPECT_THROW(b.c.jog(1), motorbus::TimeoutError);
    EXPECT_EQ(count(b.port->written, "@01J+\r"), 1u);
    EXPECT_THROW(b.c.position(), motorbus::TimeoutError);
    EXPECT_EQ(count(b.port->written, "@01PX\r"), 2u);  // one retry
    b.port->silent = false;
    // The lost "OK" did not mean the move did not start: the state says it did.
    EXPECT_TRUE(b.c.moving());
}

TEST(ArcusHostile, A15SimulatorThroughTheLink) {
    Bench b;
    b.port->silent = false;
    // An over-long, binary request: the device stays silent, the client times out...
    EXPECT_THROW(b.link->transact(std::string(300, '\xff')), motorbus::TimeoutError);
    // ...and the next valid request is answered.
    EXPECT_EQ(b.c.position(), 0);
    EXPECT_EQ(b.link->transact(std::string("@01\x01\x02", 5)), "?");
}

TEST(ArcusHostile, RefusalsAreTypedForEveryTable11_1Reply) {
    Bench b;
    b.open_loop();
    auto code_of = [&](auto&& f) -> ErrorCode {
        try {
            f();
        } catch (const ReplyError& e) {
            return e.code;
        }
        ADD_FAILURE() << "no ArcusError";
        return ErrorCode::UnknownCommand;
    };
    EXPECT_EQ(code_of([&] { b.c.change_target(5); }), ErrorCode::MotorNotMoving);
    EXPECT_EQ(code_of([&] { b.c.change_speed(500); }), ErrorCode::BadSspd);
    EXPECT_EQ(code_of([&] { b.c.command("DI9"); }), ErrorCode::IndexOutOfRange);
    b.c.jog(1);
    EXPECT_EQ(code_of([&] { b.c.move(5); }), ErrorCode::Moving);
    EXPECT_EQ(code_of([&] { b.c.change_speed(99999); }), ErrorCode::SpeedOutOfRange);
    b.c.set_s_curve(true);
    EXPECT_EQ(code_of([&] { b.c.change_speed(500); }), ErrorCode::ScvOn);
    b.c.abort();
    b.sim.force_limit(1, true);
    b.c.jog(1);
    b.run(0.01);
    EXPECT_EQ(code_of([&] { b.c.jog(-1); }), ErrorCode::StateError);
    // "?Enable RS-485 Mode" belongs to a Modbus command the manual does not
    // describe; the client still types it.
    b.port->mangle = [](const std::string&) { return "?Enable RS-485 Mode\0"s; };
    EXPECT_EQ(code_of([&] { b.c.position(); }), ErrorCode::EnableRs485);
}

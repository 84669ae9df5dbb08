// The client against the simulator through an in-memory port (and through a
// real pty with the serial PtyLineServer), plus hostile peers (2.9 A-rows).
#include <gtest/gtest.h>

#include "motorbus/drives/dmac/client.hpp"
#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/serial/line_server.hpp"
#include "sim_port.hpp"

using namespace motorbus;
using namespace motorbus::dmac;
using namespace std::chrono_literals;

namespace {

struct Bench {
    std::shared_ptr<SimClock> clock = std::make_shared<SimClock>();
    std::shared_ptr<dmac_test::SimPort> port = std::make_shared<dmac_test::SimPort>();
    std::vector<std::shared_ptr<Sim>> sims;
    std::shared_ptr<serial::LineLink> link;
    std::vector<std::unique_ptr<Client>> clients;

    explicit Bench(std::vector<int> addresses = {0}, Duration timeout = 100ms) {
        auto opts = default_line_options();
        opts.reply_timeout = timeout;
        link = std::make_shared<serial::LineLink>(port, opts);
        for (int a : addresses) {
            auto s = std::make_shared<Sim>(clock, SimOptions{.address = a});
            s->on_line(address_prefix(a) + "BRAKE OFF");  // factory BRAKE ON (annex 7.1)
            sims.push_back(s);
            port->attach(s);
            ClientOptions co;
            co.address = a;
            co.sleep = [c = clock](Duration d) { c->advance(d.count()); };
            clients.push_back(std::make_unique<Client>(link, co));
        }
    }
    Client& c(std::size_t i = 0) { return *clients[i]; }
    Sim& sim(std::size_t i = 0) { return *sims[i]; }
    void ms(std::int64_t n) { clock->advance(n * 1'000'000); }
};

std::size_t count(const std::string& hay, const std::string& needle) {
    std::size_t n = 0;
    for (auto p = hay.find(needle); p != std::string::npos; p = hay.find(needle, p + 1)) ++n;
    return n;
}

}  // namespace

TEST(Client, TypedVariablesRoundTrip) {
    Bench b;
    auto& c = b.c();
    c.set_profile(20000, 3000, 500, 700);
    EXPECT_EQ(c.read(Var::HighSpeed), 20000);
    EXPECT_EQ(c.read(Var::LowSpeed), 3000);
    EXPECT_EQ(c.read(Var::AccelTime), 500);
    EXPECT_EQ(c.read(Var::DecelTime), 700);
    EXPECT_EQ(c.read(Var::AccelTime, Radix::Hex), 500);
    EXPECT_EQ(c.read(Var::AccelTime, Radix::Bin), 500);
    c.set_user_var(32, -5);
    EXPECT_EQ(c.user_var(32), -5);
    c.set_memorized_var(8, 77);
    EXPECT_EQ(c.memorized_var(8), 77);
    c.set_timer(1, 1000);
    b.ms(400);
    EXPECT_EQ(c.timer(1), 600);
    c.set_output(3, true);
    EXPECT_EQ(c.outputs(), 4u);
    EXPECT_TRUE(c.read_bit(Var::Output, 3));
    EXPECT_FALSE(c.read_bit(Var::Output, 1));
    EXPECT_EQ(c.supply_voltage(), 32000);
    EXPECT_EQ(c.cpu_temperature(), 520);
    b.sim().set_input(1, true);
    b.sim().set_input(6, true);
    EXPECT_EQ(c.inputs(), 0x21u);
    EXPECT_THROW(c.write(Var::Status, 1), InvalidArgument);
    EXPECT_THROW(c.write(Var::TorqueRatio, 101), InvalidArgument);
    EXPECT_THROW(c.user_var(33), InvalidArgument);
    EXPECT_THROW(c.read_bit(Var::Status, 0), InvalidArgument);
    // What went over the wire: full names, CR after each request.
    EXPECT_NE(b.port->written().find("00#HIGH_SPEED:=20000, #LOW_SPEED:=3000, #ACCEL_TIME:=500, "
                                     "#DECEL_TIME:=700, READ #ERROR\r"),
              std::string::npos);
}

TEST(Client, MoveToAndWaitIdleOnSimulatedTime) {
    Bench b;
    auto& c = b.c();
    c.move_to(200000);
    auto st = c.status();
    EXPECT_TRUE(st.busy());
    EXPECT_TRUE(st.moving());
    EXPECT_TRUE(st.power_on());
    const auto t0 = b.clock->now();
    EXPECT_EQ(c.wait_idle(10s, 1ms), 200000);
    const double took_ms = static_cast<double>(b.clock->now() - t0) / 1e6;
    Motion ref;
    ref.move_to(0, 200000);
    EXPECT_NEAR(took_ms, ref.profile().duration() * 1000, 2.0);
    c.move_on(-5000);  // the manual's MOVE_ON example: half a turn CCW
    EXPECT_EQ(c.wait_idle(10s, 1ms), 195000);
    c.set_position(0);
    EXPECT_EQ(c.position(), 0);
}

TEST(Client, WaitIdleTimesOutInSimulatedTime) {
    Bench b;
    b.c().move_to(100000);  // 10 turns: busy for seconds (a MOVE_SPEED is idle once at speed)
    EXPECT_THROW(b.c().wait_idle(50ms, 10ms), TimeoutError);
    b.c().stop();
    EXPECT_NO_THROW(b.c().wait_idle(5s, 10ms));
    EXPECT_EQ(b.c().speed(), 0);
}

TEST(Client, StatusAndErrorDecoding) {
    Bench b;
    auto& c = b.c();
    c.s_curve(true);
    c.soft_ends(true);
    c.hard_ends(EndStops::Positive);
    c.optimized_current(true);
    c.inverse_polarity(Polarity::Outputs);
    auto st = c.status();
    EXPECT_TRUE(st.bit(status::kSCurve));
    EXPECT_TRUE(st.bit(status::kSoftEndsEnabled));
    EXPECT_TRUE(st.bit(status::kHardPosEnabled));
    EXPECT_FALSE(st.bit(status::kHardNegEnabled));
    EXPECT_TRUE(st.bit(status::kOptimizedCurrent));
    EXPECT_TRUE(st.bit(status::kOutputsInverted));
    EXPECT_EQ(st.names(), (std::vector<std::string>{"optimized_current", "hard_pos_enabled", "soft_ends_enabled",
                                                    "s_curve", "outputs_inverted"}));
    b.sim().inject_error(error::kOvervoltage);
    auto e = c.error();
    EXPECT_TRUE(e.bit(error::kOvervoltage));
    EXPECT_EQ(e.names(), std::vector<std::string>{"overvoltage"});
    EXPECT_TRUE(c.status().error());
    c.clear_error();
    EXPECT_FALSE(c.error().any());
}

TEST(Client, RejectedCommandsRaiseTyped) {
    Bench b;
    auto& c = b.c();
    // A5: the module rejects an undefined command (bit 12) -> UnknownCommand.
    EXPECT_THROW(c.command("FROBNICATE 3"), UnknownCommand);
    EXPECT_FALSE(c.error().any());  // acknowledged by the client
    try {
        c.command("#HIGH_SPEED:=500000");
        FAIL();
    } catch (const CommandRejected& e) {
        EXPECT_TRUE(bit_set(e.error, error::kLimit));
        EXPECT_NE(std::string(e.what()).find("limit"), std::string::npos);
    }
    EXPECT_EQ(c.read(Var::HighSpeed), 60000);
    // A latched hardware fault is not acknowledged behind the user's back.
    b.sim().inject_error(error::kThermal);
    EXPECT_THROW(c.command("#V1:=1 / 0"), CommandRejected);
    EXPECT_TRUE(c.error().bit(error::kThermal));
}

TEST(Client, VersionAndAddressChange) {
    Bench b({4});
    auto v = b.c().request_version();
    EXPECT_EQ(v.address, 4);
    EXPECT_EQ(v.code, "H142");
    EXPECT_EQ(v.product, "DMAC34-1");
    EXPECT_EQ(v.version, 1);
    EXPECT_EQ(v.release, 7);
    b.c().set_address(9);
    EXPECT_EQ(b.sim().address(), 9);
    EXPECT_EQ(b.c().address(), 9);
    EXPECT_EQ(b.c().position(), 0);
    EXPECT_THROW(b.c().set_address(64), InvalidArgument);
    EXPECT_THROW(b.c().set_baudrate(12345), InvalidArgument);
    b.c().set_baudrate(115200);
    EXPECT_EQ(b.sim().baudrate(), 115200);
}

TEST(Client, ModuleResetThroughTheClient) {
    Bench b;
    auto& c = b.c();
    c.set_user_var(1, 5);
    c.set_memorized_var(1, 6);
    c.module_reset();
    EXPECT_EQ(c.user_var(1), 0);
    EXPECT_EQ(c.memorized_var(1), 6);
    c.module_reset(true);
    EXPECT_EQ(c.memorized_var(1), 0);
    EXPECT_EQ(c.read(Var::NegativeEnd), -10000);
}

TEST(Client, SequencerUploadReadBackStartStopStep) {
    Bench b;
    auto& c = b.c();
    c.upload_sequence({"MOVE_ON 10000", "WAIT 2000", "JUMP 1"});
    EXPECT_EQ(c.read_sequence(1, 4), (std::vector<std::string>{"MON +10000", "WAI +2000", "JUM +1", ""}));
    EXPECT_THROW(c.upload_sequence({"MOVE_ON 1", "BOGUS"}), InvalidArgument);
    EXPECT_EQ(c.read_sequence_line(1), "MON +10000");  // the bad upload did not touch the program
    EXPECT_THROW(c.upload_sequence({"MOVE_ON 1, MOVE_ON 2"}), InvalidArgument);
    c.start_sequence();
    EXPECT_TRUE(c.status().sequencer_running());
    b.ms(2001);
    EXPECT_EQ(c.position(), 10000);
    EXPECT_EQ(c.line(), 2);
    c.stop_sequence();
    EXPECT_FALSE(c.status().sequencer_running());
    EXPECT_EQ(c.line(), 0);
    c.upload_sequence({"#V1:=#V1 + 10", "#V1:=#V1 * 2"}, 40);
    c.step(40);
    EXPECT_EQ(c.user_var(1), 10);
    c.step();
    EXPECT_EQ(c.user_var(1), 20);
    c.set_on_reset(40);
    c.module_reset();
    b.ms(5);
    EXPECT_EQ(c.user_var(1), 20);  // reset zeroed #V1, then lines 40 and 41 ran
    EXPECT_THROW(c.start_sequence(501), InvalidArgument);
}

TEST(Client, SingleAxisInterpolationReportsXon) {
    Bench b;
    auto& c = b.c();
    c.write(Var::InterpolFifosize, 2);
    EXPECT_EQ(c.move_interpol(10), 1);
    EXPECT_EQ(c.move_interpol(10), 2);
    EXPECT_EQ(c.move_interpol(10), std::nullopt);
    EXPECT_EQ(c.counters().xon_errors, 1u);
    EXPECT_EQ(c.interpol_count(), 2);
}

TEST(Client, StreamsAMultiAxisPathKeepingEveryFifoFed) {
    Bench b({0, 1, 2});
    // A straight line from (0,0,0) to (20000, -5000, 12000): 100 segments of 20 ms.
    std::vector<std::vector<long long>> segs(100, std::vector<long long>{200, -50, 120});
    StreamOptions so;
    so.interpol_time_ms = 20;
    so.fifo_size = 16;
    so.sleep = [c = b.clock](Duration d) { c->advance(d.count()); };
    std::vector<Client*> axes{&b.c(0), &b.c(1), &b.c(2)};
    auto st = stream_interpolation(axes, segs, so);
    EXPECT_EQ(st.segments, segs.size());
    EXPECT_GT(st.xon_errors, 0u);          // back-pressure happened...
    EXPECT_EQ(st.underruns, 0u);           // ...and no axis ever ran dry
    EXPECT_GE(st.min_level_after_start, 1);
    // The start was one global SYNCHRO INTERPOL.
    EXPECT_EQ(count(b.port->written(), "SYNCHRO INTERPOL\r"), 1u);
    b.ms(static_cast<std::int64_t>(segs.size()) * 20 + 50);
    EXPECT_EQ(b.sim(0).state().position, 20000);
    EXPECT_EQ(b.sim(1).state().position, -5000);
    EXPECT_EQ(b.sim(2).state().position, 12000);
}

TEST(Client, SynchroTopStartsArmedAxesTogether) {
    Bench b({0, 3});
    synchro(*b.link, Keyword::On);
    b.c(0).move_speed(4000);
    b.c(1).move_speed(-12500);
    b.ms(50);
    EXPECT_EQ(b.c(0).speed(), 0);
    synchro(*b.link, Keyword::Top);
    synchro(*b.link, Keyword::Off);
    b.ms(1000);
    EXPECT_EQ(b.c(0).speed(), 4000);
    EXPECT_EQ(b.c(1).speed(), -12500);
    EXPECT_EQ(b.sim(0).state().now_ms, b.sim(1).state().now_ms);
}

TEST(Client, OverARealPtyWithTheLineServer) {
    auto clock = std::make_shared<SimClock>();
    auto s0 = std::make_shared<Sim>(clock, SimOptions{.address = 0});
    auto s1 = std::make_shared<Sim>(clock, SimOptions{.address = 1});
    serial::PtyLineServer server({s0, s1});
    auto port = serial::open_port(server.slave_path(), 115200);
    auto link = std::make_shared<serial::LineLink>(port, default_line_options());
    Client c0(link, {.address = 0}), c1(link, {.address = 1});
    c1.brake(false);
    c1.move_to(1234);
    clock->advance(5'000'000'000);
    EXPECT_EQ(c1.position(), 1234);
    EXPECT_EQ(c0.position(), 0);
    EXPECT_EQ(c0.raw("READ #POSITION", true), "00#POS=+0");  // global: only 00 answers
}

// ---- hostile peers (HOSTILE_INPUTS.md 2.9) -------------------------------------------------
TEST(Client, A1NoTerminatorTimesOutAndTheNextCommandWorks) {
    Bench b;
    b.port->tamper = [](const std::string& req, const std::string& reply) {
        return req.find("#V7") != std::string::npos ? reply.substr(0, reply.size() - 2) : reply;
    };
    EXPECT_THROW(b.c().user_var(7), TimeoutError);
    EXPECT_EQ(b.c().position(), 0);  // the partial line was flushed, not prefixed
}

TEST(Client, A2NulInsideAReplyIsRejected) {
    Bench b;
    b.port->tamper = [](const std::string&, const std::string&) { return std::string("00#POS=+1\0" "23\r\n", 14); };
    try {
        b.c().position();
        FAIL();
    } catch (const ProtocolError& e) {
        EXPECT_EQ(e.bytes.size(), 12u);
    }
}

TEST(Client, A3OverlongReplyRaisesReplyTooLong) {
    Bench b;
    b.port->tamper = [](const std::string&, const std::string&) { return "00#POS=+" + std::string(400, '1') + "\r\n"; };
    EXPECT_THROW(b.c().position(), serial::ReplyTooLong);
    b.port->tamper = nullptr;
    EXPECT_EQ(b.c().position(), 0);
}

TEST(Client, A5QuestionMarkRaisesUnknownCommand) {
    Bench b;
    b.port->tamper = [](const std::string&, const std::string&) { return std::string("?XYZ\r\n"); };
    EXPECT_THROW(b.c().position(), UnknownCommand);
    b.port->tamper = nullptr;
    EXPECT_EQ(b.c().position(), 0);
}

TEST(Client, A6ReplyForAnotherParameterOrModuleIsRejected) {
    Bench b;
    b.port->tamper = [](const std::string&, const std::string&) { return std::string("00#VEL=+5\r\n"); };
    EXPECT_THROW(b.c().position(), ProtocolError);
    b.port->tamper = [](const std::string&, const std::string&) { return std::string("01#POS=+5\r\n"); };
    EXPECT_THROW(b.c().position(), ProtocolError);
    b.port->tamper = [](const std::string&, const std::string&) { return std::string("00#POS.3=+1\r\n"); };
    EXPECT_THROW(b.c().position(), ProtocolError);
    EXPECT_GE(b.c().counters().stray_lines, 3u);
}

TEST(Client, A7NumericGarbageIsRejectedAndUnsignedIsAccepted) {
    Bench b;
    for (std::string bad : {"00#POS=", "00#POS=+99999999999", "00#POS=1e3", "00#POS=+1 2", "00#POS=+12a"}) {
        b.port->tamper = [bad](const std::string&, const std::string&) { return bad + "\r\n"; };
        EXPECT_THROW(b.c().position(), ProtocolError) << bad;
    }
    b.port->tamper = [](const std::string&, const std::string&) { return std::string("00#POS=12345\r\n"); };
    EXPECT_EQ(b.c().position(), 12345);  // the manual's unsigned form
}

TEST(Client, A8LateReplyIsFlushedBeforeTheNextRequest) {
    Bench b;
    b.c().set_user_var(1, 42);
    b.port->inject("00#V1=+999\r\n");  // a late reply from a previous, timed-out request
    EXPECT_EQ(b.c().user_var(1), 42);
}

TEST(Client, A10NoiseIsSkippedAndCounted) {
    Bench b;
    b.port->tamper = [](const std::string&, const std::string& reply) {
        return std::string("\xff\xff\x00\xfe\r\n", 6) + reply;
    };
    EXPECT_EQ(b.c().position(), 0);
    EXPECT_EQ(b.c().counters().stray_lines, 1u);
}

TEST(Client, A11OnlyTheConfiguredTerminatorEndsAReply) {
    Bench b;
    for (std::string term : {std::string("\r"), std::string("\0", 1), std::string("\n\r")}) {
        b.port->tamper = [term](const std::string&, const std::string& reply) {
            return reply.substr(0, reply.size() - 2) + term;
        };
        EXPECT_THROW(b.c().position(), TimeoutError);
    }
    b.port->tamper = nullptr;
    EXPECT_EQ(b.c().position(), 0);
}

TEST(Client, A13UnsolicitedBannerIsDroppedAndFlagged) {
    Bench b;
    b.port->tamper = [](const std::string&, const std::string& reply) {
        return "00EV v1.7 H142 \"MIDI-INGENIERIE_DMAC34-1_H142-10145_25/01/05_12/04/06\" PHASE:6A BOOT:v1.1\r\n" +
               reply;
    };
    EXPECT_EQ(b.c().position(), 0);
    EXPECT_EQ(b.c().counters().device_resets, 1u);
}

TEST(Client, A14MotionCommandIsNeverRetriedOnTimeout) {
    Bench b;
    b.port->tamper = [](const std::string& req, const std::string& reply) {
        return req.find("MOVE_TO") != std::string::npos ? std::string() : reply;
    };
    EXPECT_THROW(b.c().move_to(1000), TimeoutError);
    EXPECT_EQ(count(b.port->written(), "MOVE_TO 1000"), 1u);
    b.port->tamper = nullptr;
    EXPECT_TRUE(b.c().status().moving());  // the move did start: query, don't resend
}

TEST(Client, StreamsAPlannedStraightLineSplitByTheMotionPackage) {
    Bench b({0, 1});
    std::vector<motion::Limits> lim(2, motion::Limits{50000, 100000, 100000, 0});
    auto profiles = motion::plan_straight_line({0, 0}, {30000, -12000}, lim);
    auto segs = motion::split_interpolation(profiles, 10);
    ASSERT_GT(segs.size(), 32u);
    StreamOptions so;
    so.interpol_time_ms = 10;
    so.fifo_size = 32;
    so.sleep = [c = b.clock](Duration d) { c->advance(d.count()); };
    auto st = stream_interpolation({&b.c(0), &b.c(1)}, segs, so);
    EXPECT_EQ(st.underruns, 0u);
    // The splitter makes the offsets sum exactly to each target.
    b.ms(static_cast<std::int64_t>(segs.size()) * 10 + 20);
    EXPECT_EQ(b.sim(0).state().position, 30000);
    EXPECT_EQ(b.sim(1).state().position, -12000);
}

TEST(Client, MoreTypedVariables) {
    Bench b;
    auto& c = b.c();
    c.set_torque_ratio(70);
    EXPECT_EQ(c.torque_ratio(), 70);
    c.set_soft_limits(-80000, 100000);
    EXPECT_EQ(c.soft_limits(), (std::pair<std::int32_t, std::int32_t>{-80000, 100000}));
    EXPECT_THROW(c.set_soft_limits(5, -5), InvalidArgument);
    c.set_output_config(1);
    EXPECT_EQ(c.output_config(), 1);
    c.set_line_delay(1000);
    EXPECT_EQ(c.line_delay(), 1000);
    EXPECT_THROW(c.set_line_delay(99), InvalidArgument);
    c.set_interpolation(50, 16, -1);
    EXPECT_EQ(c.read(Var::InterpolTime), 50);
    EXPECT_EQ(c.read(Var::InterpolFifosize), 16);
    EXPECT_EQ(c.read(Var::InterpolMode), -1);
    EXPECT_THROW(c.set_interpolation(1, 16), InvalidArgument);
    b.sim().set_analog(1, -3200);  // the manual's 02#IAN=-3200
    b.sim().set_analog(2, 1500);   // 04#IA2=1500
    EXPECT_EQ(c.analog_input(1), -3200);
    EXPECT_EQ(c.analog_input(2), 1500);
    c.set_analog_output(1, 4520);
    EXPECT_EQ(c.read(Var::OutputA1), 4520);
    EXPECT_THROW(c.set_analog_output(2, 10001), InvalidArgument);
    EXPECT_EQ(c.motor_temperature(), 650);
    EXPECT_EQ(c.driver_temperature(), 450);
    c.set_on_reset(12);
    EXPECT_EQ(c.on_reset(), 12);
}

// Defects found by auditing the simulator and the client against the 001
// manual line by line; each test names the section it holds the code to.
#include <gtest/gtest.h>

#include <chrono>

#include "motorbus/drives/dmac/client.hpp"
#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/serial/line_server.hpp"
#include "sim_port.hpp"
#include "sim_rig.hpp"

using namespace motorbus;
using namespace motorbus::dmac;
using motorbus::dmac::testing::Rig;
using namespace std::chrono_literals;

namespace {

struct ClientBench {
    std::shared_ptr<SimClock> clock = std::make_shared<SimClock>();
    std::shared_ptr<dmac_test::SimPort> port = std::make_shared<dmac_test::SimPort>();
    std::shared_ptr<Sim> sim;
    std::shared_ptr<serial::LineLink> link;
    std::unique_ptr<Client> client;
    explicit ClientBench(Model model = Model::Dmac34_1) {
        sim = std::make_shared<Sim>(clock, SimOptions{.address = 0, .model = model});
        port->attach(sim);
        link = std::make_shared<serial::LineLink>(port, default_line_options());
        ClientOptions co;
        co.sleep = [c = clock](Duration d) { c->advance(d.count()); };
        client = std::make_unique<Client>(link, co);
        if (model == Model::Dmac34_1 || model == Model::Dmac34_2) client->brake(false);
    }
};

}  // namespace

// ---- 3.5.4: BUSY until the target velocity is reached in velocity mode ------------------
TEST(DmacAudit, BusyEndsWhenTheTargetVelocityIsReached) {
    Rig r;
    r.tx("00#ACCEL_TIME:=1000, #HIGH_SPEED:=60000, MOVE_SPEED 30000");  // 0.5 s ramp (5.1)
    r.ms(400);
    EXPECT_TRUE(bit_set(r.status(), status::kBusy));
    EXPECT_TRUE(r.sim->physical_outputs() & 1u);  // OUT1 = BUSY (#OUTPUT_CONFIG 3)
    r.ms(101);
    EXPECT_EQ(r.read(Var::Speed), 30000);
    EXPECT_FALSE(bit_set(r.status(), status::kBusy));
    EXPECT_TRUE(bit_set(r.status(), status::kMovement));
    EXPECT_FALSE(r.sim->physical_outputs() & 1u);
    // A new target is not reached yet: busy again until the stop has run.
    r.tx("00STOP");
    r.ms(1);
    EXPECT_TRUE(bit_set(r.status(), status::kBusy));
    r.ms(600);
    EXPECT_EQ(r.status() & (bit_mask(status::kBusy) | bit_mask(status::kMovement)), 0u);
}

TEST(DmacAudit, ClientWaitIdleReturnsOnceAtSpeed) {
    ClientBench b;
    b.client->move_speed(30000);
    b.client->wait_idle(5s);  // threw TimeoutError before: BUSY held for as long as it turned
    EXPECT_EQ(b.client->speed(), 30000);
    EXPECT_TRUE(b.client->status().moving());
    EXPECT_FALSE(b.client->status().busy());
}

// ---- 5.13: #LINE_DELAY delays every reply ------------------------------------------------
TEST(DmacAudit, RepliesWaitLineDelay) {
    Rig r;
    EXPECT_EQ(r.read(Var::LineDelay), 3000);  // factory
    auto timed = [&](std::string_view req) {
        const auto t0 = std::chrono::steady_clock::now();
        std::string rep = r.tx(req);
        return std::make_pair(rep, std::chrono::steady_clock::now() - t0);
    };
    auto [rep, took] = timed("00READ #POSITION");
    EXPECT_EQ(rep, "00#POS=+0\r\n");
    EXPECT_GE(took, 3000us);  // a lower bound: the sim sleeps at least that long
    r.tx("00#LINE_DELAY:=100");
    auto [rep2, took2] = timed("00READ #LINE_DELAY");
    EXPECT_EQ(rep2, "00#LDE=+100\r\n");
    EXPECT_GE(took2, 100us);
}

TEST(DmacAudit, ClientReplyTimeoutAllowsTheLineDelay) {
    // Over a real pty: the reply comes #LINE_DELAY (3 ms) after the request,
    // later than the 1 ms the caller allows the module itself to answer.
    auto clock = std::make_shared<SimClock>();
    auto sim = std::make_shared<Sim>(clock, SimOptions{});
    serial::PtyLineServer server({sim});
    auto link = std::make_shared<serial::LineLink>(serial::open_port(server.slave_path(), 38400),
                                                   default_line_options());
    ClientOptions co;
    co.timeout = 1ms;
    Client c(link, co);
    EXPECT_EQ(c.read(Var::LineDelay), 3000);  // TimeoutError before
}

// ---- 2.1, 5.5, 5.25: supply and temperature faults ---------------------------------------
TEST(DmacAudit, UndervoltageStopsAndLatchesUntilAcknowledged) {
    Rig r;
    r.tx("00BRAKE OFF, MOVE_SPEED 20000");
    r.ms(200);
    r.sim->set_supply_voltage(11000);  // below 20 V on a DMAC34
    EXPECT_TRUE(bit_set(r.sim->state().error, error::kUndervoltage));
    const auto st = r.status();
    EXPECT_TRUE(bit_set(st, status::kError));
    EXPECT_TRUE(bit_set(st, status::kAbnormalStop));
    EXPECT_FALSE(bit_set(st, status::kMovement));
    EXPECT_FALSE(bit_set(st, status::kPowerOn));
    EXPECT_TRUE(r.sim->physical_outputs() & 2u);  // OUT2 = FAULT
    // Still too low: acknowledging latches it again; a move is refused.
    r.tx("00#ERROR:=0, MOVE_ON 1000");
    EXPECT_TRUE(bit_set(r.sim->state().error, error::kUndervoltage));
    EXPECT_EQ(r.run_until_idle(), 0);
    r.sim->set_supply_voltage(24000);
    const std::int32_t p1 = r.read(Var::Position);
    r.tx("00#ERROR:=0, MOVE_ON 1000");
    EXPECT_EQ(r.sim->state().error, 0u);
    r.run_until_idle();
    EXPECT_EQ(r.read(Var::Position), p1 + 1000);
}

TEST(DmacAudit, OvervoltageAndThermalFaultsPerModel) {
    Rig r17(0, Model::Dmac17);
    r17.sim->set_supply_voltage(45000);
    EXPECT_EQ(r17.sim->state().error, 0u);
    r17.sim->set_supply_voltage(50000);  // above 49 V on a DMAC17
    EXPECT_TRUE(bit_set(r17.sim->state().error, error::kOvervoltage));
    Rig r34;
    r34.sim->set_supply_voltage(160000);
    EXPECT_EQ(r34.sim->state().error, 0u);
    r34.sim->set_supply_voltage(32000);
    r34.sim->set_temperature(Sim::Sensor::Motor, 860);  // above 85 degC
    EXPECT_TRUE(bit_set(r34.sim->state().error, error::kThermal));
    EXPECT_EQ(r34.val("00READ #MTE"), 860);
    r34.sim->set_temperature(Sim::Sensor::Motor, 650);
    r34.tx("00#ERROR:=0");
    EXPECT_EQ(r34.sim->state().error, 0u);
    r34.sim->set_temperature(Sim::Sensor::Cpu, 1210);  // CPU above 120 degC
    EXPECT_TRUE(bit_set(r34.sim->state().error, error::kThermal));
}

TEST(DmacAudit, ClientRefusesAMoveWhileAFaultIsLatched) {
    ClientBench b;
    b.sim->inject_error(error::kOvervoltage);
    EXPECT_THROW(b.client->move_to(5000), CommandRejected);
    b.client->clear_error();
    b.client->move_to(5000);
    EXPECT_EQ(b.client->wait_idle(10s), 5000);
}

// ---- 4: a frame over 256 characters ----------------------------------------------------
TEST(DmacAudit, OverlongFrameOnThePtySetsTheSyntaxBit) {
    auto clock = std::make_shared<SimClock>();
    auto s0 = std::make_shared<Sim>(clock, SimOptions{.address = 0});
    auto s1 = std::make_shared<Sim>(clock, SimOptions{.address = 1});
    serial::PtyLineServer server({s0, s1});
    auto link = std::make_shared<serial::LineLink>(serial::open_port(server.slave_path(), 38400),
                                                   default_line_options());
    link->send("01BRAKE OFF, MOVE_TO 5000, #V1:=7" + std::string(260, ' '));
    ClientOptions co;
    co.address = 1;
    co.verify = false;
    Client c1(link, co);
    co.address = 0;
    Client c0(link, co);
    EXPECT_EQ(c1.error().raw, bit_mask(error::kSyntax));  // was 0: the line server's path lost it
    EXPECT_EQ(c0.error().raw, 0u);                         // addressed to 01 only
    EXPECT_EQ(c1.user_var(1), 0);                          // nothing of it ran
}

// ---- annex 7.1: BRAKE factory value ON ---------------------------------------------------
TEST(DmacAudit, BrakeIsAppliedAfterAResetOnADmac34) {
    Rig r(0, Model::Dmac34_1, false);
    r.tx("00MOVE_ON 1000");
    EXPECT_TRUE(bit_set(r.sim->state().error, error::kLimit));  // the brake holds the axis
    EXPECT_EQ(r.run_until_idle(), 0);
    EXPECT_TRUE(bit_set(r.status(), status::kBrake));
    r.tx("00BRAKE OFF");
    EXPECT_FALSE(bit_set(r.status(), status::kBrake));
    r.tx("00MODULE_RESET");
    EXPECT_TRUE(bit_set(r.status(), status::kBrake));
    Rig r23(0, Model::Dmac23_1);  // no brake output
    EXPECT_FALSE(bit_set(r23.status(), status::kBrake));
}

// ---- 4.15: POWER SC brakes, POWER OFF lets the rotor freewheel ---------------------------
TEST(DmacAudit, PowerScStopsSoonerThanPowerOff) {
    auto run_down = [](const char* how) {
        Rig r;
        r.tx("00BRAKE OFF, #ACCEL_TIME:=100, MOVE_SPEED 60000");
        r.ms(500);
        const std::int32_t p0 = r.read(Var::Position);
        r.tx(std::string("00POWER ") + how);
        EXPECT_FALSE(bit_set(r.status(), status::kPowerOn));
        EXPECT_TRUE(bit_set(r.status(), status::kMovement)) << how;  // still turning
        const std::int64_t ms = r.run_until_idle();
        return std::make_pair(ms, r.read(Var::Position) - p0);
    };
    const auto [sc_ms, sc_dist] = run_down("SC");
    const auto [off_ms, off_dist] = run_down("OFF");
    // 600 rpm = 100000 inc/s at the cut: SC runs v*tau = 2000 inc down (tau
    // 20 ms, ~0.24 s), OFF 20000 inc (tau 0.2 s, ~2.4 s).
    EXPECT_NEAR(sc_dist, 2000, 2);
    EXPECT_NEAR(off_dist, 20000, 2);
    EXPECT_LT(sc_ms * 5, off_ms);
}

// ---- 4.8: MODULE_RESET stops short-circuited until standstill -----------------------------
TEST(DmacAudit, ModuleResetRunsTheRotorDownShortCircuited) {
    Rig r;
    r.tx("00BRAKE OFF, #ACCEL_TIME:=100, MOVE_SPEED 60000");
    r.ms(500);
    const std::int32_t p0 = r.read(Var::Position);
    r.tx("00MODULE_RESET");
    EXPECT_TRUE(bit_set(r.status(), status::kMovement));  // was an instant halt
    EXPECT_FALSE(bit_set(r.status(), status::kPowerOn));
    EXPECT_GT(r.run_until_idle(), 100);
    EXPECT_NEAR(r.read(Var::Position) - p0, 2000, 2);  // as POWER SC: v * 20 ms
}

// ---- 5.8, annex 7.2: analog inputs per model ---------------------------------------------
TEST(DmacAudit, AnalogInputsPerModel) {
    Rig r34;
    r34.sim->set_analog(1, -3200);
    r34.sim->set_analog(2, 1500);
    EXPECT_EQ(r34.tx("00READ #INPUT_ANALOG"), "");  // a DMAC34 has #INPUT_A1/#INPUT_A2
    EXPECT_TRUE(bit_set(r34.sim->state().error, error::kSyntax));
    EXPECT_EQ(r34.tx("00READ #IA1"), "00#IA1=-3200\r\n");
    EXPECT_EQ(r34.tx("00READ #IA2"), "00#IA2=+1500\r\n");
    Rig r23(0, Model::Dmac23_2);
    r23.sim->set_analog(1, -3200);
    EXPECT_THROW(r23.sim->set_analog(2, 1), InvalidArgument);
    EXPECT_EQ(r23.tx("00READ #INPUT_ANALOG"), "00#IAN=-3200\r\n");
    EXPECT_EQ(r23.tx("00READ #IA1"), "");
}

TEST(DmacAudit, ClientAnalogInputFollowsTheModel) {
    ClientBench b34;
    b34.sim->set_analog(1, 4520);
    EXPECT_EQ(b34.client->analog_input(1), 4520);  // read #INPUT_ANALOG, which a DMAC34 lacks
    ClientBench b17(Model::Dmac17);
    b17.sim->set_analog(1, -100);
    EXPECT_EQ(b17.client->analog_input(1), -100);
    EXPECT_THROW(b17.client->analog_input(2), InvalidArgument);
}

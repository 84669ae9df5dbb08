// The generic CiA 402 simulator over an in-process CAN bus with the generic
// SdoClient as the host: its dictionary, the handshake and the modes through
// SDO, RPDO + SYNC, the heartbeat consumer, the SimulatedDevice contract.  Motion
// time is a SimClock advanced by the test.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/drives/cia402/sim.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::cia402;
using namespace std::chrono_literals;

namespace {

can::Frame frame(std::uint32_t id, std::vector<std::uint8_t> data) { return can::Frame::make(id, data); }

std::uint32_t abort_of(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const canopen::SdoAbortError& e) {
        return e.code;
    }
    return 0;
}

struct SimRig : ::testing::Test {
    SimClock clock{1'000'000'000};
    std::string hub = "cia402-" + std::to_string(reinterpret_cast<std::uintptr_t>(this));
    std::shared_ptr<can::VirtualBus> dev = can::open_virtual(hub);
    std::shared_ptr<can::VirtualBus> host = can::open_virtual(hub);
    std::unique_ptr<Sim> sim;
    std::unique_ptr<canopen::SdoClient> sdo;

    void SetUp() override {
        sim = std::make_unique<Sim>(5, clock);
        sim->attach(dev);
        sdo = std::make_unique<canopen::SdoClient>(*host, 5);
    }
    void TearDown() override {
        sdo.reset();
        sim.reset();
    }
    void enable(std::int8_t mode) {
        sdo->write_i8(0x6060, 0, mode);
        for (std::uint16_t cw : {0x06, 0x07, 0x0F}) sdo->write_u16(0x6040, 0, cw);
    }
    template <class F>
    bool run_until(F done, double seconds = 5) {
        for (int i = 0; i < seconds * 100; ++i) {
            if (done()) return true;
            clock.advance(10'000'000);
        }
        return done();
    }
    std::uint16_t statusword() { return sdo->read_u16(0x6041, 0); }
};

}  // namespace

TEST(Cia402SimTable, ServesTheStandardObjectsWithTheirDefaults) {
    std::set<std::pair<int, int>> have;
    for (const auto& r : objects()) have.insert({r.index, r.sub});
    for (std::pair<int, int> o : {std::pair{0x6040, 0}, {0x6041, 0}, {0x6060, 0}, {0x6061, 0}, {0x607A, 0}, {0x6081, 0},
                                  {0x6083, 0}, {0x6084, 0}, {0x6064, 0}, {0x606C, 0}, {0x60FF, 0}, {0x6098, 0},
                                  {0x6099, 1}, {0x6099, 2}, {0x609A, 0}, {0x607C, 0}, {0x603F, 0}, {0x6067, 0},
                                  {0x6065, 0}, {0x607D, 1}, {0x607D, 2}, {0x6085, 0}, {0x6086, 0}, {0x60FD, 0},
                                  {0x6007, 0}, {0x605A, 0}, {0x6502, 0}, {0x1000, 0}, {0x1018, 4}})
        EXPECT_TRUE(have.count(o)) << std::hex << o.first << ":" << o.second;
}

TEST_F(SimRig, DictionaryDefaultsIdentityAndRangeChecks) {
    EXPECT_EQ(sdo->read_u32(0x1000, 0), 0x00420192u);
    EXPECT_EQ(sdo->read_u32(0x1018, 2), 0x402u);
    EXPECT_EQ(sdo->read_u32(0x1018, 4), 5u);  // serial = node-ID
    EXPECT_EQ(sdo->read_string(0x1008, 0), "motorbus CiA 402 sim");
    EXPECT_EQ(sdo->read_u32(0x6081, 0), 1000u);
    EXPECT_EQ(sdo->read_i8(0x6098, 0), 19);
    EXPECT_EQ(sdo->read_u32(0x6099, 1), 5000u);
    EXPECT_EQ(sdo->read_i32(0x607D, 1), std::numeric_limits<std::int32_t>::min());
    EXPECT_EQ(sdo->read_u32(0x6502, 0), 0b100101u);
    EXPECT_EQ(canopen::decode_statusword(statusword()), canopen::Cia402State::SwitchOnDisabled);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x6081, 0, 0); }), 0x06090032u);      // below 1
    EXPECT_EQ(abort_of([&] { sdo->write_i8(0x6060, 0, 4); }), 0x06090030u);       // torque: not supported
    EXPECT_EQ(abort_of([&] { sdo->write_i8(0x6098, 0, 1); }), 0x06090030u);       // method 1: not simulated
    EXPECT_EQ(abort_of([&] { sdo->write_i16(0x6007, 0, 9); }), 0x06090031u);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x1010, 1, 0x12345678); }), 0x08000020u);  // not "save"
    sdo->write_u32(0x1010, 1, 0x65766173);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x6064, 0, 1); }), 0x06010002u);      // read-only
}

TEST_F(SimRig, ProfilePositionMoveThroughSdo) {
    sdo->write_u32(0x6081, 0, 20000);
    sdo->write_u32(0x6083, 0, 100000);
    sdo->write_u32(0x6084, 0, 100000);
    EXPECT_EQ(sdo->read_u32(0x6081, 0), 20000u);  // kept in the dictionary
    enable(1);
    EXPECT_EQ(sdo->read_i8(0x6061, 0), 1);
    sdo->write_i32(0x607A, 0, -3000);
    sdo->write_u16(0x6040, 0, 0x1F);
    EXPECT_TRUE(statusword() & canopen::sw::kSetPointAck);
    sdo->write_u16(0x6040, 0, 0x0F);
    EXPECT_FALSE(statusword() & canopen::sw::kSetPointAck);
    ASSERT_TRUE(run_until([&] { return (statusword() & canopen::sw::kTargetReached) != 0; }));
    EXPECT_EQ(sdo->read_i32(0x6064, 0), -3000);
    EXPECT_EQ(sdo->read_i32(0x606C, 0), 0);
    EXPECT_EQ(sim->last_setpoint_ns(), std::optional<Nanos>(1'000'000'000));
}

TEST_F(SimRig, ProfileVelocityAndHomingThroughSdo) {
    sdo->write_u32(0x6083, 0, 100000);
    sdo->write_i32(0x60FF, 0, 4000);
    enable(3);
    ASSERT_TRUE(run_until([&] { return sdo->read_i32(0x606C, 0) == 4000; }, 1));
    sdo->write_i32(0x60FF, 0, 0);
    ASSERT_TRUE(run_until([&] { return sdo->read_i32(0x606C, 0) == 0; }, 1));
    // Homing 19 (home switch 1000..1400) with 607Ch = 100.
    sdo->write_i32(0x607C, 0, 100);
    sdo->write_i8(0x6060, 0, 6);
    sdo->write_u16(0x6040, 0, 0x1F);
    ASSERT_TRUE(run_until([&] { return (statusword() & 0x3400) == 0x1400; }, 5));  // reached + attained
    EXPECT_EQ(sdo->read_i32(0x6064, 0), 100);
}

TEST_F(SimRig, FaultsShowIn603FAnd1001AndDigitalInputs) {
    sim->inject_fault(0x5441);
    EXPECT_EQ(canopen::decode_statusword(statusword()), canopen::Cia402State::Fault);
    EXPECT_EQ(sdo->read_u16(0x603F, 0), 0x5441);
    EXPECT_EQ(sdo->read_u8(0x1001, 0), 1);
    sim->force_limit(-1, true);
    sim->set_stop_input(true);
    EXPECT_EQ(sdo->read_u32(0x60FD, 0), 1u | (1u << 16));
}

TEST_F(SimRig, ASynchronousRpdoAppliesTargetAndControlwordOnSync) {
    sdo->write_u32(0x6081, 0, 20000);
    enable(1);
    // RPDO 1: 607Ah + 6040h, transmission type 1 (synchronous), COB-ID 0x205.
    sdo->write_u32(0x1400, 1, 0x80000205);
    sdo->write_u8(0x1400, 2, 1);
    sdo->write_u8(0x1600, 0, 0);
    sdo->write_u32(0x1600, 1, 0x607A0020);
    sdo->write_u32(0x1600, 2, 0x60400010);
    sdo->write_u8(0x1600, 0, 2);
    sdo->write_u32(0x1400, 1, 0x00000205);
    host->send(frame(0x000, {0x01, 5}));  // NMT start
    host->send(frame(0x205, {0xD0, 0x07, 0, 0, 0x1F, 0}));  // 2000, cw 0x1F
    std::this_thread::sleep_for(50ms);
    EXPECT_FALSE(sim->last_setpoint_ns().has_value());  // held until the SYNC
    host->send(frame(0x080, {}));
    for (int i = 0; i < 200 && !sim->last_setpoint_ns(); ++i) std::this_thread::sleep_for(5ms);
    ASSERT_TRUE(sim->last_setpoint_ns().has_value());
    EXPECT_EQ(sim->pdo()->engine().counters().rpdo_applied, 1u);
    ASSERT_TRUE(run_until([&] { return (statusword() & canopen::sw::kTargetReached) != 0; }));
    EXPECT_EQ(sdo->read_i32(0x6064, 0), 2000);
}

TEST_F(SimRig, ALostMasterHeartbeatAppliesTheAbortConnectionOption) {
    sdo->write_i16(0x6007, 0, 1);                   // fault
    sdo->write_u32(0x1016, 1, (127u << 16) | 50);   // consume node 127 every 50 ms
    enable(1);
    host->send(frame(0x77F, {0x05}));  // one heartbeat, then none
    for (int i = 0; i < 100 && !sim->lost_master(); ++i) std::this_thread::sleep_for(10ms);
    ASSERT_TRUE(sim->lost_master());
    EXPECT_EQ(canopen::decode_statusword(statusword()), canopen::Cia402State::Fault);
    EXPECT_EQ(sdo->read_u16(0x603F, 0), 0x8130);
    EXPECT_EQ(sdo->read_u8(0x1001, 0), 0x11);
}

TEST_F(SimRig, RequestsAreServedOnTheBusThreadNotTheNodesWorker) {
    // LocalNodeOptions::sdo_inline: a request is served on the thread the bus delivers it
    // on (where the sim's endpoint runs its subscribers), not handed to the node's worker
    // thread through its one-slot mailbox.
    std::atomic<std::thread::id> served_on{}, delivered_on{};
    const auto sub = dev->subscribe_id(0x605, false, [&](const can::Frame&) {
        delivered_on = std::this_thread::get_id();
    });
    sim->od().at(0x1008, 0)->set_read_hook([&](const canopen::Variable&, canopen::Bytes&) -> std::uint32_t {
        served_on = std::this_thread::get_id();
        return 0;
    });
    EXPECT_EQ(sdo->read_string(0x1008, 0), "motorbus CiA 402 sim");
    dev->unsubscribe(sub);
    EXPECT_NE(served_on.load(), std::thread::id{});
    EXPECT_EQ(served_on.load(), delivered_on.load());
}

TEST(Cia402SimLifetime, ADictionaryThatOutlivesItsSimulatorNoLongerReachesIt) {
    // Python may hold sim.od after the simulator is gone: the destructor takes its hooks
    // off, so a read or write is the dictionary's own (under ASan, a hook left behind is
    // a use after free).
    SimClock clock{0};
    std::shared_ptr<canopen::ObjectDictionary> od;
    {
        Sim sim(5, clock);
        od = sim.od_ptr();
        canopen::Bytes b;
        ASSERT_EQ(od->at(0x6041, 0)->remote_read(b), 0u);
        EXPECT_EQ(b.size(), 2u);
    }
    canopen::Bytes b;
    EXPECT_EQ(od->at(0x6041, 0)->remote_read(b), 0u);
    EXPECT_EQ(b, (canopen::Bytes{0, 0}));  // the stored default: no axis behind it any more
    const std::uint8_t cw[] = {0x06, 0x00};
    EXPECT_EQ(od->at(0x6040, 0)->remote_write(cw), 0u);
    EXPECT_FALSE(od->at(0x6041, 0)->has_hooks());
}

TEST_F(SimRig, SimulatedDeviceContract) {
    EXPECT_TRUE(sim->attached());
    EXPECT_EQ(sim->describe(), "cia402 sim node 5");
    EXPECT_THROW(sim->attach(dev), InvalidArgument);
    EXPECT_THROW(sim->attach(nullptr), InvalidArgument);
    sdo->write_u32(0x6081, 0, 1234);
    enable(1);
    sim->power_cycle();  // volatile settings lost, boot-up, served again
    EXPECT_TRUE(sim->attached());
    EXPECT_EQ(sdo->read_u32(0x6081, 0), 1000u);
    EXPECT_EQ(canopen::decode_statusword(statusword()), canopen::Cia402State::SwitchOnDisabled);
    sim->close();
    sim->close();  // idempotent
    EXPECT_FALSE(sim->attached());
    sdo->set_timeout(100ms);
    EXPECT_THROW(sdo->read_u32(0x6081, 0), TimeoutError);
    sim->attach(dev);  // again, state kept
    EXPECT_EQ(sdo->read_u32(0x1018, 4), 5u);
    EXPECT_THROW(Sim(0, clock), InvalidArgument);
    SimOptions bad;
    bad.heartbeat_ms = 70000;
    EXPECT_THROW(Sim(6, clock, bad), InvalidArgument);
}

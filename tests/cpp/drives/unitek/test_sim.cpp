// UNITEK simulator and client together on a virtual bus, on a SimClock: the
// manual's exchanges (ex 8-10-1), cyclic transmissions, events, motion, EEPROM.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/drives/unitek/client.hpp"
#include "motorbus/drives/unitek/sim.hpp"

using namespace motorbus;
using namespace motorbus::unitek;
using Bytes = std::vector<std::uint8_t>;
using namespace std::chrono_literals;

namespace {
int rig_no = 0;

struct Rig {
    SimClock clock{1'000'000'000};
    std::shared_ptr<can::Bus> sim_bus, host_bus, spy_bus;
    std::unique_ptr<Sim> sim;
    std::unique_ptr<Client> client;
    std::mutex m;
    std::vector<can::Frame> seen;  // everything on the bus, as a third node sees it

    explicit Rig(SimConfig cfg = {}) {
        const std::string name = "unitek-test-" + std::to_string(rig_no++);
        sim_bus = can::open_virtual(name);
        host_bus = can::open_virtual(name);
        spy_bus = can::open_virtual(name);
        spy_bus->subscribe(can::Filter{}, [this](const can::Frame& f) {
            std::lock_guard l(m);
            seen.push_back(f);
        });
        sim = std::make_unique<Sim>(clock, cfg);
        sim->attach(sim_bus);
        ClientOptions o;
        o.clock = &clock;
        o.timeout = 500ms;
        client = std::make_unique<Client>(*host_bus, RegisterTable::builtin(), o);
    }
    ~Rig() {
        // The spy's receive thread writes `seen`, a member destroyed before spy_bus:
        // stop it first (TSan found the race).
        spy_bus->close();
        client.reset();
        sim.reset();
    }
    // Frames seen so far on `id`, waiting until at least `n` arrived.
    std::vector<can::Frame> frames(std::uint32_t id, std::size_t n, std::chrono::milliseconds wait = 1000ms) {
        const auto end = std::chrono::steady_clock::now() + wait;
        for (;;) {
            std::vector<can::Frame> out;
            {
                std::lock_guard l(m);
                for (auto& f : seen)
                    if (f.id == id) out.push_back(f);
            }
            if (out.size() >= n || std::chrono::steady_clock::now() > end) return out;
            std::this_thread::sleep_for(1ms);
        }
    }
    void clear() {
        std::lock_guard l(m);
        seen.clear();
    }
    // Writes are never acknowledged: wait until the sim has taken every frame the host sent.
    void sync() {
        const auto want = host_bus->counters().tx_frames;
        const auto end = std::chrono::steady_clock::now() + 2s;
        while (std::chrono::steady_clock::now() < end) {
            const auto c = sim->counters();
            if (c.frames_in + c.ignored >= want) return;
            std::this_thread::sleep_for(100us);
        }
        ADD_FAILURE() << "the sim never took the host's frames";
    }
    void step(Nanos dt) {
        sync();
        clock.advance(dt);
        sim->service();
    }
};

Bytes payload(const can::Frame& f) { return {f.data.begin(), f.data.begin() + f.len}; }
}  // namespace

TEST(Sim, Example8ReadStatusOnce) {
    Rig r;
    EXPECT_EQ(r.client->read(kRegStatus), 0x0181);
    auto to = r.frames(0x201, 1);
    ASSERT_EQ(to.size(), 1u);
    EXPECT_EQ(payload(to[0]), (Bytes{0x3D, 0x40, 0x00}));
    auto from = r.frames(0x181, 1);
    ASSERT_EQ(from.size(), 1u);
    EXPECT_EQ(payload(from[0]), (Bytes{0x40, 0x81, 0x01, 0x00}));  // DLC 4, dummy 0x00
}

TEST(Sim, WritesAreNeverAcknowledged) {  // B-U05
    Rig r;
    r.client->write(kRegSpeedCmd, 0);
    r.client->write(kRegAccRamp, 1000);
    r.client->write(kRegEventMask, 0x30);
    r.client->write(0x99 == 0 ? 0 : kRegTorqueCmd, 0);
    EXPECT_EQ(r.client->read(kRegAccRamp), 1000);  // the read is the only frame back
    EXPECT_EQ(r.frames(0x181, 1).size(), 1u);
}

TEST(Sim, Example9CyclicEvery100ms) {
    SimConfig c;
    c.acc_ramp_ms = 0;
    Rig r(c);
    r.client->write(kRegSpeedCmd, 32767);
    r.step(1'000'000);  // ACC 0 ms: full speed from the first instant after the command
    auto s = r.client->subscribe(kRegSpeedActual, 100);
    r.sync();
    const auto wait_count = [&](std::uint64_t n) {
        for (int i = 0; i < 100000 && s->ring.count() < n; ++i) std::this_thread::sleep_for(10us);
    };
    wait_count(1);
    for (int i = 0; i < 10; ++i) {
        r.step(100'000'000);
        wait_count(static_cast<std::uint64_t>(i) + 2);
    }
    auto from = r.frames(0x181, 11);
    ASSERT_EQ(from.size(), 11u);  // the first at once, then one each 100 ms
    for (auto& f : from) EXPECT_EQ(payload(f), (Bytes{0x30, 0xFF, 0x7F, 0x00}));
    r.client->unsubscribe(kRegSpeedActual);
    EXPECT_EQ(payload(r.frames(0x201, 3).back()), (Bytes{0x3D, 0x30, 0xFF}));
    for (int i = 0; i < 10; ++i) r.step(100'000'000);
    EXPECT_EQ(r.sim->sent(kRegSpeedActual), 11u);  // stop ends the stream
    Nanos t[16];
    std::int64_t v[16];
    std::uint64_t cur = 0, lost = 0;
    const auto n = s->ring.read(cur, t, v, 16, lost);
    ASSERT_EQ(n, 11u);
    for (std::size_t i = 1; i < n; ++i) EXPECT_EQ(t[i] - t[i - 1], 100'000'000);
    EXPECT_EQ(lost, 0u);
}

TEST(Sim, EightCyclicAt1msFor10sNoLoss) {
    Rig r;
    const std::uint8_t regs[8] = {kRegSpeedActual, kRegSpeedCmd, kRegAccRamp, kRegStatus,
                                  kRegEventMask, kRegPosDest, kRegTorqueCmd, kRegA8};
    std::vector<std::shared_ptr<Stream>> streams;
    for (auto id : regs) streams.push_back(r.client->subscribe(id, 1, 1 << 14));
    // The 9th: refused by the client before anything is sent.
    Register extra;
    extra.regid = 0x34;
    extra.name = "EXTRA";
    r.client->add_register(extra);
    EXPECT_THROW(r.client->subscribe(0x34, 1), CyclicLimit);
    const auto wait_for = [&](std::uint64_t n) {
        for (int spin = 0; spin < 2'000'000; ++spin) {
            bool all = true;
            for (auto& st : streams) all = all && st->ring.count() >= n;
            if (all) return true;
            std::this_thread::yield();
        }
        return false;
    };
    r.sync();
    EXPECT_EQ(r.sim->cyclic().size(), 8u);
    ASSERT_TRUE(wait_for(1));
    for (int ms = 1; ms <= 10'000; ++ms) {
        r.step(1'000'000);
        ASSERT_TRUE(wait_for(static_cast<std::uint64_t>(ms) + 1)) << "at " << ms << " ms";
    }
    std::vector<Nanos> t(1 << 14);
    std::vector<std::int64_t> v(1 << 14);
    for (auto& st : streams) {
        std::uint64_t cur = 0, lost = 0;
        const auto n = st->ring.read(cur, t.data(), v.data(), t.size(), lost);
        EXPECT_EQ(n, 10'001u);
        EXPECT_EQ(lost, 0u);
        for (std::size_t i = 1; i < n; ++i) ASSERT_EQ(t[i] - t[i - 1], 1'000'000) << i;
    }
    // Stop requests end every stream.
    for (auto id : regs) r.client->unsubscribe(id);
    r.sync();
    EXPECT_TRUE(r.sim->cyclic().empty());
    const auto before = r.sim->counters().frames_out;
    r.step(50'000'000);
    EXPECT_EQ(r.sim->counters().frames_out, before);
}

TEST(Sim, NinthRegisterIgnoredBySim) {  // B-U08
    Rig r;
    for (std::uint8_t id : {0x30, 0x31, 0x35, 0x40, 0x52, 0x6E, 0x90, 0xA8})
        r.host_bus->send(can::Frame::make(0x201, Bytes{0x3D, id, 0x0A}));
    r.host_bus->send(can::Frame::make(0x201, Bytes{0x3D, 0x31, 0x14}));  // repeated: replaces the period
    r.sync();
    const auto seen = r.frames(0x181, 9);
    ASSERT_EQ(seen.size(), 9u);
    // A 9th register (0x68 is write-only: use a user row on a sim with a longer table).
    RegisterTable t = RegisterTable::builtin();
    Register extra;
    extra.regid = 0x34;
    extra.name = "EXTRA";
    t.add(extra);
    SimClock clock;
    Sim sim(clock, {}, t);
    std::vector<can::Frame> out;
    sim.set_output([&](const can::Frame& f) { out.push_back(f); });
    for (std::uint8_t id : {0x30, 0x31, 0x35, 0x40, 0x52, 0x6E, 0x90, 0xA8, 0x34})
        sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, id, 0x0A}));
    EXPECT_EQ(out.size(), 8u);
    EXPECT_EQ(sim.cyclic().size(), 8u);
    EXPECT_EQ(sim.counters().cyclic_refused, 1u);
    auto c = r.sim->cyclic();
    ASSERT_EQ(c.size(), 8u);
    for (auto [id, ms] : c) EXPECT_EQ(ms, id == 0x31 ? 20 : 10);
    // FF on a register that is not cyclic: ignored.
    sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, 0x68, 0xFF}));
    EXPECT_EQ(sim.cyclic().size(), 8u);
}

TEST(Sim, OnceOnACyclicRegisterKeepsTheStream) {  // B-U07
    SimClock clock;
    Sim sim(clock);
    std::vector<can::Frame> out;
    sim.set_output([&](const can::Frame& f) { out.push_back(f); });
    sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, 0x30, 0x0A}));  // every 10 ms, first at once
    EXPECT_EQ(out.size(), 1u);
    clock.advance(5'000'000);
    sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, 0x30, 0x00}));  // once: answered, stream kept
    EXPECT_EQ(out.size(), 2u);
    clock.advance(5'000'000);
    sim.service();
    EXPECT_EQ(out.size(), 3u);  // the stream's own phase: t = 10 ms
    ASSERT_EQ(sim.cyclic().size(), 1u);
    sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, 0x30, 0x14}));  // repeated: 20 ms, restarts now
    EXPECT_EQ(out.size(), 4u);
    clock.advance(19'000'000);
    sim.service();
    EXPECT_EQ(out.size(), 4u);
    clock.advance(1'000'000);
    sim.service();
    EXPECT_EQ(out.size(), 5u);
    // A late service catches up every due frame, in order, each with its own due time.
    clock.advance(100'000'000);
    sim.service();
    ASSERT_EQ(out.size(), 10u);
    for (std::size_t i = 6; i < out.size(); ++i) EXPECT_EQ(out[i].timestamp_ns - out[i - 1].timestamp_ns, 20'000'000);
}

TEST(Sim, Example10EventOnTol) {
    Rig r;
    r.sim->set_calibrated(true);
    std::atomic<int> events{0};
    r.client->on_status([&](std::uint32_t, Nanos) { ++events; });
    r.client->set_events(true);
    EXPECT_EQ(payload(r.frames(0x201, 1).back()), (Bytes{0x51, 0x10, 0x00}));
    r.step(10'000'000);
    EXPECT_EQ(r.sim->counters().events_out, 0u);  // no frame at activation (C-U12)
    r.client->write(kRegPosDest, 65536);           // one revolution
    for (int i = 0; i < 300 && !(r.sim->status() & kStatusTol); ++i) r.step(10'000'000);
    ASSERT_TRUE(r.sim->status() & kStatusTol);
    auto from = r.frames(0x181, 1);
    ASSERT_EQ(from.size(), 1u);
    EXPECT_EQ(payload(from[0]), (Bytes{0x40, 0x81, 0x31, 0x00, 0x00, 0x00}));  // DLC 6, 0x3181
    for (int i = 0; i < 100 && events.load() < 1; ++i) std::this_thread::sleep_for(1ms);
    EXPECT_EQ(r.client->last_event_status(), 0x3181u);
    // Example 10-1: mask 0x0012 -> limit switches.
    r.clear();
    r.client->set_events(true, 0x0012);
    r.sync();
    r.sim->force_limit(+1, true);
    from = r.frames(0x181, 1);
    ASSERT_EQ(from.size(), 1u);
    EXPECT_EQ(payload(from[0]), (Bytes{0x40, 0x85, 0x31, 0x00, 0x00, 0x00}));
    // Cal changes no longer trigger with this mask; events off stops them.
    r.sim->set_calibrated(false);
    r.client->set_events(false);
    r.sync();
    r.sim->force_limit(+1, false);
    r.step(1'000'000);
    EXPECT_EQ(r.frames(0x181, 2, 50ms).size(), 1u);
}

TEST(Sim, DisableAndHardwareEnable) {  // ex 2, B-U11
    Rig r;
    r.client->disable();
    EXPECT_EQ(payload(r.frames(0x201, 1).back()), (Bytes{0x51, 0x04, 0x00}));
    EXPECT_EQ(r.client->read(kRegStatus), 0x0180);
    r.client->enable();
    EXPECT_EQ(r.client->read(kRegStatus), 0x0181);
    r.sim->set_hardware_enable(false);
    EXPECT_EQ(r.client->read(kRegStatus), 0x0180);
    r.client->write(kRegSpeedCmd, 10000);  // no motion without Ena
    r.sync();
    r.step(500'000'000);
    EXPECT_EQ(r.sim->position_num(), 0.0);
}

TEST(Sim, SpeedRampFollowsAcc) {  // ex 3, ex 6, B-U24
    Rig r;
    r.client->write(kRegAccRamp, 1000);
    r.client->write(kRegSpeedCmd, 3277);  // 10 %: 100 ms of ramp
    r.step(50'000'000);
    EXPECT_NEAR(r.sim->speed_num(), 1638.5, 20);
    r.step(100'000'000);
    EXPECT_NEAR(r.sim->speed_num(), 3277, 1);
    EXPECT_EQ(r.client->read(kRegSpeedActual), 3277);
    r.client->write(kRegSpeedCmd, 0);
    r.step(2'000'000'000);
    EXPECT_NEAR(r.sim->speed_num(), 0, 1e-6);
}

TEST(Sim, PositionToPosDestWithTol) {  // ex 4
    Rig r;
    r.client->write(kRegAccRamp, 100);
    r.client->write(kRegPosDest, 3000000);
    EXPECT_EQ(r.client->read(kRegStatus) & kStatusTol, 0);
    for (int i = 0; i < 100; ++i) r.step(100'000'000);
    EXPECT_NEAR(r.sim->position_num(), 3000000, 1);
    EXPECT_EQ(r.client->read(kRegPosDest), 3000000);
    EXPECT_TRUE(r.client->read(kRegStatus) & kStatusTol);
}

TEST(Sim, TorqueAndContinuousCurrentLimit) {  // ex 5
    SimConfig c;
    c.torque_continuous_num = 10000;
    Rig r(c);
    r.client->write(kRegTorqueCmd, 16380);
    r.step(100'000'000);
    EXPECT_GT(r.sim->speed_num(), 0);
    EXPECT_TRUE(r.sim->status() & kStatusIcns);
    EXPECT_EQ(r.client->read(kRegTorqueCmd), 16380);
    r.client->write(kRegTorqueCmd, 5000);
    r.sync();
    EXPECT_FALSE(r.sim->status() & kStatusIcns);
}

TEST(Sim, LimitSwitchStopsMotionTowardsIt) {
    SimConfig c;
    c.plus_limit_num = 65536;
    c.acc_ramp_ms = 10;
    Rig r(c);
    r.client->write(kRegSpeedCmd, 3277);
    for (int i = 0; i < 100; ++i) r.step(10'000'000);
    EXPECT_TRUE(r.sim->status() & kStatusLimPlus);
    EXPECT_EQ(r.client->read(kRegStatus) & kStatusLimPlus, kStatusLimPlus);
    EXPECT_NEAR(r.sim->speed_num(), 0, 1e-6);
    EXPECT_LT(r.sim->position_num(), 65536 + 5000);
}

TEST(Sim, ReceiveIdChangeAndEepromAcrossPowerCycle) {  // ex 1, ex 7, B-U12, B-U13
    Rig r;
    r.client->write(kRegAccRamp, 250);
    r.client->set_receive_id(0x210);
    r.sync();
    EXPECT_EQ(payload(r.frames(0x201, 2).back()), (Bytes{0x68, 0x10, 0x02}));
    EXPECT_EQ(r.sim->rx_id(), 0x210u);
    EXPECT_EQ(r.client->read(kRegAccRamp), 250);  // now on 0x210
    r.host_bus->send(can::Frame::make(0x201, Bytes{0x35, 0x10, 0x00}));  // old id: ignored
    EXPECT_EQ(r.client->read(kRegAccRamp), 250);
    r.sync();
    r.sim->power_cycle();  // not stored: back to 0x201 and the factory ramp
    EXPECT_EQ(r.sim->rx_id(), 0x201u);
    EXPECT_EQ(r.sim->value(kRegAccRamp), 1000);
    r.client.reset();
    ClientOptions o;
    o.clock = &r.clock;
    r.client = std::make_unique<Client>(*r.host_bus, RegisterTable::builtin(), o);
    r.client->write(kRegAccRamp, 250);
    r.client->set_receive_id(0x210);
    r.client->store_eeprom(0);
    r.client->write(kRegAccRamp, 500);  // after the store: lost at power off
    r.sync();
    r.sim->power_cycle();
    EXPECT_EQ(r.sim->rx_id(), 0x210u);
    EXPECT_EQ(r.client->read(kRegAccRamp), 250);
    EXPECT_THROW(r.client->store_eeprom(2), InvalidArgument);
}

TEST(Sim, HostileFramesToTheDrive) {  // R1-R3, B-U20, B-U22
    SimClock clock;
    Sim sim(clock);
    std::vector<can::Frame> out;
    sim.set_output([&](const can::Frame& f) { out.push_back(f); });
    for (std::size_t n = 0; n < 3; ++n) sim.on_frame(can::Frame::make(0x201, Bytes(n, 0x3D)));
    EXPECT_EQ(sim.counters().malformed, 3u);
    sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, 0x40, 0x00, 0x99}));  // DLC 4 = 3
    sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, 0x40, 0x00, 0x00, 0x00, 1, 2, 3}));  // DLC 8 = 5
    EXPECT_EQ(out.size(), 2u);
    sim.on_frame(can::Frame::make(0x202, Bytes{0x3D, 0x40, 0x00}));  // another node's id
    sim.on_frame(can::Frame::make(0x201, Bytes{0x3D, 0x99, 0x00}));  // unknown REGID read: no reply
    sim.on_frame(can::Frame::make(0x201, Bytes{0x99, 0x01, 0x00}));  // unknown write: ignored
    EXPECT_EQ(out.size(), 2u);
    EXPECT_EQ(sim.counters().unknown, 2u);
    sim.on_frame(can::Frame::make(0x201, Bytes{0x30, 0x01, 0x00}));  // read-only
    sim.on_frame(can::Frame::make(0x201, Bytes{0x68, 0x00, 0x03}));  // rx id out of range
    sim.on_frame(can::Frame::make(0x201, Bytes{0x84, 0x02, 0x00}));  // EEPROM level 2
    EXPECT_EQ(sim.counters().refused, 3u);
    EXPECT_EQ(sim.rx_id(), 0x201u);
    // A 16-bit register written with DLC 5 takes the low 16 bits (B-U03).
    sim.on_frame(can::Frame::make(0x201, Bytes{0x35, 0xE8, 0x03, 0xAA, 0xBB}));
    EXPECT_EQ(sim.value(kRegAccRamp), 1000);
    // A signed 32-bit register written with DLC 3 sign-extends.
    sim.on_frame(can::Frame::make(0x201, Bytes{0x6E, 0xFF, 0xFF}));
    EXPECT_EQ(sim.value(kRegPosDest), -1);
}

TEST(Client, HostileRepliesAreCountedNotUsed) {  // R1, R4
    Rig r;
    auto fake = can::open_virtual("unitek-test-" + std::to_string(rig_no - 1));
    fake->send(can::Frame::make(0x181, Bytes{0x40, 0x81, 0x01}));         // DLC 3
    fake->send(can::Frame::make(0x181, Bytes{0x40, 0x81, 0x01, 0, 0}));   // DLC 5
    fake->send(can::Frame::make(0x181, Bytes{0x30, 0x00, 0x10, 0}));      // unsolicited
    fake->send(can::Frame::make(0x182, Bytes{0x30, 0x00, 0x10, 0}));      // another node
    const auto end = std::chrono::steady_clock::now() + 1s;
    while (r.client->counters().rejected + r.client->counters().unsolicited < 3 && std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(1ms);
    EXPECT_EQ(r.client->counters().rejected, 2u);
    EXPECT_EQ(r.client->counters().unsolicited, 1u);
    EXPECT_EQ(r.client->read(kRegStatus), 0x0181);  // nothing stale was queued
    EXPECT_THROW(r.client->write(0x99, 1), UnknownRegister);
    EXPECT_THROW(r.client->read(0x99), UnknownRegister);
    EXPECT_THROW(r.client->write(kRegSpeedActual, 1), InvalidArgument);
    EXPECT_THROW(r.client->write(kRegSpeedCmd, 40000), InvalidArgument);
    EXPECT_THROW(r.client->read(kRegMode), InvalidArgument);  // write-only
}

TEST(Client, CloseStopsItsStreams) {
    Rig r;
    r.client->subscribe(kRegSpeedActual, 10);
    r.client->subscribe(kRegStatus, 20);
    r.sync();
    EXPECT_EQ(r.sim->cyclic().size(), 2u);
    r.client->close();
    r.sync();
    EXPECT_TRUE(r.sim->cyclic().empty());
    EXPECT_THROW(r.client->write(kRegSpeedCmd, 0), ClosedError);
}

TEST(Client, ReadTimesOutWithoutADrive) {
    auto bus = can::open_virtual("unitek-lonely");
    ClientOptions o;
    o.timeout = 20ms;
    Client c(*bus, RegisterTable::builtin(), o);
    EXPECT_THROW(c.read(kRegStatus), TimeoutError);
}

TEST(Client, RingBufferReaderRacingTheWriter) {
    // One writer (the bus thread), one reader: every sample comes out in order or is
    // counted lost; none is read twice.
    RingBuffer ring(64);
    constexpr std::uint64_t kTotal = 200'000;
    std::thread writer([&] {
        for (std::uint64_t k = 0; k < kTotal; ++k) ring.push(static_cast<Nanos>(k), static_cast<std::int64_t>(k));
    });
    std::uint64_t cursor = 0, lost = 0, got = 0;
    std::int64_t last = -1;
    Nanos t[32];
    std::int64_t v[32];
    while (cursor < kTotal) {
        const auto n = ring.read(cursor, t, v, 32, lost);
        for (std::size_t i = 0; i < n; ++i) {
            if (v[i] <= last || t[i] != v[i]) ADD_FAILURE() << "sample " << v[i] << " after " << last;
            last = v[i];
        }
        got += n;
    }
    writer.join();
    EXPECT_EQ(cursor, kTotal);
    EXPECT_EQ(got + lost, kTotal);
}

// ---- issue 23 items 15, 16 -----------------------------------------------------------------

namespace {
// The value of the one reply to `3D regid 00` (16-bit, sign-extended when asked).
std::int64_t ask(Sim& sim, std::vector<can::Frame>& out, std::uint8_t regid, bool is_signed = false) {
    out.clear();
    sim.on_frame(can::Frame::make(sim.rx_id(), Bytes{0x3D, regid, 0x00}));
    EXPECT_EQ(out.size(), 1u);
    if (out.empty()) return -999999;
    const auto d = out.front().payload();
    const auto v = static_cast<std::uint16_t>(d[1] | (d[2] << 8));
    return is_signed ? static_cast<std::int16_t>(v) : v;
}
}  // namespace

TEST(Sim, EepromKeepsEveryWritableRegister) {  // B-U13, issue 23 item 15
    SimClock clock;
    Sim sim(clock);
    std::vector<can::Frame> out;
    sim.set_output([&](const can::Frame& f) { out.push_back(f); });
    const std::vector<Bytes> writes = {{0x51, 0x14, 0x00}, {0x35, 0xF4, 0x01}, {0x52, 0x12, 0x00},
                                       {0x31, 0xCD, 0x0C}, {0x90, 0xFC, 0x3F}, {0x24, 0x64, 0x00},
                                       {0x26, 0xB3, 0xFF}, {0x6E, 0xC0, 0xC6, 0x2D, 0x00}};
    for (const auto& w : writes) sim.on_frame(can::Frame::make(0x201, w));
    sim.on_frame(can::Frame::make(0x201, Bytes{0x84, 0x01, 0x00}));
    EXPECT_EQ(sim.counters().refused + sim.counters().unknown, 0u);
    for (const auto& w : writes) {  // RAM changes after the store: lost at power off
        Bytes c = w;
        c[1] ^= 0x01;
        sim.on_frame(can::Frame::make(0x201, c));
    }
    sim.power_cycle();
    const auto ee = sim.eeprom();
    for (auto id : {0x31, 0x35, 0x51, 0x52, 0x68, 0x6E, 0x90, 0x24, 0x26}) EXPECT_EQ(ee.count(id), 1u) << id;
    EXPECT_EQ(ee.count(kRegEeprom), 0u);  // the store command keeps no value
    EXPECT_EQ(ask(sim, out, 0x35), 500);
    EXPECT_EQ(ask(sim, out, 0x52), 0x12);
    EXPECT_EQ(ask(sim, out, 0x31, true), 3277);
    EXPECT_EQ(ask(sim, out, 0x90, true), 16380);
    EXPECT_EQ(ask(sim, out, 0x24), 100);
    EXPECT_EQ(ask(sim, out, 0x26, true), -77);
    EXPECT_EQ(sim.value(kRegPosDest), 3000000);
    EXPECT_EQ(sim.status() & kStatusEna, 0u);  // stored MODE bit 2: disabled from power-up
    EXPECT_EQ(sim.speed_num(), 0.0);          // a stored set-point starts nothing
}

TEST(Sim, CurrentCommandNineBitsAndTheSmallerLimit) {  // §6.1, B-U17, issue 23 item 16
    SimClock clock;
    SimConfig cfg;
    cfg.device = "DS 412";
    cfg.motor_i_max_num = 120;
    Sim sim(clock, cfg);
    std::vector<can::Frame> out;
    sim.set_output([&](const can::Frame& f) { out.push_back(f); });
    EXPECT_EQ(ask(sim, out, kRegDeviceCurrentMax), 230);
    EXPECT_EQ(ask(sim, out, kRegCurrentLimit), 120);
    sim.on_frame(can::Frame::make(0x201, Bytes{0x26, 0x01, 0xFE}));  // -511
    EXPECT_EQ(ask(sim, out, kRegCurrentActual, true), -120);           // the motor's limit is smaller
    sim.on_frame(can::Frame::make(0x201, Bytes{0x24, 0xFF, 0x01}));  // motor 511 > device 230
    EXPECT_EQ(ask(sim, out, kRegCurrentActual, true), -230);
    sim.on_frame(can::Frame::make(0x201, Bytes{0x26, 0x00, 0x02}));  // 512: beyond 9 bit, ignored
    sim.on_frame(can::Frame::make(0x201, Bytes{0x24, 0x00, 0x02}));
    EXPECT_EQ(sim.counters().refused, 2u);
    EXPECT_EQ(ask(sim, out, kRegCurrentCmd, true), -511);
    sim.set_hardware_enable(false);
    EXPECT_EQ(ask(sim, out, kRegCurrentActual, true), 0);  // power stage off: no current
    cfg.motor_i_max_num = 512;
    EXPECT_THROW(Sim(clock, cfg), InvalidArgument);
    cfg.motor_i_max_num.reset();
    cfg.device = "DS 999";
    EXPECT_THROW(Sim(clock, cfg), InvalidArgument);
}

TEST(Sim, NodeAtAnotherBitRateHearsAndSendsNothing) {  // §3.1, B-U21, issue 23 item 16
    SimClock clock;
    can::VirtualOptions vo;
    vo.bitrate = 250000;
    auto medium = can::open_virtual("unitek-btr-test", vo);
    auto host = can::open_virtual("unitek-btr-test", vo);
    std::atomic<int> seen{0};
    host->subscribe(can::Filter{}, [&](const can::Frame&) { ++seen; });
    SimConfig cfg;  // BTR 0x4025: 500 kbit/s
    Sim sim(clock, cfg);
    sim.attach(medium);
    EXPECT_EQ(sim.bus_bit_rate(), 250000);
    host->send(can::Frame::make(0x201, Bytes{0x3D, 0x40, 0x00}), 100ms);
    const auto end = std::chrono::steady_clock::now() + 2s;
    while (sim.counters().bit_rate_mismatch == 0 && std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(sim.counters().bit_rate_mismatch, 1u);
    EXPECT_EQ(sim.counters().frames_in, 0u);
    EXPECT_EQ(seen.load(), 0);
    sim.close();
    cfg.btr = 0x405C;  // 250 k in NDrive
    Sim at250(clock, cfg);
    at250.attach(medium);
    host->send(can::Frame::make(0x201, Bytes{0x3D, 0x40, 0x00}), 100ms);
    const auto end2 = std::chrono::steady_clock::now() + 2s;
    while (seen.load() == 0 && std::chrono::steady_clock::now() < end2) std::this_thread::sleep_for(1ms);
    EXPECT_EQ(seen.load(), 1);
    at250.close();
    cfg.btr = 0x4026;
    EXPECT_THROW(Sim(clock, cfg), InvalidArgument);
}

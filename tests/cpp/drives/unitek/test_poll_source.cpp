// UNITEK poll sources against the simulator on a virtual bus, on real time:
// the asking source reads the registers; the capture source subscribes their
// cyclic transmission, gives the drive's values with their arrival time, stops
// what it started at close(), counts a push that stopped as stale, and throws
// once the bus is gone.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/drives/unitek/poll_source.hpp"
#include "motorbus/drives/unitek/sim.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::unitek;
using namespace std::chrono_literals;

namespace {
int rig_no = 0;

struct Rig {
    RealClock clock;
    std::shared_ptr<can::Bus> sim_bus, host_bus;
    std::unique_ptr<Sim> sim;
    std::unique_ptr<Client> client;
    Rig() {
        const std::string name = "unitek-poll-" + std::to_string(rig_no++);
        sim_bus = can::open_virtual(name);
        host_bus = can::open_virtual(name);
        sim = std::make_unique<Sim>(clock);
        sim->attach(sim_bus);
        ClientOptions o;
        o.timeout = 500ms;
        client = std::make_unique<Client>(*host_bus, sim_default_table(), o);
    }
    ~Rig() {
        client.reset();
        sim.reset();
    }
};
constexpr std::uint8_t kPos = 0x6D;
}  // namespace

TEST(UnitekPollSource, ReadsTheRegistersEachSample) {
    Rig r;
    r.client->write(kRegPosDest, 0);
    PollSource src(*r.client, {kPos, kRegStatus});
    ASSERT_EQ(src.columns(), 2u);
    double row[2];
    src.read(row);
    EXPECT_EQ(row[0], static_cast<double>(r.client->read(kPos)));
    EXPECT_EQ(row[1], static_cast<double>(r.client->read(kRegStatus)));
    EXPECT_THROW(PollSource(*r.client, {}), InvalidArgument);
    EXPECT_THROW(PollSource(*r.client, {kRegMode}), InvalidArgument);  // write-only
}

TEST(UnitekCaptureSource, CapturesTheCyclicRegistersWithTheirArrival) {
    Rig r;
    CaptureSource src(*r.client, *r.host_bus, {kPos, kRegSpeedActual, kRegStatus}, 1);
    ASSERT_EQ(src.columns(), 4u);
    EXPECT_EQ(r.client->streams().size(), 3u);
    std::this_thread::sleep_for(30ms);
    double row[4];
    const Nanos before = monotonic_ns();
    src.read(row);
    ASSERT_FALSE(std::isnan(row[0]));
    EXPECT_LE(row[0], static_cast<double>(before));
    EXPECT_GT(row[0], static_cast<double>(before - 20'000'000));  // pushed every 1 ms
    EXPECT_EQ(row[1], static_cast<double>(r.client->read(kPos)));
    EXPECT_EQ(row[3], static_cast<double>(r.client->read(kRegStatus)));
    const auto stale_before = src.stale();
    // The drive stops pushing: the arrival time freezes and the reads count as stale.
    src.close();
    EXPECT_TRUE(r.client->streams().empty());
    std::this_thread::sleep_for(20ms);
    double later[4];
    src.read(later);
    EXPECT_EQ(src.stale(), stale_before + 1);
    EXPECT_LT(later[0], static_cast<double>(monotonic_ns() - src.max_age_ns()));
    // A gone bus ends the poll group: read() throws instead of repeating the last values.
    r.host_bus->close();
    EXPECT_THROW(src.read(later), ClosedError);
}

TEST(UnitekCaptureSource, SharesAUsersStreamAndLeavesItRunning) {
    Rig r;
    auto user = r.client->subscribe(kPos, 5);
    {
        CaptureSource src(*r.client, *r.host_bus, {kPos}, 1);
        EXPECT_EQ(src.interval_ms(), 5);   // the user's interval is kept
        std::this_thread::sleep_for(30ms);
        double row[2];
        src.read(row);
        EXPECT_FALSE(std::isnan(row[1]));
    }
    ASSERT_EQ(r.client->streams().size(), 1u);
    EXPECT_TRUE(user->active.load());
    EXPECT_THROW(CaptureSource(*r.client, *r.host_bus, {kPos}, 0), InvalidArgument);
}

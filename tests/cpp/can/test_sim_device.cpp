// can::SimulatedDevice, the contract every simulated CAN device implements,
// driven through the base class only: each simulator is attached to a virtual
// bus the test does not keep, answers one request, is closed (and then silent),
// is attached again and answers again, and neither hears nor is heard on a
// wire of another bit rate.  Four simulators, one test body.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/can/sim_device.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/drives/cia402/sim.hpp"
#include "motorbus/drives/pmc007/sim.hpp"
#include "motorbus/drives/unitek/sim.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/runtime/clock.hpp"

using namespace motorbus;
using namespace std::chrono_literals;

namespace {

// One simulator as the contract sees it, plus what to ask it and how it answers.
struct Case {
    std::string kind;              // what describe() starts with
    std::unique_ptr<can::SimulatedDevice> device;
    can::Frame request;            // a read the device answers
    std::uint32_t reply_id;        // ... on this id
    std::vector<std::uint8_t> reply_prefix;  // ... with these first bytes
};

// A host endpoint that keeps what arrives on one id.
struct Host {
    std::shared_ptr<can::VirtualBus> bus;
    std::mutex m;
    std::vector<can::Frame> got;
    Host(const std::string& hub, std::uint32_t id, const can::VirtualOptions& vo = {}) : bus(can::open_virtual(hub, vo)) {
        bus->subscribe_id(id, false, [this](const can::Frame& f) {
            std::lock_guard l(m);
            got.push_back(f);
        });
    }
    ~Host() { bus->close(); }  // before `got` goes: the receive thread writes it
    std::size_t count() {
        std::lock_guard l(m);
        return got.size();
    }
    // Sends `request` and waits (up to `wait`) for one more frame; returns it, or nullopt.
    std::optional<can::Frame> ask(const can::Frame& request, std::chrono::milliseconds wait = 2000ms) {
        const auto before = count();
        bus->send(request, 100ms);
        const auto end = std::chrono::steady_clock::now() + wait;
        while (count() == before && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(1ms);
        std::lock_guard l(m);
        if (got.size() == before) return std::nullopt;
        return got[before];
    }
};

std::vector<Case> cases(Clock& clock) {
    std::vector<Case> out;
    const std::uint8_t sdo_read_1000[8] = {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0};  // device type
    out.push_back({"pmc007 sim", std::make_unique<pmc007::Sim>(5, clock),
                   can::Frame::make(0x605, sdo_read_1000), 0x585, {0x43, 0x00, 0x10, 0x00}});
    const std::uint8_t read_status[3] = {0x3D, 0x40, 0x00};  // KERN_STATUS once
    out.push_back({"unitek sim", std::make_unique<unitek::Sim>(clock), can::Frame::make(0x201, read_status), 0x181,
                   {0x40}});
    arcus::SimOptions ao;
    ao.comm_type = 2;  // a unit stored as CAN: it answers on its CAN face
    ao.node_id = 3;
    out.push_back({"arcus sim", std::make_unique<arcus::Sim>(clock, ao), can::Frame::make(0x603, sdo_read_1000),
                   0x583, {0x43, 0x00, 0x10, 0x00}});
    out.push_back({"cia402 sim", std::make_unique<cia402::Sim>(7, clock), can::Frame::make(0x607, sdo_read_1000),
                   0x587, {0x43, 0x00, 0x10, 0x00}});
    return out;
}

bool starts_with(const can::Frame& f, const std::vector<std::uint8_t>& prefix) {
    if (f.len < prefix.size()) return false;
    for (std::size_t i = 0; i < prefix.size(); ++i)
        if (f.data[i] != prefix[i]) return false;
    return true;
}

std::string hub_name(const std::string& kind, const char* what) {
    static std::atomic<int> n{0};
    return "simdev-" + kind.substr(0, kind.find(' ')) + "-" + what + "-" + std::to_string(++n);
}

}  // namespace

TEST(SimulatedDevice, AttachAnswerCloseAttachAgain) {
    SimClock clock{1'000'000'000};
    for (auto& c : cases(clock)) {
        SCOPED_TRACE(c.kind);
        can::SimulatedDevice& dev = *c.device;
        EXPECT_EQ(dev.describe().rfind(c.kind, 0), 0u) << dev.describe();
        EXPECT_FALSE(dev.attached());

        const auto hub = hub_name(c.kind, "life");
        Host host(hub, c.reply_id);
        {
            // The device is the only owner of its endpoint: attach() keeps it alive.
            auto endpoint = can::open_virtual(hub);
            std::weak_ptr<can::VirtualBus> watch = endpoint;
            dev.attach(std::move(endpoint));
            EXPECT_FALSE(watch.expired());
        }
        EXPECT_TRUE(dev.attached());
        auto reply = host.ask(c.request);
        ASSERT_TRUE(reply.has_value());
        EXPECT_TRUE(starts_with(*reply, c.reply_prefix));

        // Twice on a bus is refused, naming the device.
        try {
            dev.attach(can::open_virtual(hub));
            ADD_FAILURE() << "second attach accepted";
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find(dev.describe()), std::string::npos) << e.what();
        }
        EXPECT_TRUE(dev.attached());

        dev.close();
        EXPECT_FALSE(dev.attached());
        dev.close();  // idempotent
        EXPECT_FALSE(host.ask(c.request, 200ms).has_value()) << "answered after close()";

        // Served anew on a fresh endpoint of the same hub.
        dev.attach(can::open_virtual(hub));
        EXPECT_TRUE(dev.attached());
        reply = host.ask(c.request);
        ASSERT_TRUE(reply.has_value());
        EXPECT_TRUE(starts_with(*reply, c.reply_prefix));

        // A power cycle keeps it attached, and it still answers.
        dev.power_cycle();
        EXPECT_TRUE(dev.attached());
        std::this_thread::sleep_for(50ms);
        reply = host.ask(c.request);
        ASSERT_TRUE(reply.has_value());
        EXPECT_TRUE(starts_with(*reply, c.reply_prefix));
        dev.close();

        EXPECT_THROW(dev.attach(nullptr), InvalidArgument);
        EXPECT_FALSE(dev.attached());
    }
}

TEST(SimulatedDevice, OnAWireOfAnotherBitRateNothingPasses) {
    SimClock clock{1'000'000'000};
    for (auto& c : cases(clock)) {
        SCOPED_TRACE(c.kind);
        can::SimulatedDevice& dev = *c.device;
        const double own = dev.node_bit_rate();
        ASSERT_GE(own, 0);
        // A device with no bit-rate setting (0) takes the wire's: it answers on any.
        const bool models_rate = own > 0;
        const double base = models_rate ? own : 250000;
        for (double wire : {base, base * 2}) {
            can::VirtualOptions vo;
            vo.bitrate = wire;
            const bool answers = wire == base || !models_rate;
            const auto hub = hub_name(c.kind, wire == base ? "same" : "other");
            Host host(hub, c.reply_id, vo);
            dev.attach(can::open_virtual(hub, vo));
            EXPECT_EQ(host.ask(c.request, answers ? 2000ms : 200ms).has_value(), answers) << wire;
            dev.close();
        }
    }
}

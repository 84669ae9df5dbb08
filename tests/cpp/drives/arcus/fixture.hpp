// A DMX-CAN simulator on an in-memory line with a client, on simulated time.
#pragma once
#include <chrono>
#include <cmath>
#include <memory>

#include "device_port.hpp"
#include "motorbus/drives/arcus/client.hpp"
#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/runtime/clock.hpp"

namespace arcus_test {

using namespace std::chrono_literals;

struct Bench {
    explicit Bench(motorbus::arcus::SimOptions o = {})
        : sim(clock, o),
          port(std::make_shared<DevicePort>(std::vector<motorbus::serial::LineDevice*>{&sim})),
          link(std::make_shared<motorbus::serial::LineLink>(port, motorbus::arcus::Client::line_options(30ms))),
          c(link, motorbus::arcus::ClientOptions{o.address, std::nullopt, 1}) {}

    void run(double seconds) { clock.advance(static_cast<motorbus::Nanos>(std::llround(seconds * 1e9))); }
    // Raw exchange: the request without "@NN\r", the reply bytes without NUL.
    std::string raw(const std::string& cmd) { return link->transact(motorbus::arcus::format_command(c.address(), cmd)); }
    // Open loop, powered: the simplest motor to reason about.
    void open_loop() {
        c.set_snl_enabled(false);
        c.enable(true);
    }

    motorbus::SimClock clock;
    motorbus::arcus::Sim sim;
    std::shared_ptr<DevicePort> port;
    std::shared_ptr<motorbus::serial::LineLink> link;
    motorbus::arcus::Client c;
};

}  // namespace arcus_test

// The DMAC simulator on a SimClock, driven line by line (on_line): the test
// rig shared by the simulator's test files.
#pragma once
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "motorbus/drives/dmac/sim.hpp"

namespace motorbus::dmac::testing {

struct Rig {
    std::shared_ptr<SimClock> clock = std::make_shared<SimClock>();
    std::shared_ptr<Sim> sim;
    // A DMAC34 starts with its brake applied (factory BRAKE ON, annex 7.1):
    // the rig releases it, as a user does before moving; released = false keeps it.
    explicit Rig(SimOptions o, bool released = true) {
        sim = std::make_shared<Sim>(clock, o);
        if (released) release_brake();
    }
    explicit Rig(int address = 0, Model model = Model::Dmac34_1, bool released = true) {
        SimOptions o;
        o.address = address;
        o.model = model;
        sim = std::make_shared<Sim>(clock, o);
        if (released) release_brake();
    }
    void release_brake() {
        const auto m = sim->options().model;
        if (m == Model::Dmac34_1 || m == Model::Dmac34_2) sim->on_line(address_prefix(sim->address()) + "BRAKE OFF");
    }
    std::string tx(std::string_view line) { return sim->on_line(line); }
    void ms(std::int64_t n) { clock->advance(n * 1'000'000); }
    std::int32_t read(Var v) { return sim->read(v); }
    std::uint32_t status() { return static_cast<std::uint32_t>(read(Var::Status)); }
    // Reads the decimal value of a READ reply.
    std::int32_t val(std::string_view req) {
        auto r = tx(req);
        auto p = parse_read_reply(r.substr(0, r.size() - 2));
        EXPECT_TRUE(p) << r;
        return p ? p->value : 0;
    }
    // Advances 1 ms at a time until not moving; returns the elapsed ms.
    std::int64_t run_until_idle(std::int64_t limit_ms = 100000) {
        std::int64_t t = 0;
        while (bit_set(sim->state().status, status::kMovement) && t < limit_ms) {
            ms(1);
            ++t;
        }
        return t;
    }
};

}  // namespace motorbus::dmac::testing

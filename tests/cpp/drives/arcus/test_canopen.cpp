// The DMX-CAN's CANopen front end against manual 000 chapters 8/10 and the
// hostile SDO-server / CiA 402 rows (HOSTILE_INPUTS.md 2.1, 2.11), frame by frame
// through Sim::on_can_frame on a SimClock.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/runtime/clock.hpp"

namespace {

using motorbus::can::Frame;
using Bytes = std::vector<std::uint8_t>;

struct CanBench {
    explicit CanBench(motorbus::arcus::SimOptions o = can_options()) : sim(clock, o) {}
    static motorbus::arcus::SimOptions can_options() {
        motorbus::arcus::SimOptions o;
        o.comm_type = 2;
        return o;
    }
    // One frame in; the SDO reply's 8 bytes out (empty = silent).
    Bytes req(std::uint32_t id, Bytes data) {
        auto out = sim.on_can_frame(Frame::make(id, data));
        for (const auto& f : out)
            if (f.id == 0x581) return Bytes(f.data.begin(), f.data.begin() + f.len);
        return {};
    }
    Bytes sdo(Bytes data) { return req(0x601, std::move(data)); }
    Bytes write(std::uint16_t index, std::uint8_t sub, std::uint32_t v, int size) {
        const std::uint8_t cs = size == 1 ? 0x2F : size == 2 ? 0x2B : 0x23;
        return sdo({cs, std::uint8_t(index), std::uint8_t(index >> 8), sub, std::uint8_t(v), std::uint8_t(v >> 8),
                    std::uint8_t(v >> 16), std::uint8_t(v >> 24)});
    }
    std::uint32_t read(std::uint16_t index, std::uint8_t sub = 0) {
        auto r = sdo({0x40, std::uint8_t(index), std::uint8_t(index >> 8), sub, 0, 0, 0, 0});
        EXPECT_EQ(r.size(), 8u);
        if (r.size() != 8 || (r[0] & 0xF0) != 0x40) return 0xDEADBEEF;
        return r[4] | (r[5] << 8) | (r[6] << 16) | (std::uint32_t(r[7]) << 24);
    }
    void cw(std::uint16_t v) { ASSERT_EQ(write(0x6040, 0, v, 2)[0], 0x60); }
    void run_ms(int ms) { clock.advance(static_cast<motorbus::Nanos>(ms) * 1'000'000); }

    motorbus::SimClock clock;
    motorbus::arcus::Sim sim;
};

Bytes abort_frame(std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
    return {0x80, std::uint8_t(index), std::uint8_t(index >> 8), sub, std::uint8_t(code), std::uint8_t(code >> 8),
            std::uint8_t(code >> 16), std::uint8_t(code >> 24)};
}

TEST(ArcusCanopen, FactoryFreshUnitIsSilentOnCan) {
    motorbus::SimClock clock;
    motorbus::arcus::Sim sim(clock);  // comm_type 0: RS-232 (B-A01)
    EXPECT_EQ(sim.active_protocol(), 0);
    EXPECT_TRUE(sim.on_can_frame(Frame::make(0x601, Bytes{0x40, 0, 0x10, 0, 0, 0, 0, 0})).empty());
    EXPECT_TRUE(sim.on_can_frame(Frame::make(0x000, Bytes{0x81, 0})).empty());
}

TEST(ArcusCanopen, NmtResetNodeIsAPowerCycleWithBootUpOtherNmtIgnored) {
    CanBench b;
    auto out = b.sim.on_can_frame(Frame::make(0x000, Bytes{0x81, 1}));
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].id, 0x701u);
    EXPECT_EQ(out[0].len, 1);
    EXPECT_EQ(out[0].data[0], 0);
    for (std::uint8_t c : {0x01, 0x02, 0x80, 0x82})
        EXPECT_TRUE(b.sim.on_can_frame(Frame::make(0x000, Bytes{c, 1})).empty());
    EXPECT_TRUE(b.sim.on_can_frame(Frame::make(0x000, Bytes{0x81, 2})).empty());  // another node
    // Still answering after a "stop" (B-A03: no NMT state machine).
    EXPECT_EQ(b.read(0x6402), 768u);
}

TEST(ArcusCanopen, HostileSdoServerRows) {
    CanBench b;
    // S1: unknown command specifier -> 05040001 with the request's index/sub.
    EXPECT_EQ(b.sdo({0xE0, 0x41, 0x60, 0, 0, 0, 0, 0}), abort_frame(0x6041, 0, 0x05040001));
    // S2: an abort from the client gets no reply.
    EXPECT_TRUE(b.sdo(abort_frame(0x6041, 0, 0x08000000)).empty());
    // S4/S5: DLC < 8 (no full request): ignored, never read past the DLC.
    EXPECT_TRUE(b.sdo({}).empty());
    EXPECT_TRUE(b.sdo({0x40, 0x41}).empty());
    EXPECT_TRUE(b.sdo({0x40, 0x41, 0x60, 0}).empty());
    // S6/S7: no object, no sub-index (also sub != 0 of a VAR).
    EXPECT_EQ(b.sdo({0x40, 0x17, 0x10, 0, 0, 0, 0, 0}), abort_frame(0x1017, 0, 0x06020000));
    EXPECT_EQ(b.sdo({0x40, 0x41, 0x60, 1, 0, 0, 0, 0}), abort_frame(0x6041, 1, 0x06090011));
    // S8: write RO / read WO.
    EXPECT_EQ(b.write(0x6064, 0, 5, 4), abort_frame(0x6064, 0, 0x06010002));
    EXPECT_EQ(b.sdo({0x40, 0x60, 0x60, 0, 0, 0, 0, 0}), abort_frame(0x6060, 0, 0x06010001));
    // S9: too long / too short.
    EXPECT_EQ(b.write(0x2000, 0, 1, 2), abort_frame(0x2000, 0, 0x06070012));
    EXPECT_EQ(b.write(0x6081, 0, 1, 2), abort_frame(0x6081, 0, 0x06070013));
    // S10: out of range.
    EXPECT_EQ(b.write(0x2004, 3, 99, 2), abort_frame(0x2004, 3, 0x06090030));
    EXPECT_EQ(b.write(0x2004, 4, 10001, 2), abort_frame(0x2004, 4, 0x06090030));
    EXPECT_EQ(b.write(0x6086, 0, 2, 2), abort_frame(0x6086, 0, 0x06090030));
    // S11/S14 (B-A02): segmented initiate and segments are refused; block too.
    EXPECT_EQ(b.sdo({0x21, 0x7A, 0x60, 0, 4, 0, 0, 0}), abort_frame(0x607A, 0, 0x05040001));
    EXPECT_EQ(b.sdo({0x00, 0x7A, 0x60, 0, 4, 0, 0, 0}), abort_frame(0x607A, 0, 0x05040001));
    EXPECT_EQ(b.sdo({0x60, 0x7A, 0x60, 0, 4, 0, 0, 0}), abort_frame(0x607A, 0, 0x05040001));
    EXPECT_EQ(b.sdo({0xA0, 0x08, 0x10, 0, 0x7F, 0, 0, 0}), abort_frame(0x1008, 0, 0x05040001));
    // A download without size indication takes the object's size.
    EXPECT_EQ(b.sdo({0x22, 0x7A, 0x60, 0, 0x10, 0x27, 0, 0})[0], 0x60);
    EXPECT_EQ(b.read(0x607A), 10000u);
    // Extended and RTR frames on the SDO id are not requests.
    Frame ext = Frame::make(0x601, Bytes{0x40, 0, 0x10, 0, 0, 0, 0, 0}, true);
    EXPECT_TRUE(b.sim.on_can_frame(ext).empty());
}

TEST(ArcusCanopen, D1D4D6StateMachineRows) {
    CanBench b;
    EXPECT_EQ(b.read(0x6041) & 0x4F, 0x40u);
    b.cw(0x000F);  // D1: no jump from Switch on disabled
    EXPECT_EQ(b.read(0x6041) & 0x4F, 0x40u);
    EXPECT_EQ(b.write(0x6060, 0, 2, 1), abort_frame(0x6060, 0, 0x06090030));  // D4 (velocity mode: N/A)
    ASSERT_EQ(b.write(0x6060, 0, 3, 1)[0], 0x60);
    b.cw(0x0006);
    b.cw(0x0007);
    b.cw(0x000F);
    EXPECT_EQ(b.read(0x6041) & 0x6F, 0x27u);
    EXPECT_EQ(b.read(0x6061), 3u);
    ASSERT_EQ(b.write(0x60FF, 0, 5000, 4)[0], 0x60);
    b.run_ms(300);
    EXPECT_EQ(b.read(0x606C), 5000u);
    // D6: quick stop.  The DMX-CAN has no 605Ah: it stops at once (ABORT) and
    // ends in Switch on disabled with the motor disabled (B-A11, B-A32).
    b.cw(0x0002);
    EXPECT_EQ(b.read(0x606C), 0u);
    EXPECT_EQ(b.read(0x6041) & 0x4F, 0x40u);
    EXPECT_EQ(b.read(0x2004, 1), 0u);  // no current: motor disabled
}

TEST(ArcusCanopen, AccelerationIsClampedToAppendixAWhenTheMoveStarts) {
    // E-A12: HSPD 20 000, LSPD 100 -> ACC at most 19 900 ms; HSPD 900 000,
    // LSPD 1000 -> 23 050 ms.  The SDO write keeps the written value; the move
    // ramps for the clamped time.
    struct Example {
        std::uint32_t hspd, lspd;
        int max_acc_ms;
    };
    for (const Example ex : {Example{20000, 100, 19900}, Example{900000, 1000, 23050}}) {
        motorbus::arcus::SimOptions o = CanBench::can_options();
        o.snl = false;  // pulses: the window table is in PPS
        o.world.plus_limit.reset();
        CanBench b(o);
        ASSERT_EQ(b.write(0x6081, 0, ex.hspd, 4)[0], 0x60);
        ASSERT_EQ(b.write(0x6082, 0, ex.lspd, 4)[0], 0x60);
        ASSERT_EQ(b.write(0x6083, 0, 30000, 4)[0], 0x60);
        ASSERT_EQ(b.write(0x6084, 0, 30000, 4)[0], 0x60);
        EXPECT_EQ(b.read(0x6083), 30000u);
        ASSERT_EQ(b.write(0x6060, 0, 3, 1)[0], 0x60);
        b.cw(0x0006);
        b.cw(0x0007);
        b.cw(0x000F);
        ASSERT_EQ(b.write(0x60FF, 0, ex.hspd, 4)[0], 0x60);
        b.run_ms(ex.max_acc_ms - 10);
        EXPECT_LT(b.read(0x606C), ex.hspd) << ex.hspd;
        b.run_ms(20);
        EXPECT_EQ(b.read(0x606C), ex.hspd) << ex.hspd;
    }
}

TEST(ArcusCanopen, ObjectTableHas41IndicesAndEveryReadableEntryAnswers) {
    CanBench b;
    const auto& t = motorbus::arcus::canopen_objects();
    std::vector<std::uint16_t> indices;
    for (const auto& o : t)
        if (indices.empty() || indices.back() != o.index) indices.push_back(o.index);
    EXPECT_EQ(indices.size(), 41u);
    for (const auto& o : t) {
        if (std::string(o.access) == "wo") continue;
        auto r = b.sdo({0x40, std::uint8_t(o.index), std::uint8_t(o.index >> 8), o.sub, 0, 0, 0, 0});
        ASSERT_EQ(r.size(), 8u) << o.name;
        EXPECT_NE(r[0], 0x80) << o.name;
    }
}

}  // namespace

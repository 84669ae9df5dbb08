#include <gtest/gtest.h>

#include <map>

#include "motorbus/canopen/cia402.hpp"
#include "motorbus/errors.hpp"
#include "test_nmt_support.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using S = Cia402State;
using namespace std::chrono_literals;

TEST(Cia402Statusword, DecodesEveryStateAndMasksOtherBits) {
    EXPECT_EQ(decode_statusword(0x0000), S::NotReadyToSwitchOn);
    EXPECT_EQ(decode_statusword(0x0040), S::SwitchOnDisabled);
    EXPECT_EQ(decode_statusword(0x0021), S::ReadyToSwitchOn);
    EXPECT_EQ(decode_statusword(0x0023), S::SwitchedOn);
    EXPECT_EQ(decode_statusword(0x0027), S::OperationEnabled);
    EXPECT_EQ(decode_statusword(0x0007), S::QuickStopActive);
    EXPECT_EQ(decode_statusword(0x000F), S::FaultReactionActive);
    EXPECT_EQ(decode_statusword(0x0008), S::Fault);
    // Don't-care bits (voltage, warning, remote, target reached, mode bits).
    EXPECT_EQ(decode_statusword(0x1637), S::OperationEnabled);
    EXPECT_EQ(decode_statusword((0xFFB0 & ~0x4F) | 0x40), S::SwitchOnDisabled);
    EXPECT_EQ(decode_statusword(0x0628), S::Fault);
    EXPECT_EQ(decode_statusword(0x0668), S::Unknown);
    for (auto s : {S::NotReadyToSwitchOn, S::SwitchOnDisabled, S::ReadyToSwitchOn, S::SwitchedOn,
                   S::OperationEnabled, S::QuickStopActive, S::FaultReactionActive, S::Fault})
        EXPECT_EQ(decode_statusword(statusword_bits(s)), s);
}

TEST(Cia402Statusword, D3_PatternsOutsideTheTableAreUnknown) {
    int unknown = 0;
    for (unsigned sw = 0; sw < 0x80; ++sw) {
        const auto s = decode_statusword(static_cast<std::uint16_t>(sw));
        if (s == S::Unknown) ++unknown;
        // Never "enabled" unless exactly x01x 0111.
        if (s == S::OperationEnabled) {
            EXPECT_EQ(sw & 0x6F, 0x27u) << sw;
        }
    }
    EXPECT_GT(unknown, 0);
    EXPECT_EQ(decode_statusword(0x0041), S::Unknown);
    EXPECT_EQ(decode_statusword(0x0067), S::Unknown);  // OE bits with SOD bit 6 set
    EXPECT_EQ(decode_statusword(0x0061), S::Unknown);
    EXPECT_EQ(decode_statusword(0x0003), S::Unknown);
}

TEST(Cia402Device, Transitions2To16) {
    Cia402Device d;
    std::vector<int> ts;
    d.on_state_change = [&](S, S, int t) { ts.push_back(t); };
    EXPECT_EQ(d.state(), S::SwitchOnDisabled);
    EXPECT_EQ(d.on_controlword(0x06), 2);
    EXPECT_EQ(d.on_controlword(0x07), 3);
    EXPECT_EQ(d.on_controlword(0x0F), 4);
    EXPECT_EQ(d.statusword() & 0x6F, 0x27);
    EXPECT_EQ(d.on_controlword(0x07), 5);
    EXPECT_EQ(d.on_controlword(0x06), 6);
    EXPECT_EQ(d.on_controlword(0x00), 7);
    d.on_controlword(0x06);
    d.on_controlword(0x0F);  // 3 + 4 in one go
    EXPECT_EQ(d.state(), S::OperationEnabled);
    EXPECT_EQ(d.on_controlword(0x06), 8);
    d.on_controlword(0x0F);
    EXPECT_EQ(d.on_controlword(0x0F), -1);  // no change
    EXPECT_EQ(d.on_controlword(0x00), 9);
    d.on_controlword(0x06);
    d.on_controlword(0x07);
    EXPECT_EQ(d.on_controlword(0x02), 10);
    d.on_controlword(0x06);
    d.on_controlword(0x0F);
    EXPECT_EQ(d.on_controlword(0x02), 11);
    EXPECT_EQ(d.state(), S::QuickStopActive);
    EXPECT_EQ(d.statusword() & 0x6F, 0x07);
    EXPECT_EQ(d.on_controlword(0x00), 12);
    d.fault(0x2310);
    EXPECT_EQ(d.state(), S::FaultReactionActive);
    d.fault_reaction_done();
    EXPECT_EQ(d.state(), S::Fault);
    EXPECT_EQ(d.on_controlword(0x80), 15);
    EXPECT_EQ(d.state(), S::SwitchOnDisabled);
    ASSERT_EQ(d.set_quick_stop_option(6), 0u);
    d.on_controlword(0x06);
    d.on_controlword(0x0F);
    d.on_controlword(0x02);
    EXPECT_EQ(d.on_controlword(0x0F), 16);
    EXPECT_EQ(ts, (std::vector<int>{2, 3, 4, 5, 6, 7, 2, 4, 8, 4, 9, 2, 3, 10, 2, 4, 11, 12, 13, 14, 15, 2, 4, 11, 16}));
}

TEST(Cia402Device, D1_EnableOperationFromSwitchOnDisabledDoesNothing) {
    Cia402Device d;
    EXPECT_EQ(d.on_controlword(0x000F), -1);
    EXPECT_EQ(d.state(), S::SwitchOnDisabled);
    EXPECT_EQ(d.on_controlword(0x0007), -1);
    EXPECT_EQ(d.state(), S::SwitchOnDisabled);
    EXPECT_EQ(d.on_controlword(0x0006), 2);  // the right order still works
    EXPECT_EQ(d.on_controlword(0x000F), 4);
}

TEST(Cia402Device, FaultResetOnlyOnRisingEdge) {
    Cia402Device d;
    d.on_controlword(0x80);  // bit 7 already high before the fault
    d.fault(0x5000);
    d.fault_reaction_done();
    EXPECT_EQ(d.on_controlword(0x80), -1);  // still high: no edge
    EXPECT_EQ(d.state(), S::Fault);
    EXPECT_EQ(d.on_controlword(0x06), -1);  // commands don't leave FAULT
    EXPECT_EQ(d.on_controlword(0x80), 15);
    EXPECT_EQ(d.last_error_code(), 0);
}

TEST(Cia402Device, D4_UnsupportedModeAborts) {
    Cia402Device d;
    EXPECT_EQ(d.set_mode(1), 0u);
    EXPECT_EQ(d.mode(), 1);
    EXPECT_EQ(d.set_mode(8), 0x06090030u);
    EXPECT_EQ(d.set_mode(-3), 0x06090030u);
    EXPECT_EQ(d.set_mode(42), 0x06090030u);
    EXPECT_EQ(d.mode(), 1);
    d.set_supported_modes({1, 3, 6, 8});
    EXPECT_EQ(d.set_mode(8), 0u);
}

TEST(Cia402Device, D5_LossOfMasterApplies6007) {
    struct Case {
        std::int16_t option;
        S after;
        int transition;
    };
    for (auto c : {Case{0, S::OperationEnabled, -1}, Case{1, S::FaultReactionActive, 13},
                   Case{2, S::SwitchOnDisabled, 9}, Case{3, S::QuickStopActive, 11},
                   Case{-1, S::FaultReactionActive, 13}}) {
        Cia402Device d;
        ASSERT_EQ(d.set_abort_connection_option(c.option), 0u);
        d.on_controlword(0x06);
        d.on_controlword(0x0F);
        EXPECT_EQ(d.loss_of_master(), c.transition) << c.option;
        EXPECT_EQ(d.state(), c.after) << c.option;
    }
    Cia402Device idle;
    EXPECT_EQ(idle.loss_of_master(), -1);  // only while Operation Enabled
    EXPECT_EQ(idle.state(), S::SwitchOnDisabled);
    EXPECT_EQ(idle.set_abort_connection_option(4), 0x06090030u);
}

TEST(Cia402Device, D6_QuickStopPer605A) {
    for (std::int16_t opt : {1, 2, 5, 6}) {
        Cia402Device d;
        ASSERT_EQ(d.set_quick_stop_option(opt), 0u);
        std::int16_t ramp = -99;
        d.on_quick_stop = [&](std::int16_t o) { ramp = o; };
        d.on_controlword(0x06);
        d.on_controlword(0x0F);
        EXPECT_EQ(d.on_controlword(0x0002), 11);
        EXPECT_EQ(ramp, opt);
        EXPECT_EQ(d.state(), S::QuickStopActive);
        EXPECT_TRUE(d.drive_enabled());
        d.motion_stopped();
        EXPECT_EQ(d.state(), opt <= 4 ? S::SwitchOnDisabled : S::QuickStopActive) << opt;
    }
    Cia402Device d;
    EXPECT_EQ(d.set_quick_stop_option(9), 0x06090030u);
}

TEST(Cia402Steps, NextStepTable) {
    EXPECT_EQ(next_step(S::SwitchOnDisabled, S::OperationEnabled)->controlword, 0x06);
    EXPECT_EQ(next_step(S::ReadyToSwitchOn, S::OperationEnabled)->transition, 3);
    EXPECT_EQ(next_step(S::SwitchedOn, S::OperationEnabled)->controlword, 0x0F);
    EXPECT_EQ(next_step(S::Fault, S::OperationEnabled)->transition, 15);
    EXPECT_EQ(next_step(S::OperationEnabled, S::SwitchOnDisabled)->transition, 9);
    EXPECT_EQ(next_step(S::QuickStopActive, S::OperationEnabled)->transition, 12);
    EXPECT_FALSE(next_step(S::Unknown, S::OperationEnabled));
    EXPECT_FALSE(next_step(S::OperationEnabled, S::OperationEnabled));
}

// ---- host against the device through a direct SDO shim --------------------------

namespace {

struct DeviceSdo : SdoAccess {
    Cia402Device dev;
    std::map<std::uint16_t, std::uint64_t> objects;
    std::vector<std::uint16_t> controlwords;
    bool auto_motion = true;
    DeviceSdo() {
        dev.set_supported_modes({1, 3, 6});
        dev.on_new_setpoint = [this](std::uint16_t) {
            if (dev.mode() == 6) {
                if (auto_motion) dev.set_status_bits(0x3400, 0x1400);  // homing attained + reached
            } else if (auto_motion) {
                dev.set_status_bits(0x0400, 0x0400);  // target reached at once
            }
            return true;
        };
    }
    void download(std::uint8_t, std::uint16_t index, std::uint8_t, std::span<const std::uint8_t> d) override {
        std::uint64_t v = 0;
        for (std::size_t i = 0; i < d.size(); ++i) v |= std::uint64_t(d[i]) << (8 * i);
        if (index == kControlword) {
            controlwords.push_back(static_cast<std::uint16_t>(v));
            dev.on_controlword(static_cast<std::uint16_t>(v));
        } else if (index == kModesOfOperation) {
            if (auto code = dev.set_mode(static_cast<std::int8_t>(v)))
                throw ProtocolError("SDO abort " + std::to_string(code));
        } else {
            if (index == kTargetPosition) dev.set_status_bits(0x0400, 0);
            objects[index] = v;
        }
    }
    std::vector<std::uint8_t> upload(std::uint8_t, std::uint16_t index, std::uint8_t) override {
        std::uint64_t v = 0;
        if (index == kStatusword)
            v = dev.statusword();
        else if (index == kModesOfOperationDisplay)
            v = static_cast<std::uint8_t>(dev.mode());
        else
            v = objects[index];
        return {std::uint8_t(v), std::uint8_t(v >> 8), std::uint8_t(v >> 16), std::uint8_t(v >> 24)};
    }
};

}  // namespace

TEST(Cia402Host, WalksToOperationEnabledAndBack) {
    DeviceSdo sdo;
    Cia402Host h(sdo, 5, {200ms, 1ms});
    h.go_to(S::OperationEnabled);
    EXPECT_EQ(sdo.dev.state(), S::OperationEnabled);
    EXPECT_EQ(sdo.controlwords, (std::vector<std::uint16_t>{0x06, 0x07, 0x0F}));
    h.go_to(S::SwitchOnDisabled);
    EXPECT_EQ(sdo.controlwords.back(), 0x00);
    EXPECT_EQ(h.state(), S::SwitchOnDisabled);
}

TEST(Cia402Host, FaultResetRisingEdgeThenEnable) {
    DeviceSdo sdo;
    Cia402Host h(sdo, 5, {200ms, 1ms});
    h.write_controlword(0x80);  // bit 7 left high by someone
    sdo.dev.fault(0x7300);
    sdo.dev.fault_reaction_done();
    h.go_to(S::OperationEnabled);
    EXPECT_EQ(sdo.dev.state(), S::OperationEnabled);
    // Low first, then the edge.
    EXPECT_EQ(sdo.controlwords[1], 0x00);
    EXPECT_EQ(sdo.controlwords[2], 0x80);
}

TEST(Cia402Host, PersistentFaultRaisesDriveFault) {
    DeviceSdo sdo;
    Cia402Host h(sdo, 5, {50ms, 1ms});
    sdo.dev.fault(0x7300);
    sdo.dev.fault_reaction_done();
    sdo.dev.on_state_change = [&](S, S to, int) {
        if (to == S::SwitchOnDisabled) sdo.dev.fault(0x7300), sdo.dev.fault_reaction_done();
    };
    EXPECT_THROW(h.go_to(S::OperationEnabled), DriveFault);
}

TEST(Cia402Host, D3_UnknownStatuswordIsNeverTreatedAsEnabled) {
    struct Odd : SdoAccess {
        void download(std::uint8_t, std::uint16_t, std::uint8_t, std::span<const std::uint8_t>) override {}
        std::vector<std::uint8_t> upload(std::uint8_t, std::uint16_t, std::uint8_t) override { return {0x67, 0x00}; }
    } odd;
    Cia402Host h(odd, 5, {20ms, 1ms});
    EXPECT_EQ(h.state(), S::Unknown);
    EXPECT_THROW(h.go_to(S::OperationEnabled), ProtocolError);
}

TEST(Cia402Host, ProfilePositionHandshake) {
    DeviceSdo sdo;
    Cia402Host h(sdo, 5, {200ms, 1ms});
    h.set_mode(OpMode::ProfilePosition);
    EXPECT_EQ(h.mode(), OpMode::ProfilePosition);
    h.go_to(S::OperationEnabled);
    sdo.controlwords.clear();
    h.move_to(-1000, false, true);
    EXPECT_EQ(sdo.objects[kTargetPosition], 0xFFFFFC18u);
    // new set-point with change-immediately, then lowered after the acknowledge.
    ASSERT_EQ(sdo.controlwords.size(), 2u);
    EXPECT_EQ(sdo.controlwords[0], 0x003F);
    EXPECT_EQ(sdo.controlwords[1], 0x002F);
    EXPECT_EQ(sdo.dev.statusword() & sw::kSetPointAck, 0);
    h.wait_target_reached(100ms);
    sdo.auto_motion = false;
    h.move_to(500, true, false);
    EXPECT_EQ(sdo.controlwords.back(), 0x004F);
    EXPECT_THROW(h.wait_target_reached(10ms), TimeoutError);
    sdo.dev.fault(0x8611);
    EXPECT_THROW(h.wait_target_reached(10ms), DriveFault);
}

TEST(Cia402Host, D4_UnsupportedModeSurfaces) {
    DeviceSdo sdo;
    Cia402Host h(sdo, 5, {20ms, 1ms});
    EXPECT_THROW(h.set_mode(OpMode::CyclicSyncTorque), ProtocolError);
}

TEST(Cia402Host, HomingAndVelocity) {
    DeviceSdo sdo;
    Cia402Host h(sdo, 5, {200ms, 1ms});
    h.set_mode(OpMode::Homing);
    h.go_to(S::OperationEnabled);
    h.home(std::int8_t{35}, 100ms);
    EXPECT_EQ(sdo.objects[kHomingMethod], 35u);
    EXPECT_EQ(sdo.controlwords.back(), 0x000F);
    h.set_mode(OpMode::ProfileVelocity);
    h.set_velocity(-200);
    EXPECT_EQ(sdo.objects[kTargetVelocity], 0xFFFFFF38u);
    EXPECT_EQ(sdo.controlwords.back() & cw::kHalt, 0);
}

TEST(Cia402Host, WaitsOnStatuswordPdo) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    auto dev = hub.open("dev");
    DeviceSdo sdo;
    PdoReceiver rx(*host, 0x185, {{0x6041, 0, 16}});
    Cia402Host h(sdo, 5, {200ms, 1ms});
    EXPECT_THROW(
        [&] {
            PdoReceiver other(*host, 0x285, {{0x6064, 0, 32}});
            h.use_statusword_pdo(&other);
        }(),
        InvalidArgument);
    h.use_statusword_pdo(&rx);
    // The device publishes its statusword by TPDO after every controlword.
    sdo.dev.on_state_change = [&](S, S, int) {
        auto s = sdo.dev.statusword();
        dev->send(svc_test::frame(0x185, {std::uint8_t(s), std::uint8_t(s >> 8)}));
    };
    dev->send(svc_test::frame(0x185, {0x40, 0x02}));
    h.go_to(S::OperationEnabled);
    EXPECT_EQ(rx.value(0x6041, 0).value() & 0x6F, 0x27u);
}

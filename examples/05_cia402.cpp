// 05: a CiA 402 drive simulated on a virtual bus (LocalNode + Cia402Device),
// enabled and moved in profile position mode by Cia402Host.
#include <cstdio>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/cia402.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client_access.hpp"

using namespace motorbus;
using namespace motorbus::canopen;

namespace {
std::uint16_t u16_of(std::span<const std::uint8_t> d) { return static_cast<std::uint16_t>(d[0] | d[1] << 8); }
}  // namespace

int main() {
    // ---- device side: the state machine behind an object dictionary ----
    Cia402Device dev;
    auto od = std::make_shared<ObjectDictionary>();
    auto cw = od->add_variable({.index = kControlword, .name = "Controlword", .type = DataType::Unsigned16});
    auto sw = od->add_variable({.index = kStatusword, .name = "Statusword", .type = DataType::Unsigned16,
                                .access = Access::RO});
    auto mode = od->add_variable({.index = kModesOfOperation, .name = "Modes of operation", .type = DataType::Integer8});
    auto mode_display = od->add_variable({.index = kModesOfOperationDisplay, .name = "Modes of operation display",
                                          .type = DataType::Integer8, .access = Access::RO});
    auto position = od->add_variable({.index = 0x6064, .name = "Position actual value", .type = DataType::Integer32,
                                      .access = Access::RO});
    auto target = od->add_variable({.index = kTargetPosition, .name = "Target position", .type = DataType::Integer32});
    cw->set_write_hook([&](const Variable&, std::span<const std::uint8_t> d) -> std::uint32_t {
        const std::uint16_t c = u16_of(d);
        const bool new_setpoint = (c & cw::kNewSetPoint) && dev.state() == Cia402State::OperationEnabled &&
                                  dev.mode() == static_cast<std::int8_t>(OpMode::ProfilePosition);
        dev.on_controlword(c);
        if (new_setpoint) {  // the simulated move is instantaneous
            position->set_i64(target->get_i64());
            dev.set_status_bits(sw::kTargetReached, sw::kTargetReached);
        }
        return 0;
    });
    mode->set_write_hook([&](const Variable&, std::span<const std::uint8_t> d) {
        return dev.set_mode(static_cast<std::int8_t>(d[0]));
    });
    sw->set_read_hook([&](const Variable&, Bytes& out) -> std::uint32_t {
        const std::uint16_t s = dev.statusword();
        out = {static_cast<std::uint8_t>(s), static_cast<std::uint8_t>(s >> 8)};
        return 0;
    });
    mode_display->set_read_hook([&](const Variable&, Bytes& out) -> std::uint32_t {
        out = {static_cast<std::uint8_t>(dev.mode())};
        return 0;
    });
    auto device_bus = can::open_virtual("cia402-example"), host_bus = can::open_virtual("cia402-example");
    LocalNode node(*device_bus, 5, od);

    // ---- host side ----
    BusSdoAccess sdo(*host_bus);
    Cia402Host drive(sdo, 5);
    drive.set_mode(OpMode::ProfilePosition);
    drive.go_to(Cia402State::OperationEnabled);
    std::printf("state: %s\n", to_string(drive.state()));
    drive.move_to(10000);
    drive.wait_target_reached();
    const std::int32_t reached = sdo.client(5).read_i32(0x6064, 0);
    std::printf("position: %lld\n", static_cast<long long>(reached));
    drive.go_to(Cia402State::SwitchOnDisabled);
    std::printf("state: %s\n", to_string(drive.state()));
    node.close();
    return reached == 10000 ? 0 : 1;  // ctest runs this example: a wrong position fails it
}

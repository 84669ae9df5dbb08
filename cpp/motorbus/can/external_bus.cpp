#include "motorbus/can/external_bus.hpp"

namespace motorbus::can {

ExternalBus::ExternalBus(std::string channel, SendFn send_fn, CloseFn close_fn, BusOptions opts)
    : Bus(std::move(channel), opts), send_fn_(std::move(send_fn)), close_fn_(std::move(close_fn)) {}

ExternalBus::~ExternalBus() { close(); }

}  // namespace motorbus::can

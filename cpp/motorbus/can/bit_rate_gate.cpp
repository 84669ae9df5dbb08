#include "motorbus/can/bit_rate_gate.hpp"

#include <chrono>
#include <cmath>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::can {

double medium_bit_rate(const Bus& bus) {
    // A gate stands for its node, not for a wire: ask what it taps.
    if (auto* g = dynamic_cast<const BitRateGate*>(&bus)) return g->medium_bit_rate();
    if (auto* v = dynamic_cast<const VirtualBus*>(&bus)) return v->bitrate();
    return 0.0;
}

BitRateGate::BitRateGate(Bus& medium, std::function<double()> node_bit_rate, std::shared_ptr<Bus> keep)
    : Bus(medium.channel(), BusOptions{}), inner_(medium), keep_(std::move(keep)), node_rate_(std::move(node_bit_rate)) {
    if (!node_rate_) throw InvalidArgument("bit-rate gate on " + medium.channel() + ": node bit rate is unset");
    Filter all;
    all.id = 0;
    all.mask = 0;
    all.match_extended = false;
    sub_ = inner_.subscribe(all, [this](const Frame& f) {
        if (closed()) return;
        if (!in_step()) {
            refused_.fetch_add(1, std::memory_order_relaxed);
            count_bus_error();  // what the node's controller sees: error frames
            return;
        }
        dispatch(f);
    });
}

BitRateGate::~BitRateGate() { close(); }

double BitRateGate::medium_bit_rate() const { return can::medium_bit_rate(inner_); }

bool BitRateGate::in_step() const {
    const double wire = medium_bit_rate();
    if (wire <= 0) return true;
    const double own = node_rate_();
    // 0: the node models no bit rate of its own (follows the wire); < 0: a
    // setting outside the device's table, which matches no wire.
    if (own == 0) return true;
    return own > 0 && std::fabs(own - wire) < 0.5;
}

void BitRateGate::do_send(const Frame& frame, Deadline deadline) {
    if (!in_step()) {
        // Nobody on the wire decodes it; a real controller would retry into
        // error passive.  The node goes on as if sent (it cannot know better).
        refused_.fetch_add(1, std::memory_order_relaxed);
        count_tx_dropped();
        return;
    }
    const auto left = deadline - std::chrono::steady_clock::now();
    inner_.send(frame, std::max<Duration>(std::chrono::duration_cast<Duration>(left), Duration::zero()));
}

void BitRateGate::do_close() {
    if (sub_) {
        try {
            inner_.unsubscribe(sub_);
        } catch (const std::exception&) {
        }
        sub_ = 0;
    }
}

}  // namespace motorbus::can

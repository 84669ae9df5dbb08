// A simulated node's own tap on a bus whose bit rate it may not share.
//
// A real CAN controller set to another bit rate than the wire's cannot decode
// a frame: it answers every one with an error frame and transmits nothing the
// others can read.  A simulated node whose bit-rate object takes effect at its
// power cycle or reset attaches through this gate: frames pass both ways only while the node's bit
// rate in effect equals the medium's.  A medium that models no bit rate (a
// virtual hub without wire time, a socketcand or SLCAN link, where the rate
// lives in the adapter) has none to disagree with: everything passes.
#pragma once
#include <atomic>
#include <functional>
#include <memory>

#include "motorbus/can/bus.hpp"

namespace motorbus::can {

// The bit rate a bus models, in bit/s; 0 when it models none (only a virtual
// hub with wire time has one).
double medium_bit_rate(const Bus& bus);

class BitRateGate final : public Bus {
public:
    // `node_bit_rate` is asked at every frame (bit/s; 0 = follows the wire,
    // < 0 = a setting that matches no wire): it
    // reads the node's own setting, which changes at its power cycles.  It runs
    // on the medium's receive thread and in send(): it must not block (read an
    // atomic).  `medium` must outlive the gate; `keep` may own it.
    BitRateGate(Bus& medium, std::function<double()> node_bit_rate, std::shared_ptr<Bus> keep = {});
    ~BitRateGate() override;

    // True while the node can talk on the medium (same rate, or none modelled).
    bool in_step() const;
    double medium_bit_rate() const;  // of the bus it taps (0 = none modelled)
    // Frames the node could not decode or send since the gate opened (each one
    // a frame that a real node would have answered with an error frame).
    std::uint64_t refused() const { return refused_.load(std::memory_order_relaxed); }
    const void* medium() const override { return inner_.medium(); }

protected:
    void do_send(const Frame& frame, Deadline deadline) override;
    void do_close() override;

private:
    Bus& inner_;
    std::shared_ptr<Bus> keep_;
    std::function<double()> node_rate_;
    SubscriptionId sub_ = 0;
    std::atomic<std::uint64_t> refused_{0};
};

}  // namespace motorbus::can

// In-process CAN bus: any number of endpoints joined by hub name.
//
// Without a bit rate a frame reaches the other endpoints at once.  With one,
// the hub models the wire: frames wait in each endpoint's transmit queue,
// the lowest id wins arbitration, and each occupies the wire for its
// worst-case-stuffed bit count, so bus load and latency are what a real bus
// at that rate would show.  Faults (drop, corrupt, delay, bus-off) are set per
// sending endpoint, for tests that need a bad cable.
#pragma once
#include <cstdint>
#include <memory>
#include <string>

#include "motorbus/can/bus.hpp"

namespace motorbus::can {

// Checked by set_faults() and open_virtual(): probabilities in [0, 1], delay >= 0
// (InvalidArgument naming the field otherwise).
struct FaultOptions {
    unsigned drop_every = 0;           // drop every n-th frame sent (0 = never)
    double drop_probability = 0.0;     // drop each frame with this probability, [0, 1]
    double corrupt_probability = 0.0;  // flip one random data bit with this probability, [0, 1]
    Nanos delay_ns = 0;                // extra latency before delivery, >= 0
    std::uint64_t seed = 0x5eed;       // for the probabilistic faults (reproducible)
};

// Bit rates a timed hub accepts (besides 0 = no wire time): from 1 bit/s (a
// frame lasts minutes, still a count of nanoseconds) to 1 Gbit/s.
constexpr double kMinVirtualBitrate = 1.0;
constexpr double kMaxVirtualBitrate = 1e9;

struct VirtualOptions : BusOptions {
    double bitrate = 0.0;         // bit/s; 0 = no wire time, else kMin/kMaxVirtualBitrate.  All endpoints of a hub must agree.
    std::size_t tx_queue = 64;    // frames waiting for the wire before send() blocks, >= 1
    FaultOptions faults;
    // How long an endpoint's receive thread polls for the next frame before it
    // sleeps.  Saves a thread wake-up per frame in request/response exchanges
    // (SDO), at the cost of that much CPU after each burst; 0 = always sleep.
    std::chrono::microseconds rx_spin{20};
};

// Throw InvalidArgument naming the field for values no virtual bus can work with
// (a probability outside [0, 1], a negative delay or bitrate, an empty queue).
void check_options(const FaultOptions& faults);
void check_options(const VirtualOptions& options);

class VirtualHub;

class VirtualBus final : public Bus {
public:
    VirtualBus(std::shared_ptr<VirtualHub> hub, std::string channel, const VirtualOptions& opts);
    ~VirtualBus() override;

    void set_faults(const FaultOptions& f);
    // Simulates the controller going bus-off (sends fail with LinkDown, nothing
    // is received) and recovering.
    void set_bus_off(bool off);
    double bitrate() const;
    // The hub: every endpoint of one hub is one medium.
    const void* medium() const override;

protected:
    void do_send(const Frame& frame, Deadline deadline) override;
    void do_close() override;

private:
    friend class VirtualHub;
    struct Impl;
    std::unique_ptr<Impl> impl_;
    void enqueue_rx(const Frame& f);  // called by the hub
};

// Opens an endpoint on hub `name` (created on first use, gone with its last endpoint).
std::shared_ptr<VirtualBus> open_virtual(const std::string& name, const VirtualOptions& opts = {});

}  // namespace motorbus::can

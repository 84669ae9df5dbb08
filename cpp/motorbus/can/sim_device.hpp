// What a simulated CAN device implements: the twin of serial::LineDevice.
//
// A LineDevice is handed request lines by whoever serves it (serial/); a CAN
// node is different: it lives on a bus, hears every frame and talks when it
// likes (boot-up, EMCY, cyclic frames, timers).  So the contract is not "a
// frame in, frames out" but "get on a bus, get off it":
//
//   attach(bus)   serve on `bus`.  The device SHARES OWNERSHIP of the bus until
//                 close(): a caller may drop its own reference at once.  (Sims
//                 that kept a `Bus&` made every owner -- bindings, servers,
//                 benches -- wrap them in a holder struct whose only job was to
//                 keep the bus alive as long as the sim; that is gone.)
//   close()       off the bus: every subscription removed, the device's own
//                 threads stopped, the bus reference dropped.  Idempotent; the
//                 destructor calls it.  Then attach() may be called again (to
//                 the same bus or another one), with the device's state kept.
//   attached()    whether it is on a bus (a device that took itself off the
//                 bus, e.g. a node sitting in its bootloader, may still count as
//                 attached: the bus is kept for its next power-up).
//   describe()    "<kind> sim <address>", for error messages and logs, so that
//                 a message about one of 100 simulated nodes says which.
//   power_cycle() power off and on again: stored settings take effect (node-ID,
//                 bit rate), volatile ones are lost; a CANopen node sends its
//                 boot-up when attached.  Every real device has a power switch,
//                 and every bench fault plan and test needs it.
//   node_bit_rate() the bit rate the device's controller is set to now (bit/s),
//                 0 = no bit-rate setting modelled (it takes the wire's).  A real
//                 node at another rate than the wire's decodes nothing and is
//                 heard by no one: attach through gate_onto() and that is what
//                 the simulated node does on a medium that models a bit rate.
//
// Threads: attach(), close() and power_cycle() may be called from any thread
// EXCEPT the device's own callbacks -- the bus receive thread while it runs the
// device's frame handlers, and the device's own timer/worker threads.  close()
// unsubscribes and joins those threads, which from inside them would wait on
// itself (can::Bus::unsubscribe documents the same rule).  attached(),
// describe() and node_bit_rate() are safe from anywhere, callbacks included.
//
// The bindings bind this class once (SimulatedDevice): every CAN simulator gets
// the same Python attach(bus) / close() / attached / describe() / power_cycle()
// / node_bit_rate.
#pragma once
#include <memory>
#include <string>

#include "motorbus/can/bit_rate_gate.hpp"
#include "motorbus/can/bus.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::can {

class SimulatedDevice {
public:
    virtual ~SimulatedDevice() = default;

    // Serve on `bus` (kept alive until close()).  InvalidArgument naming
    // describe() when `bus` is null or the device is already attached.
    virtual void attach(std::shared_ptr<Bus> bus) = 0;
    // Off the bus; idempotent.  Not from the device's own callbacks (see above).
    virtual void close() = 0;
    virtual bool attached() const = 0;
    // "<kind> sim <address>", e.g. "cia402 sim node 5".
    virtual std::string describe() const = 0;
    // Power off and on again (see above).
    virtual void power_cycle() = 0;
    // bit/s the node's controller runs at now; 0 = takes the wire's; < 0 = a
    // setting that matches no wire.  Asked on the bus receive thread for every
    // frame: must not block (read an atomic or a constant).
    virtual double node_bit_rate() const = 0;

protected:
    // The bus a device serves on, from the medium attach() was given: a
    // BitRateGate owning `medium` (so holding the gate keeps the medium alive)
    // that passes frames both ways only while node_bit_rate() matches the
    // medium's bit rate (or the medium models none).  InvalidArgument naming
    // describe() if `medium` is null.  Closing the gate leaves the medium open:
    // it is the caller's.
    std::shared_ptr<BitRateGate> gate_onto(std::shared_ptr<Bus> medium) {
        if (!medium) throw InvalidArgument(describe() + " attach: bus is None");
        return std::make_shared<BitRateGate>(*medium, [this] { return node_bit_rate(); }, medium);
    }
    // The InvalidArgument every attach() throws when attached twice.
    InvalidArgument already_attached() const {
        return InvalidArgument(describe() + " attach: already attached to a bus (close() it first)");
    }
};

}  // namespace motorbus::can

// Simulated Arcus DMX-CAN on its ASCII line (RS-232 point-to-point or RS-485
// multi-drop).  Answers every command of codec.hpp the way manual 000 says,
// with the motion model running on a motorbus::Clock so tests drive time with
// SimClock.  Device time advances lazily: every request (and every test hook)
// first integrates the axis up to clock.now().
#pragma once
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "motorbus/drives/arcus/codec.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/serial/line_device.hpp"

namespace motorbus::arcus {

// The world around the motor, in physical motor steps (3200 per rev; the
// encoder reads 4000 counts per rev).  Counters (PX/EX) can be re-zeroed; these
// positions cannot.
struct SimWorld {
    double home_lo = 8000, home_hi = 8400;       // home switch actuated inside [lo, hi]
    std::optional<double> minus_limit = -400000;  // actuated at or below
    std::optional<double> plus_limit = 400000;    // actuated at or above
    double z_position = 1600;                     // a Z index pulse here and every 3200 steps
    double z_width = 1.0;                         // Z is high for z_width steps from each index
    double start_position = 0;
};

struct SimOptions {
    int address = 1;            // factory DN (overridden by a store file that has DN)
    int response_type = 0;      // factory RT
    std::string store_path;     // STORE writes here; read at boot ("" = flash not persisted)
    bool eo_boot = false;       // Table 7.11 ships EOBOOT=0: motor unpowered until EO=1
    bool snl = true;            // Table 7.11 ships SL=1
    SimWorld world;
    std::int64_t tick_ns = 100'000;  // integration step
};

class Sim : public serial::LineDevice {
public:
    Sim(Clock& clock, SimOptions options = {});
    // Shares ownership of the clock (bindings, servers that outlive the caller).
    Sim(std::shared_ptr<Clock> clock, SimOptions options = {});
    ~Sim() override;

    std::string on_line(std::string_view line) override;
    std::string request_terminator() const override { return "\r"; }
    std::size_t max_request() const override { return kMaxRequest + 3; }
    std::string on_overlong() override { return ""; }

    // ---- test hooks (all thread-safe) ----
    int address() const;               // address it currently answers on
    void power_cycle();                // boot again from the store file
    void set_input(int index, bool actuated);  // DI1..DI6; DI2 is the latch input
    // Forces a switch regardless of position (nullopt = follow the world).
    void force_home(std::optional<bool> actuated);
    void force_limit(int direction, std::optional<bool> actuated);
    void set_blocked(bool blocked);    // rotor jammed: pulses go out, the shaft stays
    void disturb(double steps);        // push the rotor (e.g. a knock) without pulses
    double physical_position() const; // steps
    std::int64_t pulse_position();     // PX
    std::int64_t encoder_position();   // EX
    std::int64_t motor_status();       // MST
    int snl_status();                  // SLS
    bool busy();                       // outputting pulses
    std::string store_path() const;

    struct State;  // opaque; public only so the implementation's helpers can name it

private:
    std::string handle(const Request& req);
    mutable std::mutex mutex_;
    std::shared_ptr<Clock> clock_owner_;
    Clock& clock_;
    SimOptions options_;
    std::unique_ptr<State> s_;
};

}  // namespace motorbus::arcus

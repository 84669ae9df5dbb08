// Simulated Arcus DMX-CAN: one drive with two front ends.  On its ASCII line
// (RS-232 point-to-point or RS-485 multi-drop) it is a LineDevice; attached to
// a CAN bus (attach, the can::SimulatedDevice face) it is a CiA DSP-402 node served by SDO (manual 000
// chapters 8 and 10, sim_canopen.cpp).  Which of the two answers is the stored
// communication type (CM / 200Ah) read at power-up: a factory-fresh unit talks
// RS-232, a unit stored as CAN answers on CAN and not on its serial line.  Answers every command of codec.hpp the way manual 000 says,
// with the motion model running on a motorbus::Clock so tests drive time with
// SimClock.  Device time advances lazily: every request (and every test hook)
// first integrates the axis up to clock.now().
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/sim_device.hpp"
#include "motorbus/can/frame.hpp"

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
    // STORE writes here too; read at boot.  Without one (""), the flash lasts
    // as long as the simulator object: a power cycle keeps what was stored.
    std::string store_path;
    bool eo_boot = false;       // Table 7.11 ships EOBOOT=0: motor unpowered until EO=1
    bool snl = true;            // Table 7.11 ships SL=1
    SimWorld world;
    std::int64_t tick_ns = 100'000;  // integration step
    // Factory communication type (CM / 200Ah): 0 RS-232 (the real factory
    // setting), 1 RS-485, 2 CAN (a unit configured for CANopen).  A store file
    // overrides it.  With 2 the CANopen tables' defaults (Tables 8.11, 8.21)
    // are the factory values, with 0/1 the ASCII ones (Table 7.11).
    int comm_type = 0;
    int node_id = 1;              // factory NID / 200Ch
    int bit_rate = 5;             // factory BR / 200Bh code (1..9; 5 = 125 kbit/s)
    // 200Eh / 200Dh read 1 this long after a store / clear request (Fig. 8.1,
    // 8.2: the master polls until 0).  0 here (a SimClock test sees the result
    // at once); the served sims (arcus_canopen.make_sim on a real clock) take
    // realistic times.
    std::int64_t store_ns = 0;
    std::int64_t clear_ns = 0;
};

// One entry of the CANopen object dictionary (manual 000 Table 10.1 with the
// defaults of Tables 8.1-8.75; spec can-drives.md §3.2).  The simulator serves
// exactly these; the Python client names and types them from this table.
struct CanopenObject {
    std::uint16_t index;
    std::uint8_t sub;
    const char* name;
    const char* type;    // U8 U16 U32 I8 I16 I32 VISIBLE_STRING
    const char* access;  // ro, rw, wo, const
    std::int64_t default_value;  // factory / power-on value (CAN persona)
    std::int64_t low, high;      // accepted range of a write (rw / wo)
    const char* unit;
    bool persists;  // saved by the 200Eh store (Table 8.40)
};
const std::vector<CanopenObject>& canopen_objects();
// 200Bh code -> bit/s (Table 8.36: 1 10k, 2 20k, 3 50k, 4 100k, 5 125k, 6 250k,
// 7 500k, 8 800k, 9 1M); 0 for any other code.
double canopen_bit_rate_bps(int code);

// One object with both faces, as the real unit is one drive: a LineDevice for
// its serial line (served by a serial::LineServer) and a can::SimulatedDevice
// for its CAN port.  close() takes it off the CAN bus only.
class Sim : public serial::LineDevice, public can::SimulatedDevice {
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
    void power_cycle() override;       // boot again from the store file
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

    // ---- the CANopen front end (sim_canopen.cpp) ----
    // ---- the CAN face: can::SimulatedDevice ----
    // Serves the node on `bus` (kept alive until close()).  It answers only
    // while the communication type in effect is CAN; the boot-up frame
    // 0x700+n [00] is sent now and at every power cycle.
    void attach(std::shared_ptr<can::Bus> bus) override;
    void close() override;  // off the CAN bus (idempotent); the serial face is unaffected
    bool attached() const override;
    std::string describe() const override;  // "arcus sim node <node-ID in effect>"
    // 200Bh in effect, bit/s; -1 for a code outside Table 8.36 (matches no wire).
    double node_bit_rate() const override;
    // One received frame in, the frames the drive answers out (SDO replies);
    // an NMT reset node power-cycles the drive (its boot-up is in the result).
    // What attach runs for each frame; public for tests and the fuzzer.
    std::vector<can::Frame> on_can_frame(const can::Frame& frame);
    int active_protocol() const;  // communication type in effect: 0, 1 or 2
    int can_node_id() const;      // node-ID in effect (200Ch at the last boot)
    int can_bit_rate() const;     // bit-rate code in effect (200Bh at the last boot)
    // The node talks only on a bus at that bit rate (see can::BitRateGate); a
    // bus that models no bit rate (no wire time) carries it whatever its code.

    struct State;  // opaque; public only so the implementation's helpers can name it

private:
    std::string handle(const Request& req);
    std::string command(std::string_view cmd);  // the firmware's command interpreter, lock held
    void boot();                                // power-up, lock held
    std::vector<can::Frame> canopen_frame(const can::Frame& frame, bool& reset);  // lock held
    std::optional<can::Frame> boot_up_frame() const;  // lock held
    std::uint32_t od_read(std::uint16_t index, std::uint8_t sub, std::uint32_t& value, int& size);
    std::uint32_t od_write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, int size);
    void controlword(std::uint16_t value);
    void canopen_home();  // HM set-point: the CiA 402 method as the firmware's homing command
    void canopen_service();  // buffered set-points, PV restarts, error -> Fault
    void send_frames(const std::vector<can::Frame>& frames);
    // While set, the firmware runs a command at this (past) instant rather than
    // at clock.now(): a buffered set-point starts exactly where the previous move ended.
    std::optional<Nanos> at_;
    mutable std::mutex bus_mutex_;
    std::shared_ptr<can::Bus> bus_;  // a can::BitRateGate on the attached bus
    std::atomic<int> bit_rate_code_{5};  // active_br, read by the gate on the bus thread
    std::vector<can::SubscriptionId> subs_;
    mutable std::mutex mutex_;
    std::shared_ptr<Clock> clock_owner_;
    Clock& clock_;
    SimOptions options_;
    std::unique_ptr<State> s_;
};

}  // namespace motorbus::arcus

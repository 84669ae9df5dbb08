// The generic CiA 402 simulator: one CiA 402 drive as the profile describes it,
// served by a canopen::LocalNode (SDO server, NMT slave, boot-up) with a
// HeartbeatService (producer 1017h, consumer 1016h: a lost master applies
// 6007h), a PdoService (RPDO/TPDO 1-4, SYNC; the process data of PP/PV are
// mappable) and a canopen::Cia402Axis (state machine, profile position with the
// set-point handshake, profile velocity, homing methods 7, 11, 17-20, 33-35) on
// a motion::MotorModel with home and limit switches.
//
// Its dictionary (standard objects only; vendor 0, product 402h) is the table
// cia402::objects() lists, which the Python Drive's params describe too.
// Settings live in the dictionary (an SDO read of one is a plain read); what
// the axis computes (6041h, 6061h, 6064h, 606Ch, 60FDh, 603Fh, 1001h) is read
// through hooks, so the motion is evaluated when the host looks.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/sim_device.hpp"
#include "motorbus/canopen/cia402_axis.hpp"
#include "motorbus/canopen/heartbeat_service.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/pdo_service.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::cia402 {

struct SimOptions {
    double steps_per_rev = 3200;                        // motor model (increments per revolution)
    std::pair<double, double> home{1000, 1400};         // home switch window, increments
    std::optional<double> minus_limit = -100000.0;      // limit switch positions (nullopt: none)
    std::optional<double> plus_limit = 100000.0;
    int heartbeat_ms = 0;                               // 1017h at boot (0 = off, as CiA 301)
    double start_position = 0;
    // Throws InvalidArgument naming the option (heartbeat_ms outside 0..65535,
    // a home window with lo > hi, a -limit above the +limit, non-finite numbers).
    void validate() const;
};

// One row of the simulator's dictionary (and of the Python Drive's params).
struct ObjectRow {
    std::uint16_t index;
    std::uint8_t sub;
    const char* name;
    canopen::DataType type;
    canopen::Access access;
    std::int64_t default_value;  // numeric rows
    std::optional<std::int64_t> low, high;
    const char* unit;
    bool persists;  // saved by 1010h:01
    const char* description;
    const char* text_default = nullptr;  // VISIBLE_STRING rows
};
const std::vector<ObjectRow>& objects();
// objects() as a dictionary (records, limits, defaults, 1018h:04 = the node-ID, 1010h:01
// store), no behaviour: the simulator serves it with its hooks added, and a host (the
// generic Drive adapter) reads and writes by its typed entries.
void add_objects(canopen::ObjectDictionary& od, std::uint8_t node_id);
std::shared_ptr<canopen::ObjectDictionary> object_dictionary(std::uint8_t node_id = 1);

// A can::SimulatedDevice: attach(bus) serves the node (boot-up sent; the bus is
// kept alive until close()), close() takes it off (the motor halts where it is).
class Sim : public can::SimulatedDevice {
public:
    // Throws InvalidArgument for a node-ID outside 1..127 or a bad option.
    Sim(std::uint8_t node_id, Clock& clock, SimOptions options = {});
    // Shares ownership of the clock (bindings, servers that outlive the caller).
    Sim(std::uint8_t node_id, std::shared_ptr<Clock> clock, SimOptions options = {});
    ~Sim() override;
    Sim(const Sim&) = delete;
    Sim& operator=(const Sim&) = delete;

    void attach(std::shared_ptr<can::Bus> bus) override;
    void close() override;
    bool attached() const override;
    std::string describe() const override { return "cia402 sim node " + std::to_string(node_id_); }
    // Power off and on: the axis back in SWITCH ON DISABLED with the dictionary's
    // defaults (nothing is stored across power: 1010h only checks its signature),
    // the shaft where it was; boot-up when attached.
    void power_cycle() override;
    double node_bit_rate() const override { return 0; }  // no bit-rate setting modelled

    std::uint8_t node_id() const { return node_id_; }
    canopen::ObjectDictionary& od() { return *od_; }
    std::shared_ptr<canopen::ObjectDictionary> od_ptr() { return od_; }
    canopen::Cia402Axis& axis() { return *axis_; }
    motion::MotorModel& motor() { return *motor_; }
    std::shared_ptr<canopen::PdoService> pdo() const;
    std::shared_ptr<canopen::HeartbeatService> heartbeat() const;
    // The master's heartbeat was lost at least once (6007h applied).
    bool lost_master() const { return lost_master_.load(); }
    double position() { return axis_->pulse_position(); }

    // ---- test hooks (see Cia402Axis) ----
    void inject_fault(std::uint16_t code = 0x5441) { axis_->inject_fault(code); }
    void force_limit(int direction, bool active = true) { axis_->force_limit(direction, active); }
    void jam(bool jammed = true) { axis_->jam(jammed); }
    void set_stop_input(bool active = true) { axis_->set_stop_input(active); }
    std::optional<Nanos> last_setpoint_ns() const { return axis_->last_setpoint_ns(); }

private:
    void build_od();
    void serve(can::Bus& bus);  // a new LocalNode and services on `bus` (m_ not held)
    void hook_setting(std::uint16_t index, std::uint8_t sub);
    void publish_settings();  // the axis's settings into the dictionary (after an NMT reset)

    std::uint8_t node_id_;
    std::shared_ptr<Clock> clock_owner_;  // set by the shared_ptr constructor
    Clock& clock_;
    SimOptions options_;
    std::unique_ptr<motion::MotorModel> motor_;
    std::unique_ptr<canopen::Cia402Axis> axis_;  // declared after the motor: destroyed before it
    std::shared_ptr<canopen::ObjectDictionary> od_;
    mutable std::mutex m_;  // node and services
    std::shared_ptr<can::Bus> bus_;  // kept alive while attached
    std::unique_ptr<canopen::LocalNode> node_;
    std::shared_ptr<canopen::PdoService> pdo_;
    std::shared_ptr<canopen::HeartbeatService> hb_;
    bool attaching_ = false;
    std::atomic<bool> lost_master_{false};
};

}  // namespace motorbus::cia402

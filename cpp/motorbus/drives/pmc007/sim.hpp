// The simulated PMC007 (003 manual): a CANopen node served on a Bus whose
// dictionary is build_pmc007_od (the one table), with the device's behaviour
// on the OD hooks:
//   - SDO server / NMT / boot-up (LocalNode), heartbeat producer and consumer
//     (HeartbeatService, 1016h/1017h), 4 TPDO + 4 RPDO (PdoService, mapping
//     limited to the objects Appendix 1 marks mappable), EMCY on fault bits;
//   - motion on a motion::MotorModel with the pmc007 profile (gears, start/stop
//     speeds) on a Clock: step (6004h) and absolute (601Ch) commands, speed
//     mode, immediate stop (6020h), enable (600Eh), with the busy / ignore /
//     refuse rules of B-P07..B-P20;
//   - RAM/ROM: 2007h=2 saves the ROM objects to "flash", reset node / power
//     cycle reloads them (RAM objects return to their defaults), reset
//     communication makes the RAM values of node-ID/baud/PDO/heartbeat active;
//   - stall detection (jam the rotor with set_jammed), external stops with
//     edge selection and debounce, GPIO with the inverted polarity;
//   - the offline program (6018h/6019h), executed on the clock.
// Time: the motion, debounce and program advance when poll() runs: on every
// SDO access, from the node's timer (every 2 ms of real time) and when a test
// calls it after advancing a SimClock.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "motorbus/can/bit_rate_gate.hpp"
#include "motorbus/can/bus.hpp"
#include "motorbus/can/sim_device.hpp"
#include "motorbus/canopen/heartbeat_service.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/pdo_service.hpp"
#include "motorbus/drives/pmc007/od_table.hpp"
#include "motorbus/drives/pmc007/profile.hpp"
#include "motorbus/drives/pmc007/program.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::pmc007 {

// 6000h bits.
namespace err {
constexpr std::uint8_t kUvlo = 1u << 0, kBerr = 1u << 1, kAerr = 1u << 2, kBoc = 1u << 3, kAoc = 1u << 4,
                       kTsd = 1u << 5;
}
// 6001h bits (bit 4: EXT3 latch, the spec's reading).
namespace st {
constexpr std::uint8_t kExt1 = 1u << 0, kExt2 = 1u << 1, kStall = 1u << 2, kBusy = 1u << 3, kExt3 = 1u << 4;
}
// 6012h / 6011h:01 port bits.
namespace port {
constexpr int kGpio1 = 0, kExt1 = 7, kExt2 = 8, kEnc1 = 9, kEnc2 = 10;
}

inline constexpr std::uint32_t kAbortDeviceState = 0x08000022;
inline constexpr std::uint32_t kAbortValueRange = 0x06090030;

struct SimOptions {
    double steps_per_rev = 200;  // full steps of the motor (1.8 degree)
    double pull_out_speed = 0;   // steps/s above which the rotor stalls (0 = never)
    // A switch wired to EXT1 (pulls it low while lo <= position <= hi), e.g. the
    // home/limit switch an external-stop homing runs into.  nullopt = none.
    std::optional<std::pair<double, double>> ext1_switch{};
    // The motor model's integration step (MotorConfig::tick_ns); switch edges
    // and the end of a move are found at their own instant whatever the step.
    Nanos tick_ns = 100'000;
    // Where the "flash" lives between runs (ROM objects saved by 2007h=2, the
    // offline program saved by 6019h:03, the 602Ah position); "" = memory only.
    std::string store_path{};
    // What 1018h reads (003 documents no identity): vendor 0 = none claimed (a CiA
    // vendor ID is assigned, not invented), product code 7 ("PMC007"), revision 1.0
    // (as 100Ah "SW1.0"), serial 1.  A bench can give each sim its own.
    Identity identity{0, 7, 0x00010000, 1};
};

// 2003h baud index -> bit/s (003 §4.3.2); -1 for an index outside 0..8.
double baud_index_bps(int index);

class Sim : public can::SimulatedDevice {
public:
    Sim(std::uint8_t node_id, Clock& clock, SimOptions options = {});
    // Shares ownership of the clock (bindings, servers that outlive the caller).
    Sim(std::uint8_t node_id, std::shared_ptr<Clock> clock, SimOptions options = {});
    ~Sim();
    Sim(const Sim&) = delete;
    Sim& operator=(const Sim&) = delete;

    // ---- can::SimulatedDevice ----
    // Serve on `bus` (kept alive until close(); boot-up sent) through a gate at
    // the 2003h baud in effect; InvalidArgument if already attached.
    void attach(std::shared_ptr<can::Bus> bus) override;
    void close() override;
    bool attached() const override;
    std::string describe() const override;  // "pmc007 sim node <active node-ID>"
    // Power off and on again: flash reloaded, RAM defaults, position per 602Ah,
    // offline program auto-run, boot-up (when attached).
    void power_cycle() override;
    double node_bit_rate() const override { return baud_index_bps(baud_index_.load()); }
    // Why the last node-ID switch or return to the bus (after the bootloader)
    // failed, "" if none did.  These run on a helper thread, where an exception
    // has nobody to reach: the node stays on its old ID (or off the bus) and
    // the reason is kept here.  "node-ID N is taken" is the documented case (B-P36
    // [P]); anything else is a simulator fault a test should see.
    std::string last_error() const;
    // Back to the state of a sim newly built with the same options (flash from
    // the store file or factory values, programs empty, motor at rest at 0 with
    // the clock's now() as its time), without rebuilding the dictionary, the
    // costly part: for a harness that reuses one sim (the fuzz target).  Only
    // while not attached (InvalidArgument otherwise).
    void reset_to_new();
    // Advance motion, debounce, stall and the offline program to clock.now().
    void poll();

    // ---- what the device is doing ----
    std::uint8_t node_id() const { return node_id_; }      // the active node-ID
    std::uint8_t error_status();                            // 6000h
    std::uint8_t controller_status();                       // 6001h (busy computed)
    std::int32_t position();                                // 600Ch
    double velocity();                                      // pps, signed
    bool busy();
    bool active();  // moving, running a program or debouncing an input
    bool enabled();
    std::uint16_t gpio_value();                             // 6012h (1 = low)
    std::uint8_t active_baud_index() const { return baud_index_; }
    // B-P40: the encoder CPR in use: 6021h as it was at the last power-up (or reset
    // node); a 6021h write changes only the RAM copy until then.
    std::uint16_t active_encoder_cpr() const { return cpr_; }
    canopen::ObjectDictionary& od() { return *od_; }
    std::shared_ptr<canopen::ObjectDictionary> od_ptr() { return od_; }
    canopen::LocalNode* node() { return node_.get(); }
    std::vector<std::uint32_t> flash_program();
    std::vector<std::uint32_t> ram_program();
    bool program_running();
    std::uint32_t program_pointer();
    std::uint32_t program_counter_value();
    std::uint64_t emcy_sent() const { return emcy_sent_; }
    // B-P39: after 2007h = 1 the application is gone until power_cycle(): no SDO,
    // NMT, heartbeat, PDO or EMCY (the node is taken off the bus).
    bool in_bootloader() const { return bootloader_; }

    // ---- test hooks ----
    // A load blocks the rotor: with stall detection configured (6017h threshold
    // bits != 0) 6001h bit 2 latches; with 601Bh = 1 the motor stops.
    void set_jammed(bool jammed);
    // Drive the electrical level of an input port (6012h bit 0..10): high = true.
    void set_input(int bit, bool high);
    // The power stage detects an error (6000h bits): latched, EMCY sent.
    void inject_error(std::uint8_t bits);

private:
    struct Pending {
        Nanos t;
        bool high;
    };
    std::uint32_t on_write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> d);
    void on_reset(canopen::NmtCommand c);
    // B-P27/B-P36: a node-ID written to 2002h takes effect at reset communication
    // (or at power-up once saved): the node is served again under the new ID.
    void schedule_node_id_switch();
    void switch_node_id(std::uint8_t new_id);
    struct Services {
        std::shared_ptr<canopen::PdoService> pdo;
        std::shared_ptr<canopen::HeartbeatService> hb;
        std::shared_ptr<canopen::NodeService> ticker;
    };
    Services make_services(canopen::LocalNode& n);
    // Takes `n` and its services as the node on the bus (under m_), ending an attach.
    void install_node(std::unique_ptr<canopen::LocalNode> n, Services sv);
    canopen::LocalNodeOptions node_options();
    void publish();
    void load_power_up(bool cold);
    void write_store_locked();
    void read_store();
    void update_locked();
    std::uint32_t start_move_locked(std::int64_t delta);
    bool refused_locked() const;
    void stop_now_locked();
    ProfileParams params_locked(double speed) const;
    void on_motor_event(const motion::MotorEvent& e);
    void input_edge_locked(int bit, bool high, Nanos t);
    void level_change_locked(int bit, bool high, Nanos t);
    void emcy_locked(std::uint16_t code);
    // An EMCY of the PDO engine or the heartbeat consumer (a communication error) comes and goes.
    void comm_error(std::uint16_t code, bool active);
    // EMCY 0000h once every signalled condition (6000h errors, 6001h latches) is clear.
    void emcy_if_cleared_locked();
    // Queued EMCY frames whose 1015h inhibit time has passed go out.
    void flush_emcy_locked();
    std::uint8_t error_register_locked() const;  // 1001h
    // 2007h = 3: factory values into the working copy, through the services' hooks.
    void factory_reset_locked();
    // 1005h into the PDO engine (SYNC consumed on that COB-ID).
    void apply_sync_cob_id(const std::shared_ptr<canopen::PdoService>& pdo);
    void enter_bootloader();
    // A fresh LocalNode and services on bus_ (attach and power-up after the bootloader).
    void serve_again();
    void run_program_locked(Nanos now);
    bool exec_locked(std::uint32_t word, bool single);
    std::int64_t u(std::uint16_t i, std::uint8_t s = 0) const;
    void set(std::uint16_t i, std::uint8_t s, std::int64_t v);
    void set(const canopen::VariablePtr& var, std::int64_t v);

    std::atomic<std::uint8_t> node_id_;
    std::atomic<std::uint8_t> baud_index_{4};
    std::shared_ptr<Clock> clock_owner_;  // set by the shared_ptr constructor
    Clock& clock_;
    SimOptions opt_;
    std::shared_ptr<canopen::ObjectDictionary> od_;
    motion::MotorModel motor_;
    mutable std::recursive_mutex m_;
    std::shared_ptr<can::BitRateGate> gate_;  // bus_ while attached: the 2003h baud must match the wire's
    // Gates of earlier attachments, closed; declared before retired_ so that they outlive it.
    // (each owns its medium: a closed sim keeps the buses it served on alive until it goes, as retired
    // nodes and services still name their gates)
    std::vector<std::shared_ptr<can::BitRateGate>> old_gates_;
    can::Bus* bus_ = nullptr;
    std::unique_ptr<canopen::LocalNode> node_;
    std::shared_ptr<canopen::PdoService> pdo_;
    std::shared_ptr<canopen::HeartbeatService> hb_;
    std::shared_ptr<canopen::NodeService> ticker_;
    bool attaching_ = false;
    std::thread renode_;
    std::thread boot_;  // takes the node off the bus on entering the bootloader
    std::atomic<bool> renode_done_{false};
    std::string last_error_;  // under m_: see last_error()
    // Records why a helper-thread (re)start of the node failed (see last_error()).
    void record_node_error(const std::string& what);
    bool renode_again_ = false;  // a switch was asked for while one ran (under m_)
    std::vector<std::shared_ptr<void>> retired_;  // replaced nodes/services: their OD listeners stay valid

    std::map<std::pair<std::uint16_t, std::uint8_t>, canopen::Bytes> flash_;
    struct PowerUpRow {
        const OdRow* row;
        canopen::VariablePtr var;
        canopen::Bytes* flash;  // its flash_ entry (ROM objects), else nullptr
    };
    std::vector<PowerUpRow> power_up_;  // every dictionary row, in table order
    // The objects publish() keeps up to date, looked up once (it runs on every poll) and
    // named, so a value is set on its object by name, never by position in a list.
    struct Published {
        canopen::VariablePtr error_register;       // 1001h
        canopen::VariablePtr manufacturer_status;  // 1002h
        canopen::VariablePtr system_control;       // 2007h: reads back 0, an action
        canopen::VariablePtr error_status;         // 6000h
        canopen::VariablePtr controller_status;    // 6001h
        canopen::VariablePtr motor_position;       // 600Ch
        canopen::VariablePtr gpio_value;           // 6012h
        canopen::VariablePtr saved_position;       // 6022h
        canopen::VariablePtr step_command;         // 6004h
        canopen::VariablePtr absolute_command;     // 601Ch
        canopen::VariablePtr stop_command;         // 6020h: reads back 0, an action
        canopen::VariablePtr save_program;         // 6019h:03: reads back 0, an action
        canopen::VariablePtr run_instruction;      // 6019h:05: reads back 0, an action
        canopen::VariablePtr gpio_direction;       // 6011h:01
        canopen::VariablePtr program_word;         // 6019h:02: the word at the pointer
    };
    Published published_;
    std::vector<std::uint32_t> flash_program_, ram_program_;
    std::uint8_t errors_ = 0;   // 6000h
    std::uint8_t latched_ = 0;  // 6001h bits 0-2, 4
    bool speed_mode_running_ = false;
    std::uint32_t last_step_ = 0;
    std::int32_t last_abs_ = 0;
    std::uint16_t levels_ = 0x7FF;  // electrical level of each port, 1 = high
    std::array<std::optional<Pending>, 11> pending_{};
    bool jammed_ = false;
    std::atomic<bool> bootloader_{false};
    bool bootloader_pending_ = false;
    std::int32_t saved_position_ = 0;  // 6022h "EEPROM"
    std::atomic<std::uint64_t> emcy_sent_{0};
    Nanos last_emcy_ = -1;
    // EMCY frames raised inside the 1015h inhibit time: sent when it has passed (B-P30).
    std::deque<can::Frame> emcy_queue_;
    bool emcy_error_ = false;  // an error EMCY was sent and no 0000h since
    // Communication errors signalled by the PDO engine / heartbeat consumer (EMCY code ->
    // active): 1001h bit 4 (and bit 0) while any is active.
    std::set<std::uint16_t> comm_errors_;
    std::atomic<std::uint16_t> cpr_{500};
    // Offline program execution.
    bool running_ = false, paused_ = false, flag_ = false;
    std::uint32_t pc_ = 0, counter_ = 0;
    bool reset_en_ = false, pause_en_ = false;
    std::uint32_t reset_target_ = 0;
    bool program_fault_ = false;
};

}  // namespace motorbus::pmc007

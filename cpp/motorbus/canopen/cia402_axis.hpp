// One CiA 402 axis as a device runs it: the power state machine (Cia402Device)
// and the profile position / profile velocity / homing modes on a
// motion::MotorModel, with the set-point handshake of CiA 402 (controlword bit 4
// new set-point, bit 5 change set immediately, bit 6 relative, bit 8 halt, bit 9
// change on set-point; statusword bit 10 target reached, 11 internal limit, 12
// set-point acknowledge / speed / homing attained, 13 following / homing error).
//
// What a simulated CiA 402 node serves on top of its object dictionary: the
// generic simulator (drives/cia402/sim.hpp) hangs its dictionary on one of these.
// A vendor's device keeps its own firmware and takes the pieces it shares with
// every CiA 402 drive from here (Cia402SetPoints: the PP handshake and its
// one-deep set-point buffer, the homing-mode bookkeeping) with hooks for what it
// does its own way (its own latched faults, homing methods run by its own
// firmware: the vendor folders' CANopen simulators).
//
// Time: the motion is evaluated when someone looks (every public call runs
// MotorModel::update() first), so a SimClock test advances the clock and reads.
// Threading: every public call takes the axis's (recursive) mutex; the motor
// model's listeners run inside it.
#pragma once
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>

#include "motorbus/canopen/cia402.hpp"
#include "motorbus/motion/cia402_profile.hpp"
#include "motorbus/motion/homing.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::canopen {

// ---- the set-point handshake, shared with vendor front ends -----------------------

// What a controlword write in Operation Enabled asks of the mode's motion.
enum class SetPointAction {
    None,         // nothing to start
    Halt,         // bit 8 rose: decelerate to rest (a halted PP/HM motion is not resumed)
    Resume,       // bit 8 fell (PV runs at 60FFh again)
    Start,        // PP: the set-point starts now (the axis is idle, or bit 5 replaces the motion)
    Buffer,       // PP: the set-point waits until the running one is reached (bit 5 = 0)
    Refuse,       // PP: one set-point already waits (depth 1): no acknowledge
    StartHoming,  // HM: bit 4 rose
};

// How a vendor reads the set-point bits where CiA 402 leaves room.
struct Cia402SetPointPolicy {
    // CiA 402: while a motion runs, bit 5 = 1 replaces it now and bit 5 = 0 waits
    // for it (buffered).  A drive may instead buffer a "set of set-points" only
    // with bit 5 = 1 and ignore a set-point with bit 5 = 0 (its manual says which).
    bool buffer_on_bit5 = false;
};

// The controlword edges of profile position and homing mode as CiA 402 fig. 23
// draws them: bit 4's rising edge is a new set-point, the acknowledge (bit 12)
// stays until bit 4 falls; while a motion runs a set-point may wait in a
// one-deep buffer (a relative one adds to the set-point before it).
class Cia402SetPoints {
public:
    explicit Cia402SetPoints(Cia402SetPointPolicy policy = {}) : policy_(policy) {}
    // A controlword written in Operation Enabled (`prev`: the one before).  `idle`:
    // the axis stands and runs nothing; `accept` false refuses any set-point (a
    // vendor's latched error); `position`: where the axis is (a relative set-point
    // starting now counts from there).  Updates the acknowledge and the buffer; the
    // caller starts what the action says (target() is absolute).  A Start the
    // caller cannot run is undone with refuse().
    SetPointAction on_controlword(std::uint16_t prev, std::uint16_t cw, OpMode mode, bool idle, bool accept,
                                  double target_position, double position);
    // The running set-point was reached: the buffered one (if any) is due now.
    std::optional<double> take_buffered();
    void refuse() { ack_ = false; }
    // A mode change, a disable, a quick stop, a fault: the handshake starts over.
    void reset() {
        ack_ = false;
        buffered_.reset();
    }
    void drop_buffered() { buffered_.reset(); }
    bool acknowledged() const { return ack_; }
    bool buffered() const { return buffered_.has_value(); }
    double target() const { return target_; }  // the set-point of the last Start / Buffer

private:
    Cia402SetPointPolicy policy_;
    bool ack_ = false;
    std::optional<double> buffered_;
    double target_ = 0;
};

// ---- the axis --------------------------------------------------------------------

// The objects the modes read (their CiA 402 indexes), in drive increments.
struct Cia402AxisSettings {
    std::int32_t target_position = 0;                 // 607Ah
    std::int32_t target_velocity = 0;                 // 60FFh
    std::uint32_t profile_velocity = 1000;            // 6081h
    std::uint32_t profile_acceleration = 10000;       // 6083h
    std::uint32_t profile_deceleration = 10000;       // 6084h
    std::uint32_t quick_stop_deceleration = 100000;   // 6085h
    std::int16_t motion_profile_type = 0;             // 6086h: 0 linear, 1 sin^2
    std::int8_t homing_method = 19;                   // 6098h
    std::uint32_t homing_speed_switch = 5000;         // 6099h:01
    std::uint32_t homing_speed_zero = 1000;           // 6099h:02
    std::uint32_t homing_acceleration = 20000;        // 609Ah
    std::int32_t home_offset = 0;                     // 607Ch
    std::uint32_t following_error_window = 1000;      // 6065h
    std::int32_t min_position = std::numeric_limits<std::int32_t>::min();  // 607Dh:01
    std::int32_t max_position = std::numeric_limits<std::int32_t>::max();  // 607Dh:02
};

// What a vendor does its own way.  Every hook is optional.
struct Cia402AxisHooks {
    // Homing methods 6098h accepts (default: motion::Cia402Homing::supported).
    std::function<bool(int method)> homing_supported;
    // A vendor's own latched errors as a 603Fh code (0 = none), checked whenever
    // the axis is looked at: a code faults the drive (e.g. a latched limit error).
    std::function<std::uint16_t()> vendor_fault;
};

class Cia402Axis {
public:
    // `motor` and `clock` outlive the axis.
    Cia402Axis(motion::MotorModel& motor, Clock& clock, Cia402AxisHooks hooks = {});
    ~Cia402Axis();
    Cia402Axis(const Cia402Axis&) = delete;
    Cia402Axis& operator=(const Cia402Axis&) = delete;

    // ---- objects (the node's hooks call these) ----
    void write_controlword(std::uint16_t cw);       // 6040h
    std::uint16_t controlword() const;
    std::uint16_t statusword();                     // 6041h
    std::uint32_t set_mode(std::int8_t mode);       // 6060h: 0 or the abort code
    std::int8_t mode() const;                       // 6060h/6061h: the mode asked for is the one in effect
    std::uint32_t set_abort_connection_option(std::int16_t v);  // 6007h
    std::uint32_t set_quick_stop_option(std::int16_t v);        // 605Ah
    std::uint32_t set_homing_method(std::int8_t method);        // 6098h: 0 or 0x06090030
    void set_target_velocity(std::int32_t v);       // 60FFh (a running PV follows at once)
    // Any other setting: `f` runs on the settings under the lock.
    void update_settings(const std::function<void(Cia402AxisSettings&)>& f);
    Cia402AxisSettings settings() const;
    std::int32_t position();                        // 6064h
    std::int32_t velocity();                        // 606Ch
    std::uint32_t digital_inputs();                 // 60FDh: bit 0 -limit, 1 +limit, 2 home, 16 stop input
    std::uint16_t error_code() const;               // 603Fh (the last fault's; kept after a reset)
    std::uint8_t error_register() const;            // 1001h
    Cia402State state() const;                      // as last evaluated (statusword() evaluates)
    double pulse_position();                        // the motor's position, unrounded

    // ---- device events and test hooks ----
    // The simulator stops serving: the motor stops where it is (no state change).
    void halt_motor();
    // Power off and on: SWITCH ON DISABLED, mode 0, default settings and options,
    // no error; the motor halts where it is (the shaft does not move).
    void reset();
    // The drive detects a fault: the motor stops at once, FAULT, 603Fh = code.
    void inject_fault(std::uint16_t code);
    // A limit switch closes whatever the position (+1 / -1): a motion toward it stops.
    void force_limit(int direction, bool active);
    // The rotor blocks: past 6065h the drive faults with 0x8611.
    void jam(bool jammed);
    // The quick-stop input (60FDh bit 16): its rising edge quick-stops a moving drive.
    void set_stop_input(bool active);
    // The master's heartbeat was lost: 6007h decides (fault, disable, quick stop).
    void loss_of_master();
    // Clock time of the last PP set-point the axis took (nullopt: none yet).
    std::optional<Nanos> last_setpoint_ns() const;

private:
    enum class Activity { Idle, Pp, Pv, Homing, Stopping, QuickStop };
    motion::Cia402ProfileParams params() const;
    motion::State motion_state() const;
    double pp_time() const;     // s since the PP profile's start
    void sync_buffer();
    void update();
    void new_setpoint(std::uint16_t cw);
    void apply_velocity();
    void start_homing();
    void decelerate();
    void begin_quick_stop();
    void stop_now();
    void fault_now(std::uint16_t code);
    void on_motor_event(const motion::MotorEvent& e);
    void check_forced_limits();
    void check_following_error();

    motion::MotorModel& motor_;
    Clock& clock_;
    Cia402AxisHooks hooks_;
    mutable std::recursive_mutex m_;
    std::unique_ptr<Cia402Device> device_ = std::make_unique<Cia402Device>();
    Cia402AxisSettings s_;
    Cia402SetPoints setpoints_;
    std::unique_ptr<motion::Cia402ProfilePosition> pp_;
    Nanos pp_t0_ = 0;
    std::unique_ptr<motion::Cia402Homing> homing_;
    Activity activity_ = Activity::Idle;
    bool limit_hit_ = false;
    bool forced_plus_ = false, forced_minus_ = false;
    int soft_limit_side_ = 0;        // the PP target was clipped to 607Dh on this side
    bool following_error_ = false;   // PP statusword bit 13 until the next set-point
    double slip0_ = 0;               // the rotor's lag when the current motion began
    bool stop_input_ = false;
    std::uint16_t error_code_ = 0;
    std::uint8_t error_register_ = 0;
    std::optional<Nanos> last_setpoint_;
    int listener_ = 0;
};

}  // namespace motorbus::canopen

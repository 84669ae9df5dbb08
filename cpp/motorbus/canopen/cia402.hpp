// CiA 402 (drives and motion control): the power state machine as the host
// drives it (Cia402Host: statusword decoding, controlword transitions, PP/PV/HM
// set-point handshakes) and as a device runs it (Cia402Device, for simulators).
#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/sdo_access.hpp"

namespace motorbus::canopen {

enum class Cia402State {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
    Unknown,  // a statusword pattern outside the table (D3): never "enabled"
};
const char* to_string(Cia402State s);
// The state whose to_string() is `name` (exact spelling); nullopt otherwise.
std::optional<Cia402State> cia402_state_from_name(std::string_view name);
Cia402State decode_statusword(std::uint16_t sw);
// The state bits (0-3, 5, 6) of a statusword reporting `s`.
std::uint16_t statusword_bits(Cia402State s);

// Objects.
constexpr std::uint16_t kControlword = 0x6040;
constexpr std::uint16_t kStatusword = 0x6041;
constexpr std::uint16_t kAbortConnectionOption = 0x6007;
constexpr std::uint16_t kQuickStopOption = 0x605A;
constexpr std::uint16_t kFaultReactionOption = 0x605E;
constexpr std::uint16_t kModesOfOperation = 0x6060;
constexpr std::uint16_t kModesOfOperationDisplay = 0x6061;
constexpr std::uint16_t kTargetPosition = 0x607A;
constexpr std::uint16_t kTargetVelocity = 0x60FF;
constexpr std::uint16_t kHomingMethod = 0x6098;
constexpr std::uint16_t kSupportedDriveModes = 0x6502;

// Controlword commands (bits 0-3 and 7).
namespace cw {
constexpr std::uint16_t kShutdown = 0x0006;
constexpr std::uint16_t kSwitchOn = 0x0007;
constexpr std::uint16_t kDisableVoltage = 0x0000;
constexpr std::uint16_t kQuickStop = 0x0002;
constexpr std::uint16_t kDisableOperation = 0x0007;
constexpr std::uint16_t kEnableOperation = 0x000F;
constexpr std::uint16_t kFaultReset = 0x0080;
constexpr std::uint16_t kNewSetPoint = 1u << 4;       // PP; HM: start homing
constexpr std::uint16_t kChangeImmediately = 1u << 5;  // PP
constexpr std::uint16_t kRelative = 1u << 6;           // PP
constexpr std::uint16_t kHalt = 1u << 8;
}  // namespace cw

// Statusword bits beyond the state.
namespace sw {
constexpr std::uint16_t kVoltageEnabled = 1u << 4;
constexpr std::uint16_t kQuickStopBit = 1u << 5;  // 0 = quick stop active
constexpr std::uint16_t kWarning = 1u << 7;
constexpr std::uint16_t kRemote = 1u << 9;
constexpr std::uint16_t kTargetReached = 1u << 10;
constexpr std::uint16_t kInternalLimit = 1u << 11;
constexpr std::uint16_t kSetPointAck = 1u << 12;      // PP; PV: speed 0; HM: homing attained
constexpr std::uint16_t kFollowingError = 1u << 13;   // PP; HM: homing error
}  // namespace sw

enum class OpMode : std::int8_t {
    None = 0,
    ProfilePosition = 1,
    Velocity = 2,
    ProfileVelocity = 3,
    ProfileTorque = 4,
    Homing = 6,
    InterpolatedPosition = 7,
    CyclicSyncPosition = 8,
    CyclicSyncVelocity = 9,
    CyclicSyncTorque = 10,
};
const char* to_string(OpMode m);

// The controlword that drives `from` one step towards `to` along the CiA 402
// graph, and the transition number it causes; nullopt when no step is needed
// or none exists (Unknown, or a target that cannot be commanded).
struct Cia402Step {
    std::uint16_t controlword;
    int transition;
};
std::optional<Cia402Step> next_step(Cia402State from, Cia402State to);

// ---- host -----------------------------------------------------------------

struct Cia402HostOptions {
    std::chrono::nanoseconds timeout{std::chrono::seconds(2)};   // per state change
    std::chrono::nanoseconds sdo_poll{std::chrono::milliseconds(5)};  // when no PDO carries 0x6041
};

class Cia402Host {
public:
    Cia402Host(SdoAccess& sdo, std::uint8_t node, Cia402HostOptions options = {});

    // Statusword from this TPDO receiver when it maps 0x6041 (waits become
    // event-driven); nullptr = read over SDO.
    void use_statusword_pdo(PdoReceiver* rx);
    // Writes the controlword through `fn` (e.g. an RPDO) instead of SDO.
    void use_controlword_writer(std::function<void(std::uint16_t)> fn);

    std::uint16_t read_statusword();
    Cia402State state() { return decode_statusword(read_statusword()); }
    void write_controlword(std::uint16_t cw);
    std::uint16_t last_controlword() const { return last_cw_; }

    // Single commands.
    void shutdown() { write_controlword(cw::kShutdown); }
    void switch_on() { write_controlword(cw::kSwitchOn); }
    void enable_operation() { write_controlword(cw::kEnableOperation); }
    void disable_operation() { write_controlword(cw::kDisableOperation); }
    void disable_voltage() { write_controlword(cw::kDisableVoltage); }
    void quick_stop() { write_controlword(cw::kQuickStop); }
    // Fault reset acts on the rising edge of bit 7: clear it first if set.
    void fault_reset();

    // Walks the state machine to `target` (OperationEnabled, SwitchedOn,
    // ReadyToSwitchOn or SwitchOnDisabled), waiting for each state; throws
    // TimeoutError naming the state it got stuck in, DriveFault when the
    // drive faults on the way, ProtocolError on an UNKNOWN statusword.
    void go_to(Cia402State target);
    // Waits until the statusword satisfies mask/value; returns it.
    std::uint16_t wait_statusword(std::uint16_t mask, std::uint16_t value,
                                  std::optional<std::chrono::nanoseconds> timeout = std::nullopt);
    Cia402State wait_state(Cia402State s, std::optional<std::chrono::nanoseconds> timeout = std::nullopt);

    // Modes: writes 0x6060 and waits for 0x6061 to follow.
    void set_mode(OpMode m);
    OpMode mode();

    // Profile position: writes the target, raises new set-point, waits for
    // the acknowledge, lowers new set-point (the handshake of CiA 402 fig. 23).
    void move_to(std::int32_t target, bool relative = false, bool immediate = true);
    // Waits for target reached (bit 10); DriveFault if the drive faults.
    void wait_target_reached(std::optional<std::chrono::nanoseconds> timeout = std::nullopt);
    // Profile velocity: writes the target velocity (halt cleared).
    void set_velocity(std::int32_t velocity);
    // Homing: optional method, start (bit 4), wait attained+reached or error.
    void home(std::optional<std::int8_t> method = std::nullopt,
              std::optional<std::chrono::nanoseconds> timeout = std::nullopt);

private:
    void wait_leave(Cia402State cur, int transition);
    SdoAccess& sdo_;
    std::uint8_t node_;
    Cia402HostOptions opt_;
    PdoReceiver* sw_pdo_ = nullptr;
    std::function<void(std::uint16_t)> cw_writer_;
    std::uint16_t last_cw_ = 0;
};

// ---- device (simulators) -----------------------------------------------------

class Cia402Device {
public:
    Cia402Device();

    Cia402State state() const;
    std::uint16_t statusword() const;
    std::uint16_t controlword() const;
    // Applies a controlword; returns the transition taken (-1 = none: e.g.
    // D1, 0x000F in Switch On Disabled needs 0x0006 first).
    int on_controlword(std::uint16_t cw);

    // 0x6060: 0 or the abort code 0x06090030 for an unsupported mode (D4).
    std::uint32_t set_mode(std::int8_t mode);
    std::int8_t mode() const;
    void set_supported_modes(std::set<std::int8_t> modes);

    // Option codes (defaults: 0x6007 = 1 fault, 0x605A = 2, 0x605E = 2).
    std::uint32_t set_abort_connection_option(std::int16_t v);
    std::uint32_t set_quick_stop_option(std::int16_t v);
    std::int16_t quick_stop_option() const;
    std::int16_t abort_connection_option() const;

    // Device events.
    void fault(std::uint16_t error_code);  // transition 13 (then 14 when the reaction ends)
    void fault_reaction_done();            // transition 14
    // Loss of master (heartbeat / RPDO timeout / NMT left OPERATIONAL) while
    // Operation Enabled: applies 0x6007 (D5).  Returns the transition taken.
    int loss_of_master();
    // The quick-stop or fault ramp has brought the motor to rest.
    void motion_stopped();
    std::uint16_t last_error_code() const;

    // Mode-specific statusword bits the simulator drives (10-13 etc.).
    void set_status_bits(std::uint16_t mask, std::uint16_t value);

    // Called without the lock held.
    std::function<void(Cia402State old_state, Cia402State new_state, int transition)> on_state_change;
    // PP/HM: new set-point rising edge (bit 4) in Operation Enabled.  Return
    // true to acknowledge (bit 12 set until bit 4 falls).
    std::function<bool(std::uint16_t controlword)> on_new_setpoint;
    // Quick stop requested: the simulator ramps per 0x605A and calls motion_stopped().
    std::function<void(std::int16_t option)> on_quick_stop;

    bool drive_enabled() const;  // power to the motor: OE or QSA or FRA

private:
    struct Change {
        Cia402State from, to;
        int transition;
    };
    int go(Cia402State to, int transition, std::optional<Change>& ch);
    void notify(const std::optional<Change>& ch);
    mutable std::mutex m_;
    Cia402State state_ = Cia402State::SwitchOnDisabled;
    std::uint16_t cw_ = 0;
    std::uint16_t extra_ = 0;  // bits 8-15 and 7 set by the simulator
    bool ack_ = false;
    std::int8_t mode_ = 0;
    std::set<std::int8_t> supported_{1, 3, 6};
    std::int16_t abort_option_ = 1, quick_stop_option_ = 2, fault_option_ = 2;
    std::uint16_t error_code_ = 0;
};

}  // namespace motorbus::canopen

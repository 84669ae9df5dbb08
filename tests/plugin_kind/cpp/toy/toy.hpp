// "toy": the smallest real drive kind, written out of the tree (tests/plugin_kind/)
// to show that a kind is one C++ folder, one bindings file and one Python module
// whose Drive subclass is the plugin (docs/plugins.md).
//
// The protocol: ASCII lines, requests end with CR, replies with CR LF.  A request
// is "@<address> <command>", address 1..9; a drive answers only its own address.
//   MOVE <n>     absolute move to n steps (trapezoid at SPEED/ACCEL) -> OK
//   JOG <v>      run at v steps/s until STOP                          -> OK
//   STOP         decelerate to rest at ACCEL                          -> OK
//   ABORT        stop the step generator at once                      -> OK
//   HOME         the counter is set to 0 where the axis stands (no switch: a toy)  -> OK
//   ENABLE, DISABLE                                                   -> OK
//   CLEAR        clears a latched fault whose cause is gone (the stage stays off) -> OK
//   POS?  VEL?                                                        -> the number (steps, steps/s)
//   <NAME>?      a setting (SPEED steps/s, ACCEL steps/s^2, WINDOW steps, ADDR) -> its value
//   <NAME> <v>   sets a writable one within its range                 -> OK
//   STATUS?      "<DISABLED|IDLE|MOVING|FAULT> <NONE|TARGET|STOP|ABORT|DISABLE|FAULT> <HOMED|UNHOMED>":
//                the state, how the last motion ended (or is ending), whether HOME ran
// A refused or unknown request gets "ERR <why>".  The fault input (Sim::set_fault_input,
// an overtemperature say) stops the motor, switches the stage off and latches FAULT.
#pragma once
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "motorbus/motion/motor_model.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/serial/line_device.hpp"
#include "motorbus/serial/port.hpp"

namespace motorbus::toy {

inline constexpr const char* kRequestTerminator = "\r";
inline constexpr const char* kReplyTerminator = "\r\n";

// How the last motion ended, as STATUS? says it.
enum class LastStop { None, Target, Stop, Abort, Disable, Fault };
const char* to_string(LastStop s);

struct SimOptions {
    int address = 1;             // 1..9
    double speed = 4000;         // steps/s of a MOVE
    double accel = 40000;        // steps/s^2 of every ramp
    double start_position = 0;   // steps
};

// The simulated drive: a LineDevice for a PtyLineServer, its motion on a MotorModel.
// Thread-safe (the line server's thread and the test's both call it).
class Sim final : public serial::LineDevice {
public:
    explicit Sim(std::shared_ptr<Clock> clock = nullptr, SimOptions options = {});
    std::string on_line(std::string_view line) override;
    std::string request_terminator() const override { return kRequestTerminator; }
    std::size_t max_request() const override { return 64; }

    int address() const { return opt_.address; }
    std::int64_t position();   // steps, caught up with the clock
    bool moving();
    // The drive's fault input: active stops the motor and latches FAULT until CLEAR
    // after it is released.
    void set_fault_input(bool active);

private:
    std::string handle(std::string_view cmd, std::string_view arg);
    std::string motion(std::string_view cmd, std::string_view arg);
    std::string setting(std::string_view name, std::string_view arg);
    void stop_at_accel();

    std::shared_ptr<Clock> clock_;
    SimOptions opt_;
    std::mutex mu_;
    motion::MotorModel motor_;
    bool enabled_ = false;
    bool jogging_ = false;
    bool homed_ = false;
    bool fault_input_ = false;
    bool fault_ = false;           // latched
    double window_ = 0;            // WINDOW: steps from its target a move may end and count as arrived
    LastStop last_ = LastStop::None;
};

struct Status {
    bool enabled = false;
    bool moving = false;
    bool fault = false;
    bool homed = false;
    LastStop last_stop = LastStop::None;
};

// The host side over a LineLink (shared by the drives of one line: the link
// serialises their transactions).  A refusal ("ERR ...") throws DriveFault.
class Client {
public:
    Client(std::shared_ptr<serial::LineLink> link, int address);
    void move_to(std::int64_t target);
    void jog(double velocity);
    void stop();
    void abort();
    void enable();
    void disable();
    void clear();
    void home();
    // A setting by name (SPEED, ACCEL, WINDOW, ADDR).
    double get(const std::string& name);
    void set(const std::string& name, double value);
    std::int64_t position();
    double velocity();
    Status status();
    // One request as typed (without the address), its reply as text.
    std::string command(std::string_view text);
    int address() const { return address_; }
    const std::shared_ptr<serial::LineLink>& link() const { return link_; }

private:
    void ok(std::string_view text);
    std::shared_ptr<serial::LineLink> link_;
    int address_;
};

}  // namespace motorbus::toy

// A DMAC module as a serial LineDevice: every variable with its stored or
// volatile behaviour, the DMAC motion profile (Motion), hard and
// soft end-stops, the 500-line sequencer (one line per millisecond), the
// interpolation FIFO and MODULE_RESET [ALL].
//
// The axis is a motion::MotorModel: Motion plans, the model plays the plan
// (and the interpolation segments); #POSITION is the model's encoder and
// #SPEED its rotor speed.  One step = one count = one increment (1/10000 rev).
// Hard end-stops are the model's +/- limit switches (SimOptions) or the
// inputs as set_input() drives them; soft end-stops stop the axis where the
// commanded motion crosses #POSITIVE_END / #NEGATIVE_END.
//
// Time: device state lives on a motorbus::Clock.  Nothing runs in the
// background; each call first brings the device up to clock.now() in 1 ms
// ticks (sequencer line, timers, FIFO segment progress, end-stop checks), so
// a SimClock advanced by a test gives exact, repeatable times.  Switch edges
// and soft end-stop crossings inside a tick stop the axis at their exact time.
//
// UltraSYNC (#INTERPOL_MODE:=-1, 5.11): modules whose IN6/OUT1 are chained
// (chain_ultrasync) finish each interpolation segment together: one that is
// done waits, at rest on the segment's end, until the segment is finished on
// every chained module that interpolates in UltraSYNC, then all start the next
// one at the same tick.  In SimpleSYNC each module times its segments alone.
// Chained modules share one lock and one time line (they are advanced tick by
// tick together), so they must share one Clock.
#pragma once
#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "motorbus/drives/dmac/codec.hpp"
#include "motorbus/drives/dmac/profile.hpp"
#include "motorbus/drives/dmac/sequencer.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/serial/line_device.hpp"

namespace motorbus::dmac {

enum class Model : std::uint8_t { Dmac17, Dmac23_1, Dmac23_2, Dmac34_1, Dmac34_2 };
std::optional<Model> parse_model(std::string_view s);  // "DMAC17", "DMAC23-1", "DMAC34-1", ...
std::string_view model_name(Model m);

struct SimOptions {
    int address = 0;
    Model model = Model::Dmac34_1;
    std::string request_terminator = "\r";
    std::string reply_terminator = "\r\n";
    std::int32_t supply_voltage_mv = 32000;  // DMAC34 runs on 20..160 V, DMAC17/23 on 12..45 V
    std::int32_t cpu_temperature = 520;     // 0.1 degC
    std::int32_t driver_temperature = 450;  // DMAC34
    std::int32_t motor_temperature = 650;   // DMAC34
    std::int32_t baudrate = 38400;
    // REQUEST_VERSION fields (defaults: the manual's example module).
    std::string firmware = "v1.7";
    std::string serial_number = "H142-10145";
    std::string manufacturing_date = "25/01/05";
    std::string revision_date = "12/04/06";
    std::string phase = "6A";
    std::string boot = "v1.1";
    // Mechanical end-stop switches on the hard end-stop inputs (IN1/IN2,
    // DMAC34: IN9/IN10), fixed to the machine: `lo` is the position
    // (1/10000 rev, the axis frame at power-up) where the switch closes.
    // active_low = false: a closed switch drives the input active (wire
    // normally-closed switches as active_low = true with INVERSE_POLARITY IN).
    // Absent by default; set_input() drives those inputs either way.
    motion::SwitchConfig positive_end_switch{false, 0, 0, false};
    motion::SwitchConfig negative_end_switch{false, 0, 0, false};
    // A reference switch on IN5 (REFERENCE, CAPTURE): active on [lo, hi).
    motion::SwitchConfig reference_switch{false, 0, 0, false};
    // #LINE_DELAY is a wire-level wait before each reply, so it is real time
    // whatever the device clock is.  A caller with no wire (the fuzz target,
    // which runs the line handler thousands of times a second) turns it off.
    bool line_delay_in_real_time = true;
};

// Snapshot of what a test usually asserts on.
struct SimState {
    std::int64_t now_ms = 0;
    std::int32_t position = 0;
    std::int32_t speed = 0;          // 0.01 rpm
    std::uint32_t status = 0;
    std::uint32_t error = 0;
    int line = 0;
    bool sequencer_running = false;
    int fifo_count = 0;
    bool interpolating = false;
    bool power = false;
};

class Sim : public serial::LineDevice {
public:
    explicit Sim(std::shared_ptr<Clock> clock, SimOptions options = {});
    ~Sim() override;

    // ---- LineDevice -------------------------------------------------------
    std::string on_line(std::string_view line) override;
    void line_ends() override;
    std::string request_terminator() const override { return options_.request_terminator; }
    // A frame longer than 256 characters sets the syntax error bit of the
    // module it addresses and is not answered (its commands are not run).
    // The line server hands lines up to kOverlongWindow characters to on_line,
    // which reads the address and rejects them; a longer one reaches
    // on_overlong without its address, so every module on the line flags it.
    static constexpr std::size_t kOverlongWindow = 4096;
    std::size_t max_request() const override { return kOverlongWindow; }
    std::string on_overlong() override;

    // ---- inspection and physical world (tests, demos) --------------------
    void poll();                      // catch up with the clock
    SimState state();
    std::int32_t read(Var v);
    int address();
    std::int32_t baudrate();
    const SimOptions& options() const { return options_; }
    std::string sequence_line(int n);  // canonical text of stored line n ("" = empty)
    // Physical input n (1-based) active or not (before INVERSE_POLARITY).
    void set_input(int n, bool active);
    void set_analog(int channel, std::int32_t mv);
    // Supply voltage (mV): below 12 V (DMAC17/23) or 20 V (DMAC34) the module
    // stops and latches undervoltage (#ERROR bit 4); above 49 V / 170 V it cuts
    // motor power and latches overvoltage (bit 5) -- manual 2.1.
    void set_supply_voltage(std::int32_t mv);
    // Temperatures (0.1 degC): CPU above 120 degC, driver or motor (DMAC34)
    // above 85 degC is a thermal disjunction (bit 2, manual 3.5.4).
    enum class Sensor : std::uint8_t { Cpu, Driver, Motor };
    void set_temperature(Sensor which, std::int32_t tenths_c);
    // Sets an #ERROR bit; the fault bits (2 thermal, 3 short-circuit,
    // 4 undervoltage, 5 overvoltage) also stop the motor as the real fault does.
    void inject_error(int bit);
    std::uint32_t physical_outputs(); // after polarity and OUT1/OUT2 alternate functions
    void power_cycle();               // same as MODULE_RESET
    // Wires IN6/OUT1 of these modules into one UltraSYNC chain (5.11).  Before
    // they are served: the modules then share one lock.  InvalidArgument for
    // fewer than two distinct modules, a module already chained, or modules on
    // different clocks.
    static void chain_ultrasync(const std::vector<std::shared_ptr<Sim>>& modules);
    // A mechanical limit on the rotor (friction, a brake: the figure of 5.11):
    // an interpolation segment faster than `inc_per_s` lasts |offset| / inc_per_s
    // instead of #INTERPOL_TIME.  0 = none.
    void set_speed_limit(double inc_per_s);
    std::uint64_t lines_handled();
    std::uint64_t lines_rejected();   // frames with at least one invalid command

private:
    struct Pending;  // a move armed by SYNCHRO ON, started by SYNCHRO TOP
    struct Chain;    // IN6/OUT1 UltraSYNC wiring between modules
    void catch_up_locked() { catch_up_locked(clock_->now()); }
    void catch_up_locked(Nanos at);  // every module of the chain up to the instant `at`
    void catch_up_self_locked(std::int64_t target_ms);
    std::int64_t ms_at(Nanos t) const;
    bool idle_locked() const;
    bool ultrasync_locked() const;
    void next_segment_locked();  // the current FIFO segment is done: start the next or stop
    void tick_locked();
    std::string handle_locked(std::string_view line);
    std::string execute_locked(const Command& c, bool from_sequencer, bool global);
    std::string sequencer_command_locked(const Command& c);
    void motion_command_locked(const Command& c);
    void synchro_command_locked(Keyword k);
    std::string setting_command_locked(const Command& c);
    // v in lo..hi; out of it flags the limit error.  false for nullopt (already flagged).
    bool in_range(std::optional<std::int32_t> v, std::int64_t lo, std::int64_t hi);
    void flag(int error_bit) { error_ |= bit_mask(error_bit); }

    std::optional<std::int32_t> read_var_locked(Var v, int bit);
    std::optional<std::int32_t> eval_operand(const Operand& o);
    std::optional<std::int32_t> eval(const Expr& e);
    int write_var_locked(Var v, int bit, std::int32_t value);  // 0 or error bit

    bool var_available(Var v) const;
    std::uint32_t status_locked();
    double motion_t() const;
    Nanos tick_time() const;
    double user_position() const;  // encoder counts before quantisation
    std::int32_t position_locked() const;
    std::int32_t speed_locked() const;
    std::int32_t profile_speed_locked() const;
    bool moving_locked() const;
    bool busy_locked() const;
    void coast(double tau_s);                  // power stage off: the rotor runs down
    void fault_locked(int error_bit);          // latch a hardware fault and react
    void check_supply_locked();                // re-latch faults whose cause persists
    bool dmac34() const;
    std::uint32_t input_mask() const;
    std::uint32_t logical_inputs() const;
    void restart_motion_at(double position);
    void halt_motion();
    void command_axis();
    void start_interp_segment();
    void advance_axis(Nanos t);
    void on_axis_event(const motion::MotorEvent& e);
    bool start_move(Cmd kind, std::int32_t value);
    void check_end_stops();
    void update_end_flags();
    void reset_locked(bool factory);
    ProfileParams params() const;

    std::shared_ptr<Clock> clock_;
    SimOptions options_;
    std::shared_ptr<std::mutex> mutex_ = std::make_shared<std::mutex>();  // the chain's, when chained
    std::shared_ptr<Chain> chain_;
    Nanos epoch_ns_ = 0;
    std::int64_t now_ms_ = 0;
    std::optional<Nanos> line_end_;  // when the line being handled ended on the wire (line_ends)

    std::array<std::int32_t, kVarCount> vars_{};
    std::uint32_t error_ = 0;
    std::uint32_t physical_inputs_ = 0;
    std::int32_t analog_[3] = {0, 0, 0};

    // stored configuration flags
    bool hard_pos_ = false, hard_neg_ = false, soft_ends_ = false;
    bool invert_in_ = false, invert_out_ = false, s_curve_ = false, optimized_current_ = false;
    int address_ = 0;
    std::int32_t baudrate_ = 38400;
    // volatile state
    bool power_ = false, brake_ = false, reference_ = false, synchro_ = false;
    bool abnormal_stop_ = false;
    bool coasting_ = false;  // power off / short-circuited, rotor running down
    bool in5_last_ = false;  // IN5 as last seen, for its rising edge
    void in5_changed_locked(std::int32_t position);
    bool hard_pos_hit_ = false, hard_neg_hit_ = false, soft_pos_hit_ = false, soft_neg_hit_ = false;

    // motion: the planner (its own time line from motion_t0_ms_) and the axis
    std::unique_ptr<motion::MotorModel> axis_;
    std::unique_ptr<Motion> motion_;
    std::int64_t motion_t0_ms_ = 0;
    bool position_mode_ = false;
    // #POSITION written during a move re-homes without disturbing it: the
    // plan keeps its own frame and the user (encoder) frame is shifted by this.
    std::int64_t pos_offset_ = 0;
    std::unique_ptr<Pending> pending_;

    // interpolation
    struct Segment {
        std::int32_t offset;
        int duration_ms;
    };
    std::deque<Segment> fifo_;
    bool interpolating_ = false;
    int seg_elapsed_ms_ = 0;
    int seg_duration_ms_ = 0;   // of the segment in progress (longer than #INTERPOL_TIME if speed-limited)
    bool seg_wait_ = false;     // UltraSYNC: done, waiting for the chained modules
    double speed_limit_ = 0;    // inc/s, 0 = none

    // sequencer (sequencer.hpp); SeqHost lends it this module's commands
    struct SeqHost;
    Sequencer seq_;
    bool first_reset_ = true;

    std::uint64_t lines_handled_ = 0, lines_rejected_ = 0;
};

}  // namespace motorbus::dmac

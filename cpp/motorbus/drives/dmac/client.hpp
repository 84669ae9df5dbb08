// Host side of the DMAC ASCII protocol on a serial::LineLink: typed methods for
// every command and variable, #STATUS/#ERROR decoding, the sequencer and
// interpolation streaming.  Several clients (one per module address) may share
// one LineLink on an RS-485 bus; the link serialises their transactions.
//
// Commands have no reply on a DMAC, so with `verify` (default) the client
// appends ", READ #ERROR" to each command frame: the module executes the
// command, answers its error register, and a rejected command raises at once.
#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "motorbus/drives/dmac/codec.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/serial/port.hpp"

namespace motorbus::dmac {

using Duration = std::chrono::nanoseconds;

// The module rejected a command as undefined (#ERROR bit 12), or a peer
// answered '?'.  Python: motorbus.drives.dmac.UnknownCommand (a DriveFault).
struct UnknownCommand : DriveFault {
    using DriveFault::DriveFault;
};
// A parameter outside its range (#ERROR bit 7) or a computation error (bit 8).
struct CommandRejected : DriveFault {
    CommandRejected(const std::string& what, std::uint32_t err) : DriveFault(what), error(err) {}
    std::uint32_t error;
};

// Line settings of the DMAC: the manual does not name them, so CR after
// requests, CR LF after replies (docs/drives/dmac.md, "Where the manual is
// ambiguous"); both configurable.
serial::LineOptions default_line_options();

struct Status {
    std::uint32_t raw = 0;
    bool bit(int n) const { return bit_set(raw, n); }
    bool busy() const { return bit(status::kBusy); }
    bool moving() const { return bit(status::kMovement); }
    bool power_on() const { return bit(status::kPowerOn); }
    bool error() const { return bit(status::kError); }
    bool sequencer_running() const { return bit(status::kSeqRun); }
    bool sequencer_edit() const { return bit(status::kSeqEdit); }
    bool position_control() const { return bit(status::kPositionControl); }
    bool abnormal_stop() const { return bit(status::kAbnormalStop); }
    bool end_stop() const {
        return bit(status::kHardPosEnd) || bit(status::kHardNegEnd) || bit(status::kSoftPosEnd) ||
               bit(status::kSoftNegEnd);
    }
    std::vector<std::string> names() const { return status_names(raw); }
};

struct ErrorWord {
    std::uint32_t raw = 0;
    bool bit(int n) const { return bit_set(raw, n); }
    bool any() const { return raw != 0; }
    std::vector<std::string> names() const { return error_names(raw); }
};

struct ClientOptions {
    int address = 0;
    bool verify = true;                               // append READ #ERROR to commands
    // Per transaction: how long the module may take to answer; default: the
    // link's reply timeout.  The client adds the turnaround the DMAC itself
    // inserts (#LINE_DELAY, up to 3 ms, 5.13) and the time a full 256-character
    // request and reply take on the wire at `baud`.
    std::optional<Duration> timeout{};
    int baud = 38400;                                 // the line's speed, for that allowance
    // How the client waits (polling, FIFO back-pressure).  Default: real sleep.
    // Tests on a SimClock pass a function that advances the clock instead.
    std::function<void(Duration)> sleep{};
};

enum class StopWhat : std::uint8_t { All, Movement, Sequence };
enum class PowerMode : std::uint8_t { On, Off, ShortCircuit };
enum class EndStops : std::uint8_t { Off, All, Positive, Negative };
enum class Polarity : std::uint8_t { Off, All, Inputs, Outputs };

struct ClientCounters {
    std::uint64_t transactions = 0;
    std::uint64_t stray_lines = 0;      // lines that were not the awaited reply (late, misrouted)
    std::uint64_t xon_errors = 0;       // MOVE_INTERPOL refused: FIFO full
    std::uint64_t device_resets = 0;    // version banners seen unsolicited
};

class Client {
public:
    Client(std::shared_ptr<serial::LineLink> link, ClientOptions options = {});

    int address() const { return options_.address; }
    serial::LineLink& link() { return *link_; }
    ClientCounters counters() const { return counters_; }

    // ---- generic ---------------------------------------------------------
    // Sends `command` (without address) to this module; with verify, checks #ERROR.
    void command(std::string_view command);
    std::int32_t read(Var v, Radix r = Radix::Dec);
    bool read_bit(Var v, int bit);
    void write(Var v, std::int32_t value);
    void write_bit(Var v, int bit, bool value);
    // Whole frame as typed (address included); returns the reply line, "" if none expected.
    std::string raw(std::string_view frame, bool expect_reply);

    // ---- variables -------------------------------------------------------
    std::int32_t position() { return read(Var::Position); }
    void set_position(std::int32_t p) { write(Var::Position, p); }
    std::int32_t speed() { return read(Var::Speed); }
    std::int32_t profile_speed() { return read(Var::ProfileSpeed); }
    Status status() { return Status{static_cast<std::uint32_t>(read(Var::Status, Radix::Hex))}; }
    ErrorWord error() { return ErrorWord{static_cast<std::uint32_t>(read(Var::Error, Radix::Hex))}; }
    void clear_error();
    std::uint32_t inputs() { return static_cast<std::uint32_t>(read(Var::Input)); }
    std::uint32_t outputs() { return static_cast<std::uint32_t>(read(Var::Output)); }
    void set_outputs(std::uint32_t v) { write(Var::Output, static_cast<std::int32_t>(v)); }
    void set_output(int n, bool on) { write_bit(Var::Output, n, on); }
    std::int32_t supply_voltage() { return read(Var::SupplyVoltage); }
    std::int32_t cpu_temperature() { return read(Var::CpuTemperature); }
    std::int32_t capture() { return read(Var::Capture); }
    std::int32_t interpol_count() { return read(Var::InterpolCount); }
    std::int32_t line() { return read(Var::Line); }
    void set_profile(std::optional<std::int32_t> high_speed, std::optional<std::int32_t> low_speed,
                     std::optional<std::int32_t> accel_ms, std::optional<std::int32_t> decel_ms);
    std::int32_t torque_ratio() { return read(Var::TorqueRatio); }
    void set_torque_ratio(std::int32_t percent) { write(Var::TorqueRatio, percent); }
    // Soft end-stop positions (#NEGATIVE_END, #POSITIVE_END); enable with soft_ends(true).
    std::pair<std::int32_t, std::int32_t> soft_limits() {
        return {read(Var::NegativeEnd), read(Var::PositiveEnd)};
    }
    void set_soft_limits(std::int32_t negative, std::int32_t positive);
    std::int32_t output_config() { return read(Var::OutputConfig); }
    void set_output_config(std::int32_t bits) { write(Var::OutputConfig, bits); }
    std::int32_t line_delay() { return read(Var::LineDelay); }
    void set_line_delay(std::int32_t us) { write(Var::LineDelay, us); }
    std::int32_t on_reset() { return read(Var::OnReset); }
    // #INTERPOL_TIME (ms), #INTERPOL_FIFOSIZE (segments), #INTERPOL_MODE (0 SimpleSYNC, -1 UltraSYNC).
    void set_interpolation(std::int32_t time_ms, std::int32_t fifo_size, std::int32_t mode = 0);
    // Analog input in mV: channel 1 = #INPUT_ANALOG on a DMAC17/23, #INPUT_A1
    // on a DMAC34; channel 2 = #INPUT_A2 (DMAC34 only).  The model is learnt
    // once from REQUEST_VERSION (a module answers nothing for a variable it lacks).
    std::int32_t analog_input(int channel);
    bool is_dmac34();
    // DMAC34 analog outputs (#OUTPUT_A1/#OUTPUT_A2), 0..10000 mV.
    void set_analog_output(int channel, std::int32_t mv);
    std::int32_t driver_temperature() { return read(Var::DriverTemperature); }
    std::int32_t motor_temperature() { return read(Var::MotorTemperature); }
    std::int32_t user_var(int n) { return read(v_var(check_family(n, 32, "#V"))); }
    void set_user_var(int n, std::int32_t v) { write(v_var(check_family(n, 32, "#V")), v); }
    std::int32_t memorized_var(int n) { return read(m_var(check_family(n, 8, "#M"))); }
    void set_memorized_var(int n, std::int32_t v) { write(m_var(check_family(n, 8, "#M")), v); }
    std::int32_t timer(int n) { return read(timer_var(check_family(n, 3, "#TIMER_"))); }
    void set_timer(int n, std::int32_t ms) { write(timer_var(check_family(n, 3, "#TIMER_")), ms); }

    // ---- commands --------------------------------------------------------
    void move_to(std::int32_t position);
    void move_on(std::int32_t offset);
    void move_speed(std::int32_t speed_001rpm);
    void stop(StopWhat what = StopWhat::All);
    void halt(StopWhat what = StopWhat::All);
    void power(PowerMode mode);
    void brake(bool on);
    void hard_ends(EndStops which);
    void soft_ends(bool on);
    void s_curve(bool on);
    void optimized_current(bool on);
    void inverse_polarity(Polarity p);
    void reference(bool on);
    void module_reset(bool factory = false);
    void set_address(int new_address);  // the client follows the module to its new address
    void set_baudrate(int baud);
    VersionInfo request_version();
    // Polls #STATUS until not busy; throws TimeoutError after `timeout`.
    // Returns the final position.
    std::int32_t wait_idle(Duration timeout, Duration poll = std::chrono::milliseconds(10));

    // ---- sequencer -------------------------------------------------------
    // OPEN_SEQ, one ":n <line>" frame per line from `first`, CLOSE_SEQ; then
    // each line is read back with READ_SEQ and compared, so a line the module
    // could not store raises CommandRejected naming it.
    void upload_sequence(const std::vector<std::string>& lines, int first = 1, bool verify_readback = true);
    std::string read_sequence_line(int n);  // canonical mnemonic form, "" = empty
    std::vector<std::string> read_sequence(int first, int last);
    void start_sequence(int line = 1);
    void stop_sequence() { stop(StopWhat::Sequence); }
    void step(std::optional<int> line = std::nullopt);
    void set_on_reset(int line) { write(Var::OnReset, line); }

    // ---- interpolation (single axis) ------------------------------------
    // Queues one segment.  Returns the FIFO level after it, or nullopt when the
    // FIFO was full (XON_ERROR) and the segment was NOT queued.
    std::optional<int> move_interpol(std::int32_t offset);

private:
    static int check_family(int n, int count, const char* name);
    std::string frame(std::string_view command) const;
    std::string await(const std::string& request, const std::function<bool(std::string_view)>& match,
                      bool send_only);
    ReadReply read_reply(const std::string& request, Var v, int bit);
    void sleep(Duration d);
    Duration reply_wait() const;
    std::optional<bool> dmac34_;

    std::shared_ptr<serial::LineLink> link_;
    ClientOptions options_;
    ClientCounters counters_;
};

// ---- global (bus-wide) commands and multi-axis helpers -------------------------
void synchro(serial::LineLink& link, Keyword what);  // ON, OFF, TOP, INTERPOL (no reply)

struct StreamOptions {
    int interpol_time_ms = 100;     // #INTERPOL_TIME written to every axis first
    int fifo_size = 64;             // #INTERPOL_FIFOSIZE written to every axis first
    std::function<void(Duration)> sleep;  // back-pressure wait (default: real sleep)
    Duration backoff{};             // wait after XON_ERROR; default: a quarter segment
};

struct StreamStats {
    std::size_t segments = 0;       // per axis
    std::uint64_t frames = 0;       // MOVE_INTERPOL frames sent (all axes, retries included)
    std::uint64_t xon_errors = 0;   // refusals on a full FIFO
    int min_level_after_start = 0;  // lowest FIFO level seen once moving (0 = underrun)
    std::uint64_t underruns = 0;    // times an axis reported an empty FIFO before the end
};

// Streams a multi-axis path: segments[k][i] is axis i's offset in segment k.
// Pre-fills every FIFO (same number of segments on each axis), starts all axes
// with SYNCHRO INTERPOL, then keeps feeding them round-robin, backing off on
// XON_ERROR, until every segment is queued.  Does not wait for the end of motion.
StreamStats stream_interpolation(std::vector<Client*> axes,
                                 const std::vector<std::vector<long long>>& segments,
                                 const StreamOptions& options = {});

}  // namespace motorbus::dmac

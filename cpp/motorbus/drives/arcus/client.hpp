// Client for Arcus DMX-CAN drives on an ASCII line.
//
// One Client talks to one device address.  Several Clients may share one
// LineLink: that is an RS-485 line with up to 99 devices (LineLink serializes
// transactions).  Every call blocks until the reply or the timeout and raises a
// typed error: TimeoutError, ProtocolError (bytes the device never sends, a
// reply for another address, a non-number where a number is due), ReplyError
// (the device refused the command with a Table 11.1 reply).
//
// Motion commands are never retried after a timeout (a lost "OK" does not mean
// the move did not start: query MST instead).  Queries are idempotent and are
// retried `query_retries` times.
#pragma once
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "motorbus/drives/arcus/codec.hpp"
#include "motorbus/serial/port.hpp"

namespace motorbus::arcus {

struct ClientOptions {
    int address = 1;                                  // 1..99
    std::optional<serial::Duration> timeout;          // default: the link's reply_timeout
    int query_retries = 1;                            // extra attempts for queries after a timeout
};

enum class HomeMethod { H, HL, ZH, Z, L };
std::string_view home_command(HomeMethod m, int direction);  // "HL+", "Z-", ...

struct ClientCounters {
    std::uint64_t requests = 0, timeouts = 0, retries = 0, protocol_errors = 0, device_errors = 0,
                  noise_lines = 0;  // lines of non-printable bytes skipped (A10)
};

class Client {
public:
    Client(std::shared_ptr<serial::LineLink> link, ClientOptions options = {});

    // Line settings for a LineLink to a DMX-CAN: CR after requests, NUL after
    // replies, replies bounded to kMaxReply bytes.
    static serial::LineOptions line_options(
        serial::Duration reply_timeout = std::chrono::milliseconds(200));

    int address() const { return options_.address; }
    serial::LineLink& link() { return *link_; }
    ClientCounters counters() const { return counters_; }

    // ---- raw access -----------------------------------------------------------
    // Sends `command` (without "@NN"), returns the reply body; throws ReplyError
    // for a refusal.  `idempotent` allows retries after a timeout.
    std::string command(std::string_view command, bool idempotent = false);
    // "@00<command>": every device acts, none replies.
    static void broadcast(serial::LineLink& link, std::string_view command);

    std::int64_t query(std::string_view name);          // "HSPD" -> 1000
    void set(std::string_view name, std::int64_t value); // "HSPD=1000" -> OK
    void action(std::string_view name);                 // "J+" -> OK

    // ---- identity / configuration --------------------------------------------------
    std::string id();
    std::string version();
    std::string device_name();                   // "DMC01"
    void set_device_name(int address);           // DN=DMCnn (effective after STORE + power cycle)
    int response_type();
    void set_response_type(int rt);
    void store();

    // ---- positions and status ---------------------------------------------------------
    std::int64_t position();                     // PX
    void set_position(std::int64_t p);
    std::int64_t encoder();                      // EX
    void set_encoder(std::int64_t e);
    std::int64_t delta();                        // DX
    std::int64_t speed();                        // PS
    MotorStatus status();                        // MST
    SnlStatus snl_status();                      // SLS
    bool moving();

    // ---- profile ------------------------------------------------------------------------
    std::int64_t high_speed();
    void set_high_speed(std::int64_t pps);
    std::int64_t low_speed();
    void set_low_speed(std::int64_t pps);
    std::int64_t acceleration();
    void set_acceleration(std::int64_t ms);
    std::int64_t deceleration();
    void set_deceleration(std::int64_t ms);
    bool unique_deceleration();
    void set_unique_deceleration(bool on);
    bool s_curve();
    void set_s_curve(bool on);
    int speed_window();                          // SSPDM
    void set_speed_window(int sspdm);

    // ---- motion -------------------------------------------------------------------------
    void absolute_mode();                        // ABS
    void incremental_mode();                     // INC
    bool incremental();                          // MM
    void move(std::int64_t target);              // X
    void change_target(std::int64_t target);     // T (on the fly)
    void change_speed(std::int64_t pps);         // SSPD (on the fly)
    void jog(int direction);                     // J+ / J-
    void stop();                                 // STOP: decelerate
    void abort();                                // ABORT: immediately
    void clear();                                // CLR: limit and StepNLoop errors
    void clear_snl();                            // CLRS
    void home(HomeMethod method, int direction);  // direction +1 or -1, else InvalidArgument
    std::int64_t home_correction();              // HCA
    void set_home_correction(std::int64_t steps);
    bool return_to_zero();                       // RZ
    void set_return_to_zero(bool on);
    std::int64_t limit_correction();             // LCA
    void set_limit_correction(std::int64_t steps);
    // Polls MST until no motion bit is set; TimeoutError after `timeout`.
    void wait_idle(serial::Duration timeout, serial::Duration poll = std::chrono::milliseconds(5));

    // ---- power and currents -------------------------------------------------------------
    bool enabled();                              // EO
    void enable(bool on);
    bool enabled_at_boot();                      // EOBOOT
    void set_enabled_at_boot(bool on);
    std::int64_t current();                      // CUR, mA
    std::int64_t run_current();                  // CURR
    void set_run_current(std::int64_t ma);
    std::int64_t idle_current();                 // CURI
    void set_idle_current(std::int64_t ma);
    std::int64_t idle_time();                    // CURT, ms
    void set_idle_time(std::int64_t ms);

    // ---- I/O (1-based bit names as in the manual: DI1 is bit 0) ---------------------------
    unsigned digital_inputs();                   // DI
    bool digital_input(int n);                   // DI1..DI6
    unsigned digital_outputs();                  // DO
    void set_digital_outputs(unsigned value);    // 0..7
    bool digital_output(int n);                  // DO1..DO3
    void set_digital_output(int n, bool on);
    unsigned outputs_at_boot();                  // DOBOOT
    void set_outputs_at_boot(unsigned value);
    bool alarm_outputs();                        // EDO
    void set_alarm_outputs(bool on);
    unsigned polarity();                         // POL
    void set_polarity(unsigned bits);

    // ---- latch (DI2) and sync output (DO2) ------------------------------------------------
    void enable_latch(bool on);                  // LT
    LatchStatus latch_status();                  // LTS
    std::int64_t latched_position();             // LTP
    std::int64_t latched_encoder();              // LTE
    void sync_on();                              // SYNO
    void sync_off();                             // SYNF
    std::int64_t sync_position();                // SYNP
    void set_sync_position(std::int64_t p);
    SyncCondition sync_condition();              // SYNC
    void set_sync_condition(SyncCondition c);
    SyncStatus sync_status();                    // SYNS

    // ---- StepNLoop --------------------------------------------------------------------------
    bool snl_enabled();                          // SL
    void set_snl_enabled(bool on);
    std::int64_t snl_tolerance();                // SLT
    void set_snl_tolerance(std::int64_t counts);
    std::int64_t snl_error_range();              // SLE
    void set_snl_error_range(std::int64_t counts);
    std::int64_t snl_max_attempts();             // SLA
    void set_snl_max_attempts(std::int64_t n);
    std::int64_t snl_idle_tolerance();           // SLM
    void set_snl_idle_tolerance(std::int64_t counts);
    double snl_ratio();                          // SLR, pulses per encoder count ("0.800")
    void set_snl_ratio(double pulses_per_count); // 0.001..999.999, rounded to 1/1000

    // ---- communication settings (take effect after STORE and a power cycle) ----------------
    int comm_mode();                             // CM
    void set_comm_mode(int mode);
    int baud_code();                             // DB
    void set_baud_code(int code);
    int can_bit_rate_code();                     // BR
    void set_can_bit_rate_code(int code);
    int node_id();                               // NID
    void set_node_id(int id);

private:
    std::string transact(std::string_view command, bool idempotent);
    void expect_ok(std::string_view command, const std::string& body);
    static void check_index(int n, int max, const char* what);

    std::shared_ptr<serial::LineLink> link_;
    ClientOptions options_;
    ClientCounters counters_;
};

}  // namespace motorbus::arcus

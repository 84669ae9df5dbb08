// Arcus DMX-CAN ASCII protocol (manual 000, sections 7, 9, 11): pure codec.
//
// Request:  "@" <2-digit address> <command> CR      ("@00" = broadcast, no reply)
// Reply:    RT=0  <value> NUL        RT=1  "#" <2-digit address> <value> NUL
// Errors:   "?" <command>  or one of the fixed texts of Table 11.1.
//
// Everything here is bytes in, values out: no I/O, no state.
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "motorbus/errors.hpp"

namespace motorbus::arcus {

inline constexpr char kRequestTerminator = '\r';
inline constexpr char kReplyTerminator = '\0';
inline constexpr int kBroadcast = 0;
inline constexpr int kMaxAddress = 99;
// Longest reply the device produces is "#NN?" + an echoed command of at most
// kMaxRequest bytes; a reply longer than this is noise, not a slow device.
inline constexpr std::size_t kMaxReply = 72;
// The device echoes unknown commands back in "?<cmd>"; cap what we keep.
inline constexpr std::size_t kMaxRequest = 64;
// Largest relative move the controller accepts (Table 11.0, X).
inline constexpr std::int64_t kMaxIncrement = 262143;

// How a command is used on the wire.
enum CommandForm : unsigned {
    kQuery = 1u << 0,    // "HSPD"        -> value
    kSet = 1u << 1,      // "HSPD=1000"   -> OK
    kAction = 1u << 2,   // "J+"          -> OK
    kArgument = 1u << 3, // "X1000"       -> OK  (value glued to the name)
    kIndexed = 1u << 4,  // "DI3", "DO2=1"
};

struct CommandInfo {
    std::string_view name;
    unsigned forms;          // CommandForm bits
    bool motion;             // refused with ?Moving / ?State Error when busy / in error
    bool stored;             // written to flash by STORE (Table 7.10)
    int index_max;           // for kIndexed: highest 1-based index (DI6, DO3)
    std::string_view description;
};

// Table 11.0 plus the commands the manual describes elsewhere (T, SYNO/SYNF/SYNP/
// SYNC/SYNS, HCA, RZ, CLRS, SSPD, SSPDM).  Sorted by name.
std::span<const CommandInfo> command_table();
const CommandInfo* find_command(std::string_view name);

// Error replies of Table 11.1.
enum class ErrorCode {
    UnknownCommand,   // "?<command>" (or a bare "?")
    BadSspd,          // "?Bad SSPD Command"
    EnableRs485,      // "?Enable RS-485 Mode"
    IndexOutOfRange,  // "?Index out of Range"
    MotorNotMoving,   // "?Motor is not moving"
    Moving,           // "?Moving"
    ScvOn,            // "?SCV ON"
    SpeedOutOfRange,  // "?Speed out of range"
    StateError,       // "?State Error"
};
std::string_view error_text(ErrorCode code);        // reply body, e.g. "?Moving"
std::string_view error_name(ErrorCode code);        // "Moving"
// Classifies a reply body starting with '?'; nullopt if it is not an error.
std::optional<ErrorCode> classify_error(std::string_view body);

// The controller refused a command with one of the replies of Table 11.1.
struct ReplyError : DriveFault {
    ReplyError(ErrorCode c, std::string reply_body, std::string request_cmd)
        : DriveFault("arcus: " + std::string(request_cmd) + " -> " + reply_body),
          code(c), reply(std::move(reply_body)), command(std::move(request_cmd)) {}
    ErrorCode code;
    std::string reply;    // e.g. "?Moving"
    std::string command;  // the command that was refused
};

// ---- requests ----------------------------------------------------------------
// Validates address (0..99) and command (printable ASCII, no CR/NUL/'@', length
// <= kMaxRequest) and returns "@NN<command>\r".  Throws InvalidArgument.
std::string build_request(int address, std::string_view command);
// The same without the terminator (LineLink appends its own).
std::string format_command(int address, std::string_view command);
std::string build_query(int address, std::string_view name);
std::string build_set(int address, std::string_view name, std::int64_t value);
std::string build_action(int address, std::string_view name);
std::string build_argument(int address, std::string_view name, std::int64_t value);

// A request line as the device sees it (terminator already stripped).
struct Request {
    int address = 0;
    std::string command;  // everything after "@NN"
};
// nullopt when the line is not "@" + two digits + something.
std::optional<Request> parse_request_line(std::string_view line);

// A command split into its parts.
struct ParsedCommand {
    const CommandInfo* info = nullptr;
    enum class Op { Query, Set, Action, Argument } op = Op::Query;
    int index = 0;                       // 1-based for DI/DO bit commands, 0 = whole register
    bool index_valid = true;             // false: "?Index out of Range"
    std::optional<std::int64_t> value;   // Set / Argument
    std::string text_value;              // raw right-hand side (DN=DMC05)
};
// nullopt = not a command of the table (device replies "?<command>").
std::optional<ParsedCommand> parse_command(std::string_view command);

// ---- replies -----------------------------------------------------------------
struct Reply {
    std::optional<int> address;  // present for RT=1 replies ("#01...")
    std::string body;            // the value, "OK" or the error text
};
// `raw` is one reply without its NUL.  Accepts both formats; throws ProtocolError
// on bytes the device never sends (control chars, non-ASCII, over-long).
Reply parse_reply(std::string_view raw);
// Builds the reply bytes (terminator included) the way the device sends them.
std::string format_reply(int address, std::string_view body, int response_type);

// Strict decimal integer: optional '-' (a '+' is tolerated), 1..10 digits, no
// spaces, inside int32.  nullopt otherwise.
std::optional<std::int64_t> parse_int(std::string_view text);
// SLR's fixed-point form (docs/drives/arcus.md): "0.800" <-> 800 thousandths.
// parse_milli takes 1..6 digits, optionally '.' and 1..3 decimals, no sign;
// nullopt otherwise.  format_milli always writes three decimals.
std::optional<std::int64_t> parse_milli(std::string_view text);
std::string format_milli(std::int64_t milli);
// StepNLoop ratio limits (thousandths): 0.001..999.999 pulses per count.
inline constexpr std::int64_t kSlrMinMilli = 1, kSlrMaxMilli = 999'999;
// Throws ProtocolError when `body` is not a strict int32.
std::int64_t reply_int(std::string_view body);

// ---- decoded registers ---------------------------------------------------------
struct MotorStatus {  // MST, Table 7.3
    std::uint32_t raw = 0;
    bool constant_speed() const { return raw & 1u; }
    bool accelerating() const { return raw & 2u; }
    bool decelerating() const { return raw & 4u; }
    bool home() const { return raw & 8u; }
    bool minus_limit() const { return raw & 16u; }
    bool plus_limit() const { return raw & 32u; }
    bool minus_limit_error() const { return raw & 64u; }
    bool plus_limit_error() const { return raw & 128u; }
    bool latch_input() const { return raw & 256u; }
    bool z_index() const { return raw & 512u; }
    bool moving() const { return raw & 7u; }
};

enum class SnlStatus {  // SLS, Tables 7.6 / 8.14 (12 and 13 from 8.14)
    Idle = 0, Moving = 1, Correcting = 2, Stopping = 3, Aborting = 4, Jogging = 5,
    Homing = 6, ZHoming = 7, CorrectionRangeError = 8, CorrectionAttemptError = 9,
    StallError = 10, LimitError = 11, Disabled = 12, LimitHoming = 13,
};
std::optional<SnlStatus> snl_status_from(std::int64_t v);
std::string_view snl_status_name(SnlStatus s);
inline bool snl_error(SnlStatus s) {
    return s == SnlStatus::CorrectionRangeError || s == SnlStatus::CorrectionAttemptError ||
           s == SnlStatus::StallError || s == SnlStatus::LimitError;
}

enum class LatchStatus { Off = 0, Waiting = 1, Triggered = 2 };   // LTS, Table 7.4
enum class SyncStatus { Off = 0, Waiting = 1, Occurred = 2 };     // SYNS
enum class SyncCondition { Equal = 1, Less = 2, Greater = 3 };    // SYNC

// Appendix A speed windows.
struct SpeedWindow {
    int sspdm;
    std::int64_t hspd_min, hspd_max;  // inclusive pps
    std::int64_t min_lspd;
    std::int64_t min_acc_ms;
    std::int64_t delta;
};
std::span<const SpeedWindow> speed_windows();
// Window containing `hspd` (nullopt above 6 M).
std::optional<SpeedWindow> window_for_speed(std::int64_t hspd);
// Window selected by SSPDM (0 and 1 are the same window).
std::optional<SpeedWindow> window_for_sspdm(std::int64_t sspdm);
// Max ACC [ms] = ((HSPD - LSPD) / delta) * 1000, at least the minimum.
std::int64_t max_acc_ms(std::int64_t hspd, std::int64_t lspd);
std::int64_t min_acc_ms(std::int64_t hspd);
// ACC as the controller adjusts it ("automatically adjusted if out of range").
std::int64_t clamp_acc_ms(std::int64_t acc, std::int64_t hspd, std::int64_t lspd);

}  // namespace motorbus::arcus

// UNITEK BAMOCAR / BAMOBIL / DS register protocol on CAN (002 manual §4-§6).
//
// Not CANopen: every frame is one REGID byte followed by a little-endian value.
//   to the drive (receive id, default 0x201):   REGID v0 v1          (DLC 3, 16-bit)
//                                               REGID v0 v1 v2 v3    (DLC 5, 32-bit)
//   from the drive (transmit id, default 0x181): REGID v0 v1 dummy   (DLC 4)
//                                               REGID v0 v1 v2 v3 dummy (DLC 6)
// A read request is the pseudo-register 0x3D: `3D <REGID> <interval>` with
// interval 0x00 = once, 0x01-0xFE = every n ms, 0xFF = stop.
//
// Everything here is pure (bytes in, values out).  Malformed input throws
// FrameError, which names the byte at fault; nothing reads past the DLC.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "motorbus/errors.hpp"

namespace motorbus::unitek {

// ---- the documented REGIDs (002; specs/can-drives.md §2.2) ----------------------------
inline constexpr std::uint8_t kRegSpeedActual = 0x30;  // SPEED_IST
inline constexpr std::uint8_t kRegSpeedCmd = 0x31;     // SPEED_CMD / SPEED_SOLL
inline constexpr std::uint8_t kRegAccRamp = 0x35;      // ACC ramp, ms
inline constexpr std::uint8_t kRegRead = 0x3D;         // transmission request
inline constexpr std::uint8_t kRegStatus = 0x40;       // KERN_STATUS
inline constexpr std::uint8_t kRegMode = 0x51;         // MODE
inline constexpr std::uint8_t kRegEventMask = 0x52;    // event configuration mask
inline constexpr std::uint8_t kRegRxId = 0x68;         // CAN-ID-Rx
inline constexpr std::uint8_t kRegPosDest = 0x6E;      // POS_DEST
inline constexpr std::uint8_t kRegEeprom = 0x84;       // write EEPROM
inline constexpr std::uint8_t kRegTorqueCmd = 0x90;    // TORQUE-CMD
inline constexpr std::uint8_t kRegA8 = 0xA8;           // unnamed, §5.2's request example
// Not in 002: the actual position, which any position adapter needs.  NDrive's
// register list (outside this manual) has it; the sim serves it and the Python
// adapter adds it from its TOML file (cpp/motorbus/drives/unitek/ndrive.toml).
inline constexpr std::uint8_t kRegPosActual = 0x6D;
// Not in 002 either: NDrive's error/warning register (32 bit, read-only): bits 0-15
// the errors (each switches the power stage off), bits 16-31 the warnings.  The sim
// serves it; the Python adapter reads it to say why a move ended.
inline constexpr std::uint8_t kRegErrWarn = 0x8F;
inline constexpr std::uint32_t kErrorBits = 0x0000FFFF;
// Not in 002 either: the current registers behind §6.1's current table (NDrive's
// list; verify against your firmware's).  All in num, the device's current scale.
inline constexpr std::uint8_t kRegCurrentActual = 0x20;     // I_ACT: the current the drive delivers (RO)
inline constexpr std::uint8_t kRegCurrentLimit = 0x24;      // I_MAX: the motor's peak current limit (a parameter)
inline constexpr std::uint8_t kRegCurrentCmd = 0x26;        // I_CMD: current command value
inline constexpr std::uint8_t kRegDeviceCurrentMax = 0xC4;  // DEVICE_I_MAX: the device's peak current (RO)
// §6.1 "Current command value range: max. value +/- 9 bit" (the position and speed
// ranges, "+/- 31 bit" and "+/- 15 bit", are 2^31 - 1 and 2^15 - 1): +/- 511 num.
inline constexpr std::int64_t kCurrentCommandMax = 511;
// The analog command inputs (NDrive's list: AIN1 0xD5, AIN2 0xD6): "the analog
// command value (AIN1, AIN2) 10 V corresponds to 29490 (90 % of the max. speed)" (§6.1).
inline constexpr std::uint8_t kRegAin1 = 0xD5;
inline constexpr std::uint8_t kRegAin2 = 0xD6;
inline constexpr double kAnalogNumPerVolt = 2949.0;
inline constexpr double kAnalogMaxVolts = 10.0;  // the inputs' +/- 10 V range
// The num of `volts` on AIN1/AIN2; InvalidArgument outside +/- 10 V (or not finite).
std::int64_t analog_command_num(double volts);

inline constexpr std::uint32_t kDefaultRxId = 0x201;
inline constexpr std::uint32_t kDefaultTxId = 0x181;
inline constexpr std::uint32_t kRxIdMin = 0x201, kRxIdMax = 0x27F;
inline constexpr std::uint32_t kTxIdMin = 0x181, kTxIdMax = 0x1FF;
inline constexpr int kMaxCyclic = 8;  // "at most 8 registers" (ex 9)

// Read-request interval byte.
inline constexpr std::uint8_t kIntervalOnce = 0x00;
inline constexpr std::uint8_t kIntervalStop = 0xFF;

// KERN_STATUS bits (§2.3).  Icns has no documented bit: the sim uses bit 5 [P].
enum StatusBits : std::uint32_t {
    kStatusEna = 1u << 0,
    kStatusLimPlus = 1u << 2,
    kStatusLimMinus = 1u << 3,
    kStatusIcns = 1u << 5,
    kStatusPositionControl = 1u << 7,
    kStatusSpeedControl = 1u << 8,
    kStatusCal = 1u << 12,
    kStatusTol = 1u << 13,
};
// MODE bits.
enum ModeBits : std::uint16_t {
    kModeDisable = 1u << 2,
    kModeEvents = 1u << 4,
};
inline constexpr std::uint16_t kDefaultEventMask = 0x0030;

// The status bits an event mask selects (C-U01: the three documented masks by
// table, any other mask bit n <-> status bit n).
std::uint32_t event_status_mask(std::uint16_t mask);

// ---- errors ----------------------------------------------------------------------------
// A frame that breaks the protocol.  `byte` is the 0-based index of the byte at
// fault (== the DLC when a byte is missing); Python: UnitekFrameError(ProtocolError).
struct FrameError : ProtocolError {
    FrameError(const std::string& what, int byte_at_fault, std::vector<std::uint8_t> bytes)
        : ProtocolError(what, std::move(bytes)), byte(byte_at_fault) {}
    int byte;
};
// A REGID the register table does not know.  Python: UnitekUnknownRegister(InvalidArgument, KeyError).
struct UnknownRegister : InvalidArgument {
    UnknownRegister(const std::string& what, std::uint8_t r) : InvalidArgument(what), regid(r) {}
    std::uint8_t regid;
};
// A 9th cyclic register.  Python: UnitekCyclicLimit(InvalidArgument).
struct CyclicLimit : InvalidArgument {
    using InvalidArgument::InvalidArgument;
};

// ---- the register table (data, extendable) -------------------------------------------
enum class Access : std::uint8_t { ReadWrite, ReadOnly, WriteOnly };
// What a register's "num" means physically (§6.1); the factors come from Scalings.
enum class Quantity : std::uint8_t {
    Raw,       // num * scale (user rows: "scale" from the TOML)
    Speed,     // num / 32767 * N max  -> rpm
    Position,  // num / 65536          -> revolutions
    Current,   // num / I max num * I max A -> A (per device type)
    Torque,    // num / 32767 * 100    -> %
    Time,      // num * scale          -> ms (scale 1)
};

struct Register {
    std::uint8_t regid = 0;
    std::string name;
    int bits = 16;            // 16 or 32 on the wire
    bool is_signed = false;
    Access access = Access::ReadWrite;
    Quantity quantity = Quantity::Raw;
    std::string unit;         // physical unit after scaling ("rpm", "rev", "A", "%", "ms", "")
    double scale = 1.0;       // extra factor (Raw / Time); 1 for the others
    std::int64_t min = 0, max = 0;  // allowed num range for writes (min > max: the width's full range)
    std::string description;
    bool readable() const { return access != Access::WriteOnly; }
    bool writable() const { return access != Access::ReadOnly; }
    // Full range of the width when no range was given.
    std::int64_t lo() const;
    std::int64_t hi() const;
    // Raw wire value (zero-extended) -> the register's integer value (sign-extended if signed).
    std::int64_t from_raw(std::uint32_t raw, int raw_bits) const;
};

class RegisterTable {
public:
    // The 12 documented REGIDs (0x3D is the request itself and is not a register).
    static RegisterTable builtin();
    // Adds or replaces a row (a user's NDrive list overrides a built-in name/unit).
    // Throws InvalidArgument naming the field (bits not 16/32, regid 0x3D, empty name...).
    void add(Register r);
    const Register* find(std::uint8_t regid) const;
    const Register* find(const std::string& name) const;  // case-insensitive
    // Throws UnknownRegister.
    const Register& at(std::uint8_t regid) const;
    const Register& at(const std::string& name) const;
    std::vector<Register> rows() const;
    std::size_t size() const { return rows_.size(); }

private:
    std::map<std::uint8_t, Register> rows_;
};

// Physical scalings (§6.1).
struct Scalings {
    double n_max_rpm = 3000;          // N max: the speed of 32767 num
    double counts_per_rev = 65536;    // position num per motor revolution
    double i_max_num = 160;           // current num of the device's peak current (DS 205/405: 160 num = 10 A)
    double i_max_a = 10;
    void validate() const;
    double to_physical(const Register& r, std::int64_t num) const;
    std::int64_t to_num(const Register& r, double physical) const;  // rounded, not range-checked
};
// Current scaling of one device type (§6.1 table).
struct DeviceCurrent {
    const char* device;
    double i100_mv, i100_num, i_rms_a, i_peak_a, i_max_num, i_max_a;
};
std::span<const DeviceCurrent> device_currents();
// I_con limit example: the num for `amps` of continuous current on `device`.
std::int64_t continuous_current_num(const DeviceCurrent& d, double amps);
// The row of §6.1 for `device` ("DS 205/405", "DS 412", "DS 420"); InvalidArgument naming them.
const DeviceCurrent& device_current(const std::string& device);
// §6.1 "Limitation in the parameter field. Motor and current. The smaller value is
// effective": the peak current (num) the drive delivers at most.  InvalidArgument for
// a negative motor limit.
std::int64_t effective_current_limit_num(const DeviceCurrent& d, std::int64_t motor_limit_num);

// ---- bit timing (§3.1 table) -----------------------------------------------------------
// NDrive's CAN-Setup "NBT": each bit rate has a BTR setting value and a longest line.
struct BitTiming {
    int kbit_s;             // 1000, 500, 625, 250, 100
    std::uint16_t btr;      // 0x4002, 0x4025, 0x4014, 0x405C, 0x4425
    int max_line_m;         // 20, 70, 70, 100, 500
    double bit_rate() const { return kbit_s * 1000.0; }
};
std::span<const BitTiming> bit_timings();
inline constexpr std::uint16_t kDefaultBtr = 0x4025;  // "the UNITEK standard is 500 kB/s" (§4.1)
// InvalidArgument naming the value and the five the table has.
const BitTiming& bit_timing_for_btr(std::uint16_t btr);
const BitTiming& bit_timing_for_bit_rate(double bit_s);

// ---- frames --------------------------------------------------------------------------
// What the drive receives, as the drive evaluates it (B-U01..B-U03): DLC 3 and 4 carry
// a 16-bit value (byte 3 ignored), DLC 5..8 a 32-bit value (bytes 5..7 ignored).
struct ToDrive {
    std::uint8_t regid = 0;
    std::uint32_t value = 0;  // raw, zero-extended
    int value_bits = 16;      // 16 or 32
    bool is_request() const { return regid == kRegRead; }
    std::uint8_t request_regid() const { return static_cast<std::uint8_t>(value & 0xFF); }
    std::uint8_t request_interval() const { return static_cast<std::uint8_t>((value >> 8) & 0xFF); }
};
// Throws FrameError for DLC < 3 (naming the first missing byte).
ToDrive decode_to_drive(std::span<const std::uint8_t> data);

// What the drive sends: DLC 4 (16-bit) or DLC 6 (32-bit); the last byte is a dummy.
struct FromDrive {
    std::uint8_t regid = 0;
    std::uint32_t value = 0;  // raw, zero-extended
    int value_bits = 16;
};
// Throws FrameError for any other DLC (naming the byte at fault).
FromDrive decode_from_drive(std::span<const std::uint8_t> data);

// Encoders (the bytes of the frame).  encode_write checks the value fits the width
// (signed or unsigned) and throws InvalidArgument naming the register otherwise.
std::vector<std::uint8_t> encode_write(std::uint8_t regid, std::int64_t value, int bits);
std::vector<std::uint8_t> encode_write(const Register& r, std::int64_t value);  // + range/access checks
std::vector<std::uint8_t> encode_request(std::uint8_t regid, std::uint8_t interval);
// interval_ms 1..254 -> a cyclic request; InvalidArgument otherwise.
std::vector<std::uint8_t> encode_cyclic(std::uint8_t regid, int interval_ms);
std::vector<std::uint8_t> encode_reply(std::uint8_t regid, std::uint32_t raw, int bits, std::uint8_t dummy = 0);

std::string hex(std::span<const std::uint8_t> data);

}  // namespace motorbus::unitek

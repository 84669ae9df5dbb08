// DMAC ASCII protocol (Midi Ingenierie DMAC17/23/34): pure parsing and
// formatting of command frames and module replies.  No I/O, no state.
//
// Frame:  [aa][:n ]CMD [args][, CMD [args]]...      (aa = 00..63, absent = global)
// Reply:  aa#MNEMONIC[.bit]=+123 | =h0000007B | =b00000000 00000000 00000000 01111011
// Readings the project follows where the manual contradicts itself: see
// docs/drives/dmac.md, "Where the manual is ambiguous" (bits numbered 1..32
// from the LSB, sign always emitted on replies).
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace motorbus::dmac {

inline constexpr char kXonError = 0x17;           // full interpolation FIFO
inline constexpr std::size_t kMaxFrame = 256;      // manual: frame <= 256 characters
inline constexpr int kGlobal = -1;                 // frame without an address
inline constexpr int kMaxAddress = 63;
inline constexpr int kSeqLines = 500;

enum class Radix : std::uint8_t { Dec, Hex, Bin };

// ---- variables ---------------------------------------------------------------
// One entry per addressable variable; families (#V1..#V32, #M1..#M8,
// #TIMER_1..#TIMER_3) get one entry per member so every variable is an index.
struct VarInfo {
    std::string name;      // "#ACCEL_TIME"
    std::string mnemonic;  // "#ATI"
    bool stored;           // survives power cycle / MODULE_RESET
    bool read_only;
    std::int32_t factory;  // value after MODULE_RESET ALL (stored) or reset (volatile)
    std::int64_t min, max; // accepted write range
    bool dmac34_only;
};

enum class Var : std::uint8_t {
    AccelTime, Capture, CpuTemperature, DecelTime, DriverTemperature, Error, HighSpeed,
    Input, InputAnalog, InputA1, InputA2, InterpolCount, InterpolFifosize, InterpolMode,
    InterpolTime, LineDelay, Line, LowSpeed, MotorTemperature, NegativeEnd, OnReset,
    Output, OutputA1, OutputA2, OutputConfig, Position, PositiveEnd, ProfileSpeed, Speed,
    Status, SupplyVoltage, TorqueRatio,
    Timer1, Timer2, Timer3,
    M1, M8 = M1 + 7,
    V1, V32 = V1 + 31,
    Count_
};
inline constexpr std::size_t kVarCount = static_cast<std::size_t>(Var::Count_);
inline constexpr Var timer_var(int n) { return static_cast<Var>(static_cast<int>(Var::Timer1) + n - 1); }
inline constexpr Var m_var(int n) { return static_cast<Var>(static_cast<int>(Var::M1) + n - 1); }
inline constexpr Var v_var(int n) { return static_cast<Var>(static_cast<int>(Var::V1) + n - 1); }

const VarInfo& var_info(Var v);
// Accepts the full name or the mnemonic, with or without '#', any case.
std::optional<Var> find_variable(std::string_view name);

// ---- #STATUS and #ERROR (bit n = 1..32, bit 1 = LSB) -------------------------
namespace status {
inline constexpr int kOptimizedCurrent = 4, kHardPosEnabled = 5, kHardNegEnabled = 6,
                     kSoftEndsEnabled = 7, kHardEndsInverted = 8, kSCurve = 12,
                     kInputsInverted = 13, kOutputsInverted = 14, kSeqRun = 15,
                     kSeqEdit = 16, kHardPosEnd = 17, kHardNegEnd = 18, kSoftPosEnd = 19,
                     kSoftNegEnd = 20, kBrake = 21, kSynchro = 23, kPowerOn = 25,
                     kMovement = 26, kPositionControl = 27, kBusy = 29, kReference = 30,
                     kError = 31, kAbnormalStop = 32;
}
namespace error {
inline constexpr int kThermal = 2, kShortCircuit = 3, kUndervoltage = 4, kOvervoltage = 5,
                     kLimit = 7, kComputation = 8, kSyntax = 12;
}
inline constexpr std::uint32_t bit_mask(int bit_1based) { return 1u << (bit_1based - 1); }
inline constexpr bool bit_set(std::uint32_t word, int bit_1based) {
    return bit_1based >= 1 && bit_1based <= 32 && (word & bit_mask(bit_1based)) != 0;
}
// Names of the set bits, e.g. {"busy", "movement", "power_on"}.
std::vector<std::string> status_names(std::uint32_t status);
std::vector<std::string> error_names(std::uint32_t error);

// ---- commands ---------------------------------------------------------------
enum class Cmd : std::uint8_t {
    Invalid, Assign, Brake, Call, CloseSeq, Halt, HardEnds, If, InversePolarity, Jump,
    JumpRel, ModuleReset, MoveInterpol, MoveOn, MoveSpeed, MoveTo, Nop, OpenSeq,
    OptimizedCurrent, Power, Read, ReadSeq, Reference, Return, RequestVersion, SetAddress,
    SetBaudrate, SCurve, SoftEnds, StartSeq, Step, Stop, Synchro, Wait
};
struct CommandInfo {
    Cmd cmd;
    std::string_view name;       // "MOVE_TO"
    std::string_view mnemonic;   // "MTO"
    std::string_view alt;        // second mnemonic ("RVE") or empty
};
const CommandInfo& cmd_info(Cmd c);
std::optional<Cmd> find_command(std::string_view word);

enum class Keyword : std::uint8_t { None, On, Off, Sc, All, Pos, Neg, In, Out, Mouv, Seq, Top, Interpol };
std::string_view keyword_text(Keyword k);

enum class Op : std::uint8_t { None, Add, Sub, Mul, Div, And, Or, Gt, Lt, Ge, Le, Ne, Eq };
std::string_view op_text(Op op);

struct Operand {
    bool is_var = false;
    std::int32_t value = 0;  // constant
    Var var = Var::V1;
    int bit = 0;             // 0 = whole variable, 1..32 = that bit
    bool negate = false;     // leading '-' before a variable
    bool complement = false; // leading '!'
};
struct Expr {
    Operand lhs;
    Op op = Op::None;
    Operand rhs;
};

struct Command {
    Cmd cmd = Cmd::Invalid;
    // Assign: target variable/bit and value
    Var var = Var::V1;
    int bit = 0;
    Expr expr;                 // Assign value, IF test, or the numeric argument
    bool has_arg = false;      // numeric argument present (MOVE_TO, WAIT, START_SEQ, ...)
    Keyword keyword = Keyword::None;
    Radix radix = Radix::Dec;  // READ
    Cmd jump = Cmd::Invalid;   // IF: Jump, JumpRel or Call
    Expr target;               // IF: jump target
    int error_bit = 0;         // Invalid: error::kSyntax or error::kLimit
};

struct Request {
    int address = kGlobal;     // 0..63 or kGlobal
    int seq_line = 0;          // ":n" prefix (1..500), 0 = none
    bool address_error = false;// two digits present but > 63
    std::vector<Command> commands;
};

// Never throws; malformed commands come back as Cmd::Invalid with an error bit.
Request parse_request(std::string_view line);
// Canonical mnemonic form, as READ_SEQ prints a stored line ("MTO +2000").
std::string format_command(const Command& c);
std::string format_operand(const Operand& o);
std::string format_expr(const Expr& e);

// ---- values -----------------------------------------------------------------
// "+123" / "-5", "h0000007B", "b00000000 00000000 00000000 01111011".
std::string format_value(std::int32_t v, Radix r);
// Operand constant: optional '+'/'-' then decimal, or H/h hex (1..8 digits),
// or B/b binary (1..32 digits).  Out of int32 range -> nullopt.
std::optional<std::int32_t> parse_number(std::string_view s);

// ---- replies ----------------------------------------------------------------
struct ReadReply {
    int address = 0;
    std::string mnemonic;   // "#ATI"
    int bit = 0;
    std::int32_t value = 0;
    Radix radix = Radix::Dec;
};
// Strict: two address digits, '#', mnemonic, optional .bit, '=', value.
// Decimal accepts an optional sign (the manual prints both); hex 1..8 digits;
// binary 1..32 digits in optional groups of 8 separated by single spaces.
std::optional<ReadReply> parse_read_reply(std::string_view reply);
std::string format_read_reply(int address, Var v, int bit, std::int32_t value, Radix r);

struct SeqLineReply {
    int address = 0;
    int line = 0;
    std::string text;       // "MTO +2000"; empty for an unwritten line
};
std::optional<SeqLineReply> parse_seq_reply(std::string_view reply);
std::string format_seq_reply(int address, int line, std::string_view text);

struct VersionInfo {
    int address = 0;
    int version = 0, release = 0;  // v1.7
    std::string code;              // "H142"
    std::string model;             // from the code table, e.g. "DMAC34 standard"
    std::string ident;             // text between the quotes
    std::string manufacturer, product, serial, manufacturing_date, revision_date;
    std::string phase;             // "6A"
    std::string boot;              // "v1.1"
};
std::optional<VersionInfo> parse_version(std::string_view reply);
std::string_view model_for_code(std::string_view code);

// ---- request encoding (client side; full names as in the manual's examples) --
std::string address_prefix(int address);  // "07", "" for kGlobal
std::string encode_read(int address, Var v, Radix r = Radix::Dec, int bit = 0);
std::string encode_write(int address, Var v, std::int32_t value, int bit = 0);

}  // namespace motorbus::dmac

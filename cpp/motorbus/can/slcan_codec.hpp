// SLCAN (Lawicel ASCII) codec: pure functions and byte-stream decoders, no I/O.
//
// Two directions share one line grammar:
//   adapter -> host : frames `tiiiL<dd..>[ssss]`, replies CR / BEL / `z` / `Z` /
//                     `Fxx` / `V..` / `N..`, kernel extensions `e..` / `s..`
//   host -> adapter : commands O L C Sn s<btr> t T r R V N F Zn M m
// StreamDecoder parses the first (host role), CommandDecoder the second
// (adapter role), and AdapterSession is the adapter's state machine
// (open/closed, bitrate, timestamps) that answers commands like a CANUSB.
//
// Every decoder keeps at most kMtu bytes of a line; anything longer puts it in
// an error state until the next CR or BEL (the kernel's slcan_unesc rule).
//
// LF and NUL are separators, never line content: hosts end commands with CR LF
// (terminal programs, scripts), some firmwares pad with NUL,
// and both would otherwise prefix the next line and turn it into garbage.
//   * LF or NUL between lines is skipped;
//   * LF after line bytes ends the line like CR (LF-only peers work too);
//   * NUL after line bytes breaks that line: it is dropped as malformed at
//     its terminator (a NUL inside a frame is corruption, never a pad).
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/frame.hpp"

namespace motorbus::can::slcan {

// Longest valid line is "T1111222281122334455667788EA5F" (30 chars) + CR.
// A line body longer than this is an overflow (L1).
constexpr std::size_t kMtu = 32;
constexpr std::uint16_t kMaxTimestamp = 0xEA5F;  // 59999 ms: the adapter clock wraps at 60 s
constexpr char kOk = '\r';
constexpr char kBel = '\a';

// ---------------------------------------------------------------- encoding --

// Writes the line for `frame` (t/T/r/R, uppercase hex, CR included) into
// `out`, which must hold kMtu bytes.  Returns the line length.  Throws
// InvalidArgument for frames SLCAN cannot carry (FD, len > 8, bad id).
std::size_t encode_frame_into(const Frame& frame, char* out,
                         std::optional<std::uint16_t> timestamp_ms = std::nullopt);
std::string encode_frame(const Frame& frame,
                         std::optional<std::uint16_t> timestamp_ms = std::nullopt);

// "S6" for 500000 etc.; nullopt for a rate with no Lawicel code.  Both 750k
// (CANable) and 800k (Lawicel CAN232) map to S7.
std::optional<char> bitrate_code(unsigned bitrate);
// 10000 for '0' ... 1000000 for '8'; 0 for anything else.
unsigned bitrate_from_code(char code);

// ------------------------------------------------------------ status flags --
// `F` reply bit layout per the Lawicel CAN232/CANUSB manual (SJA1000 based).
enum StatusFlags : std::uint8_t {
    kStatusRxFifoFull = 1 << 0,
    kStatusTxFifoFull = 1 << 1,
    kStatusErrorWarning = 1 << 2,  // EI
    kStatusDataOverrun = 1 << 3,   // DOI
    // bit 4 unused
    kStatusErrorPassive = 1 << 5,  // EPI
    kStatusArbitrationLost = 1 << 6,  // ALI
    kStatusBusError = 1 << 7,         // BEI
};
// Error passive wins over error warning; the Lawicel flags cannot say bus-off.
BusState status_to_state(std::uint8_t flags);
std::uint8_t state_to_status(BusState state);

// Kernel `e` extension error bits (slcan_bump_err).
enum ErrorReportBits : std::uint16_t {
    kErrAck = 1 << 0,       // 'a'
    kErrBit0 = 1 << 1,      // 'b'
    kErrBit1 = 1 << 2,      // 'B'
    kErrCrc = 1 << 3,       // 'c'
    kErrForm = 1 << 4,      // 'f'
    kErrRxOverrun = 1 << 5, // 'o'
    kErrTxOverrun = 1 << 6, // 'O'
    kErrStuff = 1 << 7,     // 's'
};

// ------------------------------------------------- adapter -> host decoding --

enum class EventKind : std::uint8_t {
    Frame,        // a received frame (`frame`, optional `timestamp_ms`)
    Ok,           // lone CR: the oldest outstanding command succeeded
    Nack,         // BEL: the oldest outstanding command failed (L10)
    TxAck,        // `z` / `Z`: a transmit command was accepted (`extended`)
    Status,       // `Fxx` (`status`)
    Version,      // `V....` (`text` = whole line)
    Serial,       // `N....` (`text`)
    ErrorReport,  // kernel `e<n><codes>` (`error_bits`)
    StateReport,  // kernel `s<a|w|p|b><rxerr:3><txerr:3>` (`state`, `rx_errors`, `tx_errors`)
    Unknown,      // well-formed-looking line with an unsupported leading char (L11)
    Malformed,    // a line that breaks the grammar (L3, L5, L7, L8): dropped
    Overflow,     // a line longer than kMtu: dropped up to the next CR/BEL (L1)
};
const char* to_string(EventKind k);

struct Event {
    EventKind kind = EventKind::Unknown;
    Frame frame{};
    std::optional<std::uint16_t> timestamp_ms;
    std::uint8_t status = 0;
    bool extended = false;
    std::uint16_t error_bits = 0;
    BusState state = BusState::Active;
    std::uint16_t rx_errors = 0, tx_errors = 0;
    // The line's bytes (without terminator), valid only during the callback.
    std::string_view text;
};

// Parses one complete line body (no terminator).  Never reads past `line`.
Event parse_line(std::string_view line);

struct DecoderCounters {
    std::uint64_t frames = 0;
    std::uint64_t rx_errors = 0;       // malformed lines (kernel rx_errors)
    std::uint64_t rx_over_errors = 0;  // lines longer than kMtu (kernel rx_over_errors)
    std::uint64_t ignored = 0;         // unknown or unsupported non-frame lines
    std::uint64_t dropped_partial = 0; // partial lines dropped by discard_partial()
};

// Incremental decoder: feed any chunking of the byte stream, get one Event per
// line.  Holds at most kMtu bytes between calls.
class StreamDecoder {
public:
    template <class OnEvent>
    void feed(std::span<const std::uint8_t> bytes, OnEvent&& on_event) {
        for (std::uint8_t b : bytes) {
            if (b == '\n' || b == '\0') {
                if (!in_line()) continue;  // separator between lines (CR LF, pads)
                if (b == '\n') {
                    finish_line(false, on_event);  // LF-only peer
                } else {
                    broken_ = true;  // NUL inside a line: drop it at its end
                }
            } else if (b == '\r' || b == '\a') {
                finish_line(b == '\a', on_event);
            } else if (overflow_) {
                // discarding until the terminator (L1)
            } else if (len_ < kMtu) {
                buf_[len_++] = static_cast<char>(b);
            } else {
                overflow_ = true;
                len_ = 0;
                ++counters_.rx_over_errors;
                Event e;
                e.kind = EventKind::Overflow;
                on_event(static_cast<const Event&>(e));
            }
        }
    }
    // Drops a partial line (stream ended or went quiet, L2).  Returns whether
    // anything was held.
    bool discard_partial();
    std::size_t pending() const { return overflow_ ? 0 : len_; }
    bool in_overflow() const { return overflow_; }
    const DecoderCounters& counters() const { return counters_; }

private:
    bool in_line() const { return len_ > 0 || overflow_ || broken_; }
    template <class OnEvent>
    void finish_line(bool bel, OnEvent& on_event) {
        if (overflow_) {
            overflow_ = false;
            broken_ = false;
            len_ = 0;
            if (bel) emit_bel(on_event);
            return;
        }
        if (broken_) {
            broken_ = false;
            len_ = 0;
            Event e;
            e.kind = EventKind::Malformed;
            count(e);
            on_event(static_cast<const Event&>(e));
            if (bel) emit_bel(on_event);
            return;
        }
        if (len_ == 0) {
            if (bel) {
                emit_bel(on_event);
            } else {
                Event e;
                e.kind = EventKind::Ok;
                on_event(static_cast<const Event&>(e));
            }
            return;
        }
        Event e = parse_line(std::string_view(buf_, len_));
        len_ = 0;
        if (bel && e.kind != EventKind::Malformed) {
            // A BEL is never a line terminator for data: whatever preceded it
            // is an incomplete line (noise), then the BEL itself is a NACK.
            e = Event{};
            e.kind = EventKind::Malformed;
        }
        count(e);
        on_event(static_cast<const Event&>(e));
        if (bel) emit_bel(on_event);
    }
    template <class OnEvent>
    void emit_bel(OnEvent& on_event) {
        Event e;
        e.kind = EventKind::Nack;
        on_event(static_cast<const Event&>(e));
    }
    void count(const Event& e);

    char buf_[kMtu];
    std::size_t len_ = 0;
    bool overflow_ = false;
    bool broken_ = false;  // a NUL arrived inside the current line
    DecoderCounters counters_;
};

// ------------------------------------------------- host -> adapter decoding --

enum class CommandKind : std::uint8_t {
    Open,          // O
    ListenOnly,    // L
    Close,         // C
    SetBitrate,    // S0..S8 (`arg` = code 0..8)
    SetBtr,        // sxxyy (`arg` = BTR0 << 8 | BTR1)
    Transmit,      // t T r R (`frame`)
    Version,       // V
    Serial,        // N
    Status,        // F
    Timestamps,    // Z0 / Z1 (`arg`)
    AcceptCode,    // Mxxxxxxxx (`arg`)
    AcceptMask,    // mxxxxxxxx (`arg`)
    Empty,         // a bare CR
    Invalid,       // anything else, incl. bad frames and over-long lines: answer BEL
};

struct Command {
    CommandKind kind = CommandKind::Invalid;
    std::uint32_t arg = 0;
    Frame frame{};
};

// Parses one command line body.  Frames must be exact (no trailing chars).
Command parse_command(std::string_view line);

class CommandDecoder {
public:
    // Calls on_command(const Command&) per CR- (or LF-) terminated line.  BEL
    // bytes from a host are noise: they end the partial line, which is
    // dropped.  LF and NUL between commands are skipped (CR LF hosts, pads),
    // so they never cost a command; a NUL inside a line makes it Invalid.
    template <class OnCommand>
    void feed(std::span<const std::uint8_t> bytes, OnCommand&& on_command) {
        for (std::uint8_t b : bytes) {
            if (b == '\n' || b == '\0') {
                if (len_ == 0 && !overflow_ && !broken_) continue;  // separator
                if (b == '\0') {
                    broken_ = true;
                    continue;
                }
                // LF after command bytes: an LF-only host's terminator.
            }
            if (b == '\r' || b == '\a' || b == '\n') {
                const bool was_over = overflow_;
                const bool was_broken = broken_;
                overflow_ = false;
                broken_ = false;
                std::string_view line(buf_, len_);
                len_ = 0;
                if (b == '\a') continue;
                Command c;
                if (was_over) {
                    ++over_errors_;
                    c.kind = CommandKind::Invalid;
                } else if (was_broken) {
                    c.kind = CommandKind::Invalid;
                } else {
                    c = parse_command(line);
                }
                on_command(static_cast<const Command&>(c));
            } else if (overflow_) {
            } else if (len_ < kMtu) {
                buf_[len_++] = static_cast<char>(b);
            } else {
                overflow_ = true;
                len_ = 0;
            }
        }
    }
    std::uint64_t over_errors() const { return over_errors_; }

private:
    char buf_[kMtu];
    std::size_t len_ = 0;
    bool overflow_ = false;
    bool broken_ = false;  // a NUL arrived inside the current line
    std::uint64_t over_errors_ = 0;
};

// The adapter's side of the protocol, as a pure state machine.  handle()
// returns the reply bytes and, for an accepted transmit, the frame to put on
// the bus (the caller turns a failed bus send into a BEL via `transmit_failed`).
struct AdapterReply {
    std::string bytes;               // what the adapter writes back
    std::optional<Frame> transmit;   // frame to send on the bus
};

struct AdapterIdentity {
    std::string version = "V1013";  // hw 1.0, sw 1.3, as a CANUSB reports it
    std::string serial = "NMB01";
};

class AdapterSession {
public:
    explicit AdapterSession(AdapterIdentity id = {}) : id_(std::move(id)) {}
    AdapterReply handle(const Command& cmd, std::uint8_t status_flags = 0);
    // The reply to use when the bus refused `transmit`.
    static std::string transmit_failed() { return std::string(1, kBel); }

    bool is_open() const { return open_; }
    bool listen_only() const { return listen_only_; }
    bool timestamps() const { return timestamps_; }
    unsigned bitrate() const { return bitrate_; }  // 0 when set by BTR / never set
    std::optional<std::uint16_t> btr() const { return btr_; }

private:
    AdapterIdentity id_;
    bool open_ = false;
    bool listen_only_ = false;
    bool timestamps_ = false;
    unsigned bitrate_ = 0;
    std::optional<std::uint16_t> btr_;
};

}  // namespace motorbus::can::slcan

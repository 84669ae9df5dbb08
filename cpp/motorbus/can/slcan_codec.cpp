#include "motorbus/can/slcan_codec.hpp"

#include <cstdio>

#include "motorbus/errors.hpp"

namespace motorbus::can::slcan {

namespace {

constexpr char kHex[] = "0123456789ABCDEF";

// -1 for anything that is not [0-9A-Fa-f] (strict: no spaces, signs, 0x).
inline int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

// Parses exactly `n` hex digits (n <= 8) at `p`; false on any non-hex char.
inline bool parse_hex(const char* p, std::size_t n, std::uint32_t& out) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < n; ++i) {
        int d = hex_value(p[i]);
        if (d < 0) return false;
        v = (v << 4) | static_cast<std::uint32_t>(d);
    }
    out = v;
    return true;
}

inline bool parse_dec3(const char* p, std::uint16_t& out) {
    std::uint16_t v = 0;
    for (int i = 0; i < 3; ++i) {
        if (p[i] < '0' || p[i] > '9') return false;
        v = static_cast<std::uint16_t>(v * 10 + (p[i] - '0'));
    }
    out = v;
    return true;
}

enum class FrameParse { Ok, Bad };

// Parses a t/T/r/R line.  `allow_timestamp`: 0 or 4 trailing hex chars (the
// adapter -> host direction); commands must be exact.
FrameParse parse_frame_line(std::string_view line, bool allow_timestamp, Frame& f,
                            std::optional<std::uint16_t>& ts) {
    const char kind = line[0];
    const bool extended = (kind == 'T' || kind == 'R');
    const bool rtr = (kind == 'r' || kind == 'R');
    const std::size_t id_len = extended ? 8 : 3;
    if (line.size() < 1 + id_len + 1) return FrameParse::Bad;
    std::uint32_t id = 0;
    if (!parse_hex(line.data() + 1, id_len, id)) return FrameParse::Bad;            // L3
    if (id > (extended ? kMaxExtendedId : kMaxStandardId)) return FrameParse::Bad;  // L8
    const char dlc_char = line[1 + id_len];
    if (dlc_char < '0' || dlc_char > '8') return FrameParse::Bad;  // L5
    const std::size_t dlc = static_cast<std::size_t>(dlc_char - '0');
    std::size_t pos = 1 + id_len + 1;
    const std::size_t data_chars = rtr ? 0 : 2 * dlc;
    if (line.size() < pos + data_chars) return FrameParse::Bad;
    f = Frame{};
    f.id = id;
    f.extended = extended;
    f.rtr = rtr;
    f.len = static_cast<std::uint8_t>(dlc);
    for (std::size_t i = 0; i < data_chars / 2; ++i) {
        const int hi = hex_value(line[pos + 2 * i]);
        const int lo = hex_value(line[pos + 2 * i + 1]);
        if (hi < 0 || lo < 0) return FrameParse::Bad;  // L3
        f.data[i] = static_cast<std::uint8_t>((hi << 4) | lo);
    }
    pos += data_chars;
    const std::size_t trailing = line.size() - pos;
    ts.reset();
    if (trailing == 0) return FrameParse::Ok;
    if (!allow_timestamp || trailing != 4) return FrameParse::Bad;  // L7
    std::uint32_t t = 0;
    if (!parse_hex(line.data() + pos, 4, t) || t > kMaxTimestamp) return FrameParse::Bad;  // L7
    ts = static_cast<std::uint16_t>(t);
    return FrameParse::Ok;
}

}  // namespace

// ---------------------------------------------------------------- encoding --

std::size_t encode_frame_into(const Frame& frame, char* out, std::optional<std::uint16_t> timestamp_ms) {
    if (frame.is_fd()) throw InvalidArgument("slcan: CAN FD frames are not supported");
    if (auto p = frame.problem()) throw InvalidArgument(*p);
    if (timestamp_ms && *timestamp_ms > kMaxTimestamp)
        throw InvalidArgument("slcan timestamp: must be 0-59999 ms");
    std::size_t n = 0;
    out[n++] = frame.extended ? (frame.rtr ? 'R' : 'T') : (frame.rtr ? 'r' : 't');
    const int id_len = frame.extended ? 8 : 3;
    for (int i = id_len - 1; i >= 0; --i) out[n++] = kHex[(frame.id >> (4 * i)) & 0xF];
    out[n++] = static_cast<char>('0' + frame.len);
    if (!frame.rtr) {
        for (unsigned i = 0; i < frame.len; ++i) {
            out[n++] = kHex[frame.data[i] >> 4];
            out[n++] = kHex[frame.data[i] & 0xF];
        }
    }
    if (timestamp_ms) {
        for (int i = 3; i >= 0; --i) out[n++] = kHex[(*timestamp_ms >> (4 * i)) & 0xF];
    }
    out[n++] = '\r';
    return n;
}

std::string encode_frame(const Frame& frame, std::optional<std::uint16_t> timestamp_ms) {
    char buf[kMtu];
    return std::string(buf, encode_frame_into(frame, buf, timestamp_ms));
}

namespace {
constexpr unsigned kBitrates[9] = {10000,  20000,  50000,  100000, 125000,
                                   250000, 500000, 800000, 1000000};
}

std::optional<char> bitrate_code(unsigned bitrate) {
    if (bitrate == 750000) return '7';  // CANable's S7
    for (int i = 0; i < 9; ++i)
        if (kBitrates[i] == bitrate) return static_cast<char>('0' + i);
    return std::nullopt;
}

unsigned bitrate_from_code(char code) {
    if (code < '0' || code > '8') return 0;
    return kBitrates[code - '0'];
}

BusState status_to_state(std::uint8_t flags) {
    if (flags & kStatusErrorPassive) return BusState::ErrorPassive;
    if (flags & kStatusErrorWarning) return BusState::ErrorWarning;
    return BusState::Active;
}

std::uint8_t state_to_status(BusState state) {
    switch (state) {
        case BusState::ErrorWarning: return kStatusErrorWarning;
        case BusState::ErrorPassive: return kStatusErrorPassive | kStatusErrorWarning;
        case BusState::BusOff: return kStatusErrorPassive | kStatusErrorWarning | kStatusBusError;
        default: return 0;
    }
}

const char* to_string(EventKind k) {
    switch (k) {
        case EventKind::Frame: return "frame";
        case EventKind::Ok: return "ok";
        case EventKind::Nack: return "nack";
        case EventKind::TxAck: return "tx_ack";
        case EventKind::Status: return "status";
        case EventKind::Version: return "version";
        case EventKind::Serial: return "serial";
        case EventKind::ErrorReport: return "error_report";
        case EventKind::StateReport: return "state_report";
        case EventKind::Unknown: return "unknown";
        case EventKind::Malformed: return "malformed";
        case EventKind::Overflow: return "overflow";
    }
    return "?";
}

// ------------------------------------------------- adapter -> host decoding --

Event parse_line(std::string_view line) {
    Event e;
    e.text = line;
    if (line.empty()) {
        e.kind = EventKind::Ok;
        return e;
    }
    switch (line[0]) {
        case 't':
        case 'T':
        case 'r':
        case 'R':
            e.kind = parse_frame_line(line, true, e.frame, e.timestamp_ms) == FrameParse::Ok
                         ? EventKind::Frame
                         : EventKind::Malformed;
            return e;
        case 'z':
        case 'Z':
            e.kind = line.size() == 1 ? EventKind::TxAck : EventKind::Malformed;
            e.extended = line[0] == 'Z';
            return e;
        case 'F': {
            std::uint32_t v = 0;
            if (line.size() == 3 && parse_hex(line.data() + 1, 2, v)) {
                e.kind = EventKind::Status;
                e.status = static_cast<std::uint8_t>(v);
                e.state = status_to_state(e.status);
            } else {
                e.kind = EventKind::Malformed;
            }
            return e;
        }
        case 'V':
            e.kind = EventKind::Version;
            return e;
        case 'N':
            e.kind = EventKind::Serial;
            return e;
        case 'e': {
            // e<n><n codes>, n = '0'..'8' (kernel slcan_bump_err)
            e.kind = EventKind::Malformed;
            if (line.size() < 2 || line[1] < '0' || line[1] > '8') return e;
            const std::size_t n = static_cast<std::size_t>(line[1] - '0');
            if (line.size() != 2 + n) return e;
            std::uint16_t bits = 0;
            for (std::size_t i = 0; i < n; ++i) {
                switch (line[2 + i]) {
                    case 'a': bits |= kErrAck; break;
                    case 'b': bits |= kErrBit0; break;
                    case 'B': bits |= kErrBit1; break;
                    case 'c': bits |= kErrCrc; break;
                    case 'f': bits |= kErrForm; break;
                    case 'o': bits |= kErrRxOverrun; break;
                    case 'O': bits |= kErrTxOverrun; break;
                    case 's': bits |= kErrStuff; break;
                    default: return e;
                }
            }
            e.kind = EventKind::ErrorReport;
            e.error_bits = bits;
            return e;
        }
        case 's': {
            // s<state><rx:3 dec><tx:3 dec> (kernel slcan_bump_state)
            e.kind = EventKind::Malformed;
            if (line.size() != 8) return e;
            BusState st;
            switch (line[1]) {
                case 'a': st = BusState::Active; break;
                case 'w': st = BusState::ErrorWarning; break;
                case 'p': st = BusState::ErrorPassive; break;
                case 'b': st = BusState::BusOff; break;
                default: return e;
            }
            if (!parse_dec3(line.data() + 2, e.rx_errors) || !parse_dec3(line.data() + 5, e.tx_errors))
                return e;
            e.kind = EventKind::StateReport;
            e.state = st;
            return e;
        }
        default:
            e.kind = EventKind::Unknown;
            return e;
    }
}

void StreamDecoder::count(const Event& e) {
    switch (e.kind) {
        case EventKind::Frame: ++counters_.frames; break;
        case EventKind::Malformed: ++counters_.rx_errors; break;
        case EventKind::Unknown: ++counters_.ignored; break;
        default: break;
    }
}

bool StreamDecoder::discard_partial() {
    const bool had = in_line();
    if ((len_ > 0 || broken_) && !overflow_) ++counters_.dropped_partial;
    len_ = 0;
    overflow_ = false;
    broken_ = false;
    return had;
}

// ------------------------------------------------- host -> adapter decoding --

Command parse_command(std::string_view line) {
    Command c;
    c.kind = CommandKind::Invalid;
    if (line.empty()) {
        c.kind = CommandKind::Empty;
        return c;
    }
    const std::size_t n = line.size();
    std::uint32_t v = 0;
    switch (line[0]) {
        case 'O': if (n == 1) c.kind = CommandKind::Open; break;
        case 'L': if (n == 1) c.kind = CommandKind::ListenOnly; break;
        case 'C': if (n == 1) c.kind = CommandKind::Close; break;
        case 'V': if (n == 1) c.kind = CommandKind::Version; break;
        case 'N': if (n == 1) c.kind = CommandKind::Serial; break;
        case 'F': if (n == 1) c.kind = CommandKind::Status; break;
        case 'S':
            if (n == 2 && line[1] >= '0' && line[1] <= '8') {
                c.kind = CommandKind::SetBitrate;
                c.arg = static_cast<std::uint32_t>(line[1] - '0');
            }
            break;
        case 's':
            if (n == 5 && parse_hex(line.data() + 1, 4, v)) {
                c.kind = CommandKind::SetBtr;
                c.arg = v;
            }
            break;
        case 'Z':
            if (n == 2 && (line[1] == '0' || line[1] == '1')) {
                c.kind = CommandKind::Timestamps;
                c.arg = static_cast<std::uint32_t>(line[1] - '0');
            }
            break;
        case 'M':
        case 'm':
            if (n == 9 && parse_hex(line.data() + 1, 8, v)) {
                c.kind = line[0] == 'M' ? CommandKind::AcceptCode : CommandKind::AcceptMask;
                c.arg = v;
            }
            break;
        case 't':
        case 'T':
        case 'r':
        case 'R': {
            std::optional<std::uint16_t> ts;
            if (parse_frame_line(line, false, c.frame, ts) == FrameParse::Ok)
                c.kind = CommandKind::Transmit;
            break;
        }
        default: break;
    }
    return c;
}

AdapterReply AdapterSession::handle(const Command& cmd, std::uint8_t status_flags) {
    AdapterReply r;
    const std::string ok(1, kOk), bel(1, kBel);
    switch (cmd.kind) {
        case CommandKind::Open:
        case CommandKind::ListenOnly:
            if (open_) {
                r.bytes = bel;
            } else {
                open_ = true;
                listen_only_ = cmd.kind == CommandKind::ListenOnly;
                r.bytes = ok;
            }
            break;
        case CommandKind::Close:
            if (!open_) {
                r.bytes = bel;
            } else {
                open_ = false;
                listen_only_ = false;
                r.bytes = ok;
            }
            break;
        case CommandKind::SetBitrate:
        case CommandKind::SetBtr:
        case CommandKind::Timestamps:
        case CommandKind::AcceptCode:
        case CommandKind::AcceptMask:
            // Lawicel: configuration only while the channel is closed.
            if (open_) {
                r.bytes = bel;
                break;
            }
            if (cmd.kind == CommandKind::SetBitrate) {
                bitrate_ = bitrate_from_code(static_cast<char>('0' + cmd.arg));
                btr_.reset();
            } else if (cmd.kind == CommandKind::SetBtr) {
                bitrate_ = 0;
                btr_ = static_cast<std::uint16_t>(cmd.arg);
            } else if (cmd.kind == CommandKind::Timestamps) {
                timestamps_ = cmd.arg != 0;
            }
            r.bytes = ok;
            break;
        case CommandKind::Transmit:
            if (!open_ || listen_only_) {
                r.bytes = bel;
            } else {
                r.transmit = cmd.frame;
                r.bytes = cmd.frame.extended ? "Z\r" : "z\r";
            }
            break;
        case CommandKind::Version: r.bytes = id_.version + ok; break;
        case CommandKind::Serial: r.bytes = id_.serial + ok; break;
        case CommandKind::Status:
            if (!open_) {
                r.bytes = bel;
            } else {
                char buf[8];
                std::snprintf(buf, sizeof buf, "F%02X\r", status_flags);
                r.bytes = buf;
            }
            break;
        case CommandKind::Empty:
        case CommandKind::Invalid:
            r.bytes = bel;
            break;
    }
    return r;
}

}  // namespace motorbus::can::slcan

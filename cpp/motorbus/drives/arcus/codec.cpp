#include "motorbus/drives/arcus/codec.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>

namespace motorbus::arcus {

namespace {

constexpr unsigned Q = kQuery, S = kSet, A = kAction, R = kArgument, I = kIndexed;

// Sorted by name (find_command binary-searches).
constexpr CommandInfo kTable[] = {
    {"ABORT", A, false, false, 0, "stop immediately; clears StepNLoop error status"},
    {"ABS", A, false, false, 0, "absolute move mode"},
    {"ACC", Q | S, false, false, 0, "acceleration time [ms]"},
    {"BR", Q | S, false, true, 0, "CANopen bit rate code 1-9"},
    {"CLR", A, false, false, 0, "clear limit and StepNLoop errors"},
    {"CLRS", A, false, false, 0, "clear StepNLoop error (Table 7.6)"},
    {"CM", Q | S, false, true, 0, "communication mode 0 RS-232, 1 RS-485, 2 CANopen"},
    {"CUR", Q, false, true, 0, "actual current [mA]"},
    {"CURI", Q | S, false, true, 0, "idle current [mA], 0 or 100-2500"},
    {"CURR", Q | S, false, true, 0, "run current [mA], 100-2500"},
    {"CURT", Q | S, false, true, 0, "idle time before idle current [ms]"},
    {"DB", Q | S, false, true, 0, "serial baud code 1-5"},
    {"DEC", Q | S, false, false, 0, "deceleration time [ms], used if EDEC=1"},
    {"DI", Q | I, false, false, 6, "digital inputs (DI1-DI6 one bit)"},
    {"DN", Q | S, false, true, 0, "device name DMC01-DMC99"},
    {"DO", Q | S | I, false, false, 3, "digital outputs (DO1-DO3 one bit)"},
    {"DOBOOT", Q | S, false, true, 0, "digital outputs at boot"},
    {"DX", Q, false, false, 0, "StepNLoop delta [counts]"},
    {"EDEC", Q | S, false, false, 0, "unique deceleration enable"},
    {"EDO", Q | S, false, true, 0, "in-position/alarm outputs enable"},
    {"EO", Q | S, false, false, 0, "motor power enable"},
    {"EOBOOT", Q | S, false, true, 0, "motor power at boot"},
    {"EX", Q | S, true, false, 0, "encoder position"},
    {"H+", A, true, false, 0, "home on the home input, positive"},
    {"H-", A, true, false, 0, "home on the home input, negative"},
    {"HCA", Q | S, false, false, 0, "home correction amount (HL homing)"},
    {"HL+", A, true, false, 0, "home at high and low speed, positive"},
    {"HL-", A, true, false, 0, "home at high and low speed, negative"},
    {"HSPD", Q | S, false, false, 0, "high speed [pps]"},
    {"ID", Q, false, false, 0, "product id"},
    {"INC", A, false, false, 0, "incremental move mode"},
    {"J+", A, true, false, 0, "jog positive"},
    {"J-", A, true, false, 0, "jog negative"},
    {"L+", A, true, false, 0, "home on the plus limit"},
    {"L-", A, true, false, 0, "home on the minus limit"},
    {"LCA", Q | S, false, true, 0, "limit correction amount"},
    {"LSPD", Q | S, false, false, 0, "low speed [pps]"},
    {"LT", Q | S, false, false, 0, "latch enable"},
    {"LTE", Q, false, false, 0, "latched encoder position"},
    {"LTP", Q, false, false, 0, "latched pulse position"},
    {"LTS", Q, false, false, 0, "latch status"},
    {"MM", Q, false, false, 0, "move mode 0 ABS, 1 INC"},
    {"MST", Q, false, false, 0, "motor status bits"},
    {"NID", Q | S, false, true, 0, "CANopen node id 1-127"},
    {"POL", Q | S, false, true, 0, "polarity bits"},
    {"PS", Q, false, false, 0, "pulse speed"},
    {"PX", Q | S, true, false, 0, "pulse position"},
    {"RT", Q | S, false, true, 0, "response type 0/1"},
    {"RZ", Q | S, false, false, 0, "return to zero after H/HL homing"},
    {"SCV", Q | S, false, false, 0, "s-curve enable"},
    {"SL", Q | S, false, true, 0, "StepNLoop enable"},
    {"SLA", Q | S, false, true, 0, "StepNLoop max attempts"},
    {"SLE", Q | S, false, true, 0, "StepNLoop error range"},
    {"SLM", Q | S, false, true, 0, "StepNLoop idle tolerance"},
    {"SLR", Q | S, false, true, 0, "StepNLoop ratio, pulses per count (x.xxx)"},
    {"SLS", Q, false, false, 0, "StepNLoop status"},
    {"SLT", Q | S, false, true, 0, "StepNLoop tolerance"},
    {"SSPD", R, false, false, 0, "on-the-fly speed change"},
    {"SSPDM", Q | S, false, false, 0, "on-the-fly speed window"},
    {"STOP", A, false, false, 0, "decelerate to stop"},
    {"STORE", A, false, false, 0, "store to flash"},
    {"SYNC", Q | S, false, false, 0, "sync condition 1 =, 2 <, 3 >"},
    {"SYNF", A, false, false, 0, "sync output off"},
    {"SYNO", A, false, false, 0, "sync output on"},
    {"SYNP", Q | S, false, false, 0, "sync position"},
    {"SYNS", Q, false, false, 0, "sync status"},
    {"T", R, false, false, 0, "on-the-fly target change"},
    {"VER", Q, false, false, 0, "firmware version"},
    {"X", R, true, false, 0, "move (absolute in ABS, relative in INC)"},
    {"Z+", A, true, false, 0, "home on the Z index only, positive"},
    {"Z-", A, true, false, 0, "home on the Z index only, negative"},
    {"ZH+", A, true, false, 0, "home on home input then Z index, positive"},
    {"ZH-", A, true, false, 0, "home on home input then Z index, negative"},
};

constexpr bool table_sorted() {
    for (std::size_t i = 1; i < std::size(kTable); ++i)
        if (!(kTable[i - 1].name < kTable[i].name)) return false;
    return true;
}
static_assert(table_sorted(), "kTable must stay sorted for find_command");

bool printable(char c) { return c >= 0x20 && c < 0x7f; }

}  // namespace

std::span<const CommandInfo> command_table() { return kTable; }

std::optional<std::int64_t> parse_milli(std::string_view text) {
    // Digits, optionally '.' and 1..3 more digits: "0.8", "1", "0.250".
    auto dot = text.find('.');
    std::string_view whole = text.substr(0, dot);
    std::string_view frac = dot == std::string_view::npos ? std::string_view{} : text.substr(dot + 1);
    if (whole.empty() || whole.size() > 6) return std::nullopt;
    if (dot != std::string_view::npos && (frac.empty() || frac.size() > 3)) return std::nullopt;
    std::int64_t v = 0;
    for (char c : whole) {
        if (c < '0' || c > '9') return std::nullopt;
        v = v * 10 + (c - '0');
    }
    std::int64_t f = 0;
    for (std::size_t i = 0; i < 3; ++i) {
        char c = i < frac.size() ? frac[i] : '0';
        if (c < '0' || c > '9') return std::nullopt;
        f = f * 10 + (c - '0');
    }
    return v * 1000 + f;
}

std::string format_milli(std::int64_t milli) {
    const bool neg = milli < 0;
    const unsigned long long m = neg ? 0ULL - static_cast<unsigned long long>(milli) : static_cast<unsigned long long>(milli);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%llu.%03llu", neg ? "-" : "", m / 1000, m % 1000);
    return buf;
}

const CommandInfo* find_command(std::string_view name) {
    auto it = std::lower_bound(std::begin(kTable), std::end(kTable), name,
                               [](const CommandInfo& c, std::string_view n) { return c.name < n; });
    if (it == std::end(kTable) || it->name != name) return nullptr;
    return &*it;
}

std::string_view error_text(ErrorCode code) {
    switch (code) {
        case ErrorCode::UnknownCommand: return "?";
        case ErrorCode::BadSspd: return "?Bad SSPD Command";
        case ErrorCode::EnableRs485: return "?Enable RS-485 Mode";
        case ErrorCode::IndexOutOfRange: return "?Index out of Range";
        case ErrorCode::MotorNotMoving: return "?Motor is not moving";
        case ErrorCode::Moving: return "?Moving";
        case ErrorCode::ScvOn: return "?SCV ON";
        case ErrorCode::SpeedOutOfRange: return "?Speed out of range";
        case ErrorCode::StateError: return "?State Error";
    }
    return "?";
}

std::string_view error_name(ErrorCode code) {
    switch (code) {
        case ErrorCode::UnknownCommand: return "UnknownCommand";
        case ErrorCode::BadSspd: return "BadSspd";
        case ErrorCode::EnableRs485: return "EnableRs485";
        case ErrorCode::IndexOutOfRange: return "IndexOutOfRange";
        case ErrorCode::MotorNotMoving: return "MotorNotMoving";
        case ErrorCode::Moving: return "Moving";
        case ErrorCode::ScvOn: return "ScvOn";
        case ErrorCode::SpeedOutOfRange: return "SpeedOutOfRange";
        case ErrorCode::StateError: return "StateError";
    }
    return "?";
}

std::optional<ErrorCode> classify_error(std::string_view body) {
    if (body.empty() || body[0] != '?') return std::nullopt;
    for (auto c : {ErrorCode::BadSspd, ErrorCode::EnableRs485, ErrorCode::IndexOutOfRange,
                   ErrorCode::MotorNotMoving, ErrorCode::Moving, ErrorCode::ScvOn,
                   ErrorCode::SpeedOutOfRange, ErrorCode::StateError}) {
        if (body == error_text(c)) return c;
    }
    return ErrorCode::UnknownCommand;
}

// ---- requests ------------------------------------------------------------------

std::string build_request(int address, std::string_view command) {
    std::string out = format_command(address, command);
    out += kRequestTerminator;
    return out;
}

std::string format_command(int address, std::string_view command) {
    if (address < 0 || address > kMaxAddress)
        throw InvalidArgument("arcus address: " + std::to_string(address) + " not in 0..99");
    if (command.empty() || command.size() > kMaxRequest)
        throw InvalidArgument("arcus command: length must be 1.." + std::to_string(kMaxRequest));
    for (char c : command) {
        if (!printable(c) || c == '@')
            throw InvalidArgument("arcus command: only printable ASCII without '@'");
    }
    std::string out;
    out.reserve(command.size() + 4);
    out += '@';
    out += static_cast<char>('0' + address / 10);
    out += static_cast<char>('0' + address % 10);
    out += command;
    return out;
}

std::string build_query(int address, std::string_view name) { return build_request(address, name); }

std::string build_set(int address, std::string_view name, std::int64_t value) {
    return build_request(address, std::string(name) + "=" + std::to_string(value));
}

std::string build_action(int address, std::string_view name) { return build_request(address, name); }

std::string build_argument(int address, std::string_view name, std::int64_t value) {
    return build_request(address, std::string(name) + std::to_string(value));
}

std::optional<Request> parse_request_line(std::string_view line) {
    if (line.size() < 4 || line[0] != '@') return std::nullopt;
    char a = line[1], b = line[2];
    if (a < '0' || a > '9' || b < '0' || b > '9') return std::nullopt;
    Request r;
    r.address = (a - '0') * 10 + (b - '0');
    r.command = std::string(line.substr(3));
    return r;
}

std::optional<std::int64_t> parse_int(std::string_view text) {
    std::size_t i = 0;
    bool neg = false;
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) {
        neg = text[i] == '-';
        ++i;
    }
    std::size_t digits = text.size() - i;
    if (digits == 0 || digits > 10) return std::nullopt;
    std::int64_t v = 0;
    for (; i < text.size(); ++i) {
        char c = text[i];
        if (c < '0' || c > '9') return std::nullopt;
        v = v * 10 + (c - '0');
    }
    if (neg) v = -v;
    if (v < INT32_MIN || v > INT32_MAX) return std::nullopt;
    return v;
}

std::optional<ParsedCommand> parse_command(std::string_view command) {
    if (command.empty() || command.size() > kMaxRequest) return std::nullopt;
    for (char c : command)
        if (!printable(c)) return std::nullopt;
    ParsedCommand pc;
    auto eq = command.find('=');
    std::string_view lhs = command.substr(0, eq);
    std::optional<std::string_view> rhs;
    if (eq != std::string_view::npos) rhs = command.substr(eq + 1);

    auto finish_value = [&](ParsedCommand& p) -> bool {
        if (!rhs) return true;
        p.text_value = std::string(*rhs);
        p.value = parse_int(*rhs);
        return true;
    };

    if (const CommandInfo* info = find_command(lhs)) {
        pc.info = info;
        if (rhs) {
            if (!(info->forms & kSet)) return std::nullopt;
            pc.op = ParsedCommand::Op::Set;
            finish_value(pc);
            return pc;
        }
        if (info->forms & kQuery) pc.op = ParsedCommand::Op::Query;
        else if (info->forms & kAction) pc.op = ParsedCommand::Op::Action;
        else return std::nullopt;  // "X" alone, "SSPD" alone: incomplete
        return pc;
    }
    // Name followed by digits: DI3, DO2(=1), X1000, T-5, SSPD2000.
    std::size_t split = 0;
    while (split < lhs.size() && ((lhs[split] >= 'A' && lhs[split] <= 'Z') || lhs[split] == '+'))
        ++split;
    // Longest name that is a table entry and accepts a glued operand.
    for (std::size_t n = split; n > 0; --n) {
        const CommandInfo* info = find_command(lhs.substr(0, n));
        if (!info) continue;
        std::string_view operand = lhs.substr(n);
        if (info->forms & kIndexed) {
            if (operand.empty()) continue;
            for (char c : operand)
                if (c < '0' || c > '9') return std::nullopt;
            pc.info = info;
            auto idx = parse_int(operand);
            pc.index = idx ? static_cast<int>(*idx) : -1;
            pc.index_valid = idx && *idx >= 1 && *idx <= info->index_max;
            if (rhs) {
                if (info->name == "DI") return std::nullopt;  // inputs are read-only
                pc.op = ParsedCommand::Op::Set;
                finish_value(pc);
            } else {
                pc.op = ParsedCommand::Op::Query;
            }
            return pc;
        }
        if ((info->forms & kArgument) && !rhs) {
            pc.info = info;
            pc.op = ParsedCommand::Op::Argument;
            pc.text_value = std::string(operand);
            pc.value = parse_int(operand);
            return pc;
        }
        return std::nullopt;
    }
    return std::nullopt;
}

// ---- replies -------------------------------------------------------------------

Reply parse_reply(std::string_view raw) {
    auto bytes = [&] { return std::vector<std::uint8_t>(raw.begin(), raw.end()); };
    if (raw.size() > kMaxReply) throw ProtocolError("arcus reply too long", bytes());
    for (char c : raw) {
        if (!printable(c)) throw ProtocolError("arcus reply: byte outside printable ASCII", bytes());
    }
    Reply r;
    if (!raw.empty() && raw[0] == '#') {
        if (raw.size() < 3 || raw[1] < '0' || raw[1] > '9' || raw[2] < '0' || raw[2] > '9')
            throw ProtocolError("arcus reply: '#' not followed by a 2-digit address", bytes());
        r.address = (raw[1] - '0') * 10 + (raw[2] - '0');
        raw.remove_prefix(3);
    }
    if (raw.empty()) throw ProtocolError("arcus reply: empty", bytes());
    r.body = std::string(raw);
    return r;
}

std::string format_reply(int address, std::string_view body, int response_type) {
    std::string out;
    out.reserve(body.size() + 4);
    if (response_type == 1) {
        out += '#';
        out += static_cast<char>('0' + (address / 10) % 10);
        out += static_cast<char>('0' + address % 10);
    }
    out += body;
    out += kReplyTerminator;
    return out;
}

std::int64_t reply_int(std::string_view body) {
    auto v = parse_int(body);
    if (!v || (!body.empty() && body[0] == '+'))
        throw ProtocolError("arcus reply: not an integer: " + std::string(body.substr(0, 32)),
                            std::vector<std::uint8_t>(body.begin(), body.end()));
    return *v;
}

// ---- registers -------------------------------------------------------------------

std::optional<SnlStatus> snl_status_from(std::int64_t v) {
    if (v < 0 || v > 13) return std::nullopt;
    return static_cast<SnlStatus>(v);
}

std::string_view snl_status_name(SnlStatus s) {
    static constexpr std::array<std::string_view, 14> names = {
        "Idle", "Moving", "Correcting", "Stopping", "Aborting", "Jogging", "Homing",
        "ZHoming", "CorrectionRangeError", "CorrectionAttemptError", "StallError",
        "LimitError", "Disabled", "LimitHoming"};
    return names[static_cast<int>(s)];
}

namespace {
// Table A.0.  "16 K" is read as 16 000 pps; a boundary speed belongs to the lower window.
constexpr std::array<SpeedWindow, 9> kWindows = {{
    {1, 1, 16000, 10, 2, 500},
    {2, 16001, 30000, 10, 1, 1000},
    {3, 30001, 80000, 15, 1, 2000},
    {4, 80001, 160000, 25, 1, 4000},
    {5, 160001, 300000, 50, 1, 8000},
    {6, 300001, 800000, 100, 1, 18000},
    {7, 800001, 1600000, 200, 1, 39000},
    {8, 1600001, 3000000, 400, 1, 68000},
    {9, 3000001, 6000000, 500, 1, 135000},
}};
}  // namespace

std::span<const SpeedWindow> speed_windows() { return kWindows; }

std::optional<SpeedWindow> window_for_speed(std::int64_t hspd) {
    for (const auto& w : kWindows)
        if (hspd >= w.hspd_min && hspd <= w.hspd_max) return w;
    if (hspd < 1) return kWindows[0];
    return std::nullopt;
}

std::optional<SpeedWindow> window_for_sspdm(std::int64_t sspdm) {
    if (sspdm == 0) sspdm = 1;
    for (const auto& w : kWindows)
        if (w.sspdm == sspdm) return w;
    return std::nullopt;
}

std::int64_t min_acc_ms(std::int64_t hspd) {
    auto w = window_for_speed(hspd);
    return w ? w->min_acc_ms : 1;
}

std::int64_t max_acc_ms(std::int64_t hspd, std::int64_t lspd) {
    auto w = window_for_speed(hspd);
    std::int64_t delta = w ? w->delta : kWindows.back().delta;
    std::int64_t span = std::max<std::int64_t>(0, hspd - lspd);
    // The manual's example prints 23.05 s for 899000/39000 = 23.051 s: seconds are
    // truncated to two decimals before scaling to ms.
    std::int64_t centis = span * 100 / delta;
    return std::max(centis * 10, min_acc_ms(hspd));
}

std::int64_t clamp_acc_ms(std::int64_t acc, std::int64_t hspd, std::int64_t lspd) {
    return std::clamp(acc, min_acc_ms(hspd), max_acc_ms(hspd, lspd));
}

}  // namespace motorbus::arcus

#include "motorbus/drives/dmac/codec.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace motorbus::dmac {
namespace {

constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();

char upper(char c) { return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_space(char c) { return c == ' ' || c == '\t'; }
bool is_name_char(char c) {
    return is_digit(c) || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_';
}

bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (upper(a[i]) != upper(b[i])) return false;
    return true;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

std::vector<std::string_view> split_ws(std::string_view s) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && is_space(s[i])) ++i;
        std::size_t j = i;
        while (j < s.size() && !is_space(s[j])) ++j;
        if (j > i) out.push_back(s.substr(i, j - i));
        i = j;
    }
    return out;
}

// Decimal digits only (no sign); nullopt on empty, non-digit or overflow past `limit`.
std::optional<std::int64_t> parse_digits(std::string_view s, std::int64_t limit) {
    if (s.empty()) return std::nullopt;
    std::int64_t v = 0;
    for (char c : s) {
        if (!is_digit(c)) return std::nullopt;
        v = v * 10 + (c - '0');
        if (v > limit) return std::nullopt;
    }
    return v;
}

std::optional<std::uint32_t> parse_radix_digits(std::string_view s, int base) {
    std::size_t max_digits = base == 16 ? 8 : 32;
    if (s.empty() || s.size() > max_digits) return std::nullopt;
    std::uint32_t v = 0;
    for (char c : s) {
        int d;
        char u = upper(c);
        if (is_digit(u)) d = u - '0';
        else if (u >= 'A' && u <= 'F') d = u - 'A' + 10;
        else return std::nullopt;
        if (d >= base) return std::nullopt;
        v = v * static_cast<std::uint32_t>(base) + static_cast<std::uint32_t>(d);
    }
    return v;
}

std::int32_t as_i32(std::uint32_t u) {
    // Two's complement reinterpretation without implementation-defined casts.
    return u <= 0x7FFFFFFFu ? static_cast<std::int32_t>(u)
                            : static_cast<std::int32_t>(static_cast<std::int64_t>(u) - 0x100000000LL);
}

std::vector<VarInfo> build_vars() {
    std::vector<VarInfo> t(kVarCount);
    auto set = [&](Var v, const char* name, const char* mn, bool stored, bool ro,
                   std::int32_t factory, std::int64_t lo, std::int64_t hi, bool d34 = false) {
        t[static_cast<std::size_t>(v)] = VarInfo{name, mn, stored, ro, factory, lo, hi, d34};
    };
    const std::int64_t L = kI32Min, H = kI32Max;
    set(Var::AccelTime, "#ACCEL_TIME", "#ATI", true, false, 1000, 0, 12000);
    set(Var::Capture, "#CAPTURE", "#CAP", false, true, 0, L, H);
    set(Var::CpuTemperature, "#CPU_TEMPERATURE", "#CTE", false, true, 0, L, H);
    set(Var::DecelTime, "#DECEL_TIME", "#DTI", true, false, 1000, 0, 12000);
    set(Var::DriverTemperature, "#DRIVER_TEMPERATURE", "#DTE", false, true, 0, L, H, true);
    // Only 0 (acknowledge) may be written to #ERROR.
    set(Var::Error, "#ERROR", "#ERR", false, false, 0, 0, 0);
    set(Var::HighSpeed, "#HIGH_SPEED", "#HSP", true, false, 60000, 0, 400000);
    set(Var::Input, "#INPUT", "#INP", false, true, 0, L, H);
    set(Var::InputAnalog, "#INPUT_ANALOG", "#IAN", false, true, 0, L, H);
    set(Var::InputA1, "#INPUT_A1", "#IA1", false, true, 0, L, H, true);
    set(Var::InputA2, "#INPUT_A2", "#IA2", false, true, 0, L, H, true);
    set(Var::InterpolCount, "#INTERPOL_COUNT", "#ICO", false, true, 0, 0, 64);
    set(Var::InterpolFifosize, "#INTERPOL_FIFOSIZE", "#IFI", false, false, 64, 1, 64);
    set(Var::InterpolMode, "#INTERPOL_MODE", "#IMO", false, false, 0, -1, 0);
    set(Var::InterpolTime, "#INTERPOL_TIME", "#ITI", false, false, 100, 2, 138);
    set(Var::LineDelay, "#LINE_DELAY", "#LDE", true, false, 3000, 100, 3000);
    set(Var::Line, "#LINE", "#LIN", false, false, 0, 0, kSeqLines);
    set(Var::LowSpeed, "#LOW_SPEED", "#LSP", true, false, 6000, 0, 400000);
    set(Var::MotorTemperature, "#MOTOR_TEMPERATURE", "#MTE", false, true, 0, L, H, true);
    set(Var::NegativeEnd, "#NEGATIVE_END", "#NEN", true, false, -10000, L, H);
    set(Var::OnReset, "#ON_RESET", "#ORE", true, false, 0, 0, kSeqLines);
    set(Var::Output, "#OUTPUT", "#OUT", false, false, 0, L, H);
    set(Var::OutputA1, "#OUTPUT_A1", "#OA1", false, false, 0, 0, 10000, true);
    set(Var::OutputA2, "#OUTPUT_A2", "#OA2", false, false, 0, 0, 10000, true);
    set(Var::OutputConfig, "#OUTPUT_CONFIG", "#OCO", true, false, 3, 0, 3);
    set(Var::Position, "#POSITION", "#POS", true, false, 0, L, H);
    set(Var::PositiveEnd, "#POSITIVE_END", "#PEN", true, false, 10000, L, H);
    set(Var::ProfileSpeed, "#PROFILE_SPEED", "#PSP", false, true, 0, L, H);
    set(Var::Speed, "#SPEED", "#SPE", false, true, 0, L, H);
    set(Var::Status, "#STATUS", "#STA", false, true, 0, L, H);
    set(Var::SupplyVoltage, "#SUPPLY_VOLTAGE", "#SVO", false, true, 0, L, H);
    set(Var::TorqueRatio, "#TORQUE_RATIO", "#TRA", true, false, 50, 0, 100);
    static const char* const timer_names[] = {"#TIMER_1", "#TIMER_2", "#TIMER_3"};
    static const char* const timer_mn[] = {"#T1", "#T2", "#T3"};
    for (int i = 0; i < 3; ++i)
        set(timer_var(i + 1), timer_names[i], timer_mn[i], false, false, 0, 0, H);
    // Family names must outlive the table: keep them in static storage.
    static std::vector<std::string> family;
    if (family.empty()) {
        for (int i = 1; i <= 8; ++i) family.push_back(std::string("#M").append(std::to_string(i)));
        for (int i = 1; i <= 32; ++i) family.push_back(std::string("#V").append(std::to_string(i)));
    }
    for (int i = 0; i < 8; ++i)
        set(m_var(i + 1), family[static_cast<std::size_t>(i)].c_str(),
            family[static_cast<std::size_t>(i)].c_str(), true, false, 0, L, H);
    for (int i = 0; i < 32; ++i)
        set(v_var(i + 1), family[static_cast<std::size_t>(8 + i)].c_str(),
            family[static_cast<std::size_t>(8 + i)].c_str(), false, false, 0, L, H);
    return t;
}

const std::vector<VarInfo>& vars() {
    static const std::vector<VarInfo> t = build_vars();
    return t;
}

constexpr CommandInfo kCmds[] = {
    {Cmd::Invalid, "", "", ""},
    {Cmd::Assign, ":=", ":=", ""},
    {Cmd::Brake, "BRAKE", "BRA", ""},
    {Cmd::Call, "CALL", "CAL", ""},
    {Cmd::CloseSeq, "CLOSE_SEQ", "CSE", ""},
    {Cmd::Halt, "HALT", "HAL", ""},
    {Cmd::HardEnds, "HARD_ENDS", "HEN", ""},
    {Cmd::If, "IF", "IF", ""},
    {Cmd::InversePolarity, "INVERSE_POLARITY", "IPO", ""},
    {Cmd::Jump, "JUMP", "JUM", ""},
    {Cmd::JumpRel, "JUMP_REL", "JRE", ""},
    {Cmd::ModuleReset, "MODULE_RESET", "MRE", ""},
    {Cmd::MoveInterpol, "MOVE_INTERPOL", "MIN", ""},
    {Cmd::MoveOn, "MOVE_ON", "MON", ""},
    {Cmd::MoveSpeed, "MOVE_SPEED", "MSP", ""},
    {Cmd::MoveTo, "MOVE_TO", "MTO", ""},
    {Cmd::Nop, "NOP", "NOP", ""},
    {Cmd::OpenSeq, "OPEN_SEQ", "OSE", ""},
    {Cmd::OptimizedCurrent, "OPTIMIZED_CURRENT", "OCU", ""},
    {Cmd::Power, "POWER", "POW", ""},
    {Cmd::Read, "READ", "REA", ""},
    {Cmd::ReadSeq, "READ_SEQ", "RSE", ""},
    {Cmd::Reference, "REFERENCE", "REF", ""},
    {Cmd::Return, "RETURN", "RET", ""},
    {Cmd::RequestVersion, "REQUEST_VERSION", "RV", "RVE"},
    {Cmd::SetAddress, "SET_ADDRESS", "SAD", ""},
    {Cmd::SetBaudrate, "SET_BAUDRATE", "SBA", ""},
    {Cmd::SCurve, "S_CURVE", "SCU", ""},
    {Cmd::SoftEnds, "SOFT_ENDS", "SEN", ""},
    {Cmd::StartSeq, "START_SEQ", "SSE", ""},
    {Cmd::Step, "STEP", "STE", ""},
    {Cmd::Stop, "STOP", "STO", ""},
    {Cmd::Synchro, "SYNCHRO", "SYN", ""},
    {Cmd::Wait, "WAIT", "WAI", ""},
};

constexpr std::string_view kKeywords[] = {"",    "ON",  "OFF", "SC",   "ALL", "POS",     "NEG",
                                          "IN",  "OUT", "MOUV", "SEQ", "TOP", "INTERPOL"};

std::optional<Keyword> find_keyword(std::string_view w) {
    for (std::size_t i = 1; i < std::size(kKeywords); ++i)
        if (iequals(w, kKeywords[i])) return static_cast<Keyword>(i);
    return std::nullopt;
}

// Which keywords each command accepts, and whether the keyword is optional.
struct KeywordSpec {
    Cmd cmd;
    bool optional;
    std::initializer_list<Keyword> allowed;
};
const KeywordSpec* keyword_spec(Cmd c) {
    static const KeywordSpec specs[] = {
        {Cmd::Brake, false, {Keyword::On, Keyword::Off}},
        {Cmd::Halt, true, {Keyword::Mouv, Keyword::Seq}},
        {Cmd::HardEnds, false, {Keyword::All, Keyword::Off, Keyword::Pos, Keyword::Neg}},
        {Cmd::InversePolarity, false, {Keyword::Off, Keyword::All, Keyword::In, Keyword::Out}},
        {Cmd::ModuleReset, true, {Keyword::All}},
        {Cmd::OptimizedCurrent, false, {Keyword::On, Keyword::Off}},
        {Cmd::Power, false, {Keyword::On, Keyword::Off, Keyword::Sc}},
        {Cmd::Reference, false, {Keyword::On, Keyword::Off}},
        {Cmd::SCurve, false, {Keyword::On, Keyword::Off}},
        {Cmd::SoftEnds, false, {Keyword::On, Keyword::Off}},
        {Cmd::Stop, true, {Keyword::Mouv, Keyword::Seq}},
        {Cmd::Synchro, false, {Keyword::On, Keyword::Off, Keyword::Top, Keyword::Interpol}},
    };
    for (const auto& s : specs)
        if (s.cmd == c) return &s;
    return nullptr;
}

enum class ArgKind { None, Required, Optional };
ArgKind arg_kind(Cmd c) {
    switch (c) {
        case Cmd::Call: case Cmd::Jump: case Cmd::JumpRel: case Cmd::MoveInterpol:
        case Cmd::MoveOn: case Cmd::MoveSpeed: case Cmd::MoveTo: case Cmd::ReadSeq:
        case Cmd::SetAddress: case Cmd::SetBaudrate: case Cmd::Wait:
            return ArgKind::Required;
        case Cmd::StartSeq: case Cmd::Step:
            return ArgKind::Optional;
        default:
            return ArgKind::None;
    }
}

std::optional<std::pair<Var, int>> parse_var_ref(std::string_view s) {
    if (s.size() < 2 || s[0] != '#') return std::nullopt;
    std::size_t dot = s.find('.');
    std::string_view name = s.substr(0, dot);
    int bit = 0;
    if (dot != std::string_view::npos) {
        auto b = parse_digits(s.substr(dot + 1), 99);
        if (!b || *b < 1 || *b > 32) return std::nullopt;
        bit = static_cast<int>(*b);
    }
    for (std::size_t i = 1; i < name.size(); ++i)
        if (!is_name_char(name[i])) return std::nullopt;
    auto v = find_variable(name);
    if (!v) return std::nullopt;
    return std::make_pair(*v, bit);
}

std::optional<Operand> parse_operand(std::string_view t) {
    Operand o;
    if (t.empty()) return std::nullopt;
    if (t[0] == '!') {
        o.complement = true;
        t.remove_prefix(1);
    } else if (t[0] == '-' && t.size() > 1 && (t[1] == '#' || upper(t[1]) == 'H' || upper(t[1]) == 'B')) {
        o.negate = true;
        t.remove_prefix(1);
    }
    if (t.empty()) return std::nullopt;
    if (t[0] == '#') {
        auto r = parse_var_ref(t);
        if (!r) return std::nullopt;
        o.is_var = true;
        o.var = r->first;
        o.bit = r->second;
        return o;
    }
    auto n = parse_number(t);
    if (!n) return std::nullopt;
    std::int64_t v = *n;
    if (o.negate) v = -v;
    if (o.complement) v = ~v;
    o.negate = o.complement = false;
    o.value = as_i32(static_cast<std::uint32_t>(static_cast<std::uint64_t>(v) & 0xFFFFFFFFu));
    return o;
}

std::optional<Op> find_op(std::string_view t) {
    static constexpr std::pair<std::string_view, Op> ops[] = {
        {"+", Op::Add}, {"-", Op::Sub}, {"*", Op::Mul}, {"/", Op::Div}, {"&", Op::And},
        {"|", Op::Or},  {">", Op::Gt},  {"<", Op::Lt},  {">=", Op::Ge}, {"<=", Op::Le},
        {"!=", Op::Ne}, {"=", Op::Eq},
    };
    for (const auto& [s, op] : ops)
        if (t == s) return op;
    return std::nullopt;
}

std::optional<Expr> parse_expr_tokens(const std::vector<std::string_view>& tok, std::size_t b,
                                      std::size_t e) {
    Expr x;
    if (e - b == 1) {
        auto o = parse_operand(tok[b]);
        if (!o) return std::nullopt;
        x.lhs = *o;
        return x;
    }
    if (e - b == 3) {
        auto l = parse_operand(tok[b]);
        auto op = find_op(tok[b + 1]);
        auto r = parse_operand(tok[b + 2]);
        if (!l || !op || !r) return std::nullopt;
        x.lhs = *l;
        x.op = *op;
        x.rhs = *r;
        return x;
    }
    return std::nullopt;
}

std::optional<Expr> parse_expr(std::string_view s) {
    auto tok = split_ws(s);
    if (tok.empty()) return std::nullopt;
    return parse_expr_tokens(tok, 0, tok.size());
}

Command invalid(int bit = error::kSyntax) {
    Command c;
    c.cmd = Cmd::Invalid;
    c.error_bit = bit;
    return c;
}

Command parse_command(std::string_view s) {
    s = trim(s);
    if (s.empty()) return invalid();
    Command c;
    if (s[0] == '#') {
        std::size_t as = s.find(":=");
        if (as == std::string_view::npos) return invalid();
        auto ref = parse_var_ref(trim(s.substr(0, as)));
        if (!ref) return invalid();
        auto e = parse_expr(s.substr(as + 2));
        if (!e) return invalid();
        c.cmd = Cmd::Assign;
        c.var = ref->first;
        c.bit = ref->second;
        c.expr = *e;
        return c;
    }
    auto tok = split_ws(s);
    auto cmd = find_command(tok[0]);
    if (!cmd || *cmd == Cmd::Assign || *cmd == Cmd::Invalid) return invalid();
    c.cmd = *cmd;
    const std::size_t n = tok.size();
    if (c.cmd == Cmd::Read) {
        if (n != 2) return invalid();
        std::string_view t = tok[1];
        if (!t.empty() && (t[0] == 'h' || t[0] == 'H')) {
            c.radix = Radix::Hex;
            t.remove_prefix(1);
        } else if (!t.empty() && (t[0] == 'b' || t[0] == 'B')) {
            c.radix = Radix::Bin;
            t.remove_prefix(1);
        }
        auto ref = parse_var_ref(t);
        if (!ref) return invalid();
        c.var = ref->first;
        c.bit = ref->second;
        return c;
    }
    if (c.cmd == Cmd::If) {
        // IF <test> JUMP|JUMP_REL|CALL <target>: the jump word is the
        // second-to-last token; the test is everything between.
        if (n < 4) return invalid();
        auto j = find_command(tok[n - 2]);
        if (!j || (*j != Cmd::Jump && *j != Cmd::JumpRel && *j != Cmd::Call)) return invalid();
        auto test = parse_expr_tokens(tok, 1, n - 2);
        auto target = parse_expr_tokens(tok, n - 1, n);
        if (!test || !target) return invalid();
        c.jump = *j;
        c.expr = *test;
        c.target = *target;
        return c;
    }
    if (const KeywordSpec* ks = keyword_spec(c.cmd)) {
        if (n == 1) return ks->optional ? c : invalid();
        if (n != 2) return invalid();
        auto k = find_keyword(tok[1]);
        if (!k || std::find(ks->allowed.begin(), ks->allowed.end(), *k) == ks->allowed.end())
            return invalid();
        c.keyword = *k;
        return c;
    }
    switch (arg_kind(c.cmd)) {
        case ArgKind::None:
            return n == 1 ? c : invalid();
        case ArgKind::Optional:
            if (n == 1) return c;
            [[fallthrough]];
        case ArgKind::Required: {
            if (n < 2) return invalid();
            auto e = parse_expr_tokens(tok, 1, n);
            if (!e) return invalid();
            c.expr = *e;
            c.has_arg = true;
            return c;
        }
    }
    return invalid();
}

void append_bit(std::string& s, int bit) {
    s += '.';
    s += std::to_string(bit);
}

std::string two_digits(int v) {
    char b[8];
    std::snprintf(b, sizeof b, "%02d", v < 0 ? 0 : v % 100);
    return b;
}

}  // namespace

// ---- tables -----------------------------------------------------------------
const VarInfo& var_info(Var v) {
    auto i = static_cast<std::size_t>(v);
    return vars()[i < kVarCount ? i : 0];
}

std::optional<Var> find_variable(std::string_view name) {
    if (!name.empty() && name[0] == '#') name.remove_prefix(1);
    if (name.empty() || name.size() > 32) return std::nullopt;
    const auto& t = vars();
    for (std::size_t i = 0; i < t.size(); ++i) {
        std::string_view full = std::string_view(t[i].name).substr(1);
        std::string_view mn = std::string_view(t[i].mnemonic).substr(1);
        if (iequals(name, full) || iequals(name, mn)) return static_cast<Var>(i);
    }
    return std::nullopt;
}

const CommandInfo& cmd_info(Cmd c) {
    auto i = static_cast<std::size_t>(c);
    return kCmds[i < std::size(kCmds) ? i : 0];
}

std::optional<Cmd> find_command(std::string_view w) {
    if (w.empty() || w.size() > 24) return std::nullopt;
    for (std::size_t i = 2; i < std::size(kCmds); ++i) {
        const auto& ci = kCmds[i];
        if (iequals(w, ci.name) || iequals(w, ci.mnemonic) || (!ci.alt.empty() && iequals(w, ci.alt)))
            return ci.cmd;
    }
    return std::nullopt;
}

std::string_view keyword_text(Keyword k) {
    auto i = static_cast<std::size_t>(k);
    return i < std::size(kKeywords) ? kKeywords[i] : "";
}

std::string_view op_text(Op op) {
    static constexpr std::string_view t[] = {"", "+", "-", "*", "/", "&", "|", ">", "<", ">=", "<=", "!=", "="};
    auto i = static_cast<std::size_t>(op);
    return i < std::size(t) ? t[i] : "";
}

std::vector<std::string> status_names(std::uint32_t s) {
    static constexpr std::pair<int, const char*> names[] = {
        {status::kOptimizedCurrent, "optimized_current"}, {status::kHardPosEnabled, "hard_pos_enabled"},
        {status::kHardNegEnabled, "hard_neg_enabled"},    {status::kSoftEndsEnabled, "soft_ends_enabled"},
        {status::kHardEndsInverted, "hard_ends_inverted"}, {status::kSCurve, "s_curve"},
        {status::kInputsInverted, "inputs_inverted"},     {status::kOutputsInverted, "outputs_inverted"},
        {status::kSeqRun, "sequencer_run"},               {status::kSeqEdit, "sequencer_edit"},
        {status::kHardPosEnd, "hard_positive_end"},       {status::kHardNegEnd, "hard_negative_end"},
        {status::kSoftPosEnd, "soft_positive_end"},       {status::kSoftNegEnd, "soft_negative_end"},
        {status::kBrake, "brake"},                        {status::kSynchro, "synchro"},
        {status::kPowerOn, "power_on"},                   {status::kMovement, "movement"},
        {status::kPositionControl, "position_control"},   {status::kBusy, "busy"},
        {status::kReference, "reference"},                {status::kError, "error"},
        {status::kAbnormalStop, "abnormal_stop"},
    };
    std::vector<std::string> out;
    for (const auto& [b, n] : names)
        if (bit_set(s, b)) out.emplace_back(n);
    return out;
}

std::vector<std::string> error_names(std::uint32_t e) {
    static constexpr std::pair<int, const char*> names[] = {
        {error::kThermal, "thermal"},   {error::kShortCircuit, "short_circuit"},
        {error::kUndervoltage, "undervoltage"}, {error::kOvervoltage, "overvoltage"},
        {error::kLimit, "limit"},       {error::kComputation, "computation"},
        {error::kSyntax, "syntax"},
    };
    std::vector<std::string> out;
    for (const auto& [b, n] : names)
        if (bit_set(e, b)) out.emplace_back(n);
    return out;
}

// ---- requests ---------------------------------------------------------------
Request parse_request(std::string_view line) {
    Request r;
    std::string_view s = line;
    if (s.size() >= 2 && is_digit(s[0]) && is_digit(s[1])) {
        r.address = (s[0] - '0') * 10 + (s[1] - '0');
        if (r.address > kMaxAddress) r.address_error = true;
        s.remove_prefix(2);
    }
    if (line.size() > kMaxFrame) {
        r.commands.push_back(invalid());
        return r;
    }
    s = trim(s);
    if (!s.empty() && s[0] == ':') {
        std::size_t i = 1;
        while (i < s.size() && is_digit(s[i])) ++i;
        auto n = parse_digits(s.substr(1, i - 1), 9999);
        if (!n || *n < 1 || *n > kSeqLines) {
            r.commands.push_back(invalid(n ? error::kLimit : error::kSyntax));
            return r;
        }
        r.seq_line = static_cast<int>(*n);
        s = trim(s.substr(i));
    }
    if (s.empty()) {
        if (r.seq_line) r.commands.push_back(invalid());
        return r;
    }
    std::size_t start = 0;
    while (start <= s.size()) {
        std::size_t comma = s.find(',', start);
        std::size_t end = comma == std::string_view::npos ? s.size() : comma;
        r.commands.push_back(parse_command(s.substr(start, end - start)));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return r;
}

std::string format_operand(const Operand& o) {
    std::string s;
    if (o.complement) s += '!';
    if (o.negate) s += '-';
    if (o.is_var) {
        s += var_info(o.var).mnemonic;
        if (o.bit) append_bit(s, o.bit);
    } else {
        s += format_value(o.value, Radix::Dec);
    }
    return s;
}

std::string format_expr(const Expr& e) {
    std::string s = format_operand(e.lhs);
    if (e.op != Op::None) {
        s += ' ';
        s += op_text(e.op);
        s += ' ';
        s += format_operand(e.rhs);
    }
    return s;
}

std::string format_command(const Command& c) {
    if (c.cmd == Cmd::Invalid) return "";
    if (c.cmd == Cmd::Assign) {
        std::string s = var_info(c.var).mnemonic;
        if (c.bit) append_bit(s, c.bit);
        return s + ":=" + format_expr(c.expr);
    }
    std::string s(cmd_info(c.cmd).mnemonic);
    if (c.cmd == Cmd::Read) {
        s += ' ';
        if (c.radix == Radix::Hex) s += 'h';
        if (c.radix == Radix::Bin) s += 'b';
        s += var_info(c.var).mnemonic;
        if (c.bit) append_bit(s, c.bit);
        return s;
    }
    if (c.cmd == Cmd::If) {
        return s + " " + format_expr(c.expr) + " " + std::string(cmd_info(c.jump).mnemonic) + " " +
               format_expr(c.target);
    }
    if (c.keyword != Keyword::None) return s + " " + std::string(keyword_text(c.keyword));
    if (c.has_arg) return s + " " + format_expr(c.expr);
    return s;
}

// ---- values -----------------------------------------------------------------
std::string format_value(std::int32_t v, Radix r) {
    char b[48];
    auto u = static_cast<std::uint32_t>(v);
    switch (r) {
        case Radix::Hex:
            std::snprintf(b, sizeof b, "h%08X", static_cast<unsigned>(u));
            return b;
        case Radix::Bin: {
            std::string s = "b";
            for (int i = 31; i >= 0; --i) {
                s += ((u >> i) & 1u) ? '1' : '0';
                if (i % 8 == 0 && i != 0) s += ' ';
            }
            return s;
        }
        case Radix::Dec:
        default:
            std::snprintf(b, sizeof b, "%+lld", static_cast<long long>(v));
            return b;
    }
}

std::optional<std::int32_t> parse_number(std::string_view s) {
    if (s.empty()) return std::nullopt;
    char c0 = upper(s[0]);
    if (c0 == 'H') {
        auto u = parse_radix_digits(s.substr(1), 16);
        if (!u) return std::nullopt;
        return as_i32(*u);
    }
    if (c0 == 'B') {
        auto u = parse_radix_digits(s.substr(1), 2);
        if (!u) return std::nullopt;
        return as_i32(*u);
    }
    bool neg = false;
    if (s[0] == '+' || s[0] == '-') {
        neg = s[0] == '-';
        s.remove_prefix(1);
    }
    auto d = parse_digits(s, kI32Max + 1);
    if (!d) return std::nullopt;
    std::int64_t v = neg ? -*d : *d;
    if (v < kI32Min || v > kI32Max) return std::nullopt;
    return static_cast<std::int32_t>(v);
}

// ---- replies ----------------------------------------------------------------
std::optional<ReadReply> parse_read_reply(std::string_view s) {
    ReadReply r;
    if (s.size() < 5 || s.size() > 64 || !is_digit(s[0]) || !is_digit(s[1]) || s[2] != '#') return std::nullopt;
    r.address = (s[0] - '0') * 10 + (s[1] - '0');
    if (r.address > kMaxAddress) return std::nullopt;
    std::size_t i = 3;
    while (i < s.size() && is_name_char(s[i])) ++i;
    if (i == 3) return std::nullopt;
    r.mnemonic.assign(1, '#');
    r.mnemonic.append(s.substr(3, i - 3));
    for (char& c : r.mnemonic) c = upper(c);
    if (i < s.size() && s[i] == '.') {
        std::size_t j = i + 1;
        while (j < s.size() && is_digit(s[j])) ++j;
        auto b = parse_digits(s.substr(i + 1, j - i - 1), 99);
        if (!b || *b < 1 || *b > 32) return std::nullopt;
        r.bit = static_cast<int>(*b);
        i = j;
    }
    if (i >= s.size() || s[i] != '=') return std::nullopt;
    std::string_view v = s.substr(i + 1);
    if (v.empty()) return std::nullopt;
    if (v[0] == 'h' || v[0] == 'H') {
        auto u = parse_radix_digits(v.substr(1), 16);
        if (!u) return std::nullopt;
        r.value = as_i32(*u);
        r.radix = Radix::Hex;
        return r;
    }
    if (v[0] == 'b' || v[0] == 'B') {
        // Groups of 8 separated by single spaces, or one unbroken run.
        std::string digits;
        std::string_view body = v.substr(1);
        bool grouped = body.find(' ') != std::string_view::npos;
        if (grouped) {
            if (body.size() != 35) return std::nullopt;
            for (std::size_t k = 0; k < body.size(); ++k) {
                bool sep = (k % 9) == 8;
                if (sep != (body[k] == ' ')) return std::nullopt;
                if (!sep) digits += body[k];
            }
        } else {
            digits = std::string(body);
        }
        auto u = parse_radix_digits(digits, 2);
        if (!u) return std::nullopt;
        r.value = as_i32(*u);
        r.radix = Radix::Bin;
        return r;
    }
    auto n = parse_number(v);
    if (!n) return std::nullopt;
    r.value = *n;
    return r;
}

std::string format_read_reply(int address, Var v, int bit, std::int32_t value, Radix r) {
    std::string s = two_digits(address) + var_info(v).mnemonic;
    if (bit) append_bit(s, bit);
    return s + "=" + format_value(value, r);
}

std::optional<SeqLineReply> parse_seq_reply(std::string_view s) {
    // "00: 003 MTO +2000"
    if (s.size() < 7 || s.size() > kMaxFrame || !is_digit(s[0]) || !is_digit(s[1]) || s[2] != ':' ||
        s[3] != ' ')
        return std::nullopt;
    SeqLineReply r;
    r.address = (s[0] - '0') * 10 + (s[1] - '0');
    auto n = parse_digits(s.substr(4, 3), 999);
    if (!n || *n < 1 || *n > kSeqLines) return std::nullopt;
    r.line = static_cast<int>(*n);
    std::string_view rest = s.substr(7);
    if (!rest.empty()) {
        if (rest[0] != ' ') return std::nullopt;
        rest.remove_prefix(1);
    }
    for (char c : rest)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7E) return std::nullopt;
    r.text = std::string(rest);
    return r;
}

std::string format_seq_reply(int address, int line, std::string_view text) {
    char b[16];
    std::snprintf(b, sizeof b, "%03d", line < 0 ? 0 : line % 1000);
    std::string s = two_digits(address) + ": " + b;
    if (!text.empty()) {
        s += ' ';
        s += text;
    }
    return s;
}

std::string_view model_for_code(std::string_view code) {
    static constexpr std::pair<std::string_view, std::string_view> t[] = {
        {"9148", "DMAC17 standard"}, {"A148", "DMAC17 box version"}, {"B148", "DMAC17 clock & dir"},
        {"K148", "DMAC17 CANopen"},  {"F138", "DMAC23 standard"},    {"J138", "DMAC23 clock & dir"},
        {"K138", "DMAC23 CANopen"},  {"H142", "DMAC34 standard"},    {"J142", "DMAC34 clock & dir"},
        {"K142", "DMAC34 CANopen"},
    };
    for (const auto& [c, m] : t)
        if (c == code) return m;
    return "";
}

std::optional<VersionInfo> parse_version(std::string_view s) {
    // 04EV v1.7 H142 "MIDI-INGENIERIE_DMAC34-1_H142-10145_25/01/05_12/04/06" PHASE:6A BOOT:v1.1
    if (s.size() > kMaxFrame || s.size() < 8 || !is_digit(s[0]) || !is_digit(s[1])) return std::nullopt;
    VersionInfo v;
    v.address = (s[0] - '0') * 10 + (s[1] - '0');
    if (s.substr(2, 4) != "EV v") return std::nullopt;
    std::string_view rest = s.substr(6);
    std::size_t dot = rest.find('.');
    std::size_t sp = rest.find(' ');
    if (dot == std::string_view::npos || sp == std::string_view::npos || dot > sp) return std::nullopt;
    auto maj = parse_digits(rest.substr(0, dot), 999);
    auto min = parse_digits(rest.substr(dot + 1, sp - dot - 1), 999);
    if (!maj || !min) return std::nullopt;
    v.version = static_cast<int>(*maj);
    v.release = static_cast<int>(*min);
    rest = rest.substr(sp + 1);
    sp = rest.find(' ');
    if (sp == std::string_view::npos || sp == 0) return std::nullopt;
    v.code = std::string(rest.substr(0, sp));
    v.model = std::string(model_for_code(v.code));
    rest = rest.substr(sp + 1);
    if (rest.empty() || rest[0] != '"') return std::nullopt;
    std::size_t q = rest.find('"', 1);
    if (q == std::string_view::npos) return std::nullopt;
    v.ident = std::string(rest.substr(1, q - 1));
    {
        std::vector<std::string> parts;
        std::string cur;
        for (char c : v.ident) {
            if (c == '_') {
                parts.push_back(cur);
                cur.clear();
            } else {
                cur += c;
            }
        }
        parts.push_back(cur);
        if (parts.size() == 5) {
            v.manufacturer = parts[0];
            v.product = parts[1];
            v.serial = parts[2];
            v.manufacturing_date = parts[3];
            v.revision_date = parts[4];
        }
    }
    for (auto t : split_ws(rest.substr(q + 1))) {
        if (t.substr(0, 6) == "PHASE:") v.phase = std::string(t.substr(6));
        else if (t.substr(0, 5) == "BOOT:") v.boot = std::string(t.substr(5));
        else return std::nullopt;
    }
    return v;
}

// ---- request encoding -------------------------------------------------------
std::string address_prefix(int address) {
    if (address == kGlobal) return "";
    return two_digits(address);
}

std::string encode_read(int address, Var v, Radix r, int bit) {
    std::string s = address_prefix(address) + "READ ";
    if (r == Radix::Hex) s += 'h';
    if (r == Radix::Bin) s += 'b';
    s += var_info(v).name;
    if (bit) append_bit(s, bit);
    return s;
}

std::string encode_write(int address, Var v, std::int32_t value, int bit) {
    std::string s = address_prefix(address) + var_info(v).name;
    if (bit) append_bit(s, bit);
    // Decimal without '+' is what the manual types; both are accepted.
    return s + ":=" + std::to_string(value);
}

}  // namespace motorbus::dmac

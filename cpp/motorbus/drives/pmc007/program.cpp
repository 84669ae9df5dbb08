#include "motorbus/drives/pmc007/program.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>

#include "motorbus/errors.hpp"

namespace motorbus::pmc007 {
namespace {
constexpr const char* kNames[kInstructionCount] = {"ROT",  "MIC",  "DIR",  "EXTEN", "FREE", "CLR2",  "CLR1",
                                                   "VSET", "ACC",  "TRIG", "CNTI",  "CNTC", "JMP",   "JNE",
                                                   "JEQ",  "WAIT", "OUT",  "CMP",   "RESET_EN", "PAUSE_EN"};

std::string upper(std::string_view s) {
    std::string r(s);
    for (auto& c : r) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return r;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
}

std::optional<std::uint64_t> number(std::string_view s) {
    s = trim(s);
    int base = 10;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
        base = 16;
        s.remove_prefix(2);
    }
    if (s.empty()) return std::nullopt;
    std::uint64_t v = 0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
    if (ec != std::errc{} || p != s.data() + s.size()) return std::nullopt;
    return v;
}
}  // namespace

const char* mnemonic(Opcode op) {
    const auto i = static_cast<unsigned>(op);
    return i >= 1 && i <= kInstructionCount ? kNames[i - 1] : "?";
}

bool known_opcode(std::uint8_t op) { return op >= 1 && op <= kInstructionCount; }

std::optional<Opcode> opcode_from_mnemonic(std::string_view text) {
    const std::string u = upper(trim(text));
    for (int i = 0; i < kInstructionCount; ++i)
        if (u == kNames[i]) return static_cast<Opcode>(i + 1);
    return std::nullopt;
}

std::string validate(const Instruction& ins) {
    const auto d = ins.data;
    const auto o = ins.option;
    auto need_opt = [&](unsigned lo, unsigned hi) -> std::string {
        if (o < lo || o > hi)
            return std::string(mnemonic(ins.op)) + ": option " + std::to_string(o) + " outside " +
                   std::to_string(lo) + ".." + std::to_string(hi);
        return {};
    };
    auto need_data = [&](std::uint32_t lo, std::uint32_t hi) -> std::string {
        if (d < lo || d > hi)
            return std::string(mnemonic(ins.op)) + ": data " + std::to_string(d) + " outside " +
                   std::to_string(lo) + ".." + std::to_string(hi);
        return {};
    };
    std::string e;
    switch (ins.op) {
        case Opcode::ROT: e = need_opt(0, 0); return e.empty() ? need_data(1, 65536) : e;
        case Opcode::MIC:
            if (!(e = need_opt(0, 0)).empty()) return e;
            if (d == 0 || d == 2 || d == 4 || d == 8 || d == 16 || d == 32 || d == 64 || d == 128 || d == 256)
                return {};
            return "MIC: data " + std::to_string(d) + " is not 0/2/4/.../256";
        case Opcode::DIR:
        case Opcode::EXTEN:
        case Opcode::FREE: e = need_opt(0, 0); return e.empty() ? need_data(0, 1) : e;
        case Opcode::CLR2:
        case Opcode::CLR1:
        case Opcode::CNTI:
        case Opcode::CNTC: e = need_opt(0, 0); return e.empty() ? need_data(0, 0) : e;
        case Opcode::VSET: e = need_opt(0, 0); return e.empty() ? need_data(0, 6000) : e;
        case Opcode::ACC: e = need_opt(0, 0); return e.empty() ? need_data(0, 8) : e;  // C-P13: the 6008h gears
        case Opcode::TRIG: e = need_opt(0, 0); return e.empty() ? need_data(0, 3) : e;
        case Opcode::JMP:
        case Opcode::JNE:
        case Opcode::JEQ: e = need_opt(0, 0); return e.empty() ? need_data(0, 99) : e;  // C-P11
        case Opcode::WAIT: e = need_opt(1, 9); return e.empty() ? need_data(0, 1) : e;  // C-P10
        case Opcode::OUT: e = need_opt(1, 5); return e.empty() ? need_data(0, 1) : e;
        case Opcode::CMP: e = need_opt(1, 9); return e.empty() ? need_data(0, 65536) : e;
        case Opcode::RESET_EN: e = need_opt(0, 1); return e.empty() ? need_data(0, 99) : e;
        case Opcode::PAUSE_EN: e = need_opt(0, 1); return e.empty() ? need_data(0, 0) : e;
    }
    return "unknown opcode";
}

std::uint32_t encode(const Instruction& ins) {
    if (!known_opcode(static_cast<std::uint8_t>(ins.op)))
        throw InvalidArgument("pmc007 program: unknown opcode " + std::to_string(int(ins.op)));
    if (ins.option > 15) throw InvalidArgument("pmc007 program: option " + std::to_string(ins.option) + " > 15");
    if (ins.data > 0xFFFFF) throw InvalidArgument("pmc007 program: data " + std::to_string(ins.data) + " > 1048575");
    if (auto e = validate(ins); !e.empty()) throw InvalidArgument("pmc007 program: " + e);
    return (std::uint32_t(ins.op) << 24) | (std::uint32_t(ins.option) << 20) | ins.data;
}

std::optional<Instruction> decode(std::uint32_t word) {
    const auto op = static_cast<std::uint8_t>(word >> 24);
    if (!known_opcode(op)) return std::nullopt;
    return Instruction{static_cast<Opcode>(op), static_cast<std::uint8_t>((word >> 20) & 0xF), word & 0xFFFFF};
}

std::string disassemble_word(std::uint32_t word) {
    char buf[48];
    auto ins = decode(word);
    if (!ins || !validate(*ins).empty()) {
        std::snprintf(buf, sizeof buf, "RAW 0x%08X", word);
        return buf;
    }
    std::snprintf(buf, sizeof buf, "%s %u,%u", mnemonic(ins->op), unsigned(ins->option), unsigned(ins->data));
    return buf;
}

std::string disassemble(const std::vector<std::uint32_t>& words) {
    std::string out;
    for (auto w : words) out += disassemble_word(w) + "\n";
    return out;
}

std::vector<std::uint32_t> assemble(std::string_view text) {
    std::vector<std::uint32_t> out;
    std::size_t line_no = 0;
    while (!text.empty()) {
        ++line_no;
        const auto nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
        if (auto c = line.find_first_of("#;"); c != std::string_view::npos) line = line.substr(0, c);
        line = trim(line);
        if (line.empty()) continue;
        auto fail = [&](const std::string& why) -> InvalidArgument {
            return InvalidArgument("pmc007 program line " + std::to_string(line_no) + " (" + std::string(line) +
                                   "): " + why);
        };
        const auto sp = line.find_first_of(" \t");
        const std::string_view name = line.substr(0, sp);
        std::string_view args = sp == std::string_view::npos ? std::string_view{} : trim(line.substr(sp));
        if (upper(name) == "RAW") {
            auto v = number(args);
            if (!v || *v > 0xFFFFFFFFu) throw fail("RAW needs a 32-bit word");
            out.push_back(static_cast<std::uint32_t>(*v));
        } else {
            auto op = opcode_from_mnemonic(name);
            if (!op) throw fail("unknown instruction '" + std::string(name) + "'");
            Instruction ins{*op, 0, 0};
            if (!args.empty()) {
                const auto comma = args.find(',');
                if (comma == std::string_view::npos) throw fail("expected 'option,data'");
                auto o = number(args.substr(0, comma));
                auto d = number(args.substr(comma + 1));
                if (!o || !d) throw fail("option and data must be numbers");
                if (*o > 15) throw fail("option " + std::to_string(*o) + " > 15");
                if (*d > 0xFFFFF) throw fail("data " + std::to_string(*d) + " > 1048575");
                ins.option = static_cast<std::uint8_t>(*o);
                ins.data = static_cast<std::uint32_t>(*d);
            }
            if (auto e = validate(ins); !e.empty()) throw fail(e);
            out.push_back(encode(ins));
        }
        if (out.size() > kMaxProgram) throw fail("more than 100 instructions");
    }
    return out;
}

}  // namespace motorbus::pmc007

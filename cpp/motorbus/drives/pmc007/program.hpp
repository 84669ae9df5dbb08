// The PMC007 offline (user-defined) program: 20 instructions (003 §5.1).
//
// The manual never gives the 32-bit encoding of an instruction in 6019h:02.
// Reading followed (spec §1.10 [P]): bits 31-24 opcode (ROT = 0x01 ...
// PAUSE_EN = 0x14, in the order of the §5.1 table), bits 23-20 option
// (0-15), bits 19-0 data (0-1048575, enough for ROT/CMP's 65536).  A word
// with an unknown opcode still round-trips as raw text ("RAW 0x..."), so the
// words of a real device are never altered by a read-edit-write.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace motorbus::pmc007 {

enum class Opcode : std::uint8_t {
    ROT = 0x01, MIC, DIR, EXTEN, FREE, CLR2, CLR1, VSET, ACC, TRIG,
    CNTI, CNTC, JMP, JNE, JEQ, WAIT, OUT, CMP, RESET_EN, PAUSE_EN,
};
inline constexpr int kInstructionCount = 20;
inline constexpr std::size_t kMaxProgram = 100;

struct Instruction {
    Opcode op = Opcode::ROT;
    std::uint8_t option = 0;  // 0..15
    std::uint32_t data = 0;   // 0..0xFFFFF
    bool operator==(const Instruction&) const = default;
};

const char* mnemonic(Opcode op);
std::optional<Opcode> opcode_from_mnemonic(std::string_view text);  // case-insensitive
bool known_opcode(std::uint8_t op);

// Word <-> instruction.  encode throws InvalidArgument naming the field that
// does not fit (or is outside the instruction's documented range, see
// validate); decode returns nullopt for an unknown opcode.
std::uint32_t encode(const Instruction& ins);
std::optional<Instruction> decode(std::uint32_t word);
// The documented ranges (003 §5.1 with the readings C-P10, C-P11, C-P12):
// empty when valid, else why.
std::string validate(const Instruction& ins);

// Text: one instruction per line, "MNEMONIC option,data" ("ROT 0,3200",
// "WAIT 1,0", "CNTI"), '#' or ';' comments, blank lines ignored; "RAW 0x..." for
// a word with an unknown opcode.  assemble throws InvalidArgument naming the
// line; disassemble never throws.
std::vector<std::uint32_t> assemble(std::string_view text);
std::string disassemble_word(std::uint32_t word);
std::string disassemble(const std::vector<std::uint32_t>& words);

}  // namespace motorbus::pmc007

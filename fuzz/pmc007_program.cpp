// Fuzz target: the PMC007 offline-program codec.  Arbitrary text through the
// assembler (typed errors only), and arbitrary words through the disassembler:
// every word disassembles, and the text re-assembles to the same word (RAW for
// words outside the documented ranges), so a real device's program survives a
// read-edit-write unchanged.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "motorbus/drives/pmc007/program.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus::pmc007;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        auto words = assemble(text);
        if (words.size() > kMaxProgram) __builtin_trap();
        if (assemble(disassemble(words)) != words) __builtin_trap();
    } catch (const motorbus::InvalidArgument&) {
    }
    std::vector<std::uint32_t> words;
    for (std::size_t i = 0; i + 4 <= size && words.size() < kMaxProgram; i += 4)
        words.push_back(std::uint32_t(data[i]) | std::uint32_t(data[i + 1]) << 8 | std::uint32_t(data[i + 2]) << 16 |
                        std::uint32_t(data[i + 3]) << 24);
    if (assemble(disassemble(words)) != words) __builtin_trap();
    for (auto w : words)
        if (auto ins = decode(w); ins && validate(*ins).empty() && encode(*ins) != w) __builtin_trap();
    return 0;
}

// Pure line reassembly: bytes in, complete lines out.  No I/O, no clock, so the
// link, the pty line server and the fuzzer share one implementation.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace motorbus::serial {

struct FramedLine {
    enum class Kind { Line, Overlong };
    Kind kind = Kind::Line;
    // Line: the content without its terminator.  Overlong: the first bytes of
    // the discarded line (at most LineFramer::kOverlongPrefix).
    std::string text;
    std::size_t length = 0;   // content length (for Overlong: the full discarded length)
    std::string terminator;   // which terminator ended it
};

// Splits a byte stream into lines ended by any of a set of terminators.
//  * When several terminators end at the same byte the longest wins
//    ({"\n", "\r\n"}: "a\r\n" is "a").
//  * When a terminator is a prefix of another ({"\r", "\r\n"}) the line ends at
//    the shorter one at once (no waiting) and the rest of the longer one, if it
//    follows, is swallowed instead of starting a new line.
//  * A line whose content exceeds max_line stops being stored; the framer keeps
//    only a small window to find the next terminator, then reports Overlong.
//    Memory is bounded by max_line + the longest terminator.
class LineFramer {
public:
    static constexpr std::size_t kMaxTerminator = 8;
    static constexpr std::size_t kMaxLineLimit = std::size_t(1) << 20;
    static constexpr std::size_t kOverlongPrefix = 32;

    // Throws InvalidArgument on an empty terminator set, an empty or over-long
    // terminator, or max_line outside [1, kMaxLineLimit].
    LineFramer(std::vector<std::string> terminators, std::size_t max_line);

    // Consumes bytes from `in` up to and including the end of the first line
    // that completes; `consumed` says how many.  nullopt: all of `in` was
    // consumed and no line completed yet.
    std::optional<FramedLine> push(std::span<const std::uint8_t> in, std::size_t& consumed);

    // Forgets the partial line (and any pending terminator continuation).
    void reset();
    // Bytes of the current partial line (content + partial terminator).
    std::size_t partial_bytes() const { return count_; }
    bool discarding() const { return discarding_; }
    std::size_t max_line() const { return max_line_; }
    const std::vector<std::string>& terminators() const { return terms_; }

private:
    bool extends_tail(std::uint8_t b) const;

    std::vector<std::string> terms_;
    std::size_t max_line_;
    std::size_t longest_term_ = 0;
    std::string buf_;     // content + terminator bytes so far (bounded)
    std::string window_;  // last longest_term_ bytes of this line
    std::string prefix_;  // first bytes of an overlong line
    std::size_t count_ = 0;
    bool discarding_ = false;
    std::string tail_;    // terminator matched so far, while a longer one may follow
};

}  // namespace motorbus::serial

#include "motorbus/serial/line_framer.hpp"

#include <algorithm>

#include "motorbus/errors.hpp"

namespace motorbus::serial {

LineFramer::LineFramer(std::vector<std::string> terminators, std::size_t max_line)
    : terms_(std::move(terminators)), max_line_(max_line) {
    if (terms_.empty()) throw InvalidArgument("reply_terminators: need at least one terminator");
    for (const auto& t : terms_) {
        if (t.empty()) throw InvalidArgument("reply_terminators: empty terminator");
        if (t.size() > kMaxTerminator)
            throw InvalidArgument("reply_terminators: terminator longer than 8 bytes");
        longest_term_ = std::max(longest_term_, t.size());
    }
    if (max_line_ < 1 || max_line_ > kMaxLineLimit)
        throw InvalidArgument("max_line: must be in [1, 1048576]");
    buf_.reserve(std::min<std::size_t>(max_line_ + longest_term_ + 1, 4096));
}

void LineFramer::reset() {
    buf_.clear();
    window_.clear();
    prefix_.clear();
    count_ = 0;
    discarding_ = false;
    tail_.clear();
}

bool LineFramer::extends_tail(std::uint8_t b) const {
    for (const auto& t : terms_) {
        if (t.size() <= tail_.size()) continue;
        if (t.compare(0, tail_.size(), tail_) == 0 && static_cast<std::uint8_t>(t[tail_.size()]) == b)
            return true;
    }
    return false;
}

std::optional<FramedLine> LineFramer::push(std::span<const std::uint8_t> in, std::size_t& consumed) {
    consumed = 0;
    while (consumed < in.size()) {
        const std::uint8_t b = in[consumed++];
        if (!tail_.empty()) {
            if (extends_tail(b)) {
                tail_.push_back(static_cast<char>(b));
                continue;
            }
            tail_.clear();
        }
        ++count_;
        if (window_.size() == longest_term_) window_.erase(0, 1);
        window_.push_back(static_cast<char>(b));
        if (!discarding_)
            buf_.push_back(static_cast<char>(b));
        else if (prefix_.size() < kOverlongPrefix)
            prefix_.push_back(static_cast<char>(b));

        const std::string* match = nullptr;
        for (const auto& t : terms_) {
            if (t.size() > window_.size()) continue;
            if (window_.compare(window_.size() - t.size(), t.size(), t) != 0) continue;
            if (!match || t.size() > match->size()) match = &t;
        }
        if (match) {
            FramedLine out;
            out.terminator = *match;
            out.length = count_ - match->size();
            if (discarding_ || out.length > max_line_) {
                out.kind = FramedLine::Kind::Overlong;
                const std::string& seen = discarding_ ? prefix_ : buf_;
                out.text = seen.substr(0, std::min({out.length, kOverlongPrefix, seen.size()}));
            } else {
                out.kind = FramedLine::Kind::Line;
                out.text = buf_.substr(0, out.length);
            }
            std::string term = *match;
            reset();
            // Keep swallowing if a longer terminator starts with this one.
            tail_ = term;
            bool longer = false;
            for (const auto& t : terms_)
                if (t.size() > term.size() && t.compare(0, term.size(), term) == 0) longer = true;
            if (!longer) tail_.clear();
            return out;
        }
        if (!discarding_ && buf_.size() > max_line_ + longest_term_) {
            // Content is now certainly longer than max_line whatever terminator comes.
            discarding_ = true;
            prefix_ = buf_.substr(0, kOverlongPrefix);
            buf_.clear();
            buf_.shrink_to_fit();
        }
    }
    return std::nullopt;
}

}  // namespace motorbus::serial

// A CAN frame as every layer sees it.
//
// Classic CAN today (DLC 0-8); the payload array is sized for CAN FD (64 bytes)
// and `flags` carries FD/BRS/ESI so FD can be added without changing the type.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "motorbus/runtime/clock.hpp"

namespace motorbus::can {

constexpr std::uint32_t kMaxStandardId = 0x7FF;
constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFF;
constexpr std::size_t kMaxClassicLen = 8;
constexpr std::size_t kMaxFdLen = 64;

enum FrameFlags : std::uint8_t {
    kFlagFd = 1 << 0,        // CAN FD frame (not produced by any backend yet)
    kFlagBrs = 1 << 1,       // FD bit-rate switch
    kFlagEsi = 1 << 2,       // FD error state indicator
    kFlagError = 1 << 3,     // error frame reported by the adapter (data = details)
    kFlagLoopback = 1 << 4,  // our own frame echoed back to us
};

struct Frame {
    std::uint32_t id = 0;
    bool extended = false;
    bool rtr = false;
    std::uint8_t len = 0;    // payload length; for an RTR frame the requested DLC
    std::uint8_t flags = 0;  // FrameFlags
    Nanos timestamp_ns = 0;  // monotonic_ns() when received (or sent), 0 if unknown
    std::array<std::uint8_t, kMaxFdLen> data{};

    // Validating constructor: throws InvalidArgument naming the bad field.
    static Frame make(std::uint32_t id, std::span<const std::uint8_t> payload,
                      bool extended = false, bool rtr = false, int rtr_dlc = -1);

    // nullopt when valid, else a message naming the first invalid field.
    std::optional<std::string> problem() const;
    bool valid() const { return !problem(); }

    std::span<const std::uint8_t> payload() const { return {data.data(), rtr ? 0u : len}; }
    bool is_fd() const { return flags & kFlagFd; }

    // Same id, kind and payload (timestamps and loopback flag ignored).
    bool same_content(const Frame& o) const;
    // candump-like text: "123#DEADBEEF", "12345678#", "123#R2"
    std::string to_string() const;
};

// Acceptance filter: a frame passes when (frame.id & mask) == (id & mask) and,
// if `match_extended`, the frame's id width equals `extended`.
struct Filter {
    std::uint32_t id = 0;
    std::uint32_t mask = 0;  // 0 = accept all ids
    bool extended = false;
    bool match_extended = false;
    bool matches(const Frame& f) const {
        if (match_extended && f.extended != extended) return false;
        return (f.id & mask) == (id & mask);
    }
};

// Bits on the wire for a classic frame with worst-case bit stuffing, including
// the 3-bit intermission (Davis et al., "CAN schedulability analysis revisited").
unsigned wire_bits_worst_case(const Frame& f);

}  // namespace motorbus::can

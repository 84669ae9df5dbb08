#include "motorbus/can/frame.hpp"

#include <cstdio>

#include "motorbus/errors.hpp"

namespace motorbus::can {

Frame Frame::make(std::uint32_t id, std::span<const std::uint8_t> payload, bool extended,
                  bool rtr, int rtr_dlc) {
    Frame f;
    f.id = id;
    f.extended = extended;
    f.rtr = rtr;
    if (payload.size() > kMaxClassicLen)
        throw InvalidArgument("frame data: " + std::to_string(payload.size()) +
                              " bytes, a classic CAN frame carries 0-8");
    if (rtr) {
        if (!payload.empty())
            throw InvalidArgument("frame data: an RTR frame carries no data (use dlc)");
        int dlc = rtr_dlc < 0 ? 0 : rtr_dlc;
        if (dlc > 8) throw InvalidArgument("frame dlc: " + std::to_string(dlc) + ", must be 0-8");
        f.len = static_cast<std::uint8_t>(dlc);
    } else {
        f.len = static_cast<std::uint8_t>(payload.size());
        for (std::size_t i = 0; i < payload.size(); ++i) f.data[i] = payload[i];
    }
    if (auto p = f.problem()) throw InvalidArgument(*p);
    return f;
}

std::optional<std::string> Frame::problem() const {
    char buf[96];
    if (extended ? id > kMaxExtendedId : id > kMaxStandardId) {
        std::snprintf(buf, sizeof buf, "frame id: 0x%X exceeds the %s maximum 0x%X", id,
                      extended ? "29-bit" : "11-bit", extended ? kMaxExtendedId : kMaxStandardId);
        return std::string(buf);
    }
    if (is_fd()) {
        static constexpr std::uint8_t ok[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
        bool good = false;
        for (auto v : ok) good |= (v == len);
        if (!good) return "frame len: " + std::to_string(len) + " is not a CAN FD length";
        if (rtr) return std::string("frame rtr: CAN FD has no remote frames");
    } else if (len > kMaxClassicLen) {
        return "frame dlc: " + std::to_string(len) + ", a classic CAN frame carries 0-8";
    }
    return std::nullopt;
}

bool Frame::same_content(const Frame& o) const {
    if (id != o.id || extended != o.extended || rtr != o.rtr || len != o.len) return false;
    if ((flags & ~kFlagLoopback) != (o.flags & ~kFlagLoopback)) return false;
    if (rtr) return true;
    for (unsigned i = 0; i < len; ++i)
        if (data[i] != o.data[i]) return false;
    return true;
}

std::string Frame::to_string() const {
    char buf[16 + 2 * kMaxFdLen];
    int n = std::snprintf(buf, sizeof buf, extended ? "%08X#" : "%03X#", id);
    if (rtr) {
        std::snprintf(buf + n, sizeof buf - n, "R%u", len);
    } else {
        for (unsigned i = 0; i < len; ++i) n += std::snprintf(buf + n, sizeof buf - n, "%02X", data[i]);
    }
    return buf;
}

unsigned wire_bits_worst_case(const Frame& f) {
    const unsigned data_bits = f.rtr ? 0 : 8u * f.len;
    // Bits exposed to stuffing: SOF..CRC.  Standard: 34 + data, extended: 54 + data.
    const unsigned stuffed = (f.extended ? 54u : 34u) + data_bits;
    // Fixed-form tail: CRC delimiter, ACK slot+delimiter, EOF (7), intermission (3) = 13.
    return stuffed + 13u + (stuffed - 1u) / 4u;
}

}  // namespace motorbus::can

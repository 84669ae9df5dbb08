// SdoAccess: the narrow SDO interface the services need (PDO configuration,
// CiA 402 host, scanner).  Our SdoClient implements it in sdo_client_access.hpp;
// tests and Python clients implement it directly, so the services compile and
// test without a bus.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace motorbus::canopen {

class SdoAccess {
public:
    virtual ~SdoAccess() = default;
    // Writes `data` (the object's little-endian bytes) to node:index:sub.
    // Throws the client's errors (timeout, abort) unchanged.
    virtual void download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                          std::span<const std::uint8_t> data) = 0;
    virtual std::vector<std::uint8_t> upload(std::uint8_t node, std::uint16_t index,
                                             std::uint8_t sub) = 0;

    // Little-endian helpers on top of the two primitives.
    void write_u8(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint8_t v) {
        const std::uint8_t b[1] = {v};
        download(node, index, sub, b);
    }
    void write_u16(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint16_t v) {
        const std::uint8_t b[2] = {std::uint8_t(v), std::uint8_t(v >> 8)};
        download(node, index, sub, b);
    }
    void write_u32(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t v) {
        const std::uint8_t b[4] = {std::uint8_t(v), std::uint8_t(v >> 8), std::uint8_t(v >> 16),
                                   std::uint8_t(v >> 24)};
        download(node, index, sub, b);
    }
    // Reads and zero-extends up to 8 bytes.
    std::uint64_t read_uint(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
        auto d = upload(node, index, sub);
        std::uint64_t v = 0;
        for (std::size_t i = 0; i < d.size() && i < 8; ++i) v |= std::uint64_t(d[i]) << (8 * i);
        return v;
    }
};

}  // namespace motorbus::canopen

// Hex helpers shared by the SDO tests.
#pragma once
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "motorbus/canopen/sdo_codec.hpp"

namespace motorbus::test {

// "40 01 60 00" -> bytes (any whitespace; exactly as written, no padding).
inline std::vector<std::uint8_t> H(const std::string& s) {
    std::vector<std::uint8_t> out;
    std::string digits;
    for (char c : s)
        if (std::isxdigit(static_cast<unsigned char>(c))) digits.push_back(c);
    for (std::size_t i = 0; i + 1 < digits.size(); i += 2)
        out.push_back(static_cast<std::uint8_t>(std::stoul(digits.substr(i, 2), nullptr, 16)));
    return out;
}

template <class Container>
inline std::string hex(const Container& p) {
    std::string s;
    char b[4];
    for (auto x : p) {
        std::snprintf(b, sizeof b, "%s%02X", s.empty() ? "" : " ", static_cast<unsigned>(x));
        s += b;
    }
    return s;
}

// n bytes of a fixed, non-repeating pattern: transfers of any size compare byte for byte.
inline std::vector<std::uint8_t> pattern(std::size_t n) {
    std::vector<std::uint8_t> b(n);
    for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<std::uint8_t>((i * 31 + 7) ^ (i >> 8));
    return b;
}

inline std::vector<std::string> hexes(const std::vector<canopen::sdo::Payload>& v) {
    std::vector<std::string> out;
    for (auto& p : v) out.push_back(hex(p));
    return out;
}

}  // namespace motorbus::test

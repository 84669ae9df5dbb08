// CiA 301 SDO abort codes, their texts, and the typed SDO errors.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

namespace abort_code {
constexpr std::uint32_t kNone = 0;
constexpr std::uint32_t kToggleBit = 0x05030000;
constexpr std::uint32_t kTimeout = 0x05040000;
constexpr std::uint32_t kCommandSpecifier = 0x05040001;
constexpr std::uint32_t kBlockSize = 0x05040002;
constexpr std::uint32_t kSequenceNumber = 0x05040003;
constexpr std::uint32_t kCrc = 0x05040004;
constexpr std::uint32_t kOutOfMemory = 0x05040005;
constexpr std::uint32_t kUnsupportedAccess = 0x06010000;
constexpr std::uint32_t kWriteOnly = 0x06010001;   // attempt to read a write-only object
constexpr std::uint32_t kReadOnly = 0x06010002;    // attempt to write a read-only object
constexpr std::uint32_t kNoObject = 0x06020000;
constexpr std::uint32_t kNotMappable = 0x06040041;
constexpr std::uint32_t kPdoLength = 0x06040042;
constexpr std::uint32_t kParamIncompatible = 0x06040043;
constexpr std::uint32_t kInternalIncompatible = 0x06040047;
constexpr std::uint32_t kHardware = 0x06060000;
constexpr std::uint32_t kTypeMismatch = 0x06070010;
constexpr std::uint32_t kTooLong = 0x06070012;
constexpr std::uint32_t kTooShort = 0x06070013;
constexpr std::uint32_t kNoSubindex = 0x06090011;
constexpr std::uint32_t kInvalidValue = 0x06090030;
constexpr std::uint32_t kValueTooHigh = 0x06090031;
constexpr std::uint32_t kValueTooLow = 0x06090032;
constexpr std::uint32_t kMaxLessThanMin = 0x06090036;
constexpr std::uint32_t kResourceUnavailable = 0x060A0023;
constexpr std::uint32_t kGeneral = 0x08000000;
constexpr std::uint32_t kCannotStore = 0x08000020;
constexpr std::uint32_t kLocalControl = 0x08000021;
constexpr std::uint32_t kDeviceState = 0x08000022;
constexpr std::uint32_t kNoDictionary = 0x08000023;
constexpr std::uint32_t kNoData = 0x08000024;
}  // namespace abort_code

// The CiA 301 text for `code`, or nullptr when the code is not in the table.
// A device manual misprints a few codes (05030004/05030005 for the CiA
// 05040004/05040005, 0606001x for 0607001x; docs/canopen.md): those decode to
// the CiA text.
const char* abort_text(std::uint32_t code);
// "0x06020000 Object does not exist in the object dictionary" (or "... unknown abort code").
std::string describe_abort(std::uint32_t code);

struct AbortEntry {
    std::uint32_t code;
    const char* text;
};
// The table in code order (for docs, EDS tools and tests).
const std::vector<AbortEntry>& abort_table();

// The peer (or our own side, for a local refusal) aborted the transfer.
// Python: motorbus.canopen.SdoAbortError(MotorbusError) with .code, .text, .index, .subindex.
struct SdoAbortError : Error {
    SdoAbortError(std::uint32_t code, std::uint16_t index, std::uint8_t subindex,
                  bool from_peer = true);
    std::uint32_t code;
    std::uint16_t index;
    std::uint8_t subindex;
    bool from_peer;  // false when we aborted (e.g. the server sent a malformed frame)
    std::string text() const { return abort_text(code) ? abort_text(code) : "unknown abort code"; }
};

// No (complete) answer within the SDO timeout; an abort 0x05040000 carrying
// the index and sub-index has been sent.  Python: subclass of motorbus.TimeoutError.
struct SdoTimeout : TimeoutError {
    SdoTimeout(const std::string& what, std::uint16_t index, std::uint8_t subindex)
        : TimeoutError(what), index(index), subindex(subindex) {}
    std::uint16_t index;
    std::uint8_t subindex;
};

// The server sent a frame that breaks the protocol (wrong multiplexer, bad
// command specifier, short frame, size mismatch, CRC...).  `bytes` holds that
// frame; `code` is the abort code we sent in reply.
// Python: subclass of motorbus.ProtocolError with .data and .code.
struct SdoProtocolError : ProtocolError {
    SdoProtocolError(const std::string& what, std::vector<std::uint8_t> frame, std::uint32_t code,
                     std::uint16_t index, std::uint8_t subindex)
        : ProtocolError(what, std::move(frame)), code(code), index(index), subindex(subindex) {}
    std::uint32_t code;
    std::uint16_t index;
    std::uint8_t subindex;
};

}  // namespace motorbus::canopen

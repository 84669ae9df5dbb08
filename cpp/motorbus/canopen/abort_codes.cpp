#include "motorbus/canopen/abort_codes.hpp"

#include <algorithm>
#include <cstdio>

namespace motorbus::canopen {

const std::vector<AbortEntry>& abort_table() {
    static const std::vector<AbortEntry> table = {
        {0x05030000, "Toggle bit not alternated"},
        {0x05040000, "SDO protocol timed out"},
        {0x05040001, "Client/server command specifier not valid or unknown"},
        {0x05040002, "Invalid block size (block mode only)"},
        {0x05040003, "Invalid sequence number (block mode only)"},
        {0x05040004, "CRC error (block mode only)"},
        {0x05040005, "Out of memory"},
        {0x06010000, "Unsupported access to an object"},
        {0x06010001, "Attempt to read a write only object"},
        {0x06010002, "Attempt to write a read only object"},
        {0x06020000, "Object does not exist in the object dictionary"},
        {0x06040041, "Object cannot be mapped to the PDO"},
        {0x06040042, "The number and length of the objects to be mapped would exceed PDO length"},
        {0x06040043, "General parameter incompatibility reason"},
        {0x06040047, "General internal incompatibility in the device"},
        {0x06060000, "Access failed due to a hardware error"},
        {0x06070010, "Data type does not match, length of service parameter does not match"},
        {0x06070012, "Data type does not match, length of service parameter too high"},
        {0x06070013, "Data type does not match, length of service parameter too low"},
        {0x06090011, "Sub-index does not exist"},
        {0x06090030, "Invalid value for parameter (download only)"},
        {0x06090031, "Value of parameter written too high (download only)"},
        {0x06090032, "Value of parameter written too low (download only)"},
        {0x06090036, "Maximum value is less than minimum value"},
        {0x060A0023, "Resource not available: SDO connection"},
        {0x08000000, "General error"},
        {0x08000020, "Data cannot be transferred or stored to the application"},
        {0x08000021,
         "Data cannot be transferred or stored to the application because of local control"},
        {0x08000022,
         "Data cannot be transferred or stored to the application because of the present device "
         "state"},
        {0x08000023,
         "Object dictionary dynamic generation fails or no object dictionary is present"},
        {0x08000024, "No data available"},
    };
    return table;
}

const char* abort_text(std::uint32_t code) {
    // Codes a device manual misprints (docs/canopen.md, "Abort codes"): decode them as
    // the CiA codes they stand for.
    switch (code) {
        case 0x05030004: code = 0x05040004; break;
        case 0x05030005: code = 0x05040005; break;
        case 0x06060010: code = 0x06070010; break;
        case 0x06060012: code = 0x06070012; break;
        case 0x06060013: code = 0x06070013; break;
        default: break;
    }
    const auto& t = abort_table();
    auto it = std::lower_bound(t.begin(), t.end(), code,
                               [](const AbortEntry& e, std::uint32_t c) { return e.code < c; });
    return it != t.end() && it->code == code ? it->text : nullptr;
}

std::string describe_abort(std::uint32_t code) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%08X ", code);
    const char* t = abort_text(code);
    return std::string(buf) + (t ? t : "unknown abort code");
}

namespace {
std::string abort_message(std::uint32_t code, std::uint16_t index, std::uint8_t sub, bool peer) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "SDO %s 0x%04X:%02X: ", peer ? "abort from server for" : "transfer aborted for",
                  index, sub);
    return std::string(buf) + describe_abort(code);
}
}  // namespace

SdoAbortError::SdoAbortError(std::uint32_t code, std::uint16_t index, std::uint8_t subindex,
                             bool from_peer)
    : Error(abort_message(code, index, subindex, from_peer)),
      code(code),
      index(index),
      subindex(subindex),
      from_peer(from_peer) {}

}  // namespace motorbus::canopen

// The PMC007's object dictionary (003 Appendix 1, §4.3-§4.9, with the
// readings of the spec's §1.2/§1.3) as ONE table of rows.  The simulator's
// dictionary (build_pmc007_od) and the EDS shipped with the package
// (eds, written to device.eds by the generator test) both come from
// it, so the device a host talks to and the file it loads cannot disagree.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "motorbus/canopen/od.hpp"

namespace motorbus::pmc007 {

// How an object behaves over reset node / power-up (B-P37).
enum class Storage : std::uint8_t {
    Rom,    // held in RAM when written, saved to flash by 2007h=2, reloaded at reset node
    Ram,    // back to the default at reset node / power-up
    Const,  // never changes
};

struct OdRow {
    std::uint16_t index;
    std::uint8_t sub;
    const char* name;
    canopen::DataType type;
    canopen::Access access;
    bool pdo;  // Appendix 1 "PDO" column = Optional (B-P31)
    Storage storage;
    std::int64_t def;                   // numeric default (strings: see text)
    std::optional<std::int64_t> low{};  // inclusive limits enforced by the OD (range aborts)
    std::optional<std::int64_t> high{};
    const char* parent = nullptr;  // record/array name for sub-indexed objects (nullptr = VAR)
    const char* text = nullptr;    // default of a VISIBLE_STRING
    const char* expr = nullptr;    // "$NODEID+0x180" style default for the EDS
    std::int64_t node_offset = -1; // >= 0: default = node_offset + node-ID
    std::size_t alt_size = 0;      // a second size the manual lists (6020h: U8 and U32)
};

// Every index:sub of the spec (73 indices, 210 entries), in index order.
const std::vector<OdRow>& od_rows();
// The row of (index, sub), or nullptr.
const OdRow* od_row(std::uint16_t index, std::uint8_t sub);
// 1018h:01-04.  003 documents no identity: the EDS carries 0 (unknown); a simulator
// reads the identity it was given (SimOptions::identity).
struct Identity {
    std::uint32_t vendor_id = 0;
    std::uint32_t product_code = 0;
    std::uint32_t revision = 0;
    std::uint32_t serial = 0;
};
// A dictionary with every row, defaults evaluated for `node_id` (1..127), 1018h from `identity`.
std::shared_ptr<canopen::ObjectDictionary> build_pmc007_od(std::uint8_t node_id, const Identity& identity = {});
// The EDS text of that dictionary ($NODEID expressions kept).
std::string eds();

}  // namespace motorbus::pmc007

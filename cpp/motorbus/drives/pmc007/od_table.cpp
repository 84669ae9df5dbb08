#include "motorbus/drives/pmc007/od_table.hpp"

#include <map>

#include "motorbus/canopen/eds.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::pmc007 {
using canopen::Access;
using canopen::DataType;

namespace {
constexpr auto U8 = DataType::Unsigned8;
constexpr auto U16 = DataType::Unsigned16;
constexpr auto U32 = DataType::Unsigned32;
constexpr auto S32 = DataType::Integer32;
constexpr auto STR = DataType::VisibleString;
constexpr auto RO = Access::RO;
constexpr auto RW = Access::RW;
constexpr auto CONST = Access::Const;
constexpr auto ROM = Storage::Rom;
constexpr auto RAM = Storage::Ram;
using L = std::optional<std::int64_t>;
constexpr L none = std::nullopt;

std::vector<OdRow> make_rows() {
    std::vector<OdRow> t;
    auto var = [&](std::uint16_t i, const char* n, DataType ty, Access a, bool pdo, Storage st, std::int64_t d,
                   L lo = none, L hi = none) { t.push_back({i, 0, n, ty, a, pdo, st, d, lo, hi}); };
    auto mem = [&](std::uint16_t i, std::uint8_t s, const char* parent, const char* n, DataType ty, Access a,
                   bool pdo, Storage st, std::int64_t d, L lo = none, L hi = none) {
        t.push_back({i, s, n, ty, a, pdo, st, d, lo, hi, parent});
    };
    // ---- communication area (spec §1.2) ----
    var(0x1000, "Device type", U32, RO, false, Storage::Const, 0);
    var(0x1001, "Error register", U8, RO, true, RAM, 0);
    var(0x1002, "Manufacturer status register", U32, RO, true, RAM, 0);
    mem(0x1003, 0, "Pre-defined error field", "Number of errors", U8, RW, false, RAM, 0);  // only 0 (06090030)
    for (std::uint8_t s = 1; s <= 7; ++s)
        mem(0x1003, s, "Pre-defined error field", "Standard error field", U32, RO, true, RAM, 0);
    var(0x1005, "COB-ID SYNC", U32, RW, false, ROM, 0x80);
    var(0x1006, "Communication cycle period", U32, RW, false, ROM, 0);
    var(0x1007, "Synchronous window length", U32, RW, true, ROM, 0);
    t.push_back({0x1008, 0, "Manufacturer device name", STR, CONST, false, Storage::Const, 0, none, none, nullptr,
                 "PMC007 (motorbus sim)"});
    t.push_back({0x1009, 0, "Manufacturer hardware version", STR, CONST, false, Storage::Const, 0, none, none,
                 nullptr, "HW1.0"});
    t.push_back({0x100A, 0, "Manufacturer software version", STR, CONST, false, Storage::Const, 0, none, none,
                 nullptr, "SW1.0"});
    t.push_back({0x1014, 0, "COB-ID EMCY", U32, RO, false, ROM, 0x80, none, none, nullptr, nullptr,
                 "$NODEID+0x80", 0x80});
    var(0x1015, "Inhibit time EMCY", U16, RW, false, ROM, 0);
    mem(0x1016, 0, "Consumer heartbeat time", "Number of entries", U8, RO, false, ROM, 3);
    for (std::uint8_t s = 1; s <= 3; ++s)
        mem(0x1016, s, "Consumer heartbeat time", "Consumer heartbeat time", U32, RW, false, ROM, 0);
    var(0x1017, "Producer heartbeat time", U16, RW, false, ROM, 0);
    mem(0x1018, 0, "Identity object", "Number of entries", U8, RO, false, Storage::Const, 4);
    mem(0x1018, 1, "Identity object", "Vendor-ID", U32, RO, false, Storage::Const, 0);
    mem(0x1018, 2, "Identity object", "Product code", U32, RO, false, Storage::Const, 0);
    mem(0x1018, 3, "Identity object", "Revision number", U32, RO, false, Storage::Const, 0);
    mem(0x1018, 4, "Identity object", "Serial number", U32, RO, false, Storage::Const, 0);
    mem(0x1200, 0, "Server SDO parameter", "Number of entries", U8, RO, false, Storage::Const, 3);
    t.push_back({0x1200, 1, "COB-ID client to server", U32, RO, false, ROM, 0x600, none, none,
                 "Server SDO parameter", nullptr, "$NODEID+0x600", 0x600});
    t.push_back({0x1200, 2, "COB-ID server to client", U32, RO, false, ROM, 0x580, none, none,
                 "Server SDO parameter", nullptr, "$NODEID+0x580", 0x580});
    mem(0x1200, 3, "Server SDO parameter", "Node-ID of the SDO client", U32, RW, false, ROM, 0);
    mem(0x1280, 0, "Client SDO parameter", "Number of entries", U8, RO, false, RAM, 3);
    mem(0x1280, 1, "Client SDO parameter", "COB-ID client to server", U32, RW, false, RAM, 0x80000000);
    mem(0x1280, 2, "Client SDO parameter", "COB-ID server to client", U32, RW, false, RAM, 0x80000000);
    mem(0x1280, 3, "Client SDO parameter", "Node-ID of the SDO server", U32, RW, false, RAM, 0);
    // PDO communication and mapping (4 RPDO + 4 TPDO, B-P31..B-P35).  Defaults [P]:
    // predefined COB-IDs valid, type 255, nothing mapped.
    static const char* const rpdo_comm[] = {"RPDO1 communication parameter", "RPDO2 communication parameter",
                                            "RPDO3 communication parameter", "RPDO4 communication parameter"};
    static const char* const rpdo_map[] = {"RPDO1 mapping parameter", "RPDO2 mapping parameter",
                                           "RPDO3 mapping parameter", "RPDO4 mapping parameter"};
    static const char* const tpdo_comm[] = {"TPDO1 communication parameter", "TPDO2 communication parameter",
                                            "TPDO3 communication parameter", "TPDO4 communication parameter"};
    static const char* const tpdo_map[] = {"TPDO1 mapping parameter", "TPDO2 mapping parameter",
                                           "TPDO3 mapping parameter", "TPDO4 mapping parameter"};
    static const char* const rpdo_expr[] = {"$NODEID+0x200", "$NODEID+0x300", "$NODEID+0x400", "$NODEID+0x500"};
    static const char* const tpdo_expr[] = {"$NODEID+0x180", "$NODEID+0x280", "$NODEID+0x380", "$NODEID+0x480"};
    static const char* const entry_names[] = {"Mapped object 1", "Mapped object 2", "Mapped object 3",
                                              "Mapped object 4", "Mapped object 5", "Mapped object 6",
                                              "Mapped object 7", "Mapped object 8"};
    auto comm = [&](std::uint16_t idx, const char* parent, const char* expr, std::int64_t base) {
        mem(idx, 0, parent, "Highest sub-index supported", U8, RO, false, ROM, 5);
        t.push_back({idx, 1, "COB-ID", U32, RW, false, ROM, base, none, none, parent, nullptr, expr, base});
        mem(idx, 2, parent, "Transmission type", U8, RW, false, ROM, 255);
        mem(idx, 3, parent, "Inhibit time", U16, RW, false, ROM, 0);
        mem(idx, 4, parent, "Compatibility entry", U8, RW, false, ROM, 0);
        mem(idx, 5, parent, "Event timer", U16, RW, false, ROM, 0);
    };
    auto map = [&](std::uint16_t idx, const char* parent) {
        mem(idx, 0, parent, "Number of mapped objects", U8, RW, false, ROM, 0);  // > 8: 06040042 (PDO engine)
        for (std::uint8_t s = 1; s <= 8; ++s) mem(idx, s, parent, entry_names[s - 1], U32, RW, false, ROM, 0);
    };
    for (int k = 0; k < 4; ++k) comm(std::uint16_t(0x1400 + k), rpdo_comm[k], rpdo_expr[k], 0x200 + 0x100 * k);
    for (int k = 0; k < 4; ++k) map(std::uint16_t(0x1600 + k), rpdo_map[k]);
    for (int k = 0; k < 4; ++k) comm(std::uint16_t(0x1800 + k), tpdo_comm[k], tpdo_expr[k], 0x180 + 0x100 * k);
    for (int k = 0; k < 4; ++k) map(std::uint16_t(0x1A00 + k), tpdo_map[k]);

    // ---- manufacturer / device area (spec §1.3) ----
    var(0x2002, "Node ID", U8, RW, false, ROM, 5, 1, 127);
    var(0x2003, "Baud rate", U8, RW, false, ROM, 4, 0, 8);
    var(0x2007, "System control", U8, RW, false, RAM, 0);
    var(0x6000, "Error status", U8, RW, true, RAM, 0);
    var(0x6001, "Controller status", U8, RW, true, RAM, 0);
    var(0x6002, "Rotation direction", U8, RW, false, RAM, 0, 0, 1);
    var(0x6003, "Maximum speed", S32, RW, false, RAM, 0, -32000, 32000);
    var(0x6004, "Step command", U32, RW, false, RAM, 0);
    var(0x6005, "Operation mode", U8, RW, false, RAM, 0, 0, 1);
    var(0x6006, "Start speed", U16, RW, false, ROM, 400);
    var(0x6007, "Stop speed", U16, RW, false, ROM, 0);
    var(0x6008, "Acceleration coefficient", U8, RW, false, ROM, 0, 0, 8);
    var(0x6009, "Deceleration coefficient", U8, RW, false, ROM, 0, 0, 8);
    var(0x600A, "Microstepping", U16, RW, false, ROM, 0);  // a set (06090030), not a range
    var(0x600B, "Maximum phase current", U16, RW, false, ROM, 0, 0, 6000);
    var(0x600C, "Motor position", S32, RW, true, RAM, 0);
    var(0x600D, "Current attenuation coefficient", U8, RW, false, ROM, 0, 0, 3);
    var(0x600E, "Motor enable", U8, RW, false, RAM, 1, 0, 1);
    mem(0x600F, 0, "External emergency stop", "Number of entries", U8, RO, false, Storage::Const, 2);
    mem(0x600F, 1, "External emergency stop", "Enable", U8, RW, false, ROM, 0);
    mem(0x600F, 2, "External emergency stop", "Trigger mode", U8, RW, false, ROM, 0);
    var(0x6010, "Object 6010h", U8, RW, false, ROM, 0);
    mem(0x6011, 0, "GPIO parameters", "Number of entries", U8, RO, false, Storage::Const, 2);
    mem(0x6011, 1, "GPIO parameters", "Direction", U16, RW, false, ROM, 0);
    mem(0x6011, 2, "GPIO parameters", "Configuration", U32, RW, false, ROM, 0, 0, 0x3FFFFF);
    var(0x6012, "GPIO value", U16, RW, true, RAM, 0);
    mem(0x6013, 0, "OCP parameters", "Number of entries", U8, RO, false, Storage::Const, 2);
    mem(0x6013, 1, "OCP parameters", "OCT1", U8, RW, false, ROM, 0);
    mem(0x6013, 2, "OCP parameters", "OCD1", U8, RW, false, ROM, 0);
    var(0x6017, "Stall detection parameters", U16, RW, false, ROM, 0);
    mem(0x6018, 0, "Offline programming parameter 1", "Number of entries", U8, RO, false, Storage::Const, 2);
    mem(0x6018, 1, "Offline programming parameter 1", "Number of offline commands", U8, RW, false, ROM, 0, 0,
        100);
    mem(0x6018, 2, "Offline programming parameter 1", "Offline automatic operation", U8, RW, false, ROM, 0, 0, 1);
    mem(0x6019, 0, "Offline programming parameter 2", "Number of entries", U8, RO, false, Storage::Const, 5);
    mem(0x6019, 1, "Offline programming parameter 2", "Program pointer", U8, RW, false, RAM, 0, 0, 100);
    mem(0x6019, 2, "Offline programming parameter 2", "Offline command", U32, RW, false, RAM, 0);
    mem(0x6019, 3, "Offline programming parameter 2", "Save offline commands", U8, RW, false, RAM, 0, 0, 1);
    mem(0x6019, 4, "Offline programming parameter 2", "GPIO mask", U16, RW, false, RAM, 0);
    mem(0x6019, 5, "Offline programming parameter 2", "Run command", U16, RW, false, RAM, 0, 0, 1);
    var(0x601A, "External stop stabilize delay", U16, RW, false, ROM, 100, 0, 200);
    var(0x601B, "Stall set", U8, RW, false, ROM, 0, 0, 1);
    var(0x601C, "Absolute displacement command", S32, RW, false, RAM, 0, -2147483647, 2147483647);
    var(0x6020, "Stop stepping command", U8, RW, false, RAM, 0);  // 0 only (06090030)
    t.back().alt_size = 4;  // [D] App.1 UNSIGNED8, §4.5.7 UNSIGNED32: both accepted
    var(0x6021, "Encoder CPR", U16, RW, false, ROM, 500);
    var(0x6022, "Position save value", S32, RO, false, ROM, 0);
    var(0x6023, "Closed-loop KP", U8, RW, false, ROM, 48, 1, 255);
    var(0x6024, "Closed-loop KI", U8, RW, false, ROM, 48, 1, 255);
    var(0x6025, "Closed-loop KD", U8, RW, false, ROM, 32, 1, 255);
    var(0x6026, "Closed-loop filter 1", U8, RW, false, ROM, 8, 1, 128);
    var(0x6027, "Closed-loop filter 2", U16, RW, false, ROM, 8, 1, 255);
    var(0x6028, "Closed-loop stall length", U16, RW, false, ROM, 64, 1, 255);
    var(0x6029, "Torque loop enable", U8, RW, false, ROM, 1, 0, 1);
    var(0x602A, "Power-off auto save", U8, RW, false, ROM, 0, 0, 1);
    return t;
}
}  // namespace

const std::vector<OdRow>& od_rows() {
    static const std::vector<OdRow> rows = make_rows();
    return rows;
}

const OdRow* od_row(std::uint16_t index, std::uint8_t sub) {
    for (const auto& r : od_rows())
        if (r.index == index && r.sub == sub) return &r;
    return nullptr;
}

std::shared_ptr<canopen::ObjectDictionary> build_pmc007_od(std::uint8_t node_id, const Identity& identity) {
    if (node_id == 0 || node_id > 127) throw InvalidArgument("pmc007: node-ID must be 1..127");
    auto od = std::make_shared<canopen::ObjectDictionary>();
    od->set_node_id(node_id);
    auto& info = od->device_info();
    info.file_name = "pmc007.eds";
    info.description = "CQPUSI PMC007xx integrated stepper controller, CANopen CiA 301 (motorbus)";
    info.vendor_name = "CQPUSI";
    info.product_name = "PMC007";
    info.baud_rates_kbit = {20, 25, 50, 100, 125, 250, 500, 800, 1000};
    info.nr_rx_pdo = 4;
    info.nr_tx_pdo = 4;
    std::map<std::uint16_t, bool> made;
    for (const auto& r : od_rows()) {
        canopen::VariableSpec spec;
        spec.index = r.index;
        spec.subindex = r.sub;
        spec.name = r.name;
        spec.type = r.type;
        spec.access = r.access;
        spec.pdo_mappable = r.pdo;
        const bool is_signed = r.type == DataType::Integer32;
        if (r.low) spec.low_limit = is_signed ? canopen::Scalar{*r.low} : canopen::Scalar{std::uint64_t(*r.low)};
        if (r.high)
            spec.high_limit = is_signed ? canopen::Scalar{*r.high} : canopen::Scalar{std::uint64_t(*r.high)};
        if (r.text) {
            spec.default_value = canopen::Bytes(r.text, r.text + std::char_traits<char>::length(r.text));
        } else {
            std::int64_t d = r.node_offset >= 0 ? r.node_offset + node_id : r.def;
            if (r.index == 0x1018 && r.sub >= 1 && r.sub <= 4) {
                const std::uint32_t ids[] = {identity.vendor_id, identity.product_code, identity.revision,
                                             identity.serial};
                d = ids[r.sub - 1];
            }
            if (is_signed)
                spec.default_value = d;
            else
                spec.default_value = std::uint64_t(d);
        }
        if (r.expr) spec.default_expr = r.expr;
        spec.alt_size = r.alt_size;
        if (r.parent) {
            if (!made[r.index]) {
                const bool array = r.index == 0x1003 || r.index == 0x1016 || (r.index >= 0x1600 && r.index <= 0x1603) ||
                                   (r.index >= 0x1A00 && r.index <= 0x1A03);
                od->add_record(r.index, r.parent, array ? canopen::ObjectCode::Array : canopen::ObjectCode::Record);
                made[r.index] = true;
            }
            od->add_member(r.index, spec);
        } else {
            od->add_variable(spec);
        }
    }
    return od;
}

std::string eds() {
    auto od = build_pmc007_od(5);
    return canopen::to_eds(*od);
}

}  // namespace motorbus::pmc007

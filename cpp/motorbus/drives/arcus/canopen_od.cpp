#include "motorbus/drives/arcus/canopen_od.hpp"

#include <cstdio>
#include <set>
#include <string>

#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::arcus {
namespace {

// A table number as the dictionary stores it: negative ones signed, the rest unsigned.
canopen::Scalar scalar(std::int64_t v) {
    return v < 0 ? canopen::Scalar{v} : canopen::Scalar{static_cast<std::uint64_t>(v)};
}

std::string record_name(std::uint16_t index) {
    switch (index) {
        case 0x1018: return "Identity";
        case 0x2001: return "StepNLoop parameters";
        case 0x2004: return "Driver settings";
        case 0x2009: return "Latch positions";
        case 0x6099: return "Homing speeds";
    }
    char name[8];
    std::snprintf(name, sizeof name, "0x%04X", index);
    return name;
}

}  // namespace

std::shared_ptr<canopen::ObjectDictionary> canopen_object_dictionary() {
    auto od = std::make_shared<canopen::ObjectDictionary>();
    std::set<std::uint16_t> records;
    for (const auto& o : canopen_objects())
        if (o.sub != 0) records.insert(o.index);
    for (auto index : records) od->add_record(index, record_name(index));
    for (const auto& o : canopen_objects()) {
        if (records.count(o.index) && o.sub == 0) continue;  // the record's own sub 0
        canopen::VariableSpec spec;
        spec.index = o.index;
        spec.subindex = o.sub;
        spec.name = o.name;
        auto type = canopen::data_type_from_name(o.type);
        auto access = canopen::access_from_name(o.access);
        if (!type || !access) throw InvalidArgument(std::string("arcus: Table 10.1 row '") + o.name + "' is malformed");
        spec.type = *type;
        spec.access = *access;
        if (spec.type == canopen::DataType::VisibleString) {
            spec.default_value = canopen::Bytes{'D', 'M', 'C'};
        } else {
            std::visit([&](auto x) { spec.default_value = x; }, scalar(o.default_value));
            if (canopen::writable(spec.access)) {
                spec.low_limit = scalar(o.low);
                spec.high_limit = scalar(o.high);
            }
        }
        if (records.count(o.index))
            od->add_member(o.index, spec);
        else
            od->add_variable(spec);
    }
    return od;
}

}  // namespace motorbus::arcus

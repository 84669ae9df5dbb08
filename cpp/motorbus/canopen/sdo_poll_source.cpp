#include "motorbus/canopen/sdo_poll_source.hpp"

#include <algorithm>
#include <cctype>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

SdoPollSource::SdoPollSource(SdoClient& sdo, std::vector<SdoPollObject> objects)
    : sdo_(sdo), objects_(std::move(objects)) {
    if (objects_.empty()) throw InvalidArgument("SDO poll source: at least one object");
    for (auto& o : objects_) {
        std::string t = o.type;
        std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
        static const std::pair<const char*, Kind> names[] = {
            {"i8", Kind::I8},   {"i16", Kind::I16}, {"i32", Kind::I32}, {"i64", Kind::I64}, {"u8", Kind::U8},
            {"u16", Kind::U16}, {"u32", Kind::U32}, {"u64", Kind::U64}, {"f32", Kind::F32}, {"f64", Kind::F64}};
        auto it = std::find_if(std::begin(names), std::end(names), [&](const auto& p) { return t == p.first; });
        if (it == std::end(names))
            throw InvalidArgument("SDO poll object type '" + o.type + "': one of i8 i16 i32 i64 u8 u16 u32 u64 f32 f64");
        kinds_.push_back(it->second);
    }
}

void SdoPollSource::read(double* out) {
    for (std::size_t i = 0; i < objects_.size(); ++i) {
        const auto idx = objects_[i].index;
        const auto sub = objects_[i].subindex;
        switch (kinds_[i]) {
            case Kind::I8: out[i] = sdo_.read_i8(idx, sub); break;
            case Kind::I16: out[i] = sdo_.read_i16(idx, sub); break;
            case Kind::I32: out[i] = sdo_.read_i32(idx, sub); break;
            case Kind::I64: out[i] = static_cast<double>(sdo_.read_i64(idx, sub)); break;
            case Kind::U8: out[i] = sdo_.read_u8(idx, sub); break;
            case Kind::U16: out[i] = sdo_.read_u16(idx, sub); break;
            case Kind::U32: out[i] = sdo_.read_u32(idx, sub); break;
            case Kind::U64: out[i] = static_cast<double>(sdo_.read_u64(idx, sub)); break;
            case Kind::F32: out[i] = sdo_.read_f32(idx, sub); break;
            case Kind::F64: out[i] = sdo_.read_f64(idx, sub); break;
        }
    }
}

std::string SdoPollSource::describe() const { return "SDO node " + std::to_string(sdo_.node_id()); }

}  // namespace motorbus::canopen

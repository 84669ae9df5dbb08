// A poll source that reads CANopen objects by expedited SDO upload, one per
// field, through the drive's own SdoClient (shared with the Drive: the client
// serializes transfers, so the poll thread and a commanding thread take turns).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/poll/source.hpp"

namespace motorbus::canopen {

// The object's type as written in the OD tables: "i8", "i16", "i32", "i64",
// "u8", "u16", "u32", "u64", "f32", "f64" (case-insensitive).
struct SdoPollObject {
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    std::string type = "i32";
};

class SdoPollSource final : public poll::Source {
public:
    // `sdo` must outlive the source (the bindings keep it alive).  InvalidArgument
    // for an empty list or an unknown type.
    SdoPollSource(SdoClient& sdo, std::vector<SdoPollObject> objects);

    std::size_t columns() const override { return objects_.size(); }
    void read(double* out) override;
    std::string describe() const override;

private:
    enum class Kind { I8, I16, I32, I64, U8, U16, U32, U64, F32, F64 };
    SdoClient& sdo_;
    std::vector<SdoPollObject> objects_;
    std::vector<Kind> kinds_;
};

}  // namespace motorbus::canopen

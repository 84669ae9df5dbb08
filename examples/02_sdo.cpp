// 02: SDO client against a LocalNode on a virtual bus: expedited and segmented
// transfers, a typed read and write, and the abort a server sends for a value
// out of range.
#include <cstdio>
#include <string>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client.hpp"

using namespace motorbus;
using namespace motorbus::canopen;

int main() {
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x1008, .name = "Manufacturer device name", .type = DataType::VisibleString,
                      .access = Access::RO, .default_value = Bytes{'e', 'x', 'a', 'm', 'p', 'l', 'e'}});
    od->add_variable({.index = 0x2000, .name = "Offset", .type = DataType::Integer16,
                      .default_value = std::int64_t{-5}});
    od->add_variable({.index = 0x2003, .name = "Baud index", .type = DataType::Unsigned8,
                      .low_limit = std::uint64_t{0}, .high_limit = std::uint64_t{8},
                      .default_value = std::uint64_t{4}});

    auto device_bus = can::open_virtual("sdo-example"), host_bus = can::open_virtual("sdo-example");
    LocalNode node(*device_bus, 5, od);
    SdoClient sdo(*host_bus, 5);

    const std::string name = sdo.read_string(0x1008, 0);
    std::printf("name: %s\n", name.c_str());
    sdo.write_i16(0x2000, 0, -300);
    const std::int16_t offset = sdo.read_i16(0x2000, 0);
    std::printf("offset: %d served: %lld\n", offset, static_cast<long long>(od->at(0x2000, 0)->get_i64()));
    std::uint32_t refused = 0;
    try {
        sdo.write_u8(0x2003, 0, 9);  // above the high limit
    } catch (const SdoAbortError& e) {
        refused = e.code;
        std::printf("refused: 0x%08X\n", e.code);
    }
    node.close();
    // ctest runs this example: any value other than the expected one fails it.
    return name == "example" && offset == -300 && refused == 0x06090031 ? 0 : 1;
}

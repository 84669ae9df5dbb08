// Fuzz the EDS/DCF parser: any text either parses (possibly with warnings)
// or throws InvalidArgument; an imported dictionary exports and re-imports.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "motorbus/canopen/eds.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::canopen;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view text(reinterpret_cast<const char*>(data), size);
    std::vector<std::string> warnings;
    try {
        auto od = parse_eds(text, {}, &warnings);
        auto again = parse_eds(to_eds(*od), {}, &warnings);
        (void)again;
    } catch (const InvalidArgument&) {
    }
    return 0;
}

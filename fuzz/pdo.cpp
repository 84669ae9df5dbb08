// Fuzz: PDO layouts and unpack on arbitrary bytes, and the PDO engine's
// parameter validation and frame handling on arbitrary SDO writes and frames.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/pdo_engine.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::canopen;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 2) return 0;
    // 1) A layout from the first bytes, unpacking the rest.
    const std::size_t n = data[0] % 12;
    std::vector<PdoMapEntry> entries;
    for (std::size_t k = 0; k < n && 1 + k < size; ++k)
        entries.push_back({0x2000, static_cast<std::uint8_t>(k), static_cast<std::uint8_t>(data[1 + k] % 70), false});
    try {
        PdoLayout l(entries);
        std::uint64_t v[PdoLayout::kMaxEntries];
        const std::size_t off = 1 + n;
        if (off <= size && l.unpack(data + off, size - off, v)) {
            std::uint8_t out[8];
            l.pack(v, out);
            for (std::size_t k = 0; k < l.size(); ++k) (void)l.to_signed(k, v[k]);
        }
    } catch (const InvalidArgument&) {
    }

    // 2) The engine: writes to 0x1400-0x1BFF and frames, interleaved.
    SimClock clock(0);
    PdoObjectTable od;
    od.add(0x6040, 0, {16, false, true, 0});
    od.add(0x6041, 0, {16, true, false, 0x237});
    od.add(0x607A, 0, {32, true, true, 0});
    od.add(0x2001, 0, {8, true, true, 0});
    PdoEngineOptions o;
    o.node_id = 5;
    o.strict = data[0] & 0x80;
    o.sync_window_us = data[1];
    std::size_t frames = 0;
    PdoEngine eng(od, clock, o, [&](const can::Frame&) { ++frames; }, [](std::uint16_t, bool) {});
    std::size_t i = 2;
    while (i + 4 <= size) {
        const std::uint8_t op = data[i];
        if (op & 1) {
            static const std::uint16_t bases[] = {0x1400, 0x1600, 0x1800, 0x1A00};
            const std::uint16_t index = static_cast<std::uint16_t>(bases[(op >> 1) & 3] + ((op >> 3) & 7));
            const std::uint8_t sub = data[i + 1] % 12;
            const std::size_t len = data[i + 2] % 6;
            i += 3;
            std::vector<std::uint8_t> d;
            for (std::size_t k = 0; k < len && i < size; ++k) d.push_back(data[i++]);
            eng.write(index, sub, d);
            std::vector<std::uint8_t> back;
            eng.read(index, sub, back);
        } else {
            can::Frame f;
            f.id = (std::uint32_t(data[i + 1]) << 3 | (data[i + 2] & 7)) & 0x7FF;
            f.rtr = op & 2;
            f.len = static_cast<std::uint8_t>(data[i + 3] % 9);
            i += 4;
            for (std::size_t k = 0; k < f.len && i < size; ++k) f.data[k] = data[i++];
            eng.on_frame(f);
            if (op & 4) eng.set_operational(!(op & 8));
            if (op & 16) eng.notify_change(0x6041, 0);
            clock.advance(Nanos(op) * 100'000);
            eng.process(clock.now());
        }
    }
    return 0;
}

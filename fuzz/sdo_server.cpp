// Fuzz the SDO server state machine: any sequence of request frames (any
// length 0..8) and timer ticks.  Invariants: bounded buffers, bounded output
// per frame, never more than one transfer's worth of memory.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "motorbus/canopen/sdo_server.hpp"

using namespace motorbus;
using namespace motorbus::canopen;

namespace {
std::shared_ptr<ObjectDictionary> make_od() {
    auto od = std::make_shared<ObjectDictionary>();
    od->set_max_variable_size(4096);
    od->add_variable({.index = 0x6001, .type = DataType::Unsigned8, .access = Access::RO,
                      .default_value = std::uint64_t{8}});
    od->add_variable({.index = 0x2003, .type = DataType::Unsigned8, .low_limit = std::uint64_t{0},
                      .high_limit = std::uint64_t{8}});
    od->add_variable({.index = 0x2004, .type = DataType::Integer64});
    od->add_variable({.index = 0x2005, .type = DataType::Unsigned16, .access = Access::WO});
    od->add_variable({.index = 0x1008, .type = DataType::VisibleString, .max_size = 40,
                      .default_value = Bytes(30, 'x')});
    od->add_variable({.index = 0x2201, .type = DataType::Domain, .default_value = Bytes(300, 0x55)});
    auto s = od->add_variable({.index = 0x2200, .type = DataType::Domain, .access = Access::RO});
    s->set_chunk_read_hook([](const Variable&, std::size_t off, std::size_t max, Bytes& c, bool& last) {
        if (off > 200) return abort_code::kCannotStore;
        c.assign(std::min<std::size_t>(max, 5), 0xAB);
        last = off > 100;
        return 0u;
    });
    od->add_record(0x1018, "Identity");
    od->add_member(0x1018, {.subindex = 1, .type = DataType::Unsigned32, .access = Access::RO});
    return od;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static auto od = make_od();
    SdoServerConfig cfg;
    cfg.block_size = size > 0 ? static_cast<std::uint8_t>(data[0] % 130) : 127;  // 0 and >127 clamp
    SdoServerMachine srv(*od, cfg);
    SdoServerMachine::Outbox out;
    Nanos now = 0;
    std::size_t i = size > 0 ? 1 : 0;
    while (i < size) {
        const std::uint8_t hdr = data[i++];
        if (hdr == 0xFF) {  // a tick far enough to fire every timer
            now += 2'000'000'000;
            out.clear();
            srv.on_timer(now, out);
            if (out.size() > 1) std::abort();
            continue;
        }
        now += (hdr >> 4) * 100'000'000;
        const std::size_t len = std::min<std::size_t>(hdr % 9, size - i);
        out.clear();
        srv.on_request(std::span(data + i, len), now, out);
        i += len;
        if (out.size() > 127) std::abort();
        if (srv.buffered() > 4096 + 4096 + 127 * 7 * 2) std::abort();
        if (srv.idle() && srv.buffered() != 0) std::abort();  // released when done
    }
    return 0;
}

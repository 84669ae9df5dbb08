// Fuzz: heartbeat decode, 0x1016 entry validation and the consumer on a loop bus.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "motorbus/can/external_bus.hpp"
#include "motorbus/canopen/heartbeat.hpp"

using namespace motorbus;


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static can::ExternalBus bus("fuzz", [](const can::Frame&, can::Deadline) {});
    SimClock clock(0);
    canopen::HeartbeatConsumer hc(bus, clock);
    hc.monitor(5, std::chrono::milliseconds(100));
    std::vector<std::uint32_t> entries(4, 0);
    std::size_t i = 0;
    while (i + 3 <= size) {
        can::Frame f;
        f.id = 0x700u | (data[i] & 0xFF);
        f.rtr = data[i + 1] & 0x80;
        f.len = static_cast<std::uint8_t>(data[i + 1] % 9);
        clock.advance(Nanos(data[i + 2]) * 1'000'000);
        i += 3;
        for (std::size_t k = 0; k < f.len && i < size; ++k) f.data[k] = data[i++];
        (void)canopen::decode_heartbeat(f);
        bus.feed(f);
        hc.process(clock.now());
        std::uint32_t v = 0;
        for (int k = 0; k < 4; ++k) v = (v << 8) | f.data[k];
        const std::size_t sub = 1 + (f.data[4] & 3);
        if (canopen::validate_consumer_entry(entries, sub, v) == 0) entries[sub - 1] = v;
        (void)canopen::decode_consumer_entry(v);
    }
    return 0;
}

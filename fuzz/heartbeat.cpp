// Fuzz: heartbeat decode, 0x1016 entry validation and the consumer on a loop bus.
//
// The bus, clock and consumer are built once (as in the EMCY target): a
// consumer per input cost a subscription and 128 node records each time, and
// libFuzzer's per-input leak scan then ran on every input (~2 000 exec/s).
// Each input starts by monitoring node 5 and ends by forgetting every node it
// touched, so inputs stay independent; the shared SimClock only moves forward,
// and the consumer works on times relative to each node's last heartbeat, so
// an input behaves the same whatever time it starts at.  The frames it fed
// are drained from the bus's receive queue afterwards, so everything an input
// allocates is freed before it returns and libFuzzer's leak check stays cheap
// (the per-input LeakSanitizer scans were most of the time).
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "motorbus/can/external_bus.hpp"
#include "motorbus/canopen/heartbeat.hpp"

using namespace motorbus;

namespace {
// Frames looked at per input: a longer input adds run time (every frame runs
// the consumer's deadline check), not new states.
constexpr std::size_t kMaxFrames = 128;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static can::ExternalBus bus("fuzz", [](const can::Frame&, can::Deadline) {});
    static SimClock clock(0);
    static canopen::HeartbeatConsumer hc(bus, clock);
    hc.monitor(5, std::chrono::milliseconds(100));
    std::array<bool, 128> touched{};
    touched[5] = true;
    std::array<std::uint32_t, 4> entries{};
    std::vector<std::uint32_t> entry_table(entries.begin(), entries.end());
    std::size_t i = 0;
    std::size_t frames = 0;
    while (i + 3 <= size && frames++ < kMaxFrames) {
        can::Frame f;
        f.id = 0x700u | (data[i] & 0xFF);
        touched[data[i] & 0x7F] = true;
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
        if (canopen::validate_consumer_entry(entry_table, sub, v) == 0) entry_table[sub - 1] = v;
        (void)canopen::decode_consumer_entry(v);
    }
    for (std::size_t n = 1; n < touched.size(); ++n)
        if (touched[n]) hc.forget(static_cast<std::uint8_t>(n));
    // Nobody calls recv() here: empty the bus's receive queue too (as in the
    // EMCY target), or it grows for 65536 frames and every input that
    // allocates more than it frees costs a full LeakSanitizer scan.
    while (!bus.recv_many(4096, std::chrono::nanoseconds(0)).empty()) {
    }
    return 0;
}

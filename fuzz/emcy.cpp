// Fuzz: EMCY decode and the consumer's bounded history.
#include <cstddef>
#include <cstdint>

#include "motorbus/can/external_bus.hpp"
#include "motorbus/canopen/emcy.hpp"

using namespace motorbus;


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static can::ExternalBus bus("fuzz", [](const can::Frame&, can::Deadline) {});
    canopen::EmcyConsumer consumer(bus, 4);
    std::size_t i = 0;
    while (i + 2 <= size) {
        can::Frame f;
        f.id = 0x080u | (data[i] & 0x7F);
        f.flags = data[i] & 0x80 ? can::kFlagFd : 0;
        f.len = static_cast<std::uint8_t>(data[i + 1] % 65);
        i += 2;
        for (std::size_t k = 0; k < f.len && i < size; ++k) f.data[k] = data[i++];
        if (auto m = canopen::decode_emcy(f)) (void)canopen::emcy_code_text(m->code);
        bus.feed(f);
    }
    (void)consumer.wait(0, std::chrono::nanoseconds(0));
    return 0;
}

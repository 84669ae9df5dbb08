// libFuzzer target for the UNITEK codec: any bytes as a frame in both directions.
// Properties: decoding throws nothing but FrameError (whose byte index is within
// 0..8), never reads past the input (ASan), and whatever decodes re-encodes to the
// same leading bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "motorbus/drives/unitek/codec.hpp"

using namespace motorbus::unitek;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // Exactly `size` bytes on the heap, so a read past the frame is caught.
    std::vector<std::uint8_t> frame(data, data + size);
    const std::span<const std::uint8_t> in(frame.data(), frame.size());
    try {
        const auto t = decode_to_drive(in);
        const auto again = encode_write(t.regid, static_cast<std::int64_t>(t.value), t.value_bits);
        for (std::size_t i = 0; i < again.size(); ++i)
            if (again[i] != frame[i]) std::abort();
    } catch (const FrameError& e) {
        if (e.byte < 0 || e.byte > 8 || (size >= 3 && size <= 8)) std::abort();
    }
    try {
        const auto f = decode_from_drive(in);
        const auto again = encode_reply(f.regid, f.value, f.value_bits, frame[size - 1]);
        if (again != frame) std::abort();
        static const RegisterTable table = RegisterTable::builtin();
        if (const Register* r = table.find(f.regid)) (void)r->from_raw(f.value, f.value_bits);
    } catch (const FrameError& e) {
        if (e.byte < 0 || e.byte > 8 || (size == 4 || size == 6)) std::abort();
    }
    return 0;
}

// libFuzzer target for the UNITEK simulator's frame handling.  The input is a
// sequence of records: [id selector][dlc][dlc bytes][clock step]; the sim's clock
// advances between frames so cyclic transmissions, events and motion run too.
// Properties: on_frame/service never throw, every frame the sim sends is on its
// transmit id with DLC 4 or 6, at most 8 registers are ever cyclic, and a read
// of KERN_STATUS on the (possibly moved) receive id still answers afterwards.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "motorbus/drives/unitek/sim.hpp"

using namespace motorbus;
using namespace motorbus::unitek;

namespace {
// Frames looked at per input: with up to 64 ms between frames a longer input
// adds cyclic transmissions and motion, not new states.
constexpr std::size_t kMaxFrames = 64;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // The register table is built once: building it per input (a few hundred
    // named registers) was a fifth of the run time.  The sim gets a copy.
    static const RegisterTable table = sim_default_table();
    SimClock clock;
    Sim sim(clock, {}, table);
    std::size_t sent = 0;
    bool bad = false;
    sim.set_output([&](const can::Frame& f) {
        ++sent;
        if (f.id != sim.tx_id() || (f.len != 4 && f.len != 6)) bad = true;
    });
    std::size_t i = 0;
    std::size_t frames = 0;
    while (i + 2 <= size && frames < kMaxFrames) {
        const std::uint8_t sel = data[i++];
        const std::size_t dlc = data[i++] % 9;
        if (i + dlc > size) break;
        // Mostly the current receive id, sometimes another node's.
        const std::uint32_t id = (sel & 0x80) ? 0x200u + (sel & 0x7F) : sim.rx_id();
        sim.on_frame(can::Frame::make(id, {data + i, dlc}));
        i += dlc;
        ++frames;
        if (i < size) clock.advance(static_cast<Nanos>(data[i++]) * 250'000);  // 0..64 ms
        // Bound the work of one input: cyclic frames due by now.
        sim.service();
        if (sim.cyclic().size() > 8 || bad) std::abort();
        if (sent > 200000) break;
    }
    const std::size_t before = sent;
    const std::uint8_t read_status[3] = {0x3D, 0x40, 0x00};
    sim.on_frame(can::Frame::make(sim.rx_id(), read_status));
    if (sent != before + 1 || bad) std::abort();
    return 0;
}

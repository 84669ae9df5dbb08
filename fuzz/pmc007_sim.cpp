// Fuzz target: the PMC007 simulator's request handling.  Each 8-byte record is
// one SDO-level access to its dictionary (index, sub, up to 4 data bytes, and an
// operation byte: read, write of 1/2/4 bytes, input edge, jam, error, time step
// or power cycle),
// applied through the same remote_read/remote_write path the SDO server and the
// RPDOs use, with simulated time advancing between records.  The device must
// never throw, crash or hang, and its invariants hold (busy only while moving,
// 6001h bit 3 = busy, 6011h:01 bits 7-10 read 0).
//
// The sim is built once and brought back to its newly-built state per input
// (reset_to_new(), on a clock set back to the same start time): building its
// dictionary per input was nearly all the cost (~200 exec/s).  Every input thus
// starts from the same state and time as on a fresh sim, so a crash reproduces
// alone (a power cycle is one of the operations: run after every input it
// doubled the cost of one).  The motor model integrates in 1 ms steps instead
// of the default 100 us (a record may advance 1.275 s of acceleration); switch
// edges and move ends are still found at their own instant inside a step.
#include <cstddef>
#include <cstdint>
#include <span>

#include "motorbus/drives/pmc007/sim.hpp"

using namespace motorbus;
using namespace motorbus::pmc007;

namespace {
constexpr Nanos kStart = 1'000'000'000;
// Records looked at per input: a longer input adds run time, not new states
// (each record may already advance 1.275 s).
constexpr std::size_t kMaxRecords = 128;

// A simulated clock that can be set back to the start for the next input
// (SimClock never moves backwards).  Single-threaded: the sim is not attached.
class RewindableClock final : public Clock {
public:
    Nanos now() const override { return now_; }
    bool sleep_until(Nanos t) override {
        // Nobody else advances it: a SimClock would block here for ever (a hang).
        if (t > now_) __builtin_trap();
        return true;
    }
    void cancel() override {}
    bool simulated() const override { return true; }
    void advance(Nanos dt) { now_ += dt; }
    void rewind() { now_ = kStart; }

private:
    Nanos now_ = kStart;
};

SimOptions options() {
    SimOptions o;
    o.ext1_switch = std::make_pair(-1e6, -1000.0);
    o.tick_ns = 1'000'000;  // coarse steps keep long moves cheap (as in the Arcus and DMAC targets)
    return o;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static RewindableClock clock;
    static Sim sim(5, clock, options());
    clock.rewind();
    sim.reset_to_new();
    auto& od = sim.od();
    for (std::size_t i = 0; i + 8 <= size && i < kMaxRecords * 8; i += 8) {
        const std::uint8_t* r = data + i;
        const std::uint16_t index = static_cast<std::uint16_t>(r[0] | r[1] << 8);
        const std::uint8_t sub = r[2];
        const std::uint8_t op = r[3];
        switch (op % 8) {
            case 0: {
                canopen::VariablePtr v;
                if (od.lookup(index, sub, v) == 0) {
                    canopen::Bytes out;
                    (void)v->remote_read(out);
                }
                break;
            }
            case 1:
            case 2:
            case 3: {
                const std::size_t n = op % 8 == 1 ? 1 : op % 8 == 2 ? 2 : 4;
                canopen::VariablePtr v;
                if (od.lookup(index, sub, v) == 0) (void)v->remote_write(std::span<const std::uint8_t>(r + 4, n));
                break;
            }
            case 4: sim.set_input(r[4] % 11, r[5] & 1); break;
            case 5: sim.set_jammed(r[4] & 1); break;
            case 6: sim.inject_error(r[4]); break;
            case 7:
                if (r[4] & 1) sim.power_cycle();  // stored objects reloaded, 602Ah position kept
                break;
        }
        clock.advance(static_cast<Nanos>(r[7]) * 5'000'000);
        sim.poll();
        const bool busy = sim.busy();
        if (((sim.controller_status() & st::kBusy) != 0) != busy) __builtin_trap();
        if (od.at(0x6011, 1)->get_u64() & 0x780) __builtin_trap();
    }
    return 0;
}

// 09: a UNITEK servo on its REGID register protocol, simulated on a virtual bus
// with a simulated clock: writes (never acknowledged), a read, a cyclic register
// into the client's ring buffer, a position move with Tol.
#include <cstdio>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/drives/unitek/client.hpp"
#include "motorbus/drives/unitek/sim.hpp"

using namespace motorbus;
using namespace motorbus::unitek;

int main() {
    SimClock clock;
    auto sim_bus = can::open_virtual("unitek-example");
    auto bus = can::open_virtual("unitek-example");
    Sim sim(clock);
    sim.attach(sim_bus);
    ClientOptions o;
    o.clock = &clock;
    Client drive(*bus, sim_default_table(), o);

    std::printf("KERN_STATUS 0x%04llX\n", static_cast<unsigned long long>(drive.read(kRegStatus)));
    drive.write(kRegAccRamp, 1000);  // 35 E8 03 (example 6)
    std::printf("ACC_RAMP %lld ms\n", static_cast<long long>(drive.read(kRegAccRamp)));
    auto stream = drive.subscribe(kRegSpeedActual, 10);  // 3D 30 0A
    drive.write(kRegSpeedCmd, 3277);                      // 31 CD 0C: 10 % of N max
    drive.read(kRegStatus);                               // a read is the sync point for writes
    for (int ms = 0; ms < 200; ++ms) {
        clock.advance(1'000'000);
        sim.service();
        while (stream->ring.count() < sim.sent(kRegSpeedActual)) std::this_thread::yield();
    }
    Nanos t[64];
    std::int64_t v[64];
    std::uint64_t cursor = 0, lost = 0;
    const auto n = stream->ring.read(cursor, t, v, 64, lost);
    std::printf("stream 0x30: %zu samples, last period %.1f ms, lost %llu, speed %lld num\n", n,
                (t[n - 1] - t[n - 2]) / 1e6, static_cast<unsigned long long>(lost), static_cast<long long>(v[n - 1]));
    drive.unsubscribe(kRegSpeedActual);
    drive.write(kRegPosDest, 65536);  // one revolution
    drive.read(kRegStatus);
    for (int ms = 0; ms < 2000; ++ms) {
        clock.advance(1'000'000);
        sim.service();
    }
    std::printf("position %lld num, Tol %d\n", static_cast<long long>(drive.read(kRegPosActual)),
                (drive.read(kRegStatus) & kStatusTol) ? 1 : 0);
    drive.close();
    sim.close();
    return 0;
}

// 04: two Midi DMAC simulators on one pty line (one SimClock), and the C++
// client streaming an interpolated path to both: a quarter circle of radius
// 10000 increments as 40 segments of 50 ms.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "motorbus/drives/dmac/client.hpp"
#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/serial/line_server.hpp"

using namespace motorbus;

int main() {
    auto clock = std::make_shared<SimClock>();
    dmac::SimOptions o0, o1;
    o1.address = 1;
    auto a = std::make_shared<dmac::Sim>(clock, o0);
    auto b = std::make_shared<dmac::Sim>(clock, o1);
    serial::PtyLineServer server({a, b});
    auto link = std::make_shared<serial::LineLink>(serial::open_port(server.slave_path(), 0),
                                                   dmac::default_line_options());
    // Waits (back-pressure) advance the simulated time instead of sleeping.
    auto sleep = [&](dmac::Duration d) { clock->advance(d.count()); };
    dmac::ClientOptions c0, c1;
    c0.sleep = c1.sleep = sleep;
    c1.address = 1;
    dmac::Client x(link, c0), y(link, c1);
    x.brake(false);  // DMAC34: the factory brake is ON (annex 7.1)
    y.brake(false);

    std::vector<std::vector<long long>> segments;
    long long px = 10000, py = 0;
    for (int k = 1; k <= 40; ++k) {
        const double t = M_PI / 2 * k / 40;
        const long long nx = std::llround(10000 * std::cos(t)), ny = std::llround(10000 * std::sin(t));
        segments.push_back({nx - px, ny - py});
        px = nx;
        py = ny;
    }
    dmac::StreamOptions so;
    so.interpol_time_ms = 50;
    so.fifo_size = 16;
    so.sleep = sleep;
    const auto stats = dmac::stream_interpolation({&x, &y}, segments, so);
    std::printf("segments %zu underruns %llu\n", stats.segments, static_cast<unsigned long long>(stats.underruns));
    clock->advance(3'000'000'000);
    const int ex = x.position(), ey = y.position();
    std::printf("x %d y %d\n", ex, ey);
    server.close();
    return (ex == -10000 && ey == 10000 && stats.underruns == 0) ? 0 : 1;
}

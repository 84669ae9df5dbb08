// Virtual bus from C++: throughput, one-way latency, and the wire-time mode's
// frame rate against theory.  Prints one JSON object per measurement.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "motorbus/can/virtual_bus.hpp"

using namespace motorbus;
using namespace motorbus::can;
using namespace std::chrono_literals;

static double secs_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 200000;
    const std::vector<std::uint8_t> payload{1, 2, 3, 4, 5, 6, 7, 8};
    const Frame f = Frame::make(0x123, payload);

    {  // throughput: one sender thread, one recv() consumer
        auto tx = open_virtual("bench-tp"), rx = open_virtual("bench-tp");
        auto t0 = std::chrono::steady_clock::now();
        std::thread sender([&] {
            for (int i = 0; i < n; ++i) tx->send(f);
        });
        int got = 0;
        while (got < n && rx->recv(2s)) ++got;
        sender.join();
        const double dt = secs_since(t0);
        std::printf("{\"bench\": \"virtual_cpp_throughput\", \"frames\": %d, \"fps\": %.0f, \"dropped\": %llu}\n",
                    got, got / dt, (unsigned long long)rx->counters().rx_dropped);
    }
    {  // latency: send -> subscriber on the other endpoint, one frame at a time
        auto tx = open_virtual("bench-lat"), rx = open_virtual("bench-lat");
        std::atomic<Nanos> seen{0};
        rx->subscribe_id(0x123, false, [&](const Frame&) { seen.store(monotonic_ns()); });
        std::vector<double> lat;
        const int m = std::min(n, 20000);
        for (int i = 0; i < m; ++i) {
            seen.store(0);
            const Nanos t = monotonic_ns();
            tx->send(f);
            while (seen.load() == 0) std::this_thread::yield();
            lat.push_back((seen.load() - t) / 1e3);
        }
        std::sort(lat.begin(), lat.end());
        std::printf("{\"bench\": \"virtual_cpp_latency_us\", \"median\": %.2f, \"p99\": %.2f}\n",
                    lat[lat.size() / 2], lat[lat.size() * 99 / 100]);
    }
    {  // wire time at 1 Mbit/s: achieved frame rate vs 1e6 / 135 bits
        VirtualOptions o;
        o.bitrate = 1e6;
        o.tx_queue = 4096;
        auto tx = open_virtual("bench-wire", o), rx = open_virtual("bench-wire", o);
        const int m = 20000;
        std::thread sender([&] {
            for (int i = 0; i < m; ++i) tx->send(f, 5s);
        });
        Nanos first = 0, last = 0;
        int got = 0;
        auto t0 = std::chrono::steady_clock::now();
        while (got < m) {
            auto r = rx->recv(5s);
            if (!r) break;
            if (got == 0) first = r->timestamp_ns;
            last = r->timestamp_ns;
            ++got;
        }
        const double wall = secs_since(t0);
        sender.join();
        const double theory = 1e6 / wire_bits_worst_case(f);
        const double stamped = (got - 1) / ((last - first) / 1e9);
        const double observed = got / wall;
        std::printf("{\"bench\": \"virtual_wire_1mbit\", \"frames\": %d, \"theory_fps\": %.1f, "
                    "\"timestamp_fps\": %.1f, \"wall_fps\": %.1f, \"wall_error_pct\": %.3f}\n",
                    got, theory, stamped, observed, 100.0 * (observed - theory) / theory);
    }
    return 0;
}

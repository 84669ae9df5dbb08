// Request->reply round trips over a pty: LineLink (C++) against a PtyLineServer
// with an echo device, unthrottled and paced at 115200 baud.  The reference is
// a plain pyserial write/read_until loop against the SAME server in the same
// run (run as a python3 subprocess); ratios are printed.
//
//   ./build/h/bench_serial_roundtrip [iterations]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "bench_python.hpp"

#include "motorbus/serial/echo_device.hpp"
#include "motorbus/serial/line_server.hpp"
#include "motorbus/serial/port.hpp"

using namespace motorbus::serial;
using Clock = std::chrono::steady_clock;

namespace {
struct Stats {
    double per_s = 0, median_us = 0, p99_us = 0;
};

Stats summarize(std::vector<double> lat_us, double total_s) {
    std::sort(lat_us.begin(), lat_us.end());
    Stats s;
    s.per_s = static_cast<double>(lat_us.size()) / total_s;
    s.median_us = lat_us[lat_us.size() / 2];
    s.p99_us = lat_us[std::min(lat_us.size() - 1, lat_us.size() * 99 / 100)];
    return s;
}

Stats bench_link(const std::string& path, int n) {
    LineOptions o;
    o.reply_timeout = std::chrono::seconds(2);
    LineLink link(open_port(path, 115200), o);
    for (int i = 0; i < 50; ++i) link.transact("1PX");  // warm up
    std::vector<double> lat;
    lat.reserve(static_cast<std::size_t>(n));
    auto t0 = Clock::now();
    for (int i = 0; i < n; ++i) {
        auto a = Clock::now();
        std::string r = link.transact("1PX");
        if (r != "1PX") {
            std::fprintf(stderr, "bad reply\n");
            std::exit(1);
        }
        lat.push_back(std::chrono::duration<double, std::micro>(Clock::now() - a).count());
    }
    return summarize(lat, std::chrono::duration<double>(Clock::now() - t0).count());
}

// pyserial loop in a subprocess; prints "per_s median_us p99_us".
std::optional<Stats> bench_pyserial(const std::string& path, int n) {
    std::string script =
        "import serial,time,sys\n"
        "s=serial.Serial('" + path + "',115200,timeout=2)\n"
        "n=" + std::to_string(n) + "\n"
        "for _ in range(50):\n s.write(b'1PX\\r'); s.read_until(b'\\r\\n')\n"
        "lat=[]\nt0=time.perf_counter()\n"
        "for _ in range(n):\n a=time.perf_counter(); s.write(b'1PX\\r'); r=s.read_until(b'\\r\\n')\n"
        " assert r==b'1PX\\r\\n', r\n lat.append((time.perf_counter()-a)*1e6)\n"
        "tot=time.perf_counter()-t0\nlat.sort()\n"
        "print(n/tot, lat[len(lat)//2], lat[min(len(lat)-1, len(lat)*99//100)])\n";
    std::string cmd = motorbus_bench::python() + " -c \"$MB_SCRIPT\"";
    setenv("MB_SCRIPT", script.c_str(), 1);
    FILE* f = popen(cmd.c_str(), "r");
    if (!f) return std::nullopt;
    Stats s;
    int got = std::fscanf(f, "%lf %lf %lf", &s.per_s, &s.median_us, &s.p99_us);
    int rc = pclose(f);
    if (got != 3 || rc != 0) return std::nullopt;
    return s;
}

void report(const char* label, const Stats& ours, const std::optional<Stats>& ref) {
    std::printf("%-28s motorbus C++ LineLink: %9.0f rt/s  median %7.1f us  p99 %7.1f us\n", label, ours.per_s,
                ours.median_us, ours.p99_us);
    if (!ref) {
        std::printf("%-28s pyserial reference: unavailable (python3 + pyserial needed)\n", label);
        return;
    }
    std::printf("%-28s pyserial loop:         %9.0f rt/s  median %7.1f us  p99 %7.1f us\n", label, ref->per_s,
                ref->median_us, ref->p99_us);
    std::printf("%-28s ratio motorbus/pyserial: throughput x%.2f, median latency x%.2f (lower is better)\n",
                label, ours.per_s / ref->per_s, ours.median_us / ref->median_us);
}
}  // namespace

int main(int argc, char** argv) {
    int n = argc > 1 ? std::atoi(argv[1]) : 5000;
    if (n < 100) n = 100;
    for (unsigned baud : {0u, 115200u}) {
        int iters = baud ? std::min(n, 2000) : n;
        PtyLineServer server({std::make_shared<EchoLineDevice>()}, baud);
        Stats ours = bench_link(server.slave_path(), iters);
        auto ref = bench_pyserial(server.slave_path(), iters);
        std::string label = baud ? "paced 115200 baud" : "unthrottled pty";
        label += " (n=" + std::to_string(iters) + ")";
        report(label.c_str(), ours, ref);
        if (baud) {
            // 4 request + 5 reply bytes at 10 bits each: the wire floor.
            std::printf("%-28s wire floor: %.1f us per round trip\n", "", 9 * 10 * 1e6 / baud);
        }
    }
    return 0;
}

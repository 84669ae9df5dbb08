// DMAC command-to-reply round trip on a pty from C++: Client::read(#POSITION)
// against the simulator served by PtyLineServer, unthrottled and paced at
// 115200 baud.  The reference, in the same run and on the same server, is a
// plain pyserial loop (python3 subprocess) sending the same request.
//
//   ./build/h/bench_dmac_roundtrip [n=2000]
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "bench_python.hpp"

#include "motorbus/drives/dmac/client.hpp"
#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/serial/line_server.hpp"

using namespace motorbus;
using namespace motorbus::dmac;

namespace {

struct Stat {
    double median_us = 0, p99_us = 0;
};

Stat stat(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    Stat s;
    s.median_us = v[v.size() / 2] * 1e6;
    s.p99_us = v[std::max<std::size_t>(v.size() * 99 / 100, 1) - 1] * 1e6;
    return s;
}

Stat run_ours(const std::string& path, int n) {
    auto port = serial::open_port(path, 115200);
    auto opts = default_line_options();
    opts.reply_timeout = std::chrono::seconds(1);
    auto link = std::make_shared<serial::LineLink>(port, opts);
    Client c(link, {.address = 0});
    for (int i = 0; i < 50; ++i) c.position();
    std::vector<double> t;
    t.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        auto a = std::chrono::steady_clock::now();
        if (c.position() != 0) std::abort();
        t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
    }
    port->close();
    return stat(std::move(t));
}

// The pyserial loop prints "median_us p99_us".
bool run_pyserial(const std::string& path, int n, Stat& out) {
    std::string script =
        "import serial,time,statistics\n"
        "s=serial.Serial('" + path + "',115200,timeout=1.0)\n"
        "t=[]\n"
        "for i in range(50+" + std::to_string(n) + "):\n"
        "    a=time.perf_counter(); s.write(b'00READ #POSITION\\r'); r=s.read_until(b'\\r\\n')\n"
        "    assert r==b'00#POS=+0\\r\\n', r\n"
        "    if i>=50: t.append(time.perf_counter()-a)\n"
        "t.sort(); print(statistics.median(t)*1e6, t[int(len(t)*0.99)-1]*1e6)\n";
    std::string cmd = motorbus_bench::python() + " -c \"$DMAC_BENCH_SCRIPT\"";
    setenv("DMAC_BENCH_SCRIPT", script.c_str(), 1);
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return false;
    std::array<char, 256> buf{};
    bool ok = std::fgets(buf.data(), buf.size(), p) != nullptr &&
              std::sscanf(buf.data(), "%lf %lf", &out.median_us, &out.p99_us) == 2;
    return pclose(p) == 0 && ok;
}

}  // namespace

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::max(10, std::atoi(argv[1])) : 2000;
    std::printf("DMAC '00READ #POSITION' round trip from C++, %d requests each (median / p99, us)\n", n);
    for (unsigned baud : {0u, 115200u}) {
        auto sim = std::make_shared<Sim>(std::make_shared<RealClock>(), SimOptions{});
        serial::PtyLineServer server({sim}, baud);
        Stat ours = run_ours(server.slave_path(), n);
        Stat ref;
        const bool have_ref = run_pyserial(server.slave_path(), n, ref);
        std::printf("%20s: motorbus C++ dmac::Client %8.1f / %8.1f", baud ? "paced 115200 baud" : "unthrottled",
                    ours.median_us, ours.p99_us);
        if (have_ref)
            std::printf("   pyserial loop %8.1f / %8.1f   ratio (pyserial/motorbus, median) %5.2f\n", ref.median_us,
                        ref.p99_us, ref.median_us / ours.median_us);
        else
            std::printf("   pyserial loop unavailable\n");
    }
    return 0;
}

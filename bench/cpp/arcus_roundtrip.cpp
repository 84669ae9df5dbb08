// Command-to-reply round trip to the Arcus simulator on a pty: the C++ client
// (LineLink + Client) against a plain pyserial loop run in the same process
// tree on the same server, unthrottled and paced at 115200 baud.
//
//   ./build/h/bench_arcus_roundtrip [iterations]
// Prints one line per case and the ratio pyserial / motorbus (higher = faster).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "bench_python.hpp"

#include "motorbus/drives/arcus/client.hpp"
#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/serial/line_server.hpp"

using namespace motorbus;
using Clk = std::chrono::steady_clock;

namespace {

struct Stats {
    double mean_us, p50_us, p99_us;
};

Stats stats(std::vector<double> us) {
    std::sort(us.begin(), us.end());
    double sum = 0;
    for (double v : us) sum += v;
    return {sum / us.size(), us[us.size() / 2], us[std::min(us.size() - 1, us.size() * 99 / 100)]};
}

Stats cpp_loop(const std::string& path, int n) {
    auto port = serial::open_port(path, 0);
    auto link = std::make_shared<serial::LineLink>(port, arcus::Client::line_options(std::chrono::seconds(1)));
    arcus::Client c(link, {1, std::nullopt, 0});
    for (int i = 0; i < 50; ++i) (void)c.position();  // warm up
    std::vector<double> us;
    us.reserve(n);
    for (int i = 0; i < n; ++i) {
        auto t0 = Clk::now();
        (void)c.position();
        us.push_back(std::chrono::duration<double, std::micro>(Clk::now() - t0).count());
    }
    port->close();
    return stats(us);
}

// The reference: the loop a user writes with pyserial alone.
Stats pyserial_loop(const std::string& path, int n) {
    std::string script =
        "import serial,time,sys\n"
        "p=serial.Serial(sys.argv[1],115200,timeout=1)\n"
        "def rt():\n"
        "    p.write(b'@01PX\\r')\n"
        "    out=b''\n"
        "    while not out.endswith(b'\\0'):\n"
        "        c=p.read(1)\n"
        "        if not c: raise SystemExit('timeout')\n"
        "        out+=c\n"
        "    return out\n"
        "for _ in range(50): rt()\n"
        "us=[]\n"
        "for _ in range(int(sys.argv[2])):\n"
        "    t=time.perf_counter(); rt(); us.append((time.perf_counter()-t)*1e6)\n"
        "us.sort()\n"
        "print(sum(us)/len(us), us[len(us)//2], us[min(len(us)-1,len(us)*99//100)])\n";
    std::string cmd = motorbus_bench::python() + " -c \"$MB_SCRIPT\" " + path + " " + std::to_string(n);
    setenv("MB_SCRIPT", script.c_str(), 1);
    FILE* f = popen(cmd.c_str(), "r");
    if (!f) return {0, 0, 0};
    Stats s{0, 0, 0};
    if (std::fscanf(f, "%lf %lf %lf", &s.mean_us, &s.p50_us, &s.p99_us) != 3) s = {0, 0, 0};
    pclose(f);
    return s;
}

void run_case(const char* name, unsigned baud, int n) {
    RealClock clock;
    auto sim = std::make_shared<arcus::Sim>(clock, arcus::SimOptions{});
    serial::PtyLineServer server({sim}, baud);
    Stats mb = cpp_loop(server.slave_path(), n);
    Stats ref = pyserial_loop(server.slave_path(), n);
    std::printf("%-12s motorbus C++ client: mean %8.1f us  p50 %8.1f  p99 %8.1f | pyserial loop: mean %8.1f us  "
                "p50 %8.1f  p99 %8.1f | ratio (pyserial/motorbus, mean) %.2fx\n",
                name, mb.mean_us, mb.p50_us, mb.p99_us, ref.mean_us, ref.p50_us, ref.p99_us,
                mb.mean_us > 0 ? ref.mean_us / mb.mean_us : 0.0);
    server.close();
}

}  // namespace

int main(int argc, char** argv) {
    int n = argc > 1 ? std::atoi(argv[1]) : 2000;
    if (n < 10) n = 10;
    std::printf("Arcus round trip '@01PX\\r' -> '<n>\\0' on a pty, %d iterations\n", n);
    run_case("unthrottled", 0, n);
    run_case("115200 baud", 115200, n);
    return 0;
}

// PDO pack/unpack per frame (target <= 50 ns) and SYNC producer jitter.
// The reference, python `canopen`'s PdoMap decode, runs in the same run
// through python3 (it is a Python library) and the ratio is printed.
//
//   ./build/h/bench_pdo [sync_seconds=2] [sync_period_us=1000]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "bench_python.hpp"

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/sync.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using clk = std::chrono::steady_clock;

namespace {

volatile std::uint64_t g_sink;

struct Result {
    double pack_ns, unpack_ns;
};

Result measure(const PdoLayout& l, std::size_t iters) {
    std::vector<std::uint64_t> vals(l.size());
    std::uint8_t buf[8] = {};
    std::uint64_t out[PdoLayout::kMaxEntries];
    double best_pack = 1e9, best_unpack = 1e9;
    for (int rep = 0; rep < 5; ++rep) {
        auto t0 = clk::now();
        for (std::size_t i = 0; i < iters; ++i) {
            vals[0] = i;  // values change every frame
            l.pack(vals.data(), buf);
            g_sink = g_sink + buf[0];
        }
        auto t1 = clk::now();
        for (std::size_t i = 0; i < iters; ++i) {
            buf[0] = static_cast<std::uint8_t>(i);
            l.unpack(buf, 8, out);
            g_sink = g_sink + out[0];
        }
        auto t2 = clk::now();
        best_pack = std::min(best_pack, std::chrono::duration<double, std::nano>(t1 - t0).count() / double(iters));
        best_unpack = std::min(best_unpack, std::chrono::duration<double, std::nano>(t2 - t1).count() / double(iters));
    }
    return {best_pack, best_unpack};
}

// Times canopen's decode of the same 7-byte frame (on_message + .raw of every variable).
double canopen_decode_ns() {
    const char* script =
        "import timeit,canopen\n"
        "from canopen import objectdictionary as odm\n"
        "from canopen.pdo.base import PdoMap\n"
        "od=canopen.ObjectDictionary()\n"
        "for i,dt in ((0x6041,odm.UNSIGNED16),(0x6064,odm.INTEGER32),(0x6061,odm.INTEGER8)):\n"
        "  v=odm.ODVariable('v%x'%i,i,0); v.data_type=dt; od.add_object(v)\n"
        "n=canopen.RemoteNode(5,od); m=PdoMap(n.tpdo,None,None); m.cob_id=0x185\n"
        "for i,b in ((0x6041,16),(0x6064,32),(0x6061,8)): m.add_variable(i,0,b)\n"
        "d=bytes.fromhex('3706102700000001')[:7]\n"
        "def f():\n"
        "  m.on_message(0x185,d,0.0); return [v.raw for v in m.map]\n"
        "n_=20000; t=min(timeit.repeat(f,number=n_,repeat=5))\n"
        "print(t/n_*1e9)\n";
    std::string cmd = motorbus_bench::python() + " -c \"";
    for (const char* p = script; *p; ++p) {
        if (*p == '"' || *p == '\\' || *p == '$' || *p == '`') cmd += '\\';
        cmd += *p;
    }
    cmd += "\" 2>/dev/null";
    FILE* f = popen(cmd.c_str(), "r");
    if (!f) return -1;
    double ns = -1;
    if (std::fscanf(f, "%lf", &ns) != 1) ns = -1;
    pclose(f);
    return ns;
}

}  // namespace

int main(int argc, char** argv) {
    const double sync_s = argc > 1 ? std::atof(argv[1]) : 2.0;
    const int period_us = argc > 2 ? std::atoi(argv[2]) : 1000;

    const PdoMapEntry drive[] = {{0x6041, 0, 16}, {0x6064, 0, 32}, {0x6061, 0, 8}};
    const PdoMapEntry bits[] = {{0x2000, 1, 1}, {0x2000, 2, 3}, {0x2000, 3, 12}, {0x2000, 4, 7},
                                {0x2000, 5, 1}, {0x2000, 6, 20}, {0x2000, 7, 20}};
    std::vector<PdoMapEntry> eight(8, PdoMapEntry{0x2001, 0, 8});
    const std::size_t iters = 5'000'000;
    struct Case {
        const char* name;
        PdoLayout l;
    } cases[] = {{"drive 16+32+8 bits (7 B)", PdoLayout(drive)},
                 {"bit fields 1+3+12+7+1+20+20", PdoLayout(bits)},
                 {"8 x UNSIGNED8", PdoLayout(eight)}};
    std::printf("PDO pack/unpack per frame (best of 5 x %zu)\n", iters);
    Result first{};
    for (auto& c : cases) {
        auto r = measure(c.l, iters);
        if (&c == &cases[0]) first = r;
        std::printf("  %-30s pack %6.1f ns   unpack %6.1f ns\n", c.name, r.pack_ns, r.unpack_ns);
    }
    const double ref = canopen_decode_ns();
    if (ref > 0)
        std::printf("  canopen %-22s decode %6.0f ns  -> motorbus unpack is %.0fx faster\n",
                    "PdoMap (same 7 B frame)", ref, ref / first.unpack_ns);
    else
        std::printf("  canopen reference not available (python3 -c failed)\n");

    // SYNC jitter on a virtual bus (no wire time): the producer thread alone.
    auto bus = can::open_virtual("bench-sync");
    auto sink = can::open_virtual("bench-sync");
    for (bool rt : {false, true}) {
        SyncProducer p(*bus, std::chrono::microseconds(period_us));
        p.start(rt);
        std::this_thread::sleep_for(std::chrono::duration<double>(sync_s));
        p.stop();
        auto j = p.jitter();
        std::printf("SYNC producer%s, period %d us, %.1f s: %llu periods, error min %.1f us mean %.2f us "
                    "max %.1f us, p99 |error| %.1f us\n",
                    rt ? (p.realtime_granted() ? " SCHED_FIFO" : " (SCHED_FIFO refused)") : "", period_us, sync_s,
                    static_cast<unsigned long long>(j.count), j.min_ns / 1e3, j.mean_ns / 1e3, j.max_ns / 1e3,
                    j.p99_abs_ns / 1e3);
    }
    return 0;
}

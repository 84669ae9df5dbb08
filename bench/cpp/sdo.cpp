// SDO from C++: motorbus SdoClient -> LocalNode over the virtual bus, and the
// canopen package (run as `python3 bench/sdo.py --reference` in the same run)
// for the ratios.
//
//   ./build/h/bench_sdo [seconds-per-measurement]        (default 2)
//   MOTORBUS_BENCH_NO_REFERENCE=1 ./build/h/bench_sdo    (ours only)
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

#include "bench_python.hpp"

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using SteadyClock = std::chrono::steady_clock;

namespace {

struct Rate {
    double per_s, median_us, p99_us;
};

Rate rate(const std::function<void()>& fn, double seconds) {
    std::vector<double> lat;
    lat.reserve(1 << 20);
    const auto end = SteadyClock::now() + std::chrono::duration<double>(seconds);
    double total = 0;
    while (true) {
        const auto t = SteadyClock::now();
        fn();
        const auto t2 = SteadyClock::now();
        const double us = std::chrono::duration<double, std::micro>(t2 - t).count();
        lat.push_back(us);
        total += us;
        if (t2 >= end) break;
    }
    std::sort(lat.begin(), lat.end());
    return {static_cast<double>(lat.size()) / total * 1e6, lat[lat.size() / 2],
            lat[std::min(lat.size() - 1, lat.size() * 99 / 100)]};
}

double throughput(const std::function<void()>& fn, std::size_t bytes, double seconds) {
    const auto t0 = SteadyClock::now();
    std::size_t n = 0;
    while (true) {
        fn();
        ++n;
        const double dt = std::chrono::duration<double>(SteadyClock::now() - t0).count();
        if (dt >= seconds) return static_cast<double>(n * bytes) / dt;
    }
}

// Many transfers in flight: kNodes LocalNodes (ids 1..kNodes) on one virtual
// bus, each serving its own copy of the same small dictionary; kNodes client
// threads, each with its own SdoClient reading 0x1000:0 (u32) from its own node
// back to back for `seconds`.  Returns total reads/s; exits non-zero if any
// thread failed a read, timed out or completed none.
constexpr int kNodes = 8;

double expedited_rate_many(double seconds, const SdoClientOptions& copts) {
    auto host = can::open_virtual("bench-sdo-many"), dev = can::open_virtual("bench-sdo-many");
    std::vector<std::unique_ptr<LocalNode>> nodes;
    std::vector<std::unique_ptr<SdoClient>> clients;
    for (int i = 1; i <= kNodes; ++i) {
        auto od = std::make_shared<ObjectDictionary>();
        od->add_variable({.index = 0x1000, .name = "Device type", .type = DataType::Unsigned32,
                          .default_value = std::uint64_t{0x00020192}});
        od->add_variable({.index = 0x2000, .name = "Value", .type = DataType::Unsigned32,
                          .default_value = std::uint64_t{0x12345678}});
        nodes.push_back(std::make_unique<LocalNode>(*dev, static_cast<std::uint8_t>(i), od));
        clients.push_back(std::make_unique<SdoClient>(*host, static_cast<std::uint8_t>(i), copts));
    }
    std::vector<std::uint64_t> reads(kNodes, 0), errors(kNodes, 0);
    std::atomic<int> ready{0};
    std::atomic<bool> go{false};
    SteadyClock::time_point end;
    std::vector<std::thread> threads;
    for (int k = 0; k < kNodes; ++k) {
        threads.emplace_back([&, k] {
            ready.fetch_add(1);
            while (!go.load(std::memory_order_acquire)) std::this_thread::yield();
            std::uint64_t n = 0, e = 0;
            while (SteadyClock::now() < end) {
                try {
                    if (clients[k]->read_u32(0x1000, 0) != 0x00020192) ++e;
                    else ++n;
                } catch (const std::exception& ex) {
                    if (++e == 1) std::fprintf(stderr, "expedited_rate_8_nodes: node %d: %s\n", k + 1, ex.what());
                }
            }
            reads[k] = n;
            errors[k] = e;
        });
    }
    while (ready.load() < kNodes) std::this_thread::yield();
    const auto t0 = SteadyClock::now();
    end = t0 + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds));
    go.store(true, std::memory_order_release);
    for (auto& t : threads) t.join();
    const double dt = std::chrono::duration<double>(SteadyClock::now() - t0).count();
    std::uint64_t total = 0, timeouts = 0;
    bool ok = true;
    std::printf("# expedited_rate_8_nodes: reads per node");
    for (int k = 0; k < kNodes; ++k) {
        const auto c = clients[k]->counters();
        std::printf(" %llu", (unsigned long long)reads[k]);
        total += reads[k];
        timeouts += c.timeouts;
        if (reads[k] == 0 || errors[k] != 0 || c.timeouts != 0) ok = false;
    }
    std::printf("; errors %llu, client timeouts %llu\n",
                (unsigned long long)std::accumulate(errors.begin(), errors.end(), std::uint64_t{0}),
                (unsigned long long)timeouts);
    for (auto& n : nodes) n->close();
    if (!ok) {
        std::fprintf(stderr, "expedited_rate_8_nodes: FAILED (a thread had errors, timeouts or no reads)\n");
        std::exit(1);
    }
    return static_cast<double>(total) / dt;
}

std::map<std::string, double> reference(double seconds) {
    std::map<std::string, double> r;
    const std::string cmd = "PYTHONPATH=" + motorbus_bench::repo_file("python") + " " + motorbus_bench::python() +
                            " " + motorbus_bench::repo_file("bench/sdo.py") + " --reference --seconds " +
                            std::to_string(seconds);
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    char line[256];
    while (std::fgets(line, sizeof line, p)) {
        std::string s(line);
        auto eq = s.find('=');
        if (eq != std::string::npos) r[s.substr(0, eq)] = std::atof(s.c_str() + eq + 1);
    }
    pclose(p);
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    const double seconds = argc > 1 ? std::atof(argv[1]) : 2.0;
    auto host = can::open_virtual("bench-sdo"), dev = can::open_virtual("bench-sdo");
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x2000, .name = "Value", .type = DataType::Unsigned32,
                      .default_value = std::uint64_t{0x12345678}});
    od->add_variable({.index = 0x2001, .name = "Blob", .type = DataType::Domain, .max_size = 1 << 20});
    LocalNode node(*dev, 5, od);
    SdoClientOptions copts;
    if (const char* s = std::getenv("MOTORBUS_SDO_SPIN_US")) copts.spin = std::chrono::microseconds(std::atoi(s));
    SdoClient sdo(*host, 5, copts);
    const Bytes seg(4096, 0x5A), blk(65536, 0xA5);

    std::map<std::string, double> ours;
    auto r = rate([&] { (void)sdo.read_u32(0x2000, 0); }, seconds);
    ours["expedited_rate"] = r.per_s;
    ours["expedited_median_us"] = r.median_us;
    ours["expedited_p99_us"] = r.p99_us;
    od->at(0x2001, 0)->set(seg);
    ours["segmented_upload_Bps"] = throughput([&] { (void)sdo.upload(0x2001, 0); }, seg.size(), seconds);
    ours["segmented_download_Bps"] =
        throughput([&] { sdo.download(0x2001, 0, seg, TransferMode::Segmented); }, seg.size(), seconds);
    od->at(0x2001, 0)->set(blk);
    ours["block_upload_Bps"] =
        throughput([&] { (void)sdo.upload(0x2001, 0, TransferMode::Block); }, blk.size(), seconds);
    ours["block_download_Bps"] =
        throughput([&] { sdo.download(0x2001, 0, blk, TransferMode::Block); }, blk.size(), seconds);
    const auto cc = sdo.counters();
    const auto nc = node.counters();
    std::printf("# client: transfers %llu, retransmit requests %llu, timeouts %llu; server: ignored %llu, "
                "timeouts %llu; bus overruns host %llu dev %llu\n",
                (unsigned long long)cc.transfers, (unsigned long long)cc.retransmit_requests,
                (unsigned long long)cc.timeouts, (unsigned long long)nc.sdo.ignored,
                (unsigned long long)nc.sdo.timeouts, (unsigned long long)host->counters().overruns,
                (unsigned long long)dev->counters().overruns);
    node.close();
    ours["expedited_rate_8_nodes"] = expedited_rate_many(seconds, copts);

    std::map<std::string, double> ref;
    if (!std::getenv("MOTORBUS_BENCH_NO_REFERENCE")) ref = reference(seconds);
    std::printf("%-28s %14s %14s %8s\n", "SDO from C++", "motorbus", "canopen", "ratio");
    for (auto key : {"expedited_rate", "expedited_median_us", "expedited_p99_us", "segmented_upload_Bps",
                     "segmented_download_Bps", "block_upload_Bps", "block_download_Bps", "expedited_rate_8_nodes"}) {
        const double a = ours[key];
        auto it = ref.find(key);
        if (it == ref.end() || it->second <= 0 || a <= 0) {
            std::printf("%-28s %14.6g %14s %8s\n", key, a, "-", "-");
            continue;
        }
        const bool lower_better = std::string(key).ends_with("_us");
        const double ratio = lower_better ? it->second / a : a / it->second;
        std::printf("%-28s %14.6g %14.6g %7.1fx\n", key, a, it->second, ratio);
    }
    return 0;
}

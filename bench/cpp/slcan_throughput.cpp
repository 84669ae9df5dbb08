// SLCAN over a pty: frames/s and round-trip latency of SlcanBus (C++) against
// python-can's slcan interface, timed by the same C++ harness in the same run.
//
// The harness owns the pty master and plays the wire; the library under test
// (the "agent") opens the slave as an SLCAN host and runs the small protocol
// described in bench/slcan_throughput.py (rx load + sync, tx burst, ping/echo).
// The python-can agent is that script run as a subprocess.
//
//   ./build/h/bench_slcan_throughput [n_cpp=200000] [n_pycan=20000] [k=1000]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_python.hpp"

#include "motorbus/can/slcan_bus.hpp"
#include "motorbus/can/slcan_codec.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/serial/port.hpp"

using namespace motorbus;
using namespace motorbus::can;
using Steady = std::chrono::steady_clock;
using namespace std::chrono_literals;

namespace {

constexpr std::uint32_t kStop = 0x7FF, kSync = 0x201, kSyncReply = 0x202, kTxCmd = 0x300,
                        kTxFrame = 0x400, kPing = 0x100, kPong = 0x101, kLoad = 0x200;

struct Result {
    double rx_fps = 0, tx_fps = 0, rtt_median_us = 0, rtt_p99_us = 0;
    std::uint32_t rx_received = 0;
    std::size_t n = 0;
};

std::string line_for(std::uint32_t id, std::vector<std::uint8_t> data) {
    return slcan::encode_frame(Frame::make(id, data));
}

std::vector<std::uint8_t> le32(std::uint32_t v) {
    return {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
            static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)};
}

// The wire side: writes lines, decodes what the agent sends.
class Harness {
public:
    explicit Harness(std::shared_ptr<serial::Port> port) : port_(std::move(port)) {}

    void write(const std::string& s) {
        port_->write(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
    }

    // Reads until `pred(frame)` is true; returns false on timeout.
    template <class Pred>
    bool wait_frame(Pred pred, std::chrono::nanoseconds timeout) {
        const auto end = Steady::now() + timeout;
        std::uint8_t buf[65536];
        for (;;) {
            while (!ready_.empty()) {
                Frame f = ready_.front();
                ready_.erase(ready_.begin());
                if (pred(f)) return true;
            }
            auto left = end - Steady::now();
            if (left <= 0ns) return false;
            std::size_t n = port_->read(buf, left);
            dec_.feed(std::span(buf, n), [&](const slcan::Event& e) {
                if (e.kind == slcan::EventKind::Frame) ready_.push_back(e.frame);
            });
        }
    }

    Result run(std::size_t n, std::size_t k) {
        Result r;
        r.n = n;
        // readiness: ping until the agent answers
        bool up = false;
        for (int i = 0; i < 300 && !up; ++i) {
            write(line_for(kPing, {0}));
            up = wait_frame([](const Frame& f) { return f.id == kPong; }, 100ms);
        }
        if (!up) throw std::runtime_error("agent never answered");
        std::this_thread::sleep_for(100ms);
        drain();
        // rtt
        std::vector<double> rtts;
        for (std::size_t i = 0; i < k; ++i) {
            auto payload = le32(static_cast<std::uint32_t>(i));
            auto t0 = Steady::now();
            write(line_for(kPing, payload));
            if (!wait_frame([&](const Frame& f) {
                    return f.id == kPong && f.len == 4 && std::equal(payload.begin(), payload.end(), f.data.begin());
                }, 30s))
                throw std::runtime_error("no pong");
            rtts.push_back(std::chrono::duration<double, std::micro>(Steady::now() - t0).count());
        }
        std::sort(rtts.begin(), rtts.end());
        r.rtt_median_us = rtts[rtts.size() / 2];
        r.rtt_p99_us = rtts[std::min(rtts.size() - 1, rtts.size() * 99 / 100)];
        // rx
        std::string block;
        const std::string one = line_for(kLoad, {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88});
        block.reserve(one.size() * n);
        for (std::size_t i = 0; i < n; ++i) block += one;
        auto t0 = Steady::now();
        write(block);
        write(line_for(kSync, {}));
        std::uint32_t got = 0;
        if (!wait_frame([&](const Frame& f) {
                if (f.id != kSyncReply || f.len != 4) return false;
                std::memcpy(&got, f.data.data(), 4);
                return true;
            }, 300s))
            throw std::runtime_error("no sync reply");
        r.rx_fps = got / std::chrono::duration<double>(Steady::now() - t0).count();
        r.rx_received = got;
        // tx: count the agent's lines (it sends nothing else meanwhile)
        drain();
        // timed from the command, so the agent's reaction time is included
        const Steady::time_point first = Steady::now();
        write(line_for(kTxCmd, le32(static_cast<std::uint32_t>(n))));
        std::size_t seen = 0;
        std::uint8_t buf[65536];
        const auto end = Steady::now() + 300s;
        while (seen < n && Steady::now() < end) {
            std::size_t m = port_->read(buf, 1s);
            seen += static_cast<std::size_t>(std::count(buf, buf + m, '\r'));
        }
        r.tx_fps = n / std::chrono::duration<double>(Steady::now() - first).count();
        write(line_for(kStop, {}));
        return r;
    }

private:
    void drain() {
        std::uint8_t buf[65536];
        while (port_->read(buf, 20ms) > 0) {
        }
        dec_.discard_partial();
        ready_.clear();
    }
    std::shared_ptr<serial::Port> port_;
    slcan::StreamDecoder dec_;
    std::vector<Frame> ready_;
};

// The C++ agent: SlcanBus on the slave path, in-process.
void cpp_agent(const std::string& path, std::atomic<bool>& done) {
    SlcanOptions o;
    o.wait_for_acks = false;  // the harness is a silent wire
    auto bus = open_slcan(path, 500000, o);
    std::uint32_t count = 0;
    const Frame out = Frame::make(kTxFrame, std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6, 7, 8});
    while (!done) {
        auto f = bus->recv(1s);
        if (!f) continue;
        switch (f->id) {
            case kLoad: ++count; break;
            case kPing: bus->send(Frame::make(kPong, f->payload())); break;
            case kSync:
                bus->send(Frame::make(kSyncReply, le32(count)));
                count = 0;
                break;
            case kTxCmd: {
                std::uint32_t n;
                std::memcpy(&n, f->data.data(), 4);
                for (std::uint32_t i = 0; i < n; ++i) bus->send(out);
                break;
            }
            case kStop: return;
        }
    }
}

std::string script_path() { return motorbus_bench::repo_file("bench/slcan_throughput.py"); }

Result run_cpp(std::size_t n, std::size_t k) {
    serial::PtyPair pty;
    std::atomic<bool> done{false};
    std::thread agent([&] { cpp_agent(pty.slave_path(), done); });
    Harness h(pty.port());
    Result r;
    try {
        r = h.run(n, k);
    } catch (...) {
        done = true;
        agent.join();
        throw;
    }
    agent.join();
    return r;
}

Result run_pycan(std::size_t n, std::size_t k) {
    serial::PtyPair pty;
    // Resolved before fork(): the child only calls exec.
    const std::string script = script_path();
    const std::string py = motorbus_bench::python();
    pid_t pid = ::fork();
    if (pid == 0) {
        ::execlp(py.c_str(), py.c_str(), script.c_str(), "--agent", "pycan", "--path",
                 pty.slave_path().c_str(), static_cast<char*>(nullptr));
        std::_Exit(127);
    }
    Harness h(pty.port());
    Result r;
    try {
        r = h.run(n, k);
    } catch (...) {
        ::kill(pid, SIGTERM);
        ::waitpid(pid, nullptr, 0);
        throw;
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    const std::size_t n_cpp = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 200000;
    const std::size_t n_py = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 20000;
    const std::size_t k = argc > 3 ? std::strtoul(argv[3], nullptr, 10) : 1000;
    try {
        Result ref = run_pycan(n_py, k);
        Result ours = run_cpp(n_cpp, k);
        std::printf("SLCAN over a pty: SlcanBus (C++, %zu frames/phase) vs python-can slcan (%zu frames/phase), %zu round trips\n",
                    n_cpp, n_py, k);
        std::printf("%-20s%14s%14s%9s\n", "", "python-can", "motorbus C++", "ratio");
        std::printf("%-20s%14.0f%14.0f%8.1fx\n", "rx frames/s", ref.rx_fps, ours.rx_fps, ours.rx_fps / ref.rx_fps);
        std::printf("%-20s%14.0f%14.0f%8.1fx\n", "tx frames/s", ref.tx_fps, ours.tx_fps, ours.tx_fps / ref.tx_fps);
        std::printf("%-20s%14.1f%14.1f%8.1fx\n", "rtt median (us)", ref.rtt_median_us, ours.rtt_median_us,
                    ref.rtt_median_us / ours.rtt_median_us);
        std::printf("%-20s%14.1f%14.1f%8.1fx\n", "rtt p99 (us)", ref.rtt_p99_us, ours.rtt_p99_us,
                    ref.rtt_p99_us / ours.rtt_p99_us);
        std::printf("rx counts checked: python-can %u/%zu, motorbus %u/%zu\n", ref.rx_received, ref.n,
                    ours.rx_received, ours.n);
        return (ref.rx_received == ref.n && ours.rx_received == ours.n) ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench failed: %s\n", e.what());
        return 2;
    }
}

// Issue 28 ("Hardening, second round"), the CAN core:
//  item 9  -- a bus read only through callbacks (a simulated node, a server
//             endpoint) keeps kUnreadQueueCap frames for recv(), not 65 536;
//  item 10 -- waits that returned to Python for Ctrl-C only at their timeout now
//             run the interrupt check every kInterruptSlice: send() on a full
//             wire, the socketcand connect/handshake; absurd virtual bit rates
//             are refused (UBSan: 1e-9 bit/s overflowed a frame's duration).
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "motorbus/can/socketcand_bus.hpp"
#include "motorbus/can/socketcand_net.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/runtime/interrupt.hpp"

using namespace motorbus;
using namespace motorbus::can;
using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

namespace {

Frame numbered(std::uint32_t i) {
    const std::uint8_t b[4] = {std::uint8_t(i), std::uint8_t(i >> 8), std::uint8_t(i >> 16), std::uint8_t(i >> 24)};
    return Frame::make(0x123, b);
}
std::uint32_t number_of(const Frame& f) {
    return f.data[0] | f.data[1] << 8 | f.data[2] << 16 | std::uint32_t(f.data[3]) << 24;
}

// An interrupt check (what the bindings install for Ctrl-C) that fires once
// `armed` is set; counts its calls.
std::atomic<bool> g_armed{false};
std::atomic<int> g_checks{0};
struct Interrupted {};
void check() {
    ++g_checks;
    if (g_armed.load()) throw Interrupted{};
}

// Arms the check `after` from now, on another thread; returns how long the
// interrupted call took after arming (seconds), or -1 if it returned or threw
// something else.
template <class F>
double seconds_to_interrupt(F&& call, std::chrono::milliseconds after) {
    g_armed = false;
    g_checks = 0;
    std::thread arm([&] {
        std::this_thread::sleep_for(after);
        g_armed = true;
    });
    InterruptScope scope(&check);
    const auto t0 = SteadyClock::now();
    double took = -1;
    try {
        call();
    } catch (const Interrupted&) {
        took = std::chrono::duration<double>(SteadyClock::now() - t0).count() - after.count() / 1e3;
    } catch (...) {
    }
    arm.join();
    return took;
}

}  // namespace

TEST(UnreadQueue, CallbackOnlyBusKeepsACappedQueueUntilRecvIsUsed) {
    auto tx = open_virtual("r2-unread");
    auto rx = open_virtual("r2-unread");
    std::atomic<std::uint32_t> seen{0};
    rx->subscribe_id(0x123, false, [&](const Frame&) { ++seen; });
    constexpr std::uint32_t kFrames = 5000;
    for (std::uint32_t i = 0; i < kFrames; ++i) tx->send(numbered(i), 5s);
    const auto deadline = SteadyClock::now() + 10s;
    while (seen.load() < kFrames && SteadyClock::now() < deadline) std::this_thread::sleep_for(1ms);
    ASSERT_EQ(seen.load(), kFrames);
    // Only the newest kUnreadQueueCap were kept for a recv() nobody made.
    EXPECT_EQ(rx->counters().rx_dropped, kFrames - kUnreadQueueCap);
    auto kept = rx->recv_many(kFrames, 0ms);
    ASSERT_EQ(kept.size(), kUnreadQueueCap);
    EXPECT_EQ(number_of(kept.front()), kFrames - kUnreadQueueCap);
    EXPECT_EQ(number_of(kept.back()), kFrames - 1);
    // recv() used: the full rx_queue_size applies from now on.
    for (std::uint32_t i = 0; i < kFrames; ++i) tx->send(numbered(i), 5s);
    while (seen.load() < 2 * kFrames && SteadyClock::now() < deadline + 10s) std::this_thread::sleep_for(1ms);
    EXPECT_EQ(rx->recv_many(2 * kFrames, 0ms).size(), kFrames);
    EXPECT_EQ(rx->counters().rx_dropped, kFrames - kUnreadQueueCap);
}

TEST(UnreadQueue, ABusWithoutCallbacksKeepsRxQueueSize) {
    auto tx = open_virtual("r2-unread-plain");
    VirtualOptions o;
    o.rx_queue_size = 3000;
    auto rx = open_virtual("r2-unread-plain", o);
    for (std::uint32_t i = 0; i < 2500; ++i) tx->send(numbered(i), 5s);
    const auto deadline = SteadyClock::now() + 10s;
    while (rx->counters().rx_frames < 2500 && SteadyClock::now() < deadline) std::this_thread::sleep_for(1ms);
    EXPECT_EQ(rx->recv_many(5000, 0ms).size(), 2500u);
    EXPECT_EQ(rx->counters().rx_dropped, 0u);
}

TEST(VirtualBitrate, AbsurdRatesAreRefused) {
    for (double bad : {1e-9, 0.5, -1.0, 2e9, 1e300}) {
        VirtualOptions o;
        o.bitrate = bad;
        try {
            open_virtual("r2-rate", o);
            ADD_FAILURE() << "bitrate " << bad << " accepted";
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find("bitrate"), std::string::npos) << e.what();
        }
    }
    VirtualOptions ok;
    ok.bitrate = 1.0;
    EXPECT_NO_THROW(open_virtual("r2-rate-1", ok));
    ok.bitrate = 1e9;
    EXPECT_NO_THROW(open_virtual("r2-rate-2", ok));
}

// A wire at 100 bit/s (a frame ~1 s) with one transmit slot: the third send
// waits for room.  With an interrupt check installed it returns to it within a
// slice, not at its 30 s timeout.
TEST(InterruptSlices, SendOnAFullWireRunsTheCheck) {
    VirtualOptions o;
    o.bitrate = 100;
    o.tx_queue = 1;
    auto tx = open_virtual("r2-full", o);
    auto rx = open_virtual("r2-full", o);
    tx->send(numbered(0), 1s);
    tx->send(numbered(1), 1s);
    const double took = seconds_to_interrupt([&] {
        for (int i = 2; i < 10; ++i) tx->send(numbered(i), 30s);
    }, 200ms);
    EXPECT_GE(took, 0.0) << "the send was not interrupted";
    EXPECT_LT(took, 2.0);
    tx->close();
    rx->close();
}

// A server that accepts the connection and never says < hi >.
TEST(InterruptSlices, SocketcandHandshakeRunsTheCheck) {
    std::uint16_t port = 0;
    auto listener = net::tcp_listen("127.0.0.1", 0, port);  // the kernel completes the connect
    SocketcandOptions o;
    o.handshake_timeout = 30s;
    const double took = seconds_to_interrupt([&] { open_socketcand("127.0.0.1", port, "can0", o); }, 200ms);
    EXPECT_GE(took, 0.0) << "the handshake was not interrupted";
    EXPECT_LT(took, 2.0);
}

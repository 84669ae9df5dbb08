// Hardening (defect 6): a socketcand link that dies wakes every waiter with
// LinkDown -- recv(forever), recv_many(forever), a send() blocked on a full
// transmit buffer -- within a second, instead of leaving them blocked forever.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <future>
#include <string>
#include <thread>

#include "motorbus/can/socketcand_bus.hpp"
#include "motorbus/can/socketcand_net.hpp"
#include "motorbus/can/socketcand_server.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::can;
using namespace std::chrono_literals;

namespace {

// One scripted server connection: accept, raw-mode handshake, then whatever
// the test does with `c` (close it to kill the link).
struct ScriptedServer {
    std::uint16_t port = 0;
    net::Fd listener = net::tcp_listen("127.0.0.1", 0, port);
    net::Fd c;
    void accept_and_handshake(int rcvbuf = 0) {
        pollfd p{listener.get(), POLLIN, 0};
        ::poll(&p, 1, 2000);
        c = net::Fd(::accept(listener.get(), nullptr, nullptr));
        if (rcvbuf > 0) ::setsockopt(c.get(), SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
        auto say = [&](const std::string& s) { ::send(c.get(), s.data(), s.size(), MSG_NOSIGNAL); };
        auto hear = [&](std::size_t max) {
            pollfd q{c.get(), POLLIN, 0};
            ::poll(&q, 1, 2000);
            char b[64];
            [[maybe_unused]] auto r = ::recv(c.get(), b, std::min(max, sizeof b), 0);
        };
        say("< hi >");
        hear(13);  // "< open can0 >"
        say("< ok >");
        hear(13);  // "< rawmode >"
        say("< ok >");
    }
    void kill() { c = net::Fd(); }
};

SocketcandOptions opts() {
    SocketcandOptions o;
    o.connect_timeout = 2s;
    o.handshake_timeout = 2s;
    o.keepalive_period = 0ms;  // the link dies by EOF here, not by silence
    return o;
}

template <class F>
std::future<std::string> waiter(F&& f) {
    return std::async(std::launch::async, [f = std::forward<F>(f)]() -> std::string {
        try {
            f();
            return "returned";
        } catch (const LinkDown& e) {
            return std::string("LinkDown: ") + e.what();
        } catch (const std::exception& e) {
            return std::string("other: ") + e.what();
        }
    });
}

// Closes the bus when the test leaves (also on a failed ASSERT), so a waiter
// that was never woken does not block the future's destructor forever.
struct CloseOnExit {
    std::shared_ptr<SocketcandBus> bus;
    ~CloseOnExit() { bus->close(); }
};

}  // namespace

TEST(SocketcandLinkDown, BlockedRecvAndRecvManyWakeWithLinkDown) {
    ScriptedServer server;
    std::thread accept([&] { server.accept_and_handshake(); });
    auto bus = open_socketcand("127.0.0.1", server.port, "can0", opts());
    accept.join();
    auto r1 = waiter([&] { bus->recv(Duration(-1)); });
    auto r2 = waiter([&] { bus->recv_many(16, Duration(-1)); });
    CloseOnExit closer{bus};
    std::this_thread::sleep_for(50ms);  // both are waiting
    server.kill();
    ASSERT_EQ(r1.wait_for(1s), std::future_status::ready) << "recv(forever) still blocked 1 s after the link died";
    ASSERT_EQ(r2.wait_for(1s), std::future_status::ready) << "recv_many(forever) still blocked";
    EXPECT_EQ(r1.get().rfind("LinkDown: ", 0), 0u);
    const std::string m2 = r2.get();
    EXPECT_EQ(m2.rfind("LinkDown: ", 0), 0u) << m2;
    EXPECT_NE(m2.find("closed the connection"), std::string::npos) << m2;
    // Later calls do not wait either, with or without a timeout.
    EXPECT_THROW(bus->recv(Duration(-1)), LinkDown);
    EXPECT_THROW(bus->recv(5s), LinkDown);
    EXPECT_THROW(bus->send(Frame::make(0x1, {})), LinkDown);
    // Our own close() afterwards is a ClosedError, as always.
    bus->close();
    EXPECT_THROW(bus->recv(Duration(-1)), ClosedError);
}

TEST(SocketcandLinkDown, FramesReceivedBeforeTheLossAreStillDelivered) {
    ScriptedServer server;
    std::thread accept([&] { server.accept_and_handshake(); });
    auto bus = open_socketcand("127.0.0.1", server.port, "can0", opts());
    accept.join();
    const std::string f = "< frame 123 1.000000 11 >";
    ::send(server.c.get(), f.data(), f.size(), MSG_NOSIGNAL);
    std::this_thread::sleep_for(50ms);
    server.kill();
    std::this_thread::sleep_for(50ms);
    auto got = bus->recv(1s);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->id, 0x123u);
    EXPECT_THROW(bus->recv(Duration(-1)), LinkDown);
}

TEST(SocketcandLinkDown, SendBlockedOnAFullBufferWakesWithLinkDown) {
    ScriptedServer server;
    std::thread accept([&] { server.accept_and_handshake(4096); });
    SocketcandOptions o = opts();
    o.tx_buffer_bytes = 4096;
    auto bus = open_socketcand("127.0.0.1", server.port, "can0", o);
    accept.join();
    std::atomic<bool> blocked{false};
    auto s = waiter([&] {
        std::uint8_t b[8] = {1, 2, 3, 4, 5, 6, 7, 8};
        for (;;) {
            blocked = true;
            bus->send(Frame::make(0x7FF, b), std::chrono::hours(1));
        }
    });
    CloseOnExit closer{bus};
    std::this_thread::sleep_for(300ms);  // the server never reads: the client's buffer fills
    ASSERT_TRUE(blocked.load());
    ASSERT_EQ(s.wait_for(0s), std::future_status::timeout);
    server.kill();
    ASSERT_EQ(s.wait_for(1s), std::future_status::ready) << "send() still blocked 1 s after the link died";
    EXPECT_EQ(s.get().rfind("LinkDown: ", 0), 0u);
}

TEST(SocketcandLinkDown, RealServerClosedWakesAWaitingClient) {
    auto served = open_virtual("sockd-linkdown-" + std::to_string(::getpid()));
    auto server = std::make_unique<SocketcandServer>(served);
    auto bus = open_socketcand("127.0.0.1", server->port(), "can0", opts());
    auto r = waiter([&] { bus->recv(Duration(-1)); });
    CloseOnExit closer{bus};
    std::this_thread::sleep_for(50ms);
    const auto t0 = std::chrono::steady_clock::now();
    server.reset();
    ASSERT_EQ(r.wait_for(1s), std::future_status::ready);
    EXPECT_EQ(r.get().rfind("LinkDown: ", 0), 0u);
    EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s);
}

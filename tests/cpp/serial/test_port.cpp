// TtyPort / PtyPair / open_port over a real pty: bytes pass unchanged both ways.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "motorbus/serial/port.hpp"

using namespace motorbus;
using namespace motorbus::serial;
using namespace std::chrono_literals;

namespace {
std::span<const std::uint8_t> as_bytes(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

std::string read_exact(Port& p, std::size_t n, Duration timeout = 2s) {
    std::string out;
    std::uint8_t buf[256];
    auto deadline = std::chrono::steady_clock::now() + timeout;
    while (out.size() < n && std::chrono::steady_clock::now() < deadline) {
        std::size_t got = p.read(std::span(buf, std::min(sizeof buf, n - out.size())), 50ms);
        out.append(reinterpret_cast<const char*>(buf), got);
    }
    return out;
}
}  // namespace

TEST(PtyPair, BytesPassUnchangedBothWays) {
    PtyPair pty;
    EXPECT_EQ(pty.slave_path().rfind("/dev/pts/", 0), 0u);
    auto peer = pty.open_slave();
    // Every byte value, including CR, LF, NUL, XON/XOFF, DEL and 0xFF.
    std::string all;
    for (int i = 0; i < 256; ++i) all.push_back(static_cast<char>(i));
    pty.port()->write(as_bytes(all));
    EXPECT_EQ(read_exact(*peer, all.size()), all);
    peer->write(as_bytes(all));
    EXPECT_EQ(read_exact(*pty.port(), all.size()), all);
}

TEST(PtyPair, ReadTimesOutWithZero) {
    PtyPair pty;
    std::uint8_t buf[8];
    auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(pty.port()->read(buf, 20ms), 0u);
    EXPECT_GE(std::chrono::steady_clock::now() - t0, 19ms);
    EXPECT_EQ(pty.port()->read(buf, 0ns), 0u);
}

TEST(PtyPair, CloseWakesBlockedReader) {
    PtyPair pty;
    auto port = pty.port();
    std::thread t([&] {
        std::uint8_t buf[8];
        EXPECT_THROW(port->read(buf, Duration(-1)), ClosedError);
    });
    std::this_thread::sleep_for(20ms);
    port->close();
    t.join();
    std::uint8_t b = 0;
    EXPECT_THROW(port->write(std::span(&b, 1)), ClosedError);
}

TEST(PtyPair, SlaveGoneIsLinkDown) {  // L14 at the port level: unplug -> LinkDown
    PtyPair pty;
    {
        auto peer = pty.open_slave();
        pty.release_slave();
        peer->write(as_bytes("x"));
        EXPECT_EQ(read_exact(*pty.port(), 1), "x");
    }
    std::uint8_t buf[8];
    EXPECT_THROW(pty.port()->read(buf, 1s), LinkDown);
}

TEST(PtyPair, FlushInputDropsStaleBytes) {
    PtyPair pty;
    auto peer = pty.open_slave();
    peer->write(as_bytes("stale"));
    std::this_thread::sleep_for(50ms);
    pty.port()->flush_input();
    peer->write(as_bytes("new"));
    EXPECT_EQ(read_exact(*pty.port(), 3), "new");
}

TEST(TtyPort, StandardAndArbitraryBaud) {
    PtyPair pty;
    auto peer = open_port(pty.slave_path(), 115200);
    auto tty = std::dynamic_pointer_cast<TtyPort>(peer);
    ASSERT_TRUE(tty);
    EXPECT_EQ(tty->baud(), 115200u);
    tty->set_baud(9600);
    EXPECT_EQ(tty->baud(), 9600u);
    // Non-standard rate through termios2/BOTHER (the pty driver stores it).
    tty->set_baud(250000);
    EXPECT_EQ(tty->baud(), 250000u);
    EXPECT_THROW(tty->set_baud(0), InvalidArgument);
}

TEST(TtyPort, OpenErrors) {
    EXPECT_THROW(open_port("/nonexistent/tty", 9600), InvalidArgument);
    EXPECT_THROW(open_port("", 9600), InvalidArgument);
    EXPECT_THROW(open_port("/dev/null", 9600), InvalidArgument);  // not a tty
}

TEST(TtyPort, WriteTimeoutWhenPeerNeverReads) {
    PtyPair pty;
    auto m = pty.master();
    m->set_write_timeout(50ms);
    std::string big(1 << 20, 'x');
    EXPECT_THROW(m->write(as_bytes(big)), TimeoutError);
}

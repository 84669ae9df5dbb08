// PtyLineServer: LineDevices on a pty, driven by a LineLink over the slave.
#include <gtest/gtest.h>

#include <dirent.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include "motorbus/serial/line_server.hpp"
#include "motorbus/serial/port.hpp"

using namespace motorbus;
using namespace motorbus::serial;
using namespace std::chrono_literals;

namespace {
std::span<const std::uint8_t> as_bytes(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// Answers "<addr>X" with "<addr>:X\r\n" when addressed, stays silent otherwise;
// "*X" is a broadcast every device answers.
class AddressedDevice : public LineDevice {
public:
    explicit AddressedDevice(char addr, std::size_t max_req = 32) : addr_(addr), max_(max_req) {}
    std::string on_line(std::string_view line) override {
        ++lines;
        if (line.empty() || (line[0] != addr_ && line[0] != '*')) return "";
        return std::string(1, addr_) + ":" + std::string(line.substr(1)) + "\r\n";
    }
    std::size_t max_request() const override { return max_; }
    std::string on_overlong() override {
        ++overlong;
        return std::string(1, addr_) + "?\r\n";
    }
    std::atomic<int> lines{0}, overlong{0};

private:
    char addr_;
    std::size_t max_;
};

class ThrowingDevice : public LineDevice {
public:
    std::string on_line(std::string_view) override { throw std::runtime_error("broken sim"); }
};

class NulDevice : public LineDevice {  // Protocol A style: "@<addr><cmd>\r" -> "<value>\0"
public:
    std::string on_line(std::string_view line) override { return std::string(line) + std::string("\0", 1); }
};

LineOptions opts() {
    LineOptions o;
    o.reply_timeout = 1s;
    return o;
}

int open_fd_count() {
    int n = 0;
    if (DIR* d = opendir("/proc/self/fd")) {
        while (readdir(d)) ++n;
        closedir(d);
    }
    return n;
}
}  // namespace

TEST(PtyLineServer, EchoesThroughTheSlavePath) {
    auto dev = std::make_shared<AddressedDevice>('1');
    PtyLineServer server({dev});
    ASSERT_EQ(server.slave_path().rfind("/dev/pts/", 0), 0u);
    LineLink link(open_port(server.slave_path(), 115200), opts());
    EXPECT_EQ(link.transact("1PX"), "1:PX");
    EXPECT_EQ(link.transact("1V=5"), "1:V=5");
    auto c = server.counters();
    EXPECT_EQ(c.lines, 2u);
    EXPECT_EQ(c.replies, 2u);
    EXPECT_EQ(c.bytes_in, 9u);   // "1PX\r" + "1V=5\r"
    EXPECT_EQ(c.bytes_out, 13u);  // "1:PX\r\n" + "1:V=5\r\n"
}

TEST(PtyLineServer, MultiDropEveryDeviceSeesEveryLine) {
    auto a = std::make_shared<AddressedDevice>('1');
    auto b = std::make_shared<AddressedDevice>('2');
    PtyLineServer server({a, b});
    LineLink link(open_port(server.slave_path(), 0), opts());
    EXPECT_EQ(link.transact("2Q"), "2:Q");
    EXPECT_EQ(link.transact("1Q"), "1:Q");
    EXPECT_EQ(a->lines.load(), 2);
    EXPECT_EQ(b->lines.load(), 2);
    // A broadcast: both answer, in attach order.
    link.send("*B");
    EXPECT_EQ(link.read_line(1s), "1:B");
    EXPECT_EQ(link.read_line(1s), "2:B");
    // Nobody addressed: silence.
    EXPECT_THROW(link.transact("9Q", 30ms), TimeoutError);
}

TEST(PtyLineServer, RequestSplitAcrossWritesIsReassembled) {
    auto dev = std::make_shared<AddressedDevice>('1');
    PtyLineServer server({dev});
    auto client = open_port(server.slave_path(), 0);
    for (const char* part : {"1", "AB", "C", "\r"}) {
        client->write(as_bytes(part));
        std::this_thread::sleep_for(2ms);
    }
    LineLink link(client, [] {
        auto o = opts();
        o.flush_before_request = false;
        return o;
    }());
    EXPECT_EQ(link.read_line(1s), "1:ABC");
}

TEST(PtyLineServer, A15_OverlongRequestGetsOverlongReplyAndResyncs) {
    auto dev = std::make_shared<AddressedDevice>('1', 8);
    PtyLineServer server({dev});
    LineLink link(open_port(server.slave_path(), 0), opts());
    EXPECT_EQ(link.transact("1" + std::string(500, 'x')), "1?");
    EXPECT_EQ(dev->overlong.load(), 1);
    EXPECT_EQ(server.counters().overlong_lines, 1u);
    EXPECT_EQ(link.transact("1OK"), "1:OK");
}

TEST(PtyLineServer, DeviceWithSmallerCapGetsOverlongOthersGetTheLine) {
    auto small = std::make_shared<AddressedDevice>('1', 4);
    auto big = std::make_shared<AddressedDevice>('*', 64);  // answers everything
    PtyLineServer server({small, big});
    LineLink link(open_port(server.slave_path(), 0), opts());
    link.send("*123456");
    EXPECT_EQ(link.read_line(1s), "1?");
    EXPECT_EQ(link.read_line(1s), "*:123456");
}

TEST(PtyLineServer, A15_BinaryNoiseNeverStopsTheServer) {
    auto dev = std::make_shared<AddressedDevice>('1');
    PtyLineServer server({dev});
    auto client = open_port(server.slave_path(), 0);
    std::string noise;
    for (int i = 0; i < 4096; ++i) {
        char b = static_cast<char>((i * 37) & 0xff);
        noise.push_back(b == '1' || b == '*' ? '\xff' : b);  // nothing addressed to a device
    }
    // The CR at the end is how a client resyncs a line after garbage.
    client->write(as_bytes(noise + "\r"));
    LineLink link(client, opts());
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(link.transact("1after"), "1:after");
    EXPECT_GT(server.counters().lines + server.counters().overlong_lines, 10u);
}

TEST(PtyLineServer, ThrowingDeviceIsCountedAndOthersStillAnswer) {
    auto good = std::make_shared<AddressedDevice>('1');
    PtyLineServer server({std::make_shared<ThrowingDevice>(), good});
    LineLink link(open_port(server.slave_path(), 0), opts());
    EXPECT_EQ(link.transact("1X"), "1:X");
    EXPECT_EQ(server.counters().device_errors, 1u);
}

TEST(PtyLineServer, AttachWhileRunning) {
    PtyLineServer server;
    LineLink link(open_port(server.slave_path(), 0), opts());
    EXPECT_THROW(link.transact("1X", 30ms), TimeoutError);
    server.attach(std::make_shared<AddressedDevice>('1'));
    EXPECT_EQ(link.transact("1X"), "1:X");
}

TEST(PtyLineServer, NulTerminatedReplies) {
    PtyLineServer server({std::make_shared<NulDevice>()});
    auto o = opts();
    o.reply_terminators = {std::string("\0", 1)};
    LineLink link(open_port(server.slave_path(), 0), o);
    EXPECT_EQ(link.transact("@0PX"), "@0PX");
}

TEST(PtyLineServer, ServeOnAnExistingPort) {
    PtyPair pty;
    auto dev = std::make_shared<AddressedDevice>('1');
    PtyLineServer server(pty.open_slave(), {dev});
    EXPECT_EQ(server.slave_path(), "");
    LineLink link(pty.port(), opts());
    EXPECT_EQ(link.transact("1Z"), "1:Z");
}

TEST(PtyLineServer, PacedAtBaudIsNoFasterThanTheLine) {
    auto dev = std::make_shared<AddressedDevice>('1', 512);
    PtyLineServer server({dev}, 9600);
    EXPECT_EQ(server.baud(), 9600u);
    LineLink link(open_port(server.slave_path(), 0), opts());
    std::string payload(94, 'p');
    auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(link.transact("1" + payload), "1:" + payload);
    // 96 request + 98 reply bytes at 960 bytes/s cannot take less than ~200 ms.
    EXPECT_GE(std::chrono::steady_clock::now() - t0, 190ms);
}

TEST(PtyLineServer, StopsCleanlyWithoutLeakingDescriptors) {
    int before = open_fd_count();
    for (int i = 0; i < 5; ++i) {
        PtyLineServer server({std::make_shared<AddressedDevice>('1')});
        LineLink link(open_port(server.slave_path(), 0), opts());
        EXPECT_EQ(link.transact("1A"), "1:A");
    }
    EXPECT_EQ(open_fd_count(), before);
    PtyLineServer server;
    server.close();
    server.close();
    EXPECT_FALSE(server.running());
}

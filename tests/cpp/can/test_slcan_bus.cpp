// SlcanBus and SlcanServer live over pty pairs: open sequence, both
// directions over every id width and DLC, acks/NACKs/back-pressure (L10),
// status mapping (L12), echo suppression (L13), link loss and reconnect (L14),
// and the stream rows (L1, L2, L3) through the whole bus.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

#include "motorbus/can/slcan_bus.hpp"
#include "motorbus/can/slcan_server.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/serial/port.hpp"

using namespace motorbus;
using namespace motorbus::can;
using namespace std::chrono_literals;

namespace {

std::span<const std::uint8_t> bytes_of(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// Polls `pred` until true or 5 s pass (never a fixed sleep).
bool eventually(const std::function<bool()>& pred) {
    auto end = std::chrono::steady_clock::now() + 5s;
    while (std::chrono::steady_clock::now() < end) {
        if (pred()) return true;
        std::this_thread::sleep_for(1ms);
    }
    return pred();
}

// A fake adapter on the pty master: reads command lines, answers via `script`.
class ScriptedAdapter {
public:
    using Script = std::function<std::string(const std::string& line)>;
    ScriptedAdapter(std::shared_ptr<serial::Port> port, Script script)
        : port_(std::move(port)), script_(std::move(script)) {
        thread_ = std::thread([this] {
            std::array<std::uint8_t, 1024> buf;
            std::string line;
            for (;;) {
                std::size_t n;
                try {
                    n = port_->read(buf, 50ms);
                } catch (const Error&) {
                    return;
                }
                for (std::size_t i = 0; i < n; ++i) {
                    char c = static_cast<char>(buf[i]);
                    if (c != '\r') {
                        line.push_back(c);
                        continue;
                    }
                    {
                        std::lock_guard lock(m_);
                        lines_.push_back(line);
                    }
                    std::string reply = script_(line);
                    line.clear();
                    if (!reply.empty()) inject(reply);
                }
            }
        });
    }
    ~ScriptedAdapter() {
        port_->close();
        thread_.join();
    }
    void inject(const std::string& s) {
        std::lock_guard lock(wm_);
        try {
            port_->write(bytes_of(s));
        } catch (const Error&) {
        }
    }
    std::vector<std::string> lines() {
        std::lock_guard lock(m_);
        return {lines_.begin(), lines_.end()};
    }

private:
    std::shared_ptr<serial::Port> port_;
    Script script_;
    std::mutex m_, wm_;
    std::deque<std::string> lines_;
    std::thread thread_;
};

// Lawicel-like answers: configuration CR, frames z/Z, F -> flags.
std::string lawicel(const std::string& line, std::uint8_t flags = 0) {
    if (line.empty()) return "\a";
    switch (line[0]) {
        case 't': case 'r': return "z\r";
        case 'T': case 'R': return "Z\r";
        case 'F': {
            char b[8];
            std::snprintf(b, sizeof b, "F%02X\r", flags);
            return b;
        }
        case 'V': return "V1013\r";
        default: return "\r";
    }
}

SlcanOptions fast_opts() {
    SlcanOptions o;
    o.open_timeout = 500ms;
    o.ack_timeout = 500ms;
    return o;
}

std::vector<Frame> every_width_and_dlc() {
    std::vector<Frame> v;
    for (bool ext : {false, true}) {
        for (std::uint32_t id : {0u, 0x123u, ext ? kMaxExtendedId : kMaxStandardId}) {
            for (int dlc = 0; dlc <= 8; ++dlc) {
                std::vector<std::uint8_t> d;
                for (int i = 0; i < dlc; ++i) d.push_back(static_cast<std::uint8_t>(0xA0 + i * 7));
                v.push_back(Frame::make(id, d, ext));
            }
            v.push_back(Frame::make(id, {}, ext, true, 5));
        }
    }
    return v;
}

}  // namespace

TEST(SlcanBus, OpenSequenceIsCloseBitrateTimestampsOpen) {
    serial::PtyPair pty;
    ScriptedAdapter adapter(pty.port(), [](const std::string& l) { return l == "C" ? "\a" : lawicel(l); });
    auto opts = fast_opts();
    opts.timestamps = true;
    opts.bitrate = 250000;
    SlcanBus bus(pty.open_slave(), opts);
    auto lines = adapter.lines();
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_EQ(lines[0], "C");  // BEL for "already closed" is accepted
    EXPECT_EQ(lines[1], "S5");
    EXPECT_EQ(lines[2], "Z1");
    EXPECT_EQ(lines[3], "O");
    EXPECT_TRUE(bus.link_up());
    bus.close();
    // leaves the adapter closed
    EXPECT_TRUE(eventually([&] { return adapter.lines().size() == 5 && adapter.lines().back() == "C"; }));
}

// bitrate 0 is the documented "keep the adapter's rate": no S command at all.
TEST(SlcanBus, BitrateZeroKeepsTheAdaptersRate) {
    serial::PtyPair pty;
    ScriptedAdapter adapter(pty.port(), [](const std::string& l) { return lawicel(l); });
    auto opts = fast_opts();
    opts.bitrate = 0;
    SlcanBus bus(pty.open_slave(), opts);
    auto lines = adapter.lines();
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0], "C");
    EXPECT_EQ(lines[1], "O");
    bus.close();
}

TEST(SlcanBus, OpenFailsWithTypedErrors) {
    serial::PtyPair pty;
    {
        ScriptedAdapter silent(pty.port(), [](const std::string&) { return std::string(); });
        auto o = fast_opts();
        o.open_timeout = 100ms;
        EXPECT_THROW(SlcanBus(pty.open_slave(), o), TimeoutError);
    }
    serial::PtyPair pty2;
    ScriptedAdapter refuses(pty2.port(), [](const std::string& l) { return l[0] == 'S' ? "\a" : lawicel(l); });
    EXPECT_THROW(SlcanBus(pty2.open_slave(), fast_opts()), ProtocolError);
    auto bad = fast_opts();
    bad.bitrate = 83333;
    EXPECT_THROW(SlcanBus(pty2.open_slave(), bad), InvalidArgument);
}

TEST(SlcanBus, SendsExactLinesAndReceivesEveryWidthAndDlc) {
    serial::PtyPair pty;
    ScriptedAdapter adapter(pty.port(), [](const std::string& l) { return lawicel(l); });
    SlcanBus bus(pty.open_slave(), fast_opts());
    bus.send(Frame::make(0x7FF, std::vector<std::uint8_t>{0xDE, 0xAD}));
    bus.send(Frame::make(0x1FFFFFFF, std::vector<std::uint8_t>{}, true, true, 8));
    bus.flush_tx(2s);
    auto lines = adapter.lines();
    ASSERT_GE(lines.size(), 2u);
    EXPECT_EQ(lines[lines.size() - 2], "t7FF2DEAD");
    EXPECT_EQ(lines.back(), "R1FFFFFFF8");
    EXPECT_EQ(bus.stats().acks, 2u);  // open-sequence answers are consumed inline
}

TEST(SlcanServer, BothDirectionsThroughSlcanBusEveryIdWidthDlcAndRtr) {
    auto hub = "slcan-test-" + std::to_string(::getpid()) + "-a";
    auto inner = open_virtual(hub);
    auto peer = open_virtual(hub);
    SlcanServer server(inner);
    auto bus = open_slcan(server.pty_path(), 500000, fast_opts());
    ASSERT_TRUE(eventually([&] { return server.is_open(); }));
    const auto frames = every_width_and_dlc();
    // SlcanBus -> server -> virtual hub
    for (const auto& f : frames) bus->send(f);
    bus->flush_tx(5s);
    for (const auto& f : frames) {
        auto got = peer->recv(2s);
        ASSERT_TRUE(got.has_value());
        EXPECT_TRUE(got->same_content(f)) << got->to_string() << " vs " << f.to_string();
    }
    // virtual hub -> server -> SlcanBus
    for (const auto& f : frames) peer->send(f);
    for (const auto& f : frames) {
        auto got = bus->recv(2s);
        ASSERT_TRUE(got.has_value());
        EXPECT_TRUE(got->same_content(f)) << got->to_string() << " vs " << f.to_string();
    }
    // The server counts a frame after writing it, so the client can be ahead.
    EXPECT_TRUE(eventually([&] { return server.stats().forwarded == frames.size(); }));
    auto s = server.stats();
    EXPECT_EQ(s.transmitted, frames.size());
    EXPECT_EQ(s.forwarded, frames.size());
    EXPECT_EQ(bus->counters().parse_errors, 0u);
}

TEST(SlcanServer, AnswersRawCommandsAndForwardsOnlyWhileOpen) {
    auto hub = "slcan-test-" + std::to_string(::getpid()) + "-b";
    auto inner = open_virtual(hub);
    auto peer = open_virtual(hub);
    SlcanServer server(inner);
    auto tty = serial::open_port(server.pty_path(), 0);
    std::string rx;
    auto read_until = [&](std::size_t count_cr) {
        std::array<std::uint8_t, 256> buf;
        auto end = std::chrono::steady_clock::now() + 3s;
        while (std::chrono::steady_clock::now() < end &&
               static_cast<std::size_t>(std::count_if(rx.begin(), rx.end(), [](char c) { return c == '\r' || c == '\a'; })) < count_cr) {
            std::size_t n = tty->read(buf, 50ms);
            rx.append(reinterpret_cast<char*>(buf.data()), n);
        }
        std::string out = rx;
        rx.clear();
        return out;
    };
    peer->send(Frame::make(0x100, std::vector<std::uint8_t>{1}));  // closed: not forwarded
    // Delivery to the server's endpoint is asynchronous: let it land before opening.
    for (int i = 0; i < 200 && inner->counters().rx_frames < 1; ++i) std::this_thread::sleep_for(5ms);
    ASSERT_EQ(inner->counters().rx_frames, 1u);
    tty->write(bytes_of("V\rN\rt1230\rS6\rZ1\rO\r"));
    EXPECT_EQ(read_until(6), "V1013\rNMB01\r\a\r\r\r");
    peer->send(Frame::make(0x101, std::vector<std::uint8_t>{0xAB}));
    std::string line = read_until(1);
    ASSERT_EQ(line.size(), 12u) << line;  // t1011AB + 4 timestamp chars + CR
    EXPECT_EQ(line.substr(0, 7), "t1011AB");
    tty->write(bytes_of("T1FFFFFFF1EE\rF\rx\rt8000\rC\r"));
    EXPECT_EQ(read_until(5), "Z\rF00\r\a\a\r");
    auto got = peer->recv(2s);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->id, 0x1FFFFFFFu);
    EXPECT_EQ(got->data[0], 0xEE);
    peer->send(Frame::make(0x102, std::vector<std::uint8_t>{}));  // closed again
    tty->write(bytes_of("V\r"));
    EXPECT_EQ(read_until(1), "V1013\r");  // nothing forwarded before it
    EXPECT_EQ(server.stats().forwarded, 1u);
}

TEST(SlcanBus, L10_BelNackCountsTxDroppedAndFlushRaises) {
    serial::PtyPair pty;
    ScriptedAdapter adapter(pty.port(), [](const std::string& l) {
        return l == "t1230" ? std::string("\a") : lawicel(l);
    });
    SlcanBus bus(pty.open_slave(), fast_opts());
    bus.send(Frame::make(0x124, std::vector<std::uint8_t>{}));
    bus.send(Frame::make(0x123, std::vector<std::uint8_t>{}));  // refused
    bus.send(Frame::make(0x125, std::vector<std::uint8_t>{}));
    try {
        bus.flush_tx(2s);
        FAIL() << "expected ProtocolError";
    } catch (const ProtocolError& e) {
        EXPECT_NE(std::string(e.what()).find("123#"), std::string::npos) << e.what();
    }
    EXPECT_EQ(bus.counters().tx_dropped, 1u);
    EXPECT_EQ(bus.stats().nacks, 1u);
    EXPECT_EQ(bus.stats().acks, 2u);
    bus.flush_tx(1s);  // reported once
    // A lone unsolicited BEL is not a frame and counts as an adapter error.
    adapter.inject("\a");
    ASSERT_TRUE(eventually([&] { return bus.counters().bus_errors == 1; }));
    EXPECT_EQ(bus.counters().rx_frames, 0u);
}

TEST(SlcanBus, BackPressureWhenTheAdapterStopsAnswering) {
    serial::PtyPair pty;
    ScriptedAdapter adapter(pty.port(), [](const std::string& l) {
        return l[0] == 't' ? std::string() : lawicel(l);  // frames never acknowledged
    });
    auto o = fast_opts();
    o.tx_window = 2;
    o.ack_timeout = 10s;
    SlcanBus bus(pty.open_slave(), o);
    bus.send(Frame::make(1, std::vector<std::uint8_t>{}));
    bus.send(Frame::make(2, std::vector<std::uint8_t>{}));
    EXPECT_THROW(bus.send(Frame::make(3, std::vector<std::uint8_t>{}), 50ms), TimeoutError);
    adapter.inject("z\r");  // one answer frees one slot
    bus.send(Frame::make(4, std::vector<std::uint8_t>{}), 2s);
    EXPECT_EQ(bus.stats().acks, 1u);
}

TEST(SlcanBus, L12_StatusPollMapsFlagsToBusState) {
    serial::PtyPair pty;
    std::atomic<std::uint8_t> flags{0x04};
    ScriptedAdapter adapter(pty.port(), [&](const std::string& l) { return lawicel(l, flags.load()); });
    SlcanBus bus(pty.open_slave(), fast_opts());
    EXPECT_EQ(bus.query_status(2s), 0x04);
    EXPECT_EQ(bus.state(), BusState::ErrorWarning);
    flags = 0x28;  // error passive + data overrun
    EXPECT_EQ(bus.query_status(2s), 0x28);
    EXPECT_EQ(bus.state(), BusState::ErrorPassive);
    EXPECT_EQ(bus.counters().overruns, 1u);
    flags = 0x00;
    bus.query_status(2s);
    EXPECT_EQ(bus.state(), BusState::Active);
    // kernel state extension: bus-off makes send() refuse
    adapter.inject("sb256256\r");
    ASSERT_TRUE(eventually([&] { return bus.state() == BusState::BusOff; }));
    EXPECT_THROW(bus.send(Frame::make(1, std::vector<std::uint8_t>{})), LinkDown);
    adapter.inject("sa000000\r");
    ASSERT_TRUE(eventually([&] { return bus.state() == BusState::Active; }));
    // periodic polling
    serial::PtyPair pty2;
    ScriptedAdapter polled(pty2.port(), [&](const std::string& l) { return lawicel(l, 0x20); });
    auto o = fast_opts();
    o.status_poll = 20ms;
    SlcanBus bus2(pty2.open_slave(), o);
    ASSERT_TRUE(eventually([&] { return bus2.state() == BusState::ErrorPassive; }));
}

TEST(SlcanBus, L13_EchoSuppressionDropsOurOwnFramesOnly) {
    for (bool suppress : {true, false}) {
        serial::PtyPair pty;
        // ack, echo the frame, then a genuine frame from another node
        ScriptedAdapter adapter(pty.port(), [&](const std::string& l) {
            if (l[0] == 't') return "z\r" + l + "\rt3221AA\r";
            return lawicel(l);
        });
        auto o = fast_opts();
        o.echo_suppression = suppress;
        SlcanBus bus(pty.open_slave(), o);
        bus.send(Frame::make(0x321, std::vector<std::uint8_t>{0x55}));
        auto got = bus.recv(2s);
        ASSERT_TRUE(got);
        if (suppress) {
            EXPECT_EQ(got->id, 0x322u);
            EXPECT_EQ(bus.stats().echoes_suppressed, 1u);
        } else {
            EXPECT_EQ(got->id, 0x321u);  // the echo comes through when not configured
            EXPECT_EQ(bus.recv(2s)->id, 0x322u);
        }
    }
}

TEST(SlcanBus, L1_L2_L3_BadStreamInputIsCountedAndTheNextFrameArrives) {
    serial::PtyPair pty;
    ScriptedAdapter adapter(pty.port(), [](const std::string& l) { return lawicel(l); });
    auto o = fast_opts();
    o.partial_line_timeout = 30ms;
    SlcanBus bus(pty.open_slave(), o);
    adapter.inject(std::string(500, '7') + "\rt12G0\rt8000\rt1239\rQ\r");
    adapter.inject("t1232CAFE\r");
    auto got = bus.recv(2s);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->id, 0x123u);
    EXPECT_EQ(got->data[1], 0xFE);
    auto c = bus.counters();
    EXPECT_EQ(c.overruns, 1u);      // L1
    EXPECT_EQ(c.parse_errors, 3u);  // L3, L8, L5
    EXPECT_EQ(c.ignored, 1u);       // L11
    // L2: a partial line with no CR is dropped after the quiet period ...
    adapter.inject("t45");
    ASSERT_TRUE(eventually([&] { return bus.stats().partial_lines_dropped == 1; }));
    // ... and does not prefix the next line.
    adapter.inject("t4561AB\r");
    got = bus.recv(2s);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->id, 0x456u);
    EXPECT_EQ(got->data[0], 0xAB);
}

namespace {
// An in-memory port whose "cable" can be pulled: read() then throws LinkDown.
class FakePort : public serial::Port {
public:
    explicit FakePort(std::function<std::string(const std::string&)> script) : script_(std::move(script)) {}
    void write(std::span<const std::uint8_t> b) override {
        std::lock_guard lock(m_);
        if (closed_) throw ClosedError("fake: closed");
        if (unplugged_) throw LinkDown("fake: EIO");
        for (auto c : b) {
            if (c == '\r') {
                rx_ += script_(line_);
                written_.push_back(line_);
                line_.clear();
            } else {
                line_.push_back(static_cast<char>(c));
            }
        }
        cv_.notify_all();
    }
    std::size_t read(std::span<std::uint8_t> buf, serial::Duration t) override {
        std::unique_lock lock(m_);
        cv_.wait_for(lock, t, [&] { return closed_ || unplugged_ || !rx_.empty(); });
        if (closed_) throw ClosedError("fake: closed");
        if (unplugged_) throw LinkDown("fake: EIO");
        std::size_t n = std::min(buf.size(), rx_.size());
        std::copy_n(rx_.begin(), n, buf.begin());
        rx_.erase(0, n);
        return n;
    }
    void flush_input() override {}
    void close() override {
        std::lock_guard lock(m_);
        closed_ = true;
        cv_.notify_all();
    }
    std::string name() const override { return "fake"; }
    void unplug() {
        std::lock_guard lock(m_);
        unplugged_ = true;
        cv_.notify_all();
    }
    void inject(const std::string& s) {
        std::lock_guard lock(m_);
        rx_ += s;
        cv_.notify_all();
    }

private:
    std::function<std::string(const std::string&)> script_;
    std::mutex m_;
    std::condition_variable cv_;
    std::string rx_, line_;
    std::vector<std::string> written_;
    bool closed_ = false, unplugged_ = false;
};
}  // namespace

TEST(SlcanBus, L14_LinkDownSurfacesAndReconnectsWithBackoff) {
    auto first = std::make_shared<FakePort>([](const std::string& l) { return lawicel(l); });
    std::atomic<int> attempts{0};
    std::atomic<bool> plugged{false};
    std::shared_ptr<FakePort> second;
    std::mutex sm;
    auto o = fast_opts();
    o.reconnect_min = 20ms;
    o.reconnect_max = 80ms;
    SlcanBus bus(first, o, [&]() -> std::shared_ptr<serial::Port> {
        ++attempts;
        if (!plugged) throw LinkDown("no such device");
        std::lock_guard lock(sm);
        second = std::make_shared<FakePort>([](const std::string& l) { return lawicel(l); });
        return second;
    });
    EXPECT_EQ(bus.state(), BusState::Active);
    first->unplug();
    ASSERT_TRUE(eventually([&] { return !bus.link_up(); }));
    EXPECT_EQ(bus.state(), BusState::LinkDown);  // not "active" while the adapter is gone
    EXPECT_THROW(bus.send(Frame::make(1, std::vector<std::uint8_t>{})), LinkDown);
    EXPECT_EQ(bus.stats().link_downs, 1u);
    // No busy loop: with a 20-80 ms backoff, 300 ms allows a handful of tries.
    std::this_thread::sleep_for(300ms);
    EXPECT_GE(attempts.load(), 2);
    EXPECT_LE(attempts.load(), 10);
    plugged = true;
    ASSERT_TRUE(eventually([&] { return bus.link_up(); }));
    EXPECT_EQ(bus.stats().reconnects, 1u);
    EXPECT_EQ(bus.state(), BusState::Active);
    bus.send(Frame::make(0x42, std::vector<std::uint8_t>{7}));
    bus.flush_tx(2s);
    {
        std::lock_guard lock(sm);
        second->inject("t0431AB\r");
    }
    auto got = bus.recv(2s);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->id, 0x43u);
}

TEST(SlcanBus, L14_PtyHangupIsLinkDownWithoutReconnectFactory) {
    auto pty = std::make_unique<serial::PtyPair>();
    auto adapter = std::make_unique<ScriptedAdapter>(pty->port(), [](const std::string& l) { return lawicel(l); });
    SlcanBus bus(pty->open_slave(), fast_opts());
    adapter.reset();  // closes the master: the slave reads EIO (USB unplug)
    pty.reset();
    ASSERT_TRUE(eventually([&] { return !bus.link_up(); }));
    EXPECT_EQ(bus.state(), BusState::LinkDown);
    EXPECT_STREQ(to_string(bus.state()), "link-down");
    EXPECT_THROW(bus.send(Frame::make(1, std::vector<std::uint8_t>{})), LinkDown);
    bus.close();  // returns promptly: the receive thread waits, it does not spin
    EXPECT_EQ(bus.state(), BusState::Closed);
}

TEST(SlcanServer, TimestampedLinesReachSlcanBusIntact) {
    auto hub = "slcan-test-" + std::to_string(::getpid()) + "-c";
    auto inner = open_virtual(hub);
    auto peer = open_virtual(hub);
    SlcanServer server(inner);
    auto o = fast_opts();
    o.timestamps = true;  // Z1: the server appends ssss to every forwarded line (L7 accepts 4)
    auto bus = open_slcan(server.pty_path(), 125000, o);
    for (std::uint32_t id : {0x1u, 0x7FFu}) peer->send(Frame::make(id, std::vector<std::uint8_t>{0x5A, 0xA5}));
    peer->send(Frame::make(0x1ABCDEF, std::vector<std::uint8_t>{}, true, true, 2));
    for (std::uint32_t id : {0x1u, 0x7FFu}) {
        auto got = bus->recv(2s);
        ASSERT_TRUE(got);
        EXPECT_EQ(got->id, id);
        EXPECT_EQ(got->len, 2);
        EXPECT_EQ(got->data[0], 0x5A);
        EXPECT_EQ(got->data[1], 0xA5);
    }
    auto rtr = bus->recv(2s);
    ASSERT_TRUE(rtr);
    EXPECT_TRUE(rtr->rtr && rtr->extended);
    EXPECT_EQ(rtr->id, 0x1ABCDEFu);
    EXPECT_EQ(bus->counters().parse_errors, 0u);
}

TEST(SlcanBus, BurstsAreBatchedInOrderAndIsolatedFramesStillGoStraightOut) {
    auto hub = "slcan-test-" + std::to_string(::getpid()) + "-d";
    auto inner = open_virtual(hub);
    VirtualOptions vo;
    vo.rx_queue_size = 100000;
    auto peer = open_virtual(hub, vo);
    SlcanServer server(inner);
    auto o = fast_opts();
    o.wait_for_acks = false;  // no window: the burst goes as fast as it can
    auto bus = open_slcan(server.pty_path(), 500000, o);
    ASSERT_TRUE(eventually([&] { return server.is_open(); }));
    constexpr std::uint32_t kN = 5000;
    for (std::uint32_t i = 0; i < kN; ++i)
        bus->send(Frame::make(i % 0x800, std::vector<std::uint8_t>{static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8)}));
    bus->flush_tx(5s);
    for (std::uint32_t i = 0; i < kN; ++i) {
        auto got = peer->recv(5s);
        ASSERT_TRUE(got) << "frame " << i;
        ASSERT_EQ(got->id, i % 0x800);
        ASSERT_EQ(got->data[0] | (got->data[1] << 8), static_cast<int>(i & 0xFFFF));
    }
    EXPECT_EQ(bus->counters().tx_dropped, 0u);
    // A lone frame after a pause is written directly and still arrives.
    std::this_thread::sleep_for(5ms);
    bus->send(Frame::make(0x7AB, std::vector<std::uint8_t>{0x01}));
    auto got = peer->recv(2s);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->id, 0x7ABu);
}

// ---- line endings on real ptys: LF and NUL are separators (docs/slcan.md) ----

TEST(SlcanServer, CrLfHostWithNulPadsLosesNoFrameAndGetsNoBel) {
    // A CR LF host used to lose every second frame: the LF led the next
    // command, which the adapter answered with BEL and never transmitted.
    auto hub = "slcan-test-" + std::to_string(::getpid()) + "-crlf";
    auto inner = open_virtual(hub);
    auto peer = open_virtual(hub);
    SlcanServer server(inner);
    auto tty = serial::open_port(server.pty_path(), 0);
    constexpr int kFrames = 100;
    std::string out = "C\r\nS6\r\nO\r\n";
    for (int i = 0; i < kFrames; ++i) {
        char line[32];
        // CR LF, LF alone and NUL pads mixed, as different hosts send them.
        const char* end = i % 3 == 0 ? "\r\n" : i % 3 == 1 ? "\n" : "\r\n\0\0";
        std::snprintf(line, sizeof line, "t%03X2%02X%02X", 0x100 + i, i, 0xFF - i);
        out += line;
        out.append(end, i % 3 == 2 ? 4 : std::strlen(end));
    }
    tty->write(bytes_of(out));
    std::string replies;
    std::array<std::uint8_t, 512> buf;
    const std::size_t want = 3 + kFrames;  // C (BEL: closed), S6, O, then z per frame
    auto end = std::chrono::steady_clock::now() + 5s;
    while (std::chrono::steady_clock::now() < end &&
           static_cast<std::size_t>(std::count_if(replies.begin(), replies.end(),
                                                  [](char c) { return c == '\r' || c == '\a'; })) < want) {
        std::size_t n = tty->read(buf, 50ms);
        replies.append(reinterpret_cast<char*>(buf.data()), n);
    }
    std::string expected = "\a\r\r";
    for (int i = 0; i < kFrames; ++i) expected += "z\r";
    EXPECT_EQ(replies, expected);
    for (int i = 0; i < kFrames; ++i) {
        auto got = peer->recv(2s);
        ASSERT_TRUE(got.has_value()) << "frame " << i << " lost";
        EXPECT_EQ(got->id, static_cast<std::uint32_t>(0x100 + i));
        ASSERT_EQ(got->len, 2);
        EXPECT_EQ(got->data[0], i);
        EXPECT_EQ(got->data[1], 0xFF - i);
    }
    auto s = server.stats();
    EXPECT_EQ(s.transmitted, static_cast<std::uint64_t>(kFrames));
    EXPECT_EQ(s.invalid_commands, 1u);  // only the C while closed
}

TEST(SlcanBus, AdapterEndingLinesWithCrLfAndNulPadsIsDecodedWithoutErrors) {
    serial::PtyPair pty;
    // An adapter that ends every reply and frame with CR LF.
    ScriptedAdapter adapter(pty.port(), [](const std::string& l) { return lawicel(l) + "\n"; });
    SlcanBus bus(pty.open_slave(), fast_opts());
    for (int i = 0; i < 20; ++i) bus.send(Frame::make(0x200 + i, std::vector<std::uint8_t>{static_cast<std::uint8_t>(i)}));
    bus.flush_tx(2s);  // every z\r\n acknowledged one frame
    using namespace std::string_literals;
    adapter.inject("t1232CAFE\r\n\0\0t456110\r\n\0T1FFFFFFF0\n"s);
    for (std::uint32_t id : {0x123u, 0x456u, 0x1FFFFFFFu}) {
        auto got = bus.recv(2s);
        ASSERT_TRUE(got.has_value()) << std::hex << id;
        EXPECT_EQ(got->id, id);
    }
    auto c = bus.counters();
    EXPECT_EQ(c.parse_errors, 0u);
    EXPECT_EQ(c.ignored, 0u);
    EXPECT_EQ(c.bus_errors, 0u);
    EXPECT_EQ(c.tx_dropped, 0u);
    EXPECT_EQ(bus.stats().acks, 20u);
    EXPECT_EQ(bus.stats().nacks, 0u);
}

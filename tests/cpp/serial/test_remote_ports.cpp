// socket:// and rfc2217:// lines (TcpPort, Rfc2217Port, open_port) against
// TCP servers written here: a raw one and a minimal RFC 2217 one.  The RFC 2217
// server parses the Telnet stream byte by byte on its own (not with the
// client's Parser), so the two sides check each other.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/serial/port.hpp"
#include "motorbus/serial/remote_port.hpp"
#include "motorbus/serial/telnet.hpp"

using namespace motorbus;
using namespace motorbus::serial;
using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

namespace {

std::span<const std::uint8_t> as_bytes(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

std::string read_exact(Port& p, std::size_t n, Duration timeout = 5s) {
    std::string out;
    std::uint8_t buf[512];
    auto deadline = std::chrono::steady_clock::now() + timeout;
    while (out.size() < n && std::chrono::steady_clock::now() < deadline) {
        std::size_t got = p.read(std::span(buf, std::min(sizeof buf, n - out.size())), 50ms);
        out.append(reinterpret_cast<const char*>(buf), got);
    }
    return out;
}

void send_all(int fd, const Bytes& b) {
    std::size_t done = 0;
    while (done < b.size()) {
        ssize_t n = ::send(fd, b.data() + done, b.size() - done, MSG_NOSIGNAL);
        if (n <= 0) return;
        done += static_cast<std::size_t>(n);
    }
}
void send_all(int fd, const std::string& s) { send_all(fd, Bytes(s.begin(), s.end())); }

// Listens on 127.0.0.1 (a free port) and runs `session` on the first connection
// in a thread.  The session gets the socket and a stop flag.
class TestServer {
public:
    using Session = std::function<void(int fd, const std::atomic<bool>& stop)>;
    explicit TestServer(Session session) : session_(std::move(session)) {
        listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        int one = 1;
        ::setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (::bind(listener_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(listener_, 4) != 0)
            throw std::runtime_error("test server: cannot listen");
        socklen_t len = sizeof a;
        ::getsockname(listener_, reinterpret_cast<sockaddr*>(&a), &len);
        port_ = ntohs(a.sin_port);
        thread_ = std::thread([this] {
            pollfd p{listener_, POLLIN, 0};
            while (!stop_.load()) {
                if (::poll(&p, 1, 20) <= 0) continue;
                int fd = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
                if (fd < 0) continue;
                conn_.store(fd);
                session_(fd, stop_);
                if (!keep_open_.load()) drop();
                return;
            }
        });
    }
    ~TestServer() {
        stop_.store(true);
        thread_.join();
        drop();
        ::close(listener_);
    }
    std::uint16_t port() const { return port_; }
    std::string url(const std::string& scheme) const { return scheme + "://127.0.0.1:" + std::to_string(port_); }
    // Closes the connection (FIN), or with `reset` aborts it (RST).
    void drop(bool reset = false) {
        int fd = conn_.exchange(-1);
        if (fd < 0) return;
        if (reset) {
            linger l{1, 0};
            ::setsockopt(fd, SOL_SOCKET, SO_LINGER, &l, sizeof l);
        }
        ::close(fd);
    }
    void keep_open() { keep_open_.store(true); }

private:
    Session session_;
    int listener_ = -1;
    std::uint16_t port_ = 0;
    std::atomic<int> conn_{-1};
    std::atomic<bool> stop_{false};
    std::atomic<bool> keep_open_{false};
    std::thread thread_;
};

// Reads what is available (up to 20 ms), "" when nothing came or the peer left.
std::string server_read(int fd) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) return {};
    char buf[1024];
    ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

// Raw: answers each CR-terminated request with "R:<request>\r\n".
void line_echo(int fd, const std::atomic<bool>& stop) {
    std::string acc;
    while (!stop.load()) {
        acc += server_read(fd);
        for (auto cr = acc.find('\r'); cr != std::string::npos; cr = acc.find('\r')) {
            send_all(fd, "R:" + acc.substr(0, cr) + "\r\n");
            acc.erase(0, cr + 1);
        }
    }
}

// A minimal RFC 2217 access server: agrees to BINARY, SGA and COM-PORT-OPTION,
// acknowledges each COM-PORT command with its value (or with `baud_override`
// for SET-BAUDRATE), and echoes data back, IAC-escaped.
struct Rfc2217Server {
    std::mutex m;
    std::condition_variable cv;
    std::vector<std::uint32_t> bauds;  // every SET-BAUDRATE value received
    Bytes settings;                    // datasize, parity, stopsize as received
    Bytes data;                        // data bytes received, unescaped
    Bytes negotiation;                 // every IAC verb option triple received
    std::optional<std::uint32_t> baud_override;
    bool refuse_com_port = false;
    Bytes greeting;  // sent right after accept (server-initiated Telnet traffic)
    Bytes before_echo;  // inserted into every echo (commands in the data stream)
    std::atomic<bool> hangup{false};  // ends the session: the server closes the connection

    void run(int fd, const std::atomic<bool>& stop) {
        using namespace telnet;
        if (!greeting.empty()) send_all(fd, greeting);
        enum { D, I, V, SBO, SBD, SBI } st = D;
        std::uint8_t verb = 0;
        Bytes sb;
        while (!stop.load() && !hangup.load()) {
            std::string in = server_read(fd);
            Bytes echo;
            Bytes out;
            for (char ch : in) {
                auto b = static_cast<std::uint8_t>(ch);
                switch (st) {
                case D:
                    if (b == IAC) st = I;
                    else echo.push_back(b);
                    break;
                case I:
                    if (b == IAC) {
                        echo.push_back(IAC);
                        st = D;
                    } else if (b == SB) {
                        st = SBO;
                    } else if (b >= WILL && b <= DONT) {
                        verb = b;
                        st = V;
                    } else {
                        st = D;
                    }
                    break;
                case V: {
                    {
                        std::lock_guard lk(m);
                        negotiation.insert(negotiation.end(), {IAC, verb, b});
                    }
                    const bool ours = b == OPT_BINARY || b == OPT_SGA || (b == OPT_COM_PORT && !refuse_com_port);
                    if (verb == WILL) out.insert(out.end(), {IAC, ours ? DO : DONT, b});
                    if (verb == DO) out.insert(out.end(), {IAC, ours && b != OPT_COM_PORT ? WILL : WONT, b});
                    st = D;
                    break;
                }
                case SBO:
                    sb = {b};
                    st = SBD;
                    break;
                case SBD:
                    if (b == IAC) st = SBI;
                    else sb.push_back(b);
                    break;
                case SBI:
                    if (b == IAC) {
                        sb.push_back(IAC);
                        st = SBD;
                        break;
                    }
                    st = D;
                    if (sb.size() < 2 || sb[0] != OPT_COM_PORT) break;
                    {
                        std::lock_guard lk(m);
                        const std::uint8_t cmd = sb[1];
                        Bytes value(sb.begin() + 2, sb.end());
                        if (cmd == rfc2217::SET_BAUDRATE && value.size() == 4) {
                            std::uint32_t v = (std::uint32_t{value[0]} << 24) | (std::uint32_t{value[1]} << 16) |
                                              (std::uint32_t{value[2]} << 8) | value[3];
                            bauds.push_back(v);
                            if (baud_override) v = *baud_override;
                            if (v == 0) v = 9600;  // the query: our current rate
                            value = {static_cast<std::uint8_t>(v >> 24), static_cast<std::uint8_t>(v >> 16),
                                     static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v)};
                        } else if (!value.empty()) {
                            settings.push_back(value[0]);
                        }
                        auto ack = rfc2217::command(static_cast<std::uint8_t>(cmd + rfc2217::SERVER_OFFSET), value);
                        out.insert(out.end(), ack.begin(), ack.end());
                    }
                    break;
                }
            }
            if (!echo.empty()) {
                {
                    std::lock_guard lk(m);
                    data.insert(data.end(), echo.begin(), echo.end());
                }
                out.insert(out.end(), before_echo.begin(), before_echo.end());
                auto esc = telnet::escape(echo);
                out.insert(out.end(), esc.begin(), esc.end());
            }
            if (!out.empty()) send_all(fd, out);
            cv.notify_all();
        }
    }

    template <class Pred>
    bool wait(Pred pred) {
        std::unique_lock lk(m);
        return cv.wait_for(lk, 5s, pred);
    }
};

std::string all_bytes() {
    std::string s;
    for (int i = 0; i < 256; ++i) s.push_back(static_cast<char>(i));
    return s;
}

}  // namespace

// ---- URLs ---------------------------------------------------------------------------

TEST(RemoteUrl, DevicePathsAreNotUrls) {
    EXPECT_FALSE(parse_remote_url("/dev/ttyUSB0"));
    EXPECT_FALSE(parse_remote_url("/dev/pts/3"));
}

TEST(RemoteUrl, ParsesHostAndPort) {
    auto a = parse_remote_url("socket://gateway.lab:7000");
    ASSERT_TRUE(a);
    EXPECT_EQ(a->scheme, RemoteAddress::Scheme::Socket);
    EXPECT_EQ(a->host, "gateway.lab");
    EXPECT_EQ(a->port, 7000);
    auto b = parse_remote_url("rfc2217://[::1]:2217");
    ASSERT_TRUE(b);
    EXPECT_EQ(b->scheme, RemoteAddress::Scheme::Rfc2217);
    EXPECT_EQ(b->host, "::1");
    EXPECT_EQ(b->port, 2217);
}

TEST(RemoteUrl, BadUrlsAreInvalidArgumentNamingThem) {
    for (std::string bad : {"socket://host", "socket://:7000", "socket://host:0", "socket://host:65536",
                            "socket://host:70x", "socket://::1:7000", "rfc2217://[::1]7000", "socket://h:1/path",
                            "telnet://host:23", "ftp://x:1"}) {
        try {
            open_port(bad, 9600);
            ADD_FAILURE() << bad << " was accepted";
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
        }
    }
}

TEST(RemoteUrl, ConnectionRefusedIsLinkDownNamingHostPort) {
    std::uint16_t port;
    {
        TestServer gone([](int, const std::atomic<bool>&) {});
        port = gone.port();
    }  // nothing listens there any more
    const std::string hp = "127.0.0.1:" + std::to_string(port);
    for (std::string scheme : {"socket", "rfc2217"}) {
        try {
            open_port(scheme + "://" + hp, 9600);
            ADD_FAILURE() << "connected to a closed port";
        } catch (const LinkDown& e) {
            EXPECT_NE(std::string(e.what()).find(hp), std::string::npos) << e.what();
        }
    }
}

// ---- socket:// ----------------------------------------------------------------------

TEST(TcpPort, EveryByteValuePassesUnchanged) {
    TestServer server([](int fd, const std::atomic<bool>& stop) {
        while (!stop.load()) {
            auto s = server_read(fd);
            if (!s.empty()) send_all(fd, s);
        }
    });
    auto port = open_port(server.url("socket"), 9600);  // baud: ignored for raw lines
    ASSERT_TRUE(std::dynamic_pointer_cast<TcpPort>(port));
    EXPECT_FALSE(std::dynamic_pointer_cast<Rfc2217Port>(port));
    EXPECT_EQ(port->name(), server.url("socket"));
    const auto all = all_bytes();
    port->write(as_bytes(all));
    EXPECT_EQ(read_exact(*port, all.size()), all);
}

TEST(TcpPort, ReadTimesOutWithZero) {
    TestServer server([](int, const std::atomic<bool>& stop) {
        while (!stop.load()) std::this_thread::sleep_for(5ms);
    });
    auto port = open_port(server.url("socket"), 0);
    std::uint8_t buf[8];
    EXPECT_EQ(port->read(buf, 20ms), 0u);
    EXPECT_EQ(port->read(buf, 0ns), 0u);
}

TEST(TcpPort, LineLinkTransactsOverTcp) {
    TestServer server(line_echo);
    LineOptions o;
    o.reply_timeout = 5s;
    LineLink link(open_port(server.url("socket"), 0), o);
    EXPECT_EQ(link.transact("hello"), "R:hello");
    EXPECT_EQ(link.transact("again"), "R:again");
}

TEST(TcpPort, FlushInputDropsWhatHasArrived) {
    TestServer server([&](int fd, const std::atomic<bool>& stop) {
        send_all(fd, "stale");
        while (!stop.load()) {
            if (server_read(fd) == "go") {
                send_all(fd, "fresh");
                return;
            }
        }
    });
    server.keep_open();
    auto port = open_port(server.url("socket"), 0);
    EXPECT_EQ(read_exact(*port, 1), "s");  // "tale" is now buffered on our side
    port->flush_input();
    port->write(as_bytes("go"));
    EXPECT_EQ(read_exact(*port, 5), "fresh");
}

TEST(TcpPort, ServerClosingIsLinkDownNamingThePeer) {
    TestServer server([](int fd, const std::atomic<bool>&) { send_all(fd, "last words"); });
    auto port = open_port(server.url("socket"), 0);
    // What arrived before the close is still delivered, then LinkDown.
    EXPECT_EQ(read_exact(*port, 10), "last words");
    std::uint8_t buf[8];
    try {
        port->read(buf, 5s);
        ADD_FAILURE() << "no LinkDown";
    } catch (const LinkDown& e) {
        EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(server.port())), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(port->write(as_bytes("x")), LinkDown);  // and it stays down
}

TEST(TcpPort, ResetConnectionIsLinkDown) {
    std::atomic<bool> accepted{false};
    TestServer server([&](int, const std::atomic<bool>&) { accepted.store(true); });
    server.keep_open();
    auto port = open_port(server.url("socket"), 0);
    while (!accepted.load()) std::this_thread::sleep_for(1ms);
    server.drop(/*reset=*/true);
    // The first write may still be taken by the kernel; reads and later writes see the reset.
    bool down = false;
    for (int i = 0; i < 100 && !down; ++i) {
        try {
            port->write(as_bytes("ping\r"));
            std::uint8_t buf[8];
            port->read(buf, 50ms);
        } catch (const LinkDown&) {
            down = true;
        }
    }
    EXPECT_TRUE(down);
}

TEST(TcpPort, CloseWakesBlockedReader) {
    TestServer server([](int, const std::atomic<bool>& stop) {
        while (!stop.load()) std::this_thread::sleep_for(5ms);
    });
    auto port = open_port(server.url("socket"), 0);
    std::atomic<bool> entered{false};
    std::thread t([&] {
        std::uint8_t buf[8];
        entered.store(true);
        EXPECT_THROW(port->read(buf, Duration(-1)), ClosedError);
    });
    while (!entered.load()) std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(10ms);  // let it block (either way it must end in ClosedError)
    port->close();
    t.join();
    std::uint8_t buf[8];
    EXPECT_THROW(port->read(buf, 0ns), ClosedError);
    EXPECT_THROW(port->write(as_bytes("x")), ClosedError);
}

TEST(TcpPort, ConcurrentReaderAndWriter) {
    TestServer server(line_echo);
    auto port = open_port(server.url("socket"), 0);
    constexpr int kLines = 200;
    std::string expected;
    for (int i = 0; i < kLines; ++i) expected += "R:" + std::to_string(i) + "\r\n";
    std::thread writer([&] {
        for (int i = 0; i < kLines; ++i) port->write(as_bytes(std::to_string(i) + "\r"));
    });
    EXPECT_EQ(read_exact(*port, expected.size(), 10s), expected);
    writer.join();
}

// ---- rfc2217:// ---------------------------------------------------------------------

TEST(Rfc2217Port, OpenSendsBaudAnd8N1AndWaitsForTheAcks) {
    Rfc2217Server s;
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    auto port = open_port(server.url("rfc2217"), 19200);
    auto rfc = std::dynamic_pointer_cast<Rfc2217Port>(port);
    ASSERT_TRUE(rfc);
    EXPECT_EQ(rfc->baud(), 19200u);
    {
        std::lock_guard lk(s.m);
        EXPECT_EQ(s.bauds, (std::vector<std::uint32_t>{19200}));
        EXPECT_EQ(s.settings, (Bytes{8, rfc2217::PARITY_NONE, rfc2217::STOPSIZE_1}));
        // The client asked for COM-PORT-OPTION, binary and SGA both ways.
        auto has = [&](std::uint8_t verb, std::uint8_t opt) {
            for (std::size_t i = 0; i + 2 < s.negotiation.size(); i += 3)
                if (s.negotiation[i + 1] == verb && s.negotiation[i + 2] == opt) return true;
            return false;
        };
        EXPECT_TRUE(has(telnet::WILL, telnet::OPT_COM_PORT));
        EXPECT_TRUE(has(telnet::WILL, telnet::OPT_BINARY));
        EXPECT_TRUE(has(telnet::DO, telnet::OPT_BINARY));
        EXPECT_TRUE(has(telnet::WILL, telnet::OPT_SGA));
        EXPECT_TRUE(has(telnet::DO, telnet::OPT_SGA));
    }
    rfc->set_baud(115200);
    EXPECT_EQ(rfc->baud(), 115200u);
    std::lock_guard lk(s.m);
    EXPECT_EQ(s.bauds.back(), 115200u);
}

TEST(Rfc2217Port, BaudZeroAsksTheServer) {
    Rfc2217Server s;
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    auto port = std::dynamic_pointer_cast<Rfc2217Port>(open_port(server.url("rfc2217"), 0));
    ASSERT_TRUE(port);
    EXPECT_EQ(port->baud(), 9600u);  // what the server runs at
    std::lock_guard lk(s.m);
    EXPECT_EQ(s.bauds, (std::vector<std::uint32_t>{0}));
}

TEST(Rfc2217Port, EveryByteValuePassesIncludingIac) {
    Rfc2217Server s;
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    auto port = open_port(server.url("rfc2217"), 9600);
    const auto all = all_bytes() + "\xff\xff";
    port->write(as_bytes(all));
    EXPECT_EQ(read_exact(*port, all.size()), all);
    // The server saw each 0xFF once: the client escaped them as IAC IAC.
    ASSERT_TRUE(s.wait([&] { return s.data.size() >= all.size(); }));
    std::lock_guard lk(s.m);
    EXPECT_EQ(std::string(s.data.begin(), s.data.end()), all);
}

TEST(Rfc2217Port, TelnetCommandsInTheStreamAreStrippedAndAnswered) {
    using namespace telnet;
    Rfc2217Server s;
    // The server asks for ECHO and TERMINAL-TYPE (refused), and sprinkles NOPs,
    // a foreign subnegotiation and a line-state notification into the data.
    s.greeting = {IAC, WILL, 1, IAC, DO, 24};
    s.before_echo = {IAC, NOP, IAC, SB, 24, 1, IAC, SE, IAC, SB, OPT_COM_PORT, 106, 0x60, IAC, SE};
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    LineOptions o;
    o.reply_timeout = 5s;
    o.reply_terminators = {"\r"};
    LineLink link(open_port(server.url("rfc2217"), 9600), o);
    EXPECT_EQ(link.transact("@01VER"), "@01VER");  // echoed, commands gone
    EXPECT_EQ(link.transact("\xff"), "\xff");
    ASSERT_TRUE(s.wait([&] {
        auto& n = s.negotiation;
        auto has = [&](std::uint8_t verb, std::uint8_t opt) {
            for (std::size_t i = 0; i + 2 < n.size(); i += 3)
                if (n[i + 1] == verb && n[i + 2] == opt) return true;
            return false;
        };
        return has(DONT, 1) && has(WONT, 24);
    }));
}

TEST(Rfc2217Port, WrongBaudFromTheServerIsInvalidArgument) {
    Rfc2217Server s;
    s.baud_override = 9600;
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    try {
        open_port(server.url("rfc2217"), 250000);
        ADD_FAILURE() << "accepted";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("250000"), std::string::npos) << e.what();
    }
}

TEST(Rfc2217Port, RefusedComPortOptionIsProtocolError) {
    Rfc2217Server s;
    s.refuse_com_port = true;
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    EXPECT_THROW(open_port(server.url("rfc2217"), 9600), ProtocolError);
}

TEST(Rfc2217Port, ASilentServerIsTimeoutError) {
    // A raw port given as rfc2217:// (or anything not speaking Telnet).
    TestServer server([](int fd, const std::atomic<bool>& stop) {
        while (!stop.load()) server_read(fd);
    });
    RemoteOptions o;
    o.ack_timeout = 100ms;
    try {
        Rfc2217Port port(*parse_remote_url(server.url("rfc2217")), 9600, o);
        ADD_FAILURE() << "opened";
    } catch (const TimeoutError& e) {
        EXPECT_NE(std::string(e.what()).find("socket://"), std::string::npos) << e.what();  // the hint
    }
}

TEST(Rfc2217Port, SetBaudWhileAReaderBlocks) {
    // The reader owns the socket while it waits; the acknowledgement still
    // reaches set_baud, and the reader still gets its data.
    Rfc2217Server s;
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    auto port = std::dynamic_pointer_cast<Rfc2217Port>(open_port(server.url("rfc2217"), 9600));
    ASSERT_TRUE(port);
    std::string got;
    std::atomic<bool> entered{false};
    std::thread reader([&] {
        entered.store(true);
        got = read_exact(*port, 4, 10s);
    });
    while (!entered.load()) std::this_thread::sleep_for(1ms);
    port->set_baud(38400);
    EXPECT_EQ(port->baud(), 38400u);
    port->write(as_bytes("data"));
    reader.join();
    EXPECT_EQ(got, "data");
}

TEST(Rfc2217Port, ServerClosingIsLinkDown) {
    Rfc2217Server s;
    TestServer server([&](int fd, const std::atomic<bool>& stop) { s.run(fd, stop); });
    auto port = open_port(server.url("rfc2217"), 9600);
    s.hangup.store(true);
    std::uint8_t buf[8];
    EXPECT_THROW(port->read(buf, 5s), LinkDown);
}

// TcpPort and Rfc2217Port: serial lines over TCP (see remote_port.hpp).
#include "motorbus/serial/remote_port.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <shared_mutex>

#include "motorbus/serial/telnet.hpp"

namespace motorbus::serial {

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::string_view kSchemes = "socket://host:port or rfc2217://host:port";

std::optional<std::uint16_t> parse_tcp_port(std::string_view s) {
    unsigned v = 0;
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || v == 0 || v > 65535) return std::nullopt;
    return static_cast<std::uint16_t>(v);
}

int poll_timeout_ms(Clock::time_point deadline, bool forever) {
    if (forever) return -1;
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return 0;
    return left > 1000 ? 1000 : static_cast<int>(left) + 1;  // +1: never wake just before the deadline
}

struct AddrInfo {
    addrinfo* list = nullptr;
    ~AddrInfo() {
        if (list) ::freeaddrinfo(list);
    }
};

// Connects before `timeout`; returns a non-blocking socket.
int tcp_connect(const RemoteAddress& a, Duration timeout) {
    const std::string peer = a.host + ":" + std::to_string(a.port);
    AddrInfo ai;
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    const std::string service = std::to_string(a.port);
    if (int rc = ::getaddrinfo(a.host.c_str(), service.c_str(), &hints, &ai.list); rc != 0)
        throw LinkDown(a.url + ": cannot resolve host '" + a.host + "': " + ::gai_strerror(rc));
    const auto deadline = Clock::now() + timeout;
    std::string last_error = "no address";
    for (addrinfo* p = ai.list; p; p = p->ai_next) {
        int s = ::socket(p->ai_family, p->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, p->ai_protocol);
        if (s < 0) {
            last_error = std::strerror(errno);
            continue;
        }
        int err = 0;
        if (::connect(s, p->ai_addr, p->ai_addrlen) != 0) {
            err = errno;
            while (err == EINPROGRESS || err == EINTR) {
                pollfd pf{s, POLLOUT, 0};
                int n = ::poll(&pf, 1, poll_timeout_ms(deadline, false));
                if (n < 0 && errno == EINTR) continue;
                if (n == 0) {
                    if (Clock::now() < deadline) continue;
                    ::close(s);
                    throw TimeoutError(a.url + ": connecting to " + peer + " timed out after " +
                                       std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count()) +
                                       " ms");
                }
                socklen_t len = sizeof err;
                ::getsockopt(s, SOL_SOCKET, SO_ERROR, &err, &len);
                break;
            }
        }
        if (err == 0) return s;
        last_error = std::strerror(err);
        ::close(s);
    }
    throw LinkDown(a.url + ": cannot connect to " + peer + ": " + last_error);
}

}  // namespace

std::optional<RemoteAddress> parse_remote_url(const std::string& path) {
    const auto sep = path.find("://");
    if (sep == std::string::npos) return std::nullopt;
    const std::string scheme = path.substr(0, sep);
    RemoteAddress a{RemoteAddress::Scheme::Socket, {}, 0, path};
    if (scheme == "socket")
        a.scheme = RemoteAddress::Scheme::Socket;
    else if (scheme == "rfc2217")
        a.scheme = RemoteAddress::Scheme::Rfc2217;
    else
        throw InvalidArgument("serial line '" + path + "': unknown URL scheme '" + scheme + "' (a device path, " +
                              std::string(kSchemes) + ")");
    std::string_view rest(path);
    rest.remove_prefix(sep + 3);
    auto bad = [&](const std::string& why) {
        return InvalidArgument("serial line '" + path + "': " + why + " (expected " + std::string(kSchemes) + ")");
    };
    std::string_view host, port;
    if (!rest.empty() && rest.front() == '[') {  // [IPv6]:port
        const auto close = rest.find(']');
        if (close == std::string_view::npos || close + 1 >= rest.size() || rest[close + 1] != ':')
            throw bad("malformed [IPv6 address]:port");
        host = rest.substr(1, close - 1);
        port = rest.substr(close + 2);
    } else {
        const auto colon = rest.rfind(':');
        if (colon == std::string_view::npos) throw bad("no port");
        host = rest.substr(0, colon);
        port = rest.substr(colon + 1);
        if (host.find(':') != std::string_view::npos) throw bad("an IPv6 address needs brackets");
    }
    if (host.empty()) throw bad("no host");
    if (host.find_first_of("/?#@ ") != std::string_view::npos) throw bad("unexpected characters in the host");
    const auto p = parse_tcp_port(port);
    if (!p) throw bad("port '" + std::string(port) + "' is not a number in 1..65535");
    a.host = std::string(host);
    a.port = *p;
    return a;
}

// ---- TcpPort -------------------------------------------------------------------
//
// One reader and one writer may run at once (the Port contract), and the RFC
// 2217 subclass also waits for answers from the same socket.  Whoever needs
// bytes becomes the "pumper": it reads the socket without the state lock and
// hands what it read to on_received under it; everybody else waits on `cv` for
// the pumper's round to end.  So a set_baud() waiting for its acknowledgement
// and a read() blocked forever never both read the socket, and neither starves.

struct TcpPort::Impl {
    RemoteAddress address;
    RemoteOptions options;
    std::string peer;
    int fd = -1;
    int wake = -1;  // eventfd: signalled once by close(), never drained
    std::atomic<bool> closed{false};
    std::shared_mutex io;  // shared by every user of fd; exclusive to close it

    std::mutex m;  // guards what follows and on_received's state
    std::condition_variable cv;
    bool pumping = false;
    std::vector<std::uint8_t> pending;  // data read and not yet returned
    std::size_t pending_off = 0;
    std::optional<std::string> down;  // set once the connection is gone: the LinkDown text

    std::mutex wmu;  // one sender at a time (write() and protocol answers)

    void check_open() const {
        if (closed.load()) throw ClosedError(address.url + ": port closed");
    }

    std::string lost(const std::string& how) const { return address.url + ": connection to " + peer + " " + how; }
};

TcpPort::TcpPort(const RemoteAddress& address, RemoteOptions options) : impl_(std::make_unique<Impl>()) {
    impl_->address = address;
    impl_->options = options;
    impl_->peer = address.host + ":" + std::to_string(address.port);
    impl_->fd = tcp_connect(address, options.connect_timeout);
    int one = 1;
    ::setsockopt(impl_->fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    // A gateway that vanishes without a reset (power, cable) is noticed by
    // keepalive probes: ~10 s idle + 3 x 5 s, then reads raise LinkDown.
    int idle = 10, intvl = 5, cnt = 3;
    ::setsockopt(impl_->fd, SOL_SOCKET, SO_KEEPALIVE, &one, sizeof one);
    ::setsockopt(impl_->fd, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle);
    ::setsockopt(impl_->fd, IPPROTO_TCP, TCP_KEEPINTVL, &intvl, sizeof intvl);
    ::setsockopt(impl_->fd, IPPROTO_TCP, TCP_KEEPCNT, &cnt, sizeof cnt);
    impl_->wake = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (impl_->wake < 0) {
        int err = errno;
        ::close(impl_->fd);
        throw Error(std::string("eventfd: ") + std::strerror(err));
    }
}

TcpPort::~TcpPort() { close(); }

const std::string& TcpPort::peer() const { return impl_->peer; }
std::string TcpPort::name() const { return impl_->address.url; }
bool TcpPort::is_open() const { return !impl_->closed.load(); }
const RemoteOptions& TcpPort::options() const { return impl_->options; }

void TcpPort::on_received(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& data,
                          std::vector<std::uint8_t>&) {
    data.insert(data.end(), in.begin(), in.end());
}

std::vector<std::uint8_t> TcpPort::encode(std::span<const std::uint8_t> bytes) {
    return {bytes.begin(), bytes.end()};
}

void TcpPort::locked(const std::function<void()>& f) {
    std::lock_guard lk(impl_->m);
    f();
}

void TcpPort::send_raw(std::span<const std::uint8_t> bytes) {
    auto& d = *impl_;
    std::lock_guard lk(d.wmu);
    std::size_t done = 0;
    while (done < bytes.size()) {
        d.check_open();
        ssize_t n = ::send(d.fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n > 0) {
            done += static_cast<std::size_t>(n);
            continue;
        }
        const int err = n < 0 ? errno : EIO;
        if (err == EINTR) continue;
        if (err == EAGAIN || err == EWOULDBLOCK) {
            // The gateway is not taking bytes (its serial side is slower than
            // us): wait for room, or for close().
            pollfd fds[2] = {{d.fd, POLLOUT, 0}, {d.wake, POLLIN, 0}};
            if (::poll(fds, 2, -1) < 0 && errno != EINTR) throw LinkDown(d.lost(std::string("poll: ") + std::strerror(errno)));
            if (fds[1].revents) throw ClosedError(d.address.url + ": port closed");
            continue;
        }
        std::string why = d.lost(std::string("lost (write: ") + std::strerror(err) + ")");
        {
            std::lock_guard sl(d.m);
            if (!d.down) d.down = why;
        }
        d.cv.notify_all();
        throw LinkDown(why);
    }
}

bool TcpPort::wait_until(const std::function<bool()>& done, Duration timeout) {
    auto& d = *impl_;
    const bool forever = timeout.count() < 0;
    const auto deadline = Clock::now() + (forever ? Duration::zero() : timeout);
    bool tried = false;  // one look at the socket even with a zero timeout
    std::unique_lock lk(d.m);
    for (;;) {
        if (done()) return true;
        if (d.closed.load()) throw ClosedError(d.address.url + ": port closed");
        if (d.down) throw LinkDown(*d.down);
        if (tried && !forever && Clock::now() >= deadline) return false;
        tried = true;
        if (d.pumping) {
            if (forever)
                d.cv.wait(lk);
            else
                d.cv.wait_until(lk, deadline);
            continue;
        }
        // Our turn to read the socket.
        d.pumping = true;
        lk.unlock();
        std::vector<std::uint8_t> answer;
        std::optional<std::string> failure;
        pollfd fds[2] = {{d.fd, POLLIN, 0}, {d.wake, POLLIN, 0}};
        int r = ::poll(fds, 2, poll_timeout_ms(deadline, forever));
        std::array<std::uint8_t, 4096> buf;
        ssize_t n = -1;
        int err = 0;
        if (r > 0 && fds[1].revents == 0 && fds[0].revents != 0) {
            n = ::recv(d.fd, buf.data(), buf.size(), MSG_DONTWAIT);
            err = n < 0 ? errno : 0;
        }
        lk.lock();
        d.pumping = false;
        try {
            if (n > 0)
                on_received({buf.data(), static_cast<std::size_t>(n)}, d.pending, answer);
            else if (n == 0)
                failure = d.lost("closed by the server");
            else if (err != 0 && err != EAGAIN && err != EWOULDBLOCK && err != EINTR)
                failure = d.lost(std::string("lost (") + std::strerror(err) + ")");
        } catch (...) {
            d.cv.notify_all();
            throw;
        }
        if (failure && !d.down) d.down = failure;
        d.cv.notify_all();
        if (!answer.empty()) {
            lk.unlock();
            try {
                send_raw(answer);
            } catch (const LinkDown&) {
                // Recorded in `down`; reported by the loop below (data first).
            }
            lk.lock();
        }
    }
}

std::size_t TcpPort::read(std::span<std::uint8_t> buf, Duration timeout) {
    if (buf.empty()) return 0;
    auto& d = *impl_;
    std::shared_lock io(d.io);
    d.check_open();
    std::size_t got = 0;
    // The data already read is returned before a LinkDown is reported.
    wait_until(
        [&] {
            const std::size_t avail = d.pending.size() - d.pending_off;
            if (avail == 0) return false;
            got = std::min(avail, buf.size());
            std::memcpy(buf.data(), d.pending.data() + d.pending_off, got);
            d.pending_off += got;
            if (d.pending_off == d.pending.size()) {
                d.pending.clear();
                d.pending_off = 0;
            }
            return true;
        },
        timeout);
    return got;
}

void TcpPort::write(std::span<const std::uint8_t> bytes) {
    auto& d = *impl_;
    std::shared_lock io(d.io);
    d.check_open();
    {
        std::lock_guard lk(d.m);
        if (d.down) throw LinkDown(*d.down);
    }
    if (bytes.empty()) return;
    send_raw(encode(bytes));
}

void TcpPort::flush_input() {
    auto& d = *impl_;
    std::shared_lock io(d.io);
    d.check_open();
    std::vector<std::uint8_t> answer;
    {
        std::lock_guard lk(d.m);
        d.pending.clear();
        d.pending_off = 0;
        if (!d.pumping && !d.down) {
            // What has already arrived on the socket goes too; protocol bytes
            // in it are still parsed (an acknowledgement must not be lost).
            std::array<std::uint8_t, 4096> buf;
            std::vector<std::uint8_t> discard;
            for (;;) {
                ssize_t n = ::recv(d.fd, buf.data(), buf.size(), MSG_DONTWAIT);
                if (n > 0) {
                    on_received({buf.data(), static_cast<std::size_t>(n)}, discard, answer);
                    discard.clear();
                    continue;
                }
                if (n < 0 && errno == EINTR) continue;
                if (n == 0) d.down = d.lost("closed by the server");
                else if (errno != EAGAIN && errno != EWOULDBLOCK)
                    d.down = d.lost(std::string("lost (") + std::strerror(errno) + ")");
                break;
            }
        }
    }
    if (!answer.empty()) {
        try {
            send_raw(answer);
        } catch (const LinkDown&) {
            // Recorded; the next read or write reports it.
        }
    }
}

void TcpPort::close() {
    if (!impl_ || impl_->closed.exchange(true)) return;
    auto& d = *impl_;
    std::uint64_t one = 1;
    [[maybe_unused]] auto w = ::write(d.wake, &one, sizeof one);
    {
        std::lock_guard lk(d.m);  // no waiter can miss the notification
    }
    d.cv.notify_all();
    std::unique_lock lk(d.io);  // waits for blocked readers/writers to leave
    ::close(d.fd);
    ::close(d.wake);
    d.fd = -1;
    d.wake = -1;
}

// ---- Rfc2217Port -----------------------------------------------------------------

namespace {
const std::vector<std::uint8_t> kAccepted = {telnet::OPT_BINARY, telnet::OPT_SGA, telnet::OPT_COM_PORT};
}

struct Rfc2217Port::State {
    telnet::Parser parser{kAccepted, kAccepted};
    // The server's latest answer to each client command (by command code).
    std::array<std::optional<std::vector<std::uint8_t>>, 256> answers;
    std::atomic<unsigned> baud{0};
    std::mutex control;  // one COM-PORT exchange at a time
};

Rfc2217Port::Rfc2217Port(const RemoteAddress& address, unsigned baud, RemoteOptions options)
    : TcpPort(address, options), st_(std::make_unique<State>()) {
    using namespace telnet;
    try {
        std::vector<std::uint8_t> hello;
        locked([&] {
            using Want = std::pair<Side, std::uint8_t>;
            for (auto [side, opt] : {Want{Side::Local, OPT_BINARY}, Want{Side::Remote, OPT_BINARY},
                                     Want{Side::Local, OPT_SGA}, Want{Side::Remote, OPT_SGA},
                                     Want{Side::Local, OPT_COM_PORT}}) {
                auto b = st_->parser.request(side, opt);
                hello.insert(hello.end(), b.begin(), b.end());
            }
        });
        send_raw(hello);
        // COM-PORT commands mean nothing before the server agreed to the option.
        if (!wait_until([&] { return !st_->parser.pending(Side::Local, OPT_COM_PORT); }, options.ack_timeout))
            throw TimeoutError(name() + ": no answer to the Telnet negotiation from " + peer() + " within " +
                               std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(options.ack_timeout).count()) +
                               " ms (is it a telnet(rfc2217) port? raw TCP ports are socket://)");
        bool on = false;
        locked([&] { on = st_->parser.enabled(Side::Local, OPT_COM_PORT); });
        if (!on)
            throw ProtocolError(name() + ": the server at " + peer() +
                                " refused COM-PORT-OPTION (RFC 2217): it cannot set the line's baud");
        set_baud(baud);
        using Setting = std::pair<std::uint8_t, std::uint8_t>;  // command, value
        for (auto [cmd, value] : {Setting{rfc2217::SET_DATASIZE, 8}, Setting{rfc2217::SET_PARITY, rfc2217::PARITY_NONE},
                                  Setting{rfc2217::SET_STOPSIZE, rfc2217::STOPSIZE_1}}) {
            auto got = exchange(cmd, rfc2217::set_byte(cmd, value));
            if (got.size() != 1 || got[0] != value)
                throw InvalidArgument(name() + ": the server at " + peer() + " did not set 8N1 (command " +
                                      std::to_string(cmd) + " answered " +
                                      (got.empty() ? std::string("nothing") : std::to_string(got[0])) + ")");
        }
    } catch (...) {
        close();
        throw;
    }
}

Rfc2217Port::~Rfc2217Port() { close(); }

void Rfc2217Port::on_received(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& data,
                              std::vector<std::uint8_t>& answer) {
    telnet::Output out;
    st_->parser.feed(in, out);
    data.insert(data.end(), out.data.begin(), out.data.end());
    answer.insert(answer.end(), out.answer.begin(), out.answer.end());
    for (auto& e : out.events) {
        if (e.kind != telnet::Event::Kind::Subnegotiation || e.option != telnet::OPT_COM_PORT) continue;
        // Notifications (line/modem state) and server requests are not needed
        // for a request/reply line; only the answers to our commands are kept.
        if (auto r = rfc2217::parse_reply(e.payload)) st_->answers[r->command] = std::move(r->value);
    }
}

std::vector<std::uint8_t> Rfc2217Port::encode(std::span<const std::uint8_t> bytes) { return telnet::escape(bytes); }

std::vector<std::uint8_t> Rfc2217Port::exchange(std::uint8_t cmd, const std::vector<std::uint8_t>& wire) {
    std::lock_guard ctl(st_->control);
    locked([&] { st_->answers[cmd].reset(); });
    send_raw(wire);
    std::vector<std::uint8_t> got;
    if (!wait_until(
            [&] {
                if (!st_->answers[cmd]) return false;
                got = *st_->answers[cmd];
                return true;
            },
            options().ack_timeout))
        throw TimeoutError(name() + ": the server at " + peer() + " did not acknowledge RFC 2217 command " +
                           std::to_string(cmd) + " within " +
                           std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(options().ack_timeout).count()) +
                           " ms");
    return got;
}

void Rfc2217Port::set_baud(unsigned baud) {
    // SET-BAUDRATE 0 is the RFC's query: the server answers its current rate.
    auto got = exchange(rfc2217::SET_BAUDRATE, rfc2217::set_baudrate(baud));
    auto rate = rfc2217::Reply{rfc2217::SET_BAUDRATE, got}.baud();
    if (!rate)
        throw ProtocolError(name() + ": the server at " + peer() + " answered SET-BAUDRATE with " +
                                std::to_string(got.size()) + " bytes instead of 4",
                            got);
    if (baud != 0 && *rate != baud)
        throw InvalidArgument(name() + ": baud " + std::to_string(baud) + " refused by the server at " + peer() +
                              " (it runs the line at " + std::to_string(*rate) + ")");
    st_->baud.store(*rate);
}

unsigned Rfc2217Port::baud() const { return st_->baud.load(); }

std::shared_ptr<Port> open_remote_port(const RemoteAddress& address, unsigned baud, RemoteOptions options) {
    if (address.scheme == RemoteAddress::Scheme::Rfc2217)
        return std::make_shared<Rfc2217Port>(address, baud, options);
    return std::make_shared<TcpPort>(address, options);  // raw: the gateway owns the baud
}

}  // namespace motorbus::serial

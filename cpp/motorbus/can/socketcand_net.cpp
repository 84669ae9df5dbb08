#include "motorbus/can/socketcand_net.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "motorbus/errors.hpp"
#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::can::net {

Fd& Fd::operator=(Fd&& o) noexcept {
    if (this != &o) reset(o.release());
    return *this;
}

void Fd::reset(int fd) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = fd;
}

void set_nonblocking(int fd) {
    int fl = ::fcntl(fd, F_GETFL, 0);
    if (fl >= 0) ::fcntl(fd, F_SETFL, fl | O_NONBLOCK);
}

void set_nodelay(int fd) {
    int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

void set_tcp_keepalive(int fd, std::chrono::seconds idle, std::chrono::seconds interval, int count) {
    int one = 1;
    int idle_s = static_cast<int>(std::max<std::int64_t>(1, idle.count()));
    int intvl_s = static_cast<int>(std::max<std::int64_t>(1, interval.count()));
    int cnt = count < 1 ? 1 : count;
    ::setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &one, sizeof one);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &idle_s, sizeof idle_s);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &intvl_s, sizeof intvl_s);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &cnt, sizeof cnt);
}

int poll_ms_until(Deadline d, int cap) {
    // A caller with an interrupt check (Python's main thread: Ctrl-C) polls in
    // slices and runs the check between them (interruption_point()).
    if (interruptible()) cap = std::min<int>(cap, static_cast<int>(kInterruptSlice.count()));
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(d - std::chrono::steady_clock::now());
    if (left.count() <= 0) return 0;
    return left.count() > cap ? cap : static_cast<int>(left.count()) + 1;
}

namespace {

struct AddrInfo {
    addrinfo* list = nullptr;
    ~AddrInfo() {
        if (list) ::freeaddrinfo(list);
    }
};

void resolve(const std::string& host, std::uint16_t port, bool passive, AddrInfo& out) {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = passive ? AI_PASSIVE : 0;
    const std::string service = std::to_string(port);
    int rc = ::getaddrinfo(host.empty() ? nullptr : host.c_str(), service.c_str(), &hints, &out.list);
    if (rc != 0)
        throw LinkDown("socketcand: cannot resolve host '" + host + "': " + ::gai_strerror(rc));
}

}  // namespace

Fd tcp_connect(const std::string& host, std::uint16_t port, Deadline deadline) {
    AddrInfo ai;
    resolve(host, port, false, ai);
    std::string last_error = "no address";
    for (addrinfo* a = ai.list; a; a = a->ai_next) {
        Fd s(::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol));
        if (!s) {
            last_error = std::strerror(errno);
            continue;
        }
        set_nonblocking(s.get());
        if (::connect(s.get(), a->ai_addr, a->ai_addrlen) == 0) return s;
        if (errno != EINPROGRESS) {
            last_error = std::strerror(errno);
            continue;
        }
        for (;;) {
            pollfd p{s.get(), POLLOUT, 0};
            int ms = poll_ms_until(deadline);
            int n = ::poll(&p, 1, ms);
            if (n < 0 && errno == EINTR) continue;
            if (n == 0) {
                if (std::chrono::steady_clock::now() >= deadline)
                    throw TimeoutError("socketcand: connecting to " + host + ":" +
                                       std::to_string(port) + " timed out");
                interruption_point();  // Ctrl-C while the server does not answer
                continue;
            }
            int err = 0;
            socklen_t len = sizeof err;
            ::getsockopt(s.get(), SOL_SOCKET, SO_ERROR, &err, &len);
            if (err == 0) return s;
            last_error = std::strerror(err);
            break;
        }
    }
    throw LinkDown("socketcand: cannot connect to " + host + ":" + std::to_string(port) + ": " +
                   last_error);
}

Fd tcp_listen(const std::string& host, std::uint16_t port, std::uint16_t& bound_port) {
    AddrInfo ai;
    resolve(host, port, true, ai);
    std::string last_error = "no address";
    for (addrinfo* a = ai.list; a; a = a->ai_next) {
        Fd s(::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol));
        if (!s) {
            last_error = std::strerror(errno);
            continue;
        }
        int one = 1;
        ::setsockopt(s.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        if (::bind(s.get(), a->ai_addr, a->ai_addrlen) != 0 || ::listen(s.get(), 64) != 0) {
            last_error = std::strerror(errno);
            continue;
        }
        sockaddr_storage ss{};
        socklen_t len = sizeof ss;
        ::getsockname(s.get(), reinterpret_cast<sockaddr*>(&ss), &len);
        if (ss.ss_family == AF_INET)
            bound_port = ntohs(reinterpret_cast<sockaddr_in*>(&ss)->sin_port);
        else
            bound_port = ntohs(reinterpret_cast<sockaddr_in6*>(&ss)->sin6_port);
        set_nonblocking(s.get());
        return s;
    }
    throw LinkDown("socketcand server: cannot listen on " + host + ":" + std::to_string(port) +
                   ": " + last_error);
}

Wakeup::Wakeup() : fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
    if (!fd_) throw LinkDown(std::string("eventfd: ") + std::strerror(errno));
}

void Wakeup::signal() {
    std::uint64_t one = 1;
    [[maybe_unused]] auto r = ::write(fd_.get(), &one, sizeof one);
}

void Wakeup::drain() {
    std::uint64_t v;
    [[maybe_unused]] auto r = ::read(fd_.get(), &v, sizeof v);
}

}  // namespace motorbus::can::net

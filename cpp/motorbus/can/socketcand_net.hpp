// Small POSIX TCP helpers shared by the socketcand client and server.
// Internal to the socketcand backend; not a general networking layer.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

#include "motorbus/can/bus.hpp"

namespace motorbus::can::net {

// Owns a file descriptor; closes it once.
class Fd {
public:
    Fd() = default;
    explicit Fd(int fd) : fd_(fd) {}
    Fd(Fd&& o) noexcept : fd_(o.release()) {}
    Fd& operator=(Fd&& o) noexcept;
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd() { reset(); }
    int get() const { return fd_; }
    explicit operator bool() const { return fd_ >= 0; }
    int release() {
        int f = fd_;
        fd_ = -1;
        return f;
    }
    void reset(int fd = -1);

private:
    int fd_ = -1;
};

// Connects to host:port (name or address) before `deadline`.  Throws LinkDown
// when refused/unreachable, TimeoutError when the deadline passes.
Fd tcp_connect(const std::string& host, std::uint16_t port, Deadline deadline);

// Listens on host:port (port 0 = let the kernel choose); `bound_port` gets the
// chosen port.  Throws LinkDown on failure.
Fd tcp_listen(const std::string& host, std::uint16_t port, std::uint16_t& bound_port);

void set_nonblocking(int fd);
void set_nodelay(int fd);
// Kernel TCP keepalive: probes after `idle`, every `interval`, `count` misses = dead.
void set_tcp_keepalive(int fd, std::chrono::seconds idle, std::chrono::seconds interval, int count);

// An eventfd used to wake a poll() loop from another thread.
class Wakeup {
public:
    Wakeup();
    int fd() const { return fd_.get(); }
    void signal();
    void drain();

private:
    Fd fd_;
};

// Milliseconds for poll() until `d` (0 if past, capped at `cap`).
int poll_ms_until(Deadline d, int cap = 1000);

}  // namespace motorbus::can::net

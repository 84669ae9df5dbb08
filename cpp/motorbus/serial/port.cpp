// TtyPort, PtyPair and open_port: raw termios byte ports.
#include "motorbus/serial/port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/eventfd.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <shared_mutex>

#include "motorbus/serial/baud_termios2.hpp"
#include "motorbus/serial/remote_port.hpp"

namespace motorbus::serial {

namespace {

std::string errno_text(const std::string& what, int err) {
    return what + ": " + std::strerror(err);
}

struct BaudConstant {
    unsigned rate;
    speed_t code;
};

constexpr BaudConstant kStandardBauds[] = {
    {50, B50},         {75, B75},         {110, B110},       {134, B134},
    {150, B150},       {200, B200},       {300, B300},       {600, B600},
    {1200, B1200},     {1800, B1800},     {2400, B2400},     {4800, B4800},
    {9600, B9600},     {19200, B19200},   {38400, B38400},   {57600, B57600},
    {115200, B115200}, {230400, B230400},
#ifdef B460800
    {460800, B460800},
#endif
#ifdef B500000
    {500000, B500000},
#endif
#ifdef B576000
    {576000, B576000},
#endif
#ifdef B921600
    {921600, B921600},
#endif
#ifdef B1000000
    {1000000, B1000000},
#endif
#ifdef B1152000
    {1152000, B1152000},
#endif
#ifdef B1500000
    {1500000, B1500000},
#endif
#ifdef B2000000
    {2000000, B2000000},
#endif
#ifdef B2500000
    {2500000, B2500000},
#endif
#ifdef B3000000
    {3000000, B3000000},
#endif
#ifdef B3500000
    {3500000, B3500000},
#endif
#ifdef B4000000
    {4000000, B4000000},
#endif
};

std::optional<speed_t> standard_baud_code(unsigned baud) {
    for (const auto& b : kStandardBauds)
        if (b.rate == baud) return b.code;
    return std::nullopt;
}

unsigned standard_baud_rate(speed_t code) {
    for (const auto& b : kStandardBauds)
        if (b.code == code) return b.rate;
    return 0;
}

void make_raw(int fd, const std::string& name) {
    termios tio{};
    if (::tcgetattr(fd, &tio) != 0) throw InvalidArgument(errno_text(name + " is not a tty", errno));
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
    tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    if (::tcsetattr(fd, TCSANOW, &tio) != 0) throw InvalidArgument(errno_text(name + ": tcsetattr", errno));
}

// The PID holding a flock on the file `fd` is open on, from /proc/locks
// ("1: FLOCK  ADVISORY  WRITE 1234 00:18:6 0 EOF"; dev as hex maj:min); 0 if unknown.
int flock_holder(int fd) {
    struct stat st {};
    if (::fstat(fd, &st) != 0) return 0;
    std::ifstream locks("/proc/locks");
    std::string line;
    while (std::getline(locks, line)) {
        if (line.find("->") != std::string::npos) continue;  // a waiter, not the holder
        char kind[16] = {};
        int pid = 0;
        unsigned maj = 0, min = 0;
        unsigned long ino = 0;
        if (std::sscanf(line.c_str(), "%*d: %15s %*s %*s %d %x:%x:%lu", kind, &pid, &maj, &min, &ino) != 5)
            continue;
        if (std::string(kind) == "FLOCK" && maj == major(st.st_dev) && min == minor(st.st_dev) && ino == st.st_ino)
            return pid;
    }
    return 0;
}

[[noreturn]] void throw_busy(const std::string& path, int holder, const char* how) {
    std::string who = holder == 0              ? "another process"
                      : holder == ::getpid()   ? "this process (pid " + std::to_string(holder) + ")"
                                               : "pid " + std::to_string(holder);
    throw PortBusy("serial port " + path + " is busy: already open by " + who + " (" + how +
                       "); ports are opened exclusively",
                   holder);
}

// Takes the port for us alone: flock (works for root too, and tells the
// holder's PID through /proc/locks) and TIOCEXCL (other openers get EBUSY from
// open() itself, unless they are root).  Closes `fd` and throws PortBusy when
// someone else has it.
void lock_exclusive(int fd, const std::string& path) {
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        if (err == EWOULDBLOCK) {
            const int holder = flock_holder(fd);
            ::close(fd);
            throw_busy(path, holder, "flock");
        }
        // Filesystems without flock: TIOCEXCL below still guards the port.
    }
    ::ioctl(fd, TIOCEXCL);
}

timespec to_timespec(Duration d) {
    if (d.count() < 0) d = Duration::zero();
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(d.count() / 1'000'000'000);
    ts.tv_nsec = static_cast<long>(d.count() % 1'000'000'000);
    return ts;
}

}  // namespace

struct TtyPort::Impl {
    int fd = -1;
    int wake = -1;  // eventfd: signalled once by close(), never drained
    std::string name;
    bool is_device = false;
    bool exclusive = false;  // TIOCEXCL set by us: cleared again on close
    std::atomic<bool> closed{false};
    std::atomic<std::int64_t> write_timeout_ns{-1};
    mutable std::shared_mutex io;  // shared by read/write; exclusive to close the fds

    void init(int fd_, std::string name_, bool raw) {
        fd = fd_;
        name = std::move(name_);
        int flags = ::fcntl(fd, F_GETFL);
        if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0) {
            int err = errno;
            ::close(fd);
            throw InvalidArgument(errno_text(name + ": fcntl", err));
        }
        ::fcntl(fd, F_SETFD, FD_CLOEXEC);
        if (raw) {
            try {
                make_raw(fd, name);
            } catch (...) {
                ::close(fd);
                throw;
            }
        }
        wake = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
        if (wake < 0) {
            int err = errno;
            ::close(fd);
            throw Error(errno_text("eventfd", err));
        }
    }

    void check_open() const {
        if (closed.load()) throw ClosedError(name + ": port closed");
    }

    // Waits for `events` on fd or the close signal.  Returns false on timeout.
    bool wait(short events, std::chrono::steady_clock::time_point deadline, bool forever) {
        for (;;) {
            pollfd fds[2] = {{fd, events, 0}, {wake, POLLIN, 0}};
            timespec ts{};
            timespec* tsp = nullptr;
            if (!forever) {
                ts = to_timespec(deadline - std::chrono::steady_clock::now());
                tsp = &ts;
            }
            int r = ::ppoll(fds, 2, tsp, nullptr);
            if (r < 0) {
                if (errno == EINTR) continue;
                throw LinkDown(errno_text(name + ": poll", errno));
            }
            if (fds[1].revents != 0 || closed.load()) throw ClosedError(name + ": port closed");
            if (r == 0) {
                if (forever || std::chrono::steady_clock::now() >= deadline) return false;
                continue;
            }
            if (fds[0].revents & events) return true;
            if (fds[0].revents & POLLNVAL) throw ClosedError(name + ": descriptor closed");
            // POLLHUP/POLLERR without data: the peer or the device is gone.  The
            // read/write that follows reports the exact errno.
            return true;
        }
    }
};

TtyPort::TtyPort(const std::string& path, unsigned baud) : impl_(std::make_unique<Impl>()) {
    int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        int err = errno;
        if (err == EBUSY) {  // TIOCEXCL of another holder: ask the lock table who
            int holder = 0;
            if (int probe = ::open(path.c_str(), O_PATH | O_CLOEXEC); probe >= 0) {
                holder = flock_holder(probe);
                ::close(probe);
            }
            throw_busy(path, holder, "TIOCEXCL");
        }
        if (err == ENOENT || err == ENOTDIR || err == EACCES || err == ENXIO || err == ENODEV)
            throw InvalidArgument(errno_text("serial port " + path, err));
        throw LinkDown(errno_text("serial port " + path, err));
    }
    lock_exclusive(fd, path);
    impl_->init(fd, path, true);
    impl_->is_device = true;
    impl_->exclusive = true;
    if (baud != 0) {
        try {
            set_baud(baud);
        } catch (...) {
            close();
            throw;
        }
    }
}

TtyPort::TtyPort(int fd, std::string name, bool raw) : impl_(std::make_unique<Impl>()) {
    if (fd < 0) throw InvalidArgument("TtyPort: invalid file descriptor");
    impl_->init(fd, std::move(name), raw);
}

TtyPort::~TtyPort() { close(); }

void TtyPort::write(std::span<const std::uint8_t> bytes) {
    std::shared_lock lk(impl_->io);
    impl_->check_open();
    auto timeout = Duration(impl_->write_timeout_ns.load());
    bool forever = timeout.count() < 0;
    auto deadline = std::chrono::steady_clock::now() + (forever ? Duration::zero() : timeout);
    std::size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::write(impl_->fd, bytes.data() + done, bytes.size() - done);
        if (n > 0) {
            done += static_cast<std::size_t>(n);
            continue;
        }
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            if (!impl_->wait(POLLOUT, deadline, forever))
                throw TimeoutError(impl_->name + ": write blocked (peer not reading)");
            continue;
        }
        throw LinkDown(errno_text(impl_->name + ": write", n < 0 ? errno : EIO));
    }
}

std::size_t TtyPort::read(std::span<std::uint8_t> buf, Duration timeout) {
    if (buf.empty()) return 0;
    std::shared_lock lk(impl_->io);
    impl_->check_open();
    bool forever = timeout.count() < 0;
    auto deadline = std::chrono::steady_clock::now() + (forever ? Duration::zero() : timeout);
    for (;;) {
        ssize_t n = ::read(impl_->fd, buf.data(), buf.size());
        if (n > 0) return static_cast<std::size_t>(n);
        if (n == 0) throw LinkDown(impl_->name + ": end of file");
        if (errno == EINTR) continue;
        if (errno != EAGAIN && errno != EWOULDBLOCK) throw LinkDown(errno_text(impl_->name + ": read", errno));
        if (!impl_->wait(POLLIN, deadline, forever)) return 0;
    }
}

void TtyPort::flush_input() {
    std::shared_lock lk(impl_->io);
    impl_->check_open();
    ::tcflush(impl_->fd, TCIFLUSH);
    // tcflush does not see bytes still in the pty/USB hand-over; drain those too.
    std::uint8_t sink[256];
    for (;;) {
        ssize_t n = ::read(impl_->fd, sink, sizeof sink);
        if (n > 0) continue;
        if (n < 0 && errno == EINTR) continue;
        break;
    }
}

void TtyPort::close() {
    if (!impl_ || impl_->closed.exchange(true)) return;
    std::uint64_t one = 1;
    [[maybe_unused]] auto w = ::write(impl_->wake, &one, sizeof one);
    std::unique_lock lk(impl_->io);  // waits for blocked readers/writers to leave
    // The tty may outlive this descriptor (a PtyPair keeps its slave open):
    // clear the exclusive flag so the next opener is not refused.  The flock
    // goes with the descriptor.
    if (impl_->exclusive) ::ioctl(impl_->fd, TIOCNXCL);
    ::close(impl_->fd);
    ::close(impl_->wake);
    impl_->fd = -1;
    impl_->wake = -1;
}

std::string TtyPort::name() const { return impl_->name; }

void TtyPort::drain() {
    std::shared_lock lk(impl_->io);
    impl_->check_open();
    if (impl_->is_device) ::tcdrain(impl_->fd);
}

void TtyPort::set_baud(unsigned baud) {
    std::shared_lock lk(impl_->io);
    impl_->check_open();
    if (baud == 0) throw InvalidArgument("baud: must be > 0");
    if (auto code = standard_baud_code(baud)) {
        termios tio{};
        if (::tcgetattr(impl_->fd, &tio) != 0) throw InvalidArgument(errno_text(impl_->name + ": tcgetattr", errno));
        ::cfsetispeed(&tio, *code);
        ::cfsetospeed(&tio, *code);
        if (::tcsetattr(impl_->fd, TCSANOW, &tio) != 0)
            throw InvalidArgument(errno_text(impl_->name + ": baud " + std::to_string(baud), errno));
        return;
    }
    if (!detail::set_baud_termios2(impl_->fd, baud))
        throw InvalidArgument(impl_->name + ": baud " + std::to_string(baud) + " not supported by the driver");
}

unsigned TtyPort::baud() const {
    std::shared_lock lk(impl_->io);
    impl_->check_open();
    termios tio{};
    if (::tcgetattr(impl_->fd, &tio) != 0) return 0;
    speed_t code = ::cfgetospeed(&tio);
    if (unsigned r = standard_baud_rate(code)) return r;
    return detail::get_baud_termios2(impl_->fd);
}

void TtyPort::set_write_timeout(Duration timeout) { impl_->write_timeout_ns.store(timeout.count()); }

bool TtyPort::is_open() const { return !impl_->closed.load(); }

// ---- PtyPair -----------------------------------------------------------------

PtyPair::PtyPair() {
    int m = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (m < 0) throw LinkDown(errno_text("posix_openpt", errno));
    char buf[128];
    if (::grantpt(m) != 0 || ::unlockpt(m) != 0 || ::ptsname_r(m, buf, sizeof buf) != 0) {
        int err = errno;
        ::close(m);
        throw LinkDown(errno_text("pty setup", err));
    }
    slave_path_ = buf;
    slave_fd_ = ::open(buf, O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (slave_fd_ < 0) {
        int err = errno;
        ::close(m);
        throw LinkDown(errno_text("open " + slave_path_, err));
    }
    try {
        // Raw on the slave is what matters: it governs how bytes written by the
        // master are delivered to slave readers and vice versa (no echo, no ONLCR).
        make_raw(slave_fd_, slave_path_);
        master_ = std::make_shared<TtyPort>(m, "pty:" + slave_path_, true);
    } catch (...) {
        ::close(slave_fd_);
        slave_fd_ = -1;
        if (!master_) ::close(m);
        throw;
    }
}

PtyPair::~PtyPair() { close(); }

std::shared_ptr<Port> PtyPair::port() const { return master_; }
std::shared_ptr<TtyPort> PtyPair::master() const { return master_; }
const std::string& PtyPair::slave_path() const { return slave_path_; }

std::shared_ptr<TtyPort> PtyPair::open_slave(unsigned baud) const {
    return std::make_shared<TtyPort>(slave_path_, baud);
}

void PtyPair::release_slave() {
    if (slave_fd_ >= 0) ::close(slave_fd_);
    slave_fd_ = -1;
}

void PtyPair::close() {
    if (master_) master_->close();
    release_slave();
}

std::shared_ptr<Port> open_port(const std::string& path, unsigned baud) {
    if (path.empty()) throw InvalidArgument("open_port: empty path");
    // socket://host:port and rfc2217://host:port: a line behind a serial gateway.
    if (auto remote = parse_remote_url(path)) return open_remote_port(*remote, baud);
    return std::make_shared<TtyPort>(path, baud);
}

}  // namespace motorbus::serial

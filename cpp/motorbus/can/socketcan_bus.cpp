#include "motorbus/can/socketcan_bus.hpp"

#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "motorbus/errors.hpp"

namespace motorbus::can {

namespace socketcan {

namespace {

canid_t kernel_id(const Frame& f) {
    canid_t id = f.extended ? ((f.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (f.id & CAN_SFF_MASK);
    if (f.rtr) id |= CAN_RTR_FLAG;
    return id;
}

void check_sendable(const Frame& f) {
    if (auto p = f.problem()) throw InvalidArgument(*p);
    if (f.flags & kFlagError) throw InvalidArgument("frame: error frames cannot be sent");
}

Nanos realtime_ns() {
    timespec ts{};
    ::clock_gettime(CLOCK_REALTIME, &ts);
    return static_cast<Nanos>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec;
}

std::string errno_name(int e) {
    switch (e) {
        case EAFNOSUPPORT: return "EAFNOSUPPORT";
        case EPROTONOSUPPORT: return "EPROTONOSUPPORT";
        case EPERM: return "EPERM";
        case EACCES: return "EACCES";
        default: return "errno " + std::to_string(e);
    }
}

}  // namespace

struct can_frame to_can_frame(const Frame& f) {
    check_sendable(f);
    if (f.is_fd()) throw InvalidArgument("frame: a CAN FD frame needs an FD socket (fd=true)");
    struct can_frame k;
    std::memset(&k, 0, sizeof k);
    k.can_id = kernel_id(f);
    k.len = f.len;
    if (!f.rtr) std::memcpy(k.data, f.data.data(), f.len);
    return k;
}

struct canfd_frame to_canfd_frame(const Frame& f) {
    check_sendable(f);
    struct canfd_frame k;
    std::memset(&k, 0, sizeof k);
    k.can_id = kernel_id(f);
    k.len = f.len;
    if (f.flags & kFlagBrs) k.flags |= CANFD_BRS;
    if (f.flags & kFlagEsi) k.flags |= CANFD_ESI;
    if (f.is_fd()) k.flags |= CANFD_FDF;
    if (!f.rtr) std::memcpy(k.data, f.data.data(), f.len);
    return k;
}

std::optional<Frame> from_kernel(const void* data, std::size_t size, Nanos timestamp_ns) {
    if (size != CAN_MTU && size != CANFD_MTU) return std::nullopt;
    // can_frame and canfd_frame share the layout of id and length.
    struct canfd_frame k;
    std::memset(&k, 0, sizeof k);
    std::memcpy(&k, data, size);
    Frame f;
    f.timestamp_ns = timestamp_ns;
    if (k.can_id & CAN_ERR_FLAG) {
        f.id = k.can_id & CAN_ERR_MASK;
        f.extended = true;
        f.flags = kFlagError;
        f.len = CAN_ERR_DLC;
        std::memcpy(f.data.data(), k.data, CAN_ERR_DLC);
        return f;
    }
    f.extended = k.can_id & CAN_EFF_FLAG;
    f.id = k.can_id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    if (size == CANFD_MTU) {
        f.flags = kFlagFd;
        if (k.flags & CANFD_BRS) f.flags |= kFlagBrs;
        if (k.flags & CANFD_ESI) f.flags |= kFlagEsi;
        if (k.len > CANFD_MAX_DLEN) return std::nullopt;
    } else {
        f.rtr = k.can_id & CAN_RTR_FLAG;
        if (k.len > CAN_MAX_DLEN) return std::nullopt;
    }
    f.len = k.len;
    if (!f.rtr) std::memcpy(f.data.data(), k.data, k.len);
    if (f.problem()) return std::nullopt;
    return f;
}

std::vector<struct can_filter> to_kernel_filters(const std::vector<Filter>& filters) {
    std::vector<struct can_filter> out;
    out.reserve(filters.size());
    for (const Filter& f : filters) {
        struct can_filter k{};
        // The kernel matches (received_id & mask) == (can_id & mask) on the full
        // can_id word, flags included; the EFF bit joins the mask only when the
        // filter cares about the id width.
        k.can_id = f.id & CAN_EFF_MASK;
        k.can_mask = f.mask & CAN_EFF_MASK;
        if (f.match_extended) {
            k.can_mask |= CAN_EFF_FLAG;
            if (f.extended) k.can_id |= CAN_EFF_FLAG;
        }
        out.push_back(k);
    }
    return out;
}

BusState state_after_error(const Frame& e, BusState current) {
    if (!(e.flags & kFlagError)) return current;
    if (e.id & CAN_ERR_BUSOFF) return BusState::BusOff;
    if (e.id & CAN_ERR_RESTARTED) return BusState::Active;
    if ((e.id & CAN_ERR_CRTL) && e.len >= 2) {
        const std::uint8_t d1 = e.data[1];
        if (d1 & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) return BusState::ErrorPassive;
        if (d1 & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) return BusState::ErrorWarning;
        if (d1 & CAN_ERR_CRTL_ACTIVE) return BusState::Active;
    }
    return current;
}

std::optional<std::string> unavailable_reason() {
    int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd >= 0) {
        ::close(fd);
        return std::nullopt;
    }
    const int e = errno;
    std::string why = "socketcan: socket(PF_CAN, SOCK_RAW, CAN_RAW) failed with " + errno_name(e) +
                      " (" + std::strerror(e) + ")";
    if (e == EAFNOSUPPORT)
        why += ": this kernel has no CAN support (CONFIG_CAN unset or the can module not loaded)";
    return why;
}

}  // namespace socketcan

SocketCanBus::SocketCanBus(const std::string& iface, const SocketCanOptions& options)
    : Bus("socketcan:" + iface, options), opts_(options) {
    if (iface.empty() || iface.size() >= IFNAMSIZ)
        throw InvalidArgument("socketcan interface: '" + iface + "' must be 1-15 characters");
    if (auto why = socketcan::unavailable_reason()) throw LinkDown(*why);
    sock_ = net::Fd(::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
    if (!sock_) throw LinkDown(std::string("socketcan: socket: ") + std::strerror(errno));
    const unsigned index = ::if_nametoindex(iface.c_str());
    if (index == 0) throw LinkDown("socketcan: no interface '" + iface + "': " + std::strerror(errno));

    if (!opts_.kernel_filters.empty()) {
        auto k = socketcan::to_kernel_filters(opts_.kernel_filters);
        if (::setsockopt(sock_.get(), SOL_CAN_RAW, CAN_RAW_FILTER, k.data(),
                         static_cast<socklen_t>(k.size() * sizeof(k[0]))) != 0)
            throw InvalidArgument(std::string("socketcan: CAN_RAW_FILTER refused: ") + std::strerror(errno));
    }
    can_err_mask_t err_mask = opts_.error_frames ? CAN_ERR_MASK : 0;
    ::setsockopt(sock_.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask);
    if (opts_.fd) {
        int on = 1;
        if (::setsockopt(sock_.get(), SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) != 0)
            throw LinkDown(std::string("socketcan: CAN FD not supported: ") + std::strerror(errno));
    }
    int on = 1;
    ::setsockopt(sock_.get(), SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(index);
    if (::bind(sock_.get(), reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0)
        throw LinkDown("socketcan: bind to '" + iface + "': " + std::strerror(errno));
    rx_thread_ = std::thread([this] { rx_loop(); });
}

SocketCanBus::~SocketCanBus() { close(); }

void SocketCanBus::do_close() {
    stop_.store(true);
    wake_.signal();
    if (rx_thread_.joinable()) rx_thread_.join();
    // The descriptor stays open until *this is destroyed, so a send racing with
    // close() can never write to a descriptor number the process has reused.
}

void SocketCanBus::do_send(const Frame& frame, Deadline deadline) {
    struct canfd_frame fd_frame;
    struct can_frame classic;
    const void* buf;
    std::size_t size;
    if (opts_.fd && frame.is_fd()) {
        fd_frame = socketcan::to_canfd_frame(frame);
        buf = &fd_frame;
        size = CANFD_MTU;
    } else {
        classic = socketcan::to_can_frame(frame);
        buf = &classic;
        size = CAN_MTU;
    }
    auto backoff = std::chrono::microseconds(50);
    for (;;) {
        ssize_t r = ::write(sock_.get(), buf, size);
        if (r == static_cast<ssize_t>(size)) return;
        if (r < 0 && errno == EINTR) continue;
        if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
            // The qdisc is full (ENOBUFS is what CAN drivers report, and poll()
            // does not reliably wake for it): back off until the deadline.
            if (std::chrono::steady_clock::now() + backoff >= deadline)
                throw TimeoutError("socketcan: transmit queue full (ENOBUFS) until the timeout");
            pollfd p{sock_.get(), POLLOUT, 0};
            ::poll(&p, 1, static_cast<int>(backoff.count() / 1000) + 1);
            if (backoff < std::chrono::milliseconds(5)) backoff *= 2;
            continue;
        }
        if (r < 0 && (errno == ENETDOWN || errno == ENODEV || errno == ENXIO))
            throw LinkDown(std::string("socketcan: interface down: ") + std::strerror(errno));
        throw LinkDown(std::string("socketcan: write failed: ") +
                       (r < 0 ? std::strerror(errno) : "short write"));
    }
}

void SocketCanBus::rx_loop() {
    alignas(8) unsigned char frame_buf[CANFD_MTU];
    alignas(8) char control[CMSG_SPACE(sizeof(timespec)) + 64];
    while (!stop_.load()) {
        pollfd fds[2] = {{sock_.get(), POLLIN, 0}, {wake_.fd(), POLLIN, 0}};
        int n = ::poll(fds, 2, 1000);
        if (stop_.load()) return;
        if (n <= 0) continue;
        if (fds[0].revents & (POLLERR | POLLHUP | POLLNVAL)) {
            set_state(BusState::BusOff);
            return;
        }
        if (!(fds[0].revents & POLLIN)) continue;
        for (int batch = 0; batch < 64; ++batch) {
            iovec iov{frame_buf, sizeof frame_buf};
            msghdr msg{};
            msg.msg_iov = &iov;
            msg.msg_iovlen = 1;
            msg.msg_control = control;
            msg.msg_controllen = sizeof control;
            ssize_t r = ::recvmsg(sock_.get(), &msg, MSG_DONTWAIT);
            if (r < 0) {
                if (errno == ENETDOWN) set_state(BusState::BusOff);
                break;
            }
            Nanos ts = monotonic_ns();
            for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
                if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
                    timespec kt;
                    std::memcpy(&kt, CMSG_DATA(c), sizeof kt);
                    // Kernel stamps are CLOCK_REALTIME; shift them onto the monotonic line.
                    const Nanos real = static_cast<Nanos>(kt.tv_sec) * 1'000'000'000LL + kt.tv_nsec;
                    ts = real - (socketcan::realtime_ns() - monotonic_ns());
                }
            }
            auto f = socketcan::from_kernel(frame_buf, static_cast<std::size_t>(r), ts);
            if (!f) {
                count_parse_error();
                continue;
            }
            if (f->flags & kFlagError) {
                count_bus_error();
                if (f->id & CAN_ERR_CRTL) {
                    if (f->len >= 2 && (f->data[1] & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)))
                        count_overrun();
                }
                set_state(socketcan::state_after_error(*f, state()));
            }
            dispatch(*f);
        }
    }
}

std::shared_ptr<SocketCanBus> open_socketcan(const std::string& iface, const SocketCanOptions& options) {
    return std::make_shared<SocketCanBus>(iface, options);
}

}  // namespace motorbus::can

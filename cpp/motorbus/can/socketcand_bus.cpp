#include "motorbus/can/socketcand_bus.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "motorbus/errors.hpp"
#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::can {

using socketcand::Element;
using socketcand::ElementKind;
using socketcand::ParseError;

namespace {

// Sends closer together than this are a burst: batch them (see do_send).
constexpr auto kBurstGap = std::chrono::microseconds(20);

Nanos to_ns(Duration d) { return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count(); }

// Blocking write for the handshake (the socket is non-blocking).
void write_all(int fd, const std::string& s, Deadline deadline) {
    std::size_t off = 0;
    while (off < s.size()) {
        ssize_t r = ::send(fd, s.data() + off, s.size() - off, MSG_NOSIGNAL);
        if (r > 0) {
            off += static_cast<std::size_t>(r);
            continue;
        }
        if (r < 0 && errno == EINTR) continue;
        if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            pollfd p{fd, POLLOUT, 0};
            if (::poll(&p, 1, net::poll_ms_until(deadline)) == 0) {
                if (std::chrono::steady_clock::now() >= deadline)
                    throw TimeoutError("socketcand: handshake write timed out");
                interruption_point();
            }
            continue;
        }
        throw LinkDown(std::string("socketcand: write failed: ") + std::strerror(errno));
    }
}

}  // namespace

void check_options(const SocketcandOptions& o) {
    if (o.keepalive_misses < 1) throw InvalidArgument("keepalive_misses: must be >= 1");
    if (o.tx_buffer_bytes == 0)
        throw InvalidArgument("tx_buffer_bytes: 0, must be >= 1 (unsent bytes before send() waits)");
    socketcand::check_max_element(o.max_element);
    const std::pair<const char*, Duration> durations[] = {{"connect_timeout", o.connect_timeout},
                                                          {"handshake_timeout", o.handshake_timeout},
                                                          {"keepalive_period", o.keepalive_period}};
    for (const auto& [name, d] : durations)
        if (d.count() < 0) throw InvalidArgument(std::string(name) + ": must be >= 0");
    check_options(static_cast<const BusOptions&>(o), "socketcand");
}

SocketcandBus::SocketcandBus(const std::string& host, std::uint16_t port, const std::string& channel,
                             const SocketcandOptions& options)
    : Bus("socketcand:" + host + ":" + std::to_string(port) + "/" + channel, options),
      opts_(options),
      host_(host),
      port_(port),
      parser_(options.max_element) {
    socketcand::check_channel_name(channel, "socketcand channel");
    check_options(options);
    sock_ = net::tcp_connect(host, port, deadline_after(options.connect_timeout));
    net::set_nodelay(sock_.get());
    if (options.tcp_keepalive) {
        // Kernel probes are a backstop for when echo is off; seconds granularity.
        auto period = std::chrono::duration_cast<std::chrono::seconds>(options.keepalive_period);
        if (period.count() < 1) period = std::chrono::seconds(1);
        net::set_tcp_keepalive(sock_.get(), period, period, options.keepalive_misses);
    }
    handshake(channel, deadline_after(options.handshake_timeout));
    last_rx_ns_.store(monotonic_ns());
    for (const Frame& f : early_frames_) dispatch(f);
    early_frames_.clear();
    rx_thread_ = std::thread([this] { rx_loop(); });
}

SocketcandBus::~SocketcandBus() { close(); }

void SocketcandBus::handshake(const std::string& channel, Deadline deadline) {
    enum { WantHi, WantOpenOk, WantRawOk, Done } step = WantHi;
    std::vector<Element> got;
    char buf[4096];
    while (step != Done) {
        pollfd p{sock_.get(), POLLIN, 0};
        int n = ::poll(&p, 1, net::poll_ms_until(deadline));
        if (n < 0 && errno == EINTR) continue;
        if (n == 0) {
            if (std::chrono::steady_clock::now() >= deadline)
                throw TimeoutError(std::string("socketcand: no ") +
                                   (step == WantHi ? "< hi >" : "< ok >") + " from " + host_ +
                                   " within the handshake timeout");
            // A server that accepted but never says < hi >: Ctrl-C must not wait
            // for the whole handshake timeout (poll_ms_until slices it).
            interruption_point();
            continue;
        }
        ssize_t r = ::recv(sock_.get(), buf, sizeof buf, 0);
        if (r == 0) throw LinkDown("socketcand: server closed the connection during the handshake");
        if (r < 0) {
            if (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK) continue;
            throw LinkDown(std::string("socketcand: handshake read failed: ") + std::strerror(errno));
        }
        const Nanos now = monotonic_ns();
        got.clear();
        parser_.feed(std::span<const char>(buf, static_cast<std::size_t>(r)),
                     [&](const Element& e) { got.push_back(e); },
                     [&](const ParseError&) { count_parse_error(); });
        for (const Element& e : got) {
            if (step == Done) {  // frames that raced the final < ok >
                if (e.kind == ElementKind::Frame || e.kind == ElementKind::FdFrame ||
                    e.kind == ElementKind::Rtr) {
                    Frame f = e.frame;
                    f.timestamp_ns = now;
                    early_frames_.push_back(f);
                }
                continue;
            }
            if (e.kind == ElementKind::ErrorText) {
                throw LinkDown("socketcand: server refused " +
                               std::string(step == WantOpenOk ? "channel '" + channel + "'" : "rawmode") +
                               ": " + e.text);
            }
            std::string out;
            if (step == WantHi && e.kind == ElementKind::Hi) {
                socketcand::encode_open(channel, out);
                write_all(sock_.get(), out, deadline);
                step = WantOpenOk;
            } else if (step == WantOpenOk && e.kind == ElementKind::Ok) {
                socketcand::encode_command(ElementKind::RawMode, out);
                write_all(sock_.get(), out, deadline);
                step = WantRawOk;
            } else if (step == WantRawOk && e.kind == ElementKind::Ok) {
                step = Done;
            } else {
                count_ignored();
            }
        }
    }
    account_parser();
}

void SocketcandBus::do_close() {
    stop_.store(true);
    wake_.signal();
    if (rx_thread_.joinable()) rx_thread_.join();
    {
        // Best effort: hand over what is already committed, without blocking.
        if (!link_down_.load()) write_some(false);
    }
    // shutdown, not close: a sender racing with close() must hit a dead socket,
    // never a descriptor number the process has reused.  The Fd closes with *this.
    if (sock_) ::shutdown(sock_.get(), SHUT_RDWR);
}

std::string SocketcandBus::link_down_reason() const {
    std::lock_guard lk(info_mutex_);
    return link_down_reason_;
}

std::string SocketcandBus::last_server_error() const {
    std::lock_guard lk(info_mutex_);
    return last_server_error_;
}

socketcand::ParserStats SocketcandBus::parser_stats() const {
    std::lock_guard lk(stats_mutex_);
    return stats_snapshot_;
}

void SocketcandBus::mark_link_down(const std::string& why) {
    {
        std::lock_guard lk(info_mutex_);
        if (link_down_.load()) return;
        link_down_reason_ = why;
    }
    link_down_.store(true);
    tx_space_cv_.notify_all();
    // No medium any more: Bus::send() refuses with LinkDown, state() shows it,
    // and recv()/recv_many() waiters wake with LinkDown (never blocked forever).
    // (After close() the state stays Closed: our own shutdown is not a link failure.)
    if (!closed()) link_lost(why);
}

void SocketcandBus::account_parser() {
    const auto& s = parser_.stats();
    for (auto i = parser_seen_.overlong; i < s.overlong; ++i) count_overrun();
    for (auto i = parser_seen_.interrupted; i < s.interrupted; ++i) count_parse_error();
    parser_seen_ = s;
    std::lock_guard lk(stats_mutex_);
    stats_snapshot_ = s;
}

void SocketcandBus::enqueue(std::string_view element) {
    std::lock_guard lk(tx_mutex_);
    pending_.append(element);
    unsent_.fetch_add(element.size());
}

bool SocketcandBus::write_some(bool wait_turn) {
    std::unique_lock w(write_mutex_, std::defer_lock);
    if (wait_turn) {
        w.lock();
    } else if (!w.try_lock()) {
        // The current writer may be just finishing; make sure somebody looks again.
        if (!tx_pending_.exchange(true)) wake_.signal();
        return true;
    }
    bool ok = true;
    std::string failure;
    for (;;) {
        if (writing_off_ == writing_.size()) {
            writing_.clear();
            writing_off_ = 0;
            std::lock_guard lk(tx_mutex_);
            writing_.swap(pending_);
            if (writing_.empty()) {
                // Cleared only here, under tx_mutex_, where no append can slip past.
                tx_pending_.store(false);
                break;
            }
        }
        ssize_t r = ::send(sock_.get(), writing_.data() + writing_off_, writing_.size() - writing_off_,
                           MSG_NOSIGNAL | MSG_DONTWAIT);
        if (r > 0) {
            writing_off_ += static_cast<std::size_t>(r);
            unsent_.fetch_sub(static_cast<std::size_t>(r));
            tx_space_cv_.notify_all();
        } else if (r < 0 && errno == EINTR) {
            continue;
        } else if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            // The receive thread finishes the job when the socket drains (POLLOUT).
            if (!tx_pending_.exchange(true)) wake_.signal();
            break;
        } else {
            failure = std::string("socketcand: write failed: ") + std::strerror(errno);
            ok = false;
            break;
        }
    }
    w.unlock();
    // After unlocking: marking the link down runs the bus's link watchers (an
    // SDO client's wake-up), which must not run under our writer lock.
    if (!ok) {
        mark_link_down(failure);
        tx_space_cv_.notify_all();
    }
    return ok;
}

void SocketcandBus::do_send(const Frame& frame, Deadline deadline) {
    static thread_local std::string encoded;  // no allocation per frame
    encoded.clear();
    socketcand::encode_send(frame, encoded);
    bool burst;
    {
        std::unique_lock lk(tx_mutex_);
        // Back-pressure: a peer that stops reading makes send() wait, then time out.
        while (unsent_.load() >= opts_.tx_buffer_bytes && !link_down_.load()) {
            lk.unlock();
            if (!write_some(false)) throw LinkDown(link_down_reason());
            lk.lock();
            if (unsent_.load() < opts_.tx_buffer_bytes) break;
            if (std::chrono::steady_clock::now() >= deadline)
                throw TimeoutError("socketcand: the server is not reading; " +
                                   std::to_string(unsent_.load()) + " bytes still unsent");
            tx_space_cv_.wait_until(lk, std::min(deadline, std::chrono::steady_clock::now() +
                                                               std::chrono::milliseconds(5)));
            if (interruptible()) {  // Ctrl-C while the server is not reading
                lk.unlock();
                interruption_point();
                lk.lock();
            }
        }
        if (link_down_.load()) throw LinkDown(link_down_reason());
        // The element goes in whole or not at all, so the stream never carries half a frame.
        pending_.append(encoded);
        unsent_.fetch_add(encoded.size());
        // Bus::send() read the clock for `deadline` just now.  Sends with the
        // same timeout have deadlines exactly as far apart as the sends, which
        // tells a burst without a second clock read (~35 ns each on a VM).  A
        // send with a shorter timeout than the last one looks like a burst: it
        // is then batched, which is only slower, never wrong.
        burst = deadline - last_send_deadline_ < kBurstGap;
        last_send_deadline_ = deadline;
    }
    // An isolated frame is written at once (lowest latency).  In a burst the
    // receive thread writes whole batches, one system call for many frames, and
    // the sender only pays for encoding.
    if (burst || tx_pending_.load()) {
        if (!tx_pending_.exchange(true)) wake_.signal();
        return;
    }
    if (!write_some(false)) throw LinkDown(link_down_reason());
}

void SocketcandBus::handle(const Element& e, Nanos now) {
    switch (e.kind) {
        case ElementKind::Frame:
        case ElementKind::FdFrame:
        case ElementKind::Rtr: {
            rx_batch_.push_back(e.frame);
            rx_batch_.back().timestamp_ns = now;
            break;
        }
        case ElementKind::ErrorFrame: {
            count_bus_error();
            rx_batch_.push_back(e.frame);
            rx_batch_.back().timestamp_ns = now;
            break;
        }
        case ElementKind::ErrorText: {
            // The server refused something we sent (socketcand only does this for
            // unknown commands; our server also for bad or undeliverable sends).
            {
                std::lock_guard lk(info_mutex_);
                last_server_error_ = e.text;
            }
            // Counted after the text is stored: a caller that sees the count
            // must also see the reason.
            count_tx_dropped();
            break;
        }
        case ElementKind::Echo:  // keepalive reply: arrival already refreshed last_rx
            break;
        default:
            count_ignored();
            break;
    }
}

void SocketcandBus::rx_loop() {
    std::vector<char> buf(64 * 1024);
    const Nanos period = to_ns(opts_.keepalive_period);
    const Nanos dead_after = period * opts_.keepalive_misses;
    int tick_ms = 1000;
    if (period > 0) {
        tick_ms = static_cast<int>(period / 4'000'000);
        if (tick_ms < 1) tick_ms = 1;
        if (tick_ms > 1000) tick_ms = 1000;
    }
    Nanos last_echo = monotonic_ns();
    while (!stop_.load()) {
        pollfd fds[2] = {
            {sock_.get(), static_cast<short>(POLLIN | (tx_pending_.load() ? POLLOUT : 0)), 0},
            {wake_.fd(), POLLIN, 0},
        };
        int n = ::poll(fds, 2, tick_ms);
        if (n < 0 && errno != EINTR) {
            mark_link_down(std::string("socketcand: poll failed: ") + std::strerror(errno));
            return;
        }
        if (stop_.load()) return;
        if (n > 0 && (fds[1].revents & POLLIN)) wake_.drain();
        const Nanos now = monotonic_ns();
        if (n > 0 && (fds[0].revents & (POLLIN | POLLHUP | POLLERR))) {
            ssize_t r = ::recv(sock_.get(), buf.data(), buf.size(), MSG_DONTWAIT);
            if (r == 0) {
                mark_link_down("socketcand: the server closed the connection");
                return;
            }
            if (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
                mark_link_down(std::string("socketcand: read failed: ") + std::strerror(errno));
                return;
            }
            if (r > 0) {
                last_rx_ns_.store(now);
                parser_.feed(std::span<const char>(buf.data(), static_cast<std::size_t>(r)),
                             [&](const Element& e) { handle(e, now); },
                             [&](const ParseError&) { count_parse_error(); });
                // Everything this read carried reaches recv()/subscribers at once.
                dispatch_batch(rx_batch_);
                rx_batch_.clear();
                account_parser();
            }
        }
        if (tx_pending_.load() && !write_some(true)) return;
        if (period > 0) {
            const Nanos silent = now - last_rx_ns_.load();
            if (silent >= dead_after) {  // K13: the peer vanished without a FIN
                mark_link_down("socketcand: no data from the server for " +
                               std::to_string(silent / 1'000'000) + " ms (" +
                               std::to_string(opts_.keepalive_misses) +
                               " keepalive periods): peer gone or half-open TCP");
                return;
            }
            if (silent >= period && now - last_echo >= period) {
                std::string echo;
                socketcand::encode_command(ElementKind::Echo, echo);
                enqueue(echo);
                last_echo = now;
                if (!write_some(true)) return;
            }
        }
    }
}

std::shared_ptr<SocketcandBus> open_socketcand(const std::string& host, std::uint16_t port,
                                               const std::string& channel,
                                               const SocketcandOptions& options) {
    return std::make_shared<SocketcandBus>(host, port, channel, options);
}

}  // namespace motorbus::can

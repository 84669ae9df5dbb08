#include "motorbus/can/socketcand_server.hpp"

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "motorbus/errors.hpp"

namespace motorbus::can {

using socketcand::Element;
using socketcand::ElementKind;
using socketcand::ParseError;

namespace {

Nanos to_ns(Duration d) { return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count(); }

Nanos realtime_ns() {
    timespec ts{};
    ::clock_gettime(CLOCK_REALTIME, &ts);
    return static_cast<Nanos>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec;
}

// python-can reads the handshake replies with one recv() each and compares the
// whole string, so the `< ok >` for rawmode must not share a segment with the
// first frames.  Holding frames this long after it is enough on any LAN.
constexpr Nanos kRawModeSettleNs = 2'000'000;
constexpr std::size_t kOutHighWater = 64 * 1024;

}  // namespace

struct SocketcandServer::Conn {
    explicit Conn(std::size_t max_element) : parser(max_element) {}
    enum class Mode { NoBus, Bcm, Raw };

    net::Fd fd;
    socketcand::ElementParser parser;
    Mode mode = Mode::NoBus;            // I/O thread only
    std::atomic<bool> raw{false};       // read by broadcast() on the bus thread
    Nanos hold_frames_until = 0;        // see kRawModeSettleNs
    std::mutex qmu;
    // Frames waiting for this client (bounded, K15): queue[queue_head..] under qmu.
    // Two vectors swapped between the bus thread and the I/O thread keep their
    // capacity, so a busy link allocates nothing per frame (a deque allocated a
    // block every few frames on one thread and freed it on the other).
    std::vector<Frame> queue;
    std::size_t queue_head = 0;         // frames before it were dropped (K15)
    std::vector<Frame> draining;        // I/O thread only: the batch being encoded
    std::uint64_t drops = 0;            // guarded by qmu
    std::string out;                    // encoded bytes not yet written
    std::size_t out_off = 0;
    Nanos connected_at = 0;
    Nanos last_rx = 0;
    Nanos element_started = 0;
    bool closing = false;               // close once `out` is flushed
};

void check_options(const SocketcandServerOptions& o) {
    if (o.max_clients == 0) throw InvalidArgument("max_clients: 0, must be >= 1 (0 would refuse every client)");
    if (o.client_queue == 0) throw InvalidArgument("client_queue: must be >= 1");
    if (!o.channel.empty()) socketcand::check_channel_name(o.channel, "channel");  // empty = any name
    socketcand::check_max_element(o.max_element);
    const std::pair<const char*, Duration> durations[] = {{"idle_timeout", o.idle_timeout},
                                                          {"element_timeout", o.element_timeout},
                                                          {"open_timeout", o.open_timeout},
                                                          {"bus_send_budget", o.bus_send_budget}};
    for (const auto& [name, d] : durations)
        if (d.count() < 0) throw InvalidArgument(std::string(name) + ": must be >= 0");
    if (o.socket_send_buffer < 0) throw InvalidArgument("socket_send_buffer: must be >= 0 (0 = kernel default)");
}

SocketcandServer::SocketcandServer(std::shared_ptr<Bus> bus, SocketcandServerOptions options)
    : bus_(std::move(bus)), opts_(std::move(options)) {
    if (!bus_) throw InvalidArgument("SocketcandServer: bus is null");
    check_options(opts_);
    listen_ = net::tcp_listen(opts_.host, opts_.port, port_);
    wall_offset_ns_ = realtime_ns() - monotonic_ns();
    io_thread_ = std::thread([this] { io_loop(); });
    // Our own sends come back flagged as loopback when the bus has receive_own;
    // the sender's peers already got those from client_send().
    sub_ = bus_->subscribe(Filter{}, [this](const Frame& f) {
        if (!(f.flags & kFlagLoopback)) broadcast(f, nullptr);
    });
}

SocketcandServer::~SocketcandServer() { close(); }

void SocketcandServer::close() {
    std::call_once(close_once_, [&] {
        if (sub_) bus_->unsubscribe(sub_);
        stop_.store(true);
        wake_.signal();
        if (io_thread_.joinable()) io_thread_.join();
        std::lock_guard lk(conns_mutex_);
        for (auto& c : conns_) ::shutdown(c->fd.get(), SHUT_RDWR);
        conns_.clear();
        listen_.reset();
    });
}

SocketcandServerStats SocketcandServer::stats() const {
    SocketcandServerStats s;
    s.clients_accepted = counters_.clients_accepted.load();
    s.clients_refused = counters_.clients_refused.load();
    s.timeouts = counters_.timeouts.load();
    s.frames_to_bus = counters_.frames_to_bus.load();
    s.frames_to_clients = counters_.frames_to_clients.load();
    s.bus_send_retries = counters_.bus_send_retries.load();
    s.bus_send_failures = counters_.bus_send_failures.load();
    s.error_replies = counters_.error_replies.load();
    s.bad_elements = counters_.bad_elements.load();
    s.queue_drops = queue_drops_.load();
    std::lock_guard lk(conns_mutex_);
    s.clients_active = conns_.size();
    return s;
}

std::vector<std::uint64_t> SocketcandServer::client_drops() const {
    std::vector<std::uint64_t> v;
    std::lock_guard lk(conns_mutex_);
    for (auto& c : conns_) {
        std::lock_guard q(c->qmu);
        v.push_back(c->drops);
    }
    return v;
}

void SocketcandServer::broadcast(const Frame& f, const Conn* except) {
    bool wake = false;
    {
        std::lock_guard lk(conns_mutex_);
        for (auto& c : conns_) {
            if (c.get() == except || !c->raw.load(std::memory_order_relaxed)) continue;
            std::lock_guard q(c->qmu);
            if (c->queue.size() - c->queue_head >= opts_.client_queue) {  // K15: the newest frames matter most
                ++c->queue_head;
                ++c->drops;
                queue_drops_.fetch_add(1, std::memory_order_relaxed);
                // Reclaim the dropped prefix now and then: memory stays within
                // 1.5x client_queue at O(1) amortised cost per frame.
                if (c->queue_head * 2 >= opts_.client_queue) {
                    c->queue.erase(c->queue.begin(),
                                   c->queue.begin() + static_cast<std::ptrdiff_t>(c->queue_head));
                    c->queue_head = 0;
                }
            }
            wake |= c->queue.size() == c->queue_head;
            c->queue.push_back(f);
        }
    }
    if (!wake || except != nullptr) return;  // the I/O thread itself is the caller
    // Only a sleeping I/O thread needs the system call; a busy one will look
    // at the queues again before it sleeps (Dekker-style handshake with io_loop).
    work_pending_.store(true);
    if (io_sleeping_.load()) wake_.signal();
}

void SocketcandServer::reply(Conn& c, std::string_view element) { c.out.append(element); }

void SocketcandServer::reply_error(Conn& c, std::string_view message) {
    socketcand::encode_error_text(message, c.out);
    ++counters_.error_replies;
}

void SocketcandServer::client_send(Conn& c, const Frame& frame) {
    Frame f = frame;
    f.timestamp_ns = c.last_rx;  // arrival of the bytes that carried it
    // K11: a full medium (ENOBUFS on a raw socket, a full virtual queue) is a
    // transient condition.  Retry with backoff inside a small budget, then tell
    // the client, but never drop its session for it (socketcand does).
    std::chrono::steady_clock::time_point give_up{};  // computed on the first refusal only
    auto backoff = std::chrono::microseconds(100);
    for (;;) {
        try {
            Duration left = opts_.bus_send_budget;
            if (give_up != std::chrono::steady_clock::time_point{}) {
                left = std::chrono::duration_cast<Duration>(give_up - std::chrono::steady_clock::now());
                if (left.count() < 0) left = Duration::zero();
            }
            bus_->send(f, left);
            break;
        } catch (const TimeoutError&) {
            if (give_up == std::chrono::steady_clock::time_point{})
                give_up = std::chrono::steady_clock::now() + opts_.bus_send_budget;
            if (std::chrono::steady_clock::now() + backoff >= give_up) {
                ++counters_.bus_send_failures;
                reply_error(c, "send failed: bus busy, frame " + f.to_string() + " not sent");
                return;
            }
            ++counters_.bus_send_retries;
            std::this_thread::sleep_for(backoff);
            backoff *= 2;
        } catch (const Error& e) {  // LinkDown, ClosedError, InvalidArgument
            ++counters_.bus_send_failures;
            reply_error(c, std::string("send failed: ") + e.what());
            return;
        }
    }
    ++frames_to_bus_unpublished_;  // one atomic add per read chunk, not per frame
    // The other clients are nodes on the same bus.  Only this thread changes
    // conns_, so it may look at its size without the lock.
    if (conns_.size() > 1) broadcast(f, &c);
}

void SocketcandServer::handle(Conn& c, const Element& e) {
    using Mode = Conn::Mode;
    switch (e.kind) {
        case ElementKind::Echo:
            reply(c, "< echo >");
            return;
        case ElementKind::Open:
            if (c.mode != Mode::NoBus) return reply_error(c, "bus already open");
            if (!opts_.channel.empty() && e.text != opts_.channel) {
                // protocol.md: an error is returned and the connection is terminated.
                reply_error(c, "unknown bus " + e.text);
                c.closing = true;
                ++counters_.clients_refused;
                return;
            }
            c.mode = Mode::Bcm;
            return reply(c, "< ok >");
        case ElementKind::RawMode:
            if (c.mode == Mode::NoBus) return reply_error(c, "no bus open");
            if (c.mode != Mode::Raw) {
                c.mode = Mode::Raw;
                c.hold_frames_until = monotonic_ns() + kRawModeSettleNs;
                c.raw.store(true);
            }
            return reply(c, "< ok >");
        case ElementKind::BcmMode:
            if (c.mode == Mode::NoBus) return reply_error(c, "no bus open");
            c.mode = Mode::Bcm;
            c.raw.store(false);
            return reply(c, "< ok >");
        case ElementKind::Send:
        case ElementKind::SendRtr:
        case ElementKind::FdSend:
            if (c.mode == Mode::NoBus) return reply_error(c, "no bus open");
            return client_send(c, e.frame);
        default:
            // K9: BCM jobs, control/isotp modes and anything a server would say.
            return reply_error(c, "unknown command");
    }
}

bool SocketcandServer::service_input(Conn& c, Nanos now) {
    static thread_local std::vector<char> storage(64 * 1024);  // the I/O thread's read buffer
    char* buf = storage.data();
    ssize_t r = ::recv(c.fd.get(), buf, storage.size(), MSG_DONTWAIT);
    if (r == 0) return false;
    if (r < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    c.last_rx = now;
    const bool was_mid = c.parser.mid_element();
    const auto done_before = c.parser.stats().elements + c.parser.stats().bad_elements;
    std::uint64_t bad = 0;
    c.parser.feed(std::span<const char>(buf, static_cast<std::size_t>(r)),
                  [&](const Element& e) {
                      if (!c.closing) handle(c, e);
                  },
                  [&](const ParseError& err) {
                      ++bad;
                      reply_error(c, err.reason);  // K10: the client learns why
                  });
    const auto done_after = c.parser.stats().elements + c.parser.stats().bad_elements;
    if (c.parser.mid_element() && (!was_mid || done_after != done_before)) c.element_started = now;
    if (bad) counters_.bad_elements += bad;
    if (frames_to_bus_unpublished_) {
        counters_.frames_to_bus.fetch_add(frames_to_bus_unpublished_, std::memory_order_relaxed);
        frames_to_bus_unpublished_ = 0;
    }
    return true;
}

void SocketcandServer::fill_output(Conn& c) {
    if (!c.raw.load() || c.out.size() - c.out_off >= kOutHighWater) return;
    if (c.hold_frames_until && monotonic_ns() < c.hold_frames_until) return;
    c.hold_frames_until = 0;
    std::size_t head;
    {
        std::lock_guard q(c.qmu);
        if (c.queue.size() == c.queue_head) return;
        c.draining.swap(c.queue);  // c.draining was left empty, with its capacity
        head = c.queue_head;
        c.queue_head = 0;
    }
    const Nanos wall_now = realtime_ns();
    for (std::size_t i = head; i < c.draining.size(); ++i) {
        const Frame& f = c.draining[i];
        socketcand::encode_frame(f, f.timestamp_ns ? f.timestamp_ns + wall_offset_ns_ : wall_now, c.out);
    }
    counters_.frames_to_clients += c.draining.size() - head;
    c.draining.clear();
}

bool SocketcandServer::flush(Conn& c) {
    while (c.out_off < c.out.size()) {
        ssize_t r = ::send(c.fd.get(), c.out.data() + c.out_off, c.out.size() - c.out_off,
                           MSG_NOSIGNAL | MSG_DONTWAIT);
        if (r > 0) {
            c.out_off += static_cast<std::size_t>(r);
        } else if (r < 0 && errno == EINTR) {
            continue;
        } else if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            break;
        } else {
            return false;
        }
    }
    if (c.out_off == c.out.size()) {
        c.out.clear();
        c.out_off = 0;
    } else if (c.out_off > kOutHighWater) {
        c.out.erase(0, c.out_off);
        c.out_off = 0;
    }
    return true;
}

void SocketcandServer::accept_clients() {
    for (;;) {
        int fd = ::accept4(listen_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0) return;  // EAGAIN: no more pending
        net::Fd sock(fd);
        std::size_t active;
        {
            std::lock_guard lk(conns_mutex_);
            active = conns_.size();
        }
        if (active >= opts_.max_clients) {
            static constexpr char kBusy[] = "< error too many clients >";
            [[maybe_unused]] auto r = ::send(fd, kBusy, sizeof kBusy - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
            ++counters_.clients_refused;
            continue;
        }
        net::set_nodelay(fd);
        if (opts_.socket_send_buffer > 0)
            ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &opts_.socket_send_buffer,
                         sizeof opts_.socket_send_buffer);
        auto c = std::make_shared<Conn>(opts_.max_element);
        c->fd = std::move(sock);
        c->connected_at = c->last_rx = monotonic_ns();
        c->out = "< hi >";
        flush(*c);
        ++counters_.clients_accepted;
        std::lock_guard lk(conns_mutex_);
        conns_.push_back(std::move(c));
    }
}

void SocketcandServer::io_loop() {
    std::vector<pollfd> fds;
    std::vector<std::shared_ptr<Conn>> snapshot;  // only this thread changes conns_
    std::vector<char> input_ok;                   // per client: the input pass kept it alive
    const Nanos element_timeout = to_ns(opts_.element_timeout);
    const Nanos idle_timeout = to_ns(opts_.idle_timeout);
    const Nanos open_timeout = to_ns(opts_.open_timeout);
    while (!stop_.load()) {
        snapshot = conns_;
        fds.assign(2 + snapshot.size(), pollfd{});
        fds[0] = {listen_.get(), POLLIN, 0};
        fds[1] = {wake_.fd(), POLLIN, 0};
        int timeout_ms = 50;  // K14 timers are checked at least this often
        for (std::size_t i = 0; i < snapshot.size(); ++i) {
            Conn& c = *snapshot[i];
            short ev = c.closing ? 0 : POLLIN;
            if (c.out_off < c.out.size()) ev |= POLLOUT;
            if (c.hold_frames_until) timeout_ms = 1;
            fds[2 + i] = {c.fd.get(), ev, 0};
        }
        io_sleeping_.store(true);
        if (work_pending_.exchange(false)) timeout_ms = 0;
        int n = ::poll(fds.data(), fds.size(), timeout_ms);
        io_sleeping_.store(false);
        if (n < 0 && errno != EINTR) break;
        if (stop_.load()) break;
        if (n > 0 && (fds[1].revents & POLLIN)) wake_.drain();
        if (n > 0 && (fds[0].revents & POLLIN)) accept_clients();
        const Nanos now = monotonic_ns();
        std::vector<Conn*> dead;
        // Every client's input first, then every client's output: a frame a
        // client sends is queued for the others in the first pass and written
        // in the second.  Doing both per client in accept order left frames
        // for earlier-connected clients waiting for the next poll() wake-up
        // (its 50 ms timeout when nothing else happened), so each request /
        // reply between two clients cost ~50 ms.
        input_ok.assign(snapshot.size(), 1);
        if (n > 0) {
            for (std::size_t i = 0; i < snapshot.size(); ++i)
                if (fds[2 + i].revents & (POLLIN | POLLHUP | POLLERR))
                    input_ok[i] = service_input(*snapshot[i], now);
        }
        for (std::size_t i = 0; i < snapshot.size(); ++i) {
            Conn& c = *snapshot[i];
            bool alive = input_ok[i] != 0;
            if (alive) {
                fill_output(c);
                alive = flush(c);
            }
            bool timed_out = false;
            if (alive && c.parser.mid_element() && now - c.element_started > element_timeout)
                timed_out = true;  // K14: slow-loris, one byte at a time
            if (alive && idle_timeout > 0 && now - c.last_rx > idle_timeout) timed_out = true;
            if (alive && c.mode == Conn::Mode::NoBus && now - c.connected_at > open_timeout)
                timed_out = true;
            if (timed_out) {
                alive = false;
                ++counters_.timeouts;
            }
            if (alive && c.closing && c.out_off == c.out.size()) alive = false;
            if (!alive) dead.push_back(&c);
        }
        if (!dead.empty()) {
            std::lock_guard lk(conns_mutex_);
            std::erase_if(conns_, [&](const std::shared_ptr<Conn>& p) {
                for (Conn* d : dead)
                    if (p.get() == d) return true;
                return false;
            });
        }
    }
}

}  // namespace motorbus::can

#include "motorbus/can/slcan_bus.hpp"

#include <algorithm>
#include <array>

#include "motorbus/errors.hpp"
#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::can {

using slcan::Event;
using slcan::EventKind;
using Clock = std::chrono::steady_clock;

namespace {
// The receive thread wakes at least this often to expire acks and partial lines.
constexpr auto kReadSlice = std::chrono::milliseconds(50);

std::span<const std::uint8_t> as_bytes(const char* p, std::size_t n) {
    return {reinterpret_cast<const std::uint8_t*>(p), n};
}
}  // namespace

void check_options(const SlcanOptions& o) {
    // 0 is a documented choice: leave the adapter's configured rate alone (no S command).
    if (o.bitrate != 0 && !o.btr && !slcan::bitrate_code(o.bitrate))
        throw InvalidArgument("slcan bitrate: " + std::to_string(o.bitrate) +
                              " has no Sn code (10k 20k 50k 100k 125k 250k 500k 750k/800k 1M); "
                              "use btr for other rates, or 0 to keep the adapter's rate");
    if (o.tx_window == 0) throw InvalidArgument("slcan tx_window: must be >= 1");
    const std::pair<const char*, Duration> durations[] = {
        {"ack_timeout", o.ack_timeout},   {"open_timeout", o.open_timeout},
        {"status_poll", o.status_poll},   {"partial_line_timeout", o.partial_line_timeout},
        {"echo_window", o.echo_window},   {"tx_coalesce", o.tx_coalesce},
        {"reconnect_min", o.reconnect_min}, {"reconnect_max", o.reconnect_max}};
    for (const auto& [name, d] : durations)
        if (d.count() < 0) throw InvalidArgument(std::string("slcan ") + name + ": must be >= 0");
    if (o.reconnect_min > o.reconnect_max)
        throw InvalidArgument("slcan reconnect_min: longer than reconnect_max");
    check_options(o.bus, "slcan");
}

SlcanBus::SlcanBus(std::shared_ptr<serial::Port> port, SlcanOptions options, PortFactory reconnect)
    : Bus(port ? "slcan:" + port->name() : "slcan", options.bus),
      opts_(std::move(options)),
      factory_(std::move(reconnect)) {
    if (!port) throw InvalidArgument("slcan: no port");
    check_options(opts_);
    if (auto* tty = dynamic_cast<serial::TtyPort*>(port.get()))
        tty->set_write_timeout(std::chrono::seconds(2));
    try {
        open_sequence(*port);
    } catch (...) {
        port->close();
        throw;
    }
    port_ = std::move(port);
    link_up_ = true;
    stats_.link_up = true;
    thread_ = std::thread([this] { run(); });
    tx_thread_ = std::thread([this] { tx_writer(); });
}

SlcanBus::~SlcanBus() { close(); }

// ------------------------------------------------------------ open sequence --

void SlcanBus::open_sequence(serial::Port& port) {
    port.flush_input();
    decoder_.discard_partial();
    // C first: a previous session may have left the channel open, and the
    // adapter refuses configuration while open.  BEL just means "was closed".
    command_inline(port, "C", true);
    if (opts_.btr) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "s%04X", *opts_.btr);
        command_inline(port, buf, false);
    } else if (opts_.bitrate != 0) {
        command_inline(port, std::string("S") + *slcan::bitrate_code(opts_.bitrate), false);
    }
    if (opts_.timestamps) command_inline(port, "Z1", false);
    command_inline(port, opts_.listen_only ? "L" : "O", false);
}

void SlcanBus::command_inline(serial::Port& port, const std::string& line, bool bel_ok) {
    const std::string bytes = line + "\r";
    awaiting_ = opts_.wait_for_acks;
    awaited_done_ = false;
    awaited_ok_ = false;
    port.write(as_bytes(bytes.data(), bytes.size()));
    if (!opts_.wait_for_acks) return;
    const auto deadline = Clock::now() + opts_.open_timeout;
    std::array<std::uint8_t, 512> buf;
    while (!awaited_done_) {
        {
            std::lock_guard lock(mutex_);
            if (stop_) {
                awaiting_ = false;
                throw ClosedError("slcan " + channel() + ": closed while opening");
            }
        }
        const auto now = Clock::now();
        if (now >= deadline) {
            awaiting_ = false;
            throw TimeoutError("slcan " + channel() + ": no answer to '" + line +
                               "' (an adapter that never answers needs wait_for_acks=False)");
        }
        if (interruptible()) {  // Ctrl-C while an adapter does not answer the open sequence
            try {
                interruption_point();
            } catch (...) {
                awaiting_ = false;
                throw;
            }
        }
        auto slice = std::min<Duration>(deadline - now, kReadSlice);
        std::size_t n = port.read(buf, slice);
        if (n) decoder_.feed(std::span(buf.data(), n), [&](const Event& e) { handle(e); });
    }
    awaiting_ = false;
    if (!awaited_ok_ && !bel_ok)
        throw ProtocolError("slcan " + channel() + ": adapter refused '" + line + "' (BEL)",
                            std::vector<std::uint8_t>(line.begin(), line.end()));
}

// ------------------------------------------------------------------ sending --

void SlcanBus::do_send(const Frame& frame, Deadline deadline) {
    char line[slcan::kMtu];
    const std::size_t n = slcan::encode_frame_into(frame, line);
    std::shared_ptr<serial::Port> port;
    {
        std::unique_lock lock(mutex_);
        // Interruptible: Ctrl-C while the adapter does not acknowledge.
        const bool ok = interruptible_wait_until(cv_, lock, deadline, [&] {
            return stop_ || !link_up_ ||
                   ((!opts_.wait_for_acks || pending_.size() < opts_.tx_window) &&
                    txbuf_.size() + n <= kTxBufMax);
        });
        if (stop_) throw ClosedError("slcan " + channel() + " is closed");
        if (!link_up_) throw LinkDown("slcan " + channel() + ": link down (reconnecting)");
        if (!ok)
            throw TimeoutError("slcan " + channel() + ": " + std::to_string(pending_.size()) +
                               " commands unanswered by the adapter (tx window full)");
        if (opts_.wait_for_acks)
            pending_.push_back(Pending{frame.extended ? 'T' : 't', Clock::now() + opts_.ack_timeout,
                                       true, frame});
        if (opts_.echo_suppression) {
            if (echoes_.size() >= 1024) echoes_.pop_front();
            echoes_.push_back(Echo{frame, Clock::now() + opts_.echo_window});
        }
        const auto now = Clock::now();
        const bool burst = opts_.tx_coalesce > Duration::zero() && now - last_send_ < opts_.tx_coalesce;
        last_send_ = now;
        if (burst || writing_ || !txbuf_.empty()) {
            // Queue behind the line being written; the writer thread sends
            // the whole batch with one write() (order is preserved).
            txbuf_.append(line, n);
            ++txbuf_frames_;
            if (!writing_) cv_.notify_all();
            return;
        }
        // An isolated frame goes straight out: no thread hand-over latency.
        writing_ = true;
        port = port_;
    }
    WriterRelease release{this};
    try {
        port->write(as_bytes(line, n));
    } catch (const LinkDown& e) {
        link_lost(e.what());
        throw;
    } catch (const ClosedError&) {
        throw LinkDown("slcan " + channel() + ": port closed under the send");
    }
}

void SlcanBus::tx_writer() {
    std::string batch;
    std::unique_lock lock(mutex_);
    for (;;) {
        cv_.wait(lock, [&] { return stop_ || (!txbuf_.empty() && !writing_); });
        if (txbuf_.empty()) return;  // stopping with nothing left
        if (!link_up_ || stop_) {
            // The frames were accepted by send() but never reached the adapter.
            for (std::size_t i = 0; i < txbuf_frames_; ++i) count_tx_dropped();
            txbuf_.clear();
            txbuf_frames_ = 0;
            cv_.notify_all();
            if (stop_) return;
            continue;
        }
        writing_ = true;
        batch.swap(txbuf_);
        txbuf_.clear();
        const std::size_t frames = txbuf_frames_;
        txbuf_frames_ = 0;
        auto port = port_;
        lock.unlock();
        bool lost = false;
        try {
            port->write(as_bytes(batch.data(), batch.size()));
        } catch (const LinkDown& e) {
            link_lost(e.what());
            lost = true;
        } catch (const Error&) {
            lost = true;  // closed under us, or the peer stopped reading (write timeout)
        }
        if (lost)
            for (std::size_t i = 0; i < frames; ++i) count_tx_dropped();
        batch.clear();
        lock.lock();
        writing_ = false;
        cv_.notify_all();
    }
}

void SlcanBus::claim_writer(std::unique_lock<std::mutex>& lock, Deadline deadline) {
    // One whole line at a time on the port, and (with acks) at most tx_window
    // unanswered commands: back-pressure instead of an adapter FIFO overflow.
    const bool ok = interruptible_wait_until(cv_, lock, deadline, [&] {
        return stop_ || !link_up_ ||
               (!writing_ && txbuf_.empty() &&
                (!opts_.wait_for_acks || pending_.size() < opts_.tx_window));
    });
    if (stop_) throw ClosedError("slcan " + channel() + " is closed");
    if (!link_up_) throw LinkDown("slcan " + channel() + ": link down (reconnecting)");
    if (!ok)
        throw TimeoutError("slcan " + channel() + ": " + std::to_string(pending_.size()) +
                           " commands unanswered by the adapter (tx window full)");
    writing_ = true;
}

void SlcanBus::release_writer() {
    {
        std::lock_guard lock(mutex_);
        writing_ = false;
    }
    cv_.notify_all();
}

void SlcanBus::write_command(const std::string& text, char kind, Deadline deadline) {
    const std::string line = text + "\r";
    std::shared_ptr<serial::Port> port;
    {
        std::unique_lock lock(mutex_);
        claim_writer(lock, deadline);
        if (opts_.wait_for_acks)
            pending_.push_back(Pending{kind, Clock::now() + opts_.ack_timeout, false, {}});
        port = port_;
    }
    WriterRelease release{this};
    try {
        port->write(as_bytes(line.data(), line.size()));
    } catch (const LinkDown& e) {
        link_lost(e.what());
        throw;
    }
}

void SlcanBus::flush_tx(Duration timeout) {
    std::unique_lock lock(mutex_);
    if (!interruptible_wait_for(cv_, lock, timeout, [&] {
            return stop_ || !link_up_ || (pending_.empty() && txbuf_.empty() && !writing_);
        }))
        throw TimeoutError("slcan " + channel() + ": " + std::to_string(pending_.size()) +
                           " commands still unanswered");
    if (stop_) throw ClosedError("slcan " + channel() + " is closed");
    if (!link_up_) throw LinkDown("slcan " + channel() + ": link down");
    if (nacked_frames_since_flush_) {
        auto n = nacked_frames_since_flush_;
        nacked_frames_since_flush_ = 0;
        std::string last = last_nacked_;
        throw ProtocolError("slcan " + channel() + ": adapter refused " + std::to_string(n) +
                                " frame(s) (BEL); last " + last,
                            std::vector<std::uint8_t>(last.begin(), last.end()));
    }
}

std::uint8_t SlcanBus::query_status(Duration timeout) {
    if (!opts_.wait_for_acks)
        throw InvalidArgument("slcan query_status: needs wait_for_acks (the reply is matched)");
    std::uint64_t before;
    {
        std::lock_guard lock(mutex_);
        before = stats_.status_replies;
    }
    const auto deadline = deadline_after(timeout);
    write_command("F", 'F', deadline);
    std::unique_lock lock(mutex_);
    if (!interruptible_wait_until(cv_, lock, deadline, [&] { return stop_ || stats_.status_replies != before; }))
        throw TimeoutError("slcan " + channel() + ": no answer to 'F'");
    if (stop_) throw ClosedError("slcan " + channel() + " is closed");
    return stats_.last_status;
}

SlcanStats SlcanBus::stats() const {
    std::lock_guard lock(mutex_);
    SlcanStats s = stats_;
    s.partial_lines_dropped = stats_.partial_lines_dropped;
    return s;
}

bool SlcanBus::link_up() const {
    std::lock_guard lock(mutex_);
    return link_up_;
}

// ---------------------------------------------------------------- receiving --

void SlcanBus::handle(const Event& e) {
    switch (e.kind) {
        case EventKind::Frame: {
            if (opts_.echo_suppression) {
                std::lock_guard lock(mutex_);
                const auto now = Clock::now();
                while (!echoes_.empty() && echoes_.front().expires < now) echoes_.pop_front();
                auto it = std::find_if(echoes_.begin(), echoes_.end(),
                                       [&](const Echo& x) { return x.frame.same_content(e.frame); });
                if (it != echoes_.end()) {
                    echoes_.erase(it);
                    ++stats_.echoes_suppressed;
                    return;
                }
            }
            Frame f = e.frame;
            f.timestamp_ns = monotonic_ns();
            dispatch(f);
            return;
        }
        case EventKind::Ok:
        case EventKind::TxAck:
            if (awaiting_) {
                awaited_done_ = true;
                awaited_ok_ = true;
            } else {
                complete_oldest(true, 0);
            }
            return;
        case EventKind::Nack:
            if (awaiting_) {
                awaited_done_ = true;
                awaited_ok_ = false;
            } else {
                complete_oldest(false, 0);
            }
            return;
        case EventKind::Status: {
            if (e.status & slcan::kStatusDataOverrun) count_overrun();
            if (e.status & slcan::kStatusBusError) count_bus_error();
            if (state() != BusState::Closed) set_state(e.state);
            {
                std::lock_guard lock(mutex_);
                stats_.last_status = e.status;
                ++stats_.status_replies;
            }
            if (awaiting_) {
                awaited_done_ = awaited_ok_ = true;
            } else {
                complete_oldest(true, 'F');
            }
            cv_.notify_all();
            return;
        }
        case EventKind::Version:
        case EventKind::Serial: {
            {
                std::lock_guard lock(mutex_);
                (e.kind == EventKind::Version ? stats_.version : stats_.serial_number) = std::string(e.text);
            }
            if (awaiting_) {
                awaited_done_ = awaited_ok_ = true;
            } else {
                complete_oldest(true, e.kind == EventKind::Version ? 'V' : 'N');
            }
            return;
        }
        case EventKind::ErrorReport:
            count_bus_error();
            if (e.error_bits & (slcan::kErrRxOverrun | slcan::kErrTxOverrun)) count_overrun();
            return;
        case EventKind::StateReport:
            if (state() != BusState::Closed) set_state(e.state);
            return;
        case EventKind::Unknown: count_ignored(); return;
        case EventKind::Malformed: count_parse_error(); return;
        case EventKind::Overflow: count_overrun(); return;
    }
}

bool SlcanBus::complete_oldest(bool ok, char reply_kind) {
    std::lock_guard lock(mutex_);
    if (pending_.empty() || (reply_kind != 0 && pending_.front().cmd != reply_kind)) {
        // Unsolicited: a status/version line nobody asked for is just
        // information; a stray CR is ignored; a stray BEL is an adapter error.
        if (!ok) {
            ++stats_.nacks;
            count_bus_error();
        } else if (reply_kind == 0) {
            count_ignored();
        }
        return false;
    }
    Pending p = std::move(pending_.front());
    pending_.pop_front();
    if (ok) {
        ++stats_.acks;
    } else {
        ++stats_.nacks;
        if (p.is_frame) {
            count_tx_dropped();
            ++nacked_frames_since_flush_;
            last_nacked_ = p.frame.to_string();  // rendered only when refused
        }
    }
    cv_.notify_all();
    return true;
}

void SlcanBus::expire_pending(Deadline now) {
    std::lock_guard lock(mutex_);
    bool any = false;
    while (!pending_.empty() && pending_.front().expires <= now) {
        pending_.pop_front();
        ++stats_.ack_timeouts;
        any = true;
    }
    if (any) cv_.notify_all();
}

void SlcanBus::link_lost(const std::string& why) {
    std::shared_ptr<serial::Port> port;
    {
        std::lock_guard lock(mutex_);
        if (!link_up_) return;
        link_up_ = false;
        stats_.link_up = false;
        ++stats_.link_downs;
        stats_.ack_timeouts += pending_.size();
        pending_.clear();
        echoes_.clear();
        for (std::size_t i = 0; i < txbuf_frames_; ++i) count_tx_dropped();
        txbuf_.clear();
        txbuf_frames_ = 0;
        port = port_;
    }
    if (state() != BusState::Closed) set_state(BusState::LinkDown);
    cv_.notify_all();
    // Wakes a writer blocked on the dead port; the receive thread reconnects.
    if (port) port->close();
    // Frames in flight are lost: a waiting SDO transfer ends with LinkDown now
    // rather than at its timeout (Bus link watchers).
    if (!closed()) link_interrupted(why);
}

bool SlcanBus::reopen() {
    std::shared_ptr<serial::Port> port;
    try {
        port = factory_();
        if (!port) return false;
        if (auto* tty = dynamic_cast<serial::TtyPort*>(port.get()))
            tty->set_write_timeout(std::chrono::seconds(2));
        {
            // Senders bail out while the link is down; wait for one still
            // inside write() on the dead port to leave.
            std::unique_lock lock(mutex_);
            cv_.wait(lock, [&] { return !writing_ || stop_; });
            if (stop_) {
                port->close();
                return false;
            }
            writing_ = true;
        }
        WriterRelease release{this};
        open_sequence(*port);
        {
            std::lock_guard lock(mutex_);
            if (stop_) {
                port->close();
                return false;
            }
            port_ = port;
            link_up_ = true;
            stats_.link_up = true;
            ++stats_.reconnects;
        }
        if (state() == BusState::LinkDown) set_state(BusState::Active);
        cv_.notify_all();
        return true;
    } catch (const std::exception&) {
        if (port) port->close();
        return false;
    }
}

void SlcanBus::run() {
    std::array<std::uint8_t, 4096> buf;
    auto last_rx = Clock::now();
    auto next_poll = Clock::now() + opts_.status_poll;
    Duration backoff = opts_.reconnect_min;
    for (;;) {
        std::shared_ptr<serial::Port> port;
        {
            std::unique_lock lock(mutex_);
            if (stop_) return;
            if (!link_up_) {
                if (!factory_) {
                    // Nothing to reconnect with: stay down until closed.
                    cv_.wait(lock, [&] { return stop_; });
                    return;
                }
                // Backoff first, so an adapter that dies right after opening
                // cannot make this loop spin (L14).
                cv_.wait_for(lock, backoff, [&] { return stop_; });
                if (stop_) return;
                lock.unlock();
                const bool ok = reopen();
                backoff = std::min<Duration>(backoff * 2, opts_.reconnect_max);
                if (ok) last_rx = Clock::now();
                continue;
            }
            port = port_;
        }
        std::size_t n = 0;
        try {
            n = port->read(buf, kReadSlice);
        } catch (const LinkDown& e) {
            decoder_.discard_partial();
            link_lost(e.what());
            continue;
        } catch (const ClosedError& e) {
            decoder_.discard_partial();
            link_lost(e.what());
            continue;
        }
        const auto now = Clock::now();
        if (n) {
            decoder_.feed(std::span(buf.data(), n), [&](const Event& e) { handle(e); });
            last_rx = now;
            backoff = opts_.reconnect_min;  // the link carried data: it is healthy again
        } else if (decoder_.pending() && now - last_rx > opts_.partial_line_timeout) {
            decoder_.discard_partial();  // L2
            count_parse_error();
            std::lock_guard lock(mutex_);
            ++stats_.partial_lines_dropped;
        }
        expire_pending(now);
        if (opts_.status_poll > Duration::zero() && now >= next_poll) {
            next_poll = now + opts_.status_poll;
            // Never block the receive thread behind a sender waiting for acks
            // that only this thread can deliver: skip the poll when busy.
            bool claimed = false;
            {
                std::lock_guard lock(mutex_);
                if (!writing_ && txbuf_.empty() && link_up_ &&
                    (!opts_.wait_for_acks || pending_.size() < opts_.tx_window)) {
                    writing_ = claimed = true;
                    if (opts_.wait_for_acks)
                        pending_.push_back(Pending{'F', now + opts_.ack_timeout, false, {}});
                }
            }
            if (claimed) {
                WriterRelease release{this};
                try {
                    port->write(as_bytes("F\r", 2));
                } catch (const Error&) {
                }
            }
        }
    }
}

void SlcanBus::do_close() {
    std::shared_ptr<serial::Port> port;
    bool up;
    {
        std::unique_lock lock(mutex_);
        // Frames already accepted by send() still go out (bounded wait).
        cv_.wait_for(lock, std::chrono::milliseconds(500),
                     [&] { return !link_up_ || (txbuf_.empty() && !writing_); });
        stop_ = true;
        port = port_;
        up = link_up_;
    }
    cv_.notify_all();
    if (tx_thread_.joinable()) tx_thread_.join();
    if (port && up) {
        // Leave the adapter closed, as python-can does; best effort, bounded.
        bool claimed = false;
        {
            std::unique_lock lock(mutex_);
            claimed = cv_.wait_for(lock, std::chrono::milliseconds(200), [&] { return !writing_; });
            if (claimed) writing_ = true;
        }
        if (claimed) {
            WriterRelease release{this};
            try {
                port->write(as_bytes("C\r", 2));
            } catch (const std::exception&) {
            }
        }
    }
    if (port) port->close();
    if (thread_.joinable()) thread_.join();
}

std::shared_ptr<SlcanBus> open_slcan(const std::string& path, unsigned bitrate, SlcanOptions options) {
    options.bitrate = bitrate;
    const unsigned baud = options.tty_baud;
    auto port = serial::open_port(path, baud);
    return std::make_shared<SlcanBus>(std::move(port), std::move(options),
                                      [path, baud] { return serial::open_port(path, baud); });
}

}  // namespace motorbus::can

#include "motorbus/can/bus.hpp"

#include <algorithm>

#include "motorbus/errors.hpp"
#include "motorbus/runtime/completions.hpp"

namespace motorbus::can {

const char* to_string(BusState s) {
    switch (s) {
        case BusState::Active: return "active";
        case BusState::ErrorWarning: return "error-warning";
        case BusState::ErrorPassive: return "error-passive";
        case BusState::BusOff: return "bus-off";
        case BusState::Closed: return "closed";
        case BusState::LinkDown: return "link-down";
    }
    return "unknown";
}

void check_options(const BusOptions& options, const std::string& channel) {
    if (options.rx_queue_size == 0)
        throw InvalidArgument("bus " + channel + " rx_queue_size: 0, must be >= 1 (frames kept for recv())");
}

Bus::Bus(std::string channel, BusOptions options)
    : options_(options), channel_(std::move(channel)) {
    check_options(options_, channel_);
}

Bus::~Bus() {
    // Derived classes must have called close() in their own destructor, while
    // their members still exist; this is only a safety net for the base state.
    closed_.store(true);
    rx_cv_.notify_all();
}

void Bus::send(const Frame& frame, Duration timeout) {
    if (closed_.load()) throw ClosedError("bus " + channel_ + " is closed");
    if (auto p = frame.problem()) throw InvalidArgument(*p);
    if (state_.load() == BusState::BusOff)
        throw LinkDown("bus " + channel_ + " is bus-off: frame not sent");
    do_send(frame, deadline_after(timeout));
    tx_frames_.fetch_add(1, std::memory_order_relaxed);
    tx_bits_.fetch_add(wire_bits_worst_case(frame), std::memory_order_relaxed);
    if (options_.receive_own) {
        Frame own = frame;
        own.flags |= kFlagLoopback;
        if (own.timestamp_ns == 0) own.timestamp_ns = monotonic_ns();
        dispatch(own);
    }
}

void Bus::link_lost(const std::string& reason) {
    {
        std::lock_guard lock(rx_mutex_);
        if (link_lost_.load()) return;
        link_lost_reason_ = reason;
        link_lost_.store(true);
    }
    if (!closed_.load()) set_state(BusState::BusOff);
    rx_cv_.notify_all();
    fail_waiters(std::make_exception_ptr(LinkDown("bus " + channel_ + ": link down: " + reason)));
    link_interrupted(reason);
}

void Bus::link_interrupted(const std::string& reason) {
    {
        std::lock_guard lock(watch_mutex_);
        last_link_loss_ = reason;
        // Counted under the lock that guards the reason: a reader that sees the
        // new count also sees its reason.
        link_losses_.fetch_add(1, std::memory_order_acq_rel);
    }
    notify_link_watchers();
}

std::string Bus::link_loss_reason() const {
    std::lock_guard lock(watch_mutex_);
    return last_link_loss_;
}

SubscriptionId Bus::watch_link(std::function<void()> cb) {
    const SubscriptionId id = next_sub_++;
    std::lock_guard lock(watch_mutex_);
    watchers_.emplace_back(id, std::make_shared<const std::function<void()>>(std::move(cb)));
    return id;
}

void Bus::unwatch_link(SubscriptionId id) {
    std::lock_guard lock(watch_mutex_);
    std::erase_if(watchers_, [&](const auto& w) { return w.first == id; });
}

void Bus::notify_link_watchers() {
    std::vector<std::shared_ptr<const std::function<void()>>> cbs;
    {
        std::lock_guard lock(watch_mutex_);
        for (const auto& w : watchers_) cbs.push_back(w.second);
    }
    // No lock held: a watcher takes its own (an SDO client's), which its owner
    // may hold while it calls send() -- the very call that may find the link dead.
    for (const auto& cb : cbs) (*cb)();
}

// Waits until the recv() queue has a frame: false after `timeout` (negative =
// forever); ClosedError once the bus is closed and the queue drained, LinkDown
// once the link is lost and the queue drained.
bool Bus::wait_for_rx(std::unique_lock<std::mutex>& lock, Duration timeout) {
    if (!rx_queue_.empty()) return true;  // the common case under load: no clock read, no wait
    auto ready = [&] { return !rx_queue_.empty() || closed_.load() || link_lost_.load(); };
    if (timeout.count() == 0 && !ready()) return false;  // a poll: no timed wait (a syscall)
    if (timeout.count() < 0) {
        rx_cv_.wait(lock, ready);
    } else if (!rx_cv_.wait_for(lock, timeout, ready)) {
        return false;
    }
    if (rx_queue_.empty()) {
        if (closed_.load()) throw ClosedError("bus " + channel_ + " is closed");
        throw LinkDown("bus " + channel_ + ": link down: " + link_lost_reason_);
    }
    return true;
}

std::optional<Frame> Bus::recv(Duration timeout) {
    std::unique_lock lock(rx_mutex_);
    recv_used_ = true;
    if (!wait_for_rx(lock, timeout)) return std::nullopt;
    Frame f = rx_queue_.front();
    rx_queue_.pop_front();
    return f;
}

std::vector<Frame> Bus::recv_many(std::size_t max, Duration timeout) {
    std::vector<Frame> out;
    std::unique_lock lock(rx_mutex_);
    recv_used_ = true;
    if (max == 0) return out;
    if (!wait_for_rx(lock, timeout)) return out;
    const auto n = static_cast<std::ptrdiff_t>(std::min(max, rx_queue_.size()));
    out.assign(rx_queue_.begin(), rx_queue_.begin() + n);
    rx_queue_.erase(rx_queue_.begin(), rx_queue_.begin() + n);
    return out;
}

std::vector<Frame> Bus::recv_or_wait(std::size_t max, std::shared_ptr<Completions> done, std::uint64_t token) {
    if (max == 0) throw InvalidArgument("bus " + channel_ + " recv: max 0, must be >= 1 frame");
    if (!done) throw InvalidArgument("bus " + channel_ + " recv: no completion queue");
    std::vector<Frame> out;
    std::unique_lock lock(rx_mutex_);
    recv_used_ = true;
    if (wait_for_rx(lock, Duration::zero())) {  // throws once closed / link-down and drained
        const auto n = static_cast<std::ptrdiff_t>(std::min(max, rx_queue_.size()));
        out.assign(rx_queue_.begin(), rx_queue_.begin() + n);
        rx_queue_.erase(rx_queue_.begin(), rx_queue_.begin() + n);
        return out;
    }
    rx_waiters_.push_back(RxWaiter{std::move(done), token, max});
    return out;
}

bool Bus::cancel_wait(const Completions* done, std::uint64_t token) {
    std::lock_guard lock(rx_mutex_);
    auto it = std::find_if(rx_waiters_.begin(), rx_waiters_.end(),
                           [&](const RxWaiter& w) { return w.done.get() == done && w.token == token; });
    if (it == rx_waiters_.end()) return false;
    rx_waiters_.erase(it);
    return true;
}

void Bus::fail_waiters(std::exception_ptr error) {
    std::deque<RxWaiter> waiters;
    {
        std::lock_guard lock(rx_mutex_);
        waiters.swap(rx_waiters_);
    }
    // Outside the lock: a loop without add_reader is woken by a call that takes the GIL.
    for (auto& w : waiters) w.done->fail(w.token, error);
}

void Bus::set_filters(std::vector<Filter> filters) {
    std::lock_guard lock(rx_mutex_);
    recv_used_ = true;  // filters are for recv(): someone means to read
    filters_ = std::move(filters);
}

SubscriptionId Bus::add_subscriber(std::shared_ptr<Subscriber> s, bool exact) {
    std::lock_guard lock(table_mutex_);
    auto t = std::make_shared<Table>(*table_);
    if (exact)
        t->by_id[id_key(s->filter.id, s->filter.extended)].push_back(s);
    else
        t->masked.push_back(s);
    table_ = std::move(t);
    subscriber_count_.fetch_add(1, std::memory_order_release);
    return s->id;
}

SubscriptionId Bus::subscribe(const Filter& filter, FrameCallback cb) {
    auto s = std::make_shared<Subscriber>(Subscriber{next_sub_++, filter, std::move(cb)});
    const bool exact = filter.match_extended &&
                       filter.mask == (filter.extended ? kMaxExtendedId : kMaxStandardId);
    return add_subscriber(std::move(s), exact);
}

SubscriptionId Bus::subscribe_id(std::uint32_t id, bool extended, FrameCallback cb) {
    Filter f{id, extended ? kMaxExtendedId : kMaxStandardId, extended, true};
    return subscribe(f, std::move(cb));
}

void Bus::unsubscribe(SubscriptionId sid) {
    {
        std::lock_guard lock(table_mutex_);
        auto t = std::make_shared<Table>(*table_);
        auto drop = [&](std::vector<std::shared_ptr<Subscriber>>& v) {
            v.erase(std::remove_if(v.begin(), v.end(), [&](auto& s) { return s->id == sid; }),
                    v.end());
        };
        for (auto it = t->by_id.begin(); it != t->by_id.end();) {
            drop(it->second);
            it = it->second.empty() ? t->by_id.erase(it) : std::next(it);
        }
        drop(t->masked);
        std::size_t n = t->masked.size();
        for (auto& [k, v] : t->by_id) n += v.size();
        subscriber_count_.store(static_cast<int>(n), std::memory_order_release);
        table_ = std::move(t);
    }
    // Wait for an in-flight dispatch on another thread to finish, so the
    // caller may destroy whatever the callback captured.
    if (dispatch_thread_.load() != std::this_thread::get_id()) {
        std::lock_guard wait(dispatch_mutex_);
    }
}

void Bus::dispatch_batch(std::span<const Frame> frames) {
    if (frames.empty()) return;
    rx_frames_.fetch_add(frames.size(), std::memory_order_relaxed);
    std::uint64_t bits = 0;
    for (const auto& f : frames)
        if (!(f.flags & kFlagLoopback)) bits += wire_bits_worst_case(f);
    rx_bits_.fetch_add(bits, std::memory_order_relaxed);
    std::shared_ptr<const Table> table;
    {
        std::lock_guard lock(table_mutex_);
        table = table_;
    }
    const bool callbacks = !table->by_id.empty() || !table->masked.empty();
    if (callbacks) {
        std::lock_guard running(dispatch_mutex_);
        dispatch_thread_.store(std::this_thread::get_id());
        for (const Frame& frame : frames) {
            if (auto it = table->by_id.find(id_key(frame.id, frame.extended)); it != table->by_id.end())
                for (auto& s : it->second) s->cb(frame);
            for (auto& s : table->masked)
                if (s->filter.matches(frame)) s->cb(frame);
        }
        dispatch_thread_.store(std::thread::id{});
    }
    std::vector<std::pair<RxWaiter, std::vector<Frame>>> served;
    {
        std::lock_guard lock(rx_mutex_);
        // Read only through callbacks so far: keep a few frames, not rx_queue_size.
        const std::size_t cap =
            callbacks && !recv_used_ ? std::min(options_.rx_queue_size, kUnreadQueueCap) : options_.rx_queue_size;
        for (const Frame& frame : frames) {
            if (!filters_.empty() &&
                std::none_of(filters_.begin(), filters_.end(),
                             [&](const Filter& f) { return f.matches(frame); }))
                continue;
            while (rx_queue_.size() >= cap) {
                rx_queue_.pop_front();
                rx_dropped_.fetch_add(1, std::memory_order_relaxed);
            }
            rx_queue_.push_back(frame);
        }
        // Event-loop waiters take what arrived, each in one batch: the loop wakes once per burst.
        while (!rx_waiters_.empty() && !rx_queue_.empty()) {
            RxWaiter w = std::move(rx_waiters_.front());
            rx_waiters_.pop_front();
            const auto n = static_cast<std::ptrdiff_t>(std::min(w.max, rx_queue_.size()));
            served.emplace_back(std::move(w), std::vector<Frame>(rx_queue_.begin(), rx_queue_.begin() + n));
            rx_queue_.erase(rx_queue_.begin(), rx_queue_.begin() + n);
        }
    }
    // Outside rx_mutex_: a loop without add_reader is woken by a call that takes the GIL.
    for (auto& [w, batch] : served) w.done->push(w.token, std::move(batch));
    if (frames.size() == 1)
        rx_cv_.notify_one();
    else
        rx_cv_.notify_all();
}

BusCounters Bus::counters() const {
    BusCounters c;
    c.rx_frames = rx_frames_.load();
    c.tx_frames = tx_frames_.load();
    c.rx_dropped = rx_dropped_.load();
    c.tx_dropped = tx_dropped_.load();
    c.overruns = overruns_.load();
    c.parse_errors = parse_errors_.load();
    c.bus_errors = bus_errors_.load();
    c.ignored = ignored_.load();
    c.rx_bits = rx_bits_.load();
    c.tx_bits = tx_bits_.load();
    return c;
}

void Bus::close() {
    std::call_once(close_once_, [&] {
        closed_.store(true);
        // Before do_close(), which may take a while (joins): a transfer waiting
        // for a response on another thread ends now with ClosedError.
        notify_link_watchers();
        do_close();
        state_.store(BusState::Closed);
        rx_cv_.notify_all();
        fail_waiters(std::make_exception_ptr(ClosedError("bus " + channel_ + " is closed")));
    });
}

}  // namespace motorbus::can

#include "motorbus/can/virtual_bus.hpp"

#include <algorithm>
#include <cmath>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <queue>
#include <random>
#include <thread>
#include <vector>

#include "motorbus/errors.hpp"
#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::can {

namespace {
using Clock = std::chrono::steady_clock;
Clock::time_point at_ns(Nanos t) { return Clock::time_point(std::chrono::nanoseconds(t)); }
}  // namespace

// ---------------------------------------------------------------------------
// Hub: the shared medium.
class VirtualHub : public std::enable_shared_from_this<VirtualHub> {
public:
    VirtualHub(std::string name, double bitrate) : name_(std::move(name)), bitrate_(bitrate) {}
    ~VirtualHub() { stop_wire(); }

    const std::string& name() const { return name_; }
    double bitrate() const { return bitrate_; }
    bool timed() const { return bitrate_ > 0; }

    void attach(VirtualBus* ep) {
        std::lock_guard lock(mutex_);
        endpoints_.push_back(ep);
    }
    void detach(VirtualBus* ep) {
        std::unique_lock lock(mutex_);
        // Wait until no delivery holds a reference to this endpoint.
        idle_cv_.wait(lock, [&] { return delivering_ == 0; });
        endpoints_.erase(std::remove(endpoints_.begin(), endpoints_.end(), ep), endpoints_.end());
        wire_cv_.notify_all();
    }

    // Hands `f` to every endpoint but the sender, now.  One frame at a time: on a
    // wire every node sees the frames in one order, so a reply that an endpoint
    // sends the moment it receives a request (its receive thread runs while this
    // loop is still handing the request to the others) waits here until the
    // request has reached everyone; without it a third endpoint (candump, a
    // recorder) saw the reply before the request.  Recursive: a delivery that
    // runs no callback never sends, but one that did must not deadlock.
    void deliver(const Frame& f, const VirtualBus* sender) {
        std::lock_guard order(order_mutex_);
        std::vector<VirtualBus*> targets;
        {
            std::lock_guard lock(mutex_);
            ++delivering_;
            targets = endpoints_;
        }
        for (auto* ep : targets)
            if (ep != sender) ep->enqueue_rx(f);
        {
            std::lock_guard lock(mutex_);
            --delivering_;
        }
        idle_cv_.notify_all();
    }

    // Timed path: a frame waiting for the wire (bitrate > 0) or for its delay.
    struct Pending {
        Frame frame;
        const VirtualBus* sender;
        Nanos enqueued;
        Nanos delay;
    };
    // Blocks while the sender already has `cap` frames waiting; false on timeout.
    bool submit(Pending p, std::size_t cap, Deadline deadline) {
        std::unique_lock lock(mutex_);
        ensure_wire();
        auto& q = tx_[p.sender];
        // Interruptible: Ctrl-C while the wire is saturated (the check runs
        // with the hub unlocked; `q` stays valid, only forget_sender() erases it,
        // and not while its endpoint is sending).
        if (timed() &&
            !interruptible_wait_until(space_cv_, lock, deadline, [&] { return q.size() < cap || stopping_; }))
            return false;
        if (!timed()) {
            delayed_.push(Due{p.enqueued + p.delay, seq_++, p.frame, p.sender});
        } else {
            q.push_back(std::move(p));
        }
        wire_cv_.notify_all();
        return true;
    }
    void forget_sender(const VirtualBus* s) {
        std::lock_guard lock(mutex_);
        tx_.erase(s);
        space_cv_.notify_all();
    }

private:
    struct Due {
        Nanos due;
        std::uint64_t seq;
        Frame frame;
        const VirtualBus* sender;
        Nanos delay = 0;  // fault delay still to apply after the wire (wire frames only)
        bool operator>(const Due& o) const { return due != o.due ? due > o.due : seq > o.seq; }
    };

    void ensure_wire() {
        if (!wire_.joinable()) wire_ = std::thread([this] { wire_loop(); });
    }
    void stop_wire() {
        {
            std::lock_guard lock(mutex_);
            stopping_ = true;
        }
        wire_cv_.notify_all();
        space_cv_.notify_all();
        if (wire_.joinable()) wire_.join();
    }

    // The wire: arbitration by lowest id among the heads of the transmit
    // queues, then the frame's bit time, then its fault delay.  Start times are
    // computed from the ideal schedule (not from when this thread woke up), so
    // the frame rate is exact even though each wake-up is a little late.
    void wire_loop() {
        std::unique_lock lock(mutex_);
        std::optional<Due> on_wire;  // frame being transmitted, due = end of its last bit
        while (!stopping_) {
            const Nanos now = monotonic_ns();
            // 1. frames whose delay elapsed
            // Every branch that drops the lock to deliver starts the loop over,
            // so nothing that changed meanwhile (a stop, a new frame) is slept through.
            if (!delayed_.empty() && delayed_.top().due <= now) {
                Due d = delayed_.top();
                delayed_.pop();
                d.frame.timestamp_ns = d.due;
                lock.unlock();
                deliver(d.frame, d.sender);
                lock.lock();
                continue;
            }
            // 2. end of the frame on the wire
            if (on_wire && on_wire->due <= now) {
                Due d = *on_wire;
                on_wire.reset();
                wire_free_ = d.due;
                if (d.delay > 0) {
                    delayed_.push(Due{d.due + d.delay, seq_++, d.frame, d.sender});
                } else {
                    d.frame.timestamp_ns = d.due;
                    lock.unlock();
                    deliver(d.frame, d.sender);
                    lock.lock();
                }
                continue;
            }
            // 3. arbitration for the next frame: the wire is next free at
            // t_start; every head queued by then competes, lowest id wins.
            if (!on_wire && timed()) {
                Nanos t_start = INT64_MAX;
                for (auto& [sender, q] : tx_)
                    if (!q.empty()) t_start = std::min(t_start, q.front().enqueued);
                if (t_start != INT64_MAX) {
                    t_start = std::max(t_start, wire_free_);
                    std::deque<Pending>* best = nullptr;
                    for (auto& [sender, q] : tx_) {
                        if (q.empty() || q.front().enqueued > t_start) continue;
                        if (!best || arbitration_key(q.front().frame) < arbitration_key(best->front().frame))
                            best = &q;
                    }
                    Pending p = std::move(best->front());
                    best->pop_front();
                    space_cv_.notify_all();
                    const auto bits = wire_bits_worst_case(p.frame);
                    const Nanos dur = static_cast<Nanos>(bits * 1e9 / bitrate_ + 0.5);
                    on_wire = Due{t_start + dur, seq_++, p.frame, p.sender, p.delay};
                    wire_free_ = t_start + dur;
                    continue;
                }
            }
            // 4. sleep until the next event
            Nanos next = INT64_MAX;
            if (on_wire) next = on_wire->due;
            if (!delayed_.empty()) next = std::min(next, delayed_.top().due);
            if (next == INT64_MAX)
                wire_cv_.wait(lock);
            else
                wire_cv_.wait_until(lock, at_ns(next));
        }
    }

    // Lower wins: the 11-bit id is compared as its top bits of the 29-bit space,
    // and at equal base id a standard frame beats an extended one.
    static std::uint64_t arbitration_key(const Frame& f) {
        std::uint64_t base = f.extended ? (f.id >> 18) : f.id;
        std::uint64_t ext = f.extended ? (f.id & 0x3FFFF) : 0;
        return (base << 20) | (static_cast<std::uint64_t>(f.extended) << 19) | (ext << 1) |
               static_cast<std::uint64_t>(f.rtr);
    }

    std::string name_;
    double bitrate_;
    std::mutex mutex_;
    std::condition_variable wire_cv_, space_cv_, idle_cv_;
    std::vector<VirtualBus*> endpoints_;
    int delivering_ = 0;
    std::recursive_mutex order_mutex_;  // one fan-out at a time (deliver)
    std::map<const VirtualBus*, std::deque<Pending>> tx_;
    std::priority_queue<Due, std::vector<Due>, std::greater<Due>> delayed_;
    std::uint64_t seq_ = 0;
    Nanos wire_free_ = 0;
    bool stopping_ = false;
    std::thread wire_;
};

namespace {
std::mutex g_hubs_mutex;
std::map<std::string, std::weak_ptr<VirtualHub>> g_hubs;
}  // namespace

// ---------------------------------------------------------------------------
// Endpoint: an inbox filled by the hub, drained by this endpoint's own
// receive thread, which runs subscribers and feeds recv().
struct VirtualBus::Impl {
    std::shared_ptr<VirtualHub> hub;
    VirtualOptions opts;
    std::mutex mutex;
    std::condition_variable cv;
    std::vector<Frame> inbox;
    bool stop = false;
    bool bus_off = false;
    bool dispatching = false;  // the receive thread is working through a batch
    bool sleeping = false;     // the receive thread waits on `cv` (needs a notify)
    std::atomic<bool> pending{false};  // inbox non-empty, read by the spinning receive thread
    FaultOptions faults;
    std::mt19937_64 rng;
    std::uint64_t sent_count = 0;
    std::thread rx_thread;
    static constexpr std::size_t kInboxCap = 1 << 16;
};

VirtualBus::VirtualBus(std::shared_ptr<VirtualHub> hub, std::string channel,
                       const VirtualOptions& opts)
    : Bus(std::move(channel), opts), impl_(std::make_unique<Impl>()) {
    impl_->hub = std::move(hub);
    impl_->opts = opts;
    impl_->faults = opts.faults;
    impl_->rng.seed(opts.faults.seed);
    impl_->rx_thread = std::thread([this] {
        std::vector<Frame> batch;
        const auto spin = impl_->opts.rx_spin;  // >= 0, checked by open_virtual
        for (;;) {
            // Request/response traffic (an SDO exchange) brings the next frame
            // a few microseconds after the last batch: poll for it briefly
            // before sleeping, so neither side pays a futex wake-up per frame.
            if (spin.count() > 0 && !impl_->pending.load(std::memory_order_acquire)) {
                const auto until = std::chrono::steady_clock::now() + spin;
                while (!impl_->pending.load(std::memory_order_acquire) &&
                       std::chrono::steady_clock::now() < until)
                    std::this_thread::yield();
            }
            {
                std::unique_lock lock(impl_->mutex);
                impl_->sleeping = true;
                impl_->cv.wait(lock, [&] { return impl_->stop || !impl_->inbox.empty(); });
                impl_->sleeping = false;
                if (impl_->stop) return;
                batch.swap(impl_->inbox);
                impl_->pending.store(false, std::memory_order_relaxed);
                impl_->dispatching = true;
            }
            for (const Frame& f : batch) dispatch(f);
            batch.clear();
            std::lock_guard lock(impl_->mutex);
            impl_->dispatching = false;
        }
    });
    impl_->hub->attach(this);
}

VirtualBus::~VirtualBus() { close(); }

void VirtualBus::do_close() {
    impl_->hub->detach(this);
    impl_->hub->forget_sender(this);
    {
        std::lock_guard lock(impl_->mutex);
        impl_->stop = true;
        impl_->pending.store(true, std::memory_order_release);  // ends a spin at once
    }
    impl_->cv.notify_all();
    if (impl_->rx_thread.joinable() && impl_->rx_thread.get_id() != std::this_thread::get_id())
        impl_->rx_thread.join();
    else if (impl_->rx_thread.joinable())
        impl_->rx_thread.detach();
}

void VirtualBus::enqueue_rx(const Frame& f) {
    bool wake = false, direct = false;
    {
        std::lock_guard lock(impl_->mutex);
        if (impl_->stop || impl_->bus_off) return;
        // No callback to run and nothing older in flight: hand the frame to
        // recv() directly and save two thread wake-ups per frame.
        if (impl_->inbox.empty() && !impl_->dispatching && !has_subscribers()) direct = true;
    }
    if (direct) {
        dispatch(f);
        return;
    }
    {
        std::lock_guard lock(impl_->mutex);
        if (impl_->stop || impl_->bus_off) return;
        if (impl_->inbox.size() >= Impl::kInboxCap) {
            // The receive thread is stuck in a slow callback: a real controller
            // would overrun its FIFO.  Count it; never block the sender.
            count_overrun();
            return;
        }
        wake = impl_->inbox.empty() && impl_->sleeping;
        impl_->inbox.push_back(f);
        impl_->pending.store(true, std::memory_order_release);
    }
    if (wake) impl_->cv.notify_one();
}

void VirtualBus::set_faults(const FaultOptions& f) {
    check_options(f);
    std::lock_guard lock(impl_->mutex);
    impl_->faults = f;
    impl_->rng.seed(f.seed);
    impl_->sent_count = 0;
}

void VirtualBus::set_bus_off(bool off) {
    {
        std::lock_guard lock(impl_->mutex);
        impl_->bus_off = off;
    }
    set_state(off ? BusState::BusOff : BusState::Active);
    if (off) count_bus_error();
}

double VirtualBus::bitrate() const { return impl_->hub->bitrate(); }

const void* VirtualBus::medium() const { return impl_->hub.get(); }

void VirtualBus::do_send(const Frame& frame, Deadline deadline) {
    Frame f = frame;
    Nanos delay;
    {
        std::lock_guard lock(impl_->mutex);
        auto& fl = impl_->faults;
        ++impl_->sent_count;
        std::uniform_real_distribution<double> u(0.0, 1.0);
        if ((fl.drop_every && impl_->sent_count % fl.drop_every == 0) ||
            (fl.drop_probability > 0 && u(impl_->rng) < fl.drop_probability)) {
            count_tx_dropped();
            return;
        }
        if (fl.corrupt_probability > 0 && f.len > 0 && !f.rtr && u(impl_->rng) < fl.corrupt_probability) {
            const auto bit = impl_->rng() % (8u * f.len);
            f.data[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
        }
        delay = fl.delay_ns;
    }
    const Nanos now = monotonic_ns();
    f.timestamp_ns = now;
    if (!impl_->hub->timed() && delay == 0) {
        impl_->hub->deliver(f, this);
        return;
    }
    if (!impl_->hub->submit({f, this, now, delay}, impl_->opts.tx_queue, deadline))
        throw TimeoutError("virtual bus " + channel() + ": transmit queue full (" +
                           std::to_string(impl_->opts.tx_queue) + " frames waiting for the wire)");
}

void check_options(const FaultOptions& f) {
    auto prob = [](const char* name, double p) {
        if (!(p >= 0.0 && p <= 1.0))  // NaN fails both
            throw InvalidArgument(std::string("virtual bus faults ") + name + ": " + std::to_string(p) +
                                  ", must be in [0, 1]");
    };
    prob("drop_probability", f.drop_probability);
    prob("corrupt_probability", f.corrupt_probability);
    if (f.delay_ns < 0)
        throw InvalidArgument("virtual bus faults delay: " + std::to_string(f.delay_ns) + " ns, must be >= 0");
}

void check_options(const VirtualOptions& opts) {
    // 0 = no wire time; otherwise a rate whose frame times are representable:
    // 1e-9 bit/s made a frame last 1.6e20 ns, past Nanos (UBSan: float-cast-overflow).
    if (!(opts.bitrate == 0 || (opts.bitrate >= kMinVirtualBitrate && opts.bitrate <= kMaxVirtualBitrate)))
        throw InvalidArgument("virtual bus bitrate: " + std::to_string(opts.bitrate) +
                               " bit/s, must be 0 (no wire time) or 1 to 1e9 bit/s");
    if (opts.rx_spin.count() < 0) throw InvalidArgument("virtual bus rx_spin: must be >= 0");
    if (opts.tx_queue == 0) throw InvalidArgument("virtual bus tx_queue: 0, must be >= 1 (frames waiting for the wire)");
    if (opts.rx_queue_size == 0)
        throw InvalidArgument("virtual bus rx_queue_size: 0, must be >= 1 (frames kept for recv())");
    check_options(opts.faults);
}

std::shared_ptr<VirtualBus> open_virtual(const std::string& name, const VirtualOptions& opts) {
    if (name.empty()) throw InvalidArgument("virtual bus name: must not be empty");
    check_options(opts);
    std::shared_ptr<VirtualHub> hub;
    {
        std::lock_guard lock(g_hubs_mutex);
        hub = g_hubs[name].lock();
        if (!hub) {
            hub = std::make_shared<VirtualHub>(name, opts.bitrate);
            g_hubs[name] = hub;
        } else if (hub->bitrate() != opts.bitrate) {
            throw InvalidArgument("virtual bus bitrate: " + std::to_string(opts.bitrate) +
                                  " differs from the " + std::to_string(hub->bitrate()) +
                                  " of the endpoints already on '" + name + "'");
        }
        for (auto it = g_hubs.begin(); it != g_hubs.end();)
            it = it->second.expired() ? g_hubs.erase(it) : std::next(it);
    }
    return std::make_shared<VirtualBus>(hub, "virtual:" + name, opts);
}

}  // namespace motorbus::can

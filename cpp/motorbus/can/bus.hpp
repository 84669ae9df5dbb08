// The bus every backend implements.
//
// A backend (virtual, SLCAN, socketcand, SocketCAN, bridge) only has to
//   * put frames on its medium in do_send(), blocking until `deadline` when
//     the medium is full (back-pressure, never a silent drop), and
//   * call dispatch() from its single receive thread for every frame it gets.
// The base class owns everything else: acceptance filters, the bounded queue
// behind recv(), subscribers dispatched by CAN id, counters and bus state.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "motorbus/can/frame.hpp"

namespace motorbus {
class Completions;  // motorbus/runtime/completions.hpp
}

namespace motorbus::can {

using Duration = std::chrono::nanoseconds;
using Deadline = std::chrono::steady_clock::time_point;
inline Deadline deadline_after(Duration d) { return std::chrono::steady_clock::now() + d; }

// LinkDown: the link to the adapter or server is gone (unplugged, killed) and the
// backend is reconnecting; frames can neither be sent nor received meanwhile.
enum class BusState { Active, ErrorWarning, ErrorPassive, BusOff, Closed, LinkDown };
const char* to_string(BusState s);

struct BusCounters {
    std::uint64_t rx_frames = 0;     // frames received from the medium
    std::uint64_t tx_frames = 0;     // frames handed to the medium
    std::uint64_t rx_dropped = 0;    // received frames dropped because recv() queue was full
    std::uint64_t tx_dropped = 0;    // frames the medium lost (fault injection, adapter NACK)
    std::uint64_t overruns = 0;      // adapter/medium reported overrun or line too long
    std::uint64_t parse_errors = 0;  // malformed input from the medium, discarded
    std::uint64_t bus_errors = 0;    // error frames / BEL / error states reported
    std::uint64_t ignored = 0;       // well-formed input we do not use (status lines etc.)
    // The wire bits of those frames (wire_bits_worst_case each, our own echoes left out):
    // their rate over the bit rate is the bus load this program sees, counted where the
    // frames pass anyway rather than by a listener per frame in Python.
    std::uint64_t rx_bits = 0;
    std::uint64_t tx_bits = 0;
};

using FrameCallback = std::function<void(const Frame&)>;
using SubscriptionId = std::uint64_t;

// A bus with subscribers (callbacks) on which recv()/recv_many()/set_filters()
// was never called keeps at most this many frames for a recv() that may never
// come: a simulated node or a server endpoint consumes frames only through its
// callbacks, and 127 of them kept 65 536 unread frames each (811 MB).  The first
// recv() (or set_filters()) lifts the cap to rx_queue_size; the newest frames
// are kept, the others counted in rx_dropped.
constexpr std::size_t kUnreadQueueCap = 1024;

struct BusOptions {
    // Frames kept for recv(); the oldest is dropped past this.  >= 1
    // (InvalidArgument otherwise: 0 used to pop from an empty queue).
    // See kUnreadQueueCap for a bus read only through callbacks.
    std::size_t rx_queue_size = 65536;
    bool receive_own = false;           // deliver frames we sent back to recv()/subscribers
};

// Throws InvalidArgument naming the field (and `channel`) for a value no bus can
// work with.  Every bus constructor calls it; the fuzz target fuzz/options.cpp too.
void check_options(const BusOptions& options, const std::string& channel);

class Bus {
public:
    explicit Bus(std::string channel, BusOptions options = {});
    virtual ~Bus();
    Bus(const Bus&) = delete;
    Bus& operator=(const Bus&) = delete;

    // Puts `frame` on the bus.  Blocks while the medium is full; throws
    // TimeoutError when it is still full after `timeout`, InvalidArgument for an
    // invalid frame, ClosedError after close(), LinkDown when the medium is gone.
    void send(const Frame& frame, Duration timeout = std::chrono::seconds(1));

    // Next frame that passed the filters, or nullopt after `timeout`
    // (a negative timeout waits forever).  Throws ClosedError once closed and
    // drained, LinkDown once the backend lost its link and the queue is drained
    // (a waiter is woken at once when the link dies).
    std::optional<Frame> recv(Duration timeout);

    // Up to `max` frames at once, oldest first: waits like recv() for the
    // first, then takes whatever else is already queued without waiting.
    // Empty after `timeout`.  One lock (and, from Python, one GIL release) per
    // batch instead of per frame, for consumers that drain a busy bus.
    std::vector<Frame> recv_many(std::size_t max, Duration timeout);

    // recv() for an event loop (completion-based: no thread waits).  Returns up
    // to `max` queued frames at once when there are any.  Otherwise returns an
    // empty vector and leaves a waiter: the next frames that pass the filters
    // are pushed to `done` under `token` as one std::vector<Frame> (a burst is
    // one completion), or the ClosedError / LinkDown that recv() would throw
    // is failed into it.  Throws like recv() when closed or link-down and
    // drained; InvalidArgument for max 0.
    std::vector<Frame> recv_or_wait(std::size_t max, std::shared_ptr<Completions> done, std::uint64_t token);
    // Withdraws a waiter of recv_or_wait (a cancelled await): false when it was
    // already completed (its frames are then on their way to `done`).
    bool cancel_wait(const Completions* done, std::uint64_t token);

    // Acceptance filters for recv() (subscribers have their own).  Empty = all.
    void set_filters(std::vector<Filter> filters);

    // Calls `cb` on the bus's receive thread for each frame passing `filter`.
    // Subscriptions to one exact id are found by hash lookup, so many clients on
    // one bus cost O(1) per frame.  Callbacks must not block for long.
    SubscriptionId subscribe(const Filter& filter, FrameCallback cb);
    SubscriptionId subscribe_id(std::uint32_t id, bool extended, FrameCallback cb);
    // After it returns, the callback is not running and will not run again
    // (unless called from inside that very callback).
    void unsubscribe(SubscriptionId id);

    BusState state() const { return state_.load(); }
    BusCounters counters() const;
    const std::string& channel() const { return channel_; }
    bool closed() const { return closed_.load(); }

    // Stops the backend, wakes every waiter.  Idempotent.
    void close();

    // Link watchers: `cb` runs (on whichever thread notices, with no bus lock
    // held) when the link is lost -- for good (link_lost()) or while the backend
    // reconnects (link_interrupted()) -- and when close() starts.  For a waiter
    // that is not in recv() (an SDO transfer waiting for its response) to wake at
    // once instead of at its timeout.  `cb` must be quick and must not call back
    // into this bus; it may still run once just after unwatch_link() returns,
    // so it must capture only what outlives that (a shared_ptr).
    SubscriptionId watch_link(std::function<void()> cb);
    void unwatch_link(SubscriptionId id);
    // How many times the link was lost or interrupted since the bus opened, and
    // why the last time (empty if never): a transfer that sees the count change
    // while it waits knows frames of its exchange may have been lost.
    std::uint64_t link_losses() const { return link_losses_.load(std::memory_order_acquire); }
    std::string link_loss_reason() const;

    // Identity of the medium this endpoint is on: endpoints that see each
    // other's frames as one bus share it (all endpoints of one virtual hub).
    // Default: this bus object.  Lets a node-ID be claimed once per medium.
    virtual const void* medium() const { return this; }

protected:
    // Backend hooks ----------------------------------------------------------
    virtual void do_send(const Frame& frame, Deadline deadline) = 0;
    // Stop I/O and join the receive thread.  Called once, from close().
    virtual void do_close() = 0;

    // Called from the receive thread for each received frame.
    void dispatch(const Frame& frame) { dispatch_batch({&frame, 1}); }
    // The same for every frame of one read: one lock and one wake-up for the
    // batch instead of one per frame (stream backends parse many per read).
    void dispatch_batch(std::span<const Frame> frames);
    // Backends must call this at the end of their destructor-initiated close
    // path; derived destructors call close() themselves (virtual dispatch).
    void set_state(BusState s) { state_.store(s); }
    // The medium is gone for good (TCP EOF, reset, keepalive silence): the
    // state turns bus-off, send() refuses with LinkDown, and every recv() /
    // recv_many() waiter -- now or later, once the queue is drained -- gets
    // LinkDown(reason) instead of waiting forever.  Not for our own close().
    void link_lost(const std::string& reason);
    // The link dropped but the backend reconnects by itself (an SLCAN adapter
    // unplugged): recv() goes on, but link watchers are told and link_losses()
    // counts it, since frames in flight were lost.
    void link_interrupted(const std::string& reason);

    // True while anyone is subscribed; lets a backend skip its thread hop
    // when there is no callback to run (frames then go straight to recv()).
    bool has_subscribers() const { return subscriber_count_.load(std::memory_order_acquire) > 0; }

    // Counter bumps for backends.
    void count_parse_error() { parse_errors_.fetch_add(1, std::memory_order_relaxed); }
    void count_overrun() { overruns_.fetch_add(1, std::memory_order_relaxed); }
    void count_bus_error() { bus_errors_.fetch_add(1, std::memory_order_relaxed); }
    void count_tx_dropped() { tx_dropped_.fetch_add(1, std::memory_order_relaxed); }
    void count_ignored() { ignored_.fetch_add(1, std::memory_order_relaxed); }

    const BusOptions options_;

private:
    struct Subscriber {
        SubscriptionId id;
        Filter filter;
        FrameCallback cb;
    };
    struct Table {
        std::unordered_map<std::uint64_t, std::vector<std::shared_ptr<Subscriber>>> by_id;
        std::vector<std::shared_ptr<Subscriber>> masked;
    };
    static std::uint64_t id_key(std::uint32_t id, bool extended) {
        return (static_cast<std::uint64_t>(extended) << 32) | id;
    }
    SubscriptionId add_subscriber(std::shared_ptr<Subscriber> s, bool exact);
    bool wait_for_rx(std::unique_lock<std::mutex>& lock, Duration timeout);
    // Completion-based waiters (recv_or_wait), oldest first, each served once.
    struct RxWaiter {
        std::shared_ptr<Completions> done;
        std::uint64_t token;
        std::size_t max;
    };
    void fail_waiters(std::exception_ptr error);

    std::string channel_;
    std::atomic<BusState> state_{BusState::Active};
    std::atomic<bool> closed_{false};
    std::once_flag close_once_;

    // recv() queue
    std::mutex rx_mutex_;
    std::condition_variable rx_cv_;
    std::deque<Frame> rx_queue_;
    std::vector<Filter> filters_;
    std::atomic<bool> link_lost_{false};
    std::string link_lost_reason_;  // rx_mutex_
    bool recv_used_ = false;        // rx_mutex_: recv()/recv_many()/set_filters() was called
    std::deque<RxWaiter> rx_waiters_;  // rx_mutex_

    // subscribers: copy-on-write table, read under table_mutex_ by dispatch()
    std::mutex table_mutex_;
    std::shared_ptr<const Table> table_ = std::make_shared<Table>();
    std::recursive_mutex dispatch_mutex_;  // held while callbacks run
    std::atomic<std::thread::id> dispatch_thread_{};
    std::atomic<SubscriptionId> next_sub_{1};
    std::atomic<int> subscriber_count_{0};

    // link watchers (watch_link): called without any lock held
    void notify_link_watchers();
    mutable std::mutex watch_mutex_;
    std::vector<std::pair<SubscriptionId, std::shared_ptr<const std::function<void()>>>> watchers_;
    std::atomic<std::uint64_t> link_losses_{0};
    std::string last_link_loss_;  // watch_mutex_

    std::atomic<std::uint64_t> rx_frames_{0}, tx_frames_{0}, rx_dropped_{0}, tx_dropped_{0},
        overruns_{0}, parse_errors_{0}, bus_errors_{0}, ignored_{0}, rx_bits_{0}, tx_bits_{0};
};

}  // namespace motorbus::can

// AsyncReceiver: a stream of a bus's frames for an event loop, without a
// thread per wait and without the bus's receive thread waiting for anyone.
//
//   auto rx = std::make_shared<AsyncReceiver>(bus, filters, 1024);
//   auto frames = rx->take_or_arm(256, done, token);   // frames now, or armed
//   ...when done->fd() is readable: the batch is in done->drain() under token;
//   the loop then calls take_or_arm again, which returns the rest of the burst.
//
// It is a subscription of its own (Bus::subscribe): it takes nothing from the
// bus's recv() queue, and each receiver sees every frame its filters pass.
// The receive thread appends each frame to a bounded queue; when the loop is
// waiting (armed), the first frame is pushed to the Completions at once and
// the following ones queue until the loop comes back for them -- one wake-up
// per burst.  A full queue drops the newest frame and counts it (overflows):
// the receive thread never blocks on a slow loop.  When the bus closes or its
// link is lost for good, the queued frames are still handed out, then
// take_or_arm throws ClosedError / LinkDown (and an armed waiter gets that
// error as its completion).
#pragma once
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/runtime/completions.hpp"

namespace motorbus::can {

struct AsyncReceiverCounters {
    std::uint64_t received = 0;   // frames that passed the filters (queued, delivered or dropped)
    std::uint64_t overflows = 0;  // of those, dropped because the queue was full
    std::uint64_t wakeups = 0;    // completions pushed (one per burst the loop waited for)
};

class AsyncReceiver {
public:
    // `filters`: empty = every frame; a frame passes when one filter matches.
    // `capacity`: frames kept while the loop is busy, >= 1 (InvalidArgument).
    AsyncReceiver(std::shared_ptr<Bus> bus, std::vector<Filter> filters, std::size_t capacity);
    ~AsyncReceiver();  // close()
    AsyncReceiver(const AsyncReceiver&) = delete;
    AsyncReceiver& operator=(const AsyncReceiver&) = delete;

    // Up to `max` queued frames, oldest first; when none, arms the receiver:
    // the next frames are pushed to `done` under `token` as a std::vector<Frame>
    // and an empty vector is returned.  Throws ClosedError / LinkDown once the
    // stream ended and is drained, InvalidArgument for max 0 or no `done`.
    std::vector<Frame> take_or_arm(std::size_t max, std::shared_ptr<Completions> done, std::uint64_t token);
    // Up to `max` queued frames without arming (empty when none); throws like
    // take_or_arm once ended and drained.
    std::vector<Frame> take(std::size_t max);
    // Withdraws the armed waiter (a cancelled await): false if there was none
    // (it already completed, or was never armed).
    bool disarm();
    // Ends the stream: unsubscribes (after which no callback runs), an armed
    // waiter gets ClosedError; queued frames are still handed out.  Idempotent.
    void close();

    bool ended() const;        // closed, or the bus closed / lost its link
    std::size_t queued() const;
    std::size_t capacity() const { return capacity_; }
    AsyncReceiverCounters counters() const;

private:
    struct State;
    std::shared_ptr<Bus> bus_;
    std::size_t capacity_;
    std::shared_ptr<State> state_;  // shared with the bus callbacks, which may outlive a call to close()
    SubscriptionId subscription_ = 0, watcher_ = 0;
    std::once_flag close_once_;
};

}  // namespace motorbus::can

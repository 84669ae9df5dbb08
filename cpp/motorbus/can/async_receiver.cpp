#include "motorbus/can/async_receiver.hpp"

#include <algorithm>
#include <utility>

#include "motorbus/errors.hpp"

namespace motorbus::can {

struct AsyncReceiver::State {
    std::vector<Filter> filters;
    std::size_t capacity = 0;
    mutable std::mutex m;
    std::deque<Frame> queue;
    std::shared_ptr<Completions> done;  // set while armed
    std::uint64_t token = 0;
    std::exception_ptr end;             // why the stream ended (null while it runs)
    AsyncReceiverCounters counters;

    // The bus's receive thread, for each frame.
    void on_frame(const Frame& frame) {
        if (!filters.empty() &&
            std::none_of(filters.begin(), filters.end(), [&](const Filter& f) { return f.matches(frame); }))
            return;
        std::shared_ptr<Completions> wake;
        std::uint64_t tok = 0;
        {
            std::lock_guard lock(m);
            if (end) return;
            ++counters.received;
            if (done) {  // the loop waits: this frame goes now, the rest of the burst queues
                wake.swap(done);
                tok = token;
                ++counters.wakeups;
            } else if (queue.size() >= capacity) {
                ++counters.overflows;  // the newest is dropped: what was queued keeps its order
                return;
            } else {
                queue.push_back(frame);
                return;
            }
        }
        // Outside the lock: a loop without add_reader is woken by a call that takes the GIL.
        wake->push(tok, std::vector<Frame>{frame});
    }

    // Ends the stream once (the first reason wins); an armed waiter gets the error.
    void finish(std::exception_ptr why) {
        std::shared_ptr<Completions> wake;
        std::uint64_t tok = 0;
        {
            std::lock_guard lock(m);
            if (end) return;
            end = why;
            wake.swap(done);
            tok = token;
        }
        if (wake) wake->fail(tok, why);
    }

    std::vector<Frame> take_locked(std::size_t max) {
        const auto n = static_cast<std::ptrdiff_t>(std::min(max, queue.size()));
        std::vector<Frame> out(queue.begin(), queue.begin() + n);
        queue.erase(queue.begin(), queue.begin() + n);
        return out;
    }
};

AsyncReceiver::AsyncReceiver(std::shared_ptr<Bus> bus, std::vector<Filter> filters, std::size_t capacity)
    : bus_(std::move(bus)), capacity_(capacity), state_(std::make_shared<State>()) {
    if (!bus_) throw InvalidArgument("AsyncReceiver: no bus");
    if (capacity_ == 0)
        throw InvalidArgument("bus " + bus_->channel() + " frame stream queue: 0, must be >= 1 frame");
    state_->filters = std::move(filters);
    state_->capacity = capacity_;
    // The callbacks hold the state, not this object: the link watcher may run
    // once more just after unwatch_link() returns.
    auto state = state_;
    Bus* bus_ptr = bus_.get();  // the watcher is called by this bus, so it is alive then
    watcher_ = bus_->watch_link([state, bus_ptr] {
        if (bus_ptr->closed())
            state->finish(std::make_exception_ptr(ClosedError("bus " + bus_ptr->channel() + " is closed")));
        else if (bus_ptr->state() == BusState::BusOff)  // lost for good (a reconnecting link goes on)
            state->finish(std::make_exception_ptr(
                LinkDown("bus " + bus_ptr->channel() + ": link down: " + bus_ptr->link_loss_reason())));
    });
    // One subscription for all filters: a frame two filters match is delivered once.
    const bool exact = state_->filters.size() == 1 && state_->filters[0].match_extended &&
                       state_->filters[0].mask == (state_->filters[0].extended ? kMaxExtendedId : kMaxStandardId);
    subscription_ = exact ? bus_->subscribe(state_->filters[0], [state](const Frame& f) { state->on_frame(f); })
                          : bus_->subscribe(Filter{}, [state](const Frame& f) { state->on_frame(f); });
    // A bus closed before the subscription existed never calls the watcher again.
    if (bus_->closed())
        state_->finish(std::make_exception_ptr(ClosedError("bus " + bus_->channel() + " is closed")));
}

AsyncReceiver::~AsyncReceiver() { close(); }

std::vector<Frame> AsyncReceiver::take_or_arm(std::size_t max, std::shared_ptr<Completions> done,
                                              std::uint64_t token) {
    if (max == 0) throw InvalidArgument("bus " + bus_->channel() + " frame stream: max 0, must be >= 1 frame");
    if (!done) throw InvalidArgument("bus " + bus_->channel() + " frame stream: no completion queue");
    std::lock_guard lock(state_->m);
    if (!state_->queue.empty()) return state_->take_locked(max);
    if (state_->end) std::rethrow_exception(state_->end);
    state_->done = std::move(done);
    state_->token = token;
    return {};
}

std::vector<Frame> AsyncReceiver::take(std::size_t max) {
    std::lock_guard lock(state_->m);
    if (state_->queue.empty() && state_->end) std::rethrow_exception(state_->end);
    return state_->take_locked(max);
}

bool AsyncReceiver::disarm() {
    std::lock_guard lock(state_->m);
    if (!state_->done) return false;
    state_->done.reset();
    return true;
}

void AsyncReceiver::close() {
    std::call_once(close_once_, [&] {
        bus_->unsubscribe(subscription_);
        bus_->unwatch_link(watcher_);
        state_->finish(std::make_exception_ptr(ClosedError("bus " + bus_->channel() + " frame stream is closed")));
    });
}

bool AsyncReceiver::ended() const {
    std::lock_guard lock(state_->m);
    return static_cast<bool>(state_->end);
}

std::size_t AsyncReceiver::queued() const {
    std::lock_guard lock(state_->m);
    return state_->queue.size();
}

AsyncReceiverCounters AsyncReceiver::counters() const {
    std::lock_guard lock(state_->m);
    return state_->counters;
}

}  // namespace motorbus::can

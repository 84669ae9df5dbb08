// A user callback that one thread may replace (or clear) while a service
// thread calls it.  A plain std::function member cannot do that: assigning it
// destroys the callable another thread may be running (a use-after-free, seen
// as an abort under ASan when Python cleared a heartbeat callback while the
// consumer's timer thread called it).  The slot holds the callable behind a
// shared pointer: a call takes a copy of the pointer under a short lock and
// runs outside it, so a replaced callable lives until the calls in progress
// end, and callbacks may set the slot again without deadlocking.
// Used like the std::function it replaces: `slot = f;  slot = nullptr;
// if (slot) slot(args...);`.
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <utility>

namespace motorbus {

template <class Signature>
class CallbackSlot;

template <class... Args>
class CallbackSlot<void(Args...)> {
public:
    using Function = std::function<void(Args...)>;

    CallbackSlot() = default;
    CallbackSlot(const CallbackSlot&) = delete;
    CallbackSlot& operator=(const CallbackSlot&) = delete;

    CallbackSlot& operator=(Function f) {
        auto next = f ? std::make_shared<const Function>(std::move(f)) : nullptr;
        std::lock_guard lock(m_);
        fn_.swap(next);
        return *this;  // the previous callable is released here, after the lock
    }
    CallbackSlot& operator=(std::nullptr_t) { return *this = Function{}; }

    explicit operator bool() const {
        std::lock_guard lock(m_);
        return fn_ != nullptr;
    }

    // Calls the current callable, if any (a no-op once cleared).
    template <class... CallArgs>
    void operator()(CallArgs&&... args) const {
        std::shared_ptr<const Function> f;
        {
            std::lock_guard lock(m_);
            f = fn_;
        }
        if (f) (*f)(std::forward<CallArgs>(args)...);
    }

private:
    mutable std::mutex m_;
    std::shared_ptr<const Function> fn_;
};

}  // namespace motorbus

// Completions: finished operations handed to an event loop without a thread per
// wait and without the finishing thread touching the caller's runtime.
//
//   auto done = std::make_shared<Completions>();
//   loop watches done->fd() for readability (Python: loop.add_reader);
//   any thread: done->push(token, value)  /  done->fail(token, error);
//   the loop thread, when fd() is readable: for (auto& c : done->drain()) ...
//
// Why an eventfd and a queue: a thread that finishes an operation (a bus's
// receive thread completing an SDO transfer, a line's worker reading a reply)
// must not take Python's GIL for each result -- it appends a C++ value to the
// queue and writes the eventfd only when the queue goes from empty to not
// empty, so a burst of 127 completions wakes the loop once and the loop
// converts the whole batch in one go (the way gRPC's asyncio layer drains its
// completion queue).  Values are C++ (std::any): nothing here ever refers to a
// Python object, so a completion may outlive the loop or the interpreter.
#pragma once
#include <any>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <vector>

namespace motorbus {

struct Completion {
    std::uint64_t token = 0;          // the caller's name for the operation
    std::any value;                   // the result (empty for operations that return nothing)
    std::exception_ptr error;         // set when the operation failed
};

class Completions {
public:
    Completions();
    ~Completions();
    Completions(const Completions&) = delete;
    Completions& operator=(const Completions&) = delete;

    // The eventfd a loop watches: readable while completions are queued.
    int fd() const { return fd_; }
    void push(std::uint64_t token, std::any value);
    void fail(std::uint64_t token, std::exception_ptr error);
    // Wakes the loop without a completion (a result delivered another way).
    void notify();
    // Everything queued, oldest first; clears the eventfd.
    std::vector<Completion> drain();
    std::size_t pending() const;
    // Totals since construction: completions queued, and wake-ups written (one per
    // empty -> not-empty transition: the batching the loop sees).
    std::uint64_t pushed() const;
    std::uint64_t wakeups() const;
    // For loops that cannot watch a descriptor: called (on the pushing thread,
    // outside the lock) instead of nothing at each wake-up.  Empty = none.
    void set_wakeup(std::function<void()> wakeup);

private:
    void queue(Completion c);
    void wake();

    int fd_ = -1;
    mutable std::mutex mutex_;
    std::vector<Completion> queue_;
    std::uint64_t pushed_ = 0, wakeups_ = 0;
    std::function<void()> wakeup_;
};

}  // namespace motorbus

#include "motorbus/runtime/completions.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>
#include <utility>

namespace motorbus {

Completions::Completions() {
    fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "eventfd");
}

Completions::~Completions() {
    if (fd_ >= 0) ::close(fd_);
}

void Completions::push(std::uint64_t token, std::any value) {
    queue(Completion{token, std::move(value), nullptr});
}

void Completions::fail(std::uint64_t token, std::exception_ptr error) {
    queue(Completion{token, {}, std::move(error)});
}

void Completions::queue(Completion c) {
    bool first;
    {
        std::lock_guard lock(mutex_);
        first = queue_.empty();
        queue_.push_back(std::move(c));
        ++pushed_;
        if (first) ++wakeups_;
    }
    // Only the first of a burst wakes the loop: the drain takes the rest with it.
    if (first) wake();
}

void Completions::notify() { wake(); }

void Completions::wake() {
    std::uint64_t one = 1;
    // A full counter (2^64 - 2 unread wake-ups) cannot happen while a loop drains;
    // EAGAIN then still leaves the descriptor readable, which is all a wake-up means.
    [[maybe_unused]] auto n = ::write(fd_, &one, sizeof one);
    std::function<void()> wakeup;
    {
        std::lock_guard lock(mutex_);
        wakeup = wakeup_;
    }
    if (wakeup) wakeup();
}

std::vector<Completion> Completions::drain() {
    // Clear the eventfd before taking the queue: a push after the swap writes it
    // again, so no completion is ever left queued behind a cleared descriptor.
    std::uint64_t count;
    [[maybe_unused]] auto n = ::read(fd_, &count, sizeof count);
    std::vector<Completion> out;
    std::lock_guard lock(mutex_);
    out.swap(queue_);
    return out;
}

std::size_t Completions::pending() const {
    std::lock_guard lock(mutex_);
    return queue_.size();
}

std::uint64_t Completions::pushed() const {
    std::lock_guard lock(mutex_);
    return pushed_;
}

std::uint64_t Completions::wakeups() const {
    std::lock_guard lock(mutex_);
    return wakeups_;
}

void Completions::set_wakeup(std::function<void()> wakeup) {
    std::lock_guard lock(mutex_);
    wakeup_ = std::move(wakeup);
}

}  // namespace motorbus

// Completions: the queue + eventfd an event loop drains.
#include <gtest/gtest.h>
#include <poll.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include "motorbus/runtime/completions.hpp"

using motorbus::Completions;

namespace {
bool readable(int fd, int timeout_ms = 0) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) == 1 && (p.revents & POLLIN);
}
}  // namespace

TEST(Completions, ABurstWakesTheLoopOnceAndDrainsInOrder) {
    Completions c;
    EXPECT_FALSE(readable(c.fd()));
    for (int i = 0; i < 127; ++i) c.push(static_cast<std::uint64_t>(i), i * 10);
    EXPECT_TRUE(readable(c.fd()));
    EXPECT_EQ(c.wakeups(), 1u);        // one wake-up for the whole burst
    auto batch = c.drain();
    ASSERT_EQ(batch.size(), 127u);
    for (int i = 0; i < 127; ++i) {
        EXPECT_EQ(batch[i].token, static_cast<std::uint64_t>(i));
        EXPECT_EQ(std::any_cast<int>(batch[i].value), i * 10);
    }
    EXPECT_FALSE(readable(c.fd()));    // drained: the descriptor is clear again
    c.push(500, std::string("next"));
    EXPECT_TRUE(readable(c.fd()));
    EXPECT_EQ(c.wakeups(), 2u);
}

TEST(Completions, AFailureCarriesItsException) {
    Completions c;
    c.fail(7, std::make_exception_ptr(std::runtime_error("no answer")));
    auto batch = c.drain();
    ASSERT_EQ(batch.size(), 1u);
    EXPECT_EQ(batch[0].token, 7u);
    EXPECT_FALSE(batch[0].value.has_value());
    EXPECT_THROW(std::rethrow_exception(batch[0].error), std::runtime_error);
}

TEST(Completions, NoCompletionIsLeftBehindAClearedDescriptor) {
    // Four threads push while the reader drains whenever the fd is readable: every
    // token arrives exactly once, and the reader never blocks on a queue it missed.
    Completions c;
    constexpr int kThreads = 4, kEach = 20000;
    std::vector<std::thread> pushers;
    for (int t = 0; t < kThreads; ++t)
        pushers.emplace_back([&, t] {
            for (int i = 0; i < kEach; ++i) c.push(static_cast<std::uint64_t>(t * kEach + i), {});
        });
    std::vector<int> seen(kThreads * kEach, 0);
    std::size_t got = 0;
    while (got < seen.size()) {
        ASSERT_TRUE(readable(c.fd(), 5000)) << "queued completions behind a cleared eventfd";
        for (auto& x : c.drain()) {
            ++seen[x.token];
            ++got;
        }
    }
    for (auto& p : pushers) p.join();
    for (int n : seen) EXPECT_EQ(n, 1);
    EXPECT_EQ(c.pushed(), seen.size());
    EXPECT_LT(c.wakeups(), c.pushed());  // batched
}

TEST(Completions, AWakeupFunctionServesLoopsWithoutDescriptors) {
    Completions c;
    std::atomic<int> calls{0};
    c.set_wakeup([&] { ++calls; });
    c.push(1, {});
    c.push(2, {});
    EXPECT_EQ(calls.load(), 1);
    c.drain();
    c.notify();
    EXPECT_EQ(calls.load(), 2);
    c.set_wakeup({});
    c.push(3, {});
    EXPECT_EQ(calls.load(), 2);
}

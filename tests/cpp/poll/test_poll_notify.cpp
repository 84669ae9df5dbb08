// PollGroup::notify_when: the poll thread tells an event loop (through a
// Completions) that N rows are ready, once per request, and that it ended.
#include <gtest/gtest.h>
#include <poll.h>

#include <any>
#include <atomic>
#include <memory>
#include <stdexcept>
#include <vector>

#include "motorbus/errors.hpp"
#include "motorbus/poll/poll_group.hpp"
#include "motorbus/runtime/completions.hpp"

using namespace motorbus;
using namespace motorbus::poll;

namespace {

class Counter final : public Source {
public:
    std::size_t columns() const override { return 1; }
    void read(double* out) override {
        const int n = ++reads;
        if (fail_after > 0 && n > fail_after) throw LinkDown("gone");
        out[0] = n;
    }
    std::string describe() const override { return "counter"; }
    std::atomic<int> reads{0};
    int fail_after = 0;
};

bool readable(int fd, int timeout_ms) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) == 1 && (p.revents & POLLIN);
}

}  // namespace

TEST(PollGroupNotify, OneCompletionWhenTheRowsAreThere) {
    auto src = std::make_shared<Counter>();
    PollGroup g({src}, {.period_ns = 1'000'000, .capacity = 256});
    auto done = std::make_shared<Completions>();
    g.start();
    EXPECT_FALSE(g.notify_when(20, done, 42));       // not yet: armed
    ASSERT_TRUE(readable(done->fd(), 5000));
    auto c = done->drain();
    ASSERT_EQ(c.size(), 1u);                         // one completion for 20 rows, not one per sample
    EXPECT_EQ(c[0].token, 42u);
    EXPECT_GE(std::any_cast<std::int64_t>(c[0].value), 20);
    EXPECT_EQ(done->wakeups(), 1u);
    EXPECT_GE(g.ring().available(), 20u);
    EXPECT_TRUE(g.notify_when(5, done, 43));         // already there: nothing armed
    EXPECT_FALSE(g.cancel_notify());
    // A withdrawn request never fires.
    EXPECT_FALSE(g.notify_when(200, done, 44));
    EXPECT_TRUE(g.cancel_notify());
    g.stop();
    EXPECT_EQ(done->pending(), 0u);
    EXPECT_TRUE(g.notify_when(200, done, 45));       // stopped: nothing to wait for
    EXPECT_THROW(g.notify_when(0, done, 46), InvalidArgument);
    EXPECT_THROW(g.notify_when(257, done, 47), InvalidArgument);  // more than the ring holds
}

TEST(PollGroupNotify, AGroupThatEndsCompletesTheWaiter) {
    auto src = std::make_shared<Counter>();
    src->fail_after = 5;
    PollGroup g({src}, {.period_ns = 1'000'000, .capacity = 256});
    auto done = std::make_shared<Completions>();
    g.start();
    // Either armed before the failure (the thread's end fires it) or already ended (true).
    if (!g.notify_when(100, done, 7)) {
        ASSERT_TRUE(readable(done->fd(), 5000));
        auto c = done->drain();
        ASSERT_EQ(c.size(), 1u);
        EXPECT_EQ(c[0].token, 7u);
        EXPECT_LT(std::any_cast<std::int64_t>(c[0].value), 100);  // fewer rows: it ended
    }
    g.stop();
    EXPECT_EQ(g.stats().error_type, "LinkDown");
}

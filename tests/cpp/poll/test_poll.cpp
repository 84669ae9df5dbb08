// The generic poller: schedule bookkeeping, the ring (order, wrap, overflow),
// the histogram's quantiles, and a PollGroup thread over fake sources (values,
// timestamps, late/missed counting, a failing source ending the group).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "motorbus/errors.hpp"
#include "motorbus/poll/capture.hpp"
#include "motorbus/poll/poll_group.hpp"

using namespace motorbus;
using namespace motorbus::poll;

TEST(Schedule, OnTimeSampleGoesToTheNextDeadline) {
    Schedule s(1'000, 100);
    EXPECT_EQ(s.deadline(0), 1'000);
    EXPECT_EQ(s.deadline(3), 1'300);
    auto n = s.after(0, 1'050);
    EXPECT_EQ(n.index, 1u);
    EXPECT_EQ(n.skipped, 0u);
    EXPECT_FALSE(n.late);
}

TEST(Schedule, OverrunIsLateAndSkipsWholePeriods) {
    Schedule s(0, 100);
    auto n = s.after(0, 100);  // finished exactly at the next deadline: late, nothing skipped
    EXPECT_TRUE(n.late);
    EXPECT_EQ(n.index, 1u);
    EXPECT_EQ(n.skipped, 0u);
    n = s.after(2, 560);  // deadlines 300, 400, 500 passed: 500 is sampled now, 300 and 400 are missed
    EXPECT_TRUE(n.late);
    EXPECT_EQ(n.index, 5u);
    EXPECT_EQ(n.skipped, 2u);
}

TEST(Schedule, RefusesANonPositivePeriod) { EXPECT_THROW(Schedule(0, 0), InvalidArgument); }

TEST(SampleRing, TakesRowsInOrderAcrossTheWrap) {
    SampleRing r(4, 2);
    std::vector<std::int64_t> k(4), t(4);
    std::vector<double> v(8);
    for (int i = 0; i < 3; ++i) {
        const double row[2] = {double(i), double(-i)};
        r.push(i, 100 + i, row);
    }
    ASSERT_EQ(r.take(k.data(), t.data(), v.data(), 4), 3u);
    for (int i = 3; i < 7; ++i) {  // wraps: slots 3, 0, 1, 2
        const double row[2] = {double(i), double(-i)};
        r.push(i, 100 + i, row);
    }
    ASSERT_EQ(r.available(), 4u);
    ASSERT_EQ(r.take(k.data(), t.data(), v.data(), 4), 4u);
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(k[i], 3 + i);
        EXPECT_EQ(t[i], 103 + i);
        EXPECT_EQ(v[2 * i], 3 + i);
        EXPECT_EQ(v[2 * i + 1], -(3 + i));
    }
    EXPECT_EQ(r.overflowed(), 0u);
    EXPECT_EQ(r.written(), 7u);
}

TEST(SampleRing, CountsRowsOverwrittenBeforeTheyWereRead) {
    SampleRing r(3, 1);
    for (int i = 0; i < 5; ++i) {
        const double x = i;
        r.push(i, 100 + i, &x);
    }
    EXPECT_EQ(r.overflowed(), 2u);
    std::vector<std::int64_t> k(3), t(3);
    std::vector<double> v(3);
    ASSERT_EQ(r.take(k.data(), t.data(), v.data(), 3), 3u);
    EXPECT_EQ(k[0], 2);
    EXPECT_EQ(t[0], 102);  // the two oldest rows are gone, the rest are intact
    EXPECT_EQ(v[2], 4.0);
    EXPECT_THROW(SampleRing(0, 1), InvalidArgument);
}

TEST(Histogram, QuantilesFromMicrosecondBins) {
    Histogram h;
    for (int i = 1; i <= 100; ++i) h.add(i * 1'000 - 500);  // 0.5 µs .. 99.5 µs
    EXPECT_EQ(h.count(), 100u);
    EXPECT_EQ(h.quantile(0.5), 50'000);
    EXPECT_EQ(h.quantile(0.99), 99'000);
    EXPECT_EQ(h.max(), 99'500);
    EXPECT_EQ(h.quantile(1.0), 99'500);  // never above the exact maximum
    Histogram empty;
    EXPECT_EQ(empty.quantile(0.99), 0);
}

namespace {

// Counts its reads; sleeps `delay` per read; throws LinkDown at read `fail_at`.
class FakeSource : public Source {
public:
    FakeSource(std::size_t columns, std::chrono::microseconds delay = {}, int fail_at = -1)
        : columns_(columns), delay_(delay), fail_at_(fail_at) {}
    std::size_t columns() const override { return columns_; }
    void read(double* out) override {
        const int n = reads_++;
        if (n == fail_at_) throw LinkDown("fake link gone");
        if (delay_.count()) std::this_thread::sleep_for(delay_);
        for (std::size_t c = 0; c < columns_; ++c) out[c] = n * 10.0 + static_cast<double>(c);
    }
    std::string describe() const override { return "fake"; }
    std::atomic<int> reads_{0};

private:
    std::size_t columns_;
    std::chrono::microseconds delay_;
    int fail_at_;
};

struct Taken {
    std::vector<std::int64_t> k, t;
    std::vector<double> v;
};

Taken take_all(PollGroup& g) {
    Taken out;
    const std::size_t n = g.ring().available();
    out.k.resize(n);
    out.t.resize(n);
    out.v.resize(n * g.columns());
    out.t.resize(g.ring().take(out.k.data(), out.t.data(), out.v.data(), n));
    out.k.resize(out.t.size());
    return out;
}

}  // namespace

TEST(PollGroup, WritesEverySourceColumnsWithIncreasingTimestamps) {
    auto a = std::make_shared<FakeSource>(2), b = std::make_shared<FakeSource>(1);
    PollOptions o;
    o.period_ns = 2'000'000;
    PollGroup g({a, b}, o);
    EXPECT_EQ(g.columns(), 3u);
    g.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    g.stop();
    const auto got = take_all(g);
    const auto st = g.stats();
    ASSERT_GE(got.t.size(), 20u);
    EXPECT_EQ(st.samples + st.missed, got.t.size());
    for (std::size_t i = 0; i < got.t.size(); ++i) {
        if (i) {
            EXPECT_GT(got.t[i], got.t[i - 1]);
            EXPECT_EQ(got.k[i], got.k[i - 1] + 1);  // one row per deadline, sampled or missed
        }
        if (std::isnan(got.v[3 * i])) continue;  // a missed deadline on a loaded machine
        EXPECT_EQ(got.v[3 * i + 1] - got.v[3 * i], 1.0);  // source a: its two columns of one read
        EXPECT_EQ(std::fmod(got.v[3 * i + 2], 10.0), 0.0);  // source b: its one column
    }
    // Absolute schedule: the mean interval is the period.
    const double mean = double(got.t.back() - got.t.front()) / double(got.t.size() - 1);
    EXPECT_NEAR(mean, 2'000'000, 200'000);
    EXPECT_FALSE(st.running);
    EXPECT_EQ(st.error, "");
}

TEST(PollGroup, ASlowSourceIsCountedLateAndMissedWithNaNRows) {
    // 2.5 ms reads at a 1 ms period: every sample is late and at least one
    // deadline passes entirely during each.
    auto slow = std::make_shared<FakeSource>(1, std::chrono::microseconds(2'500));
    PollOptions o;
    o.period_ns = 1'000'000;
    PollGroup g({slow}, o);
    g.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(60));
    g.stop();
    const auto st = g.stats();
    const auto got = take_all(g);
    EXPECT_GE(st.late, 5u);
    EXPECT_GE(st.missed, st.late);
    std::size_t nan_rows = 0;
    for (double x : got.v) nan_rows += std::isnan(x) ? 1 : 0;
    EXPECT_EQ(nan_rows, st.missed);
    EXPECT_EQ(got.t.size(), st.samples + st.missed);
}

TEST(PollGroup, AFailingSourceEndsTheGroupWithItsError) {
    auto bad = std::make_shared<FakeSource>(1, std::chrono::microseconds(0), 5);
    PollOptions o;
    o.period_ns = 1'000'000;
    PollGroup g({bad}, o);
    g.start();
    for (int i = 0; i < 500 && g.running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    EXPECT_FALSE(g.running());
    const auto st = g.stats();
    EXPECT_EQ(st.error_type, "LinkDown");
    EXPECT_EQ(st.error, "fake link gone");
    EXPECT_EQ(st.samples, 5u);
    g.stop();  // after the thread ended on its own: returns at once
}

TEST(PollGroup, StopEndsALongSleepPromptly) {
    auto a = std::make_shared<FakeSource>(1);
    PollOptions o;
    o.period_ns = 10'000'000'000;  // 10 s
    PollGroup g({a}, o);
    g.start();
    const auto t0 = std::chrono::steady_clock::now();
    g.stop();
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
    EXPECT_EQ(a->reads_.load(), 0);
}

TEST(PollGroup, RefusesBadOptions) {
    auto a = std::make_shared<FakeSource>(1);
    PollOptions o;
    o.spin_ns = 2 * o.period_ns;
    EXPECT_THROW(PollGroup({a}, o), InvalidArgument);
    EXPECT_THROW(PollGroup({}, PollOptions{}), InvalidArgument);
    PollGroup g({a}, PollOptions{});
    g.start();
    EXPECT_THROW(g.start(), InvalidArgument);
}

TEST(Schedule, IndexAtIsTheLatestDeadlinePassed) {
    Schedule s(1'000, 100);
    EXPECT_EQ(s.index_at(500), 0u);
    EXPECT_EQ(s.index_at(1'000), 0u);
    EXPECT_EQ(s.index_at(1'099), 0u);
    EXPECT_EQ(s.index_at(1'250), 2u);
}

// ---- capture sources' shared part --------------------------------------------------

TEST(CaptureSlots, NothingArrivedIsNanAndStale) {
    CaptureSlots slots(2, 3'000'000);
    double row[3];
    slots.read(row, 10'000'000);
    EXPECT_TRUE(std::isnan(row[0]) && std::isnan(row[1]) && std::isnan(row[2]));
    EXPECT_EQ(slots.stale(), 1u);
}

TEST(CaptureSlots, RowIsOldestArrivalThenValuesAndAgeCountsStale) {
    CaptureSlots slots(3, 3'000'000);
    const double a[2] = {1.5, -2.0};
    const double b = 7.0;
    slots.set(0, a, 2, 10'000'000);
    double row[4];
    slots.read(row, 11'000'000);  // the third value never came
    EXPECT_TRUE(std::isnan(row[0]));
    EXPECT_EQ(row[1], 1.5);
    EXPECT_EQ(row[2], -2.0);
    EXPECT_TRUE(std::isnan(row[3]));
    EXPECT_EQ(slots.stale(), 1u);
    slots.set(2, &b, 1, 12'000'000);
    slots.read(row, 12'500'000);  // fresh: the oldest (10 ms) is 2.5 ms old <= 3 ms
    EXPECT_EQ(row[0], 10'000'000.0);
    EXPECT_EQ(row[3], 7.0);
    EXPECT_EQ(slots.stale(), 1u);
    slots.read(row, 13'000'001);  // the push of values 0-1 stopped: 3 ms + 1 ns old
    EXPECT_EQ(row[0], 10'000'000.0);
    EXPECT_EQ(row[1], 1.5);       // the last word is still given, its age shows in row[0]
    EXPECT_EQ(slots.stale(), 2u);
}

TEST(CaptureSlots, RefusesNoValuesOrNoAge) {
    EXPECT_THROW(CaptureSlots(0, 1), InvalidArgument);
    EXPECT_THROW(CaptureSlots(1, 0), InvalidArgument);
}

namespace {
// A capture-like source: reports stale reads, which the group sums into its stats.
class StaleSource final : public Source {
public:
    std::size_t columns() const override { return 1; }
    void read(double* out) override {
        out[0] = 1.0;
        stale_.fetch_add(1);
    }
    std::string describe() const override { return "stale"; }
    std::uint64_t stale() const override { return stale_.load(); }

private:
    std::atomic<std::uint64_t> stale_{0};
};
}  // namespace

TEST(PollGroup, StatsSumTheSourcesStaleReads) {
    auto a = std::make_shared<StaleSource>();
    auto b = std::make_shared<StaleSource>();
    PollGroup g({a, b}, {.period_ns = 2'000'000, .capacity = 64});
    g.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    g.stop();
    const auto s = g.stats();
    EXPECT_GT(s.samples, 3u);
    EXPECT_EQ(s.stale, a->stale() + b->stale());
    EXPECT_EQ(s.stale, 2 * s.samples);
}

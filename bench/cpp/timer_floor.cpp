// The machine's own floor for a periodic thread: a 1 kHz loop sleeping to
// absolute deadlines on CLOCK_MONOTONIC (clock_nanosleep, TIMER_ABSTIME) and
// doing nothing else, at normal priority.  How late it wakes is the least
// period error any poller can have on this machine and load: bench/poller.py
// prints it beside the Poller's figures so the two can be told apart.
//
//   build/dev/bench_timer_floor [seconds=10] [rate_hz=1000]
#include <time.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {
std::int64_t now_ns() {
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
}  // namespace

int main(int argc, char** argv) {
    const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
    const double rate = argc > 2 ? std::atof(argv[2]) : 1000.0;
    if (!(seconds > 0) || !(rate > 0)) {
        std::fprintf(stderr, "usage: bench_timer_floor [seconds > 0] [rate_hz > 0]\n");
        return 2;
    }
    const std::int64_t period = static_cast<std::int64_t>(1e9 / rate);
    const std::uint64_t n = static_cast<std::uint64_t>(seconds * rate);
    std::vector<std::int64_t> late, period_error;
    late.reserve(n);
    period_error.reserve(n);
    std::int64_t previous = -1;  // the last wake-up's lateness, when the one before k was not missed
    std::uint64_t missed = 0;
    const std::int64_t t0 = now_ns() + 10'000'000;
    for (std::uint64_t k = 0; k < n; ++k) {
        const std::int64_t deadline = t0 + static_cast<std::int64_t>(k) * period;
        timespec ts{static_cast<time_t>(deadline / 1'000'000'000), static_cast<long>(deadline % 1'000'000'000)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
        }
        const std::int64_t l = now_ns() - deadline;
        late.push_back(l);
        // As the Poller counts it: |interval between consecutive wake-ups - period|.
        if (previous >= 0) period_error.push_back(std::llabs(l - previous));
        previous = l;
        if (l >= period) {  // woke past the next deadline: a poller would have missed one
            const std::uint64_t skip = static_cast<std::uint64_t>(l / period);
            missed += skip;
            k += skip;
            previous = -1;
        }
    }
    auto q = [](std::vector<std::int64_t>& v, double p) {
        std::sort(v.begin(), v.end());
        return v.empty() ? 0.0 : v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))] / 1e3;
    };
    std::printf("timer floor: %zu wake-ups at %.0f Hz, missed %llu; wake-up late p50 %.1f p99 %.1f max %.1f us; "
                "period error p50 %.1f p99 %.1f max %.1f us\n",
                late.size(), rate, static_cast<unsigned long long>(missed), q(late, 0.5), q(late, 0.99), q(late, 1.0),
                q(period_error, 0.5), q(period_error, 0.99), q(period_error, 1.0));
    return 0;
}

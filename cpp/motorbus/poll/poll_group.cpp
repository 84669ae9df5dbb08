#include "motorbus/poll/poll_group.hpp"

#include <sys/prctl.h>

#include <cmath>
#include <cstdlib>
#include <limits>

#include "motorbus/errors.hpp"

namespace motorbus::poll {
namespace {

std::size_t total_columns(const std::vector<std::shared_ptr<Source>>& sources) {
    if (sources.empty()) throw InvalidArgument("PollGroup: at least one source");
    std::size_t n = 0;
    for (const auto& s : sources) {
        if (!s) throw InvalidArgument("PollGroup: a source is None");
        n += s->columns();
    }
    return n;
}

}  // namespace

PollGroup::PollGroup(std::vector<std::shared_ptr<Source>> sources, PollOptions options)
    : sources_(std::move(sources)), options_(options), ring_(options.capacity, total_columns(sources_)) {
    if (options_.period_ns <= 0) throw InvalidArgument("PollGroup period: must be > 0");
    if (options_.spin_ns < 0 || options_.spin_ns > options_.period_ns)
        throw InvalidArgument("PollGroup spin: between 0 and the period");
}

PollGroup::~PollGroup() { stop(); }

void PollGroup::start() {
    if (started_) throw InvalidArgument("PollGroup: already started (make a new one to poll again)");
    started_ = true;
    running_ = true;
    thread_ = std::thread([this] { run(); });
}

void PollGroup::stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    running_ = false;
    check_notify();  // a group stopped before its thread started: a waiter still learns it
}

bool PollGroup::notify_when(std::size_t rows, std::shared_ptr<Completions> done, std::uint64_t token) {
    if (!done) throw InvalidArgument("PollGroup notify_when: no completion queue");
    if (rows == 0 || rows > ring_.capacity())
        throw InvalidArgument("PollGroup notify_when: rows " + std::to_string(rows) + ", must be 1.." +
                              std::to_string(ring_.capacity()) + " (the ring's capacity)");
    std::lock_guard lock(notify_mutex_);
    // running_ is cleared before the thread's last check_notify(), which takes this lock:
    // a request made after it sees running_ false here, one made before is fired by it.
    if (!running_.load() || ring_.available() >= rows) {
        notify_done_.reset();
        notify_armed_ = false;
        return true;
    }
    notify_done_ = std::move(done);
    notify_token_ = token;
    notify_rows_ = rows;
    notify_armed_ = true;
    return false;
}

bool PollGroup::cancel_notify() {
    std::lock_guard lock(notify_mutex_);
    const bool armed = static_cast<bool>(notify_done_);
    notify_done_.reset();
    notify_armed_ = false;
    return armed;
}

void PollGroup::check_notify() {
    std::shared_ptr<Completions> done;
    std::uint64_t token = 0;
    std::size_t available = 0;
    {
        std::lock_guard lock(notify_mutex_);
        if (!notify_done_) return;
        available = ring_.available();
        if (running_.load() && available < notify_rows_) return;
        done.swap(notify_done_);
        token = notify_token_;
        notify_armed_ = false;
    }
    done->push(token, static_cast<std::int64_t>(available));
}

void PollGroup::fail(const char* type, const std::string& what) {
    std::lock_guard lock(stats_mutex_);
    error_type_ = type;
    error_ = what;
}

void PollGroup::run() {
    // A normal thread's timed sleeps may end up to 50 µs late (the kernel's default
    // timer slack, to batch wake-ups); a poller wants its deadline.
    prctl(PR_SET_TIMERSLACK, 1000UL, 0UL, 0UL, 0UL);
    if (options_.realtime) {
        const bool rt = try_realtime(options_.priority);
        std::lock_guard lock(stats_mutex_);
        realtime_ = rt;
    }
    std::vector<double> row(ring_.columns());
    std::vector<double> nan_row(ring_.columns(), std::numeric_limits<double>::quiet_NaN());
    // Deadline 0 at start_ns (groups of one Poller share it, so their rows of one
    // index are one instant), or one period from now.
    const Schedule schedule(options_.start_ns > 0 ? options_.start_ns : monotonic_ns() + options_.period_ns,
                            options_.period_ns);
    std::uint64_t k = 0;
    Nanos previous_start = -1;
    std::uint64_t previous_index = 0;
    try {
        while (sleep_until(schedule.deadline(k), options_.spin_ns, stop_)) {
            const Nanos start = monotonic_ns();
            // Woken after a later deadline (preempted): the ones in between are missed.
            if (const auto woke = schedule.index_at(start); woke > k) {
                for (std::uint64_t j = k; j < woke; ++j)
                    ring_.push(static_cast<std::int64_t>(j), schedule.deadline(j), nan_row.data());
                {
                    std::lock_guard lock(stats_mutex_);
                    missed_ += woke - k;
                }
                k = woke;
            }
            double* out = row.data();
            for (auto& s : sources_) {
                s->read(out);
                out += s->columns();
            }
            const Nanos end = monotonic_ns();
            ring_.push(static_cast<std::int64_t>(k), start, row.data());
            const auto next = schedule.after(k, end);
            for (std::uint64_t j = k + 1; j < next.index; ++j) ring_.push(static_cast<std::int64_t>(j), schedule.deadline(j), nan_row.data());
            {
                std::lock_guard lock(stats_mutex_);
                ++samples_;
                wake_latency_.add(start - schedule.deadline(k));
                read_time_.add(end - start);
                if (previous_start >= 0 && previous_index + 1 == k)
                    period_error_.add(std::llabs((start - previous_start) - options_.period_ns));
                late_ += next.late ? 1 : 0;
                missed_ += next.skipped;
            }
            previous_start = start;
            previous_index = k;
            k = next.index;
            if (notify_armed_.load(std::memory_order_relaxed)) check_notify();
        }
    } catch (const LinkDown& e) {
        fail("LinkDown", e.what());
    } catch (const ClosedError& e) {
        fail("ClosedError", e.what());
    } catch (const TimeoutError& e) {
        fail("TimeoutError", e.what());
    } catch (const ProtocolError& e) {
        fail("ProtocolError", e.what());
    } catch (const Error& e) {
        fail("MotorbusError", e.what());
    } catch (const std::exception& e) {
        fail("Error", e.what());
    }
    running_ = false;
    check_notify();  // the loop waiting for rows learns the group ended
}

PollStats PollGroup::stats() const {
    PollStats s;
    s.overflowed = ring_.overflowed();
    s.period_ns = options_.period_ns;
    s.running = running_.load();
    for (const auto& src : sources_) s.stale += src->stale();
    std::lock_guard lock(stats_mutex_);
    s.samples = samples_;
    s.missed = missed_;
    s.late = late_;
    s.period_error_p50 = period_error_.quantile(0.5);
    s.period_error_p99 = period_error_.quantile(0.99);
    s.period_error_max = period_error_.max();
    s.wake_latency_p50 = wake_latency_.quantile(0.5);
    s.wake_latency_p99 = wake_latency_.quantile(0.99);
    s.wake_latency_max = wake_latency_.max();
    s.read_time_p50 = read_time_.quantile(0.5);
    s.read_time_p99 = read_time_.quantile(0.99);
    s.read_time_max = read_time_.max();
    s.realtime = realtime_;
    s.error = error_;
    s.error_type = error_type_;
    return s;
}

}  // namespace motorbus::poll

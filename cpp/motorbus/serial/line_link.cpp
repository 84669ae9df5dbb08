// LineLink: request/reply framing over a Port (see port.hpp for the contract).
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include "motorbus/runtime/callback_slot.hpp"
#include "motorbus/runtime/fifo_mutex.hpp"
#include "motorbus/runtime/interrupt.hpp"
#include "motorbus/serial/line_framer.hpp"
#include "motorbus/serial/port.hpp"

namespace motorbus::serial {

namespace {
using Clock = std::chrono::steady_clock;

// A printable rendering of a request for error messages (hostile bytes stay escaped).
std::string printable(std::string_view s) {
    std::string out;
    for (unsigned char c : s.substr(0, 40)) {
        if (c >= 0x20 && c < 0x7f) {
            out.push_back(static_cast<char>(c));
        } else {
            static const char* hex = "0123456789abcdef";
            out += "\\x";
            out.push_back(hex[c >> 4]);
            out.push_back(hex[c & 15]);
        }
    }
    if (s.size() > 40) out += "...";
    return out;
}

std::vector<std::uint8_t> to_vec(const std::string& s) { return {s.begin(), s.end()}; }

constexpr std::size_t kFlushCap = 1 << 16;  // a device streaming forever cannot stall a request
}  // namespace

struct LineLink::Impl {
    std::shared_ptr<Port> port;
    LineOptions options;
    LineFramer framer;
    FifoMutex mutex;  // one transaction at a time, in the order they were asked for
    std::mutex worker_mutex;  // transact_async's worker: made once (never waits on a transaction)
    std::vector<std::uint8_t> pending;  // read but not yet framed
    std::string echo;                   // bytes we expect back from an echoing adapter
    std::size_t echo_pos = 0;
    CallbackSlot<void(char, const std::string&)> trace;  // set_trace (may change while in use)

    struct {
        std::atomic<std::uint64_t> bytes_in{0}, bytes_out{0}, requests{0}, replies{0}, timeouts{0},
            stale_bytes{0}, overlong_lines{0}, echo_bytes{0}, echo_mismatches{0};
    } c;

    Impl(std::shared_ptr<Port> p, LineOptions o)
        : port(std::move(p)), options(std::move(o)), framer(options.reply_terminators, options.max_line) {
        if (!port) throw InvalidArgument("LineLink: port is null");
        if (options.request_terminator.size() > LineFramer::kMaxTerminator)
            throw InvalidArgument("request_terminator: longer than 8 bytes");
        if (options.turnaround.count() < 0) throw InvalidArgument("turnaround: must be >= 0");
    }

    void flush_stale() {
        std::size_t stale = pending.size() + framer.partial_bytes();
        pending.clear();
        framer.reset();
        std::uint8_t buf[512];
        std::size_t drained = 0;
        while (drained < kFlushCap) {
            std::size_t n = port->read(buf, Duration::zero());
            if (n == 0) break;
            drained += n;
        }
        c.bytes_in += drained;
        stale += drained;
        c.stale_bytes += stale;
        echo.clear();
        echo_pos = 0;
    }

    void write_line(std::string_view request) {
        std::string out;
        out.reserve(request.size() + options.request_terminator.size());
        out.append(request);
        out.append(options.request_terminator);
        if (options.echo_suppression) {
            echo = out;
            echo_pos = 0;
        }
        port->write({reinterpret_cast<const std::uint8_t*>(out.data()), out.size()});
        c.bytes_out += out.size();
        ++c.requests;
        trace('>', std::string(request));
    }

    // Newly read bytes go through echo suppression, then into `pending`.
    void accept(const std::uint8_t* data, std::size_t n) {
        std::size_t i = 0;
        while (i < n && echo_pos < echo.size()) {
            if (data[i] == static_cast<std::uint8_t>(echo[echo_pos])) {
                ++echo_pos;
                ++i;
                continue;
            }
            // Not our echo after all (adapter does not echo, or it was mangled):
            // what looked like echo is reply data and must not be lost.
            ++c.echo_mismatches;
            pending.insert(pending.end(), echo.begin(), echo.begin() + static_cast<std::ptrdiff_t>(echo_pos));
            echo.clear();
            echo_pos = 0;
            break;
        }
        if (!echo.empty() && echo_pos == echo.size()) {
            c.echo_bytes += echo.size();
            echo.clear();
            echo_pos = 0;
        }
        pending.insert(pending.end(), data + i, data + n);
    }

    // Frames the next line, reading until `deadline`.  nullopt on timeout.
    std::optional<FramedLine> next_line(Clock::time_point deadline, bool forever) {
        std::uint8_t buf[512];
        for (;;) {
            if (!pending.empty()) {
                std::size_t used = 0;
                auto line = framer.push(pending, used);
                pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(used));
                if (line) return line;
            }
            Duration wait = Duration(-1);
            if (!forever) {
                auto now = Clock::now();
                wait = now >= deadline ? Duration::zero() : std::chrono::duration_cast<Duration>(deadline - now);
            }
            if (interruptible() && (wait.count() < 0 || wait > kInterruptSlice)) wait = kInterruptSlice;
            std::size_t n = port->read(buf, wait);
            if (n == 0) {
                if (!forever && Clock::now() >= deadline) return std::nullopt;
                interruption_point();
                continue;
            }
            c.bytes_in += n;
            accept(buf, n);
        }
    }

    std::string finish(const FramedLine& line) {
        if (line.kind == FramedLine::Kind::Overlong) {
            ++c.overlong_lines;
            throw ReplyTooLong("ReplyTooLong: reply of " + std::to_string(line.length) + " bytes exceeds max_line " +
                                   std::to_string(options.max_line),
                               to_vec(line.text));
        }
        ++c.replies;
        trace('<', line.text);
        return line.text;
    }
};

LineLink::LineLink(std::shared_ptr<Port> port, LineOptions options)
    : impl_(std::make_unique<Impl>(std::move(port), std::move(options))) {}

// transact_async's thread: one per link, so a loop awaiting a hundred transactions
// costs one thread, not a hundred; the FifoMutex keeps them in order with the
// blocking callers' transactions.
struct LineLink::Worker {
    struct Job {
        std::string request;
        std::optional<Duration> timeout;
        std::shared_ptr<Completions> done;
        std::uint64_t token;
    };
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<Job> jobs;
    bool stopping = false;
    std::thread thread;

    void serve(LineLink& link) {
        std::unique_lock lk(mutex);
        for (;;) {
            cv.wait(lk, [&] { return stopping || !jobs.empty(); });
            if (stopping) break;
            Job job = std::move(jobs.front());
            jobs.pop_front();
            lk.unlock();
            try {
                std::string reply = link.transact(job.request, job.timeout);
                job.done->push(job.token, std::vector<std::uint8_t>(reply.begin(), reply.end()));
            } catch (...) {
                job.done->fail(job.token, std::current_exception());
            }
            lk.lock();
        }
        for (auto& job : jobs)
            job.done->fail(job.token, std::make_exception_ptr(ClosedError("LineLink: closed with the transaction queued")));
        jobs.clear();
    }
};

LineLink::~LineLink() {
    if (worker_) {
        {
            std::lock_guard lk(worker_->mutex);
            worker_->stopping = true;
        }
        worker_->cv.notify_all();
        worker_->thread.join();    // a transaction in progress ends within its reply timeout
    }
}

void LineLink::transact_async(std::string request, std::optional<Duration> timeout, std::shared_ptr<Completions> done,
                              std::uint64_t token) {
    if (!done) throw InvalidArgument("LineLink.transact_async: no completion queue");
    {
        std::lock_guard lk(impl_->worker_mutex);
        if (!worker_) {
            worker_ = std::make_unique<Worker>();
            worker_->thread = std::thread([this] { worker_->serve(*this); });
        }
    }
    {
        std::lock_guard lk(worker_->mutex);
        worker_->jobs.push_back(Worker::Job{std::move(request), timeout, std::move(done), token});
    }
    worker_->cv.notify_one();
}

std::string LineLink::transact(std::string_view request, std::optional<Duration> timeout) {
    auto& d = *impl_;
    std::lock_guard lk(d.mutex);
    if (d.options.flush_before_request) d.flush_stale();
    d.write_line(request);
    if (d.options.turnaround > Duration::zero()) {
        // RS-485: our transceiver drives the bus until the last stop bit is out,
        // then needs the turn-around time before the drive may answer.
        d.port->drain();
        interruptible_sleep_for(d.options.turnaround);
    }
    Duration t = timeout.value_or(d.options.reply_timeout);
    bool forever = t.count() < 0;
    auto deadline = Clock::now() + (forever ? Duration::zero() : t);
    std::optional<FramedLine> line;
    try {
        line = d.next_line(deadline, forever);
    } catch (...) {
        // Interrupted (or the link failed): the partial reply goes, as after a timeout.
        d.framer.reset();
        d.pending.clear();
        d.echo.clear();
        d.echo_pos = 0;
        throw;
    }
    if (!line) {
        if (d.framer.discarding()) {
            // The cap was already exceeded: that is the real diagnosis.
            ++d.c.overlong_lines;
            d.framer.reset();
            throw ReplyTooLong("ReplyTooLong: reply exceeds max_line " + std::to_string(d.options.max_line) +
                               " and no terminator arrived");
        }
        ++d.c.timeouts;
        d.trace('!', "no reply within " +
                         std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(t).count()) + " ms");
        std::size_t partial = d.framer.partial_bytes() + d.pending.size();
        d.framer.reset();
        d.pending.clear();
        d.echo.clear();
        d.echo_pos = 0;
        throw TimeoutError("no reply to '" + printable(request) + "' within " +
                           std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(t).count()) +
                           " ms (" + std::to_string(partial) + " partial bytes discarded)");
    }
    return d.finish(*line);
}

void LineLink::send(std::string_view request) {
    auto& d = *impl_;
    std::lock_guard lk(d.mutex);
    d.write_line(request);
}

std::optional<std::string> LineLink::read_line(Duration timeout) {
    auto& d = *impl_;
    std::lock_guard lk(d.mutex);
    bool forever = timeout.count() < 0;
    auto line = d.next_line(Clock::now() + (forever ? Duration::zero() : timeout), forever);
    if (!line) return std::nullopt;  // a partial line stays buffered for the next call
    return d.finish(*line);
}

const LineOptions& LineLink::options() const { return impl_->options; }

Port& LineLink::port() { return *impl_->port; }

void LineLink::set_trace(Trace trace) { impl_->trace = std::move(trace); }

LineCounters LineLink::counters() const {
    const auto& c = impl_->c;
    LineCounters out;
    out.bytes_in = c.bytes_in;
    out.bytes_out = c.bytes_out;
    out.requests = c.requests;
    out.replies = c.replies;
    out.timeouts = c.timeouts;
    out.stale_bytes = c.stale_bytes;
    out.overlong_lines = c.overlong_lines;
    out.echo_bytes = c.echo_bytes;
    out.echo_mismatches = c.echo_mismatches;
    return out;
}

}  // namespace motorbus::serial

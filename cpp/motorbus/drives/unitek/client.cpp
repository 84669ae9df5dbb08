#include "motorbus/drives/unitek/client.hpp"

#include <algorithm>
#include <cstdio>

namespace motorbus::unitek {

namespace {
std::string regid_text(std::uint8_t r) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02X", r);
    return buf;
}
}  // namespace

// ---- RingBuffer ------------------------------------------------------------------------

RingBuffer::RingBuffer(std::size_t capacity) : cap_(capacity), t_(capacity), v_(capacity) {
    if (capacity == 0 || capacity > (std::size_t{1} << 28))
        throw InvalidArgument("unitek ring capacity: 1..268435456 samples, not " + std::to_string(capacity));
}

// Slots are accessed through atomic_ref (plain int64 storage, so numpy can view it):
// a reader that races a lapping writer gets a stale or a new sample, never a torn one,
// and read() counts such samples as lost.
void RingBuffer::push(Nanos t, std::int64_t v) {
    const std::uint64_t k = written_.load(std::memory_order_relaxed);
    // Seqlock pairing with read(): a reader that sees these slot stores also sees
    // started_ > k, and so knows the slot's older sample (k - capacity) is gone.
    started_.store(k + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    std::atomic_ref<Nanos>(t_[k % cap_]).store(t, std::memory_order_relaxed);
    std::atomic_ref<std::int64_t>(v_[k % cap_]).store(v, std::memory_order_relaxed);
    written_.store(k + 1, std::memory_order_release);
}

std::size_t RingBuffer::read(std::uint64_t& cursor, Nanos* t, std::int64_t* v, std::size_t max,
                             std::uint64_t& lost) const {
    const std::uint64_t end = written_.load(std::memory_order_acquire);
    if (end - cursor > cap_) {
        lost += end - cursor - cap_;
        cursor = end - cap_;
    }
    std::size_t n = 0;
    while (cursor < end && n < max) {
        t[n] = std::atomic_ref<Nanos>(const_cast<Nanos&>(t_[cursor % cap_])).load(std::memory_order_relaxed);
        v[n] = std::atomic_ref<std::int64_t>(const_cast<std::int64_t&>(v_[cursor % cap_])).load(std::memory_order_relaxed);
        ++n;
        ++cursor;
    }
    // The writer may have lapped the samples just copied (the oldest first): drop
    // that prefix and count it lost, so what is returned is exactly what was written.
    // `started_` also covers a sample the writer is half-way through.
    std::atomic_thread_fence(std::memory_order_acquire);
    const std::uint64_t after = started_.load(std::memory_order_relaxed);
    if (after > cap_ && cursor - n < after - cap_) {
        const std::size_t bad = static_cast<std::size_t>(std::min<std::uint64_t>(n, after - cap_ - (cursor - n)));
        lost += bad;
        std::copy(t + bad, t + n, t);
        std::copy(v + bad, v + n, v);
        n -= bad;
    }
    return n;
}

// ---- Client ----------------------------------------------------------------------

Client::Client(can::Bus& bus, RegisterTable table, ClientOptions options)
    : bus_(bus), table_(std::move(table)), opt_(options), rx_id_(options.rx_id) {
    if (opt_.rx_id < kRxIdMin || opt_.rx_id > kRxIdMax)
        throw InvalidArgument("unitek rx_id: 0x201..0x27F, not " + std::to_string(opt_.rx_id));
    if (opt_.tx_id < kTxIdMin || opt_.tx_id > kTxIdMax)
        throw InvalidArgument("unitek tx_id: 0x181..0x1FF, not " + std::to_string(opt_.tx_id));
    if (opt_.timeout <= std::chrono::nanoseconds::zero()) throw InvalidArgument("unitek timeout: must be positive");
    sub_ = bus_.subscribe_id(opt_.tx_id, false, [this](const can::Frame& f) { on_frame(f); });
}

Client::~Client() {
    try {
        close();
    } catch (...) {
    }
}

void Client::close() {
    if (closing_.exchange(true)) return;
    std::vector<std::uint8_t> regids;
    {
        std::lock_guard l(m_);
        for (auto& [id, s] : streams_) regids.push_back(id);
    }
    // The drive would keep sending what we subscribed to: stop it (best effort,
    // the bus may be gone already).
    for (auto id : regids) {
        try {
            send(encode_request(id, kIntervalStop));
        } catch (const Error&) {
        }
    }
    closed_ = true;
    bus_.unsubscribe(sub_);
    std::lock_guard l(m_);
    for (auto& [id, s] : streams_) s->active = false;
    streams_.clear();
    cv_.notify_all();
}

void Client::add_register(Register r) {
    std::lock_guard l(m_);
    table_.add(std::move(r));
}

void Client::send(const std::vector<std::uint8_t>& bytes) {
    if (closed_.load()) throw ClosedError("unitek client: closed");
    bus_.send(can::Frame::make(rx_id_.load(), bytes), opt_.timeout);
}

void Client::write(std::uint8_t regid, std::int64_t value) {
    std::vector<std::uint8_t> bytes;
    {
        std::lock_guard l(m_);
        bytes = encode_write(table_.at(regid), value);
    }
    send(bytes);
    if (regid == kRegMode) {
        std::lock_guard l(m_);
        mode_ = static_cast<std::uint16_t>(value);
        events_on_ = (mode_ & kModeEvents) != 0;
    }
}

void Client::write_raw(std::uint8_t regid, std::int64_t value, int bits) {
    if (regid == kRegRead) throw InvalidArgument("unitek write_raw: 0x3D is the read request (use read/subscribe)");
    send(encode_write(regid, value, bits));
}

std::int64_t Client::read(std::uint8_t regid, std::optional<std::chrono::nanoseconds> timeout) {
    const auto limit = timeout.value_or(opt_.timeout);
    if (limit <= std::chrono::nanoseconds::zero()) throw InvalidArgument("unitek read timeout: must be positive");
    std::unique_lock l(m_);
    const Register& r = table_.at(regid);
    if (!r.readable()) throw InvalidArgument("unitek register " + r.name + " (" + regid_text(regid) + "): write-only");
    const std::uint64_t gen = arrivals_[regid];
    ++waiting_[regid];
    l.unlock();
    try {
        send(encode_request(regid, kIntervalOnce));
    } catch (...) {
        l.lock();
        --waiting_[regid];
        throw;
    }
    l.lock();
    const bool ok = cv_.wait_for(l, limit, [&] { return arrivals_[regid] != gen || closed_.load(); });
    --waiting_[regid];
    if (closed_.load()) throw ClosedError("unitek client: closed");
    if (!ok)
        throw TimeoutError("unitek: no reply to the read of " + r.name + " (" + regid_text(regid) + ") within " +
                           std::to_string(std::chrono::duration<double>(limit).count()) + " s");
    return last_value_[regid];
}

std::shared_ptr<Stream> Client::subscribe(std::uint8_t regid, int interval_ms, std::size_t capacity,
                                                SampleCallback callback) {
    auto bytes = encode_cyclic(regid, interval_ms);  // checks the interval first
    std::shared_ptr<Stream> s;
    {
        std::lock_guard l(m_);
        const Register& r = table_.at(regid);
        if (!r.readable()) throw InvalidArgument("unitek register " + r.name + ": write-only, cannot be streamed");
        auto it = streams_.find(regid);
        if (it != streams_.end()) {
            s = it->second;
            s->interval_ms = interval_ms;
        } else {
            if (static_cast<int>(streams_.size()) >= kMaxCyclic) {
                std::string list;
                for (auto& [id, st] : streams_) list += (list.empty() ? "" : ", ") + regid_text(id);
                throw CyclicLimit("unitek: at most 8 registers transmit cyclically (002 ex 9); " + list +
                                  " are running: unsubscribe one before " + regid_text(regid));
            }
            s = std::make_shared<Stream>(regid, interval_ms, capacity);
            s->callback = std::move(callback);
            streams_[regid] = s;
        }
    }
    send(bytes);
    return s;
}

void Client::unsubscribe(std::uint8_t regid) {
    std::shared_ptr<Stream> s;
    {
        std::lock_guard l(m_);
        auto it = streams_.find(regid);
        if (it == streams_.end()) return;
        s = it->second;
        streams_.erase(it);
    }
    s->active = false;
    send(encode_request(regid, kIntervalStop));
}

std::vector<std::shared_ptr<Stream>> Client::streams() const {
    std::lock_guard l(m_);
    std::vector<std::shared_ptr<Stream>> out;
    for (auto& [id, s] : streams_) out.push_back(s);
    return out;
}

void Client::write_mode(std::uint16_t mode) { write(kRegMode, mode); }

void Client::enable() { write_mode(static_cast<std::uint16_t>(mode() & ~kModeDisable)); }
void Client::disable() { write_mode(static_cast<std::uint16_t>(mode() | kModeDisable)); }

void Client::set_events(bool on, std::optional<std::uint16_t> mask) {
    if (mask) write(kRegEventMask, *mask);
    const std::uint16_t m = mode();
    write_mode(static_cast<std::uint16_t>(on ? (m | kModeEvents) : (m & ~kModeEvents)));
}

void Client::on_status(StatusCallback cb) {
    std::lock_guard l(m_);
    status_cb_ = std::move(cb);
}

std::optional<std::uint32_t> Client::last_event_status() const {
    std::lock_guard l(m_);
    return last_status_;
}

std::uint64_t Client::events() const {
    std::lock_guard l(m_);
    return events_;
}

std::uint16_t Client::mode() const {
    std::lock_guard l(m_);
    return mode_;
}

void Client::set_receive_id(std::uint32_t rx_id) {
    write(kRegRxId, rx_id);  // checks 0x201..0x27F
    rx_id_ = rx_id;
}

void Client::store_eeprom(int level) {
    if (level != 0 && level != 1) throw InvalidArgument("unitek EEPROM level: 0 or 1, not " + std::to_string(level));
    write(kRegEeprom, level);
}

ClientCounters Client::counters() const {
    std::lock_guard l(m_);
    return counters_;
}

void Client::on_frame(const can::Frame& f) {
    if (f.rtr || f.extended || (f.flags & can::kFlagLoopback)) return;
    const Nanos t = opt_.clock ? opt_.clock->now() : (f.timestamp_ns ? f.timestamp_ns : monotonic_ns());
    FromDrive d;
    try {
        d = decode_from_drive(f.payload());
    } catch (const FrameError&) {
        std::lock_guard l(m_);
        ++counters_.rejected;  // R1
        return;
    }
    std::shared_ptr<Stream> stream;
    StatusCallback status_cb;
    std::int64_t value = 0;
    bool used = false, event = false;
    {
        std::lock_guard l(m_);
        const Register* r = table_.find(d.regid);
        if (r == nullptr) {
            ++counters_.unsolicited;
            return;
        }
        value = r->from_raw(d.value, d.value_bits);
        if (d.regid == kRegStatus && d.value_bits == 32 && events_on_) {
            event = used = true;
            last_status_ = static_cast<std::uint32_t>(d.value);
            ++events_;
            status_cb = status_cb_;
        }
        if (!event) {
            auto w = waiting_.find(d.regid);
            if (w != waiting_.end() && w->second > 0) {
                last_value_[d.regid] = value;
                ++arrivals_[d.regid];
                used = true;
                cv_.notify_all();
            }
            auto s = streams_.find(d.regid);
            if (s != streams_.end()) {
                stream = s->second;
                used = true;
            }
        }
        if (used) ++counters_.replies;
        else ++counters_.unsolicited;  // R4: no request outstanding, not cyclic, no events
    }
    if (stream) {
        stream->ring.push(t, value);
        if (stream->callback) {
            try {
                stream->callback(d.regid, t, value);
            } catch (...) {
                std::lock_guard l(m_);
                ++counters_.callback_errors;
            }
        }
    }
    if (status_cb) {
        try {
            status_cb(static_cast<std::uint32_t>(d.value), t);
        } catch (...) {
            std::lock_guard l(m_);
            ++counters_.callback_errors;
        }
    }
}

}  // namespace motorbus::unitek

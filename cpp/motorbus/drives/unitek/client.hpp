// Host side of the UNITEK register protocol over any can::Bus.
//
// Writes go out as `REGID value` and are never acknowledged (B-U05): read back
// where it matters.  read() sends `3D REGID 00` and waits for the reply.
// subscribe() starts a cyclic transmission (`3D REGID t`) whose frames the bus
// receive thread decodes straight into a ring buffer of (timestamp, value)
// pairs -- no Python, no GIL on that path -- and optionally hands to a callback.
// At most 8 registers are cyclic at once (002 ex 9): a 9th subscribe() throws
// CyclicLimit before anything is sent.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/drives/unitek/codec.hpp"
#include "motorbus/runtime/clock.hpp"

namespace motorbus::unitek {

// A fixed ring of (timestamp ns, value) written by one thread (the bus receive
// thread) and read by another.  The writer never blocks and never allocates:
// when the reader falls behind by more than the capacity, the oldest samples
// are overwritten and counted as lost by read().
class RingBuffer {
public:
    explicit RingBuffer(std::size_t capacity);
    void push(Nanos t, std::int64_t v);
    std::size_t capacity() const { return cap_; }
    std::uint64_t count() const { return written_.load(std::memory_order_acquire); }  // ever pushed
    // Copies the samples after `cursor` (at most `max`) and moves the cursor;
    // `lost` grows by the samples overwritten before they could be read.
    std::size_t read(std::uint64_t& cursor, Nanos* t, std::int64_t* v, std::size_t max, std::uint64_t& lost) const;
    // The storage itself (zero-copy views; sample k lives at k % capacity).
    const Nanos* times() const { return t_.data(); }
    const std::int64_t* values() const { return v_.data(); }

private:
    std::size_t cap_;
    std::vector<Nanos> t_;
    std::vector<std::int64_t> v_;
    std::atomic<std::uint64_t> written_{0};  // samples complete
    std::atomic<std::uint64_t> started_{0};  // samples begun (written_ or written_ + 1)
};

using SampleCallback = std::function<void(std::uint8_t regid, Nanos t, std::int64_t value)>;
using StatusCallback = std::function<void(std::uint32_t status, Nanos t)>;

struct Stream {
    Stream(std::uint8_t r, int ms, std::size_t capacity) : regid(r), interval_ms(ms), ring(capacity) {}
    std::uint8_t regid;
    std::atomic<int> interval_ms;
    RingBuffer ring;
    std::atomic<bool> active{true};
    SampleCallback callback;  // set before the stream is published
};

struct ClientOptions {
    std::uint32_t rx_id = kDefaultRxId;  // the drive's receive id (we send to it)
    std::uint32_t tx_id = kDefaultTxId;  // the drive's transmit id (we listen to it)
    std::chrono::nanoseconds timeout = std::chrono::milliseconds(200);
    Clock* clock = nullptr;  // timestamps from this clock (a SimClock in tests); default: frame time
};

struct ClientCounters {
    std::uint64_t replies = 0;      // frames used (read replies, stream samples, events)
    std::uint64_t rejected = 0;     // from the drive with a DLC other than 4/6 (R1)
    std::uint64_t unsolicited = 0;  // well-formed but nobody asked (R4)
    std::uint64_t callback_errors = 0;
};

class Client {
public:
    Client(can::Bus& bus, RegisterTable table = RegisterTable::builtin(), ClientOptions options = {});
    can::Bus& bus() const { return bus_; }  // what capture sources subscribe on
    ~Client();
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    const RegisterTable& table() const { return table_; }
    void add_register(Register r);

    // Checked write: UnknownRegister, InvalidArgument (read-only, out of range).
    void write(std::uint8_t regid, std::int64_t value);
    // Unchecked write of `bits` (16/32) for registers outside the table.
    void write_raw(std::uint8_t regid, std::int64_t value, int bits);
    // Read once; TimeoutError after `timeout` (default: the options' timeout).
    std::int64_t read(std::uint8_t regid, std::optional<std::chrono::nanoseconds> timeout = std::nullopt);

    // Cyclic transmission every `interval_ms` (1..254).  Subscribing again to the
    // same register changes its period and keeps its ring.
    std::shared_ptr<Stream> subscribe(std::uint8_t regid, int interval_ms, std::size_t capacity = 65536,
                                      SampleCallback callback = nullptr);
    // `3D REGID FF`: the drive stops sending it.  No-op for a register not subscribed.
    void unsubscribe(std::uint8_t regid);
    std::vector<std::shared_ptr<Stream>> streams() const;

    // MODE (0x51) is write-only: the client keeps the value it last wrote.
    void enable();   // MODE bit 2 = 0
    void disable();  // MODE bit 2 = 1
    // MODE bit 4 on/off; with a mask, writes 0x52 first.
    void set_events(bool on, std::optional<std::uint16_t> mask = std::nullopt);
    void on_status(StatusCallback cb);
    std::optional<std::uint32_t> last_event_status() const;
    std::uint64_t events() const;
    std::uint16_t mode() const;

    // 0x68: the drive listens on `rx_id` from now on (and so does this client).
    void set_receive_id(std::uint32_t rx_id);
    // 0x84: store the parameters (level 0 or 1).
    void store_eeprom(int level = 0);

    std::uint32_t rx_id() const { return rx_id_.load(); }
    std::uint32_t tx_id() const { return opt_.tx_id; }
    ClientCounters counters() const;
    void close();  // stops every stream (best effort) and unsubscribes

private:
    void on_frame(const can::Frame& f);
    void send(const std::vector<std::uint8_t>& bytes);
    void write_mode(std::uint16_t mode);

    can::Bus& bus_;
    RegisterTable table_;
    ClientOptions opt_;
    std::atomic<std::uint32_t> rx_id_;
    can::SubscriptionId sub_ = 0;

    mutable std::mutex m_;
    std::condition_variable cv_;
    std::map<std::uint8_t, int> waiting_;                  // regid -> readers waiting
    std::map<std::uint8_t, std::uint64_t> arrivals_;       // regid -> replies seen (generation)
    std::map<std::uint8_t, std::int64_t> last_value_;
    std::map<std::uint8_t, std::shared_ptr<Stream>> streams_;
    std::uint16_t mode_ = 0;
    bool events_on_ = false;
    std::optional<std::uint32_t> last_status_;
    std::uint64_t events_ = 0;
    StatusCallback status_cb_;
    ClientCounters counters_;
    std::atomic<bool> closed_{false};
    std::atomic<bool> closing_{false};
};

}  // namespace motorbus::unitek

// SDO client: the state machine of one transfer (pure: frames in, frames out)
// and SdoClient, which runs it over a motorbus Bus.
//
//   auto bus = motorbus::can::open_virtual("hub");
//   SdoClient sdo(*bus, 5);                       // requests on 0x605, responses on 0x585
//   std::uint8_t status = sdo.read_u8(0x6001, 0);
//   sdo.write_u32(0x6004, 0, 3200);
//   Bytes blob = sdo.upload(0x1F50, 1, TransferMode::Block);
//
// Errors: SdoAbortError (the server refused; .code, CiA text), SdoTimeout (no
// answer; we sent abort 0x05040000 with the multiplexer), SdoProtocolError
// (the server broke the protocol; we sent the abort in .code; .bytes = frame).
//
// Threading: one transfer per client (= per SDO channel) at a time; threads
// sharing a client are serialized in arrival order.  Clients for different
// nodes (or channels) run concurrently; each costs one O(1) subscription.
//
// A transfer waiting for its response ends at once with LinkDown when the
// bus's link is lost (or interrupted: frames of the exchange may be gone) and
// with ClosedError when the bus is closed, from any thread (Bus::watch_link).
//
// Completion-based transfers (the awaitable face, motorbus.aio):
//
//   auto done = std::make_shared<Completions>();
//   sdo.upload_async(0x1000, 0, TransferMode::Auto, done, 7);   // returns at once
//   ... done->fd() turns readable: done->drain() has {7, Bytes} or {7, error}
//
// The transfer runs on the bus's receive thread (on_frame) and ends with exactly
// one completion: push(token, Bytes) for an upload, push(token, {}) for a
// download, fail(token, error) with the errors the blocking call throws -- unless
// the caller withdrew it with cancel().  Async transfers of one client queue in
// the order they were asked (one transfer per SDO channel, CiA 301); a blocking
// transfer on the same client waits for the running one and goes before the
// queued ones, so the two never interleave on the wire.
//
// Deadlines: nothing in here sleeps for an async transfer.  Whoever waits for
// the completion arms a timer at the deadline and calls check_deadline() then
// (the asyncio face: loop.call_later per awaited transfer).  Why not a timer
// thread: the goal is no thread per wait and no more threads while 127
// transfers are awaited than without them; the event loop already is a timer
// heap, and a C++ timer thread would also need a wake-up for every frame (each
// restarts the response timeout).  A blocking transfer queued behind an async
// one enforces that one's deadline itself while it waits (a loop that went away
// cannot leave the channel stuck for blocking callers).
#pragma once
#include <any>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/datatypes.hpp"
#include "motorbus/canopen/sdo_codec.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/runtime/completions.hpp"

namespace motorbus::canopen {

enum class TransferMode {
    Auto,       // upload: the server picks expedited/segmented; download: expedited if <= 4 bytes
    Segmented,  // download: segmented even for <= 4 bytes (upload: same as Auto)
    Block,      // block transfer; a server that refuses block mode is an SdoAbortError
                // (0x05040001) unless fallback_to_segmented was asked for
};

constexpr Nanos kNoDeadline = std::numeric_limits<Nanos>::max();

struct SdoClientConfig {
    Nanos timeout_ns = 1'000'000'000;      // per response (restarted by every frame received)
    std::size_t max_transfer = 1u << 20;   // larger uploads abort 0x05040005 before allocating
    std::uint8_t block_size = 127;         // sub-block size we offer in block upload (1..127)
    // Offer CRC in block transfers, and require it: a server that answers
    // without CRC gets abort 0x05040004 (a block transfer delivers CRC-checked
    // data or fails).  false = no CRC asked for, none checked.
    bool block_crc = true;
    // pst of block upload: the server may switch to the plain upload protocol
    // (expedited / segmented, no CRC) for data up to this many bytes.  0 = never:
    // a switch is then refused (abort 0x05040001) -- under bit errors a block
    // initiate response read as an expedited one delivered its size as the value
    // -- unless fallback_to_segmented accepts CRC-less answers (counted in fallbacks).
    std::uint8_t protocol_switch = 0;
    // Server refuses block mode (abort 0x05040001 / 0x06010000 to the block
    // initiate) -> retry the same transfer segmented (no CRC).  Off by default:
    // a caller who asked for block gets block or SdoAbortError.
    bool fallback_to_segmented = false;
    // Block upload: ack what arrived when a sub-block stalls for this fraction of
    // the timeout, so the server retransmits the rest (B12/B13).
    double subblock_timer_fraction = 0.7;
};

// Counters of one client (across its transfers).
struct SdoClientCounters {
    std::uint64_t transfers = 0;
    std::uint64_t aborts_received = 0;   // server aborted
    std::uint64_t aborts_sent = 0;       // we aborted (timeout, protocol error)
    std::uint64_t timeouts = 0;
    std::uint64_t ignored_frames = 0;    // responses while idle (C8) or duplicates
    std::uint64_t retransmit_requests = 0;  // block: sub-blocks acked short (lost frames)
    std::uint64_t fallbacks = 0;          // block refused, retried segmented
    // Initiate responses and aborts naming another multiplexer than the one we
    // asked: another client's (two processes on one node's default SDO channel),
    // ignored -- the transfer waits on for its own response.
    std::uint64_t foreign_responses = 0;
};

// One transfer at a time; feed it every frame from the response COB-ID and
// call on_timer() at next_deadline().  Outgoing payloads are appended to `out`.
class SdoClientMachine {
public:
    enum class Status { Idle, Running, Done, Failed };
    using Outbox = std::vector<sdo::Payload>;

    explicit SdoClientMachine(SdoClientConfig config = {});

    void start_upload(std::uint16_t index, std::uint8_t subindex, TransferMode mode, Nanos now,
                      Outbox& out);
    void start_download(std::uint16_t index, std::uint8_t subindex,
                        std::span<const std::uint8_t> data, TransferMode mode, Nanos now,
                        Outbox& out);
    // Any payload (0..8 bytes) received on the response COB-ID.
    void on_frame(std::span<const std::uint8_t> payload, Nanos now, Outbox& out);
    void on_timer(Nanos now, Outbox& out);
    // Forget the transfer (after Done/Failed); the machine becomes Idle.
    void reset();
    // Give up a Running transfer: the server is told (abort `code` with the
    // multiplexer, appended to `out`) and the machine becomes Idle.  Until the
    // next transfer's initiate is answered, frames naming no object (the
    // abandoned transfer's last answer, still in flight) are ignored.
    void abandon(std::uint32_t code, Outbox& out);

    Status status() const { return status_; }
    bool busy() const { return status_ == Status::Running; }
    Nanos next_deadline() const;
    const Bytes& result() const { return data_; }           // uploaded bytes (Done)
    Bytes take_result() { Bytes b; b.swap(data_); return b; }
    std::exception_ptr error() const { return error_; }      // Failed
    const SdoClientCounters& counters() const { return counters_; }
    const SdoClientConfig& config() const { return config_; }
    sdo::Multiplexer multiplexer() const { return mux_; }    // of the current transfer
    void set_config(const SdoClientConfig& c) { config_ = c; }

private:
    enum class Phase {
        None,
        UpInitiate, UpSegment,
        DnInitiate, DnSegment,
        BlkUpInitiate, BlkUpSub, BlkUpEnd,
        BlkDnInitiate, BlkDnSub, BlkDnEnd,
    };
    void fail_abort(std::uint32_t code, Outbox& out, std::span<const std::uint8_t> frame,
                    const std::string& why);
    void fail_peer_abort(std::span<const std::uint8_t> frame, Outbox& out);
    void touch(Nanos now);
    bool check_mux(std::span<const std::uint8_t> p, Outbox& out);
    bool foreign(std::span<const std::uint8_t> p) const;
    static bool names_object(std::span<const std::uint8_t> p);  // an initiate response or an abort
    void finish();
    void send_next_download_segment(Outbox& out);
    void send_block_download_subblock(Outbox& out);
    void on_upload(std::span<const std::uint8_t> p, Outbox& out);
    void on_download(std::span<const std::uint8_t> p, Outbox& out);
    void on_block_upload(std::span<const std::uint8_t> p, Nanos now, Outbox& out);
    void on_block_download(std::span<const std::uint8_t> p, Outbox& out);
    void start_segmented_download(Outbox& out);
    void start_plain_upload(Outbox& out);
    void block_upload_ack(Outbox& out);
    void block_upload_repeat(Outbox& out);

    SdoClientConfig config_;
    SdoClientCounters counters_;
    Status status_ = Status::Idle;
    Phase phase_ = Phase::None;
    TransferMode mode_ = TransferMode::Auto;
    sdo::Multiplexer mux_;
    Bytes data_;                 // upload: received; download: to send
    std::size_t pos_ = 0;        // download: bytes already acknowledged/sent
    std::optional<std::uint32_t> indicated_;
    bool toggle_ = false;
    bool crc_ = false;
    std::uint8_t blksize_ = 0;
    std::uint8_t seq_ = 0;       // block: last in-order seqno received / sent
    // Block upload: the last acknowledgement we sent (to repeat it when it is
    // lost) and whether any segment arrived since it (or since the start command).
    bool acked_ = false;
    std::uint8_t last_ackseq_ = 0, last_ack_blksize_ = 0;
    bool segment_since_ack_ = false;
    std::size_t sent_segments_ = 0;  // block download: segments in the current sub-block
    bool sent_last_ = false;         // block download: the current sub-block ends the data
    Nanos deadline_ = kNoDeadline;
    Nanos sub_deadline_ = kNoDeadline;
    Nanos started_ = 0;
    std::exception_ptr error_;
    bool skip_stale_ = false;  // abandon(): not cleared by reset(), by the next answer naming an object
};

struct SdoClientOptions {
    std::chrono::nanoseconds timeout = std::chrono::seconds(1);
    std::size_t max_transfer = 1u << 20;  // >= 1 (InvalidArgument otherwise)
    std::uint8_t block_size = 127;        // 1-127 (InvalidArgument otherwise)
    bool block_crc = true;                // offer and require CRC (SdoClientConfig::block_crc)
    // Opt-in: a server that refuses block mode gets the transfer segmented
    // (Python: SdoClient(..., block_fallback=True)).  Default: SdoAbortError.
    bool fallback_to_segmented = false;
    // Idempotent reads are retried this many times after a timeout (writes never are).
    unsigned read_retries = 0;
    // Before sleeping, the caller polls (yielding the CPU) this long for the
    // response: saves a thread wake-up per round trip on fast links.  0 = sleep at once.
    std::chrono::microseconds spin{50};
    // COB-IDs; 0 = the default channel 0x600+n / 0x580+n.
    std::uint32_t request_id = 0;
    std::uint32_t response_id = 0;
};

class SdoClient {
public:
    SdoClient(can::Bus& bus, std::uint8_t node_id, SdoClientOptions options = {});
    ~SdoClient();
    SdoClient(const SdoClient&) = delete;
    SdoClient& operator=(const SdoClient&) = delete;

    Bytes upload(std::uint16_t index, std::uint8_t subindex, TransferMode mode = TransferMode::Auto);
    void download(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                  TransferMode mode = TransferMode::Auto);

    // Typed access: the value must have exactly the type's size (else
    // SdoProtocolError-free InvalidArgument naming the sizes, C14).
    std::uint8_t read_u8(std::uint16_t i, std::uint8_t s);
    std::uint16_t read_u16(std::uint16_t i, std::uint8_t s);
    std::uint32_t read_u32(std::uint16_t i, std::uint8_t s);
    std::uint64_t read_u64(std::uint16_t i, std::uint8_t s);
    std::int8_t read_i8(std::uint16_t i, std::uint8_t s);
    std::int16_t read_i16(std::uint16_t i, std::uint8_t s);
    std::int32_t read_i32(std::uint16_t i, std::uint8_t s);
    std::int64_t read_i64(std::uint16_t i, std::uint8_t s);
    float read_f32(std::uint16_t i, std::uint8_t s);
    double read_f64(std::uint16_t i, std::uint8_t s);
    std::string read_string(std::uint16_t i, std::uint8_t s);  // trailing NULs dropped
    Bytes read_domain(std::uint16_t i, std::uint8_t s, TransferMode mode = TransferMode::Auto) {
        return upload(i, s, mode);
    }
    void write_u8(std::uint16_t i, std::uint8_t s, std::uint8_t v);
    void write_u16(std::uint16_t i, std::uint8_t s, std::uint16_t v);
    void write_u32(std::uint16_t i, std::uint8_t s, std::uint32_t v);
    void write_u64(std::uint16_t i, std::uint8_t s, std::uint64_t v);
    void write_i8(std::uint16_t i, std::uint8_t s, std::int8_t v);
    void write_i16(std::uint16_t i, std::uint8_t s, std::int16_t v);
    void write_i32(std::uint16_t i, std::uint8_t s, std::int32_t v);
    void write_i64(std::uint16_t i, std::uint8_t s, std::int64_t v);
    void write_f32(std::uint16_t i, std::uint8_t s, float v);
    void write_f64(std::uint16_t i, std::uint8_t s, double v);
    void write_string(std::uint16_t i, std::uint8_t s, std::string_view v);
    void write_domain(std::uint16_t i, std::uint8_t s, std::span<const std::uint8_t> v,
                      TransferMode mode = TransferMode::Auto) {
        download(i, s, v, mode);
    }

    // Completion-based transfers (see the top of this file).  Return at once;
    // the transfer ends with one completion on `done` named `token`.
    void upload_async(std::uint16_t index, std::uint8_t subindex, TransferMode mode,
                      std::shared_ptr<Completions> done, std::uint64_t token);
    void download_async(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                        TransferMode mode, std::shared_ptr<Completions> done, std::uint64_t token);
    // Fires the running async transfer's timers that are due (timeout: abort sent,
    // SdoTimeout completed or an idempotent read retried; block upload sub-block
    // timer), and notices a bus that closed or lost its link.  Returns when to call
    // again: the running async transfer's next deadline (monotonic_ns), or
    // kNoDeadline when no async transfer is running (queued ones start later).
    Nanos check_deadline();
    // Withdraws an async transfer: a queued one is dropped; the running one is
    // aborted on the wire (0x08000000, general error) and the next one starts.
    // No completion follows.  False when `token` was not pending (already done).
    bool cancel(const std::shared_ptr<Completions>& done, std::uint64_t token);
    // Async transfers asked for and not yet completed (queued + running).
    std::size_t async_pending() const;
    // Fails every pending async transfer with ClosedError, aborts the running
    // one on the wire, and refuses later transfers (ClosedError).  Idempotent;
    // the destructor calls it.
    void close();
    bool closed() const { return closed_.load(); }

    std::uint8_t node_id() const { return node_id_; }
    std::uint32_t request_id() const { return request_id_; }
    std::uint32_t response_id() const { return response_id_; }
    // A copy: options may change concurrently (set_timeout).
    SdoClientOptions options() const {
        std::lock_guard lock(mutex_);
        return options_;
    }
    void set_timeout(std::chrono::nanoseconds t);
    SdoClientCounters counters() const;

private:
    template <class T>
    T read_le(std::uint16_t i, std::uint8_t s);
    template <class T>
    void write_le(std::uint16_t i, std::uint8_t s, T v);
    void run(std::unique_lock<std::mutex>& lock, std::uint64_t link_losses);
    void send_out();
    void on_frame(const can::Frame& f);

    // --- async transfers (all under mutex_) ---
    struct AsyncTransfer {
        bool upload = true;
        std::uint16_t index = 0;
        std::uint8_t subindex = 0;
        Bytes data;
        TransferMode mode = TransferMode::Auto;
        std::shared_ptr<Completions> done;
        std::uint64_t token = 0;
        unsigned attempt = 0;
    };
    // A completion decided under the lock, delivered after it is released: a
    // Completions wake-up hook may take a lock of its own (Python's GIL for a
    // loop without add_reader), which must never be waited for under mutex_.
    struct Finished {
        std::shared_ptr<Completions> done;
        std::uint64_t token;
        std::any value;
        std::exception_ptr error;
    };
    using FinishedList = std::vector<Finished>;
    static void deliver(FinishedList& finished);
    void submit_async(AsyncTransfer t);
    std::exception_ptr start_async_locked(AsyncTransfer& t);
    void start_next_async_locked(FinishedList& out);
    void settle_async_locked(FinishedList& out);
    void fail_current_async_locked(std::exception_ptr e, FinishedList& out);
    Nanos check_deadline_locked(FinishedList& out);
    void on_link_event_locked(FinishedList& out);
    std::exception_ptr bus_gone_error() const;
    // Blocking transfers: wait for the channel (an async transfer may be running).
    void acquire_channel(std::unique_lock<std::mutex>& lock);
    void release_channel_locked(FinishedList& out);
    struct ChannelGuard;

    // The caller's wait: shared with the bus's link watcher, which may still
    // run once after the client is gone (Bus::unwatch_link).
    struct Sync {
        std::mutex mutex;               // guards machine_, outbox_, send_error_, owner
        // The client, for the link watcher to fail its async transfers; null once
        // the client is closing (the watcher may run once after that).
        SdoClient* owner = nullptr;
        std::condition_variable cv;
        // The thread sending with `mutex` held: a link watcher it triggers
        // itself (its send found the link dead) must not lock `mutex` again.
        std::atomic<std::thread::id> sending{};
    };

    can::Bus& bus_;
    std::uint8_t node_id_;
    SdoClientOptions options_;
    std::uint32_t request_id_, response_id_;
    std::mutex transfer_mutex_;   // one transfer per channel
    std::shared_ptr<Sync> sync_ = std::make_shared<Sync>();
    std::mutex& mutex_ = sync_->mutex;
    std::condition_variable& cv_ = sync_->cv;
    // A send from the receive thread (the next request of a transfer) failed
    // because the link is gone or the bus closed: the transfer ends with it.
    std::exception_ptr send_error_;
    SdoClientMachine machine_;
    SdoClientMachine::Outbox outbox_;
    can::SubscriptionId sub_ = 0;
    can::SubscriptionId link_watch_ = 0;
    std::atomic<bool> idle_{true};  // the machine is not Running (for the spin-wait)

    std::deque<AsyncTransfer> async_queue_;           // mutex_: asked, not started
    std::optional<AsyncTransfer> async_current_;      // mutex_: running on machine_
    std::uint64_t async_link_losses_ = 0;             // mutex_: link_losses() when it started
    std::exception_ptr async_send_error_;             // mutex_: a send of the running one failed
    int blocking_waiting_ = 0;                        // mutex_: blocking callers wanting the channel
    bool blocking_running_ = false;                   // mutex_: a blocking transfer owns machine_
    std::atomic<bool> closed_{false};
};

}  // namespace motorbus::canopen

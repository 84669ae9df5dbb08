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
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <limits>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/datatypes.hpp"
#include "motorbus/canopen/sdo_codec.hpp"
#include "motorbus/runtime/clock.hpp"

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

    // The caller's wait: shared with the bus's link watcher, which may still
    // run once after the client is gone (Bus::unwatch_link).
    struct Sync {
        std::mutex mutex;               // guards machine_, outbox_, send_error_
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
};

}  // namespace motorbus::canopen

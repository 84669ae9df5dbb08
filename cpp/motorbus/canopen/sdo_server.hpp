// SDO server state machine (pure: request payload in, response payloads out)
// serving an ObjectDictionary with expedited, segmented and block transfers.
//
// LocalNode runs it on a bus; tests and fuzzers drive it directly:
//   SdoServerMachine srv(od);
//   SdoServerMachine::Outbox out;
//   srv.on_request(bytes_from_0x600_plus_n, now_ns, out);   // out: bytes for 0x580+n
//   if (now_ns >= srv.next_deadline()) srv.on_timer(now_ns, out);
//
// Policies where CiA 301 leaves a choice (documented in docs/canopen.md):
//   * a request shorter than 8 bytes whose fields are missing is refused with
//     0x05040001 (S4, S19); DLC 0 is ignored and counted (S5);
//   * block seqno 0 aborts 0x05040003 (B4); a duplicate/out-of-order seqno is
//     ignored and the sub-block acked up to the last good one (B6, B13);
//   * segmented downloads to fixed-size objects are checked at initiate (S11),
//     and every buffer is bounded by the object's size or max_buffer (S12).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "motorbus/canopen/od.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/canopen/sdo_codec.hpp"

namespace motorbus::canopen {

struct SdoServerConfig {
    Nanos timeout_ns = 1'000'000'000;  // client silent this long mid-transfer -> abort 0x05040000 (S16)
    std::size_t max_buffer = 0;        // largest download buffered; 0 = the OD's max_variable_size
    std::uint8_t block_size = 127;     // sub-block size we ask for in block download (1..127)
    bool block_transfer = true;        // false: refuse block requests with 0x05040001 (B16)
};

struct SdoServerCounters {
    std::uint64_t requests = 0;        // payloads processed
    std::uint64_t responses = 0;       // payloads sent (including aborts)
    std::uint64_t aborts_sent = 0;
    std::uint64_t aborts_received = 0;
    std::uint64_t ignored = 0;         // DLC 0, stray block segments, duplicates
    std::uint64_t timeouts = 0;
    std::uint64_t dropped = 0;         // mailbox full (filled in by LocalNode, S18)
    std::uint64_t transfers_completed = 0;
};

class SdoServerMachine {
public:
    using Outbox = std::vector<sdo::Payload>;

    explicit SdoServerMachine(ObjectDictionary& od, SdoServerConfig config = {});

    void on_request(std::span<const std::uint8_t> payload, Nanos now, Outbox& out);
    void on_timer(Nanos now, Outbox& out);
    Nanos next_deadline() const { return deadline_ < sub_deadline_ ? deadline_ : sub_deadline_; }
    bool idle() const { return phase_ == Phase::Idle; }
    // True while a block download sub-block is streaming in: those frames are
    // consumed straight from the receive thread (no mailbox) so none is lost.
    bool receiving_subblock() const { return phase_ == Phase::BlkDnSub; }
    // True for a request that gets no response (an abort, the client's final
    // block-upload confirmation): the client does not wait before its next
    // request, so LocalNode consumes these at once instead of via its mailbox.
    bool consumes_silently(std::span<const std::uint8_t> p) const {
        if (p.empty()) return true;
        if (p[0] == 0x80 || (sdo::ccs_of(p[0]) == sdo::Ccs::Abort && phase_ != Phase::BlkDnSub)) return true;
        return phase_ == Phase::BlkUpEnd && (p[0] & 0xE3) == 0xA1;
    }
    // True when handling `p` runs no application code (no hook, no listener):
    // LocalNode answers these on the receive thread.  Requests that may run
    // hooks, and anything unexpected while idle, go through its single-slot
    // mailbox to the worker thread (so a flood is dropped and counted).
    bool handles_inline(std::span<const std::uint8_t> p) const;
    // Drop any transfer without a word (NMT reset, stop).
    void reset();
    // Bytes currently held for a transfer (bounded; 0 when idle).
    std::size_t buffered() const { return buffer_.capacity() + pending_.capacity() * 7; }

    const SdoServerCounters& counters() const { return counters_; }
    SdoServerCounters& counters() { return counters_; }
    const SdoServerConfig& config() const { return config_; }

private:
    enum class Phase {
        Idle,
        DnSegment,
        UpSegment,
        BlkDnSub, BlkDnEnd,
        BlkUpStart, BlkUpSub, BlkUpEnd,
    };
    void abort(sdo::Multiplexer m, std::uint32_t code, Outbox& out);
    void emit(const sdo::Payload& p, Outbox& out);
    void idle_request(std::span<const std::uint8_t> p, Nanos now, Outbox& out);
    void initiate_upload(sdo::Multiplexer m, Nanos now, Outbox& out);
    void initiate_download(std::span<const std::uint8_t> p, sdo::Multiplexer m, Nanos now, Outbox& out);
    void block_download_initiate(std::span<const std::uint8_t> p, sdo::Multiplexer m, Nanos now, Outbox& out);
    void block_upload_initiate(std::span<const std::uint8_t> p, sdo::Multiplexer m, Nanos now, Outbox& out);
    void on_download_segment(std::span<const std::uint8_t> p, Nanos now, Outbox& out);
    void on_upload_segment(std::span<const std::uint8_t> p, Nanos now, Outbox& out);
    void on_block_download(std::span<const std::uint8_t> p, Nanos now, Outbox& out);
    void on_block_upload(std::span<const std::uint8_t> p, Nanos now, Outbox& out);
    void send_upload_subblock(Outbox& out);
    void touch(Nanos now);
    // Fetch up to `max` more bytes of the upload source; returns 0 or an abort code.
    std::uint32_t pull(std::size_t max, Bytes& chunk, bool& last);
    void release();
    std::size_t cap() const;

    ObjectDictionary& od_;
    SdoServerConfig config_;
    SdoServerCounters counters_;
    Phase phase_ = Phase::Idle;
    sdo::Multiplexer mux_;
    VariablePtr var_;
    Bytes buffer_;                 // download: received; upload: snapshot of the value
    std::size_t pos_ = 0;          // upload: bytes of buffer_ sent
    std::optional<std::uint32_t> indicated_;
    bool toggle_ = false;
    bool crc_ = false;
    bool streaming_ = false;       // upload via the chunk hook
    bool stream_done_ = false;
    std::uint8_t blksize_ = 0;
    std::uint8_t seq_ = 0;         // block download: last in-order seqno
    std::uint16_t crc_acc_ = 0;    // block upload: CRC of the data produced so far
    // block upload: segments produced but not yet acknowledged (kept for retransmission)
    std::vector<std::array<std::uint8_t, 7>> pending_;
    std::size_t sent_count_ = 0;       // of pending_, sent in the current sub-block
    std::uint8_t last_len_ = 7;        // data bytes in the final segment
    bool has_last_ = false;            // pending_.back() is the final segment
    std::size_t limit_ = 0;            // download: most bytes accepted
    Nanos deadline_ = kNoDeadline;
    Nanos sub_deadline_ = kNoDeadline; // block download: ack a stalled sub-block (B12)
};

}  // namespace motorbus::canopen

#include "motorbus/runtime/interrupt.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/errors.hpp"

#include <algorithm>
#include <exception>
#include <cstdio>
#include <cstring>
#include <thread>

namespace motorbus::canopen {

using namespace sdo;
namespace ac = abort_code;

namespace {
std::string hexdump(std::span<const std::uint8_t> p) {
    std::string s;
    char b[4];
    for (auto x : p) {
        std::snprintf(b, sizeof b, "%s%02X", s.empty() ? "" : " ", x);
        s += b;
    }
    return s;
}
}  // namespace

SdoClientMachine::SdoClientMachine(SdoClientConfig config) : config_(config) {
    if (config_.block_size == 0 || config_.block_size > kMaxBlockSize) config_.block_size = kMaxBlockSize;
}

void SdoClientMachine::reset() {
    status_ = Status::Idle;
    phase_ = Phase::None;
    Bytes().swap(data_);
    pos_ = 0;
    indicated_.reset();
    toggle_ = crc_ = sent_last_ = false;
    seq_ = 0;
    acked_ = segment_since_ack_ = false;
    last_ackseq_ = last_ack_blksize_ = 0;
    sent_segments_ = 0;
    deadline_ = sub_deadline_ = kNoDeadline;
    error_ = nullptr;
}

Nanos SdoClientMachine::next_deadline() const {
    if (status_ != Status::Running) return kNoDeadline;
    return std::min(deadline_, sub_deadline_);
}

void SdoClientMachine::touch(Nanos now) {
    deadline_ = now > kNoDeadline - config_.timeout_ns ? kNoDeadline : now + config_.timeout_ns;
}

void SdoClientMachine::start_upload(std::uint16_t index, std::uint8_t subindex, TransferMode mode,
                                    Nanos now, Outbox& out) {
    reset();
    status_ = Status::Running;
    mode_ = mode;
    mux_ = {index, subindex};
    started_ = now;
    ++counters_.transfers;
    touch(now);
    if (mode == TransferMode::Block) {
        phase_ = Phase::BlkUpInitiate;
        out.push_back(block_upload_initiate(mux_, config_.block_crc, config_.block_size,
                                            config_.protocol_switch));
    } else {
        start_plain_upload(out);
    }
}

void SdoClientMachine::start_plain_upload(Outbox& out) {
    phase_ = Phase::UpInitiate;
    out.push_back(initiate_upload(mux_));
}

void SdoClientMachine::start_download(std::uint16_t index, std::uint8_t subindex,
                                      std::span<const std::uint8_t> data, TransferMode mode,
                                      Nanos now, Outbox& out) {
    reset();
    status_ = Status::Running;
    mode_ = mode;
    mux_ = {index, subindex};
    data_.assign(data.begin(), data.end());
    started_ = now;
    ++counters_.transfers;
    touch(now);
    if (mode == TransferMode::Block) {
        phase_ = Phase::BlkDnInitiate;
        out.push_back(block_download_initiate(mux_, config_.block_crc,
                                              static_cast<std::uint32_t>(data_.size())));
    } else {
        start_segmented_download(out);
    }
}

void SdoClientMachine::start_segmented_download(Outbox& out) {
    phase_ = Phase::DnInitiate;
    pos_ = 0;
    if (mode_ != TransferMode::Segmented && !data_.empty() && data_.size() <= 4)
        out.push_back(initiate_download_expedited(mux_, data_));
    else
        out.push_back(initiate_download_segmented(mux_, static_cast<std::uint32_t>(data_.size())));
}

void SdoClientMachine::fail_abort(std::uint32_t code, Outbox& out, std::span<const std::uint8_t> frame,
                                  const std::string& why) {
    out.push_back(abort_transfer(mux_, code));
    ++counters_.aborts_sent;
    char buf[64];
    std::snprintf(buf, sizeof buf, "SDO 0x%04X:%02X: ", mux_.index, mux_.subindex);
    error_ = std::make_exception_ptr(SdoProtocolError(
        std::string(buf) + why + " [" + hexdump(frame) + "]; sent abort " + describe_abort(code),
        Bytes(frame.begin(), frame.end()), code, mux_.index, mux_.subindex));
    status_ = Status::Failed;
    phase_ = Phase::None;
    Bytes().swap(data_);
}

void SdoClientMachine::fail_peer_abort(std::span<const std::uint8_t> frame, Outbox& out) {
    const std::uint32_t code = abort_code_of(frame);  // C4, C5: short or zero -> 0x08000000
    ++counters_.aborts_received;
    const bool initiating = phase_ == Phase::BlkUpInitiate || phase_ == Phase::BlkDnInitiate;
    if (initiating && config_.fallback_to_segmented &&
        (code == ac::kCommandSpecifier || code == ac::kUnsupportedAccess)) {
        // B16: the server has no block mode; the same transfer, segmented.
        ++counters_.fallbacks;
        if (phase_ == Phase::BlkUpInitiate) {
            start_plain_upload(out);
        } else {
            mode_ = TransferMode::Auto;
            start_segmented_download(out);
        }
        return;
    }
    error_ = std::make_exception_ptr(SdoAbortError(code, mux_.index, mux_.subindex));
    status_ = Status::Failed;
    phase_ = Phase::None;
    Bytes().swap(data_);
}

void SdoClientMachine::abandon(std::uint32_t code, Outbox& out) {
    if (status_ == Status::Running) {
        out.push_back(abort_transfer(mux_, code));
        ++counters_.aborts_sent;
        skip_stale_ = true;
    }
    reset();
}

void SdoClientMachine::finish() {
    status_ = Status::Done;
    phase_ = Phase::None;
    deadline_ = sub_deadline_ = kNoDeadline;
}

bool SdoClientMachine::check_mux(std::span<const std::uint8_t> p, Outbox& out) {
    auto m = multiplexer_of(p);
    if (!m) {
        fail_abort(ac::kCommandSpecifier, out, p, "response too short for its multiplexer");  // C15
        return false;
    }
    if (*m != mux_) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "response names 0x%04X:%02X (mismatch)", m->index, m->subindex);
        fail_abort(ac::kParamIncompatible, out, p, buf);  // C2
        return false;
    }
    return true;
}

// A frame that carries a multiplexer (an initiate response of any protocol, an
// abort) naming another object than ours: the response to another client on
// the same COB-IDs (two processes asking one node).  Not inside a block
// upload's sub-block, where byte 0 is a sequence number, not a specifier.
bool SdoClientMachine::names_object(std::span<const std::uint8_t> p) {
    if (p.size() < 4) return false;
    const std::uint8_t cs = p[0];
    return scs_of(cs) == Scs::InitiateUpload || scs_of(cs) == Scs::InitiateDownload ||
           scs_of(cs) == Scs::Abort ||
           (cs & 0xE1) == 0xC0 ||  // block upload initiate response (ss 0)
           (cs & 0xE3) == 0xA0;    // block download initiate response (ss 0)
}

bool SdoClientMachine::foreign(std::span<const std::uint8_t> p) const {
    if (phase_ == Phase::BlkUpSub || !names_object(p)) return false;
    const auto m = multiplexer_of(p);
    return m && *m != mux_;
}

void SdoClientMachine::on_frame(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    if (status_ != Status::Running) {  // C8: stray response, nothing to queue
        ++counters_.ignored_frames;
        return;
    }
    if (p.empty()) return fail_abort(ac::kCommandSpecifier, out, p, "empty response");
    if (foreign(p)) {
        // Another client's: ours is still to come.  It does not restart our
        // timeout, so a busy neighbour cannot keep this transfer waiting forever.
        ++counters_.foreign_responses;
        return;
    }
    if (skip_stale_) {
        // The transfer before this one was abandoned (cancelled) mid-way: the
        // server's answer to its last request may still be on the way.  Until
        // our initiate is answered, a frame that names no object (a segment, a
        // sub-block) is that answer: ignored, not a protocol error.
        const bool initiating = phase_ == Phase::UpInitiate || phase_ == Phase::DnInitiate ||
                                phase_ == Phase::BlkUpInitiate || phase_ == Phase::BlkDnInitiate;
        if (initiating && !names_object(p)) {
            ++counters_.ignored_frames;
            return;
        }
        skip_stale_ = false;
    }
    const bool in_segments = phase_ == Phase::BlkUpSub;
    if ((in_segments && p[0] == 0x80) || (!in_segments && scs_of(p[0]) == Scs::Abort))
        return fail_peer_abort(p, out);  // C3: unconfirmed, no reply
    touch(now);
    switch (phase_) {
        case Phase::UpInitiate:
        case Phase::UpSegment:
            return on_upload(p, out);
        case Phase::DnInitiate:
        case Phase::DnSegment:
            return on_download(p, out);
        case Phase::BlkUpInitiate:
        case Phase::BlkUpSub:
        case Phase::BlkUpEnd:
            return on_block_upload(p, now, out);
        case Phase::BlkDnInitiate:
        case Phase::BlkDnSub:
        case Phase::BlkDnEnd:
            return on_block_download(p, out);
        case Phase::None: break;
    }
}

void SdoClientMachine::on_upload(std::span<const std::uint8_t> p, Outbox& out) {
    if (phase_ == Phase::UpInitiate) {
        if (scs_of(p[0]) != Scs::InitiateUpload)
            return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");  // C6
        if (!check_mux(p, out)) return;
        const auto f = initiate_flags(p[0]);
        if (f.expedited) {
            std::size_t n = f.size_indicated ? 4u - f.unused : std::min<std::size_t>(4, p.size() - 4);
            if (p.size() < 4 + n)
                return fail_abort(ac::kCommandSpecifier, out, p, "expedited data missing (short frame)");
            data_.assign(p.begin() + 4, p.begin() + 4 + static_cast<std::ptrdiff_t>(n));
            return finish();
        }
        if (f.size_indicated) {
            if (p.size() < 8) return fail_abort(ac::kCommandSpecifier, out, p, "size missing (short frame)");
            const std::uint32_t size = get_le32(&p[4]);
            if (size > config_.max_transfer)  // C10: refuse before allocating
                return fail_abort(ac::kOutOfMemory, out, p,
                                  "indicated size " + std::to_string(size) + " exceeds max_transfer");
            indicated_ = size;
            data_.reserve(std::min<std::size_t>(size, 65536));
        }
        phase_ = Phase::UpSegment;
        toggle_ = false;
        out.push_back(upload_segment(toggle_));
        return;
    }
    if (scs_of(p[0]) != Scs::UploadSegment)
        return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
    const auto f = segment_flags(p[0]);
    if (f.toggle != toggle_) return fail_abort(ac::kToggleBit, out, p, "toggle bit not alternated");  // C7
    const std::size_t n = kSegmentData - f.unused;
    if (p.size() < 1 + n) return fail_abort(ac::kCommandSpecifier, out, p, "segment shorter than its n");
    if (indicated_ && data_.size() + n > *indicated_)  // C11
        return fail_abort(ac::kTooLong, out, p, "more data than indicated");
    if (data_.size() + n > config_.max_transfer)  // C13
        return fail_abort(ac::kOutOfMemory, out, p, "upload exceeds max_transfer");
    data_.insert(data_.end(), p.begin() + 1, p.begin() + 1 + static_cast<std::ptrdiff_t>(n));
    if (f.last) {
        if (indicated_ && data_.size() < *indicated_)  // C12
            return fail_abort(ac::kTooShort, out, p, "less data than indicated");
        return finish();
    }
    toggle_ = !toggle_;
    out.push_back(upload_segment(toggle_));
}

void SdoClientMachine::send_next_download_segment(Outbox& out) {
    const std::size_t n = std::min(kSegmentData, data_.size() - pos_);
    const bool last = pos_ + n >= data_.size();
    out.push_back(download_segment(toggle_, std::span(data_).subspan(pos_, n), last));
    pos_ += n;
}

void SdoClientMachine::on_download(std::span<const std::uint8_t> p, Outbox& out) {
    if (phase_ == Phase::DnInitiate) {
        if (scs_of(p[0]) != Scs::InitiateDownload)
            return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
        if (!check_mux(p, out)) return;
        const bool expedited = mode_ != TransferMode::Segmented && !data_.empty() && data_.size() <= 4;
        if (expedited) return finish();
        phase_ = Phase::DnSegment;
        toggle_ = false;
        pos_ = 0;
        return send_next_download_segment(out);
    }
    if (scs_of(p[0]) != Scs::DownloadSegment)
        return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
    if (bool(p[0] & 0x10) != toggle_) return fail_abort(ac::kToggleBit, out, p, "toggle bit not alternated");
    if (pos_ >= data_.size()) return finish();
    toggle_ = !toggle_;
    send_next_download_segment(out);
}

void SdoClientMachine::block_upload_ack(Outbox& out) {
    out.push_back(sdo::block_upload_ack(seq_, blksize_));
    acked_ = true;
    last_ackseq_ = seq_;
    last_ack_blksize_ = blksize_;
    segment_since_ack_ = false;
    seq_ = 0;
}

// Nothing arrived since our last frame of the block upload: that frame was
// lost (or the server's answer was).  Repeat it as it was.  An acknowledgement
// with ackseq 0 here would tell a server still waiting for the lost one that
// none of the sub-block arrived: it resends it, and with the same sequence
// numbers as a new sub-block the client would take it as new data.
void SdoClientMachine::block_upload_repeat(Outbox& out) {
    ++counters_.retransmit_requests;
    if (!acked_)
        out.push_back(block_upload_start());
    else
        out.push_back(sdo::block_upload_ack(last_ackseq_, last_ack_blksize_));
}

void SdoClientMachine::on_block_upload(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    const auto arm_sub = [&] {
        sub_deadline_ = now + static_cast<Nanos>(static_cast<double>(config_.timeout_ns) *
                                                 config_.subblock_timer_fraction);
    };
    if (phase_ == Phase::BlkUpInitiate) {
        if (scs_of(p[0]) == Scs::InitiateUpload) {  // protocol switch by the server
            // Only when we allowed it: the plain protocol has no CRC, and a block
            // initiate response with one flipped bit reads as an expedited
            // response carrying the size as the value.  Allowed by a threshold
            // (pst > 0), or by fallback_to_segmented: the caller accepts CRC-less
            // transfers from servers without block mode, and some (the `canopen`
            // package's) answer a block upload request with a plain one.
            if (config_.protocol_switch == 0 && !config_.fallback_to_segmented)
                return fail_abort(ac::kCommandSpecifier, out, p,
                                  "server switched to a non-block upload (no CRC) the client did not allow");
            if (config_.protocol_switch == 0) ++counters_.fallbacks;
            phase_ = Phase::UpInitiate;
            return on_upload(p, out);
        }
        if ((p[0] & 0xE1) != 0xC0)
            return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
        if (!check_mux(p, out)) return;
        if (p[0] & 0x02) {
            if (p.size() < 8) return fail_abort(ac::kCommandSpecifier, out, p, "size missing (short frame)");
            const std::uint32_t size = get_le32(&p[4]);
            if (size > config_.max_transfer)  // C10
                return fail_abort(ac::kOutOfMemory, out, p,
                                  "indicated size " + std::to_string(size) + " exceeds max_transfer");
            indicated_ = size;
            data_.reserve(std::min<std::size_t>(size + 7, 1u << 20));
        }
        if (config_.block_crc && !(p[0] & 0x04))
            return fail_abort(ac::kCrc, out, p, "server declined the CRC of the block upload (its data would be unchecked)");
        crc_ = config_.block_crc;
        blksize_ = config_.block_size;
        seq_ = 0;
        phase_ = Phase::BlkUpSub;
        out.push_back(block_upload_start());
        arm_sub();
        return;
    }
    if (phase_ == Phase::BlkUpEnd) {
        if ((p[0] & 0xE3) != 0xC1) {
            if (p.size() == 8 && (p[0] & 0x7F) != 0) {  // a late retransmission: harmless
                ++counters_.ignored_frames;
                return;
            }
            return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
        }
        if (p.size() < 3) return fail_abort(ac::kCommandSpecifier, out, p, "end frame without CRC");
        const std::size_t unused = (p[0] >> 2) & 7;
        if (unused > data_.size() || (unused == 7 && data_.size() > 7))  // B10
            return fail_abort(ac::kCommandSpecifier, out, p, "end frame n inconsistent with the data");
        data_.resize(data_.size() - unused);
        if (indicated_ && data_.size() != *indicated_)  // B11
            return fail_abort(data_.size() > *indicated_ ? ac::kTooLong : ac::kTooShort, out, p,
                              "received " + std::to_string(data_.size()) + " bytes, indicated " +
                                  std::to_string(*indicated_));
        if (crc_ && crc16(data_) != get_le16(&p[1])) return fail_abort(ac::kCrc, out, p, "CRC mismatch");  // B9
        out.push_back(block_upload_end_response());
        return finish();
    }
    // BlkUpSub: segments c|seqno + 7 bytes.
    if (p.size() < 8) return fail_abort(ac::kCommandSpecifier, out, p, "block segment shorter than 8 bytes");
    const std::uint8_t seqno = p[0] & 0x7F;
    const bool last = p[0] & 0x80;
    if (seqno == 0) return fail_abort(ac::kSequenceNumber, out, p, "sequence number 0");
    arm_sub();
    segment_since_ack_ = true;
    if (seqno == seq_ + 1) {
        if (indicated_ && data_.size() >= *indicated_ + (*indicated_ == 0 ? 1 : 0))  // C11
            return fail_abort(ac::kTooLong, out, p, "more data than indicated");
        if (data_.size() >= config_.max_transfer)  // C13
            return fail_abort(ac::kOutOfMemory, out, p, "upload exceeds max_transfer");
        data_.insert(data_.end(), p.begin() + 1, p.begin() + 8);
        seq_ = seqno;
        if (last) {
            block_upload_ack(out);
            phase_ = Phase::BlkUpEnd;
            arm_sub();  // repeats this acknowledgement if the end frame does not come
        } else if (seq_ >= blksize_) {
            block_upload_ack(out);
        }
        return;
    }
    if (seqno <= seq_) {  // B6: overlap of a retransmission
        ++counters_.ignored_frames;
        return;
    }
    // A gap (B13): at the end of the sub-block, ask for the rest again.
    if (last || seqno >= blksize_) {
        ++counters_.retransmit_requests;
        block_upload_ack(out);
    }
}

void SdoClientMachine::send_block_download_subblock(Outbox& out) {
    sent_segments_ = 0;
    sent_last_ = false;
    std::size_t off = pos_;
    while (sent_segments_ < blksize_) {
        const std::size_t n = std::min(kSegmentData, data_.size() - off);
        const bool last = off + n >= data_.size();
        out.push_back(block_segment(static_cast<std::uint8_t>(sent_segments_ + 1),
                                    std::span(data_).subspan(off, n), last));
        ++sent_segments_;
        off += n;
        if (last) {
            sent_last_ = true;
            break;
        }
    }
}

void SdoClientMachine::on_block_download(std::span<const std::uint8_t> p, Outbox& out) {
    if (phase_ == Phase::BlkDnInitiate) {
        if (scs_of(p[0]) == Scs::InitiateDownload || (p[0] & 0xE3) != 0xA0)
            return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
        if (!check_mux(p, out)) return;
        if (p.size() < 5) return fail_abort(ac::kCommandSpecifier, out, p, "block size missing");
        if (p[4] == 0 || p[4] > kMaxBlockSize)  // B8
            return fail_abort(ac::kBlockSize, out, p, "invalid block size " + std::to_string(p[4]));
        if (config_.block_crc && !(p[0] & 0x04))
            return fail_abort(ac::kCrc, out, p, "server declined the CRC of the block download (it would not check the data)");
        crc_ = config_.block_crc;
        blksize_ = p[4];
        pos_ = 0;
        phase_ = Phase::BlkDnSub;
        return send_block_download_subblock(out);
    }
    if (phase_ == Phase::BlkDnEnd) {
        if ((p[0] & 0xE3) != 0xA1) return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
        return finish();
    }
    if ((p[0] & 0xE3) != 0xA2) return fail_abort(ac::kCommandSpecifier, out, p, "unexpected command specifier");
    if (p.size() < 3) return fail_abort(ac::kCommandSpecifier, out, p, "acknowledgement too short");
    const std::uint8_t ackseq = p[1], blksize = p[2];
    if (ackseq > sent_segments_) return fail_abort(ac::kSequenceNumber, out, p, "ackseq beyond the sub-block");
    if (blksize == 0 || blksize > kMaxBlockSize)  // B8
        return fail_abort(ac::kBlockSize, out, p, "invalid block size " + std::to_string(blksize));
    const bool all = ackseq == sent_segments_;
    pos_ = std::min(data_.size(), pos_ + std::size_t{ackseq} * kSegmentData);
    blksize_ = blksize;
    if (all && sent_last_) {
        const std::size_t rem = data_.size() % kSegmentData;
        const auto unused = static_cast<std::uint8_t>(data_.empty() ? 7 : rem ? kSegmentData - rem : 0);
        out.push_back(block_download_end(unused, crc_ ? crc16(data_) : 0));
        phase_ = Phase::BlkDnEnd;
        return;
    }
    if (!all) ++counters_.retransmit_requests;
    send_block_download_subblock(out);
}

void SdoClientMachine::on_timer(Nanos now, Outbox& out) {
    if (status_ != Status::Running) return;
    if (now >= deadline_) {  // C1: abort WITH the multiplexer, then report
        out.push_back(abort_transfer(mux_, ac::kTimeout));
        ++counters_.aborts_sent;
        ++counters_.timeouts;
        char buf[96];
        std::snprintf(buf, sizeof buf, "SDO 0x%04X:%02X: no response within %.3f s", mux_.index,
                      mux_.subindex, static_cast<double>(config_.timeout_ns) / 1e9);
        error_ = std::make_exception_ptr(SdoTimeout(buf, mux_.index, mux_.subindex));
        status_ = Status::Failed;
        phase_ = Phase::None;
        Bytes().swap(data_);
        return;
    }
    if ((phase_ == Phase::BlkUpSub || phase_ == Phase::BlkUpEnd) && now >= sub_deadline_) {
        sub_deadline_ = kNoDeadline;
        if (phase_ == Phase::BlkUpEnd || !segment_since_ack_) {
            // Our start command or last acknowledgement was lost (the server
            // still waits for it): say the same again.
            block_upload_repeat(out);
            return;
        }
        // B12: the server stalled mid sub-block; ack what arrived so it resends the rest.
        ++counters_.retransmit_requests;
        block_upload_ack(out);
    }
}

// ===========================================================================

SdoClient::SdoClient(can::Bus& bus, std::uint8_t node_id, SdoClientOptions options)
    : bus_(bus), node_id_(node_id), options_(options) {
    if ((node_id == 0 || node_id > 127) && (!options.request_id || !options.response_id))
        throw InvalidArgument("SdoClient node_id: " + std::to_string(node_id) + ", must be 1-127");
    request_id_ = options.request_id ? options.request_id : kDefaultRequestBase + node_id;
    response_id_ = options.response_id ? options.response_id : kDefaultResponseBase + node_id;
    if (request_id_ > can::kMaxStandardId || response_id_ > can::kMaxStandardId)
        throw InvalidArgument("SdoClient COB-IDs must be 11-bit");
    if (options.block_size == 0 || options.block_size > kMaxBlockSize)
        throw InvalidArgument("SdoClient block_size: " + std::to_string(options.block_size) +
                              ", must be 1-127 (segments per sub-block, CiA 301)");
    if (options.max_transfer == 0)
        throw InvalidArgument("SdoClient max_transfer: 0, must be >= 1 byte");
    SdoClientConfig c;
    c.timeout_ns = options.timeout.count() > 0 ? options.timeout.count() : 1;
    c.max_transfer = options.max_transfer;
    c.block_size = options.block_size;
    c.block_crc = options.block_crc;
    c.fallback_to_segmented = options.fallback_to_segmented;
    machine_.set_config(c);
    sync_->owner = this;
    sub_ = bus_.subscribe_id(response_id_, false, [this](const can::Frame& f) { on_frame(f); });
    // Link lost or bus closed: wake a waiting transfer now (run() sees which) and
    // end the running async one.  Taking the mutex orders the wake-up after the
    // waiter's predicate check; the one thread that must not take it is the one
    // sending under it (its send throws, and that path ends the transfer).
    link_watch_ = bus_.watch_link([s = sync_] {
        FinishedList finished;
        if (s->sending.load() != std::this_thread::get_id()) {
            std::lock_guard lock(s->mutex);
            if (s->owner) s->owner->on_link_event_locked(finished);
        }
        s->cv.notify_all();
        deliver(finished);
    });
}

SdoClient::~SdoClient() {
    close();
    {
        std::lock_guard lock(mutex_);
        sync_->owner = nullptr;  // a link watcher running after this does not reach us
    }
    bus_.unwatch_link(link_watch_);
    bus_.unsubscribe(sub_);
}

void SdoClient::set_timeout(std::chrono::nanoseconds t) {
    std::lock_guard tl(transfer_mutex_);
    std::lock_guard lock(mutex_);
    options_.timeout = t;
    auto c = machine_.config();
    c.timeout_ns = t.count() > 0 ? t.count() : 1;
    machine_.set_config(c);
}

SdoClientCounters SdoClient::counters() const {
    std::lock_guard lock(mutex_);
    return machine_.counters();
}

void SdoClient::send_out() {
    struct Sending {
        std::atomic<std::thread::id>& who;
        explicit Sending(std::atomic<std::thread::id>& w) : who(w) { who.store(std::this_thread::get_id()); }
        ~Sending() { who.store(std::thread::id{}); }
    } sending(sync_->sending);
    for (const auto& p : outbox_) {
        can::Frame f;
        f.id = request_id_;
        f.len = 8;
        std::memcpy(f.data.data(), p.data(), 8);
        bus_.send(f, options_.timeout);
    }
    outbox_.clear();
}

void SdoClient::on_frame(const can::Frame& f) {
    if (f.rtr || (f.flags & (can::kFlagError | can::kFlagLoopback))) return;
    bool done, sooner, wake_blocking = false;
    FinishedList finished;
    {
        std::lock_guard lock(mutex_);
        const Nanos before = machine_.next_deadline();
        machine_.on_frame(f.payload(), monotonic_ns(), outbox_);
        // A timer armed earlier than the one the caller sleeps on (the block
        // upload's sub-block timer) must wake it, or it fires only at the old
        // deadline, racing with the transfer timeout.
        sooner = machine_.next_deadline() < before;
        try {
            send_out();
        } catch (const LinkDown&) {
            // The link is gone or the bus closed: the transfer ends with that now.
            outbox_.clear();
            if (machine_.busy()) (async_current_ ? async_send_error_ : send_error_) = std::current_exception();
            sooner = true;
        } catch (const ClosedError&) {
            outbox_.clear();
            if (machine_.busy()) (async_current_ ? async_send_error_ : send_error_) = std::current_exception();
            sooner = true;
        } catch (const std::exception&) {
            // The medium refused (full): the transfer runs into its timeout.
            outbox_.clear();
        }
        done = !machine_.busy();
        if (async_current_) {
            // An async transfer: complete it here, on the receive thread, and
            // start the next one queued (or hand the channel to a blocking caller).
            settle_async_locked(finished);
            wake_blocking = blocking_waiting_ > 0 && !async_current_;
        }
    }
    deliver(finished);
    // Tell the caller after unlocking, so a spinning caller does not then
    // block on the mutex this thread still holds.
    if (done) {
        idle_.store(true, std::memory_order_release);
        cv_.notify_all();
    } else if (sooner || wake_blocking) {
        cv_.notify_all();
    }
}

void SdoClient::run(std::unique_lock<std::mutex>& lock, std::uint64_t link_losses) {
    send_error_ = nullptr;
    try {
        send_out();
    } catch (...) {
        machine_.reset();
        throw;
    }
    // Why the bus will not bring our response: closed, or its link lost (or
    // interrupted) since the transfer started.  Checked by the wait's predicate.
    auto bus_gone = [&] {
        return send_error_ || closed_.load() || bus_.closed() || bus_.link_losses() != link_losses;
    };
    if (options_.spin.count() > 0 && machine_.busy()) {
        idle_.store(false, std::memory_order_relaxed);
        lock.unlock();
        const auto until = std::chrono::steady_clock::now() + options_.spin;
        while (!idle_.load(std::memory_order_acquire) && std::chrono::steady_clock::now() < until)
            std::this_thread::yield();
        lock.lock();
    }
    while (machine_.busy()) {
        const Nanos dl = machine_.next_deadline();
        // An interrupted wait (Ctrl-C) leaves no transfer behind; the server
        // drops its side at its own timeout.
        struct ResetUnlessDone {
            SdoClientMachine& m;
            int uncaught = std::uncaught_exceptions();
            ~ResetUnlessDone() {
                if (std::uncaught_exceptions() > uncaught) m.reset();
            }
        } reset_on_throw{machine_};
        interruptible_wait_until(cv_, lock, std::chrono::steady_clock::time_point(std::chrono::nanoseconds(dl)),
                       [&] {
                           // A timer armed after we went to sleep (next_deadline() < dl)
                           // must wake us too, or it fires only at the old deadline.
                           return !machine_.busy() || machine_.next_deadline() < dl ||
                                  monotonic_ns() >= machine_.next_deadline() || bus_gone();
                       });
        if (machine_.busy() && bus_gone()) {
            // No abort to send: the bus cannot carry it.  The server drops its
            // side at its own timeout.  (reset_on_throw forgets the transfer.)
            char what[40];
            std::snprintf(what, sizeof what, "SDO 0x%04X:%02X: ", machine_.multiplexer().index,
                          machine_.multiplexer().subindex);
            if (send_error_) std::rethrow_exception(send_error_);
            if (closed_.load())
                throw ClosedError(std::string(what) + "SDO client of node " + std::to_string(node_id_) +
                                  " closed during the transfer");
            if (bus_.closed())
                throw ClosedError(std::string(what) + "bus " + bus_.channel() + " closed during the transfer");
            const std::string why = bus_.link_loss_reason();
            throw LinkDown(std::string(what) + "link of " + bus_.channel() + " lost during the transfer" +
                           (why.empty() ? "" : ": " + why));
        }
        if (machine_.busy() && monotonic_ns() >= machine_.next_deadline()) {
            machine_.on_timer(monotonic_ns(), outbox_);
            try {
                send_out();
            } catch (const std::exception&) {
                outbox_.clear();
            }
        }
    }
    if (machine_.status() == SdoClientMachine::Status::Failed) {
        auto e = machine_.error();
        machine_.reset();
        std::rethrow_exception(e);
    }
}

// The channel for one blocking transfer, and back: the queued async transfers
// start again when it is released (normally or by an exception).
struct SdoClient::ChannelGuard {
    SdoClient& client;
    std::unique_lock<std::mutex>& lock;
    ChannelGuard(SdoClient& c, std::unique_lock<std::mutex>& l) : client(c), lock(l) { client.acquire_channel(lock); }
    ~ChannelGuard() {
        FinishedList finished;
        if (!lock.owns_lock()) lock.lock();
        client.release_channel_locked(finished);
        lock.unlock();
        deliver(finished);
    }
};

Bytes SdoClient::upload(std::uint16_t index, std::uint8_t subindex, TransferMode mode) {
    std::lock_guard tl(transfer_mutex_);
    std::unique_lock lock(mutex_);
    ChannelGuard channel(*this, lock);
    for (unsigned attempt = 0;; ++attempt) {
        const std::uint64_t losses = bus_.link_losses();
        machine_.start_upload(index, subindex, mode, monotonic_ns(), outbox_);
        try {
            run(lock, losses);
        } catch (const SdoTimeout&) {
            if (attempt < options_.read_retries) continue;  // reads are idempotent
            throw;
        }
        Bytes out = machine_.take_result();
        machine_.reset();
        return out;
    }
}

void SdoClient::download(std::uint16_t index, std::uint8_t subindex,
                         std::span<const std::uint8_t> data, TransferMode mode) {
    std::lock_guard tl(transfer_mutex_);
    std::unique_lock lock(mutex_);
    ChannelGuard channel(*this, lock);
    const std::uint64_t losses = bus_.link_losses();
    machine_.start_download(index, subindex, data, mode, monotonic_ns(), outbox_);
    run(lock, losses);
    machine_.reset();
}

// ---- async transfers --------------------------------------------------------

void SdoClient::deliver(FinishedList& finished) {
    for (auto& f : finished) {
        if (f.error)
            f.done->fail(f.token, std::move(f.error));
        else
            f.done->push(f.token, std::move(f.value));
    }
    finished.clear();
}

void SdoClient::upload_async(std::uint16_t index, std::uint8_t subindex, TransferMode mode,
                             std::shared_ptr<Completions> done, std::uint64_t token) {
    if (!done) throw InvalidArgument("SdoClient upload_async: no Completions to complete on");
    AsyncTransfer t;
    t.upload = true;
    t.index = index;
    t.subindex = subindex;
    t.mode = mode;
    t.done = std::move(done);
    t.token = token;
    submit_async(std::move(t));
}

void SdoClient::download_async(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                               TransferMode mode, std::shared_ptr<Completions> done, std::uint64_t token) {
    if (!done) throw InvalidArgument("SdoClient download_async: no Completions to complete on");
    AsyncTransfer t;
    t.upload = false;
    t.index = index;
    t.subindex = subindex;
    t.data.assign(data.begin(), data.end());
    t.mode = mode;
    t.done = std::move(done);
    t.token = token;
    submit_async(std::move(t));
}

void SdoClient::submit_async(AsyncTransfer t) {
    FinishedList finished;
    {
        std::lock_guard lock(mutex_);
        if (closed_.load()) {
            finished.push_back({t.done, t.token, {},
                                std::make_exception_ptr(ClosedError(
                                    "SDO client of node " + std::to_string(node_id_) + " is closed"))});
        } else {
            async_queue_.push_back(std::move(t));
            start_next_async_locked(finished);
        }
    }
    deliver(finished);
}

// Starts `t` on the machine and sends its first request; the error when that
// send failed (the transfer then never ran), else null.
std::exception_ptr SdoClient::start_async_locked(AsyncTransfer& t) {
    async_send_error_ = nullptr;
    async_link_losses_ = bus_.link_losses();
    if (t.upload)
        machine_.start_upload(t.index, t.subindex, t.mode, monotonic_ns(), outbox_);
    else
        machine_.start_download(t.index, t.subindex, t.data, t.mode, monotonic_ns(), outbox_);
    try {
        send_out();
    } catch (...) {
        outbox_.clear();
        machine_.reset();
        return std::current_exception();
    }
    return nullptr;
}

void SdoClient::start_next_async_locked(FinishedList& out) {
    while (!async_current_ && !blocking_running_ && blocking_waiting_ == 0 && !async_queue_.empty()) {
        async_current_ = std::move(async_queue_.front());
        async_queue_.pop_front();
        if (auto e = start_async_locked(*async_current_)) {
            out.push_back({async_current_->done, async_current_->token, {}, e});
            async_current_.reset();
        }
    }
}

void SdoClient::fail_current_async_locked(std::exception_ptr e, FinishedList& out) {
    out.push_back({async_current_->done, async_current_->token, {}, std::move(e)});
    machine_.reset();
    outbox_.clear();
    async_current_.reset();
    async_send_error_ = nullptr;
    start_next_async_locked(out);
}

// The running async transfer, when the machine is done with it (or a send of
// it failed): its completion, then the next transfer.
void SdoClient::settle_async_locked(FinishedList& out) {
    if (!async_current_) return;
    if (machine_.busy()) {
        if (async_send_error_) fail_current_async_locked(async_send_error_, out);
        return;
    }
    AsyncTransfer& t = *async_current_;
    if (machine_.status() == SdoClientMachine::Status::Failed) {
        std::exception_ptr e = machine_.error();
        bool timed_out = false;
        try {
            std::rethrow_exception(e);
        } catch (const SdoTimeout&) {
            timed_out = true;
        } catch (...) {
        }
        if (timed_out && t.upload && t.attempt < options_.read_retries) {  // reads are idempotent
            ++t.attempt;
            machine_.reset();
            if (auto se = start_async_locked(t)) fail_current_async_locked(se, out);
            return;
        }
        return fail_current_async_locked(e, out);
    }
    out.push_back({t.done, t.token, t.upload ? std::any(machine_.take_result()) : std::any{}, nullptr});
    machine_.reset();
    async_current_.reset();
    async_send_error_ = nullptr;
    start_next_async_locked(out);
}

std::exception_ptr SdoClient::bus_gone_error() const {
    char what[40];
    std::snprintf(what, sizeof what, "SDO 0x%04X:%02X: ", machine_.multiplexer().index,
                  machine_.multiplexer().subindex);
    if (closed_.load())
        return std::make_exception_ptr(ClosedError(std::string(what) + "SDO client of node " +
                                                   std::to_string(node_id_) + " closed"));
    if (bus_.closed())
        return std::make_exception_ptr(
            ClosedError(std::string(what) + "bus " + bus_.channel() + " closed during the transfer"));
    if (bus_.link_losses() != async_link_losses_) {
        const std::string why = bus_.link_loss_reason();
        return std::make_exception_ptr(LinkDown(std::string(what) + "link of " + bus_.channel() +
                                                " lost during the transfer" + (why.empty() ? "" : ": " + why)));
    }
    return nullptr;
}

void SdoClient::on_link_event_locked(FinishedList& out) {
    if (!async_current_) return;
    // No abort to send: the bus cannot carry it.  Queued transfers then start
    // and fail at their first send if the bus is gone for good (ClosedError,
    // LinkDown), or run normally after an interruption.
    if (auto e = bus_gone_error()) fail_current_async_locked(e, out);
}

Nanos SdoClient::check_deadline() {
    FinishedList finished;
    Nanos next;
    bool wake_blocking;
    {
        std::lock_guard lock(mutex_);
        next = check_deadline_locked(finished);
        wake_blocking = blocking_waiting_ > 0 && !async_current_;
    }
    deliver(finished);
    if (wake_blocking) cv_.notify_all();
    return next;
}

Nanos SdoClient::check_deadline_locked(FinishedList& out) {
    if (!async_current_) return kNoDeadline;
    if (auto e = bus_gone_error()) {
        fail_current_async_locked(e, out);
    } else if (machine_.busy() && monotonic_ns() >= machine_.next_deadline()) {
        machine_.on_timer(monotonic_ns(), outbox_);  // C1: abort with the multiplexer, SdoTimeout
        try {
            send_out();
        } catch (const std::exception&) {
            outbox_.clear();
        }
        settle_async_locked(out);
    }
    return async_current_ ? machine_.next_deadline() : kNoDeadline;
}

bool SdoClient::cancel(const std::shared_ptr<Completions>& done, std::uint64_t token) {
    FinishedList finished;
    bool found = false, wake_blocking = false;
    {
        std::lock_guard lock(mutex_);
        auto it = std::find_if(async_queue_.begin(), async_queue_.end(),
                               [&](const AsyncTransfer& t) { return t.done == done && t.token == token; });
        if (it != async_queue_.end()) {
            async_queue_.erase(it);
            found = true;
        } else if (async_current_ && async_current_->done == done && async_current_->token == token) {
            // The server is told, so it does not keep the transfer open until its
            // own timeout: the channel is usable for the next one at once.
            machine_.abandon(ac::kGeneral, outbox_);
            try {
                send_out();
            } catch (const std::exception&) {
                outbox_.clear();
            }
            async_current_.reset();
            async_send_error_ = nullptr;
            start_next_async_locked(finished);
            found = true;
            wake_blocking = blocking_waiting_ > 0 && !async_current_;
        }
    }
    deliver(finished);
    if (wake_blocking) cv_.notify_all();
    return found;
}

std::size_t SdoClient::async_pending() const {
    std::lock_guard lock(mutex_);
    return async_queue_.size() + (async_current_ ? 1 : 0);
}

void SdoClient::close() {
    if (closed_.exchange(true)) return;
    FinishedList finished;
    {
        std::lock_guard lock(mutex_);
        auto e = std::make_exception_ptr(
            ClosedError("SDO client of node " + std::to_string(node_id_) + " closed with the transfer pending"));
        if (async_current_) {
            machine_.abandon(ac::kGeneral, outbox_);
            try {
                send_out();
            } catch (const std::exception&) {
                outbox_.clear();
            }
            finished.push_back({async_current_->done, async_current_->token, {}, e});
            async_current_.reset();
        }
        for (auto& t : async_queue_) finished.push_back({t.done, t.token, {}, e});
        async_queue_.clear();
    }
    cv_.notify_all();  // a blocking transfer ends with ClosedError (run()'s bus_gone)
    deliver(finished);
}

void SdoClient::acquire_channel(std::unique_lock<std::mutex>& lock) {
    if (closed_.load())
        throw ClosedError("SDO client of node " + std::to_string(node_id_) + " is closed");
    if (async_current_) {
        ++blocking_waiting_;
        try {
            while (async_current_) {
                // Enforce the async transfer's deadline here: its loop may be gone.
                const Nanos dl = machine_.next_deadline();
                interruptible_wait_until(cv_, lock, std::chrono::steady_clock::time_point(std::chrono::nanoseconds(dl)),
                                         [&] {
                                             return !async_current_ || closed_.load() ||
                                                    monotonic_ns() >= machine_.next_deadline() ||
                                                    bus_gone_error() != nullptr;
                                         });
                if (closed_.load())
                    throw ClosedError("SDO client of node " + std::to_string(node_id_) + " closed");
                if (async_current_) {
                    FinishedList finished;
                    check_deadline_locked(finished);
                    if (!finished.empty()) {
                        lock.unlock();
                        deliver(finished);
                        lock.lock();
                    }
                }
            }
        } catch (...) {
            --blocking_waiting_;
            FinishedList finished;  // the queue held back for us may run again
            start_next_async_locked(finished);
            if (!finished.empty()) {
                lock.unlock();
                deliver(finished);
                lock.lock();
            }
            throw;
        }
        --blocking_waiting_;
    }
    blocking_running_ = true;
}

void SdoClient::release_channel_locked(FinishedList& out) {
    if (!blocking_running_) {
        // acquire_channel threw (closed, interrupted): the queue may start again.
        start_next_async_locked(out);
        return;
    }
    blocking_running_ = false;
    start_next_async_locked(out);
}

template <class T>
T SdoClient::read_le(std::uint16_t i, std::uint8_t s) {
    Bytes b = upload(i, s);
    if (b.size() != sizeof(T)) {  // C14: decode by indicated size, refuse the type
        char buf[96];
        std::snprintf(buf, sizeof buf, "SDO 0x%04X:%02X: value has %zu bytes, expected %zu", i, s,
                      b.size(), sizeof(T));
        throw InvalidArgument(buf);
    }
    T v;
    if constexpr (sizeof(T) == 1) {
        std::memcpy(&v, b.data(), 1);
    } else {
        std::uint64_t u = 0;
        for (std::size_t k = 0; k < sizeof(T); ++k) u |= std::uint64_t{b[k]} << (8 * k);
        if constexpr (std::is_floating_point_v<T>) {
            if constexpr (sizeof(T) == 4) {
                auto u32 = static_cast<std::uint32_t>(u);
                std::memcpy(&v, &u32, 4);
            } else {
                std::memcpy(&v, &u, 8);
            }
        } else {
            v = static_cast<T>(u);
        }
    }
    return v;
}

template <class T>
void SdoClient::write_le(std::uint16_t i, std::uint8_t s, T v) {
    std::uint8_t b[sizeof(T)];
    std::uint64_t u = 0;
    if constexpr (std::is_floating_point_v<T>) {
        if constexpr (sizeof(T) == 4) {
            std::uint32_t u32;
            std::memcpy(&u32, &v, 4);
            u = u32;
        } else {
            std::memcpy(&u, &v, 8);
        }
    } else {
        u = static_cast<std::uint64_t>(v);
    }
    for (std::size_t k = 0; k < sizeof(T); ++k) b[k] = static_cast<std::uint8_t>(u >> (8 * k));
    download(i, s, std::span<const std::uint8_t>(b, sizeof(T)));
}

std::uint8_t SdoClient::read_u8(std::uint16_t i, std::uint8_t s) { return read_le<std::uint8_t>(i, s); }
std::uint16_t SdoClient::read_u16(std::uint16_t i, std::uint8_t s) { return read_le<std::uint16_t>(i, s); }
std::uint32_t SdoClient::read_u32(std::uint16_t i, std::uint8_t s) { return read_le<std::uint32_t>(i, s); }
std::uint64_t SdoClient::read_u64(std::uint16_t i, std::uint8_t s) { return read_le<std::uint64_t>(i, s); }
std::int8_t SdoClient::read_i8(std::uint16_t i, std::uint8_t s) { return read_le<std::int8_t>(i, s); }
std::int16_t SdoClient::read_i16(std::uint16_t i, std::uint8_t s) { return read_le<std::int16_t>(i, s); }
std::int32_t SdoClient::read_i32(std::uint16_t i, std::uint8_t s) { return read_le<std::int32_t>(i, s); }
std::int64_t SdoClient::read_i64(std::uint16_t i, std::uint8_t s) { return read_le<std::int64_t>(i, s); }
float SdoClient::read_f32(std::uint16_t i, std::uint8_t s) { return read_le<float>(i, s); }
double SdoClient::read_f64(std::uint16_t i, std::uint8_t s) { return read_le<double>(i, s); }

std::string SdoClient::read_string(std::uint16_t i, std::uint8_t s) {
    Bytes b = upload(i, s);
    while (!b.empty() && b.back() == 0) b.pop_back();
    return std::string(b.begin(), b.end());
}

void SdoClient::write_u8(std::uint16_t i, std::uint8_t s, std::uint8_t v) { write_le(i, s, v); }
void SdoClient::write_u16(std::uint16_t i, std::uint8_t s, std::uint16_t v) { write_le(i, s, v); }
void SdoClient::write_u32(std::uint16_t i, std::uint8_t s, std::uint32_t v) { write_le(i, s, v); }
void SdoClient::write_u64(std::uint16_t i, std::uint8_t s, std::uint64_t v) { write_le(i, s, v); }
void SdoClient::write_i8(std::uint16_t i, std::uint8_t s, std::int8_t v) { write_le(i, s, v); }
void SdoClient::write_i16(std::uint16_t i, std::uint8_t s, std::int16_t v) { write_le(i, s, v); }
void SdoClient::write_i32(std::uint16_t i, std::uint8_t s, std::int32_t v) { write_le(i, s, v); }
void SdoClient::write_i64(std::uint16_t i, std::uint8_t s, std::int64_t v) { write_le(i, s, v); }
void SdoClient::write_f32(std::uint16_t i, std::uint8_t s, float v) { write_le(i, s, v); }
void SdoClient::write_f64(std::uint16_t i, std::uint8_t s, double v) { write_le(i, s, v); }

void SdoClient::write_string(std::uint16_t i, std::uint8_t s, std::string_view v) {
    download(i, s, std::span(reinterpret_cast<const std::uint8_t*>(v.data()), v.size()));
}

}  // namespace motorbus::canopen

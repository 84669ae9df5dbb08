#include "motorbus/canopen/sdo_server.hpp"

#include <algorithm>

namespace motorbus::canopen {

using namespace sdo;
namespace ac = abort_code;

SdoServerMachine::SdoServerMachine(ObjectDictionary& od, SdoServerConfig config)
    : od_(od), config_(config) {
    if (config_.block_size == 0 || config_.block_size > kMaxBlockSize) config_.block_size = kMaxBlockSize;
}

std::size_t SdoServerMachine::cap() const {
    return config_.max_buffer ? config_.max_buffer : od_.max_variable_size();
}

void SdoServerMachine::emit(const Payload& p, Outbox& out) {
    out.push_back(p);
    ++counters_.responses;
}

void SdoServerMachine::abort(Multiplexer m, std::uint32_t code, Outbox& out) {
    emit(abort_transfer(m, code), out);
    ++counters_.aborts_sent;
    release();
}

void SdoServerMachine::release() {
    phase_ = Phase::Idle;
    var_.reset();
    Bytes().swap(buffer_);  // give the memory back, not just the size (S16)
    std::vector<std::array<std::uint8_t, 7>>().swap(pending_);
    sent_count_ = 0;
    pos_ = 0;
    indicated_.reset();
    streaming_ = stream_done_ = has_last_ = false;
    seq_ = 0;
    crc_acc_ = 0;
    deadline_ = sub_deadline_ = kNoDeadline;
}

void SdoServerMachine::reset() { release(); }

bool SdoServerMachine::handles_inline(std::span<const std::uint8_t> p) const {
    if (consumes_silently(p)) return true;
    switch (phase_) {
        case Phase::Idle: {
            auto m = multiplexer_of(p);
            const Ccs c = ccs_of(p[0]);
            if (!m || !(c == Ccs::InitiateUpload || c == Ccs::InitiateDownload || c == Ccs::BlockUpload ||
                        c == Ccs::BlockDownload))
                return false;
            VariablePtr var;
            if (od_.lookup(m->index, m->subindex, var)) return true;  // the answer is an abort
            return !var->has_hooks();
        }
        case Phase::BlkDnSub: return true;
        case Phase::DnSegment:  // only the last segment commits (and may run hooks)
            return (p[0] & 0xE1) == 0x00 || !var_ || !var_->has_hooks();
        case Phase::BlkDnEnd: return !var_ || !var_->has_hooks();
        case Phase::UpSegment:
        case Phase::BlkUpStart:
        case Phase::BlkUpSub: return !streaming_;
        case Phase::BlkUpEnd: return true;
    }
    return false;
}

void SdoServerMachine::touch(Nanos now) {
    deadline_ = now > kNoDeadline - config_.timeout_ns ? kNoDeadline : now + config_.timeout_ns;
}

void SdoServerMachine::on_request(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    ++counters_.requests;
    if (p.empty()) {  // S5: nothing to decode, nothing to answer
        ++counters_.ignored;
        return;
    }
    if (p[0] == 0x80 || (ccs_of(p[0]) == Ccs::Abort && phase_ != Phase::BlkDnSub)) {
        // S2/S3: an abort is unconfirmed; whatever was buffered is dropped uncommitted.
        ++counters_.aborts_received;
        release();
        return;
    }
    switch (phase_) {
        case Phase::Idle: idle_request(p, now, out); return;
        case Phase::DnSegment:
            if (ccs_of(p[0]) == Ccs::DownloadSegment) return on_download_segment(p, now, out);
            break;
        case Phase::UpSegment:
            if (ccs_of(p[0]) == Ccs::UploadSegment) return on_upload_segment(p, now, out);
            break;
        case Phase::BlkDnSub:
        case Phase::BlkDnEnd: return on_block_download(p, now, out);
        case Phase::BlkUpStart:
        case Phase::BlkUpSub:
        case Phase::BlkUpEnd: return on_block_upload(p, now, out);
    }
    // A request that does not belong to the transfer in progress.
    abort(mux_, ac::kCommandSpecifier, out);
}

void SdoServerMachine::idle_request(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    const Ccs ccs = ccs_of(p[0]);
    auto m = multiplexer_of(p);
    switch (ccs) {
        case Ccs::InitiateDownload:
        case Ccs::InitiateUpload:
        case Ccs::BlockUpload:
        case Ccs::BlockDownload:
            if (!m) return abort(Multiplexer{}, ac::kCommandSpecifier, out);  // S4: no multiplexer
            break;
        default:
            // S1 (unknown CCS) and S14 (segment with no transfer): refuse,
            // echoing whatever multiplexer bytes are there.
            return abort(m.value_or(Multiplexer{}), ac::kCommandSpecifier, out);
    }
    mux_ = *m;
    switch (ccs) {
        case Ccs::InitiateUpload: return initiate_upload(*m, now, out);
        case Ccs::InitiateDownload: return initiate_download(p, *m, now, out);
        case Ccs::BlockDownload:
            if ((p[0] & 0x01) != 0 || !config_.block_transfer) return abort(*m, ac::kCommandSpecifier, out);
            return block_download_initiate(p, *m, now, out);
        default:
            if ((p[0] & 0x03) != 0 || !config_.block_transfer) return abort(*m, ac::kCommandSpecifier, out);
            return block_upload_initiate(p, *m, now, out);
    }
}

// ---- upload ---------------------------------------------------------------

std::uint32_t SdoServerMachine::pull(std::size_t max, Bytes& chunk, bool& last) {
    chunk.clear();
    if (!streaming_) {
        const std::size_t n = std::min(max, buffer_.size() - pos_);
        chunk.assign(buffer_.begin() + static_cast<std::ptrdiff_t>(pos_),
                     buffer_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
        pos_ += n;
        last = pos_ >= buffer_.size();
        return 0;
    }
    auto hook = var_ ? var_->chunk_read_hook() : ChunkReadHook{};
    if (!hook) return ac::kGeneral;
    // The hook may deliver less than asked; keep asking until full or done.
    while (chunk.size() < max && !stream_done_) {
        Bytes part;
        bool done = false;
        if (auto c = hook(*var_, pos_, max - chunk.size(), part, done)) return c;  // S22
        if (part.size() > max - chunk.size()) return ac::kGeneral;
        if (part.empty() && !done) return ac::kNoData;  // a hook that stalls would spin forever
        pos_ += part.size();
        if (pos_ > cap()) return ac::kOutOfMemory;
        chunk.insert(chunk.end(), part.begin(), part.end());
        stream_done_ = done;
    }
    last = stream_done_;
    return 0;
}

void SdoServerMachine::initiate_upload(Multiplexer m, Nanos now, Outbox& out) {
    VariablePtr var;
    if (auto c = od_.lookup(m.index, m.subindex, var)) return abort(m, c, out);  // S6, S7
    if (!readable(var->access())) return abort(m, ac::kWriteOnly, out);        // S8
    var_ = var;
    if (var->chunk_read_hook()) {
        streaming_ = true;  // size unknown in advance: segmented, size not indicated
        emit(initiate_upload_segmented_response(m, std::nullopt), out);
    } else {
        if (auto c = var->remote_read(buffer_)) return abort(m, c, out);
        if (!buffer_.empty() && buffer_.size() <= 4) {
            emit(initiate_upload_expedited_response(m, buffer_), out);
            ++counters_.transfers_completed;
            return release();
        }
        emit(initiate_upload_segmented_response(m, static_cast<std::uint32_t>(buffer_.size())), out);
    }
    phase_ = Phase::UpSegment;
    toggle_ = false;
    pos_ = 0;
    touch(now);
}

void SdoServerMachine::on_upload_segment(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    if (bool(p[0] & 0x10) != toggle_) return abort(mux_, ac::kToggleBit, out);
    Bytes chunk;
    bool last = false;
    if (auto c = pull(kSegmentData, chunk, last)) return abort(mux_, c, out);
    emit(upload_segment_response(toggle_, chunk, last), out);
    toggle_ = !toggle_;
    if (last) {
        ++counters_.transfers_completed;
        return release();
    }
    touch(now);
}

// ---- download -------------------------------------------------------------

void SdoServerMachine::initiate_download(std::span<const std::uint8_t> p, Multiplexer m, Nanos now,
                                         Outbox& out) {
    VariablePtr var;
    if (auto c = od_.lookup(m.index, m.subindex, var)) return abort(m, c, out);
    if (!writable(var->access())) return abort(m, ac::kReadOnly, out);
    const auto f = initiate_flags(p[0]);
    if (f.expedited) {
        std::size_t n = 4;
        if (f.size_indicated) n = 4u - f.unused;
        else if (var->size() && var->size() < 4) n = var->size();
        if (p.size() < 4 + n) return abort(m, ac::kCommandSpecifier, out);  // data not in the frame
        if (auto c = var->remote_write(p.subspan(4, n))) return abort(m, c, out);  // S9, S10
        emit(initiate_download_response(m), out);
        ++counters_.transfers_completed;
        return release();
    }
    limit_ = std::min(var->max_size(), cap());
    if (f.size_indicated) {
        if (p.size() < 8) return abort(m, ac::kCommandSpecifier, out);
        const std::uint32_t size = get_le32(&p[4]);
        if (auto c = var->check_size_for_write(size)) return abort(m, c, out);  // S11: before buffering
        if (size > limit_) return abort(m, ac::kOutOfMemory, out);
        indicated_ = size;
        limit_ = size;
    }
    var_ = var;
    buffer_.reserve(std::min<std::size_t>(limit_, 4096));
    emit(initiate_download_response(m), out);
    phase_ = Phase::DnSegment;
    toggle_ = false;
    touch(now);
}

void SdoServerMachine::on_download_segment(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    const auto f = segment_flags(p[0]);
    if (f.toggle != toggle_) return abort(mux_, ac::kToggleBit, out);  // S13
    const std::size_t n = kSegmentData - f.unused;
    if (p.size() < 1 + n) return abort(mux_, ac::kCommandSpecifier, out);  // S19
    if (buffer_.size() + n > limit_)  // S12: never buffer beyond the object
        return abort(mux_, indicated_ || limit_ >= var_->max_size() ? ac::kTooLong : ac::kOutOfMemory,
                     out);
    buffer_.insert(buffer_.end(), p.begin() + 1, p.begin() + 1 + static_cast<std::ptrdiff_t>(n));
    if (f.last) {
        if (indicated_ && buffer_.size() != *indicated_) return abort(mux_, ac::kTooShort, out);
        if (auto c = var_->remote_write(buffer_)) return abort(mux_, c, out);
        emit(download_segment_response(toggle_), out);
        ++counters_.transfers_completed;
        return release();
    }
    emit(download_segment_response(toggle_), out);
    toggle_ = !toggle_;
    touch(now);
}

// ---- block download -------------------------------------------------------

void SdoServerMachine::block_download_initiate(std::span<const std::uint8_t> p, Multiplexer m,
                                               Nanos now, Outbox& out) {
    VariablePtr var;
    if (auto c = od_.lookup(m.index, m.subindex, var)) return abort(m, c, out);
    if (!writable(var->access())) return abort(m, ac::kReadOnly, out);
    limit_ = std::min(var->max_size(), cap());
    if (p[0] & 0x02) {
        if (p.size() < 8) return abort(m, ac::kCommandSpecifier, out);
        const std::uint32_t size = get_le32(&p[4]);
        if (auto c = var->check_size_for_write(size)) return abort(m, c, out);  // B15
        if (size > limit_) return abort(m, ac::kOutOfMemory, out);
        indicated_ = size;
        limit_ = size;
    }
    var_ = var;
    crc_ = p[0] & 0x04;
    blksize_ = config_.block_size;
    seq_ = 0;
    buffer_.reserve(std::min<std::size_t>(limit_ + 7, 4096));
    // CRC only if the client offered it (CiA 301: used when both support it).
    // Saying yes regardless let a request whose cc bit was lost (a flipped bit)
    // commit data nobody checked; now such a client sees sc=0 and refuses.
    emit(block_download_initiate_response(m, crc_, blksize_), out);
    phase_ = Phase::BlkDnSub;
    touch(now);
    sub_deadline_ = now + static_cast<Nanos>(config_.timeout_ns * 0.7);
}

void SdoServerMachine::on_block_download(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    if (phase_ == Phase::BlkDnEnd) {
        if ((p[0] & 0xE3) != 0xC1) return abort(mux_, ac::kCommandSpecifier, out);
        if (p.size() < 3) return abort(mux_, ac::kCommandSpecifier, out);
        const std::size_t unused = (p[0] >> 2) & 7;
        if (unused > buffer_.size() || (unused == 7 && buffer_.size() > 7))
            return abort(mux_, ac::kCommandSpecifier, out);  // B10
        buffer_.resize(buffer_.size() - unused);
        if (indicated_ && buffer_.size() != *indicated_)  // B11
            return abort(mux_, buffer_.size() > *indicated_ ? ac::kTooLong : ac::kTooShort, out);
        if (buffer_.size() > limit_) return abort(mux_, ac::kTooLong, out);
        if (crc_ && crc16(buffer_) != get_le16(&p[1])) return abort(mux_, ac::kCrc, out);  // B9
        if (auto c = var_->remote_write(buffer_)) return abort(mux_, c, out);
        emit(block_download_end_response(), out);
        ++counters_.transfers_completed;
        return release();
    }
    // Sub-block segments: byte 0 is c|seqno, not a command specifier.
    if (p.size() < 8) return abort(mux_, ac::kCommandSpecifier, out);
    const std::uint8_t seqno = p[0] & 0x7F;
    const bool last = p[0] & 0x80;
    if (seqno == 0) return abort(mux_, ac::kSequenceNumber, out);  // B4: never valid
    touch(now);
    sub_deadline_ = now + static_cast<Nanos>(config_.timeout_ns * 0.7);
    if (seqno == seq_ + 1) {
        if (buffer_.size() >= limit_ && !(limit_ == 0 && buffer_.empty()))
            return abort(mux_, indicated_ ? ac::kTooLong : ac::kOutOfMemory, out);
        buffer_.insert(buffer_.end(), p.begin() + 1, p.begin() + 8);
        seq_ = seqno;
    } else if (seqno <= seq_) {
        ++counters_.ignored;  // B6: retransmitted overlap
        return;
    } else if (!(last || seqno >= blksize_)) {
        ++counters_.ignored;  // B13: a frame was lost; the ack below asks for the rest
        return;
    }
    if (last && seqno == seq_) {
        emit(block_download_ack(seq_, blksize_), out);
        seq_ = 0;
        phase_ = Phase::BlkDnEnd;
        sub_deadline_ = kNoDeadline;
    } else if (seqno >= blksize_ || last) {
        // End of a sub-block (possibly with holes): ack the in-order part.
        emit(block_download_ack(seq_, blksize_), out);
        seq_ = 0;
    }
}

// ---- block upload -------------------------------------------------------------

void SdoServerMachine::block_upload_initiate(std::span<const std::uint8_t> p, Multiplexer m,
                                             Nanos now, Outbox& out) {
    if (p.size() < 5) return abort(m, ac::kCommandSpecifier, out);
    const std::uint8_t blksize = p[4];
    if (blksize == 0 || blksize > kMaxBlockSize) return abort(m, ac::kBlockSize, out);  // B1, B2
    const std::uint8_t pst = p.size() >= 6 ? p[5] : 0;
    VariablePtr var;
    if (auto c = od_.lookup(m.index, m.subindex, var)) return abort(m, c, out);
    if (!readable(var->access())) return abort(m, ac::kWriteOnly, out);
    var_ = var;
    std::optional<std::uint32_t> size;
    if (var->chunk_read_hook()) {
        streaming_ = true;
    } else {
        if (auto c = var->remote_read(buffer_)) return abort(m, c, out);
        size = static_cast<std::uint32_t>(buffer_.size());
        if (pst != 0 && buffer_.size() <= pst) {
            // Protocol switch: small enough for the plain upload protocol.
            var_.reset();
            Bytes().swap(buffer_);
            return initiate_upload(m, now, out);
        }
    }
    crc_ = p[0] & 0x04;
    blksize_ = blksize;
    pos_ = 0;
    emit(block_upload_initiate_response(m, true, size), out);
    phase_ = Phase::BlkUpStart;
    touch(now);
}

void SdoServerMachine::send_upload_subblock(Outbox& out) {
    // Top the unacknowledged segments up to one sub-block, then send them all.
    while (pending_.size() < blksize_ && !has_last_) {
        Bytes chunk;
        bool last = false;
        if (auto c = pull(kSegmentData, chunk, last)) return abort(mux_, c, out);  // S22
        std::array<std::uint8_t, 7> seg{};
        std::copy(chunk.begin(), chunk.end(), seg.begin());
        crc_acc_ = crc16(chunk, crc_acc_);
        pending_.push_back(seg);
        if (last) {
            has_last_ = true;
            last_len_ = static_cast<std::uint8_t>(chunk.size());
        }
    }
    sent_count_ = std::min<std::size_t>(pending_.size(), blksize_);
    for (std::size_t i = 0; i < sent_count_; ++i) {
        const bool final_seg = has_last_ && i + 1 == pending_.size();
        emit(block_segment(static_cast<std::uint8_t>(i + 1), pending_[i], final_seg), out);
    }
    phase_ = Phase::BlkUpSub;
}

void SdoServerMachine::on_block_upload(std::span<const std::uint8_t> p, Nanos now, Outbox& out) {
    if (phase_ == Phase::BlkUpStart) {
        if (p[0] != 0xA3) return abort(mux_, ac::kCommandSpecifier, out);
        touch(now);
        return send_upload_subblock(out);
    }
    if (phase_ == Phase::BlkUpEnd) {
        if ((p[0] & 0xE3) != 0xA1) return abort(mux_, ac::kCommandSpecifier, out);
        ++counters_.transfers_completed;
        return release();
    }
    // BlkUpSub: waiting for the client's acknowledgement.
    if ((p[0] & 0xE3) != 0xA2) return abort(mux_, ac::kCommandSpecifier, out);
    if (p.size() < 3) return abort(mux_, ac::kCommandSpecifier, out);
    const std::uint8_t ackseq = p[1], blksize = p[2];
    if (ackseq > sent_count_) return abort(mux_, ac::kSequenceNumber, out);  // B3
    if (blksize == 0 || blksize > kMaxBlockSize) return abort(mux_, ac::kBlockSize, out);  // B8
    touch(now);
    pending_.erase(pending_.begin(), pending_.begin() + ackseq);
    blksize_ = blksize;
    if (pending_.empty() && has_last_) {
        emit(block_upload_end(static_cast<std::uint8_t>(kSegmentData - last_len_), crc_acc_), out);
        phase_ = Phase::BlkUpEnd;
        return;
    }
    send_upload_subblock(out);
}

void SdoServerMachine::on_timer(Nanos now, Outbox& out) {
    if (phase_ == Phase::Idle) return;
    if (now >= deadline_) {  // S16
        ++counters_.timeouts;
        return abort(mux_, ac::kTimeout, out);
    }
    if (phase_ == Phase::BlkDnSub && now >= sub_deadline_) {
        // B12: the client stalled mid sub-block; ack what arrived so it resends the rest.
        emit(block_download_ack(seq_, blksize_), out);
        seq_ = 0;
        sub_deadline_ = kNoDeadline;
    }
}

}  // namespace motorbus::canopen

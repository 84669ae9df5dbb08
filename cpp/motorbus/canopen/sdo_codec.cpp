#include "motorbus/canopen/sdo_codec.hpp"

#include <algorithm>
#include <cstdio>

#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/datatypes.hpp"

namespace motorbus::canopen::sdo {

namespace {
Payload with_mux(std::uint8_t b0, Multiplexer m) {
    Payload p{};
    p[0] = b0;
    put_le16(&p[1], m.index);
    p[3] = m.subindex;
    return p;
}
std::size_t clamp_copy(std::uint8_t* dst, std::span<const std::uint8_t> src, std::size_t max) {
    const std::size_t n = std::min(src.size(), max);
    std::copy_n(src.begin(), n, dst);
    return n;
}
// Initiate frames share one layout in both directions; only the command
// specifier (0x20 download request, 0x40 upload response) differs.
// Expedited: e=1, s=1, n = 4 - bytes of data in byte 4-7.
Payload initiate_expedited(std::uint8_t cs, Multiplexer m, std::span<const std::uint8_t> data) {
    const std::size_t n = std::min<std::size_t>(data.size(), 4);
    Payload p = with_mux(static_cast<std::uint8_t>(cs | ((4 - n) << 2) | 0x03), m);
    clamp_copy(&p[4], data, 4);
    return p;
}
// Segmented: e=0, s=1 with the size in bytes 4-7 when it is known.
Payload initiate_segmented(std::uint8_t cs, Multiplexer m, std::optional<std::uint32_t> size) {
    Payload p = with_mux(static_cast<std::uint8_t>(size ? cs | 0x01 : cs), m);
    if (size) put_le32(&p[4], *size);
    return p;
}
}  // namespace

std::optional<Multiplexer> multiplexer_of(std::span<const std::uint8_t> p) {
    if (p.size() < 4) return std::nullopt;
    return Multiplexer{get_le16(&p[1]), p[3]};
}

Payload initiate_download_expedited(Multiplexer m, std::span<const std::uint8_t> data) {
    return initiate_expedited(0x20, m, data);
}

Payload initiate_download_segmented(Multiplexer m, std::optional<std::uint32_t> size) {
    return initiate_segmented(0x20, m, size);
}

Payload initiate_download_response(Multiplexer m) { return with_mux(0x60, m); }

Payload download_segment(bool toggle, std::span<const std::uint8_t> data, bool last) {
    Payload p{};
    const std::size_t n = clamp_copy(&p[1], data, 7);
    p[0] = static_cast<std::uint8_t>((toggle ? 0x10 : 0) | ((7 - n) << 1) | (last ? 1 : 0));
    return p;
}

Payload download_segment_response(bool toggle) {
    Payload p{};
    p[0] = static_cast<std::uint8_t>(0x20 | (toggle ? 0x10 : 0));
    return p;
}

Payload initiate_upload(Multiplexer m) { return with_mux(0x40, m); }

Payload initiate_upload_expedited_response(Multiplexer m, std::span<const std::uint8_t> data) {
    return initiate_expedited(0x40, m, data);
}

Payload initiate_upload_segmented_response(Multiplexer m, std::optional<std::uint32_t> size) {
    return initiate_segmented(0x40, m, size);
}

Payload upload_segment(bool toggle) {
    Payload p{};
    p[0] = static_cast<std::uint8_t>(0x60 | (toggle ? 0x10 : 0));
    return p;
}

Payload upload_segment_response(bool toggle, std::span<const std::uint8_t> data, bool last) {
    Payload p{};
    const std::size_t n = clamp_copy(&p[1], data, 7);
    p[0] = static_cast<std::uint8_t>((toggle ? 0x10 : 0) | ((7 - n) << 1) | (last ? 1 : 0));
    return p;
}

Payload abort_transfer(Multiplexer m, std::uint32_t code) {
    Payload p = with_mux(0x80, m);
    put_le32(&p[4], code);
    return p;
}

Payload block_download_initiate(Multiplexer m, bool crc, std::optional<std::uint32_t> size) {
    Payload p = with_mux(static_cast<std::uint8_t>(0xC0 | (crc ? 0x04 : 0) | (size ? 0x02 : 0)), m);
    if (size) put_le32(&p[4], *size);
    return p;
}

Payload block_download_initiate_response(Multiplexer m, bool crc, std::uint8_t blksize) {
    Payload p = with_mux(static_cast<std::uint8_t>(0xA0 | (crc ? 0x04 : 0)), m);
    p[4] = blksize;
    return p;
}

Payload block_segment(std::uint8_t seqno, std::span<const std::uint8_t> data, bool last) {
    Payload p{};
    p[0] = static_cast<std::uint8_t>((last ? 0x80 : 0) | (seqno & 0x7F));
    clamp_copy(&p[1], data, 7);
    return p;
}

Payload block_download_ack(std::uint8_t ackseq, std::uint8_t blksize) {
    Payload p{};
    p[0] = 0xA2;
    p[1] = ackseq;
    p[2] = blksize;
    return p;
}

Payload block_download_end(std::uint8_t unused_in_last, std::uint16_t crc) {
    Payload p{};
    p[0] = static_cast<std::uint8_t>(0xC1 | ((unused_in_last & 7) << 2));
    put_le16(&p[1], crc);
    return p;
}

Payload block_download_end_response() {
    Payload p{};
    p[0] = 0xA1;
    return p;
}

Payload block_upload_initiate(Multiplexer m, bool crc, std::uint8_t blksize, std::uint8_t pst) {
    Payload p = with_mux(static_cast<std::uint8_t>(0xA0 | (crc ? 0x04 : 0)), m);
    p[4] = blksize;
    p[5] = pst;
    return p;
}

Payload block_upload_initiate_response(Multiplexer m, bool crc, std::optional<std::uint32_t> size) {
    Payload p = with_mux(static_cast<std::uint8_t>(0xC0 | (crc ? 0x04 : 0) | (size ? 0x02 : 0)), m);
    if (size) put_le32(&p[4], *size);
    return p;
}

Payload block_upload_start() {
    Payload p{};
    p[0] = 0xA3;
    return p;
}

// Block acknowledgements and end frames have one layout in both directions
// in CiA 301: the upload forms are the download ones.
Payload block_upload_ack(std::uint8_t ackseq, std::uint8_t blksize) {
    return block_download_ack(ackseq, blksize);
}

Payload block_upload_end(std::uint8_t unused_in_last, std::uint16_t crc) {
    return block_download_end(unused_in_last, crc);
}

Payload block_upload_end_response() { return block_download_end_response(); }

std::uint32_t abort_code_of(std::span<const std::uint8_t> p) {
    if (p.size() < 8) return abort_code::kGeneral;
    const std::uint32_t c = get_le32(&p[4]);
    return c ? c : abort_code::kGeneral;
}

namespace {
struct CrcTable {
    std::uint16_t t[256];
    constexpr CrcTable() : t{} {
        for (unsigned i = 0; i < 256; ++i) {
            std::uint16_t c = static_cast<std::uint16_t>(i << 8);
            for (int b = 0; b < 8; ++b)
                c = static_cast<std::uint16_t>(c & 0x8000 ? (c << 1) ^ 0x1021 : c << 1);
            t[i] = c;
        }
    }
};
constexpr CrcTable kCrc{};
}  // namespace

std::uint16_t crc16(std::span<const std::uint8_t> data, std::uint16_t crc) {
    for (auto b : data)
        crc = static_cast<std::uint16_t>((crc << 8) ^ kCrc.t[((crc >> 8) ^ b) & 0xFF]);
    return crc;
}

namespace {
std::string mux_text(std::span<const std::uint8_t> p) {
    auto m = multiplexer_of(p);
    if (!m) return " (short)";
    char buf[24];
    std::snprintf(buf, sizeof buf, " 0x%04X:%02X", m->index, m->subindex);
    return buf;
}
}  // namespace

std::string describe_request(std::span<const std::uint8_t> p) {
    if (p.empty()) return "empty SDO request";
    switch (ccs_of(p[0])) {
        case Ccs::DownloadSegment: return "download segment";
        case Ccs::InitiateDownload: return "initiate download" + mux_text(p);
        case Ccs::InitiateUpload: return "initiate upload" + mux_text(p);
        case Ccs::UploadSegment: return "upload segment request";
        case Ccs::Abort: return "abort" + mux_text(p) + " " + describe_abort(abort_code_of(p));
        case Ccs::BlockUpload: return "block upload";
        case Ccs::BlockDownload: return "block download";
        default: return "invalid client command specifier";
    }
}

std::string describe_response(std::span<const std::uint8_t> p) {
    if (p.empty()) return "empty SDO response";
    switch (scs_of(p[0])) {
        case Scs::UploadSegment: return "upload segment";
        case Scs::DownloadSegment: return "download segment response";
        case Scs::InitiateUpload: return "initiate upload response" + mux_text(p);
        case Scs::InitiateDownload: return "initiate download response" + mux_text(p);
        case Scs::Abort: return "abort" + mux_text(p) + " " + describe_abort(abort_code_of(p));
        case Scs::BlockDownload: return "block download response";
        case Scs::BlockUpload: return "block upload response";
        default: return "invalid server command specifier";
    }
}

}  // namespace motorbus::canopen::sdo

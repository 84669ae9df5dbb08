// Pure SDO codecs (CiA 301 §7.2.4.3): one encoder per command, one decoder
// that classifies any 0..8-byte payload.  No state, no I/O, no allocation.
//
// Byte 0 carries the command specifier in bits 7..5: the client's (CCS) on
// 0x600+n, the server's (SCS) on 0x580+n.  The same bit pattern means
// different things in the two directions, hence two decoders.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace motorbus::canopen::sdo {

using Payload = std::array<std::uint8_t, 8>;  // SDO frames are always DLC 8 on the wire

constexpr std::uint16_t kDefaultRequestBase = 0x600;   // client -> server, + node-id
constexpr std::uint16_t kDefaultResponseBase = 0x580;  // server -> client, + node-id
constexpr std::uint8_t kMaxBlockSize = 127;
constexpr std::size_t kSegmentData = 7;

// Client command specifiers (request direction).
enum class Ccs : std::uint8_t {
    DownloadSegment = 0,
    InitiateDownload = 1,
    InitiateUpload = 2,
    UploadSegment = 3,
    Abort = 4,
    BlockUpload = 5,
    BlockDownload = 6,
    Invalid = 7,
};
// Server command specifiers (response direction).
enum class Scs : std::uint8_t {
    UploadSegment = 0,
    DownloadSegment = 1,
    InitiateUpload = 2,
    InitiateDownload = 3,
    Abort = 4,
    BlockDownload = 5,
    BlockUpload = 6,
    Invalid = 7,
};
// Sub-commands of the block services (bits 1..0 of byte 0, or bit 0 for server block download).
enum class BlockCs : std::uint8_t { Initiate = 0, End = 1, Ack = 2, Start = 3 };

inline Ccs ccs_of(std::uint8_t b0) { return static_cast<Ccs>(b0 >> 5); }
inline Scs scs_of(std::uint8_t b0) { return static_cast<Scs>(b0 >> 5); }

// ---- fields shared by many commands ----------------------------------------
struct Multiplexer {
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    bool operator==(const Multiplexer&) const = default;
};
// Bytes 1..3; nullopt when the payload is shorter than 4 bytes.
std::optional<Multiplexer> multiplexer_of(std::span<const std::uint8_t> p);

// ---- encoders (all return 8 bytes, unused bytes zero) ------------------------
// Expedited download of 1..4 bytes (size indicated); segmented initiate when
// `data` is empty and `size` is given (size indicated, e=0).
Payload initiate_download_expedited(Multiplexer m, std::span<const std::uint8_t> data);
Payload initiate_download_segmented(Multiplexer m, std::optional<std::uint32_t> size);
Payload initiate_download_response(Multiplexer m);
Payload download_segment(bool toggle, std::span<const std::uint8_t> data, bool last);
Payload download_segment_response(bool toggle);
Payload initiate_upload(Multiplexer m);
// Expedited upload response with 1..4 bytes (size indicated).
Payload initiate_upload_expedited_response(Multiplexer m, std::span<const std::uint8_t> data);
Payload initiate_upload_segmented_response(Multiplexer m, std::optional<std::uint32_t> size);
Payload upload_segment(bool toggle);
Payload upload_segment_response(bool toggle, std::span<const std::uint8_t> data, bool last);
Payload abort_transfer(Multiplexer m, std::uint32_t code);

Payload block_download_initiate(Multiplexer m, bool crc, std::optional<std::uint32_t> size);
Payload block_download_initiate_response(Multiplexer m, bool crc, std::uint8_t blksize);
// One sub-block segment (either direction): seqno 1..127, 7 data bytes, `last` = c bit.
Payload block_segment(std::uint8_t seqno, std::span<const std::uint8_t> data, bool last);
Payload block_download_ack(std::uint8_t ackseq, std::uint8_t blksize);  // server -> client
Payload block_download_end(std::uint8_t unused_in_last, std::uint16_t crc);  // client -> server
Payload block_download_end_response();

Payload block_upload_initiate(Multiplexer m, bool crc, std::uint8_t blksize, std::uint8_t pst);
Payload block_upload_initiate_response(Multiplexer m, bool crc, std::optional<std::uint32_t> size);
Payload block_upload_start();
Payload block_upload_ack(std::uint8_t ackseq, std::uint8_t blksize);  // client -> server
Payload block_upload_end(std::uint8_t unused_in_last, std::uint16_t crc);  // server -> client
Payload block_upload_end_response();

// ---- decoders ---------------------------------------------------------------
// Bits of the initiate byte.
struct InitiateFlags {
    bool expedited = false;       // e
    bool size_indicated = false;  // s
    std::uint8_t unused = 0;      // n: bytes of the 4 that carry no data (valid when e && s)
};
inline InitiateFlags initiate_flags(std::uint8_t b0) {
    return {bool(b0 & 0x02), bool(b0 & 0x01), static_cast<std::uint8_t>((b0 >> 2) & 3)};
}
// Segment byte: toggle bit 4, n bits 3..1, c bit 0.
struct SegmentFlags {
    bool toggle = false;
    std::uint8_t unused = 0;  // 0..7 bytes without data
    bool last = false;
};
inline SegmentFlags segment_flags(std::uint8_t b0) {
    return {bool(b0 & 0x10), static_cast<std::uint8_t>((b0 >> 1) & 7), bool(b0 & 0x01)};
}
// Abort code from an abort payload.  CiA 301 lets no abort carry 0 or be
// short, so a code that is missing (DLC < 8) or zero reads as 0x08000000.
std::uint32_t abort_code_of(std::span<const std::uint8_t> p);

// CRC-16/XMODEM (poly 0x1021, init 0, no reflection), the CRC of block transfers.
std::uint16_t crc16(std::span<const std::uint8_t> data, std::uint16_t crc = 0);

// Human-readable summary of a payload in either direction ("initiate upload 0x6001:00").
std::string describe_request(std::span<const std::uint8_t> p);
std::string describe_response(std::span<const std::uint8_t> p);

}  // namespace motorbus::canopen::sdo

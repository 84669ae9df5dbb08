// socketcand wire format (linux-can/socketcand doc/protocol.md): ASCII elements
// `< word arg ... >` on a TCP stream, in both directions.
//
// Pure codec: bytes in, elements out; frames in, bytes out.  No sockets here.
//
// The parser is incremental and never lets one bad element poison the stream
// (python-can keeps a bad element in its buffer and fails every later recv):
//   * bytes outside `< ... >` are discarded and counted (K1, K3),
//   * an element longer than `max_element` is abandoned and the parser resyncs
//     at the next `<` (K2); so is an element interrupted by a new `<`,
//   * a complete but malformed element (bad hex, bad timestamp, odd data hex,
//     too much data, id out of range) is reported through on_error, counted,
//     and parsing continues with the next element (K5, K6, K7, K10).
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "motorbus/can/frame.hpp"

namespace motorbus::can::socketcand {

enum class ElementKind : std::uint8_t {
    // server -> client
    Hi,          // < hi >
    Ok,          // < ok >
    Frame,       // < frame ID SEC.USEC DATA >          (classic data frame)
    FdFrame,     // < fdframe ID FLAGS SEC.USEC DATA >  (CAN FD frame)
    Rtr,         // < rtr ID SEC.USEC DLC >             (remote frame)
    ErrorFrame,  // < error CLASS SEC.USEC >            (bus error frame)
    ErrorText,   // < error any text >                  (server refused a command)
    // client -> server
    Open,        // < open CHANNEL >
    RawMode,     // < rawmode >
    BcmMode,     // < bcmmode >
    ControlMode, // < controlmode >
    IsotpMode,   // < isotpmode >
    Send,        // < send ID DLC B0 .. >
    SendRtr,     // < sendrtr ID DLC >
    FdSend,      // < fdsend ID FLAGS LEN B0 .. >
    // both directions
    Echo,        // < echo >
    Unknown,     // a well-formed element whose command we do not know (text = command word)
};
const char* to_string(ElementKind k);

struct Element {
    ElementKind kind = ElementKind::Unknown;
    can::Frame frame;        // Frame, FdFrame, Rtr, ErrorFrame (id = error class), Send*, FdSend
    Nanos remote_time_ns = 0;  // the SEC.USEC of frame/rtr/error elements, as nanoseconds
    std::string text;        // Open: channel; ErrorText: message; Unknown: command word
};

// Why an element was refused.  `element` is the offending text (bounded).
struct ParseError {
    std::string reason;
    std::string_view element;
};

struct ParserStats {
    std::uint64_t elements = 0;          // well-formed elements delivered
    std::uint64_t bad_elements = 0;      // complete elements refused (K5/K6/K7/K10)
    std::uint64_t overlong = 0;          // elements abandoned at the length cap (K2)
    std::uint64_t interrupted = 0;       // elements cut short by a new '<'
    std::uint64_t discarded_bytes = 0;   // non-blank bytes outside any element (K1, K3)
};

// Longest element we accept.  The longest one we understand is an fdsend with
// 64 space-separated bytes (~230 chars); socketcand itself allows 8290, python-can 200.
constexpr std::size_t kDefaultMaxElement = 1024;
constexpr std::size_t kMaxChannelName = 16;  // protocol.md: "at maximum 16 characters"
// The range accepted for a max_element option: the longest frame element
// (`< frame 1FFFFFFF 4294967295.999999 0011223344556677 >`, 55 bytes) must fit.
constexpr std::size_t kMinMaxElement = 64;
constexpr std::size_t kMaxMaxElement = 65535;
// A channel (bus) name a socketcand peer can open: 1-16 printable characters, no
// blank and no < or > (they would end the `< open name >` element).  Throws
// InvalidArgument naming `field`.
void check_channel_name(const std::string& channel, const char* field);
// A max_element option in [kMinMaxElement, kMaxMaxElement]; InvalidArgument otherwise.
void check_max_element(std::size_t max_element);

// Parses one complete element, `<` through `>` inclusive.  Returns the reason
// on failure (the element is then empty/undefined).
const char* parse_element(std::string_view element, Element& out);

class ElementParser {
public:
    explicit ElementParser(std::size_t max_element = kDefaultMaxElement);

    // Feeds stream bytes.  For each complete element calls on_element(const
    // Element&) or on_error(const ParseError&).  Never throws on any input.
    template <class OnElement, class OnError>
    void feed(std::span<const char> bytes, OnElement&& on_element, OnError&& on_error) {
        auto deliver = [&](std::string_view text) {
            const char* why = parse_element(text, element_);
            if (why) {
                ++stats_.bad_elements;
                on_error(ParseError{why, text});
            } else {
                ++stats_.elements;
                on_element(static_cast<const Element&>(element_));
            }
        };
        std::size_t i = 0;
        while (i < bytes.size()) {
            if (in_element_) {  // the rest of an element that began in an earlier chunk
                i += scan(bytes.subspan(i));
                if (ready_) {
                    ready_ = false;
                    deliver(buffer_);
                    buffer_.clear();
                }
                continue;
            }
            // Whole elements inside this chunk are parsed where they lie, without a copy.
            Next next = find_element(bytes, i);
            i = next.resume;
            if (next.complete) deliver(next.element);
        }
    }
    // True while a `<` has been seen and its `>` has not (for element timeouts, K14).
    bool mid_element() const { return in_element_; }
    const ParserStats& stats() const { return stats_; }
    // Drops any partial element (e.g. after a timeout) without counting it.
    void reset();

private:
    // Consumes bytes up to and including the end of one element; sets ready_.
    std::size_t scan(std::span<const char> bytes);
    struct Next {
        std::size_t resume;        // where to continue in the chunk
        bool complete;             // `element` is a whole element to parse
        std::string_view element;
    };
    // Outside an element: skips noise (K1, K3), then takes one element that
    // ends inside the chunk, or buffers its beginning, or abandons it (K2).
    Next find_element(std::span<const char> bytes, std::size_t from);

    std::size_t max_element_;
    std::string buffer_;
    Element element_;
    bool in_element_ = false;
    bool skipping_ = false;  // after an overlong element: discard until the next '<'
    bool ready_ = false;
    ParserStats stats_;
};

// ---- encoders (append to `out`; never throw for a valid Frame) ---------------
// Server side.  `time_ns` is written as SEC.USEC (socketcand uses wall-clock time).
// Data is written as contiguous hex, like socketcand, which python-can requires.
void encode_frame(const can::Frame& f, Nanos time_ns, std::string& out);
void encode_error_text(std::string_view message, std::string& out);  // `<`/`>` are replaced
// Client side: < send ... >, < sendrtr ... > or < fdsend ... >.
void encode_send(const can::Frame& f, std::string& out);
// Argument-less commands: < hi >, < ok >, < echo >, < rawmode >, ...
void encode_command(ElementKind k, std::string& out);
void encode_open(std::string_view channel, std::string& out);

}  // namespace motorbus::can::socketcand

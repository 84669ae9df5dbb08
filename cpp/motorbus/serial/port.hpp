// Byte ports (termios serial, pty) and the line link that frames ASCII requests
// and replies on them.  CONTRACT: this header is the interface the drive
// clients and simulators build on; the serial work implements it.
#pragma once
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace motorbus::serial {

using Duration = std::chrono::nanoseconds;

// A bidirectional byte stream.  Thread-safe for one reader + one writer.
class Port {
public:
    virtual ~Port() = default;
    // Writes all bytes (blocking); throws LinkDown when the peer is gone.
    virtual void write(std::span<const std::uint8_t> bytes) = 0;
    // Reads what is available, waiting up to `timeout` for the first byte.
    // Returns 0 on timeout; throws LinkDown on EOF/EIO.
    virtual std::size_t read(std::span<std::uint8_t> buf, Duration timeout) = 0;
    // Discards unread input (stale bytes, late replies).
    virtual void flush_input() = 0;
    virtual void close() = 0;
    virtual std::string name() const = 0;
};

struct LineOptions {
    std::string request_terminator = "\r";            // appended to each request
    std::vector<std::string> reply_terminators = {"\r\n"};  // any of these ends a reply
    std::size_t max_line = 256;                       // longer replies: ReplyTooLong (ProtocolError)
    Duration reply_timeout = std::chrono::milliseconds(500);
    bool flush_before_request = true;                 // drop stale bytes before each request
    bool echo_suppression = false;                    // RS-485 adapters that echo our own bytes
    Duration turnaround = Duration::zero();           // RS-485: wait after the request before listening
};

// Request/reply framing on a Port.  One transaction at a time (internally serialized).
class LineLink {
public:
    LineLink(std::shared_ptr<Port> port, LineOptions options);
    ~LineLink();
    // Sends `request` + terminator, returns the reply without its terminator.
    // Throws TimeoutError (partial reply discarded) or ProtocolError.
    std::string transact(std::string_view request, std::optional<Duration> timeout = {});
    // Sends without waiting for a reply (broadcasts).
    void send(std::string_view request);
    // Reads one reply line (e.g. unsolicited), nullopt on timeout.
    std::optional<std::string> read_line(Duration timeout);
    const LineOptions& options() const;
    Port& port();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace motorbus::serial

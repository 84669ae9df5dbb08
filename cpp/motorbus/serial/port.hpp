// Byte ports (termios serial, pty) and the line link that frames ASCII requests
// and replies on them.  CONTRACT: this header is the interface the drive
// clients and simulators build on; the serial work implements it.
#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "motorbus/errors.hpp"
#include "motorbus/runtime/completions.hpp"

namespace motorbus::serial {

using Duration = std::chrono::nanoseconds;

// The port is already open elsewhere (another process, or another TtyPort in
// this one): ports are opened exclusively (flock + TIOCEXCL), so two users
// never read each other's replies.  The message names the port and, where the
// kernel tells (/proc/locks), the holder's PID.  A LinkDown, so Python sees
// motorbus.LinkDown (a ConnectionError).
struct PortBusy : LinkDown {
    PortBusy(const std::string& what, int holder) : LinkDown(what), holder_pid(holder) {}
    int holder_pid;  // 0 when unknown
};

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
    // Blocks until written bytes have left the transmitter (tcdrain on a UART).
    // RS-485 turn-around is timed from here.  No-op where it means nothing (pty).
    virtual void drain() {}
};

// A termios file descriptor (a UART, a USB-serial adapter, a pty side) in raw
// mode: no echo, no CR/LF translation, no flow control, 8N1.
// read() and write() may run concurrently from two threads; close() from any
// thread wakes both and makes them throw ClosedError.
class TtyPort : public Port {
public:
    // Opens `path` and configures it.  `baud` = 0 keeps the current speed.
    // Standard rates use the B* constants; any other rate uses termios2/BOTHER
    // (InvalidArgument if the driver refuses it).
    TtyPort(const std::string& path, unsigned baud);
    // Takes ownership of an already open descriptor (e.g. a pty master).
    TtyPort(int fd, std::string name, bool make_raw);
    ~TtyPort() override;
    TtyPort(const TtyPort&) = delete;
    TtyPort& operator=(const TtyPort&) = delete;

    void write(std::span<const std::uint8_t> bytes) override;
    std::size_t read(std::span<std::uint8_t> buf, Duration timeout) override;
    void flush_input() override;
    void close() override;
    std::string name() const override;
    void drain() override;

    // Changes the line speed of an open port (see the constructor for rules).
    void set_baud(unsigned baud);
    // The speed reported by the driver (0 if unknown).
    unsigned baud() const;
    // Bound on a blocked write (peer not reading); negative = wait forever.
    void set_write_timeout(Duration timeout);
    bool is_open() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// A pseudo-terminal pair for tests and simulators.  The master side is a Port
// (ours); the slave path (/dev/pts/N) is for a peer: pyserial, python-can's
// slcan interface, or another TtyPort.  Both sides are raw, so bytes pass
// unchanged.  The pair keeps its own slave descriptor open so the master never
// sees a spurious hang-up while peers open and close the slave.
class PtyPair {
public:
    PtyPair();
    ~PtyPair();
    PtyPair(const PtyPair&) = delete;
    PtyPair& operator=(const PtyPair&) = delete;

    std::shared_ptr<Port> port() const;          // the master side
    std::shared_ptr<TtyPort> master() const;     // same, typed
    const std::string& slave_path() const;
    // Opens the slave as a TtyPort (a C++ peer for tests).
    std::shared_ptr<TtyPort> open_slave(unsigned baud = 0) const;
    // Drops the pair's own hold on the slave: once every peer has closed it,
    // the master reads EIO -> LinkDown (models a USB adapter being unplugged).
    void release_slave();
    void close();

private:
    std::shared_ptr<TtyPort> master_;
    std::string slave_path_;
    int slave_fd_ = -1;
};

// Opens a serial device by path at `baud` (0 = keep the current speed), or a
// line behind a serial gateway: socket://host:port (raw TCP; `baud` ignored,
// the gateway sets the line) or rfc2217://host:port (`baud` sent to the gateway,
// 0 = keep its rate).  See remote_port.hpp for the rules and errors.
std::shared_ptr<Port> open_port(const std::string& path, unsigned baud);

// The reply exceeded LineOptions::max_line; the excess was discarded up to the
// next terminator.  `bytes` holds the first bytes of the offending line.
struct ReplyTooLong : ProtocolError {
    using ProtocolError::ProtocolError;
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

// What a LineLink has seen since it was created.
struct LineCounters {
    std::uint64_t bytes_in = 0;        // read from the port (echo and stale bytes included)
    std::uint64_t bytes_out = 0;       // written, terminators included
    std::uint64_t requests = 0;        // transact() + send() calls that wrote
    std::uint64_t replies = 0;         // lines returned by transact()/read_line()
    std::uint64_t timeouts = 0;        // transact() calls that got no complete reply
    std::uint64_t stale_bytes = 0;     // discarded by the flush before a request
    std::uint64_t overlong_lines = 0;  // replies longer than max_line (ReplyTooLong)
    std::uint64_t echo_bytes = 0;      // own bytes skipped by echo suppression
    std::uint64_t echo_mismatches = 0; // expected echo did not arrive as sent
};

// Request/reply framing on a Port.  One transaction at a time (internally serialized).
class LineLink {
public:
    LineLink(std::shared_ptr<Port> port, LineOptions options);
    ~LineLink();
    // Sends `request` + terminator, returns the reply without its terminator.
    // Throws TimeoutError (partial reply discarded) or ProtocolError.
    std::string transact(std::string_view request, std::optional<Duration> timeout = {});
    // Completion-based transact() for event loops: returns at once; the transaction
    // runs on the link's own worker thread (one per link, started on first use, in
    // the FIFO order of every transaction on the link) and ends with
    // done->push(token, reply as std::vector<std::uint8_t>) or done->fail(token,
    // the error transact() throws).  Jobs still queued when the link is destroyed
    // fail with ClosedError.
    void transact_async(std::string request, std::optional<Duration> timeout, std::shared_ptr<Completions> done,
                        std::uint64_t token);
    // Sends without waiting for a reply (broadcasts).
    void send(std::string_view request);
    // Reads one reply line (e.g. unsolicited), nullopt on timeout.
    std::optional<std::string> read_line(Duration timeout);
    const LineOptions& options() const;
    Port& port();
    LineCounters counters() const;
    // A protocol trace: called with '>' and each request written (without its
    // terminator), '<' and each reply line read, '!' and a note when a request gets
    // no reply in time.  Runs on the transacting thread inside the link's lock (it
    // must not use this link); an empty function turns it off.
    using Trace = std::function<void(char direction, const std::string& text)>;
    void set_trace(Trace trace);

private:
    struct Impl;
    struct Worker;
    std::unique_ptr<Impl> impl_;
    std::unique_ptr<Worker> worker_;   // transact_async's thread, made on first use
};

}  // namespace motorbus::serial

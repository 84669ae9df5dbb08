// Serial lines reached over TCP, as served by ser2net and other serial
// gateways: raw TCP (socket://host:port) and Telnet with the RFC 2217
// COM-PORT-OPTION (rfc2217://host:port).  open_port() (port.hpp) hands these
// URLs here, so every user of a line path (vendor open_line, LineLink, a bench
// file's `port = ...`) takes them unchanged.
#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "motorbus/serial/port.hpp"

namespace motorbus::serial {

struct RemoteOptions {
    // Bound on the TCP connect (an unreachable gateway must not hang open_port).
    Duration connect_timeout = std::chrono::seconds(5);
    // Bound on each RFC 2217 exchange: the option negotiation and the server's
    // answer to SET-BAUDRATE / data size / parity / stop size.
    Duration ack_timeout = std::chrono::seconds(3);
};

// A parsed line URL.
struct RemoteAddress {
    enum class Scheme : std::uint8_t { Socket, Rfc2217 };
    Scheme scheme;
    std::string host;  // without the brackets of an IPv6 literal
    std::uint16_t port;
    std::string url;   // as given, for messages and Port::name()
};

// nullopt when `path` is not a URL (no "scheme://": a device path).  A URL
// with an unknown scheme or a malformed host:port throws InvalidArgument naming it.
std::optional<RemoteAddress> parse_remote_url(const std::string& path);

// Raw TCP: the bytes of the serial line, unchanged, both ways (ser2net's
// `accepter: tcp,...`).  The gateway owns the line settings (its connector's
// `9600n81`), so there is no baud here: open_port ignores its `baud` for
// socket:// URLs.  TCP_NODELAY is set (requests are short and latency-bound)
// and TCP keepalive probes a silent peer.
//
// Errors: connection refused / unreachable -> LinkDown naming host:port;
// connect timeout -> TimeoutError; the connection dropped (EOF, ECONNRESET,
// EPIPE) -> LinkDown naming the peer, from read() and write(), never a hang;
// close() from any thread wakes a blocked read()/write() with ClosedError.
// Ports are not opened exclusively: the gateway decides who may connect.
class TcpPort : public Port {
public:
    TcpPort(const RemoteAddress& address, RemoteOptions options = {});
    ~TcpPort() override;
    TcpPort(const TcpPort&) = delete;
    TcpPort& operator=(const TcpPort&) = delete;

    void write(std::span<const std::uint8_t> bytes) override;
    std::size_t read(std::span<std::uint8_t> buf, Duration timeout) override;
    // Discards what is buffered here and what has already arrived on the socket.
    void flush_input() override;
    void close() override;
    std::string name() const override;  // the URL
    bool is_open() const;
    // "host:port", as used in error messages.
    const std::string& peer() const;

protected:
    // Bytes read from the socket, called with the state lock held: appends the
    // line's data to `data` and bytes to send back to `answer`.  Raw: all data.
    virtual void on_received(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& data,
                             std::vector<std::uint8_t>& answer);
    // What write() puts on the wire for `bytes`.  Raw: the bytes themselves.
    virtual std::vector<std::uint8_t> encode(std::span<const std::uint8_t> bytes);
    // Sends bytes as they are (protocol bytes: no encode()).
    void send_raw(std::span<const std::uint8_t> bytes);
    // Reads the socket (or waits for the thread that does) until `done()` holds
    // (evaluated with the state lock held) or `timeout` passes: false on timeout.
    // Throws LinkDown / ClosedError like read().
    bool wait_until(const std::function<bool()>& done, Duration timeout);
    // Runs `f` with the state lock held (the lock on_received runs under).
    void locked(const std::function<void()>& f);
    const RemoteOptions& options() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Telnet (RFC 854) with the RFC 2217 COM-PORT-OPTION (ser2net's
// `accepter: telnet(rfc2217),tcp,...`): the line's baud and 8N1 are sent to the
// gateway, which sets them on its serial port.  At open: WILL/DO BINARY, WILL/DO
// SUPPRESS-GO-AHEAD, WILL COM-PORT-OPTION, then SET-BAUDRATE, SET-DATASIZE 8,
// SET-PARITY NONE, SET-STOPSIZE 1, each waited for (ack_timeout).  baud 0 asks
// the server for its current rate instead of setting one.  Telnet commands in
// the stream are answered and stripped; a 0xFF data byte travels as IAC IAC.
//
// Errors, besides TcpPort's: no answer to the negotiation (e.g. a raw TCP port
// given as rfc2217://) -> TimeoutError; the server refuses COM-PORT-OPTION ->
// ProtocolError; the server sets another rate than asked -> InvalidArgument.
class Rfc2217Port : public TcpPort {
public:
    Rfc2217Port(const RemoteAddress& address, unsigned baud, RemoteOptions options = {});
    ~Rfc2217Port() override;

    // SET-BAUDRATE; returns once the server acknowledged it.
    void set_baud(unsigned baud);
    // The rate the server last acknowledged.
    unsigned baud() const;

protected:
    void on_received(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& data,
                     std::vector<std::uint8_t>& answer) override;
    std::vector<std::uint8_t> encode(std::span<const std::uint8_t> bytes) override;

private:
    struct State;
    std::unique_ptr<State> st_;
    // Sends one COM-PORT command and waits for the server's answer to it.
    std::vector<std::uint8_t> exchange(std::uint8_t cmd, const std::vector<std::uint8_t>& wire);
};

// Opens a line URL (socket:// or rfc2217://) at `baud`.
std::shared_ptr<Port> open_remote_port(const RemoteAddress& address, unsigned baud, RemoteOptions options = {});

}  // namespace motorbus::serial

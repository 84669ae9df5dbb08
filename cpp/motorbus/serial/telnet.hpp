// Telnet (RFC 854/855) stream parsing and the RFC 2217 COM-PORT-OPTION codec,
// as pure code: bytes in -> data bytes, events and answers out.  No sockets
// here, so the parser is unit-tested and fuzzed on its own (fuzz/telnet_rfc2217.cpp);
// Rfc2217Port (remote_port.hpp) feeds it what it reads from the TCP connection.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace motorbus::serial::telnet {

// RFC 854 command bytes (the ones that follow IAC).
inline constexpr std::uint8_t SE = 240;
inline constexpr std::uint8_t NOP = 241;
inline constexpr std::uint8_t SB = 250;
inline constexpr std::uint8_t WILL = 251;
inline constexpr std::uint8_t WONT = 252;
inline constexpr std::uint8_t DO = 253;
inline constexpr std::uint8_t DONT = 254;
inline constexpr std::uint8_t IAC = 255;

// Options we take part in.
inline constexpr std::uint8_t OPT_BINARY = 0;        // RFC 856: 8-bit data, no CR NUL / CR LF rules
inline constexpr std::uint8_t OPT_SGA = 3;           // RFC 858: suppress go-ahead (full duplex)
inline constexpr std::uint8_t OPT_COM_PORT = 44;     // RFC 2217

// Which side of the connection an option is for: ours (we WILL, they DO) or
// the peer's (they WILL, we DO).
enum class Side : std::uint8_t { Local, Remote };

struct Event {
    enum class Kind : std::uint8_t {
        OptionOn,        // `option` is now enabled on `side`
        OptionOff,       // `option` is now disabled on `side` (refused, or turned off)
        Subnegotiation,  // IAC SB option payload IAC SE; payload unescaped (IAC IAC -> 0xFF)
        Command,         // another IAC command (NOP, GA, AYT, BRK...): reported, not acted on
    };
    Kind kind;
    Side side = Side::Local;
    std::uint8_t option = 0;  // the option, or the command byte for Kind::Command
    std::vector<std::uint8_t> payload;
    bool truncated = false;  // subnegotiation longer than kMaxSubnegotiation: payload cut
    bool operator==(const Event&) const = default;
};

// What one feed() produced.
struct Output {
    std::vector<std::uint8_t> data;    // the data stream, Telnet stripped
    std::vector<Event> events;
    std::vector<std::uint8_t> answer;  // bytes to send back (option negotiation replies)
};

// A Telnet client-side parser with per-option state kept as RFC 1143 asks
// (without the queue bits): an answer is only sent when a request changes the
// state, so two sides never loop on WILL/DO.  Options are accepted for a side
// when listed in `accept_local` / `accept_remote`; everything else is refused.
class Parser {
public:
    static constexpr std::size_t kMaxSubnegotiation = 512;

    Parser(std::vector<std::uint8_t> accept_local, std::vector<std::uint8_t> accept_remote);

    // Parses `in` (any split of the stream gives the same result) and appends to `out`.
    void feed(std::span<const std::uint8_t> in, Output& out);

    // Asks to enable `option` on `side` (IAC WILL / IAC DO): returns the bytes to
    // send, empty when it is already on or already asked for.
    std::vector<std::uint8_t> request(Side side, std::uint8_t option);

    bool enabled(Side side, std::uint8_t option) const;
    // True while our request for `option` on `side` waits for the peer's answer.
    bool pending(Side side, std::uint8_t option) const;

    // Subnegotiations dropped for malformed framing (IAC followed by neither IAC nor SE).
    std::uint64_t malformed() const { return malformed_; }

private:
    enum class Q : std::uint8_t { No, Yes, WantYes };
    enum class State : std::uint8_t { Data, Iac, Verb, SbOption, SbData, SbIac };

    void on_verb(std::uint8_t verb, std::uint8_t option, Output& out);
    void after_iac(std::uint8_t byte, Output& out);
    bool accepts(Side side, std::uint8_t option) const;

    std::array<Q, 256> local_{};
    std::array<Q, 256> remote_{};
    std::array<bool, 256> accept_local_{};
    std::array<bool, 256> accept_remote_{};
    State state_ = State::Data;
    std::uint8_t verb_ = 0;
    std::uint8_t sb_option_ = 0;
    std::vector<std::uint8_t> sb_;
    bool sb_truncated_ = false;
    std::uint64_t malformed_ = 0;
};

// Escapes data for the wire: every 0xFF becomes IAC IAC.
std::vector<std::uint8_t> escape(std::span<const std::uint8_t> data);

}  // namespace motorbus::serial::telnet

namespace motorbus::serial::rfc2217 {

// Client -> server commands (RFC 2217 §3); the server answers with command + 100.
inline constexpr std::uint8_t SIGNATURE = 0;
inline constexpr std::uint8_t SET_BAUDRATE = 1;
inline constexpr std::uint8_t SET_DATASIZE = 2;
inline constexpr std::uint8_t SET_PARITY = 3;
inline constexpr std::uint8_t SET_STOPSIZE = 4;
inline constexpr std::uint8_t SET_CONTROL = 5;
inline constexpr std::uint8_t PURGE_DATA = 12;
inline constexpr std::uint8_t SERVER_OFFSET = 100;

inline constexpr std::uint8_t PARITY_NONE = 1;
inline constexpr std::uint8_t STOPSIZE_1 = 1;

// IAC SB COM-PORT-OPTION command value... IAC SE, with IAC bytes of the value
// doubled (a baud of 0x...FF... must not end the subnegotiation early).
std::vector<std::uint8_t> command(std::uint8_t cmd, std::span<const std::uint8_t> value);
std::vector<std::uint8_t> set_baudrate(std::uint32_t baud);  // network byte order
std::vector<std::uint8_t> set_byte(std::uint8_t cmd, std::uint8_t value);

// A server's answer to one of our commands, decoded from a COM-PORT-OPTION
// subnegotiation payload (already unescaped).  nullopt: not a server answer
// (too short, or a client command code).
struct Reply {
    std::uint8_t command;  // the client command it answers (reply code - 100)
    std::vector<std::uint8_t> value;
    // The 4-byte value of SET-BAUDRATE, if the payload has one.
    std::optional<std::uint32_t> baud() const;
};
std::optional<Reply> parse_reply(std::span<const std::uint8_t> payload);

}  // namespace motorbus::serial::rfc2217

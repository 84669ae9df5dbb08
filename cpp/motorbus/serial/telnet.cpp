// Telnet stream parser and RFC 2217 codec (see telnet.hpp).
#include "motorbus/serial/telnet.hpp"

namespace motorbus::serial::telnet {

Parser::Parser(std::vector<std::uint8_t> accept_local, std::vector<std::uint8_t> accept_remote) {
    for (auto o : accept_local) accept_local_[o] = true;
    for (auto o : accept_remote) accept_remote_[o] = true;
}

bool Parser::accepts(Side side, std::uint8_t option) const {
    return side == Side::Local ? accept_local_[option] : accept_remote_[option];
}

bool Parser::enabled(Side side, std::uint8_t option) const {
    return (side == Side::Local ? local_ : remote_)[option] == Q::Yes;
}

bool Parser::pending(Side side, std::uint8_t option) const {
    return (side == Side::Local ? local_ : remote_)[option] == Q::WantYes;
}

std::vector<std::uint8_t> Parser::request(Side side, std::uint8_t option) {
    auto& q = (side == Side::Local ? local_ : remote_)[option];
    if (q != Q::No) return {};
    q = Q::WantYes;
    return {IAC, side == Side::Local ? WILL : DO, option};
}

// WILL/WONT speak about the peer's side (Remote), DO/DONT about ours (Local).
// RFC 854: a request to enter a state we are already in is not answered; a
// request we refuse is answered with the negative; the peer's answer to our own
// request (WantYes) is not answered again.
void Parser::on_verb(std::uint8_t verb, std::uint8_t option, Output& out) {
    const bool about_remote = verb == WILL || verb == WONT;
    const Side side = about_remote ? Side::Remote : Side::Local;
    const bool positive = verb == WILL || verb == DO;
    auto& q = (about_remote ? remote_ : local_)[option];
    const std::uint8_t yes = about_remote ? DO : WILL;
    const std::uint8_t no = about_remote ? DONT : WONT;
    auto answer = [&](std::uint8_t v) { out.answer.insert(out.answer.end(), {IAC, v, option}); };
    if (positive) {
        switch (q) {
        case Q::No:
            if (accepts(side, option)) {
                q = Q::Yes;
                answer(yes);
                out.events.push_back({Event::Kind::OptionOn, side, option, {}, false});
            } else {
                answer(no);
            }
            break;
        case Q::WantYes:  // the answer to our request
            q = Q::Yes;
            out.events.push_back({Event::Kind::OptionOn, side, option, {}, false});
            break;
        case Q::Yes:
            break;
        }
    } else {
        switch (q) {
        case Q::Yes:  // the peer turns it off: confirm
            q = Q::No;
            answer(no);
            out.events.push_back({Event::Kind::OptionOff, side, option, {}, false});
            break;
        case Q::WantYes:  // our request refused
            q = Q::No;
            out.events.push_back({Event::Kind::OptionOff, side, option, {}, false});
            break;
        case Q::No:
            break;
        }
    }
}

// The byte after an IAC in the data stream.
void Parser::after_iac(std::uint8_t byte, Output& out) {
    switch (byte) {
    case IAC:
        out.data.push_back(IAC);
        state_ = State::Data;
        break;
    case WILL:
    case WONT:
    case DO:
    case DONT:
        verb_ = byte;
        state_ = State::Verb;
        break;
    case SB:
        state_ = State::SbOption;
        break;
    default:  // NOP, GA, AYT, BRK, a stray SE...: nothing to do for a serial line
        out.events.push_back({Event::Kind::Command, Side::Remote, byte, {}, false});
        state_ = State::Data;
        break;
    }
}

void Parser::feed(std::span<const std::uint8_t> in, Output& out) {
    for (std::size_t i = 0; i < in.size(); ++i) {
        const std::uint8_t b = in[i];
        switch (state_) {
        case State::Data: {
            if (b == IAC) {
                state_ = State::Iac;
                break;
            }
            // Copy the run of plain data up to the next IAC in one go.
            std::size_t j = i;
            while (j < in.size() && in[j] != IAC) ++j;
            out.data.insert(out.data.end(), in.begin() + static_cast<std::ptrdiff_t>(i),
                            in.begin() + static_cast<std::ptrdiff_t>(j));
            i = j - 1;
            break;
        }
        case State::Iac:
            after_iac(b, out);
            break;
        case State::Verb:
            on_verb(verb_, b, out);
            state_ = State::Data;
            break;
        case State::SbOption:
            sb_option_ = b;
            sb_.clear();
            sb_truncated_ = false;
            state_ = State::SbData;
            break;
        case State::SbData:
            if (b == IAC) {
                state_ = State::SbIac;
            } else if (sb_.size() < kMaxSubnegotiation) {
                sb_.push_back(b);
            } else {
                sb_truncated_ = true;
            }
            break;
        case State::SbIac:
            if (b == IAC) {  // an escaped 0xFF inside the payload
                if (sb_.size() < kMaxSubnegotiation)
                    sb_.push_back(IAC);
                else
                    sb_truncated_ = true;
                state_ = State::SbData;
            } else if (b == SE) {
                out.events.push_back({Event::Kind::Subnegotiation, Side::Remote, sb_option_, std::move(sb_),
                                      sb_truncated_});
                sb_.clear();
                state_ = State::Data;
            } else {
                // IAC <command> inside a subnegotiation: the peer forgot IAC SE.
                // Drop the unfinished subnegotiation and take the command as it
                // stands, so one bad frame does not swallow the data after it.
                ++malformed_;
                sb_.clear();
                after_iac(b, out);
            }
            break;
        }
    }
}

std::vector<std::uint8_t> escape(std::span<const std::uint8_t> data) {
    std::vector<std::uint8_t> out;
    out.reserve(data.size() + 8);
    for (auto b : data) {
        out.push_back(b);
        if (b == IAC) out.push_back(IAC);
    }
    return out;
}

}  // namespace motorbus::serial::telnet

namespace motorbus::serial::rfc2217 {

using namespace telnet;

std::vector<std::uint8_t> command(std::uint8_t cmd, std::span<const std::uint8_t> value) {
    std::vector<std::uint8_t> out{IAC, SB, OPT_COM_PORT, cmd};
    for (auto b : value) {
        out.push_back(b);
        if (b == IAC) out.push_back(IAC);
    }
    out.insert(out.end(), {IAC, SE});
    return out;
}

std::vector<std::uint8_t> set_baudrate(std::uint32_t baud) {
    const std::uint8_t v[4] = {static_cast<std::uint8_t>(baud >> 24), static_cast<std::uint8_t>(baud >> 16),
                               static_cast<std::uint8_t>(baud >> 8), static_cast<std::uint8_t>(baud)};
    return command(SET_BAUDRATE, v);
}

std::vector<std::uint8_t> set_byte(std::uint8_t cmd, std::uint8_t value) {
    const std::uint8_t v[1] = {value};
    return command(cmd, v);
}

std::optional<std::uint32_t> Reply::baud() const {
    if (command != SET_BAUDRATE || value.size() != 4) return std::nullopt;
    return (std::uint32_t{value[0]} << 24) | (std::uint32_t{value[1]} << 16) | (std::uint32_t{value[2]} << 8) |
           std::uint32_t{value[3]};
}

std::optional<Reply> parse_reply(std::span<const std::uint8_t> payload) {
    if (payload.empty() || payload[0] < SERVER_OFFSET) return std::nullopt;
    return Reply{static_cast<std::uint8_t>(payload[0] - SERVER_OFFSET), {payload.begin() + 1, payload.end()}};
}

}  // namespace motorbus::serial::rfc2217

#include "motorbus/drives/dmac/client.hpp"

#include <algorithm>
#include <thread>

#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::dmac {
namespace {

constexpr int kMaxStrayLines = 8;  // lines skipped while looking for the awaited reply
constexpr Duration kMaxLineDelay = std::chrono::microseconds(3000);  // #LINE_DELAY range 100..3000 us

std::vector<std::uint8_t> bytes_of(std::string_view s) { return {s.begin(), s.end()}; }

std::string describe_error(std::uint32_t e) {
    std::string s;
    for (const auto& n : error_names(e)) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? "none" : s;
}

}  // namespace

serial::LineOptions default_line_options() {
    serial::LineOptions o;
    o.request_terminator = "\r";
    o.reply_terminators = {"\r\n"};
    o.max_line = kMaxFrame;
    o.reply_timeout = std::chrono::milliseconds(500);
    o.flush_before_request = true;
    return o;
}

Client::Client(std::shared_ptr<serial::LineLink> link, ClientOptions options)
    : link_(std::move(link)), options_(std::move(options)) {
    if (!link_) throw InvalidArgument("DmacClient: link is null");
    if (options_.address < 0 || options_.address > kMaxAddress)
        throw InvalidArgument("DmacClient address: " + std::to_string(options_.address) +
                              " is outside 0..63 (global commands go through synchro()/raw())");
    if (options_.baud != 9600 && options_.baud != 19200 && options_.baud != 38400 && options_.baud != 115200)
        throw InvalidArgument("DmacClient baud: " + std::to_string(options_.baud) +
                              " is not 9600, 19200, 38400 or 115200");
}

int Client::check_family(int n, int count, const char* name) {
    if (n < 1 || n > count)
        throw InvalidArgument(std::string(name) + "n: n=" + std::to_string(n) + " is outside 1.." +
                              std::to_string(count));
    return n;
}

void Client::sleep(Duration d) {
    if (options_.sleep) options_.sleep(d);
    else interruptible_sleep_for(d);  // an interruption point (Ctrl-C) on every poll
}

Duration Client::reply_wait() const {
    const Duration base = options_.timeout.value_or(link_->options().reply_timeout);
    // 10 bits a character; a request and its reply of up to 256 characters each.
    const Duration wire = std::chrono::nanoseconds(2LL * static_cast<long long>(kMaxFrame) * 10 *
                                                   1'000'000'000LL / std::max(options_.baud, 1));
    return base + kMaxLineDelay + wire;
}

std::string Client::frame(std::string_view command) const {
    std::string f = address_prefix(options_.address);
    f += command;
    if (f.size() > kMaxFrame)
        throw InvalidArgument("DMAC frame: " + std::to_string(f.size()) + " characters exceeds 256");
    return f;
}

std::string Client::await(const std::string& request,
                              const std::function<bool(std::string_view)>& match, bool send_only) {
    ++counters_.transactions;
    if (send_only) {
        link_->send(request);
        return "";
    }
    std::string reply = link_->transact(request, reply_wait());
    const std::string first = reply;
    for (int i = 0; i < kMaxStrayLines; ++i) {
        if (match(reply)) return reply;
        if (!reply.empty() && reply[0] == '?') throw UnknownCommand("DMAC answered '" + reply + "' to '" + request + "'");
        ++counters_.stray_lines;
        if (reply.find("EV v") != std::string::npos) ++counters_.device_resets;
        auto next = link_->read_line(reply_wait());
        if (!next) break;
        reply = *next;
    }
    throw ProtocolError("DMAC: no valid reply to '" + request + "' (got '" + first + "')", bytes_of(first));
}

ReadReply Client::read_reply(const std::string& request, Var v, int bit) {
    const std::string prefix = address_prefix(options_.address) + var_info(v).mnemonic;
    std::optional<ReadReply> got;
    await(request, [&](std::string_view line) {
        auto r = parse_read_reply(line);
        if (!r) {
            // Our variable, but the value breaks the grammar: reject now rather
            // than wait for another line.
            if (line.substr(0, prefix.size()) == prefix &&
                (line.size() == prefix.size() || line[prefix.size()] == '=' || line[prefix.size()] == '.'))
                throw ProtocolError("DMAC: malformed value in '" + std::string(line) + "'", bytes_of(line));
            return false;
        }
        if (r->address != options_.address || r->mnemonic != var_info(v).mnemonic || r->bit != bit) return false;
        got = *r;
        return true;
    }, false);
    return *got;
}

// ---- generic ------------------------------------------------------------------------
void Client::command(std::string_view cmd) {
    if (!options_.verify) {
        await(frame(cmd), nullptr, true);
        return;
    }
    const ReadReply r = read_reply(frame(cmd) + ", READ #ERROR", Var::Error, 0);
    const auto err = static_cast<std::uint32_t>(r.value);
    const std::uint32_t command_bits =
        bit_mask(error::kSyntax) | bit_mask(error::kLimit) | bit_mask(error::kComputation);
    const std::uint32_t hardware = err & ~command_bits;
    const std::uint32_t faults = bit_mask(error::kThermal) | bit_mask(error::kShortCircuit) |
                                 bit_mask(error::kUndervoltage) | bit_mask(error::kOvervoltage);
    // With a fault latched the power stage stays off: a move or POWER ON is
    // not carried out (manual 2.1), so say so instead of waiting for nothing.
    if ((err & faults) && (cmd.find("MOVE_") != std::string_view::npos || cmd.find("POWER ON") != std::string_view::npos))
        throw CommandRejected("DMAC " + std::to_string(options_.address) + " did not run '" + std::string(cmd) +
                                  "': a fault is latched (#ERROR " + describe_error(err) +
                                  "); acknowledge it with clear_error()",
                              err);
    if (!(err & command_bits)) return;
    // Acknowledge a command error so the next command starts clean, unless a
    // hardware fault is latched too: that one is the user's to acknowledge.
    if (!hardware) read_reply(frame("#ERROR:=0, READ #ERROR"), Var::Error, 0);
    const std::string what = "DMAC " + std::to_string(options_.address) + " rejected '" + std::string(cmd) +
                             "': #ERROR " + describe_error(err);
    if (err & bit_mask(error::kSyntax)) throw UnknownCommand(what);
    throw CommandRejected(what, err);
}

std::int32_t Client::read(Var v, Radix r) {
    std::string req = encode_read(options_.address, v, r);
    return read_reply(req, v, 0).value;
}

bool Client::read_bit(Var v, int bit) {
    if (bit < 1 || bit > 32) throw InvalidArgument("bit: " + std::to_string(bit) + " is outside 1..32");
    return read_reply(encode_read(options_.address, v, Radix::Dec, bit), v, bit).value != 0;
}

void Client::write(Var v, std::int32_t value) {
    const VarInfo& vi = var_info(v);
    if (vi.read_only) throw InvalidArgument(vi.name + " is read-only");
    if (value < vi.min || value > vi.max)
        throw InvalidArgument(vi.name + ": " + std::to_string(value) + " is outside " + std::to_string(vi.min) +
                              ".." + std::to_string(vi.max));
    command(encode_write(kGlobal, v, value));
}

void Client::write_bit(Var v, int bit, bool value) {
    const VarInfo& vi = var_info(v);
    if (vi.read_only) throw InvalidArgument(vi.name + " is read-only");
    if (bit < 1 || bit > 32) throw InvalidArgument("bit: " + std::to_string(bit) + " is outside 1..32");
    command(encode_write(kGlobal, v, value ? 1 : 0, bit));
}

std::string Client::raw(std::string_view f, bool expect_reply) {
    ++counters_.transactions;
    if (!expect_reply) {
        link_->send(f);
        return "";
    }
    return link_->transact(f, options_.timeout);
}

void Client::clear_error() { command("#ERROR:=0"); }

void Client::set_profile(std::optional<std::int32_t> hs, std::optional<std::int32_t> ls,
                             std::optional<std::int32_t> acc, std::optional<std::int32_t> dec) {
    // One frame: the module applies all of them before the next move.
    std::string f;
    auto add = [&](Var v, std::optional<std::int32_t> x) {
        if (!x) return;
        const VarInfo& vi = var_info(v);
        if (*x < vi.min || *x > vi.max)
            throw InvalidArgument(vi.name + ": " + std::to_string(*x) + " is outside " + std::to_string(vi.min) +
                                  ".." + std::to_string(vi.max));
        if (!f.empty()) f += ", ";
        f += encode_write(kGlobal, v, *x);
    };
    add(Var::HighSpeed, hs);
    add(Var::LowSpeed, ls);
    add(Var::AccelTime, acc);
    add(Var::DecelTime, dec);
    if (!f.empty()) command(f);
}

void Client::set_soft_limits(std::int32_t negative, std::int32_t positive) {
    if (negative > positive)
        throw InvalidArgument("soft limits: #NEGATIVE_END " + std::to_string(negative) + " is above #POSITIVE_END " +
                              std::to_string(positive));
    command(encode_write(kGlobal, Var::NegativeEnd, negative) + ", " + encode_write(kGlobal, Var::PositiveEnd, positive));
}

void Client::set_interpolation(std::int32_t time_ms, std::int32_t fifo_size, std::int32_t mode) {
    auto check = [](Var v, std::int32_t x) {
        const VarInfo& vi = var_info(v);
        if (x < vi.min || x > vi.max)
            throw InvalidArgument(vi.name + ": " + std::to_string(x) + " is outside " + std::to_string(vi.min) + ".." +
                                  std::to_string(vi.max));
    };
    check(Var::InterpolTime, time_ms);
    check(Var::InterpolFifosize, fifo_size);
    check(Var::InterpolMode, mode);
    command(encode_write(kGlobal, Var::InterpolTime, time_ms) + ", " +
            encode_write(kGlobal, Var::InterpolFifosize, fifo_size) + ", " +
            encode_write(kGlobal, Var::InterpolMode, mode));
}

bool Client::is_dmac34() {
    // Software codes H142/J142/K142 are the DMAC34 firmwares (4.19).
    if (!dmac34_) {
        const VersionInfo v = request_version();
        dmac34_ = v.code.size() == 4 && v.code.substr(1) == "142";
    }
    return *dmac34_;
}

std::int32_t Client::analog_input(int channel) {
    if (channel != 1 && channel != 2)
        throw InvalidArgument("analog input: channel " + std::to_string(channel) + " is not 1 or 2");
    const bool d34 = is_dmac34();
    if (channel == 2 && !d34) throw InvalidArgument("analog input: channel 2 exists on a DMAC34 only");
    return read(channel == 2 ? Var::InputA2 : d34 ? Var::InputA1 : Var::InputAnalog);
}

void Client::set_analog_output(int channel, std::int32_t mv) {
    if (channel != 1 && channel != 2)
        throw InvalidArgument("analog output: channel " + std::to_string(channel) + " is not 1 or 2");
    write(channel == 1 ? Var::OutputA1 : Var::OutputA2, mv);
}

// ---- commands -------------------------------------------------------------------------
void Client::move_to(std::int32_t p) { command("MOVE_TO " + std::to_string(p)); }
void Client::move_on(std::int32_t d) { command("MOVE_ON " + std::to_string(d)); }
void Client::move_speed(std::int32_t v) {
    if (v < -400000 || v > 400000)
        throw InvalidArgument("MOVE_SPEED: " + std::to_string(v) + " is outside -400000..400000 (0.01 rpm)");
    command("MOVE_SPEED " + std::to_string(v));
}

static const char* stop_arg(StopWhat w) {
    switch (w) {
        case StopWhat::Movement: return " MOUV";
        case StopWhat::Sequence: return " SEQ";
        default: return "";
    }
}
void Client::stop(StopWhat w) { command(std::string("STOP") + stop_arg(w)); }
void Client::halt(StopWhat w) { command(std::string("HALT") + stop_arg(w)); }

void Client::power(PowerMode m) {
    command(m == PowerMode::On ? "POWER ON" : m == PowerMode::Off ? "POWER OFF" : "POWER SC");
}
void Client::brake(bool on) { command(on ? "BRAKE ON" : "BRAKE OFF"); }
void Client::hard_ends(EndStops e) {
    static const char* t[] = {"HARD_ENDS OFF", "HARD_ENDS ALL", "HARD_ENDS POS", "HARD_ENDS NEG"};
    command(t[static_cast<int>(e)]);
}
void Client::soft_ends(bool on) { command(on ? "SOFT_ENDS ON" : "SOFT_ENDS OFF"); }
void Client::s_curve(bool on) { command(on ? "S_CURVE ON" : "S_CURVE OFF"); }
void Client::optimized_current(bool on) { command(on ? "OPTIMIZED_CURRENT ON" : "OPTIMIZED_CURRENT OFF"); }
void Client::inverse_polarity(Polarity p) {
    static const char* t[] = {"INVERSE_POLARITY OFF", "INVERSE_POLARITY ALL", "INVERSE_POLARITY IN",
                              "INVERSE_POLARITY OUT"};
    command(t[static_cast<int>(p)]);
}
void Client::reference(bool on) { command(on ? "REFERENCE ON" : "REFERENCE OFF"); }
void Client::module_reset(bool factory) { command(factory ? "MODULE_RESET ALL" : "MODULE_RESET"); }

void Client::set_address(int a) {
    if (a < 0 || a > kMaxAddress) throw InvalidArgument("SET_ADDRESS: " + std::to_string(a) + " is outside 0..63");
    // The module answers under its new address, so send, follow, then verify there.
    await(frame("SET_ADDRESS " + std::to_string(a)), nullptr, true);
    options_.address = a;
    if (options_.verify) {
        const ErrorWord e = error();
        if (e.bit(error::kSyntax) || e.bit(error::kLimit))
            throw CommandRejected("SET_ADDRESS: #ERROR " + describe_error(e.raw), e.raw);
    }
}

void Client::set_baudrate(int baud) {
    if (baud != 9600 && baud != 19200 && baud != 38400 && baud != 115200)
        throw InvalidArgument("SET_BAUDRATE: " + std::to_string(baud) + " is not 9600, 19200, 38400 or 115200");
    // Applied at once by the module: the caller changes the port speed next.
    await(frame("SET_BAUDRATE " + std::to_string(baud)), nullptr, true);
}

VersionInfo Client::request_version() {
    std::optional<VersionInfo> v;
    await(frame("REQUEST_VERSION"), [&](std::string_view line) {
        v = parse_version(line);
        return v && v->address == options_.address;
    }, false);
    return *v;
}

std::int32_t Client::wait_idle(Duration timeout, Duration poll) {
    Duration waited{0};
    for (;;) {
        if (!status().busy()) return position();
        if (timeout.count() >= 0 && waited >= timeout)  // negative: wait forever
            throw TimeoutError("DMAC " + std::to_string(options_.address) + ": still moving after " +
                               std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count()) +
                               " ms");
        sleep(poll);
        waited += poll;
    }
}

// ---- sequencer ----------------------------------------------------------------------------
void Client::upload_sequence(const std::vector<std::string>& lines, int first, bool verify_readback) {
    if (first < 1 || first + static_cast<int>(lines.size()) - 1 > kSeqLines)
        throw InvalidArgument("sequence: lines " + std::to_string(first) + ".." +
                              std::to_string(first + static_cast<int>(lines.size()) - 1) + " exceed 1..500");
    // Validate locally first: a bad line must not leave a half-written program.
    std::vector<std::string> expected;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const std::string& l = lines[i];
        Request r = parse_request(l);
        if (l.find(',') != std::string::npos || r.address != kGlobal || r.seq_line || r.commands.size() != 1 ||
            r.commands[0].cmd == Cmd::Invalid)
            throw InvalidArgument("sequence line " + std::to_string(first + static_cast<int>(i)) + ": '" + l +
                                  "' is not one valid DMAC command");
        expected.push_back(format_command(r.commands[0]));
    }
    command("OPEN_SEQ");
    for (std::size_t i = 0; i < lines.size(); ++i)
    {
        std::string f(1, ':');
        f.append(std::to_string(first + static_cast<int>(i))).append(1, ' ').append(lines[i]);
        command(f);
    }
    command("CLOSE_SEQ");
    if (!verify_readback) return;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const int n = first + static_cast<int>(i);
        std::string got = read_sequence_line(n);
        if (got != expected[i])
            throw CommandRejected("sequence line " + std::to_string(n) + ": stored '" + got + "', expected '" +
                                  expected[i] + "'", 0);
    }
}

std::string Client::read_sequence_line(int n) {
    if (n < 1 || n > kSeqLines) throw InvalidArgument("READ_SEQ: line " + std::to_string(n) + " is outside 1..500");
    std::optional<SeqLineReply> got;
    await(frame("READ_SEQ " + std::to_string(n)), [&](std::string_view line) {
        got = parse_seq_reply(line);
        return got && got->address == options_.address && got->line == n;
    }, false);
    return got->text;
}

std::vector<std::string> Client::read_sequence(int first, int last) {
    std::vector<std::string> out;
    for (int n = first; n <= last; ++n) out.push_back(read_sequence_line(n));
    return out;
}

void Client::start_sequence(int line) {
    if (line < 1 || line > kSeqLines) throw InvalidArgument("START_SEQ: line " + std::to_string(line) + " is outside 1..500");
    command("START_SEQ " + std::to_string(line));
}

void Client::step(std::optional<int> line) {
    if (line && (*line < 1 || *line > kSeqLines))
        throw InvalidArgument("STEP: line " + std::to_string(*line) + " is outside 1..500");
    command(line ? "STEP " + std::to_string(*line) : std::string("STEP"));
}

// ---- interpolation ---------------------------------------------------------------------------
std::optional<int> Client::move_interpol(std::int32_t offset) {
    const std::string req = frame("MOVE_INTERPOL " + std::to_string(offset)) + ", READ #INTERPOL_COUNT";
    const std::string prefix = address_prefix(options_.address) + "#ICO=";
    bool full = false;
    std::optional<ReadReply> got;
    await(req, [&](std::string_view line) {
        // A full FIFO answers the single byte XON_ERROR before the READ's reply.
        full = !line.empty() && line[0] == kXonError;
        if (full) line.remove_prefix(1);
        auto r = parse_read_reply(line);
        if (!r || r->address != options_.address || r->mnemonic != "#ICO" || r->bit) return false;
        got = r;
        return true;
    }, false);
    if (full) {
        ++counters_.xon_errors;
        return std::nullopt;
    }
    return got->value;
}

void synchro(serial::LineLink& link, Keyword what) {
    switch (what) {
        case Keyword::On: link.send("SYNCHRO ON"); return;
        case Keyword::Off: link.send("SYNCHRO OFF"); return;
        case Keyword::Top: link.send("SYNCHRO TOP"); return;
        case Keyword::Interpol: link.send("SYNCHRO INTERPOL"); return;
        default: throw InvalidArgument("SYNCHRO: ON, OFF, TOP or INTERPOL");
    }
}

StreamStats stream_interpolation(std::vector<Client*> axes, const std::vector<std::vector<long long>>& segments,
                                 const StreamOptions& o) {
    if (axes.empty()) throw InvalidArgument("stream_interpolation: no axes");
    for (auto* a : axes)
        if (!a) throw InvalidArgument("stream_interpolation: null axis");
    if (o.interpol_time_ms < 2 || o.interpol_time_ms > 138)
        throw InvalidArgument("#INTERPOL_TIME: " + std::to_string(o.interpol_time_ms) + " is outside 2..138 ms");
    if (o.fifo_size < 1 || o.fifo_size > 64)
        throw InvalidArgument("#INTERPOL_FIFOSIZE: " + std::to_string(o.fifo_size) + " is outside 1..64");
    for (std::size_t k = 0; k < segments.size(); ++k) {
        if (segments[k].size() != axes.size())
            throw InvalidArgument("segment " + std::to_string(k) + " has " + std::to_string(segments[k].size()) +
                                  " offsets for " + std::to_string(axes.size()) + " axes");
        for (long long off : segments[k])
            if (off < -2147483648LL || off > 2147483647LL)
                throw InvalidArgument("segment " + std::to_string(k) + ": offset outside int32");
    }
    StreamStats st;
    st.segments = segments.size();
    st.min_level_after_start = o.fifo_size;
    if (segments.empty()) return st;
    auto wait = [&](Duration d) {
        if (o.sleep) o.sleep(d);
        else interruptible_sleep_for(d);
    };
    const Duration backoff = o.backoff.count() > 0 ? o.backoff
                                                   : std::chrono::microseconds(o.interpol_time_ms * 250);
    for (auto* a : axes) {
        a->write(Var::InterpolTime, o.interpol_time_ms);
        a->write(Var::InterpolFifosize, o.fifo_size);
        if (a->interpol_count() != 0)
            throw DriveFault("DMAC " + std::to_string(a->address()) + ": interpolation FIFO not empty before start");
    }
    const std::size_t n = axes.size();
    std::vector<std::size_t> next(n, 0);
    const std::size_t prefill = std::min<std::size_t>(static_cast<std::size_t>(o.fifo_size), segments.size());
    for (std::size_t k = 0; k < prefill; ++k)
        for (std::size_t i = 0; i < n; ++i) {
            ++st.frames;
            if (!axes[i]->move_interpol(static_cast<std::int32_t>(segments[k][i])))
                throw DriveFault("DMAC " + std::to_string(axes[i]->address()) + ": FIFO full while pre-filling");
            next[i] = k + 1;
        }
    synchro(axes[0]->link(), Keyword::Interpol);
    for (;;) {
        bool pending = false, progressed = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (next[i] >= segments.size()) continue;
            pending = true;
            ++st.frames;
            auto level = axes[i]->move_interpol(static_cast<std::int32_t>(segments[next[i]][i]));
            if (!level) {
                ++st.xon_errors;
                continue;
            }
            progressed = true;
            ++next[i];
            // The level counts the segment just queued: 1 means the axis had run dry.
            st.min_level_after_start = std::min(st.min_level_after_start, *level - 1);
            if (*level <= 1) ++st.underruns;
        }
        if (!pending) break;
        if (!progressed) wait(backoff);
    }
    return st;
}

}  // namespace motorbus::dmac

#include "motorbus/drives/arcus/client.hpp"

#include <cmath>
#include <thread>

#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::arcus {

namespace {
// "X" + std::to_string(v) trips a g++ 12 -Wrestrict false positive; append instead.
std::string glued(std::string_view name, std::int64_t value) {
    std::string s(name);
    s += std::to_string(value);
    return s;
}
// A line no DMX-CAN would send: empty, or holding bytes outside printable ASCII.
bool is_noise(std::string_view raw) {
    if (raw.empty()) return true;
    for (char c : raw)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) return true;
    return false;
}
}  // namespace

std::string_view home_command(HomeMethod m, int direction) {
    bool plus = direction >= 0;
    switch (m) {
        case HomeMethod::H: return plus ? "H+" : "H-";
        case HomeMethod::HL: return plus ? "HL+" : "HL-";
        case HomeMethod::ZH: return plus ? "ZH+" : "ZH-";
        case HomeMethod::Z: return plus ? "Z+" : "Z-";
        case HomeMethod::L: return plus ? "L+" : "L-";
    }
    return "H+";
}

Client::Client(std::shared_ptr<serial::LineLink> link, ClientOptions options)
    : link_(std::move(link)), options_(options) {
    if (!link_) throw InvalidArgument("arcus client: link is null");
    if (options_.address < 1 || options_.address > kMaxAddress)
        throw InvalidArgument("arcus client address: must be 1..99 (00 is broadcast)");
    if (options_.query_retries < 0) throw InvalidArgument("arcus client query_retries: must be >= 0");
}

serial::LineOptions Client::line_options(serial::Duration reply_timeout) {
    serial::LineOptions o;
    o.request_terminator = std::string(1, kRequestTerminator);
    o.reply_terminators = {std::string(1, kReplyTerminator)};
    o.max_line = kMaxReply;
    o.reply_timeout = reply_timeout;
    o.flush_before_request = true;
    return o;
}

std::string Client::transact(std::string_view command, bool idempotent) {
    std::string request = format_command(options_.address, command);
    int attempts = idempotent ? 1 + options_.query_retries : 1;
    for (int i = 0;; ++i) {
        ++counters_.requests;
        std::string raw;
        Reply reply;
        try {
            auto timeout = options_.timeout.value_or(link_->options().reply_timeout);
            auto deadline = std::chrono::steady_clock::now() + timeout;
            raw = link_->transact(request, options_.timeout);
            // Line noise (baud mismatch, a glitch) ends at some NUL like a reply
            // does: skip such lines and keep listening for the real reply.
            for (;;) {
                if (is_noise(raw)) {
                    ++counters_.noise_lines;
                    auto left = deadline - std::chrono::steady_clock::now();
                    auto next = left.count() > 0 ? link_->read_line(left) : std::nullopt;
                    if (!next) throw TimeoutError("arcus: no reply to '" + request + "' (only line noise)");
                    raw = std::move(*next);
                    continue;
                }
                break;
            }
            try {
                reply = parse_reply(raw);
            } catch (const ProtocolError&) {
                ++counters_.protocol_errors;
                throw;
            }
        } catch (const TimeoutError&) {
            ++counters_.timeouts;
            if (i + 1 >= attempts) throw;
            ++counters_.retries;
            continue;
        }
        if (reply.address && *reply.address != options_.address) {
            // A reply for another device (a late one, or a duplicate address on the line).
            ++counters_.protocol_errors;
            throw ProtocolError("arcus: reply from #" + std::to_string(*reply.address) + " to a request for " +
                                    std::to_string(options_.address),
                                std::vector<std::uint8_t>(raw.begin(), raw.end()));
        }
        if (auto code = classify_error(reply.body)) {
            ++counters_.device_errors;
            throw ReplyError(*code, reply.body, std::string(command));
        }
        return reply.body;
    }
}

std::string Client::command(std::string_view command, bool idempotent) {
    return transact(command, idempotent);
}

void Client::broadcast(serial::LineLink& link, std::string_view command) {
    link.send(format_command(kBroadcast, command));
}

void Client::expect_ok(std::string_view command, const std::string& body) {
    if (body != "OK") {
        ++counters_.protocol_errors;
        throw ProtocolError("arcus: expected OK to " + std::string(command) + ", got '" + body.substr(0, 32) + "'",
                            std::vector<std::uint8_t>(body.begin(), body.end()));
    }
}

std::int64_t Client::query(std::string_view name) {
    std::string body = transact(name, true);
    try {
        return reply_int(body);
    } catch (const ProtocolError&) {
        ++counters_.protocol_errors;
        throw;
    }
}

void Client::set(std::string_view name, std::int64_t value) {
    std::string cmd(name);
    cmd += '=';
    cmd += std::to_string(value);
    expect_ok(cmd, transact(cmd, false));
}

void Client::action(std::string_view name) { expect_ok(name, transact(name, false)); }

void Client::check_index(int n, int max, const char* what) {
    if (n < 1 || n > max)
        throw InvalidArgument(std::string(what) + ": index must be 1.." + std::to_string(max));
}

// ---- identity / configuration ---------------------------------------------------

std::string Client::id() { return transact("ID", true); }
std::string Client::version() { return transact("VER", true); }
std::string Client::device_name() { return transact("DN", true); }
void Client::set_device_name(int address) {
    if (address < 1 || address > kMaxAddress) throw InvalidArgument("DN: address must be 1..99");
    char buf[16];
    std::snprintf(buf, sizeof buf, "DN=DMC%02d", address);
    expect_ok(buf, transact(buf, false));
}
int Client::response_type() { return static_cast<int>(query("RT")); }
void Client::set_response_type(int rt) {
    if (rt != 0 && rt != 1) throw InvalidArgument("RT: must be 0 or 1");
    set("RT", rt);
}
void Client::store() { action("STORE"); }

// ---- positions and status -----------------------------------------------------------

std::int64_t Client::position() { return query("PX"); }
void Client::set_position(std::int64_t p) { set("PX", p); }
std::int64_t Client::encoder() { return query("EX"); }
void Client::set_encoder(std::int64_t e) { set("EX", e); }
std::int64_t Client::delta() { return query("DX"); }
std::int64_t Client::speed() { return query("PS"); }
MotorStatus Client::status() {
    std::int64_t v = query("MST");
    if (v < 0 || v > 1023) {
        ++counters_.protocol_errors;
        throw ProtocolError("arcus: MST out of range: " + std::to_string(v));
    }
    return MotorStatus{static_cast<std::uint32_t>(v)};
}
SnlStatus Client::snl_status() {
    std::int64_t v = query("SLS");
    auto s = snl_status_from(v);
    if (!s) {
        ++counters_.protocol_errors;
        throw ProtocolError("arcus: SLS out of range: " + std::to_string(v));
    }
    return *s;
}
bool Client::moving() { return status().moving(); }

// ---- profile ----------------------------------------------------------------------------

std::int64_t Client::high_speed() { return query("HSPD"); }
void Client::set_high_speed(std::int64_t pps) { set("HSPD", pps); }
std::int64_t Client::low_speed() { return query("LSPD"); }
void Client::set_low_speed(std::int64_t pps) { set("LSPD", pps); }
std::int64_t Client::acceleration() { return query("ACC"); }
void Client::set_acceleration(std::int64_t ms) { set("ACC", ms); }
std::int64_t Client::deceleration() { return query("DEC"); }
void Client::set_deceleration(std::int64_t ms) { set("DEC", ms); }
bool Client::unique_deceleration() { return query("EDEC") != 0; }
void Client::set_unique_deceleration(bool on) { set("EDEC", on); }
bool Client::s_curve() { return query("SCV") != 0; }
void Client::set_s_curve(bool on) { set("SCV", on); }
int Client::speed_window() { return static_cast<int>(query("SSPDM")); }
void Client::set_speed_window(int sspdm) {
    if (sspdm < 0 || sspdm > 9) throw InvalidArgument("SSPDM: must be 0..9");
    set("SSPDM", sspdm);
}

// ---- motion ---------------------------------------------------------------------------------

void Client::absolute_mode() { action("ABS"); }
void Client::incremental_mode() { action("INC"); }
bool Client::incremental() { return query("MM") != 0; }
void Client::move(std::int64_t target) {
    std::string cmd = glued("X", target);
    expect_ok(cmd, transact(cmd, false));
}
void Client::change_target(std::int64_t target) {
    std::string cmd = glued("T", target);
    expect_ok(cmd, transact(cmd, false));
}
void Client::change_speed(std::int64_t pps) {
    std::string cmd = glued("SSPD", pps);
    expect_ok(cmd, transact(cmd, false));
}
void Client::jog(int direction) { action(direction >= 0 ? "J+" : "J-"); }
// STOP and ABORT only ever stop motion: repeating them is harmless, so they
// may be retried (a lost stop is worse than a duplicate).
void Client::stop() { expect_ok("STOP", transact("STOP", true)); }
void Client::abort() { expect_ok("ABORT", transact("ABORT", true)); }
void Client::clear() { action("CLR"); }
void Client::clear_snl() { action("CLRS"); }
void Client::home(HomeMethod method, int direction) {
    if (direction != 1 && direction != -1) throw InvalidArgument("home direction: +1 or -1");
    action(home_command(method, direction));
}
std::int64_t Client::home_correction() { return query("HCA"); }
void Client::set_home_correction(std::int64_t steps) { set("HCA", steps); }
bool Client::return_to_zero() { return query("RZ") != 0; }
void Client::set_return_to_zero(bool on) { set("RZ", on); }
std::int64_t Client::limit_correction() { return query("LCA"); }
void Client::set_limit_correction(std::int64_t steps) { set("LCA", steps); }

void Client::wait_idle(serial::Duration timeout, serial::Duration poll) {
    // A negative timeout waits forever; each poll is an interruption point (Ctrl-C).
    const bool forever = timeout.count() < 0;
    const auto deadline = std::chrono::steady_clock::now() + (forever ? serial::Duration::zero() : timeout);
    for (;;) {
        if (!moving()) return;
        if (!forever && std::chrono::steady_clock::now() >= deadline)
            throw TimeoutError("arcus: still moving after " +
                               std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count()) +
                               " ms");
        interruptible_sleep_for(poll);
    }
}

// ---- power and currents ---------------------------------------------------------------------

bool Client::enabled() { return query("EO") != 0; }
void Client::enable(bool on) { set("EO", on); }
bool Client::enabled_at_boot() { return query("EOBOOT") != 0; }
void Client::set_enabled_at_boot(bool on) { set("EOBOOT", on); }
std::int64_t Client::current() { return query("CUR"); }
std::int64_t Client::run_current() { return query("CURR"); }
void Client::set_run_current(std::int64_t ma) {
    if (ma < 100 || ma > 2500) throw InvalidArgument("CURR: must be 100..2500 mA");
    set("CURR", ma);
}
std::int64_t Client::idle_current() { return query("CURI"); }
void Client::set_idle_current(std::int64_t ma) {
    if (ma != 0 && (ma < 100 || ma > 2500)) throw InvalidArgument("CURI: must be 0 or 100..2500 mA");
    set("CURI", ma);
}
std::int64_t Client::idle_time() { return query("CURT"); }
void Client::set_idle_time(std::int64_t ms) { set("CURT", ms); }

// ---- I/O ---------------------------------------------------------------------------------------

unsigned Client::digital_inputs() { return static_cast<unsigned>(query("DI")) & 63u; }
bool Client::digital_input(int n) {
    check_index(n, 6, "DI");
    return query(glued("DI", n)) != 0;
}
unsigned Client::digital_outputs() { return static_cast<unsigned>(query("DO")) & 7u; }
void Client::set_digital_outputs(unsigned value) {
    if (value > 7) throw InvalidArgument("DO: must be 0..7");
    set("DO", value);
}
bool Client::digital_output(int n) {
    check_index(n, 3, "DO");
    return query(glued("DO", n)) != 0;
}
void Client::set_digital_output(int n, bool on) {
    check_index(n, 3, "DO");
    set(glued("DO", n), on);
}
unsigned Client::outputs_at_boot() { return static_cast<unsigned>(query("DOBOOT")); }
void Client::set_outputs_at_boot(unsigned value) {
    if (value > 7) throw InvalidArgument("DOBOOT: must be 0..7");
    set("DOBOOT", value);
}
bool Client::alarm_outputs() { return query("EDO") != 0; }
void Client::set_alarm_outputs(bool on) { set("EDO", on); }
unsigned Client::polarity() { return static_cast<unsigned>(query("POL")); }
void Client::set_polarity(unsigned bits) {
    if (bits > 511) throw InvalidArgument("POL: must be 0..511 (bits 0-8)");
    set("POL", bits);
}

// ---- latch and sync ------------------------------------------------------------------------------

void Client::enable_latch(bool on) { set("LT", on); }
LatchStatus Client::latch_status() {
    std::int64_t v = query("LTS");
    if (v < 0 || v > 2) throw ProtocolError("arcus: LTS out of range: " + std::to_string(v));
    return static_cast<LatchStatus>(v);
}
std::int64_t Client::latched_position() { return query("LTP"); }
std::int64_t Client::latched_encoder() { return query("LTE"); }
void Client::sync_on() { action("SYNO"); }
void Client::sync_off() { action("SYNF"); }
std::int64_t Client::sync_position() { return query("SYNP"); }
void Client::set_sync_position(std::int64_t p) {
    if (p < -(1 << 27) || p > (1 << 27) - 1) throw InvalidArgument("SYNP: must fit 28 bits signed");
    set("SYNP", p);
}
SyncCondition Client::sync_condition() {
    std::int64_t v = query("SYNC");
    if (v < 1 || v > 3) throw ProtocolError("arcus: SYNC out of range: " + std::to_string(v));
    return static_cast<SyncCondition>(v);
}
void Client::set_sync_condition(SyncCondition c) { set("SYNC", static_cast<int>(c)); }
SyncStatus Client::sync_status() {
    std::int64_t v = query("SYNS");
    if (v < 0 || v > 2) throw ProtocolError("arcus: SYNS out of range: " + std::to_string(v));
    return static_cast<SyncStatus>(v);
}

// ---- StepNLoop ---------------------------------------------------------------------------------------

bool Client::snl_enabled() { return query("SL") != 0; }
void Client::set_snl_enabled(bool on) { set("SL", on); }
std::int64_t Client::snl_tolerance() { return query("SLT"); }
void Client::set_snl_tolerance(std::int64_t c) { set("SLT", c); }
std::int64_t Client::snl_error_range() { return query("SLE"); }
void Client::set_snl_error_range(std::int64_t c) { set("SLE", c); }
std::int64_t Client::snl_max_attempts() { return query("SLA"); }
void Client::set_snl_max_attempts(std::int64_t n) { set("SLA", n); }
std::int64_t Client::snl_idle_tolerance() { return query("SLM"); }
void Client::set_snl_idle_tolerance(std::int64_t c) { set("SLM", c); }
double Client::snl_ratio() {
    auto body = transact("SLR", true);
    auto milli = parse_milli(body);
    if (!milli) {
        ++counters_.protocol_errors;
        throw ProtocolError("arcus: SLR -> '" + body + "' is not a ratio like 0.800");
    }
    return static_cast<double>(*milli) / 1000.0;
}
void Client::set_snl_ratio(double r) {
    const double milli = std::round(r * 1000.0);
    if (!std::isfinite(r) || milli < static_cast<double>(kSlrMinMilli) || milli > static_cast<double>(kSlrMaxMilli))
        throw InvalidArgument("arcus SLR: a ratio of 0.001..999.999 pulses per count, not " + std::to_string(r));
    const std::string cmd = "SLR=" + format_milli(static_cast<std::int64_t>(milli));
    expect_ok(cmd, transact(cmd, false));
}

// ---- communication ---------------------------------------------------------------------------------------

int Client::comm_mode() { return static_cast<int>(query("CM")); }
void Client::set_comm_mode(int mode) {
    if (mode < 0 || mode > 2) throw InvalidArgument("CM: must be 0..2");
    set("CM", mode);
}
int Client::baud_code() { return static_cast<int>(query("DB")); }
void Client::set_baud_code(int code) {
    if (code < 1 || code > 5) throw InvalidArgument("DB: must be 1..5");
    set("DB", code);
}
int Client::can_bit_rate_code() { return static_cast<int>(query("BR")); }
void Client::set_can_bit_rate_code(int code) {
    if (code < 1 || code > 9) throw InvalidArgument("BR: must be 1..9");
    set("BR", code);
}
int Client::node_id() { return static_cast<int>(query("NID")); }
void Client::set_node_id(int id) {
    if (id < 1 || id > 127) throw InvalidArgument("NID: must be 1..127");
    set("NID", id);
}

}  // namespace motorbus::arcus

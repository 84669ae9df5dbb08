// The DMX-CAN firmware's command handlers.  Each command of the codec's table
// (codec.cpp, kTable) has one handler per form it takes (query, set, action or
// argument); the table of handlers below is checked against the codec's at
// first use, so a command added to one and not the other fails every test
// instead of answering "?".
#include "motorbus/drives/arcus/sim_commands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace motorbus::arcus::sim_detail {

void save_flash(const std::string& path, Flash f) {
    if (path.empty()) return;
    std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::trunc);
        for (auto& [k, v] : f.fields()) out << k << '=' << *v << '\n';
        if (!out) return;
    }
    std::rename(tmp.c_str(), path.c_str());
}

std::string unknown_reply(std::string_view raw) {
    bool clean = std::all_of(raw.begin(), raw.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
    std::string reply = "?";
    if (clean && raw.size() <= kMaxRequest) reply.append(raw);
    return reply;
}

namespace {

using Op = ParsedCommand::Op;
using M = Homing::Method;

// One command being run: the state it acts on and the parts of the request.
struct Cmd {
    State& s;
    SimEngine e;
    motion::MotorModel& m;
    const SimOptions& o;
    Nanos now;
    const ParsedCommand& pc;
    std::string_view raw;
    std::optional<std::int64_t> v;  // the value of NAME=value / NAMEvalue
    bool busy;

    static std::string ok() { return "OK"; }
    static std::string num(std::int64_t x) { return std::to_string(x); }
    static std::string error(ErrorCode c) { return std::string(error_text(c)); }
    std::string unknown() const { return unknown_reply(raw); }
    bool in(std::int64_t lo, std::int64_t hi) const { return v && *v >= lo && *v <= hi; }
    // NAME=value into a field, refused ("?NAME=value") out of lo..hi.
    std::string set(std::int64_t& field, std::int64_t lo, std::int64_t hi) {
        if (!in(lo, hi)) return unknown();
        field = *v;
        return ok();
    }
    bool refuse_in_error() const { return s.minus_err || s.plus_err || s.snl.in_error(); }
    // §6: "When motor is disabled, no motion is done": the command is taken
    // (OK, no error of Table 11.1 fits) and no pulse goes out.
    bool disabled() const { return s.eo == 0; }
};

using Handler = std::string (*)(Cmd&);

struct Handlers {
    std::string_view name;
    Handler query = nullptr;
    Handler set = nullptr;  // called with a numeric value only, unless text_set
    Handler run = nullptr;  // action or argument
    bool text_set = false;  // the set handler parses pc.text_value itself (DN, SLR)
};

// ---- motion commands shared by several names ---------------------------------

std::string jog(Cmd& c, int dir) {
    State& s = c.s;
    if (c.refuse_in_error()) return Cmd::error(ErrorCode::StateError);
    if (c.disabled()) return Cmd::ok();
    s.idle_current_motion = false;
    c.e.configure_arcus();
    s.job = Job::Jog;
    s.stopping = false;
    s.snl.begin(motion::SnlActivity::Jog);
    s.arcus.jog(c.m.pulse_position(), dir);
    c.e.command_arcus();
    c.e.check_limit_at_start(c.e.physical_direction(dir), c.now);
    return Cmd::ok();
}

std::string home(Cmd& c, M method, int dir) {
    if (c.refuse_in_error()) return Cmd::error(ErrorCode::StateError);
    if (c.disabled()) return Cmd::ok();
    c.s.idle_current_motion = false;
    c.s.snl.begin(method == M::Z   ? motion::SnlActivity::ZHome
                  : method == M::L ? motion::SnlActivity::LimitHome
                                   : motion::SnlActivity::Home);
    c.e.start_homing(method, dir, c.now);
    return Cmd::ok();
}

// ---- queries with more than a field -------------------------------------------

std::string query_di(Cmd& c) {
    if (c.pc.index) return Cmd::num((c.s.inputs >> (c.pc.index - 1)) & 1u);
    return Cmd::num(c.s.inputs & 63u);
}

std::string query_do(Cmd& c) {
    std::int64_t o = c.e.outputs();
    if (c.pc.index) return Cmd::num((o >> (c.pc.index - 1)) & 1);
    return Cmd::num(o);
}

std::string query_dn(Cmd& c) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "DMC%02d", static_cast<int>(c.s.cfg.dn % 100));
    return buf;
}

// ---- sets with more than a range check -----------------------------------------

std::string set_dn(Cmd& c) {
    // DMC05, DMK05 or 05: the address is the two digits (docs/drives/arcus.md).
    std::string_view t = c.pc.text_value;
    if (t.size() == 5 && (t.substr(0, 3) == "DMC" || t.substr(0, 3) == "DMK")) t.remove_prefix(3);
    auto a = t.size() == 2 ? parse_int(t) : std::nullopt;
    if (!a || *a < 1 || *a > 99) return c.unknown();
    c.s.cfg.dn = *a;
    return Cmd::ok();
}

std::string set_slr(Cmd& c) {
    // Fixed point, three decimals (docs/drives/arcus.md): "SLR=0.8".
    auto milli = parse_milli(c.pc.text_value);
    if (!milli || *milli < kSlrMinMilli || *milli > kSlrMaxMilli) return c.unknown();
    if (c.busy) return Cmd::error(ErrorCode::Moving);
    c.s.cfg.slr = *milli;
    c.e.apply_wiring();
    c.e.configure_snl();
    return Cmd::ok();
}

std::string set_do(Cmd& c) {
    if (c.pc.index) {
        if (!c.in(0, 1)) return c.unknown();
        std::int64_t bit = std::int64_t{1} << (c.pc.index - 1);
        c.s.user_do = *c.v ? (c.s.user_do | bit) : (c.s.user_do & ~bit);
    } else {
        if (!c.in(0, 7)) return c.unknown();
        c.s.user_do = *c.v;
    }
    return Cmd::ok();
}

// ACC and DEC: times in ms, clamped to what the speeds allow.
std::string set_ramp(Cmd& c, std::int64_t& field) {
    if (!c.in(1, INT32_MAX)) return c.unknown();
    field = clamp_acc_ms(*c.v, c.s.hspd, c.s.lspd);
    return Cmd::ok();
}

std::string set_curi(Cmd& c) {
    if (!(c.in(0, 0) || c.in(100, 2500))) return c.unknown();
    c.s.cfg.curi = *c.v;
    return Cmd::ok();
}

std::string set_eo(Cmd& c) {
    State& s = c.s;
    if (!c.in(0, 1)) return c.unknown();
    s.eo = *c.v;
    if (!s.eo && c.m.moving()) {
        // Power off: the pulses stop at once, as ABORT (no motion is done).
        if (s.homing && s.homing->running()) s.homing->abort();
        c.m.halt();
        c.e.end_job(c.now);
    }
    c.e.apply_jam();
    return Cmd::ok();
}

std::string set_ex(Cmd& c) {
    c.m.set_encoder(*c.v);
    if (c.e.snl_on()) c.m.set_pulse_position(static_cast<double>(*c.v));
    return Cmd::ok();
}

std::string set_px(Cmd& c) {
    c.m.set_pulse_position(static_cast<double>(*c.v));
    if (c.e.snl_on()) c.m.set_encoder(*c.v);
    return Cmd::ok();
}

std::string set_lt(Cmd& c) {
    if (!c.in(0, 1)) return c.unknown();
    c.s.lt = *c.v;
    if (*c.v) c.m.arm_latch();
    else c.m.disarm_latch();
    return Cmd::ok();
}

std::string set_pol(Cmd& c) {
    auto r = c.set(c.s.cfg.pol, 0, 511);
    c.e.apply_wiring();
    return r;
}

std::string set_sl(Cmd& c) {
    State& s = c.s;
    if (!c.in(0, 1)) return c.unknown();
    if (c.busy) return Cmd::error(ErrorCode::Moving);
    if (*c.v != s.cfg.sl) {
        // Position units change: counts with SNL, pulses without.
        std::int64_t ex = c.e.encoder();
        c.m.set_pulse_position(*c.v ? static_cast<double>(ex) : std::round(static_cast<double>(ex) * c.e.slr()));
    }
    s.cfg.sl = *c.v;
    c.e.apply_wiring();
    c.e.configure_snl();
    s.snl.clear();
    return Cmd::ok();
}

// StepNLoop parameters (SLA, SLE, SLM, SLT): stored, then handed to the StepNLoop machine.
std::string set_snl(Cmd& c, std::int64_t& field) {
    auto r = c.set(field, 0, INT32_MAX);
    c.e.configure_snl();
    return r;
}

// ---- arguments --------------------------------------------------------------

std::string run_x(Cmd& c) {
    State& s = c.s;
    if (!c.v) return c.unknown();
    if (c.refuse_in_error()) return Cmd::error(ErrorCode::StateError);
    double from = c.m.pulse_position();
    double target = s.inc_mode ? from + static_cast<double>(*c.v) : static_cast<double>(*c.v);
    if (std::abs(target - from) > static_cast<double>(kMaxIncrement)) return c.unknown();
    c.e.configure_arcus();
    if (s.arcus.move(from, target) != MotionReply::Ok) return c.unknown();
    if (c.disabled()) return Cmd::ok();
    s.idle_current_motion = false;
    s.job = Job::Target;
    s.stopping = false;
    s.snl.begin(motion::SnlActivity::Move);
    c.e.command_arcus();
    if (!c.m.moving()) {
        c.e.end_job(c.now);
        return Cmd::ok();
    }
    c.e.check_limit_at_start(c.e.physical_direction(target - from), c.now);
    return Cmd::ok();
}

std::string run_t(Cmd& c) {
    State& s = c.s;
    if (!c.v) return c.unknown();
    if (!c.busy || s.job != Job::Target || s.stopping || !s.arcus_profile)
        return Cmd::error(ErrorCode::MotorNotMoving);
    // The profile model's frame differs from PX by a constant shift.
    const double t = c.e.arcus_time();
    const double shift = s.arcus.profile().position(t) - c.m.pulse_position();
    auto r = s.arcus.change_target(t, static_cast<double>(*c.v) + shift);
    if (r != MotionReply::Ok) return arcus_reply_text(r);
    c.m.revise(s.arcus.profile());
    return Cmd::ok();
}

std::string run_sspd(Cmd& c) {
    State& s = c.s;
    if (!c.v || *c.v <= 0) return Cmd::error(ErrorCode::BadSspd);
    if (s.scv) return Cmd::error(ErrorCode::ScvOn);
    // The window is in PPS; under StepNLoop the value is in counts/s.
    double pps = static_cast<double>(*c.v) * (c.e.snl_on() ? c.e.slr() : 1.0);
    auto wdw = window_for_sspdm(s.sspdm);
    if (!wdw || pps < static_cast<double>(wdw->hspd_min) || pps > static_cast<double>(wdw->hspd_max))
        return Cmd::error(ErrorCode::SpeedOutOfRange);
    // A target move or a jog (the homing routines run their own speeds).
    if (!c.busy || s.stopping || !s.arcus_profile || (s.job != Job::Target && s.job != Job::Jog))
        return Cmd::error(ErrorCode::BadSspd);
    s.arcus.set_sspdm(static_cast<int>(s.sspdm));
    auto r = s.arcus.change_speed(c.e.arcus_time(), static_cast<double>(*c.v));
    if (r != MotionReply::Ok) return arcus_reply_text(r);
    c.m.revise(s.arcus.profile());
    return Cmd::ok();
}

// ---- actions ------------------------------------------------------------------

std::string run_abort(Cmd& c) {
    State& s = c.s;
    if (s.homing && s.homing->running()) s.homing->abort();
    c.m.halt();
    s.job = Job::None;
    s.stopping = false;
    // Table 11.0: ABORT clears the StepNLoop error status, the limit error
    // (SLS 11) included; MST's limit error bits stay until CLR (Table 7.3).
    s.snl.clear();
    s.idle_since = c.now;
    return Cmd::ok();
}

std::string run_stop(Cmd& c) {
    State& s = c.s;
    if (c.busy) {
        if (s.job == Job::Home && s.homing && s.homing->running()) {
            s.homing->stop();
            s.job = Job::Stop;
        } else if (s.arcus_profile) {
            s.arcus.stop(c.e.arcus_time());
            c.m.revise(s.arcus.profile());
            if (s.job != Job::Jog) s.job = Job::Stop;
        }
        s.stopping = true;
        if (!c.m.moving()) c.e.motion_done(c.now);
    }
    return Cmd::ok();
}

std::string run_clr(Cmd& c) {
    c.s.minus_err = c.s.plus_err = false;
    c.s.snl.clear();
    return Cmd::ok();
}

std::string run_clrs(Cmd& c) {
    if (c.s.snl.status() != motion::SnlStatus::LimitError) c.s.snl.clear();
    return Cmd::ok();
}

std::string run_store(Cmd& c) {
    c.s.flash = c.s.cfg;
    c.s.stored = true;
    save_flash(c.o.store_path, c.s.flash);
    return Cmd::ok();
}

std::string run_syno(Cmd& c) {
    State& s = c.s;
    s.sync_on = true;
    s.sync_hit = false;
    std::int64_t ex = c.e.encoder();
    if (s.sync_cond != 1 || ex == s.synp) c.e.check_sync(ex, ex);
    return Cmd::ok();
}

std::string run_synf(Cmd& c) {
    c.s.sync_on = false;
    c.s.sync_hit = false;
    c.s.user_do &= ~std::int64_t{2};
    return Cmd::ok();
}

// ---- the table ------------------------------------------------------------------
// Short handlers are written in place; `[](Cmd& c) { ... }` converts to Handler.
#define MB_Q(expr) [](Cmd& c) -> std::string { return Cmd::num(expr); }
#define MB_SET(field, lo, hi) [](Cmd& c) { return c.set(field, lo, hi); }

const Handlers kHandlers[] = {
    {"ABORT", nullptr, nullptr, run_abort},
    {"ABS", nullptr, nullptr, [](Cmd& c) { c.s.inc_mode = 0; return Cmd::ok(); }},
    {"ACC", MB_Q(c.s.acc), [](Cmd& c) { return set_ramp(c, c.s.acc); }},
    {"BR", MB_Q(c.s.cfg.br), MB_SET(c.s.cfg.br, 1, 9)},
    {"CLR", nullptr, nullptr, run_clr},
    {"CLRS", nullptr, nullptr, run_clrs},
    {"CM", MB_Q(c.s.cfg.cm), MB_SET(c.s.cfg.cm, 0, 2)},
    {"CUR", MB_Q(c.e.current(c.now))},
    {"CURI", MB_Q(c.s.cfg.curi), set_curi},
    {"CURR", MB_Q(c.s.cfg.curr), MB_SET(c.s.cfg.curr, 100, 2500)},
    {"CURT", MB_Q(c.s.cfg.curt), MB_SET(c.s.cfg.curt, 0, INT32_MAX)},
    {"DB", MB_Q(c.s.cfg.db), MB_SET(c.s.cfg.db, 1, 5)},
    {"DEC", MB_Q(c.s.dec), [](Cmd& c) { return set_ramp(c, c.s.dec); }},
    {"DI", query_di},
    {"DN", query_dn, set_dn, nullptr, true},
    {"DO", query_do, set_do},
    {"DOBOOT", MB_Q(c.s.cfg.doboot), MB_SET(c.s.cfg.doboot, 0, 7)},
    {"DX", MB_Q(c.e.delta())},
    {"EDEC", MB_Q(c.s.edec), MB_SET(c.s.edec, 0, 1)},
    {"EDO", MB_Q(c.s.cfg.edo), MB_SET(c.s.cfg.edo, 0, 1)},
    {"EO", MB_Q(c.s.eo), set_eo},
    {"EOBOOT", MB_Q(c.s.cfg.eoboot), MB_SET(c.s.cfg.eoboot, 0, 1)},
    {"EX", MB_Q(c.e.encoder()), set_ex},
    {"H+", nullptr, nullptr, [](Cmd& c) { return home(c, M::H, 1); }},
    {"H-", nullptr, nullptr, [](Cmd& c) { return home(c, M::H, -1); }},
    {"HCA", MB_Q(c.s.hca), MB_SET(c.s.hca, 0, INT32_MAX)},
    {"HL+", nullptr, nullptr, [](Cmd& c) { return home(c, M::HL, 1); }},
    {"HL-", nullptr, nullptr, [](Cmd& c) { return home(c, M::HL, -1); }},
    {"HSPD", MB_Q(c.s.hspd), MB_SET(c.s.hspd, 1, 6'000'000)},
    {"ID", [](Cmd&) -> std::string { return "DriveMax-CAN"; }},
    {"INC", nullptr, nullptr, [](Cmd& c) { c.s.inc_mode = 1; return Cmd::ok(); }},
    {"J+", nullptr, nullptr, [](Cmd& c) { return jog(c, 1); }},
    {"J-", nullptr, nullptr, [](Cmd& c) { return jog(c, -1); }},
    {"L+", nullptr, nullptr, [](Cmd& c) { return home(c, M::L, 1); }},
    {"L-", nullptr, nullptr, [](Cmd& c) { return home(c, M::L, -1); }},
    {"LCA", MB_Q(c.s.cfg.lca), MB_SET(c.s.cfg.lca, 0, INT32_MAX)},
    {"LSPD", MB_Q(c.s.lspd), MB_SET(c.s.lspd, 1, 6'000'000)},
    {"LT", MB_Q(c.s.lt), set_lt},
    {"LTE", MB_Q(c.s.lte)},
    {"LTP", MB_Q(c.s.ltp)},
    {"LTS", MB_Q(static_cast<int>(c.m.latch_state()))},
    {"MM", MB_Q(c.s.inc_mode)},
    {"MST", MB_Q(c.e.mst())},
    {"NID", MB_Q(c.s.cfg.nid), MB_SET(c.s.cfg.nid, 1, 127)},
    {"POL", MB_Q(c.s.cfg.pol), set_pol},
    {"PS", MB_Q(std::llround(std::fabs(c.m.pulse_velocity())))},
    {"PX", MB_Q(c.e.pulse()), set_px},
    {"RT", MB_Q(c.s.cfg.rt), MB_SET(c.s.cfg.rt, 0, 1)},
    {"RZ", MB_Q(c.s.rz), MB_SET(c.s.rz, 0, 1)},
    {"SCV", MB_Q(c.s.scv), MB_SET(c.s.scv, 0, 1)},
    {"SL", MB_Q(c.s.cfg.sl), set_sl},
    {"SLA", MB_Q(c.s.cfg.sla), [](Cmd& c) { return set_snl(c, c.s.cfg.sla); }},
    {"SLE", MB_Q(c.s.cfg.sle), [](Cmd& c) { return set_snl(c, c.s.cfg.sle); }},
    {"SLM", MB_Q(c.s.cfg.slm), [](Cmd& c) { return set_snl(c, c.s.cfg.slm); }},
    {"SLR", [](Cmd& c) { return format_milli(c.s.cfg.slr); }, set_slr, nullptr, true},
    {"SLS", MB_Q(c.e.sls())},
    {"SLT", MB_Q(c.s.cfg.slt), [](Cmd& c) { return set_snl(c, c.s.cfg.slt); }},
    {"SSPD", nullptr, nullptr, run_sspd},
    {"SSPDM", MB_Q(c.s.sspdm), MB_SET(c.s.sspdm, 0, 9)},
    {"STOP", nullptr, nullptr, run_stop},
    {"STORE", nullptr, nullptr, run_store},
    {"SYNC", MB_Q(c.s.sync_cond), MB_SET(c.s.sync_cond, 1, 3)},
    {"SYNF", nullptr, nullptr, run_synf},
    {"SYNO", nullptr, nullptr, run_syno},
    {"SYNP", MB_Q(c.s.synp), MB_SET(c.s.synp, -kSyncMax - 1, kSyncMax)},
    {"SYNS", MB_Q(c.s.sync_on ? (c.s.sync_hit ? 2 : 1) : 0)},
    {"T", nullptr, nullptr, run_t},
    {"VER", [](Cmd&) -> std::string { return "V106"; }},
    {"X", nullptr, nullptr, run_x},
    {"Z+", nullptr, nullptr, [](Cmd& c) { return home(c, M::Z, 1); }},
    {"Z-", nullptr, nullptr, [](Cmd& c) { return home(c, M::Z, -1); }},
    {"ZH+", nullptr, nullptr, [](Cmd& c) { return home(c, M::ZH, 1); }},
    {"ZH-", nullptr, nullptr, [](Cmd& c) { return home(c, M::ZH, -1); }},
};

#undef MB_Q
#undef MB_SET

// The handlers in the order of the codec's table, so a parsed command finds
// its own by its CommandInfo's position.  Throws std::logic_error when the two
// tables disagree (a command, or a form of one, without its handler).
const std::vector<const Handlers*>& by_codec_position() {
    static const std::vector<const Handlers*> table = [] {
        const auto codec = command_table();
        std::vector<const Handlers*> out(codec.size(), nullptr);
        for (const Handlers& h : kHandlers) {
            const CommandInfo* info = find_command(h.name);
            if (!info) throw std::logic_error("arcus sim: handler for " + std::string(h.name) + ", not in the codec");
            out[static_cast<std::size_t>(info - codec.data())] = &h;
        }
        for (std::size_t i = 0; i < codec.size(); ++i) {
            const CommandInfo& c = codec[i];
            const Handlers* h = out[i];
            const bool runs = (c.forms & (kAction | kArgument)) != 0;
            if (!h || bool(c.forms & kQuery) != bool(h->query) || bool(c.forms & kSet) != bool(h->set) ||
                runs != bool(h->run))
                throw std::logic_error("arcus sim: the handlers of " + std::string(c.name) +
                                       " differ from the codec's forms");
        }
        return out;
    }();
    return table;
}

}  // namespace

std::string run_command(State& s, const SimOptions& options, Nanos now, const ParsedCommand& pc,
                        std::string_view raw) {
    Cmd c{s, SimEngine(s, options), *s.motor, options, now, pc, raw, pc.value, s.motor->moving()};
    const Handlers& h = *by_codec_position()[static_cast<std::size_t>(pc.info - command_table().data())];
    switch (pc.op) {
    case Op::Query:
        return h.query ? h.query(c) : c.unknown();
    case Op::Set:
        // Every set but DN's and SLR's takes an integer.
        if (!h.set || (!h.text_set && !c.v)) return c.unknown();
        return h.set(c);
    case Op::Action:
    case Op::Argument:
        return h.run ? h.run(c) : c.unknown();
    }
    return c.unknown();
}

}  // namespace motorbus::arcus::sim_detail

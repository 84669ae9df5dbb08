#include "motorbus/drives/arcus/sim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "motorbus/drives/arcus/sim_core.hpp"

namespace motorbus::arcus {


// ------------------------------------------------------------------------------

Sim::Sim(Clock& clock, SimOptions options)
    : clock_(clock), options_(std::move(options)), s_(std::make_unique<State>()) {
    if (options_.address < 1 || options_.address > kMaxAddress)
        throw InvalidArgument("arcus sim address: must be 1..99");
    if (options_.response_type != 0 && options_.response_type != 1)
        throw InvalidArgument("arcus sim response_type: must be 0 or 1");
    if (options_.tick_ns <= 0) throw InvalidArgument("arcus sim tick_ns: must be > 0");
    s_->motor = std::make_unique<motion::MotorModel>(clock_, motor_config(options_));
    s_->motor->displace(options_.world.start_position);
    State* sp = s_.get();
    const SimOptions* op = &options_;
    s_->motor->add_listener([sp, op](const motion::MotorEvent& e) { SimEngine(*sp, *op).on_event(e); });
    if (options_.comm_type < 0 || options_.comm_type > 2)
        throw InvalidArgument("arcus sim comm_type: must be 0 (RS-232), 1 (RS-485) or 2 (CAN)");
    if (options_.node_id < 1 || options_.node_id > 127) throw InvalidArgument("arcus sim node_id: must be 1..127");
    if (options_.bit_rate < 1 || options_.bit_rate > 9)
        throw InvalidArgument("arcus sim bit_rate: a 200Bh code 1..9 (10k 20k 50k 100k 125k 250k 500k 800k 1M)");
    if (options_.store_ns < 0 || options_.clear_ns < 0)
        throw InvalidArgument("arcus sim store/clear duration: must be >= 0");
    std::lock_guard lock(mutex_);
    boot();
}

Sim::Sim(std::shared_ptr<Clock> clock, SimOptions options)
    : Sim((clock ? *clock : throw InvalidArgument("arcus sim: clock is null")), std::move(options)) {
    clock_owner_ = std::move(clock);
}

Sim::~Sim() { detach_can(); }

namespace {

bool load_flash(const std::string& path, Flash& f) {
    if (path.empty()) return false;
    std::ifstream in(path);
    if (!in) return false;
    Flash tmp = f;
    auto fields = tmp.fields();
    std::string line;
    while (std::getline(in, line)) {
        auto eq = line.find('=');
        if (eq == std::string::npos) continue;
        auto it = fields.find(line.substr(0, eq));
        auto v = parse_int(std::string_view(line).substr(eq + 1));
        if (it != fields.end() && v) *it->second = *v;
    }
    f = tmp;
    return true;
}

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

}  // namespace

void Sim::power_cycle() {
    std::optional<can::Frame> boot_up;
    {
        std::lock_guard lock(mutex_);
        boot();
        boot_up = boot_up_frame();
    }
    if (boot_up) send_frames({*boot_up});
}

void Sim::boot() {
    State& s = *s_;
    const Nanos now = clock_.now();
    SimEngine(s, options_).advance(now);
    if (s.homing) s.homing.reset();
    if (s.homing_listener) s.motor->remove_listener(s.homing_listener);
    auto motor = std::move(s.motor);  // the shaft stays where it is
    unsigned inputs = s.inputs;
    bool blocked = s.blocked;
    // The flash outlives the power cycle, store file or not (issue 23 #1).
    const bool stored = s.stored;
    const Flash kept = s.flash;
    s = State{};
    s.motor = std::move(motor);
    s.inputs = inputs;
    s.blocked = blocked;
    s.flash.dn = options_.address;
    s.flash.rt = options_.response_type;
    s.flash.eoboot = options_.eo_boot ? 1 : 0;
    s.flash.sl = options_.snl ? 1 : 0;
    s.flash.cm = options_.comm_type;
    s.flash.nid = options_.node_id;
    s.flash.br = options_.bit_rate;
    if (options_.comm_type == 2) {
        // A unit set up for CANopen: the CANopen tables' defaults (Tables 8.11,
        // 8.21, where the ASCII persona follows Table 7.11; docs/drives/arcus.md).
        s.flash.slt = 10;
        s.flash.curr = 1500;
        s.flash.curi = 500;
    }
    load_flash(options_.store_path, s.flash);
    if (stored) {
        // What this simulator stored (the file, when there is one, holds the same).
        s.flash = kept;
        s.stored = true;
    }
    s.cfg = s.flash;
    s.active_address = static_cast<int>(std::clamp<std::int64_t>(s.cfg.dn, 1, 99));
    s.active_rt = s.cfg.rt ? 1 : 0;
    s.active_cm = static_cast<int>(std::clamp<std::int64_t>(s.cfg.cm, 0, 2));
    s.active_nid = static_cast<int>(std::clamp<std::int64_t>(s.cfg.nid, 1, 127));
    s.active_br = static_cast<int>(s.cfg.br);
    bit_rate_code_.store(s.active_br);
    s.eo = s.cfg.eoboot ? 1 : 0;
    s.user_do = s.cfg.doboot & 7;
    motion::MotorModel& m = *s.motor;
    m.halt();
    m.disarm_latch();
    SimEngine e(s, options_);
    e.apply_wiring();
    m.set_pulse_position(0);  // counters start at 0
    m.set_encoder(0);
    e.configure_snl();
    s.idle_since = now - s.cfg.curt * 1'000'000 - 1;
}

int Sim::address() const {
    std::lock_guard lock(mutex_);
    return s_->active_address;
}

std::string Sim::store_path() const { return options_.store_path; }

#define MOTORBUS_ARCUS_SYNC()            \
    std::lock_guard lock(mutex_);        \
    SimEngine e(*s_, options_);          \
    e.advance(clock_.now())

void Sim::set_input(int index, bool actuated) {
    if (index < 1 || index > 6) throw InvalidArgument("arcus sim input: index must be 1..6");
    MOTORBUS_ARCUS_SYNC();
    bool before = e.latch_in();
    unsigned bit = 1u << (index - 1);
    s_->inputs = actuated ? (s_->inputs | bit) : (s_->inputs & ~bit);
    auto& m = *s_->motor;
    if (!before && e.latch_in() && m.latch_state() == motion::MotorModel::LatchState::Armed) {
        m.trigger_latch();
        s_->ltp = std::llround(m.latched_pulse());
        s_->lte = m.latched_encoder();
    }
}

void Sim::force_home(std::optional<bool> actuated) {
    MOTORBUS_ARCUS_SYNC();
    s_->motor->force_switch(motion::Switch::Home, actuated);
}

void Sim::force_limit(int direction, std::optional<bool> actuated) {
    MOTORBUS_ARCUS_SYNC();
    s_->motor->force_switch(direction > 0 ? motion::Switch::PlusLimit : motion::Switch::MinusLimit, actuated);
}

void Sim::set_blocked(bool blocked) {
    MOTORBUS_ARCUS_SYNC();
    s_->blocked = blocked;
    e.apply_jam();
}

void Sim::disturb(double steps) {
    MOTORBUS_ARCUS_SYNC();
    const std::int64_t enc_prev = e.encoder();
    s_->motor->displace(steps);
    if (s_->motor->moving()) e.sample(enc_prev);
    else if (s_->job == Job::None) e.verify_position(/*idle=*/true);
}

double Sim::physical_position() const {
    MOTORBUS_ARCUS_SYNC();
    return s_->motor->physical_position();
}

std::int64_t Sim::pulse_position() {
    MOTORBUS_ARCUS_SYNC();
    return e.pulse();
}
std::int64_t Sim::encoder_position() {
    MOTORBUS_ARCUS_SYNC();
    return e.encoder();
}
std::int64_t Sim::motor_status() {
    MOTORBUS_ARCUS_SYNC();
    return e.mst();
}
int Sim::snl_status() {
    MOTORBUS_ARCUS_SYNC();
    return e.sls();
}
bool Sim::busy() {
    MOTORBUS_ARCUS_SYNC();
    return s_->motor->moving();
}

std::string Sim::on_line(std::string_view line) {
    // A burst of noise before the '@' does not hide the request: the device's
    // parser restarts at every '@'.
    auto at = line.rfind('@');
    if (at == std::string_view::npos) return "";
    auto req = parse_request_line(line.substr(at));
    if (!req) return "";
    try {
        std::lock_guard lock(mutex_);
        // Stored as CAN and power-cycled: the serial line is silent (B-A01).
        if (s_->active_cm == 2) return "";
        if (req->address != kBroadcast && req->address != s_->active_address) return "";
        std::string body = handle(*req);
        if (req->address == kBroadcast) return "";
        return format_reply(s_->active_address, body, s_->active_rt);
    } catch (const std::exception&) {
        return "";  // never let a bug in one command take the line down
    }
}

// The firmware's command interpreter, reached by the CANopen front end: both
// front ends end in the same commands on the same state.  mutex_ held.
std::string Sim::command(std::string_view cmd) {
    Request req;
    req.address = s_->active_address;
    req.command = std::string(cmd);
    return handle(req);
}

// Runs one command; returns the reply body.  mutex_ held.
std::string Sim::handle(const Request& req) {
    State& s = *s_;
    SimEngine e(s, options_);
    Nanos now = at_.value_or(clock_.now());
    e.advance(now);
    motion::MotorModel& m = *s.motor;

    const std::string& cmd = req.command;
    auto unknown = [&] {
        bool clean = std::all_of(cmd.begin(), cmd.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
        return clean && cmd.size() <= kMaxRequest ? "?" + cmd : std::string("?");
    };
    auto pc = parse_command(cmd);
    if (!pc) return unknown();
    const CommandInfo& info = *pc->info;
    const std::string_view name = info.name;
    using Op = ParsedCommand::Op;
    auto num = [](std::int64_t v) { return std::to_string(v); };
    const std::string ok = "OK";

    if (!pc->index_valid) return std::string(error_text(ErrorCode::IndexOutOfRange));
    bool busy = m.moving();
    if (info.motion && pc->op != Op::Query && busy) return std::string(error_text(ErrorCode::Moving));

    // Value checks for "NAME=value".
    std::optional<std::int64_t> v = pc->value;
    auto in = [&](std::int64_t lo, std::int64_t hi) { return v && *v >= lo && *v <= hi; };

    auto refuse_in_error = [&] { return s.minus_err || s.plus_err || s.snl.in_error(); };
    // §6: "When motor is disabled, no motion is done": the command is taken
    // (OK, no error of Table 11.1 fits) and no pulse goes out.
    auto disabled = [&] { return s.eo == 0; };
    auto jog = [&](int dir) -> std::string {
        if (refuse_in_error()) return std::string(error_text(ErrorCode::StateError));
        if (disabled()) return ok;
        s.idle_current_motion = false;
        e.configure_arcus();
        s.job = Job::Jog;
        s.stopping = false;
        s.snl.begin(motion::SnlActivity::Jog);
        s.arcus.jog(m.pulse_position(), dir);
        e.command_arcus();
        e.check_limit_at_start(e.physical_direction(dir), now);
        return ok;
    };
    auto home = [&](Homing::Method method, int dir) -> std::string {
        if (refuse_in_error()) return std::string(error_text(ErrorCode::StateError));
        if (disabled()) return ok;
        s.idle_current_motion = false;
        using M = Homing::Method;
        s.snl.begin(method == M::Z   ? motion::SnlActivity::ZHome
                    : method == M::L ? motion::SnlActivity::LimitHome
                                     : motion::SnlActivity::Home);
        e.start_homing(method, dir, now);
        return ok;
    };

    if (pc->op == Op::Query) {
        if (name == "DI") {
            if (pc->index) return num((s.inputs >> (pc->index - 1)) & 1u);
            return num(s.inputs & 63u);
        }
        if (name == "DO") {
            std::int64_t o = e.outputs();
            if (pc->index) return num((o >> (pc->index - 1)) & 1);
            return num(o);
        }
        if (name == "ACC") return num(s.acc);
        if (name == "BR") return num(s.cfg.br);
        if (name == "CM") return num(s.cfg.cm);
        if (name == "CUR") return num(e.current(now));
        if (name == "CURI") return num(s.cfg.curi);
        if (name == "CURR") return num(s.cfg.curr);
        if (name == "CURT") return num(s.cfg.curt);
        if (name == "DB") return num(s.cfg.db);
        if (name == "DEC") return num(s.dec);
        if (name == "DN") {
            char buf[8];
            std::snprintf(buf, sizeof buf, "DMC%02d", static_cast<int>(s.cfg.dn % 100));
            return buf;
        }
        if (name == "DOBOOT") return num(s.cfg.doboot);
        if (name == "DX") return num(e.delta());
        if (name == "EDEC") return num(s.edec);
        if (name == "EDO") return num(s.cfg.edo);
        if (name == "EO") return num(s.eo);
        if (name == "EOBOOT") return num(s.cfg.eoboot);
        if (name == "EX") return num(e.encoder());
        if (name == "HCA") return num(s.hca);
        if (name == "HSPD") return num(s.hspd);
        if (name == "ID") return "DriveMax-CAN";
        if (name == "LCA") return num(s.cfg.lca);
        if (name == "LSPD") return num(s.lspd);
        if (name == "LT") return num(s.lt);
        if (name == "LTE") return num(s.lte);
        if (name == "LTP") return num(s.ltp);
        if (name == "LTS") return num(static_cast<int>(m.latch_state()));
        if (name == "MM") return num(s.inc_mode);
        if (name == "MST") return num(e.mst());
        if (name == "NID") return num(s.cfg.nid);
        if (name == "POL") return num(s.cfg.pol);
        if (name == "PS") return num(std::llround(std::fabs(m.pulse_velocity())));
        if (name == "PX") return num(e.pulse());
        if (name == "RT") return num(s.cfg.rt);
        if (name == "RZ") return num(s.rz);
        if (name == "SCV") return num(s.scv);
        if (name == "SL") return num(s.cfg.sl);
        if (name == "SLA") return num(s.cfg.sla);
        if (name == "SLE") return num(s.cfg.sle);
        if (name == "SLM") return num(s.cfg.slm);
        if (name == "SLR") return format_milli(s.cfg.slr);
        if (name == "SLS") return num(e.sls());
        if (name == "SLT") return num(s.cfg.slt);
        if (name == "SSPDM") return num(s.sspdm);
        if (name == "SYNC") return num(s.sync_cond);
        if (name == "SYNP") return num(s.synp);
        if (name == "SYNS") return num(s.sync_on ? (s.sync_hit ? 2 : 1) : 0);
        if (name == "VER") return "V106";
        return unknown();
    }

    if (pc->op == Op::Set) {
        if (name == "DN") {
            // DMC05, DMK05 or 05: the manual writes the name all three ways; the
            // address is the two digits (docs/drives/arcus.md, readings).
            std::string_view t = pc->text_value;
            if (t.size() == 5 && (t.substr(0, 3) == "DMC" || t.substr(0, 3) == "DMK")) t.remove_prefix(3);
            auto a = t.size() == 2 ? parse_int(t) : std::nullopt;
            if (!a || *a < 1 || *a > 99) return unknown();
            s.cfg.dn = *a;
            return ok;
        }
        if (name == "SLR") {
            // Fixed point, three decimals (docs/drives/arcus.md): "SLR=0.8".
            auto milli = parse_milli(pc->text_value);
            if (!milli || *milli < kSlrMinMilli || *milli > kSlrMaxMilli) return unknown();
            if (busy) return std::string(error_text(ErrorCode::Moving));
            s.cfg.slr = *milli;
            e.apply_wiring();
            e.configure_snl();
            return ok;
        }
        if (!v) return unknown();
        if (name == "DO") {
            if (pc->index) {
                if (!in(0, 1)) return unknown();
                std::int64_t bit = std::int64_t{1} << (pc->index - 1);
                s.user_do = *v ? (s.user_do | bit) : (s.user_do & ~bit);
            } else {
                if (!in(0, 7)) return unknown();
                s.user_do = *v;
            }
            return ok;
        }
        auto set = [&](std::int64_t& field, std::int64_t lo, std::int64_t hi) -> std::string {
            if (!in(lo, hi)) return unknown();
            field = *v;
            return ok;
        };
        if (name == "ACC") {
            if (!in(1, INT32_MAX)) return unknown();
            s.acc = clamp_acc_ms(*v, s.hspd, s.lspd);
            return ok;
        }
        if (name == "DEC") {
            if (!in(1, INT32_MAX)) return unknown();
            s.dec = clamp_acc_ms(*v, s.hspd, s.lspd);
            return ok;
        }
        if (name == "BR") return set(s.cfg.br, 1, 9);
        if (name == "CM") return set(s.cfg.cm, 0, 2);
        if (name == "CURI") {
            if (!(in(0, 0) || in(100, 2500))) return unknown();
            s.cfg.curi = *v;
            return ok;
        }
        if (name == "CURR") return set(s.cfg.curr, 100, 2500);
        if (name == "CURT") return set(s.cfg.curt, 0, INT32_MAX);
        if (name == "DB") return set(s.cfg.db, 1, 5);
        if (name == "DOBOOT") return set(s.cfg.doboot, 0, 7);
        if (name == "EDEC") return set(s.edec, 0, 1);
        if (name == "EDO") return set(s.cfg.edo, 0, 1);
        if (name == "EO") {
            if (!in(0, 1)) return unknown();
            s.eo = *v;
            if (!s.eo && m.moving()) {
                // Power off: the pulses stop at once, as ABORT (no motion is done).
                if (s.homing && s.homing->running()) s.homing->abort();
                m.halt();
                e.end_job(now);
            }
            e.apply_jam();
            return ok;
        }
        if (name == "EOBOOT") return set(s.cfg.eoboot, 0, 1);
        if (name == "EX") {
            m.set_encoder(*v);
            if (e.snl_on()) m.set_pulse_position(static_cast<double>(*v));
            return ok;
        }
        if (name == "PX") {
            m.set_pulse_position(static_cast<double>(*v));
            if (e.snl_on()) m.set_encoder(*v);
            return ok;
        }
        if (name == "HCA") return set(s.hca, 0, INT32_MAX);
        if (name == "HSPD") return set(s.hspd, 1, 6'000'000);
        if (name == "LSPD") return set(s.lspd, 1, 6'000'000);
        if (name == "LCA") return set(s.cfg.lca, 0, INT32_MAX);
        if (name == "LT") {
            if (!in(0, 1)) return unknown();
            s.lt = *v;
            if (*v) m.arm_latch();
            else m.disarm_latch();
            return ok;
        }
        if (name == "NID") return set(s.cfg.nid, 1, 127);
        if (name == "POL") {
            auto r = set(s.cfg.pol, 0, 511);
            e.apply_wiring();
            return r;
        }
        if (name == "RT") return set(s.cfg.rt, 0, 1);
        if (name == "RZ") return set(s.rz, 0, 1);
        if (name == "SCV") return set(s.scv, 0, 1);
        if (name == "SL") {
            if (!in(0, 1)) return unknown();
            if (busy) return std::string(error_text(ErrorCode::Moving));
            if (*v != s.cfg.sl) {
                // Position units change: counts with SNL, pulses without.
                std::int64_t ex = e.encoder();
                m.set_pulse_position(*v ? static_cast<double>(ex) : std::round(static_cast<double>(ex) * e.slr()));
            }
            s.cfg.sl = *v;
            e.apply_wiring();
            e.configure_snl();
            s.snl.clear();
            return ok;
        }
        // StepNLoop parameters: stored, then handed to the StepNLoop machine.
        if (name == "SLA" || name == "SLE" || name == "SLM" || name == "SLT") {
            auto& field = name == "SLA" ? s.cfg.sla : name == "SLE" ? s.cfg.sle : name == "SLM" ? s.cfg.slm : s.cfg.slt;
            auto r = set(field, 0, INT32_MAX);
            e.configure_snl();
            return r;
        }
        if (name == "SSPDM") return set(s.sspdm, 0, 9);
        if (name == "SYNC") return set(s.sync_cond, 1, 3);
        if (name == "SYNP") return set(s.synp, -kSyncMax - 1, kSyncMax);
        return unknown();
    }

    if (pc->op == Op::Argument) {
        if (name == "X") {
            if (!v) return unknown();
            if (refuse_in_error()) return std::string(error_text(ErrorCode::StateError));
            double from = m.pulse_position();
            double target = s.inc_mode ? from + static_cast<double>(*v) : static_cast<double>(*v);
            if (std::abs(target - from) > static_cast<double>(kMaxIncrement)) return unknown();
            e.configure_arcus();
            if (s.arcus.move(from, target) != ArcusReply::Ok) return unknown();
            if (disabled()) return ok;
            s.idle_current_motion = false;
            s.job = Job::Target;
            s.stopping = false;
            s.snl.begin(motion::SnlActivity::Move);
            e.command_arcus();
            if (!m.moving()) {
                e.end_job(now);
                return ok;
            }
            e.check_limit_at_start(e.physical_direction(target - from), now);
            return ok;
        }
        if (name == "T") {
            if (!v) return unknown();
            if (!busy || s.job != Job::Target || s.stopping || !s.arcus_profile)
                return std::string(error_text(ErrorCode::MotorNotMoving));
            // The profile model's frame differs from PX by a constant shift.
            const double t = e.arcus_time();
            const double shift = s.arcus.profile().position(t) - m.pulse_position();
            auto r = s.arcus.change_target(t, static_cast<double>(*v) + shift);
            if (r != ArcusReply::Ok) return arcus_reply_text(r);
            m.revise(s.arcus.profile());
            return ok;
        }
        if (name == "SSPD") {
            if (!v || *v <= 0) return std::string(error_text(ErrorCode::BadSspd));
            if (s.scv) return std::string(error_text(ErrorCode::ScvOn));
            // The window is in PPS; under StepNLoop the value is in counts/s.
            double pps = static_cast<double>(*v) * (e.snl_on() ? e.slr() : 1.0);
            auto wdw = window_for_sspdm(s.sspdm);
            if (!wdw || pps < static_cast<double>(wdw->hspd_min) || pps > static_cast<double>(wdw->hspd_max))
                return std::string(error_text(ErrorCode::SpeedOutOfRange));
            // A target move or a jog (the homing routines run their own speeds).
            if (!busy || s.stopping || !s.arcus_profile || (s.job != Job::Target && s.job != Job::Jog))
                return std::string(error_text(ErrorCode::BadSspd));
            s.arcus.set_sspdm(static_cast<int>(s.sspdm));
            auto r = s.arcus.change_speed(e.arcus_time(), static_cast<double>(*v));
            if (r != ArcusReply::Ok) return arcus_reply_text(r);
            m.revise(s.arcus.profile());
            return ok;
        }
        return unknown();
    }

    // Actions.
    if (name == "ABORT") {
        if (s.homing && s.homing->running()) s.homing->abort();
        m.halt();
        s.job = Job::None;
        s.stopping = false;
        // Table 11.0: ABORT clears the StepNLoop error status, the limit error
        // (SLS 11) included; MST's limit error bits stay until CLR (Table 7.3).
        s.snl.clear();
        s.idle_since = now;
        return ok;
    }
    if (name == "STOP") {
        if (busy) {
            if (s.job == Job::Home && s.homing && s.homing->running()) {
                s.homing->stop();
                s.job = Job::Stop;
            } else if (s.arcus_profile) {
                s.arcus.stop(e.arcus_time());
                m.revise(s.arcus.profile());
                if (s.job != Job::Jog) s.job = Job::Stop;
            }
            s.stopping = true;
            if (!m.moving()) e.motion_done(now);
        }
        return ok;
    }
    if (name == "CLR") {
        s.minus_err = s.plus_err = false;
        s.snl.clear();
        return ok;
    }
    if (name == "CLRS") {
        if (s.snl.status() != motion::SnlStatus::LimitError) s.snl.clear();
        return ok;
    }
    if (name == "ABS") { s.inc_mode = 0; return ok; }
    if (name == "INC") { s.inc_mode = 1; return ok; }
    if (name == "STORE") {
        s.flash = s.cfg;
        s.stored = true;
        save_flash(options_.store_path, s.flash);
        return ok;
    }
    if (name == "SYNO") {
        s.sync_on = true;
        s.sync_hit = false;
        std::int64_t ex = e.encoder();
        if (s.sync_cond != 1 || ex == s.synp) e.check_sync(ex, ex);
        return ok;
    }
    if (name == "SYNF") {
        s.sync_on = false;
        s.sync_hit = false;
        s.user_do &= ~std::int64_t{2};
        return ok;
    }
    using M = Homing::Method;
    if (name == "J+") return jog(1);
    if (name == "J-") return jog(-1);
    if (name == "H+") return home(M::H, 1);
    if (name == "H-") return home(M::H, -1);
    if (name == "HL+") return home(M::HL, 1);
    if (name == "HL-") return home(M::HL, -1);
    if (name == "ZH+") return home(M::ZH, 1);
    if (name == "ZH-") return home(M::ZH, -1);
    if (name == "Z+") return home(M::Z, 1);
    if (name == "Z-") return home(M::Z, -1);
    if (name == "L+") return home(M::L, 1);
    if (name == "L-") return home(M::L, -1);
    return unknown();
}

}  // namespace motorbus::arcus

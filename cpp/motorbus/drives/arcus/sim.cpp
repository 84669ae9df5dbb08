#include "motorbus/drives/arcus/sim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "motorbus/drives/arcus/profile.hpp"
#include "motorbus/drives/arcus/homing.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/stepnloop.hpp"

namespace motorbus::arcus {

namespace {

// The DMX-CAN's own StepNLoop ratio: 3200 steps per 4000 counts (SLR 0.800).
constexpr std::int64_t kFactorySlrMilli = 800;
constexpr std::int64_t kSyncMax = (1 << 27) - 1;  // SYNP is a 28-bit signed number

// Flash contents (Table 7.10) with the Table 7.11 factory defaults.
struct Flash {
    std::int64_t br = 5, cm = 0, curi = 1000, curr = 1600, curt = 500, db = 1, dn = 1,
                 doboot = 7, edo = 1, eoboot = 0, lca = 1000, pol = 0, rt = 0, sl = 1,
                 sla = 10, sle = 1000, slm = 5, slt = 20, nid = 1, slr = kFactorySlrMilli;

    std::map<std::string, std::int64_t*> fields() {
        return {{"BR", &br},     {"CM", &cm},         {"CURI", &curi}, {"CURR", &curr},
                {"CURT", &curt}, {"DB", &db},         {"DN", &dn},     {"DOBOOT", &doboot},
                {"EDO", &edo},   {"EOBOOT", &eoboot}, {"LCA", &lca},   {"POL", &pol},
                {"RT", &rt},     {"SL", &sl},         {"SLA", &sla},   {"SLE", &sle},
                {"SLM", &slm},   {"SLR", &slr},       {"SLT", &slt},   {"NID", &nid}};
    }
};

// What the axis is doing, for SLS and for what happens when the motion ends.
enum class Job { None, Target, Correct, Jog, Stop, Home };

// The world as the motor model sees it.  The switches read active where they
// are actuated; POL bits 4 and 5 invert that at run time.
motion::MotorConfig motor_config(const SimOptions& o) {
    const SimWorld& w = o.world;
    motion::MotorConfig c;  // 3200 steps and 4000 counts per rev: the DMX-CAN's
    c.index_position = w.z_position;
    c.index_width_steps = w.z_width;
    c.home = motion::SwitchConfig{true, w.home_lo, w.home_hi, false};
    c.minus_limit = motion::SwitchConfig{w.minus_limit.has_value(), w.minus_limit.value_or(0), 0, false};
    c.plus_limit = motion::SwitchConfig{w.plus_limit.has_value(), w.plus_limit.value_or(0), 0, false};
    c.tick_ns = o.tick_ns;
    return c;
}

}  // namespace

struct Sim::State {
    Flash flash;       // what STORE writes / boot reads
    Flash cfg;         // live values of the stored items
    int active_address = 1;
    int active_rt = 0;

    // Volatile parameters (not in Table 7.10; reset at boot).
    std::int64_t hspd = 1000, lspd = 100, acc = 300, dec = 300, edec = 0, scv = 0, hca = 100,
                 rz = 0, sspdm = 0, inc_mode = 0, eo = 0, user_do = 0, lt = 0, synp = 0,
                 sync_cond = 1;
    bool sync_on = false, sync_hit = false;
    std::int64_t ltp = 0, lte = 0;

    // The motor and its world (rotor, encoder, switches, Z, latch, jam).  It
    // outlives power cycles: the shaft stays where it is.
    std::unique_ptr<motion::MotorModel> motor;
    // X, J, T, SSPD, STOP: the profile model; the motor runs its profile
    // while arcus_profile is true.
    ArcusMotion arcus{ArcusProfileParams{}};
    bool arcus_profile = false;
    // H, HL, L, Z, ZH (declared after the motor: destroyed before it).
    std::unique_ptr<ArcusHoming> homing;
    int homing_listener = 0;  // runs after the homing's own listener
    int home_direction = 1;   // physical direction of the search

    Job job = Job::None;
    bool stopping = false;
    motion::StepNLoop snl{motion::SnlConfig{}};  // the position verification state machine (errors 8..11)
    bool minus_err = false, plus_err = false;

    bool blocked = false;
    // The running (or last) motion is an SLM correction: Table 7.5 runs it on
    // idle current.
    bool idle_current_motion = false;
    unsigned inputs = 0;  // DI1..DI6 actuated
    Nanos idle_since = 0;
};

// ------------------------------------------------------------------------------
// Everything below runs with mutex_ held.
using State = Sim::State;

// The drive's firmware around the motor model: the sim's behaviour, split out
// of the class so the header stays small.
class SimEngine {
public:
    SimEngine(State& s, const SimOptions& o) : s(s), o(o) {}
    State& s;
    const SimOptions& o;

    motion::MotorModel& m() const { return *s.motor; }
    bool snl_on() const { return s.cfg.sl != 0; }
    // SLR: pulses per encoder count, the ratio StepNLoop converts with.
    double slr() const { return static_cast<double>(s.cfg.slr) / 1000.0; }
    // Position units: encoder counts with StepNLoop (SLR pulses each), pulses
    // without; POL bit 1 reverses.
    double steps_per_unit() const { return (snl_on() ? slr() : 1.0) * ((s.cfg.pol & 2) ? -1.0 : 1.0); }
    int physical_direction(double units_direction) const {
        const double d = units_direction * steps_per_unit();
        return d > 0 ? 1 : (d < 0 ? -1 : 0);
    }
    std::int64_t pulse() const { return m().pulse_count(); }
    std::int64_t encoder() const { return m().encoder(); }
    std::int64_t delta() const { return snl_on() ? pulse() - encoder() : 0; }
    bool latch_in() const { return bool(s.inputs & 2u) != bool(s.cfg.pol & 64); }

    // POL, SL, EO and the jam into the motor model.
    void apply_wiring() {
        using motion::Switch;
        m().set_steps_per_unit(steps_per_unit());
        m().set_switch_inverted(Switch::Home, (s.cfg.pol & 32) != 0);
        m().set_switch_inverted(Switch::MinusLimit, (s.cfg.pol & 16) != 0);
        m().set_switch_inverted(Switch::PlusLimit, (s.cfg.pol & 16) != 0);
        apply_jam();
    }
    // An unpowered (EO=0) or blocked rotor stays put while the pulses go out.
    void apply_jam() { m().set_jammed(s.blocked || !s.eo); }

    ArcusProfileParams profile_params(double hspd_override = -1) const {
        ArcusProfileParams ap;
        ap.snl_ratio = snl_on() ? slr() : 1.0;
        // arcus_effective refuses speeds outside 1..6 000 000 PPS; the sim
        // validates HSPD/LSPD itself, so only clamp what unit conversion moved.
        const double min_units = 1.0 / ap.snl_ratio;
        const double max_units = 6'000'000.0 / ap.snl_ratio;
        const double hspd = hspd_override > 0 ? hspd_override : static_cast<double>(s.hspd);
        ap.hspd = std::clamp(hspd, min_units, max_units);
        ap.lspd = std::clamp(static_cast<double>(std::min(s.lspd, s.hspd)), 1e-6, ap.hspd);
        ap.acc_ms = std::max(static_cast<double>(s.acc), 1e-3);
        ap.dec_ms = std::max(static_cast<double>(s.dec), 1e-3);
        ap.edec = s.edec != 0;
        ap.scv = s.scv != 0;
        return ap;
    }
    void configure_arcus(double hspd_override = -1) {
        s.arcus.set_params(profile_params(hspd_override));
        s.arcus.set_sspdm(static_cast<int>(std::clamp<std::int64_t>(s.sspdm, 0, 9)));
    }
    void command_arcus() {
        m().command(s.arcus.profile());
        s.arcus_profile = true;
    }
    double arcus_time() const { return m().profile_time(m().time()); }

    int sls() const {
        if (!snl_on()) return 12;
        if (s.snl.in_error()) return static_cast<int>(s.snl.status());
        switch (s.job) {
            case Job::None: return 0;
            case Job::Target: return s.stopping ? 3 : 1;
            case Job::Correct: return 2;
            case Job::Jog: return s.stopping ? 3 : 5;
            case Job::Stop: return 3;
            case Job::Home: return s.homing ? s.homing->snl_status() : 6;
        }
        return 0;
    }

    // MST bits 0..2.
    ArcusPhase phase() const {
        if (!m().moving()) return ArcusPhase::Idle;
        if (s.arcus_profile) return s.arcus.phase(arcus_time());
        const double v = m().pulse_velocity(), a = m().commanded_acceleration() * (steps_per_unit() > 0 ? 1 : -1);
        if (v * a > 0) return ArcusPhase::Accel;
        if (v * a < 0) return ArcusPhase::Decel;
        return ArcusPhase::Const;
    }

    std::int64_t mst() const {
        std::int64_t v = 0;
        const auto ph = phase();
        if (ph == ArcusPhase::Const) v |= 1;
        if (ph == ArcusPhase::Accel) v |= 2;
        if (ph == ArcusPhase::Decel) v |= 4;
        if (m().home_active()) v |= 8;
        if (m().minus_limit_active()) v |= 16;
        if (m().plus_limit_active()) v |= 32;
        if (s.minus_err) v |= 64;
        if (s.plus_err) v |= 128;
        if (latch_in()) v |= 256;
        if (m().index_active()) v |= 512;
        return v;
    }

    bool in_position() const {
        return snl_on() && !m().moving() && !s.snl.in_error() && std::llabs(delta()) <= s.cfg.slt;
    }

    std::int64_t outputs() const {
        std::int64_t v = s.user_do & 7;
        bool dedicated = snl_on() && s.cfg.edo;
        if (dedicated) {
            // POL bit 7 inverts the in-position output, bit 8 the alarm (Table 7.2).
            const bool in_pos = in_position() != ((s.cfg.pol & 128) != 0);
            const bool alarm = s.snl.in_error() != ((s.cfg.pol & 256) != 0);
            v = (v & ~std::int64_t{5}) | (in_pos ? 1 : 0) | (alarm ? 4 : 0);
        }
        if (s.sync_on) {
            // EQUAL is a pulse "only when the encoder position and sync position
            // are equal"; LESS/GREATER stay on once the condition occurred.
            const bool on = s.sync_cond == 1 ? encoder() == s.synp : s.sync_hit;
            v = (v & ~std::int64_t{2}) | (on ? 2 : 0);
        }
        return v;
    }

    std::int64_t current(Nanos now) const {
        if (!s.eo) return 0;
        bool running = m().moving() || now - s.idle_since < s.cfg.curt * 1'000'000;
        return running && !s.idle_current_motion ? s.cfg.curr : s.cfg.curi;
    }

    void configure_snl() {
        motion::SnlConfig c;
        c.enabled = snl_on();
        c.tolerance = static_cast<std::uint32_t>(s.cfg.slt);
        c.error_range = static_cast<std::uint32_t>(s.cfg.sle);
        c.max_attempts = static_cast<std::uint32_t>(s.cfg.sla);
        c.idle_tolerance = static_cast<std::uint32_t>(s.cfg.slm);
        c.ratio = slr();
        s.snl.configure(c);
    }

    // Table 7.7, motor idle: in position, a correction move, or an error.
    void verify_position(bool idle = false) {
        if (!snl_on()) return;
        const double d = static_cast<double>(pulse() - encoder());
        auto dec = idle ? s.snl.idle_check(d) : s.snl.motion_done(d);
        if (dec.action != motion::SnlAction::Correct) return;
        // Re-run the remaining distance at low speed from where the encoder says we are.
        const double target = m().pulse_position();
        const double from = target - dec.correction;
        m().set_pulse_position(from);
        configure_arcus(static_cast<double>(std::min(s.lspd, s.hspd)));
        s.idle_current_motion = dec.idle_current;
        s.job = Job::Correct;
        s.stopping = false;
        if (s.arcus.move(from, target) == ArcusReply::Ok) command_arcus();
        if (!m().moving()) s.job = Job::None;
    }

    // The motion stopped without a target to verify.
    void end_job(Nanos t) {
        s.job = Job::None;
        s.stopping = false;
        s.idle_since = t;
        s.snl.end_without_verification();
    }

    // A limit in the direction of travel stops the motor at once and latches
    // the limit error (MST bits 6/7, SLS 11).
    void limit_stop(int side, Nanos t) {
        if (s.homing && s.homing->running()) s.homing->abort();
        m().halt();
        (side > 0 ? s.plus_err : s.minus_err) = true;
        s.snl.limit_hit();
        end_job(t);
    }
    // Motion starting into a limit that is already active: the event that
    // would announce it never comes.
    void check_limit_at_start(int physical_dir, Nanos t) {
        if (physical_dir > 0 && m().plus_limit_active()) limit_stop(1, t);
        else if (physical_dir < 0 && m().minus_limit_active()) limit_stop(-1, t);
    }

    void check_sync(std::int64_t a, std::int64_t b) {
        bool hit = false;
        switch (s.sync_cond) {
            case 1: hit = std::min(a, b) <= s.synp && s.synp <= std::max(a, b); break;
            case 2: hit = b < s.synp; break;
            case 3: hit = b > s.synp; break;
        }
        if (hit) s.sync_hit = true;
    }

    // ---- the motor's events ----
    void on_event(const motion::MotorEvent& e) {
        using K = motion::MotorEvent::Kind;
        switch (e.kind) {
            case K::PlusLimitOn:
            case K::MinusLimitOn: {
                const int side = e.kind == K::PlusLimitOn ? 1 : -1;
                if (e.direction != side) break;
                // Limit homing runs onto its limit on purpose: ArcusHoming backs off.
                if (s.job == Job::Home && s.homing && s.homing->running() &&
                    s.homing->method() == ArcusHoming::Method::L && side == s.home_direction)
                    break;
                limit_stop(side, e.t);
                break;
            }
            case K::ProfileDone:
                motion_done(e.t);
                break;
            default:
                break;
        }
    }

    void motion_done(Nanos t) {
        s.idle_since = t;
        switch (s.job) {
            case Job::Target:
            case Job::Correct:
                s.job = Job::None;
                s.stopping = false;
                verify_position();
                break;
            case Job::Jog:
            case Job::Stop:
                end_job(t);
                break;
            case Job::Home:  // the homing's own listener decides; after_homing_event ends the job
            case Job::None:
                break;
        }
    }

    // Runs after ArcusHoming's listener.
    void after_homing_event(const motion::MotorEvent& e) {
        if (s.job == Job::Home && s.homing && !s.homing->running()) end_homing(e.t);
    }

    void end_homing(Nanos t) {
        if (s.homing->result() == motion::HomingResult::LimitError) {
            (s.home_direction > 0 ? s.plus_err : s.minus_err) = true;
            s.snl.limit_hit();
        }
        end_job(t);
    }

    void start_homing(ArcusHoming::Method method, int dir, Nanos now) {
        if (s.homing) s.homing.reset();
        if (s.homing_listener) m().remove_listener(s.homing_listener);
        ArcusHomingOptions ho;
        ho.hca = static_cast<double>(s.hca);
        ho.lca = static_cast<double>(s.cfg.lca);
        ho.rz = s.rz != 0;
        ho.zero_encoder = true;  // PX and EX both read 0 at home
        s.homing = std::make_unique<ArcusHoming>(m(), profile_params(), ho);
        State* sp = &s;
        const SimOptions* op = &o;
        s.homing_listener =
            m().add_listener([sp, op](const motion::MotorEvent& e) { SimEngine(*sp, *op).after_homing_event(e); });
        s.job = Job::Home;
        s.stopping = false;
        s.arcus_profile = false;
        s.home_direction = physical_direction(dir);
        s.homing->start(method, dir);
        if (!s.homing->running()) end_homing(now);
    }

    // The drive's sampling of the encoder between events: the StepNLoop
    // delta (stall error 10) and the DO2 sync comparator.
    void sample(std::int64_t enc_prev) {
        if (s.sync_on && !s.sync_hit) check_sync(enc_prev, encoder());
        if (snl_on() && m().moving() &&
            s.snl.monitor(static_cast<double>(pulse() - encoder())).action == motion::SnlAction::StopNow) {
            if (s.homing && s.homing->running()) s.homing->abort();
            m().halt();  // stall error (10)
            s.job = Job::None;
            s.stopping = false;
            s.idle_since = m().time();
        }
    }

    // Brings the motor to `now`.  The delta only changes while the rotor is
    // held (a follower rotor keeps it constant between events), and the sync
    // comparator only matters while armed: only then is the motion sampled
    // every tick; otherwise the model runs from event to event.
    void advance(Nanos now) {
        while (m().time() < now) {
            const bool sampled =
                m().moving() && ((s.sync_on && !s.sync_hit) || (snl_on() && (s.blocked || !s.eo)));
            if (!sampled) {
                m().advance_to(now);
                break;
            }
            // A long unobserved stretch is sampled at most ~1e6 times.
            const Nanos span = now - m().time();
            const Nanos step = std::min<Nanos>(span, std::max<Nanos>(o.tick_ns, span / 1'000'000));
            const std::int64_t enc_prev = encoder();
            m().advance_to(m().time() + step);
            sample(enc_prev);
        }
    }
};

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
    power_cycle();
}

Sim::Sim(std::shared_ptr<Clock> clock, SimOptions options)
    : Sim((clock ? *clock : throw InvalidArgument("arcus sim: clock is null")), std::move(options)) {
    clock_owner_ = std::move(clock);
}

Sim::~Sim() = default;

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
    std::lock_guard lock(mutex_);
    State& s = *s_;
    const Nanos now = clock_.now();
    SimEngine(s, options_).advance(now);
    if (s.homing) s.homing.reset();
    if (s.homing_listener) s.motor->remove_listener(s.homing_listener);
    auto motor = std::move(s.motor);  // the shaft stays where it is
    unsigned inputs = s.inputs;
    bool blocked = s.blocked;
    s = State{};
    s.motor = std::move(motor);
    s.inputs = inputs;
    s.blocked = blocked;
    s.flash.dn = options_.address;
    s.flash.rt = options_.response_type;
    s.flash.eoboot = options_.eo_boot ? 1 : 0;
    s.flash.sl = options_.snl ? 1 : 0;
    load_flash(options_.store_path, s.flash);
    s.cfg = s.flash;
    s.active_address = static_cast<int>(std::clamp<std::int64_t>(s.cfg.dn, 1, 99));
    s.active_rt = s.cfg.rt ? 1 : 0;
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
        if (req->address != kBroadcast && req->address != s_->active_address) return "";
        std::string body = handle(*req);
        if (req->address == kBroadcast) return "";
        return format_reply(s_->active_address, body, s_->active_rt);
    } catch (const std::exception&) {
        return "";  // never let a bug in one command take the line down
    }
}

// Runs one command; returns the reply body.  mutex_ held.
std::string Sim::handle(const Request& req) {
    State& s = *s_;
    SimEngine e(s, options_);
    Nanos now = clock_.now();
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
    auto home = [&](ArcusHoming::Method method, int dir) -> std::string {
        if (refuse_in_error()) return std::string(error_text(ErrorCode::StateError));
        if (disabled()) return ok;
        s.idle_current_motion = false;
        using M = ArcusHoming::Method;
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
            // DMC05, DMK05 or 05: the address is the two digits (DESIGN.md).
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
    using M = ArcusHoming::Method;
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

#include "motorbus/drives/arcus/sim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "motorbus/drives/arcus/profile.hpp"
#include "motorbus/motion/stepnloop.hpp"

namespace motorbus::arcus {

namespace {

constexpr double kStepsPerRev = 3200;
constexpr double kCountsPerStep = 4000.0 / 3200.0;
constexpr std::int64_t kSyncMax = (1 << 27) - 1;  // SYNP is a 28-bit signed number

// Flash contents (Table 7.10) with the Table 7.11 factory defaults.
struct Flash {
    std::int64_t br = 5, cm = 0, curi = 1000, curr = 1600, curt = 500, db = 1, dn = 1,
                 doboot = 7, edo = 1, eoboot = 0, lca = 1000, pol = 0, rt = 0, sl = 1,
                 sla = 10, sle = 1000, slm = 5, slt = 20, nid = 1;

    std::map<std::string, std::int64_t*> fields() {
        return {{"BR", &br},     {"CM", &cm},         {"CURI", &curi}, {"CURR", &curr},
                {"CURT", &curt}, {"DB", &db},         {"DN", &dn},     {"DOBOOT", &doboot},
                {"EDO", &edo},   {"EOBOOT", &eoboot}, {"LCA", &lca},   {"POL", &pol},
                {"RT", &rt},     {"SL", &sl},         {"SLA", &sla},   {"SLE", &sle},
                {"SLM", &slm},   {"SLT", &slt},       {"NID", &nid}};
    }
};

enum class Job { None, Target, Correct, Jog, Stop, HomeH, HomeHL, HomeZH, HomeZ, HomeL };

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
    int latch_state = 0;
    std::int64_t ltp = 0, lte = 0;

    // Motion.
    detail::Axis axis;
    Job job = Job::None;
    int phase = 0;
    int home_dir = 1;
    double move_target = 0;
    motion::StepNLoop snl{motion::SnlConfig{}};  // the position verification state machine (errors 8..11)
    bool minus_err = false, plus_err = false;

    // The motor and its world.
    double phys = 0;
    std::int64_t enc_offset = 0;
    bool blocked = false;
    unsigned inputs = 0;  // DI1..DI6 actuated
    std::optional<bool> force_home, force_minus, force_plus;

    Nanos t = 0;
    Nanos idle_since = 0;
};

Sim::Sim(Clock& clock, SimOptions options)
    : clock_(clock), options_(std::move(options)), s_(std::make_unique<State>()) {
    if (options_.address < 1 || options_.address > kMaxAddress)
        throw InvalidArgument("arcus sim address: must be 1..99");
    if (options_.response_type != 0 && options_.response_type != 1)
        throw InvalidArgument("arcus sim response_type: must be 0 or 1");
    if (options_.tick_ns <= 0) throw InvalidArgument("arcus sim tick_ns: must be > 0");
    s_->phys = options_.world.start_position;
    power_cycle();
}

Sim::Sim(std::shared_ptr<Clock> clock, SimOptions options)
    : Sim((clock ? *clock : throw InvalidArgument("arcus sim: clock is null")), std::move(options)) {
    clock_owner_ = std::move(clock);
}

Sim::~Sim() = default;

// ------------------------------------------------------------------------------
// Everything below runs with mutex_ held.
// Helpers are free functions on State to keep the class header small.
namespace {

using State = Sim::State;

bool snl_on(const State& s) { return s.cfg.sl != 0; }
double steps_per_unit(const State& s) { return snl_on(s) ? 1.0 / kCountsPerStep : 1.0; }
int dir_sign(const State& s) { return (s.cfg.pol & 2) ? -1 : 1; }

std::int64_t encoder(const State& s) {
    return std::llround(s.phys * kCountsPerStep) + s.enc_offset;
}
std::int64_t pulse(const State& s) { return std::llround(s.axis.position()); }
std::int64_t delta(const State& s) { return snl_on(s) ? pulse(s) - encoder(s) : 0; }

bool in_interval(double x, double lo, double hi) { return x >= lo && x <= hi; }

bool home_actuated(const State& s, const SimWorld& w, double phys) {
    if (s.force_home) return *s.force_home;
    return in_interval(phys, w.home_lo, w.home_hi);
}
bool minus_actuated(const State& s, const SimWorld& w, double phys) {
    if (s.force_minus) return *s.force_minus;
    return w.minus_limit && phys <= *w.minus_limit;
}
bool plus_actuated(const State& s, const SimWorld& w, double phys) {
    if (s.force_plus) return *s.force_plus;
    return w.plus_limit && phys >= *w.plus_limit;
}
// Polarity bit set = the input's sense is inverted.
bool home_in(const State& s, const SimWorld& w, double p) {
    return home_actuated(s, w, p) != bool(s.cfg.pol & 32);
}
bool minus_in(const State& s, const SimWorld& w, double p) {
    return minus_actuated(s, w, p) != bool(s.cfg.pol & 16);
}
bool plus_in(const State& s, const SimWorld& w, double p) {
    return plus_actuated(s, w, p) != bool(s.cfg.pol & 16);
}
bool latch_in(const State& s) { return bool(s.inputs & 2u) != bool(s.cfg.pol & 64); }
bool z_in(const SimWorld& w, double p) {
    double m = std::fmod(p - w.z_position, kStepsPerRev);
    if (m < 0) m += kStepsPerRev;
    return m < w.z_width;
}

// Fraction of the step [a, b] at which `level` first becomes true (0 if already).
template <class F>
std::optional<double> first_true(double a, double b, F level) {
    if (level(a)) return 0.0;
    if (!level(b)) return std::nullopt;
    double lo = 0, hi = 1;
    for (int i = 0; i < 40; ++i) {
        double mid = 0.5 * (lo + hi);
        if (level(a + (b - a) * mid)) hi = mid;
        else lo = mid;
    }
    return hi;
}

// Z index crossing (the window is narrow enough to be jumped over in one step).
std::optional<double> z_fraction(const SimWorld& w, double a0, double b0) {
    if (z_in(w, a0)) return 0.0;
    if (b0 == a0) return std::nullopt;
    double a = a0 - w.z_position, b = b0 - w.z_position;
    if (b > a) {
        double m = std::ceil(a / kStepsPerRev) * kStepsPerRev;
        if (m <= b) return (m - a) / (b - a);
    } else {
        double m = std::floor(a / kStepsPerRev) * kStepsPerRev + w.z_width;
        if (m > a) m -= kStepsPerRev;
        if (m >= b) return (a - m) / (a - b);
    }
    return std::nullopt;
}

}  // namespace

// The sim's behaviour, split out of the class so the header stays small.
class SimEngine {
public:
    SimEngine(State& s, const SimOptions& o) : s(s), o(o) {}
    State& s;
    const SimOptions& o;

    // ---- configuration of a motion from the live parameters ----
    void configure_axis(double hspd_override = -1) {
        detail::Axis::Params p;
        p.hspd = static_cast<double>(hspd_override > 0 ? hspd_override : s.hspd);
        p.lspd = static_cast<double>(std::min(s.lspd, s.hspd));
        p.acc_ms = static_cast<double>(s.acc);
        p.dec_ms = static_cast<double>(s.dec);
        p.edec = s.edec != 0;
        p.scurve = s.scv != 0;
        p.snl_ratio = snl_on(s) ? 1.0 / kCountsPerStep : 1.0;
        p.sspdm = static_cast<int>(s.sspdm);
        s.axis.configure(p);
    }

    void zero_counters_at(double cmd_at, double phys_at) {
        s.axis.set_position(s.axis.position() - cmd_at);
        s.move_target -= cmd_at;
        s.enc_offset = -std::llround(phys_at * kCountsPerStep);
    }
    void zero_here() { zero_counters_at(s.axis.position(), s.phys); }

    void set_error_limit(int dir) {
        (dir > 0 ? s.plus_err : s.minus_err) = true;
        s.snl.limit_hit();
        s.job = Job::None;
    }

    int sls() const {
        if (!snl_on(s)) return 12;
        if (s.snl.in_error()) return static_cast<int>(s.snl.status());
        switch (s.job) {
            case Job::None: return 0;
            case Job::Target: return s.axis.stopping() ? 3 : 1;
            case Job::Correct: return 2;
            case Job::Jog: return s.axis.stopping() ? 3 : 5;
            case Job::Stop: return 3;
            case Job::HomeH:
            case Job::HomeHL: return 6;
            case Job::HomeZH: return s.phase >= 2 ? 7 : 6;
            case Job::HomeZ: return 7;
            case Job::HomeL: return 13;
        }
        return 0;
    }

    std::int64_t mst() const {
        std::int64_t v = 0;
        if (s.axis.constant()) v |= 1;
        if (s.axis.accelerating()) v |= 2;
        if (s.axis.decelerating()) v |= 4;
        if (home_in(s, o.world, s.phys)) v |= 8;
        if (minus_in(s, o.world, s.phys)) v |= 16;
        if (plus_in(s, o.world, s.phys)) v |= 32;
        if (s.minus_err) v |= 64;
        if (s.plus_err) v |= 128;
        if (latch_in(s)) v |= 256;
        if (z_in(o.world, s.phys)) v |= 512;
        return v;
    }

    bool in_position() const {
        return snl_on(s) && !s.axis.busy() && !s.snl.in_error() &&
               std::llabs(delta(s)) <= s.cfg.slt;
    }

    std::int64_t outputs() const {
        std::int64_t v = s.user_do & 7;
        bool dedicated = snl_on(s) && s.cfg.edo;
        if (dedicated) {
            v = (v & ~std::int64_t{5}) | (in_position() ? 1 : 0) | (s.snl.in_error() ? 4 : 0);
        }
        if (s.sync_on) v = (v & ~std::int64_t{2}) | (s.sync_hit ? 2 : 0);
        return v;
    }

    std::int64_t current(Nanos now) const {
        if (!s.eo) return 0;
        bool running = s.axis.busy() || now - s.idle_since < s.cfg.curt * 1'000'000;
        return running ? s.cfg.curr : s.cfg.curi;
    }

    // ---- SNL position verification at the end of a target move / when idle ----
    void configure_snl() {
        motion::SnlConfig c;
        c.enabled = snl_on(s);
        c.tolerance = static_cast<std::uint32_t>(s.cfg.slt);
        c.error_range = static_cast<std::uint32_t>(s.cfg.sle);
        c.max_attempts = static_cast<std::uint32_t>(s.cfg.sla);
        c.idle_tolerance = static_cast<std::uint32_t>(s.cfg.slm);
        c.ratio = 1.0 / kCountsPerStep;
        s.snl.configure(c);
    }

    // Table 7.7, motor idle: in position, a correction move, or an error.
    void verify_position(bool idle = false) {
        if (!snl_on(s)) return;
        double delta = static_cast<double>(pulse(s) - encoder(s));
        auto d = idle ? s.snl.idle_check(delta) : s.snl.motion_done(delta);
        if (d.action != motion::SnlAction::Correct) return;
        // Re-run the remaining distance at low speed from where the encoder says we are.
        double target = s.axis.position();
        s.axis.set_position(target - d.correction);
        configure_axis(static_cast<double>(std::min(s.lspd, s.hspd)));
        s.job = Job::Correct;
        s.axis.move_to(target);
        if (!s.axis.busy()) s.job = Job::None;
    }

    // ---- one integration step ----
    void tick(double dt, Nanos now) {
        double cmd_prev = s.axis.position(), phys_prev = s.phys;
        std::int64_t enc_prev = encoder(s);
        bool stopped = s.axis.step(dt);
        double dcmd = s.axis.position() - cmd_prev;
        if (s.eo && !s.blocked) s.phys += dcmd * steps_per_unit(s) * dir_sign(s);
        double dphys = s.phys - phys_prev;
        auto cmd_at = [&](double f) { return cmd_prev + f * dcmd; };
        auto phys_at = [&](double f) { return phys_prev + f * dphys; };
        auto stop_at = [&](double f) {
            s.axis.halt();
            s.axis.set_position(cmd_at(f));
            s.phys = phys_at(f);
        };
        const SimWorld& w = o.world;
        int travel = dcmd > 0 ? 1 : (dcmd < 0 ? -1 : 0);

        // Limits in the direction of travel stop the motor at once.
        if (travel != 0) {
            auto hit = travel > 0
                           ? first_true(phys_prev, s.phys, [&](double p) { return plus_in(s, w, p); })
                           : first_true(phys_prev, s.phys, [&](double p) { return minus_in(s, w, p); });
            if (hit) {
                stop_at(*hit);
                if (s.job == Job::HomeL && s.phase == 0 && travel == s.home_dir) {
                    // Limit homing: back off by LCA at high speed, that is zero.
                    s.phase = 1;
                    configure_axis();
                    s.axis.move_to(s.axis.position() - travel * static_cast<double>(s.cfg.lca));
                    if (!s.axis.busy()) finish_limit_homing();
                } else {
                    set_error_limit(travel);
                }
                after_motion(now);
                return;
            }
        }

        switch (s.job) {
            case Job::HomeH:
            case Job::HomeHL:
                if (s.phase == 0) {
                    auto f = first_true(phys_prev, s.phys, [&](double p) { return home_in(s, w, p); });
                    if (f && travel != 0) {
                        zero_counters_at(cmd_at(*f), phys_at(*f));
                        s.axis.decel_stop();
                        s.phase = 1;
                    }
                } else if (s.job == Job::HomeHL && s.phase == 2) {
                    auto f = first_true(phys_prev, s.phys, [&](double p) { return home_in(s, w, p); });
                    if (f) {
                        s.phase = 3;  // through the switch at high speed
                        configure_axis();
                        s.axis.run(-s.home_dir, true);
                    }
                } else if (s.job == Job::HomeHL && s.phase == 3) {
                    if (!home_in(s, w, s.phys)) {
                        s.phase = 4;  // then HCA further
                        configure_axis();
                        s.axis.move_to(s.axis.position() - s.home_dir * static_cast<double>(s.hca));
                    }
                } else if (s.job == Job::HomeHL && s.phase == 5) {
                    auto f = first_true(phys_prev, s.phys, [&](double p) { return home_in(s, w, p); });
                    if (f) {
                        stop_at(*f);
                        zero_here();
                        s.job = Job::None;
                    }
                }
                break;
            case Job::HomeZH:
                if (s.phase == 0) {
                    auto f = first_true(phys_prev, s.phys, [&](double p) { return home_in(s, w, p); });
                    if (f && travel != 0) {
                        s.axis.decel_stop();
                        s.phase = 1;
                    }
                } else if (s.phase == 2) {
                    z_stop(phys_prev, cmd_at, phys_at, stop_at);
                }
                break;
            case Job::HomeZ:
                z_stop(phys_prev, cmd_at, phys_at, stop_at);
                break;
            default:
                break;
        }

        // Sync output on DO2.
        if (s.sync_on && !s.sync_hit) check_sync(enc_prev, encoder(s));

        // Delta monitoring while moving.
        if (snl_on(s) && s.axis.busy() &&
            s.snl.monitor(static_cast<double>(pulse(s) - encoder(s))).action == motion::SnlAction::StopNow) {
            s.axis.halt();  // stall error (10)
            s.job = Job::None;
        }
        if (stopped || !s.axis.busy()) after_motion(now);
    }

    template <class CmdAt, class PhysAt, class StopAt>
    void z_stop(double phys_prev, CmdAt, PhysAt, StopAt stop_at) {
        auto f = z_fraction(o.world, phys_prev, s.phys);
        if (f && s.phys != phys_prev) {
            stop_at(*f);
            zero_here();
            s.job = Job::None;
        }
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

    void finish_limit_homing() {
        zero_here();
        s.job = Job::None;
    }

    // Called whenever the axis is idle after a step: moves the job to its next phase.
    void after_motion(Nanos now) {
        if (s.axis.busy()) return;
        s.idle_since = now;
        const bool verifying = s.job == Job::Target || s.job == Job::Correct;
        dispatch_stop();
        if (s.job == Job::None && !verifying) s.snl.end_without_verification();
    }

    void dispatch_stop() {
        switch (s.job) {
            case Job::None:
                break;
            case Job::Target:
            case Job::Correct:
                s.job = Job::None;
                verify_position();
                break;
            case Job::Jog:
            case Job::Stop:
                s.job = Job::None;
                break;
            case Job::HomeH:
                if (s.phase == 1 && s.rz) {
                    s.phase = 2;
                    configure_axis();
                    s.axis.move_to(0);
                    if (s.axis.busy()) break;
                }
                if (s.phase == 0) break;  // stopped without seeing home (limit handled elsewhere)
                s.job = Job::None;
                break;
            case Job::HomeHL:
                if (s.phase == 1) {
                    s.phase = 2;  // back towards the switch at low speed
                    configure_axis();
                    s.axis.run(-s.home_dir, false);
                } else if (s.phase == 4) {
                    s.phase = 5;  // and forward onto it again at low speed
                    configure_axis();
                    s.axis.run(s.home_dir, false);
                } else {
                    s.job = Job::None;
                }
                break;
            case Job::HomeZH:
                if (s.phase == 1) {
                    s.phase = 2;
                    configure_axis();
                    s.axis.run(s.home_dir, false);
                } else {
                    s.job = Job::None;
                }
                break;
            case Job::HomeZ:
                s.job = Job::None;
                break;
            case Job::HomeL:
                if (s.phase == 1) finish_limit_homing();
                else s.job = Job::None;
                break;
        }
    }

    void advance(Nanos now, std::int64_t tick_ns) {
        while (s.t < now) {
            if (!s.axis.busy()) {
                s.t = now;
                break;
            }
            // A long unobserved stretch (a jog left running on real time) is
            // integrated in at most ~1e6 steps: positions come from the profile
            // model exactly, and crossings are interpolated inside the step.
            Nanos step = std::max<Nanos>(tick_ns, (now - s.t) / 1'000'000);
            Nanos dt = std::min<Nanos>(step, now - s.t);
            s.t += dt;
            tick(static_cast<double>(dt) * 1e-9, s.t);
        }
    }
};

// ------------------------------------------------------------------------------

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
    double phys = s.phys;
    unsigned inputs = s.inputs;
    bool blocked = s.blocked;
    auto fh = s.force_home, fm = s.force_minus, fp = s.force_plus;
    s = State{};
    s.phys = phys;  // the shaft stays where it is
    s.inputs = inputs;
    s.blocked = blocked;
    s.force_home = fh;
    s.force_minus = fm;
    s.force_plus = fp;
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
    s.enc_offset = -std::llround(s.phys * kCountsPerStep);  // counters start at 0
    s.t = clock_.now();
    SimEngine(s, options_).configure_snl();
    s.idle_since = s.t - s.cfg.curt * 1'000'000 - 1;
}

int Sim::address() const {
    std::lock_guard lock(mutex_);
    return s_->active_address;
}

std::string Sim::store_path() const { return options_.store_path; }

#define MOTORBUS_ARCUS_SYNC()            \
    std::lock_guard lock(mutex_);        \
    SimEngine e(*s_, options_);          \
    e.advance(clock_.now(), options_.tick_ns)

void Sim::set_input(int index, bool actuated) {
    if (index < 1 || index > 6) throw InvalidArgument("arcus sim input: index must be 1..6");
    MOTORBUS_ARCUS_SYNC();
    bool before = latch_in(*s_);
    unsigned bit = 1u << (index - 1);
    s_->inputs = actuated ? (s_->inputs | bit) : (s_->inputs & ~bit);
    if (s_->latch_state == 1 && !before && latch_in(*s_)) {
        s_->ltp = pulse(*s_);
        s_->lte = encoder(*s_);
        s_->latch_state = 2;
    }
}

void Sim::force_home(std::optional<bool> actuated) {
    MOTORBUS_ARCUS_SYNC();
    s_->force_home = actuated;
}

void Sim::force_limit(int direction, std::optional<bool> actuated) {
    MOTORBUS_ARCUS_SYNC();
    (direction > 0 ? s_->force_plus : s_->force_minus) = actuated;
}

void Sim::set_blocked(bool blocked) {
    MOTORBUS_ARCUS_SYNC();
    s_->blocked = blocked;
}

void Sim::disturb(double steps) {
    MOTORBUS_ARCUS_SYNC();
    s_->phys += steps;
    if (!s_->axis.busy() && s_->job == Job::None) e.verify_position(/*idle=*/true);
}

double Sim::physical_position() const {
    std::lock_guard lock(mutex_);
    return s_->phys;
}

std::int64_t Sim::pulse_position() {
    MOTORBUS_ARCUS_SYNC();
    return pulse(*s_);
}
std::int64_t Sim::encoder_position() {
    MOTORBUS_ARCUS_SYNC();
    return encoder(*s_);
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
    return s_->axis.busy();
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
    e.advance(now, options_.tick_ns);

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
    bool busy = s.axis.busy();
    if (info.motion && pc->op != Op::Query && busy) return std::string(error_text(ErrorCode::Moving));

    // Value checks for "NAME=value".
    std::optional<std::int64_t> v = pc->value;
    auto in = [&](std::int64_t lo, std::int64_t hi) { return v && *v >= lo && *v <= hi; };

    auto start_move = [&](Job job, int dir) -> std::string {
        if (s.minus_err || s.plus_err || s.snl.in_error()) return std::string(error_text(ErrorCode::StateError));
        e.configure_axis();
        s.job = job;
        s.phase = 0;
        s.home_dir = dir;
        s.snl.begin(job == Job::Jog     ? motion::SnlActivity::Jog
                    : job == Job::HomeZ ? motion::SnlActivity::ZHome
                    : job == Job::HomeL ? motion::SnlActivity::LimitHome
                                        : motion::SnlActivity::Home);
        switch (job) {
            case Job::Jog:
            case Job::HomeH:
            case Job::HomeHL:
            case Job::HomeZH:
            case Job::HomeL: s.axis.run(dir, true); break;
            case Job::HomeZ: s.axis.run(dir, false); break;
            default: break;
        }
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
        if (name == "DX") return num(delta(s));
        if (name == "EDEC") return num(s.edec);
        if (name == "EDO") return num(s.cfg.edo);
        if (name == "EO") return num(s.eo);
        if (name == "EOBOOT") return num(s.cfg.eoboot);
        if (name == "EX") return num(encoder(s));
        if (name == "HCA") return num(s.hca);
        if (name == "HSPD") return num(s.hspd);
        if (name == "ID") return "DriveMax-CAN";
        if (name == "LCA") return num(s.cfg.lca);
        if (name == "LSPD") return num(s.lspd);
        if (name == "LT") return num(s.lt);
        if (name == "LTE") return num(s.lte);
        if (name == "LTP") return num(s.ltp);
        if (name == "LTS") return num(s.latch_state);
        if (name == "MM") return num(s.inc_mode);
        if (name == "MST") return num(e.mst());
        if (name == "NID") return num(s.cfg.nid);
        if (name == "POL") return num(s.cfg.pol);
        if (name == "PS") return num(std::llround(s.axis.speed()));
        if (name == "PX") return num(pulse(s));
        if (name == "RT") return num(s.cfg.rt);
        if (name == "RZ") return num(s.rz);
        if (name == "SCV") return num(s.scv);
        if (name == "SL") return num(s.cfg.sl);
        if (name == "SLA") return num(s.cfg.sla);
        if (name == "SLE") return num(s.cfg.sle);
        if (name == "SLM") return num(s.cfg.slm);
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
            return ok;
        }
        if (name == "EOBOOT") return set(s.cfg.eoboot, 0, 1);
        if (name == "EX") {
            s.enc_offset = *v - std::llround(s.phys * kCountsPerStep);
            if (snl_on(s)) s.axis.set_position(static_cast<double>(*v));
            return ok;
        }
        if (name == "PX") {
            s.axis.set_position(static_cast<double>(*v));
            if (snl_on(s)) s.enc_offset = *v - std::llround(s.phys * kCountsPerStep);
            return ok;
        }
        if (name == "HCA") return set(s.hca, 0, INT32_MAX);
        if (name == "HSPD") return set(s.hspd, 1, 6'000'000);
        if (name == "LSPD") return set(s.lspd, 1, 6'000'000);
        if (name == "LCA") return set(s.cfg.lca, 0, INT32_MAX);
        if (name == "LT") {
            if (!in(0, 1)) return unknown();
            s.lt = *v;
            s.latch_state = *v ? 1 : 0;
            return ok;
        }
        if (name == "NID") return set(s.cfg.nid, 1, 127);
        if (name == "POL") return set(s.cfg.pol, 0, 511);
        if (name == "RT") return set(s.cfg.rt, 0, 1);
        if (name == "RZ") return set(s.rz, 0, 1);
        if (name == "SCV") return set(s.scv, 0, 1);
        if (name == "SL") {
            if (!in(0, 1)) return unknown();
            if (busy) return std::string(error_text(ErrorCode::Moving));
            if (*v != s.cfg.sl) {
                // Position units change: counts with SNL, pulses without.
                std::int64_t ex = encoder(s);
                s.axis.set_position(*v ? static_cast<double>(ex) : std::round(ex / kCountsPerStep));
            }
            s.cfg.sl = *v;
            e.configure_snl();
            s.snl.clear();
            return ok;
        }
        if (name == "SLA") {
            auto r = set(s.cfg.sla, 0, INT32_MAX);
            e.configure_snl();
            return r;
        }
        if (name == "SLE") {
            auto r = set(s.cfg.sle, 0, INT32_MAX);
            e.configure_snl();
            return r;
        }
        if (name == "SLM") {
            auto r = set(s.cfg.slm, 0, INT32_MAX);
            e.configure_snl();
            return r;
        }
        if (name == "SLT") {
            auto r = set(s.cfg.slt, 0, INT32_MAX);
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
            if (s.minus_err || s.plus_err || s.snl.in_error()) return std::string(error_text(ErrorCode::StateError));
            double from = s.axis.position();
            double target = s.inc_mode ? from + static_cast<double>(*v) : static_cast<double>(*v);
            if (std::abs(target - from) > static_cast<double>(kMaxIncrement)) return unknown();
            e.configure_axis();
            s.job = Job::Target;
            s.snl.begin(motion::SnlActivity::Move);
            s.move_target = target;
            s.axis.move_to(target);
            if (!s.axis.busy()) {
                s.job = Job::None;
                e.after_motion(now);
            }
            return ok;
        }
        if (name == "T") {
            if (!v) return unknown();
            if (!busy || s.job != Job::Target || s.axis.stopping())
                return std::string(error_text(ErrorCode::MotorNotMoving));
            auto r = s.axis.retarget(static_cast<double>(*v));
            if (r != motion::ArcusReply::Ok) return motion::arcus_reply_text(r);
            s.move_target = static_cast<double>(*v);
            return ok;
        }
        if (name == "SSPD") {
            if (!v || *v <= 0) return std::string(error_text(ErrorCode::BadSspd));
            if (s.scv) return std::string(error_text(ErrorCode::ScvOn));
            // The window is in PPS; under StepNLoop the value is in counts/s.
            double pps = static_cast<double>(*v) * (snl_on(s) ? 1.0 / kCountsPerStep : 1.0);
            auto wdw = window_for_sspdm(s.sspdm);
            if (!wdw || pps < static_cast<double>(wdw->hspd_min) || pps > static_cast<double>(wdw->hspd_max))
                return std::string(error_text(ErrorCode::SpeedOutOfRange));
            if (!busy || s.axis.stopping()) return std::string(error_text(ErrorCode::BadSspd));
            s.axis.set_sspdm(static_cast<int>(s.sspdm));
            auto r = s.axis.change_speed(static_cast<double>(*v));
            if (r != motion::ArcusReply::Ok) return motion::arcus_reply_text(r);
            return ok;
        }
        return unknown();
    }

    // Actions.
    if (name == "ABORT") {
        s.axis.halt();
        s.job = Job::None;
        if (s.snl.status() != motion::SnlStatus::LimitError) s.snl.clear();
        s.idle_since = now;
        return ok;
    }
    if (name == "STOP") {
        if (busy) {
            s.axis.decel_stop();
            if (s.job != Job::Jog && s.job != Job::Target) s.job = Job::Stop;
            if (s.job == Job::Target) s.job = Job::Stop;
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
        std::int64_t ex = encoder(s);
        if (s.sync_cond != 1 || ex == s.synp) e.check_sync(ex, ex);
        return ok;
    }
    if (name == "SYNF") {
        s.sync_on = false;
        s.sync_hit = false;
        s.user_do &= ~std::int64_t{2};
        return ok;
    }
    if (name == "J+") return start_move(Job::Jog, 1);
    if (name == "J-") return start_move(Job::Jog, -1);
    if (name == "H+") return start_move(Job::HomeH, 1);
    if (name == "H-") return start_move(Job::HomeH, -1);
    if (name == "HL+") return start_move(Job::HomeHL, 1);
    if (name == "HL-") return start_move(Job::HomeHL, -1);
    if (name == "ZH+") return start_move(Job::HomeZH, 1);
    if (name == "ZH-") return start_move(Job::HomeZH, -1);
    if (name == "Z+") return start_move(Job::HomeZ, 1);
    if (name == "Z-") return start_move(Job::HomeZ, -1);
    if (name == "L+") return start_move(Job::HomeL, 1);
    if (name == "L-") return start_move(Job::HomeL, -1);
    return unknown();
}

}  // namespace motorbus::arcus

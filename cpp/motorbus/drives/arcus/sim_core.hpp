// The Arcus DMX-CAN simulator's core, shared by its two front ends: the ASCII
// line (sim.cpp, Sim::on_line) and CANopen CiA DSP-402 (sim_canopen.cpp).  One
// motor, one StepNLoop, one homing engine, one flash: the front ends only
// translate their protocol into the same firmware state.  Internal header of
// the arcus folder (not installed API).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "motorbus/canopen/cia402_axis.hpp"
#include "motorbus/drives/arcus/homing.hpp"
#include "motorbus/drives/arcus/profile.hpp"
#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/stepnloop.hpp"

namespace motorbus::arcus {

namespace sim_detail {

// The DMX-CAN's own StepNLoop ratio: 3200 steps per 4000 counts (SLR 0.800).
inline constexpr std::int64_t kFactorySlrMilli = 800;
inline constexpr std::int64_t kSyncMax = (1 << 27) - 1;  // SYNP is a 28-bit signed number

// Flash contents (Table 7.10) with the Table 7.11 factory defaults.
struct Flash {
    std::int64_t br = 5, cm = 0, curi = 1000, curr = 1600, curt = 500, db = 1, dn = 1,
                 doboot = 7, edo = 1, eoboot = 0, lca = 1000, pol = 0, rt = 0, sl = 1,
                 sla = 10, sle = 1000, slm = 5, slt = 20, nid = 1, slr = kFactorySlrMilli;
    // Stored objects that only the CANopen front end reaches (Table 8.40):
    // 607Ch home offset, 607Eh polarity, 6086h motion profile type.
    std::int64_t hofs = 0, cpol = 0, mpt = 0;

    std::map<std::string, std::int64_t*> fields() {
        return {{"BR", &br},     {"CM", &cm},         {"CURI", &curi}, {"CURR", &curr},
                {"CURT", &curt}, {"DB", &db},         {"DN", &dn},     {"DOBOOT", &doboot},
                {"EDO", &edo},   {"EOBOOT", &eoboot}, {"LCA", &lca},   {"POL", &pol},
                {"RT", &rt},     {"SL", &sl},         {"SLA", &sla},   {"SLE", &sle},
                {"SLM", &slm},   {"SLR", &slr},       {"SLT", &slt},   {"NID", &nid},
                {"HOFS", &hofs}, {"CPOL", &cpol},     {"MPT", &mpt}};
    }
};

// What the axis is doing, for SLS and for what happens when the motion ends.
enum class Job { None, Target, Correct, Jog, Stop, Home };

// The world as the motor model sees it.  The switches read active where they
// are actuated; POL bits 4 and 5 invert that at run time.
inline motion::MotorConfig motor_config(const SimOptions& o) {
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

// The power state machine (manual 000 §8, Fig. 8.3) is CiA 402's, as every CiA 402
// device runs it (canopen::Cia402Device).  The DMX-CAN's reading: a quick stop is an
// immediate stop straight to Switch on disabled (605Ah = 0, B-A11) and a fault has no
// reaction to wait for.
inline std::unique_ptr<canopen::Cia402Device> make_power_state_machine() {
    auto d = std::make_unique<canopen::Cia402Device>();
    d->set_quick_stop_option(0);
    return d;
}

// The CANopen front end's own (volatile) objects; everything else it shows is
// the shared firmware state.  Defaults the manual leaves open are the ASCII
// power-on values of the same quantities (HSPD 1000, LSPD 100, ACC/DEC 300).
struct CanopenState {
    // Held by pointer: the device has a mutex, and a power cycle assigns a new State.
    std::unique_ptr<canopen::Cia402Device> device = make_power_state_machine();
    canopen::Cia402State state() const { return device->state(); }
    std::uint16_t cw = 0;
    std::int8_t mode = 0;         // 6060h as last written
    std::int8_t active_mode = 0;  // the mode entered at T3 (6061h while Operation enabled)
    std::int32_t target_position = 0, target_velocity = 0;
    std::uint32_t profile_velocity = 1000, end_velocity = 100, acceleration = 300, deceleration = 300;
    std::int8_t homing_method = 35;
    std::uint32_t home_switch_speed = 1000, home_zero_speed = 100, homing_acceleration = 300;
    std::uint8_t latch_enable = 0;
    std::uint8_t clear_error = 0, store = 0;  // 200Dh / 200Eh handshakes
    Nanos clear_until = 0, store_until = 0;
    // Profile position: the set-point handshake every CiA 402 drive shares
    // (acknowledge, the one-deep buffer of a "set of set-points", absolute
    // targets in drive units), read as manual 000 C-A09 reads bit 5: a set-point
    // while moving is buffered only with bit 5 = 1.
    canopen::Cia402SetPoints setpoints{canopen::Cia402SetPointPolicy{.buffer_on_bit5 = true}};
    // Homing: started, attained, failed.
    bool homing_started = false, homing_attained = false, homing_error = false;
    // Profile velocity: run at 60FFh once the motor is idle (after a halt,
    // a direction change, a new speed).
    bool pv_pending = false;
};

}  // namespace sim_detail

using namespace sim_detail;

struct Sim::State {
    Flash flash;       // what STORE writes / boot reads
    bool stored = false;  // STORE ran since the simulator was made: boot keeps `flash`
    Flash cfg;         // live values of the stored items
    int active_address = 1;
    int active_rt = 0;
    int active_cm = 0;   // communication type read at power-up (B-A01)
    int active_nid = 1;  // CANopen node-ID read at power-up (B-A05)
    int active_br = 5;
    CanopenState co;

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
    Motion arcus{ProfileParams{}};
    bool arcus_profile = false;
    // H, HL, L, Z, ZH (declared after the motor: destroyed before it).
    std::unique_ptr<Homing> homing;
    int homing_listener = 0;  // runs after the homing's own listener
    int home_direction = 1;   // physical direction of the search
    // Set by the CANopen front end for the homing it is about to start (607Ch):
    // see HomingOptions.  Consumed by start_homing.
    std::optional<double> home_final_target;
    bool home_backoff_lspd = false;

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

    ProfileParams profile_params(double hspd_override = -1) const {
        ProfileParams ap;
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
    Phase phase() const {
        if (!m().moving()) return Phase::Idle;
        if (s.arcus_profile) return s.arcus.phase(arcus_time());
        const double v = m().pulse_velocity(), a = m().commanded_acceleration() * (steps_per_unit() > 0 ? 1 : -1);
        if (v * a > 0) return Phase::Accel;
        if (v * a < 0) return Phase::Decel;
        return Phase::Const;
    }

    std::int64_t mst() const {
        std::int64_t v = 0;
        const auto ph = phase();
        if (ph == Phase::Const) v |= 1;
        if (ph == Phase::Accel) v |= 2;
        if (ph == Phase::Decel) v |= 4;
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
        if (s.arcus.move(from, target) == MotionReply::Ok) command_arcus();
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
                // Limit homing runs onto its limit on purpose: Homing backs off.
                if (s.job == Job::Home && s.homing && s.homing->running() &&
                    s.homing->method() == Homing::Method::L && side == s.home_direction)
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

    // Runs after Homing's listener.
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

    void start_homing(Homing::Method method, int dir, Nanos now) {
        if (s.homing) s.homing.reset();
        if (s.homing_listener) m().remove_listener(s.homing_listener);
        HomingOptions ho;
        ho.hca = static_cast<double>(s.hca);
        ho.lca = static_cast<double>(s.cfg.lca);
        ho.rz = s.rz != 0;
        ho.zero_encoder = true;  // PX and EX both read 0 at home
        ho.final_target = s.home_final_target;
        ho.backoff_at_lspd = s.home_backoff_lspd;
        s.home_final_target.reset();
        s.home_backoff_lspd = false;
        s.homing = std::make_unique<Homing>(m(), profile_params(), ho);
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

}  // namespace motorbus::arcus

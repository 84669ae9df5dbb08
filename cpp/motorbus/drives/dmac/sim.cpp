#include "motorbus/drives/dmac/sim.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <limits>
#include <thread>

#include "motorbus/drives/dmac/sim_internal.hpp"

namespace motorbus::dmac {

using namespace sim_detail;

struct Sim::Chain {
    std::vector<Sim*> members;
};

namespace {

constexpr std::int64_t kNsPerMs = 1'000'000;
// A soft end-stop reached by an exact crossing sits on it to within rounding.
constexpr double kEndTolerance = 1e-6;

motion::MotorConfig axis_config(const SimOptions& o) {
    motion::MotorConfig c;
    // One step = one encoder count = one DMAC increment: every position the
    // firmware reports is the model's encoder as is.
    c.steps_per_rev = kIncrementsPerRev;
    c.counts_per_rev = kIncrementsPerRev;
    c.index_width_steps = 1;
    c.plus_limit = o.positive_end_switch;
    c.minus_limit = o.negative_end_switch;
    c.home = o.reference_switch;
    c.tick_ns = kNsPerMs;  // the firmware's own tick; edges inside it are refined anyway
    return c;
}

std::int32_t wrap_i32(std::int64_t v) {
    auto u = static_cast<std::uint32_t>(static_cast<std::uint64_t>(v) & 0xFFFFFFFFu);
    return u <= 0x7FFFFFFFu ? static_cast<std::int32_t>(u)
                            : static_cast<std::int32_t>(static_cast<std::int64_t>(u) - 0x100000000LL);
}

std::int32_t round_i32(double v) {
    if (!std::isfinite(v)) return 0;
    double r = std::round(v);
    if (r > 2147483647.0) return std::numeric_limits<std::int32_t>::max();
    if (r < -2147483648.0) return std::numeric_limits<std::int32_t>::min();
    return static_cast<std::int32_t>(r);
}

}  // namespace

std::optional<Model> parse_model(std::string_view s) {
    static constexpr std::pair<std::string_view, Model> t[] = {
        {"DMAC17", Model::Dmac17},     {"DMAC23", Model::Dmac23_1},   {"DMAC23-1", Model::Dmac23_1},
        {"DMAC23-2", Model::Dmac23_2}, {"DMAC34", Model::Dmac34_1},   {"DMAC34-1", Model::Dmac34_1},
        {"DMAC34-2", Model::Dmac34_2},
    };
    for (const auto& [n, m] : t)
        if (n == s) return m;
    return std::nullopt;
}

std::string_view model_name(Model m) {
    switch (m) {
        case Model::Dmac17: return "DMAC17";
        case Model::Dmac23_1: return "DMAC23-1";
        case Model::Dmac23_2: return "DMAC23-2";
        case Model::Dmac34_1: return "DMAC34-1";
        case Model::Dmac34_2: return "DMAC34-2";
    }
    return "DMAC34-1";
}

Sim::Sim(std::shared_ptr<Clock> clock, SimOptions options)
    : clock_(std::move(clock)), options_(std::move(options)) {
    if (!clock_) clock_ = std::make_shared<RealClock>();
    if (options_.address < 0 || options_.address > kMaxAddress)
        throw InvalidArgument("DmacSim address: " + std::to_string(options_.address) +
                              " is outside 0..63");
    address_ = options_.address;
    baudrate_ = options_.baudrate;
    axis_ = std::make_unique<motion::MotorModel>(*clock_, axis_config(options_));
    epoch_ns_ = axis_->time();  // the model's time is the device's, tick for tick
    axis_->add_listener([this](const motion::MotorEvent& e) { on_axis_event(e); });
    std::lock_guard lock(*mutex_);
    restart_motion_at(0);
    reset_locked(true);
}

Sim::~Sim() {
    if (!chain_) return;
    std::lock_guard lock(*mutex_);
    auto& m = chain_->members;
    m.erase(std::remove(m.begin(), m.end(), this), m.end());
}

void Sim::chain_ultrasync(const std::vector<std::shared_ptr<Sim>>& modules) {
    std::vector<Sim*> ms;
    for (const auto& m : modules) {
        if (!m) throw InvalidArgument("DmacSim chain_ultrasync: a module is None");
        if (std::find(ms.begin(), ms.end(), m.get()) == ms.end()) ms.push_back(m.get());
    }
    if (ms.size() < 2) throw InvalidArgument("DmacSim chain_ultrasync: two modules or more (IN6/OUT1 of each wired to the next)");
    for (auto* m : ms) {
        if (m->chain_) throw InvalidArgument("DmacSim chain_ultrasync: module " + std::to_string(m->address()) + " is already chained");
        if (m->clock_ != ms.front()->clock_)
            throw InvalidArgument("DmacSim chain_ultrasync: the chained modules must share one clock");
    }
    for (auto* m : ms) m->poll();  // each on the clock's now before they tick together
    auto chain = std::make_shared<Chain>();
    chain->members = ms;
    auto mutex = std::make_shared<std::mutex>();
    for (auto* m : ms) {
        m->chain_ = chain;
        m->mutex_ = mutex;
    }
}

void Sim::set_speed_limit(double inc_per_s) {
    if (!std::isfinite(inc_per_s) || inc_per_s < 0)
        throw InvalidArgument("DmacSim speed limit: increments/s >= 0 (0 = none), not " + std::to_string(inc_per_s));
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    speed_limit_ = inc_per_s;
}

bool Sim::dmac34() const {
    return options_.model == Model::Dmac34_1 || options_.model == Model::Dmac34_2;
}

std::uint32_t Sim::input_mask() const { return dmac34() ? 0x3FFu : 0x3Fu; }

std::uint32_t Sim::logical_inputs() const {
    // The end-stop switches are wired onto the same inputs a test can drive.
    std::uint32_t electrical = physical_inputs_;
    if (options_.positive_end_switch.present && axis_->plus_limit_input())
        electrical |= dmac34() ? bit_mask(9) : bit_mask(1);
    if (options_.negative_end_switch.present && axis_->minus_limit_input())
        electrical |= dmac34() ? bit_mask(10) : bit_mask(2);
    if (options_.reference_switch.present && axis_->home_input()) electrical |= bit_mask(5);
    return (electrical ^ (invert_in_ ? input_mask() : 0u)) & input_mask();
}

bool Sim::var_available(Var v) const {
    // #INPUT_ANALOG is the DMAC17/23 name; a DMAC34 has #INPUT_A1/#INPUT_A2 (5.8, 7.2).
    if (v == Var::InputAnalog) return !dmac34();
    return dmac34() || !var_info(v).dmac34_only;
}

ProfileParams Sim::params() const {
    ProfileParams p;
    p.high_speed = vars_[static_cast<std::size_t>(Var::HighSpeed)];
    p.low_speed = vars_[static_cast<std::size_t>(Var::LowSpeed)];
    p.accel_time_ms = vars_[static_cast<std::size_t>(Var::AccelTime)];
    p.decel_time_ms = vars_[static_cast<std::size_t>(Var::DecelTime)];
    p.s_curve = s_curve_;
    return p;
}

// ---- time -------------------------------------------------------------------
double Sim::motion_t() const { return static_cast<double>(now_ms_ - motion_t0_ms_) / 1000.0; }

Nanos Sim::tick_time() const { return epoch_ns_ + now_ms_ * kNsPerMs; }

double Sim::user_position() const {
    const double counts = axis_->steps_to_counts(axis_->physical_position());
    return counts + static_cast<double>(axis_->encoder() - std::llround(counts));
}

std::int32_t Sim::position_locked() const { return wrap_i32(axis_->encoder()); }

// #SPEED: the rotor's measured speed, whoever drives it -- the power stage,
// or nothing while it runs down after POWER OFF/SC, a fault or MODULE_RESET.
std::int32_t Sim::speed_locked() const {
    return round_i32(inc_per_s_to_speed(axis_->steps_to_counts(axis_->velocity())));
}

// #PROFILE_SPEED: "the computed speed of the module" (5.24): what its profile
// (or interpolation segment) asks for; nothing while the power stage is off.
std::int32_t Sim::profile_speed_locked() const {
    if (coasting_ || seg_wait_) return 0;
    return round_i32(inc_per_s_to_speed(axis_->steps_to_counts(axis_->commanded_velocity())));
}

bool Sim::moving_locked() const {
    return interpolating_ || (coasting_ && axis_->moving()) || motion_->moving(motion_t());
}

// BUSY: active until the target is reached (3.5.4) -- the target velocity in
// velocity mode, the target position otherwise.  A rotor running down with
// the power stage off has no target.
bool Sim::busy_locked() const { return interpolating_ || (!coasting_ && motion_->busy(motion_t())); }

void Sim::coast(double tau) {
    const double v = axis_->velocity();  // increments/s
    interpolating_ = false;
    fifo_.clear();
    seg_elapsed_ms_ = 0;
    seg_wait_ = false;
    pending_.reset();
    // Exponential run-down until below half an increment per second.
    if (std::fabs(v) > 0.5) {
        const double duration = tau * std::log(std::fabs(v) / 0.5);
        motion::Profile p(motion::State{0, v, 0, 0});
        p.append_exp_approach(duration, v * tau, tau).finish(v * tau * (1 - std::exp(-duration / tau)), 0);
        axis_->halt();
        axis_->command(p, tick_time());
        restart_motion_at(user_position());
        coasting_ = true;
    } else {
        axis_->halt();
        restart_motion_at(user_position());
        coasting_ = false;
    }
}

std::int64_t Sim::ms_at(Nanos t) const { return (t - epoch_ns_) / kNsPerMs; }

bool Sim::idle_locked() const {
    const bool timers = vars_[static_cast<std::size_t>(Var::Timer1)] ||
                        vars_[static_cast<std::size_t>(Var::Timer2)] ||
                        vars_[static_cast<std::size_t>(Var::Timer3)];
    return !seq_.running() && !timers && !moving_locked();
}

bool Sim::ultrasync_locked() const {
    return chain_ && vars_[static_cast<std::size_t>(Var::InterpolMode)] == -1;
}

void Sim::catch_up_locked(Nanos at) {
    if (!chain_) {
        catch_up_self_locked(ms_at(at));
        return;
    }
    // Chained modules live on one time line: each step ticks every module whose
    // next tick is the earliest due, then the chain releases a finished segment.
    // A module with nothing evolving jumps to now on its own (the chain only ever
    // releases modules that interpolate, which are never idle).
    const auto& ms = chain_->members;
    std::vector<std::int64_t> target;  // one instant: a real clock moves on while this loop runs
    for (auto* m : ms) target.push_back(m->ms_at(at));
    for (;;) {
        Nanos next = std::numeric_limits<Nanos>::max();
        for (std::size_t i = 0; i < ms.size(); ++i) {
            Sim* m = ms[i];
            if (m->now_ms_ >= target[i]) continue;
            if (m->idle_locked()) m->catch_up_self_locked(target[i]);
            else next = std::min(next, m->tick_time() + kNsPerMs);
        }
        if (next == std::numeric_limits<Nanos>::max()) return;
        for (std::size_t i = 0; i < ms.size(); ++i) {
            Sim* m = ms[i];
            if (m->now_ms_ < target[i] && !m->idle_locked() && m->tick_time() + kNsPerMs <= next) m->tick_locked();
        }
        // IN6/OUT1: a segment ends when it is finished on every module in UltraSYNC.
        bool any = false, all_done = true;
        for (auto* m : ms)
            if (m->interpolating_ && m->ultrasync_locked()) {
                any = true;
                all_done = all_done && m->seg_wait_;
            }
        if (any && all_done)
            for (auto* m : ms)
                if (m->seg_wait_) m->next_segment_locked();
    }
}

void Sim::catch_up_self_locked(std::int64_t target) {
    while (now_ms_ < target) {
        if (idle_locked()) {
            // Nothing evolves while idle: jump instead of ticking through it.
            now_ms_ = target;
            axis_->advance_to(tick_time());
            break;
        }
        tick_locked();
    }
}

void Sim::tick_locked() {
    ++now_ms_;
    for (int i = 1; i <= 3; ++i) {
        auto& t = vars_[static_cast<std::size_t>(timer_var(i))];
        if (t > 0) --t;
    }
    advance_axis(tick_time());
    if (coasting_ && !axis_->moving()) {
        coasting_ = false;
        restart_motion_at(user_position());
    }
    if (interpolating_ && !fifo_.empty() && !seg_wait_ && ++seg_elapsed_ms_ >= seg_duration_ms_) {
        // The segment's profile has just ended on its exact end position.  In
        // UltraSYNC the module waits there for the chain (catch_up_locked).
        if (ultrasync_locked()) seg_wait_ = true;
        else next_segment_locked();
    }
    if (seg_wait_ && !ultrasync_locked()) next_segment_locked();  // the mode changed meanwhile
    if (interpolating_ && fifo_.empty()) {
        // FIFO ran dry: the movement stops; a new SYNCHRO INTERPOL is needed.
        interpolating_ = false;
        seg_elapsed_ms_ = 0;
        restart_motion_at(user_position());
    }
    check_end_stops();
    if (seq_.running()) {
        SeqHost host(*this);
        seq_.tick(host, now_ms_);
    }
}

void Sim::poll() {
    std::lock_guard lock(*mutex_);
    catch_up_locked();
}

// ---- motion -----------------------------------------------------------------
void Sim::restart_motion_at(double position) {
    pos_offset_ = 0;
    motion_ = std::make_unique<Motion>(params(), position);
    motion_t0_ms_ = now_ms_;
    position_mode_ = false;
}

void Sim::halt_motion() {
    coasting_ = false;
    interpolating_ = false;
    fifo_.clear();
    seg_elapsed_ms_ = 0;
    seg_wait_ = false;
    axis_->halt();
    restart_motion_at(user_position());
}

void Sim::command_axis() { axis_->command_from(motion_->profile(), motion_t(), tick_time()); }

void Sim::next_segment_locked() {
    seg_wait_ = false;
    fifo_.pop_front();
    if (!fifo_.empty()) {
        start_interp_segment();
        return;
    }
    // FIFO ran dry: the movement stops; a new SYNCHRO INTERPOL is needed.
    interpolating_ = false;
    seg_elapsed_ms_ = 0;
    restart_motion_at(user_position());
}

void Sim::start_interp_segment() {
    // One FIFO entry: #INTERPOL_TIME ms at constant speed, ending exactly on its
    // offset -- or longer, at the speed a mechanical limit allows.
    const Segment& s = fifo_.front();
    int duration = std::max(s.duration_ms, 1);
    const double need = std::fabs(static_cast<double>(s.offset)) * 1000.0 / duration;
    if (speed_limit_ > 0 && need > speed_limit_)
        duration = static_cast<int>(std::ceil(std::fabs(static_cast<double>(s.offset)) * 1000.0 / speed_limit_));
    const double v = static_cast<double>(s.offset) * 1000.0 / duration;
    motion::Profile seg(motion::State{0, v, 0, 0});
    seg.append_jump(duration / 1000.0, v, 0, 0).finish(static_cast<double>(s.offset), 0);
    axis_->command(seg);
    seg_elapsed_ms_ = 0;
    seg_duration_ms_ = duration;
    seg_wait_ = false;
}

// Advances the axis to t, stopping it where the commanded motion would first
// go beyond an enabled soft end-stop ("movement is stopped", manual 1.2.3).
void Sim::advance_axis(Nanos t) {
    if (soft_ends_ && axis_->moving() && t > axis_->time()) {
        const motion::Profile& prof = axis_->profile();
        const double t_from = axis_->profile_time(axis_->time());
        const double t_to = axis_->profile_time(t);
        // The plan's frame -> the user's: constant while the rotor follows it.
        const double shift = user_position() - prof.position(t_from);
        double t_stop = -1;
        auto consider = [&](Var end, double dir) {
            const double level = static_cast<double>(vars_[static_cast<std::size_t>(end)]) - shift;
            // Already at or beyond it: check_end_stops handles that at the tick.
            if (dir * (prof.position(t_from) - level) >= 0) return;
            if (dir * (prof.position(t_to) - level) <= 0) return;
            const double tc = prof.first_crossing(level, t_from);
            if (tc >= t_from && tc <= t_to && (t_stop < 0 || tc < t_stop)) t_stop = tc;
        };
        consider(Var::PositiveEnd, 1.0);
        consider(Var::NegativeEnd, -1.0);
        if (t_stop >= 0) {
            // The first nanosecond on or past the end-stop, so it reads as reached.
            const auto past = static_cast<Nanos>(std::ceil(t_stop * 1e9));
            const Nanos at = std::clamp<Nanos>(axis_->profile_start() + past,
                                               axis_->time(), t);
            const Nanos before = axis_->profile_start();
            axis_->advance_to(at);
            // A hard end-stop may have stopped the axis first.
            if (axis_->profile_start() == before && axis_->moving()) {
                halt_motion();
                abnormal_stop_ = true;
            }
        }
    }
    axis_->advance_to(t);
}

void Sim::on_axis_event(const motion::MotorEvent& e) {
    using K = motion::MotorEvent::Kind;
    if (e.kind == K::HomeOn || e.kind == K::HomeOff) {
        in5_changed_locked(wrap_i32(e.encoder));
        return;
    }
    if (e.kind != K::PlusLimitOn && e.kind != K::PlusLimitOff && e.kind != K::MinusLimitOn &&
        e.kind != K::MinusLimitOff)
        return;
    // A switch edge (either polarity) may activate an end-stop input: stop at its exact time.
    update_end_flags();
    if ((hard_pos_hit_ && e.direction > 0) || (hard_neg_hit_ && e.direction < 0)) {
        halt_motion();
        abnormal_stop_ = true;
    }
}

bool Sim::start_move(Cmd kind, std::int32_t value) {
    if (brake_) {
        flag(error::kLimit);
        return false;
    }
    // A latched hardware fault keeps the power stage off until #ERROR:=0 or a reset (2.1).
    if (error_ & kFaultBits) return false;
    if (coasting_) {
        // The power stage takes the rotor over where it is.
        coasting_ = false;
        axis_->halt();
        restart_motion_at(user_position());
    }
    const double p = user_position();
    int dir = 0;
    if (kind == Cmd::MoveTo) dir = (value > p) - (value < p);
    else dir = (value > 0) - (value < 0);
    // An end-stop that is hit only lets the axis move back.
    update_end_flags();
    if (dir > 0 && (hard_pos_hit_ || soft_pos_hit_)) {
        flag(error::kLimit);
        return false;
    }
    if (dir < 0 && (hard_neg_hit_ || soft_neg_hit_)) {
        flag(error::kLimit);
        return false;
    }
    if (interpolating_) halt_motion();
    try {
        motion_->set_params(params());
        const double t = motion_t();
        // Targets are in the user's frame; the profile runs in its own (see pos_offset_).
        if (kind == Cmd::MoveTo) {
            motion_->move_to(t, static_cast<std::int64_t>(value) - pos_offset_);
        } else if (kind == Cmd::MoveOn) {
            // Relative to the target of a position move in progress, else to where the axis is.
            const std::int64_t base = (position_mode_ && motion_->moving(t))
                                          ? motion_->target()
                                          : std::llround(p) - pos_offset_;
            motion_->move_to(t, base + value);
        } else {
            motion_->move_speed(t, value);
        }
        command_axis();
    } catch (const std::exception&) {
        flag(error::kLimit);
        halt_motion();
        return false;
    }
    position_mode_ = kind != Cmd::MoveSpeed;
    power_ = true;
    abnormal_stop_ = false;
    return true;
}

void Sim::update_end_flags() {
    const double p = user_position();
    const auto pen = static_cast<double>(vars_[static_cast<std::size_t>(Var::PositiveEnd)]);
    const auto nen = static_cast<double>(vars_[static_cast<std::size_t>(Var::NegativeEnd)]);
    const std::uint32_t in = logical_inputs();
    const std::uint32_t in_pos = dmac34() ? bit_mask(9) : bit_mask(1);
    const std::uint32_t in_neg = dmac34() ? bit_mask(10) : bit_mask(2);
    hard_pos_hit_ = hard_pos_ && (in & in_pos);
    hard_neg_hit_ = hard_neg_ && (in & in_neg);
    soft_pos_hit_ = soft_ends_ && p >= pen - kEndTolerance;
    soft_neg_hit_ = soft_ends_ && p <= nen + kEndTolerance;
}

// At a tick: an end-stop already active stops motion towards it (an input
// set from outside, or a move started beyond a soft end-stop).
void Sim::check_end_stops() {
    update_end_flags();
    if (!moving_locked()) return;
    const double v = axis_->commanded_velocity();
    if (((hard_pos_hit_ || soft_pos_hit_) && v > 0) || ((hard_neg_hit_ || soft_neg_hit_) && v < 0)) {
        halt_motion();
        abnormal_stop_ = true;
    }
}

// ---- reset --------------------------------------------------------------------
void Sim::reset_locked(bool factory) {
    for (std::size_t i = 0; i < kVarCount; ++i) {
        const VarInfo& vi = var_info(static_cast<Var>(i));
        if (vi.read_only) continue;
        // Serial line configuration (#LINE_DELAY) survives even MODULE_RESET ALL.
        if (static_cast<Var>(i) == Var::LineDelay && factory && !first_reset_) continue;
        if (!vi.stored || factory) vars_[i] = vi.factory;
    }
    if (factory) {
        hard_pos_ = hard_neg_ = soft_ends_ = false;
        invert_in_ = invert_out_ = false;
        s_curve_ = optimized_current_ = false;
    }
    vars_[static_cast<std::size_t>(Var::Capture)] = 0;
    error_ = 0;
    power_ = reference_ = synchro_ = abnormal_stop_ = false;
    // BRAKE's factory value is ON (annex 7.1): the fail-safe brake is applied
    // after a reset until BRAKE OFF (the brake output exists on a DMAC34 only).
    brake_ = dmac34();
    pending_.reset();
    interpolating_ = false;
    fifo_.clear();
    seg_elapsed_ms_ = 0;
    seg_wait_ = false;
    seq_.reset();
    // "Motor is powered off and then stopped (short-circuited) until complete
    // stop" (4.8): a moving rotor runs down as under POWER SC.
    coast(kShortCircuitTau);
    // Position is stored (kept across a reset) unless factory settings are restored.
    if (factory) {
        axis_->set_encoder(0);
        if (!coasting_) restart_motion_at(user_position());
    }
    first_reset_ = false;
    check_supply_locked();
    const std::int32_t on_reset = vars_[static_cast<std::size_t>(Var::OnReset)];
    if (on_reset >= 1 && on_reset <= kSeqLines) seq_.start(on_reset);
}

void Sim::power_cycle() {
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    reset_locked(false);
}

// ---- variables ----------------------------------------------------------------
std::uint32_t Sim::status_locked() {
    update_end_flags();
    std::uint32_t s = 0;
    auto set = [&](int bit, bool on) {
        if (on) s |= bit_mask(bit);
    };
    const bool moving = moving_locked();
    set(status::kOptimizedCurrent, optimized_current_);
    set(status::kHardPosEnabled, hard_pos_);
    set(status::kHardNegEnabled, hard_neg_);
    set(status::kSoftEndsEnabled, soft_ends_);
    set(status::kHardEndsInverted, invert_in_);
    set(status::kSCurve, s_curve_);
    set(status::kInputsInverted, invert_in_);
    set(status::kOutputsInverted, invert_out_);
    set(status::kSeqRun, seq_.running());
    set(status::kSeqEdit, seq_.editing());
    set(status::kHardPosEnd, hard_pos_hit_);
    set(status::kHardNegEnd, hard_neg_hit_);
    set(status::kSoftPosEnd, soft_pos_hit_);
    set(status::kSoftNegEnd, soft_neg_hit_);
    set(status::kBrake, brake_);
    set(status::kSynchro, synchro_);
    set(status::kPowerOn, power_);
    set(status::kMovement, moving);
    if (moving && position_mode_ && !interpolating_) {
        const double err = static_cast<double>(motion_->target() + pos_offset_) - user_position();
        set(status::kPositionControl, std::fabs(err) <= kApproachIncrements);
    }
    set(status::kBusy, busy_locked());
    set(status::kReference, reference_);
    set(status::kError, error_ != 0);
    set(status::kAbnormalStop, abnormal_stop_);
    return s;
}

std::optional<std::int32_t> Sim::read_var_locked(Var v, int bit) {
    if (!var_available(v)) return std::nullopt;
    std::int32_t value;
    switch (v) {
        case Var::Position: value = position_locked(); break;
        case Var::Speed: value = speed_locked(); break;
        case Var::ProfileSpeed: value = profile_speed_locked(); break;
        case Var::Status: value = wrap_i32(status_locked()); break;
        case Var::Error: value = wrap_i32(error_); break;
        case Var::Input: value = wrap_i32(logical_inputs()); break;
        case Var::InputAnalog:
        case Var::InputA1: value = analog_[1]; break;
        case Var::InputA2: value = analog_[2]; break;
        case Var::InterpolCount: value = static_cast<std::int32_t>(fifo_.size()); break;
        case Var::Line: value = seq_.line(); break;
        case Var::CpuTemperature: value = options_.cpu_temperature; break;
        case Var::DriverTemperature: value = options_.driver_temperature; break;
        case Var::MotorTemperature: value = options_.motor_temperature; break;
        case Var::SupplyVoltage: value = options_.supply_voltage_mv; break;
        default: value = vars_[static_cast<std::size_t>(v)]; break;
    }
    if (bit) return (static_cast<std::uint32_t>(value) >> (bit - 1)) & 1u;
    return value;
}

int Sim::write_var_locked(Var v, int bit, std::int32_t value) {
    const VarInfo& vi = var_info(v);
    if (!var_available(v) || vi.read_only) return error::kSyntax;
    if (bit) {
        if (value != 0 && value != 1) return error::kLimit;
        auto cur = read_var_locked(v, 0);
        if (!cur) return error::kSyntax;
        auto u = static_cast<std::uint32_t>(*cur);
        u = value ? (u | bit_mask(bit)) : (u & ~bit_mask(bit));
        value = wrap_i32(u);
    }
    if (value < vi.min || value > vi.max) return error::kLimit;
    switch (v) {
        case Var::Position: {
            // Re-home: the encoder count jumps, the current motion continues from
            // the new origin (interpolation segments are relative anyway).
            const std::int64_t shift = static_cast<std::int64_t>(value) - axis_->encoder();
            axis_->set_encoder(value);
            if (moving_locked()) pos_offset_ += shift;
            else restart_motion_at(user_position());
            return 0;
        }
        case Var::Error:
            error_ = 0;
            // A supply or temperature still out of range latches again at once.
            check_supply_locked();
            return 0;
        case Var::Line:
            if (value == 0) seq_.stop();
            else seq_.set_line(value);
            return 0;
        default:
            vars_[static_cast<std::size_t>(v)] = value;
            return 0;
    }
}

std::optional<std::int32_t> Sim::eval_operand(const Operand& o) {
    std::int64_t v;
    if (o.is_var) {
        auto r = read_var_locked(o.var, o.bit);
        if (!r) {
            flag(error::kSyntax);
            return std::nullopt;
        }
        v = *r;
    } else {
        v = o.value;
    }
    if (o.negate) v = -v;
    if (o.complement) v = ~v;
    return wrap_i32(v);
}

std::optional<std::int32_t> Sim::eval(const Expr& e) {
    auto a = eval_operand(e.lhs);
    if (!a) return std::nullopt;
    if (e.op == Op::None) return a;
    auto b = eval_operand(e.rhs);
    if (!b) return std::nullopt;
    const std::int64_t x = *a, y = *b;
    switch (e.op) {
        case Op::Add: return wrap_i32(x + y);
        case Op::Sub: return wrap_i32(x - y);
        case Op::Mul: return wrap_i32(x * y);
        case Op::Div:
            if (y == 0) {
                flag(error::kComputation);
                return std::nullopt;
            }
            return wrap_i32(x / y);
        case Op::And: return wrap_i32(x & y);
        case Op::Or: return wrap_i32(x | y);
        case Op::Gt: return x > y;
        case Op::Lt: return x < y;
        case Op::Ge: return x >= y;
        case Op::Le: return x <= y;
        case Op::Ne: return x != y;
        case Op::Eq: return x == y;
        case Op::None: break;
    }
    return a;
}

std::string Sim::on_line(std::string_view line) {
    std::string reply;
    std::int32_t delay_us = 0;
    {
        std::lock_guard lock(*mutex_);
        try {
            // The command acts when the line ended on the wire: a SYNCHRO TOP heard by
            // two modules starts both at one millisecond, however the server orders them.
            catch_up_locked(line_end_.value_or(clock_->now()));
            line_end_.reset();
            reply = handle_locked(line);
        } catch (...) {
            // Hostile input must never take the device down: flag and stay silent.
            flag(error::kSyntax);
            reply.clear();
        }
        delay_us = vars_[static_cast<std::size_t>(Var::LineDelay)];
    }
    // #LINE_DELAY (5.13): the module waits that long after the end of the
    // command before it answers.  A wire-level delay, so real time whatever
    // the device clock is; taken outside the lock.
    if (!reply.empty() && delay_us > 0 && options_.line_delay_in_real_time)
        std::this_thread::sleep_for(std::chrono::microseconds(delay_us));
    return reply;
}

void Sim::line_ends() {
    std::lock_guard lock(*mutex_);
    line_end_ = clock_->now();
}

std::string Sim::on_overlong() {
    std::lock_guard lock(*mutex_);
    catch_up_locked(line_end_.value_or(clock_->now()));
    line_end_.reset();
    ++lines_rejected_;
    // Beyond kOverlongWindow the address is lost with the line: every module flags it.
    flag(error::kSyntax);
    return "";
}

// ---- inspection -------------------------------------------------------------------
SimState Sim::state() {
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    SimState s;
    s.now_ms = now_ms_;
    s.position = position_locked();
    s.speed = speed_locked();
    s.status = status_locked();
    s.error = error_;
    s.line = seq_.line();
    s.sequencer_running = seq_.running();
    s.fifo_count = static_cast<int>(fifo_.size());
    s.interpolating = interpolating_;
    s.power = power_;
    return s;
}

std::int32_t Sim::read(Var v) {
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    return read_var_locked(v, 0).value_or(0);
}

int Sim::address() {
    std::lock_guard lock(*mutex_);
    return address_;
}

std::int32_t Sim::baudrate() {
    std::lock_guard lock(*mutex_);
    return baudrate_;
}

std::string Sim::sequence_line(int n) {
    std::lock_guard lock(*mutex_);
    if (n < 1 || n > kSeqLines) return "";
    const auto& l = seq_.program_line(n);
    return l ? format_command(*l) : "";
}

void Sim::set_input(int n, bool active) {
    if (n < 1 || n > 10) throw InvalidArgument("DmacSim input: " + std::to_string(n) + " is outside 1..10");
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    if (active) physical_inputs_ |= bit_mask(n);
    else physical_inputs_ &= ~bit_mask(n);
    in5_changed_locked(position_locked());
    check_end_stops();
}

void Sim::in5_changed_locked(std::int32_t position) {
    const bool is = (logical_inputs() & bit_mask(5)) != 0;
    const bool rising = is && !in5_last_;
    in5_last_ = is;
    if (!rising) return;
    // IN5 rising edge: capture, and re-home in reference mode when turning CW (4.18).
    vars_[static_cast<std::size_t>(Var::Capture)] = position;
    if (reference_ && axis_->velocity() > 0) {
        write_var_locked(Var::Position, 0, 0);
        reference_ = false;
    }
}

void Sim::set_analog(int channel, std::int32_t mv) {
    // One analog input on a DMAC17/23, two on a DMAC34 (1.2.1, 3.5.3).
    if (channel < 1 || channel > (dmac34() ? 2 : 1))
        throw InvalidArgument("DmacSim analog channel: " + std::to_string(channel) + " (a " +
                              std::string(model_name(options_.model)) + " has " + (dmac34() ? "1 and 2)" : "1 only)"));
    std::lock_guard lock(*mutex_);
    analog_[channel] = mv;
}

void Sim::set_supply_voltage(std::int32_t mv) {
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    options_.supply_voltage_mv = mv;
    check_supply_locked();
}

void Sim::set_temperature(Sensor which, std::int32_t tenths_c) {
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    switch (which) {
        case Sensor::Cpu: options_.cpu_temperature = tenths_c; break;
        case Sensor::Driver: options_.driver_temperature = tenths_c; break;
        case Sensor::Motor: options_.motor_temperature = tenths_c; break;
    }
    check_supply_locked();
}

void Sim::inject_error(int bit) {
    if (bit < 1 || bit > 32) throw InvalidArgument("DmacSim error bit: 1..32");
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    if (kFaultBits & bit_mask(bit)) fault_locked(bit);
    else flag(bit);
}

void Sim::fault_locked(int bit) {
    const bool already = (error_ & bit_mask(bit)) != 0;
    flag(bit);
    if (already) return;
    if (moving_locked() && !coasting_) abnormal_stop_ = true;
    // Undervoltage: "motion is stopped" and the module locks out; the other
    // disjunctions cut the motor power, so the rotor runs down freely.
    if (bit == error::kUndervoltage) halt_motion();
    else coast(kFreewheelTau);
    power_ = false;
}

void Sim::check_supply_locked() {
    const std::int32_t mv = options_.supply_voltage_mv;
    const std::int32_t under = dmac34() ? 20000 : 12000;
    const std::int32_t over = dmac34() ? 170000 : 49000;
    if (mv < under) fault_locked(error::kUndervoltage);
    if (mv > over) fault_locked(error::kOvervoltage);
    const bool hot = options_.cpu_temperature > 1200 ||
                     (dmac34() && (options_.driver_temperature > 850 || options_.motor_temperature > 850));
    if (hot) fault_locked(error::kThermal);
}

std::uint32_t Sim::physical_outputs() {
    std::lock_guard lock(*mutex_);
    catch_up_locked();
    const std::uint32_t mask = dmac34() ? 0xFFu : 0x0Fu;
    auto logical = static_cast<std::uint32_t>(vars_[static_cast<std::size_t>(Var::Output)]);
    const std::int32_t cfg = vars_[static_cast<std::size_t>(Var::OutputConfig)];
    if (cfg & 1) logical = (logical & ~1u) | (busy_locked() ? 1u : 0u);
    if (cfg & 2) logical = (logical & ~2u) | ((error_ & kFaultBits) ? 2u : 0u);
    return (logical ^ (invert_out_ ? mask : 0u)) & mask;
}

std::uint64_t Sim::lines_handled() {
    std::lock_guard lock(*mutex_);
    return lines_handled_;
}

std::uint64_t Sim::lines_rejected() {
    std::lock_guard lock(*mutex_);
    return lines_rejected_;
}

}  // namespace motorbus::dmac

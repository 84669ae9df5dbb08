#include "motorbus/canopen/cia402_axis.hpp"

#include <cmath>
#include <string>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

namespace {
constexpr std::uint16_t kSimBits = sw::kRemote | sw::kTargetReached | sw::kInternalLimit | sw::kFollowingError;
constexpr std::uint16_t kChangeOnSetPoint = 1u << 9;
constexpr std::uint32_t kAbortRange = 0x06090030;  // value range of parameter exceeded
}  // namespace

// ---- Cia402SetPoints -----------------------------------------------------------------

SetPointAction Cia402SetPoints::on_controlword(std::uint16_t prev, std::uint16_t cw, OpMode mode, bool idle,
                                               bool accept, double target_position, double position) {
    if (!(cw & cw::kNewSetPoint)) ack_ = false;  // the acknowledge lasts while bit 4 does
    const bool halt = cw & cw::kHalt;
    if (halt && !(prev & cw::kHalt)) {
        buffered_.reset();  // a halted PP move does not resume its buffered set-point
        return SetPointAction::Halt;
    }
    if (halt) return SetPointAction::None;
    if (prev & cw::kHalt) {
        if (mode == OpMode::ProfileVelocity) return SetPointAction::Resume;
    }
    const bool rising = (cw & cw::kNewSetPoint) && !(prev & cw::kNewSetPoint);
    if (!rising) return SetPointAction::None;
    if (mode == OpMode::Homing) return SetPointAction::StartHoming;
    if (mode != OpMode::ProfilePosition) return SetPointAction::None;
    if (!accept) {
        ack_ = false;
        return SetPointAction::None;
    }
    const double value = target_position;
    const bool relative = cw & cw::kRelative;
    const bool bit5 = cw & cw::kChangeImmediately;
    const bool now = idle || (!policy_.buffer_on_bit5 && bit5);
    if (now) {
        target_ = relative ? position + value : value;
        buffered_.reset();
        ack_ = true;
        return SetPointAction::Start;
    }
    // A motion runs: the set-point waits for it, one deep.
    if ((policy_.buffer_on_bit5 && !bit5) || buffered_) {
        ack_ = false;
        return SetPointAction::Refuse;
    }
    target_ = relative ? target_ + value : value;  // relative to the set-point before it
    buffered_ = target_;
    ack_ = true;
    return SetPointAction::Buffer;
}

std::optional<double> Cia402SetPoints::take_buffered() {
    auto b = buffered_;
    buffered_.reset();
    return b;
}

// ---- Cia402Axis ----------------------------------------------------------------------

Cia402Axis::Cia402Axis(motion::MotorModel& motor, Clock& clock, Cia402AxisHooks hooks)
    : motor_(motor), clock_(clock), hooks_(std::move(hooks)) {
    // Called from motor_.update(), i.e. with m_ held.
    listener_ = motor_.add_listener([this](const motion::MotorEvent& e) { on_motor_event(e); });
}

Cia402Axis::~Cia402Axis() {
    std::lock_guard l(m_);
    homing_.reset();  // its listener goes before the motor does
    motor_.remove_listener(listener_);
}

motion::Cia402ProfileParams Cia402Axis::params() const {
    motion::Cia402ProfileParams p;
    p.profile_velocity = s_.profile_velocity;
    p.profile_acceleration = s_.profile_acceleration;
    p.profile_deceleration = s_.profile_deceleration;
    p.quick_stop_deceleration = s_.quick_stop_deceleration;
    p.motion_profile_type = s_.motion_profile_type;
    return p;
}

motion::State Cia402Axis::motion_state() const {
    return motion::State{motor_.pulse_position(), motor_.pulse_velocity(), 0, 0};
}

double Cia402Axis::pp_time() const { return static_cast<double>(clock_.now() - pp_t0_) / 1e9; }

// ---- objects -------------------------------------------------------------------------

void Cia402Axis::write_controlword(std::uint16_t value) {
    std::lock_guard l(m_);
    update();
    const std::uint16_t prev = device_->controlword();
    const Cia402State before = device_->state();
    device_->on_controlword(value);
    const Cia402State after = device_->state();
    if (after != Cia402State::OperationEnabled) {
        setpoints_.reset();
        if (before == Cia402State::OperationEnabled && after == Cia402State::QuickStopActive)
            begin_quick_stop();
        else if (after != Cia402State::QuickStopActive)
            stop_now();  // power stage off: the motor stops where it is
        return;
    }
    if (before != Cia402State::OperationEnabled) setpoints_.reset();
    const auto mode = static_cast<OpMode>(device_->mode());
    sync_buffer();
    const bool idle = !motor_.moving() || activity_ != Activity::Pp;
    const auto action = setpoints_.on_controlword(prev, value, mode, idle, true, s_.target_position,
                                                  motor_.pulse_position());
    switch (action) {
        case SetPointAction::Halt:
            if (activity_ == Activity::Homing && homing_) {
                // A halted homing is over, not attained (CiA 402: bits 10/12/13 = 1/0/0).
                homing_->abort();
                homing_.reset();
            }
            if (motor_.moving() && activity_ != Activity::Stopping) decelerate();
            return;
        case SetPointAction::Start:
        case SetPointAction::Buffer:
            new_setpoint(value);
            return;
        case SetPointAction::StartHoming:
            start_homing();
            return;
        default: break;
    }
    if (mode == OpMode::ProfileVelocity && !(value & cw::kHalt)) {
        activity_ = Activity::Pv;
        apply_velocity();
    }
}

std::uint16_t Cia402Axis::controlword() const {
    std::lock_guard l(m_);
    return device_->controlword();
}

std::uint16_t Cia402Axis::statusword() {
    std::lock_guard l(m_);
    update();
    const auto mode = static_cast<OpMode>(device_->mode());
    const bool moving = motor_.moving();
    std::uint16_t bits = sw::kRemote;
    if (limit_hit_ || motor_.minus_limit_active() || motor_.plus_limit_active() || (soft_limit_side_ && !moving))
        bits |= sw::kInternalLimit;
    switch (mode) {
        case OpMode::ProfilePosition:
            if (!moving) bits |= sw::kTargetReached;  // the set-point (and any buffered one) is played out
            if (following_error_) bits |= sw::kFollowingError;
            break;
        case OpMode::ProfileVelocity:
            if (!moving || std::fabs(motor_.pulse_velocity() - s_.target_velocity) < 0.5) bits |= sw::kTargetReached;
            break;
        case OpMode::Homing:
            if ((!homing_ && !moving) || (homing_ && homing_->result() != motion::HomingResult::Running))
                bits |= sw::kTargetReached;
            if (homing_ && homing_->error()) bits |= sw::kFollowingError;  // bit 13: homing error
            break;
        default:
            if (!moving) bits |= sw::kTargetReached;
    }
    device_->set_status_bits(kSimBits, bits);
    std::uint16_t word = device_->statusword() & static_cast<std::uint16_t>(~sw::kSetPointAck);
    if (mode == OpMode::ProfilePosition && setpoints_.acknowledged()) word |= sw::kSetPointAck;
    // Bit 12 of homing mode is "homing attained", not the set-point acknowledge.
    if (mode == OpMode::Homing && homing_ && homing_->attained()) word |= sw::kSetPointAck;
    return word;
}

std::uint32_t Cia402Axis::set_mode(std::int8_t mode) {
    std::lock_guard l(m_);
    update();
    if (const auto code = device_->set_mode(mode)) return code;
    pp_.reset();
    setpoints_.reset();
    return 0;
}

std::int8_t Cia402Axis::mode() const {
    std::lock_guard l(m_);
    return device_->mode();
}

std::uint32_t Cia402Axis::set_abort_connection_option(std::int16_t v) {
    std::lock_guard l(m_);
    return device_->set_abort_connection_option(v);
}

std::uint32_t Cia402Axis::set_quick_stop_option(std::int16_t v) {
    std::lock_guard l(m_);
    return device_->set_quick_stop_option(v);
}

std::uint32_t Cia402Axis::set_homing_method(std::int8_t method) {
    std::lock_guard l(m_);
    const bool ok = hooks_.homing_supported ? hooks_.homing_supported(method) : motion::Cia402Homing::supported(method);
    if (!ok) return kAbortRange;
    s_.homing_method = method;
    return 0;
}

void Cia402Axis::set_target_velocity(std::int32_t v) {
    std::lock_guard l(m_);
    update();
    s_.target_velocity = v;
    if (activity_ == Activity::Pv) apply_velocity();
}

void Cia402Axis::update_settings(const std::function<void(Cia402AxisSettings&)>& f) {
    std::lock_guard l(m_);
    update();
    f(s_);
}

Cia402AxisSettings Cia402Axis::settings() const {
    std::lock_guard l(m_);
    return s_;
}

std::int32_t Cia402Axis::position() {
    std::lock_guard l(m_);
    update();
    return static_cast<std::int32_t>(std::llround(motor_.pulse_position()));
}

std::int32_t Cia402Axis::velocity() {
    std::lock_guard l(m_);
    update();
    return static_cast<std::int32_t>(std::llround(motor_.pulse_velocity()));
}

std::uint32_t Cia402Axis::digital_inputs() {
    std::lock_guard l(m_);
    update();
    std::uint32_t v = 0;
    if (motor_.minus_limit_active() || forced_minus_) v |= 1u;
    if (motor_.plus_limit_active() || forced_plus_) v |= 2u;
    if (motor_.home_active()) v |= 4u;
    if (stop_input_) v |= 1u << 16;
    return v;
}

std::uint16_t Cia402Axis::error_code() const {
    std::lock_guard l(m_);
    return error_code_;
}

std::uint8_t Cia402Axis::error_register() const {
    std::lock_guard l(m_);
    return error_register_;
}

Cia402State Cia402Axis::state() const {
    std::lock_guard l(m_);
    return device_->state();
}

double Cia402Axis::pulse_position() {
    std::lock_guard l(m_);
    motor_.update();
    return motor_.pulse_position();
}

std::optional<Nanos> Cia402Axis::last_setpoint_ns() const {
    std::lock_guard l(m_);
    return last_setpoint_;
}

// ---- events and test hooks ---------------------------------------------------------------

void Cia402Axis::halt_motor() {
    std::lock_guard l(m_);
    stop_now();
}

void Cia402Axis::reset() {
    std::lock_guard l(m_);
    stop_now();
    device_ = std::make_unique<Cia402Device>();
    s_ = Cia402AxisSettings{};
    setpoints_.reset();
    pp_.reset();
    limit_hit_ = forced_plus_ = forced_minus_ = following_error_ = stop_input_ = false;
    soft_limit_side_ = 0;
    error_code_ = 0;
    error_register_ = 0;
    last_setpoint_.reset();
}

void Cia402Axis::inject_fault(std::uint16_t code) {
    std::lock_guard l(m_);
    fault_now(code);
}

void Cia402Axis::force_limit(int direction, bool active) {
    if (direction != 1 && direction != -1)
        throw InvalidArgument("cia402 force_limit: direction +1 or -1, not " + std::to_string(direction));
    std::lock_guard l(m_);
    update();
    (direction > 0 ? forced_plus_ : forced_minus_) = active;
    check_forced_limits();
}

void Cia402Axis::jam(bool jammed) {
    std::lock_guard l(m_);
    update();
    motor_.set_jammed(jammed);
}

void Cia402Axis::set_stop_input(bool active) {
    std::lock_guard l(m_);
    update();
    const bool rising = active && !stop_input_;
    stop_input_ = active;
    if (rising && device_->state() == Cia402State::OperationEnabled) {
        device_->on_controlword(cw::kQuickStop);
        setpoints_.reset();
        if (device_->state() == Cia402State::QuickStopActive)
            begin_quick_stop();
        else
            stop_now();
    }
}

void Cia402Axis::loss_of_master() {
    std::lock_guard l(m_);
    const Cia402State before = device_->state();
    device_->loss_of_master();
    const Cia402State after = device_->state();
    if (after == before) return;
    setpoints_.reset();
    if (after == Cia402State::QuickStopActive) {
        begin_quick_stop();
        return;
    }
    stop_now();
    if (after == Cia402State::FaultReactionActive) {
        // 6007h = 1: a fault (0x8130); the motor stopped at once, so the reaction is over.
        device_->fault_reaction_done();
        error_code_ = device_->last_error_code();
        error_register_ = 0x11;  // generic + communication error
    }
}

// ---- behaviour (m_ held) -----------------------------------------------------------------

void Cia402Axis::sync_buffer() {
    // The profile plays a buffered set-point itself once the running one is reached.
    if (!setpoints_.buffered()) return;
    if (!pp_ || activity_ != Activity::Pp) {
        setpoints_.drop_buffered();
        return;
    }
    pp_->target_reached(pp_time());
    if (!pp_->setpoint_pending()) setpoints_.drop_buffered();
}

void Cia402Axis::new_setpoint(std::uint16_t cw) {
    const double target = s_.target_position;
    if (!pp_ || !motor_.moving() || activity_ != Activity::Pp) {
        pp_ = std::make_unique<motion::Cia402ProfilePosition>(params(), motor_.pulse_position());
        pp_t0_ = clock_.now();
    }
    last_setpoint_ = clock_.now();
    const double t = pp_time();
    pp_->new_setpoint(t, target, (cw & cw::kRelative) != 0, (cw & cw::kChangeImmediately) != 0,
                      (cw & kChangeOnSetPoint) != 0);
    if (!pp_->setpoint_pending()) setpoints_.drop_buffered();
    // Software position limits (607Dh): a target beyond one is clipped to it (CiA 402),
    // and the drive shows internal limit active (bit 11) once it stands there.
    const double lo = s_.min_position, hi = s_.max_position;
    const auto& prof = pp_->profile();
    const double end = prof.position(prof.duration());
    soft_limit_side_ = end > hi ? 1 : (end < lo ? -1 : 0);
    if (soft_limit_side_) pp_->new_setpoint(t, soft_limit_side_ > 0 ? hi : lo, false, true);
    // The planner keeps one time line from pp_t0_: join it where it is now.
    motor_.command_from(pp_->profile(), t);
    activity_ = Activity::Pp;
    limit_hit_ = false;
    following_error_ = false;
    check_forced_limits();
}

void Cia402Axis::apply_velocity() {
    motor_.command(motion::cia402_velocity_profile(motion_state(), s_.target_velocity, params(), 1e6));
    limit_hit_ = false;
}

void Cia402Axis::start_homing() {
    motion::Cia402HomingParams p;
    p.method = s_.homing_method;
    p.speed_switch = s_.homing_speed_switch;
    p.speed_zero = s_.homing_speed_zero;
    p.acceleration = s_.homing_acceleration;
    p.home_offset = s_.home_offset;
    homing_.reset();  // its listener goes before the next one comes
    homing_ = std::make_unique<motion::Cia402Homing>(motor_, p);
    homing_->start();
    activity_ = Activity::Homing;
}

void Cia402Axis::decelerate() {
    motor_.command(motion::cia402_velocity_profile(motion_state(), 0.0, params(), 0.0));
    activity_ = Activity::Stopping;
}

void Cia402Axis::begin_quick_stop() {
    if (homing_) {
        homing_->abort();
        homing_.reset();
    }
    if (motor_.moving()) motor_.command(motion::cia402_quick_stop_profile(motion_state(), params()));
    activity_ = Activity::QuickStop;
}

void Cia402Axis::stop_now() {
    if (homing_) {
        homing_->abort();
        homing_.reset();
    }
    motor_.halt();
    activity_ = Activity::Idle;
}

void Cia402Axis::fault_now(std::uint16_t code) {
    stop_now();
    setpoints_.reset();
    device_->fault(code);
    device_->fault_reaction_done();
    error_code_ = code;
    error_register_ = 0x01;  // generic error
}

void Cia402Axis::on_motor_event(const motion::MotorEvent& e) {
    // A limit switch met while moving toward it stops the motor at once (CiA 402:
    // internal limit active).  The homing methods use the switches themselves.
    if (activity_ == Activity::Homing) return;
    using K = motion::MotorEvent::Kind;
    if ((e.kind == K::MinusLimitOn && e.direction < 0) || (e.kind == K::PlusLimitOn && e.direction > 0)) {
        motor_.halt();
        limit_hit_ = true;
        activity_ = Activity::Idle;
    }
}

void Cia402Axis::update() {
    motor_.update();
    check_forced_limits();
    check_following_error();
    if (activity_ == Activity::QuickStop && !motor_.moving()) {
        device_->motion_stopped();
        activity_ = Activity::Idle;
    }
    if (hooks_.vendor_fault) {
        const Cia402State st = device_->state();
        if (st != Cia402State::Fault && st != Cia402State::FaultReactionActive && st != Cia402State::SwitchOnDisabled)
            if (const std::uint16_t code = hooks_.vendor_fault()) fault_now(code);
    }
}

void Cia402Axis::check_forced_limits() {
    // A switch closed by force_limit stops a motion toward it, as one met at its place.
    if (activity_ == Activity::Homing || !motor_.moving()) return;
    const double v = motor_.commanded_velocity();
    if ((forced_plus_ && v > 0) || (forced_minus_ && v < 0)) {
        motor_.halt();
        limit_hit_ = true;
        activity_ = Activity::Idle;
    }
}

void Cia402Axis::check_following_error() {
    // The rotor lags the demand by more than 6065h: stop, fault 0x8611, and report where
    // the rotor is (the position a real drive's encoder shows).  The lag counts from
    // where it was when the motion began: steps a jam lost earlier are lost for good
    // (an open-loop counter), not a following error of this motion.
    if (!motor_.moving()) {
        slip0_ = motor_.slip();
        return;
    }
    if (std::fabs(motor_.slip() - slip0_) <= static_cast<double>(s_.following_error_window)) return;
    const double rotor = motor_.pulse_position() - (motor_.slip() - slip0_);
    stop_now();
    motor_.set_pulse_position(rotor);
    motor_.set_encoder(static_cast<std::int64_t>(std::llround(rotor)));
    following_error_ = true;
    device_->fault(0x8611);
    device_->fault_reaction_done();
    setpoints_.reset();
    error_code_ = 0x8611;
    error_register_ = 0x01;
}

}  // namespace motorbus::canopen

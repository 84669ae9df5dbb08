#include "motorbus/drives/unitek/sim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/motion/planner.hpp"

namespace motorbus::unitek {

namespace {
constexpr double kFull = 32767.0;
constexpr double kHoldForever = 1.0e6;  // s: a speed command holds until the next command

motion::MotorConfig motor_config(const SimConfig& c) {
    motion::MotorConfig m;
    m.steps_per_rev = kCountsPerRev;  // a servo: the "steps" are the position num
    m.counts_per_rev = kCountsPerRev;
    if (c.minus_limit_num) m.minus_limit = {true, *c.minus_limit_num, 0, false, false};
    if (c.plus_limit_num) m.plus_limit = {true, *c.plus_limit_num, 0, false, false};
    m.tick_ns = 250'000;
    return m;
}

Register row(std::uint8_t id, const char* name, bool is_signed, Access a, Quantity q, std::int64_t lo,
             std::int64_t hi, const char* what) {
    Register r;
    r.regid = id;
    r.name = name;
    r.bits = 16;
    r.is_signed = is_signed;
    r.access = a;
    r.quantity = q;
    if (q == Quantity::Current) r.unit.push_back('A');  // (GCC 12 -Wrestrict misfires on a ternary literal)
    r.min = lo;
    r.max = hi;
    r.description = what;
    return r;
}
}  // namespace

RegisterTable sim_default_table() {
    RegisterTable t = RegisterTable::builtin();
    Register r;
    r.regid = kRegPosActual;
    r.name = "POS_IST";
    r.bits = 32;
    r.is_signed = true;
    r.access = Access::ReadOnly;
    r.quantity = Quantity::Position;
    r.unit = "rev";
    r.description = "actual position (NDrive list, not in 002)";
    t.add(r);
    Register e;
    e.regid = kRegErrWarn;
    e.name = "ERR_WARN";
    e.bits = 32;
    e.is_signed = false;
    e.access = Access::ReadOnly;
    e.quantity = Quantity::Raw;
    e.description = "errors (bits 0-15) and warnings (bits 16-31) (NDrive list, not in 002)";
    t.add(e);
    // §6.1's current table: the command is +/- 9 bit; the registers are NDrive's.
    t.add(row(kRegCurrentCmd, "I_CMD", true, Access::ReadWrite, Quantity::Current, -kCurrentCommandMax,
              kCurrentCommandMax, "current command value, +/- 9 bit (NDrive list, not in 002)"));
    t.add(row(kRegCurrentActual, "I_ACT", true, Access::ReadOnly, Quantity::Current, 1, 0,
              "actual current: the command within the smaller of motor and device limit (NDrive list)"));
    t.add(row(kRegCurrentLimit, "I_MAX", false, Access::ReadWrite, Quantity::Current, 0, kCurrentCommandMax,
              "the motor's peak current limit in num (NDrive list, not in 002)"));
    t.add(row(kRegDeviceCurrentMax, "DEVICE_I_MAX", false, Access::ReadOnly, Quantity::Current, 1, 0,
              "the device's peak current in num, §6.1 table (NDrive list)"));
    Register a1 = row(kRegAin1, "AIN1", true, Access::ReadOnly, Quantity::Speed, 1, 0,
                      "analog command input 1: 10 V = 29490 num (§6.1; NDrive list)");
    a1.unit = "rpm";
    t.add(a1);
    a1.regid = kRegAin2;
    a1.name = "AIN2";
    a1.description = "analog command input 2: 10 V = 29490 num (§6.1; NDrive list)";
    t.add(a1);
    return t;
}

void SimConfig::validate() const {
    if (rx_id < kRxIdMin || rx_id > kRxIdMax) throw InvalidArgument("unitek sim rx_id: 0x201..0x27F");
    if (tx_id < kTxIdMin || tx_id > kTxIdMax) throw InvalidArgument("unitek sim tx_id: 0x181..0x1FF");
    RampParams{n_max_rpm, acc_ramp_ms, dec_ramp_ms}.validate();
    if (tol_num < 0) throw InvalidArgument("unitek sim tol_num: >= 0");
    if (minus_limit_num && plus_limit_num && !(*minus_limit_num < *plus_limit_num))
        throw InvalidArgument("unitek sim limits: minus_limit_num must be below plus_limit_num");
    if (torque_continuous_num < 0 || torque_continuous_num > 32767)
        throw InvalidArgument("unitek sim torque_continuous_num: 0..32767");
    device_current(device);
    bit_timing_for_btr(btr);
    if (analog_command < 0 || analog_command > 2) {
        std::string what = "unitek sim analog_command: 0 (the bus), 1 (AIN1) or 2 (AIN2), not ";
        what += std::to_string(analog_command);  // appended: GCC 12's -Wrestrict misfires on "..." + string
        throw InvalidArgument(what);
    }
    if (motor_i_max_num && (*motor_i_max_num < 0 || *motor_i_max_num > kCurrentCommandMax))
        throw InvalidArgument("unitek sim motor_i_max_num: 0..511 num (the +/- 9-bit current range), not " +
                              std::to_string(*motor_i_max_num));
}

Sim::Sim(Clock& clock, SimConfig cfg, RegisterTable table)
    : clock_(clock), cfg_((cfg.validate(), cfg)), table_(std::move(table)), motor_(clock, motor_config(cfg_)),
      rx_id_(cfg_.rx_id), calibrated_(cfg_.calibrated) {
    reset_ram_locked();
    regs_[kRegAccRamp] = static_cast<std::int64_t>(std::llround(cfg_.acc_ramp_ms));
    regs_[kRegRxId] = rx_id_;
    // The factory EEPROM: every writable register as it is at the first power-up.
    for (const auto& r : table_.rows())
        if (r.writable() && r.regid != kRegEeprom) eeprom_[r.regid] = regs_[r.regid];
    last_status_ = status_locked();
}

Sim::Sim(std::shared_ptr<Clock> clock, SimConfig cfg, RegisterTable table)
    : Sim(clock ? *clock : throw InvalidArgument("unitek sim: clock is None"), std::move(cfg), std::move(table)) {
    clock_owner_ = std::move(clock);
}

Sim::~Sim() { close(); }

std::string Sim::describe() const {
    // The transmit id: constant (the receive id may change at run time) and the node's own on the bus.
    char buf[40];
    std::snprintf(buf, sizeof buf, "unitek sim tx 0x%03X", static_cast<unsigned>(cfg_.tx_id));
    return buf;
}

void Sim::reset_ram_locked() {
    for (const auto& r : table_.rows()) regs_[r.regid] = 0;
    regs_[kRegEventMask] = kDefaultEventMask;
    regs_[kRegCurrentLimit] =
        cfg_.motor_i_max_num.value_or(static_cast<std::int64_t>(device_current(cfg_.device).i_max_num));
    mode_ = 0;
    err_warn_ = 0;
    slots_.clear();
    activity_ = Activity::Idle;
}

void Sim::attach(std::shared_ptr<can::Bus> bus) {
    std::lock_guard l(m_);
    if (gate_) throw already_attached();
    // A medium with a bit rate (a virtual hub with wire time) must share the node's:
    // the gate passes nothing either way otherwise (and counts it).
    gate_ = gate_onto(std::move(bus));
    // The gate itself, not `this`: a send racing close() finds a closed bus, never a freed one.
    out_ = [gate = gate_](const can::Frame& f) {
        if (!gate->closed()) gate->send(f, std::chrono::milliseconds(100));
    };
    // All standard ids: the receive id can change at run time (0x68).
    sub_ = gate_->subscribe(can::Filter{0, 0, false, true}, [this](const can::Frame& f) { on_frame(f); });
    timer_ = std::make_unique<TimerThread>();
    // service() asks for 1 ms while something moves or events are on; idle, 10 ms is enough.
    timer_->start(clock_, [this](Nanos) { return service(); }, 10'000'000);
}

void Sim::set_output(std::function<void(const can::Frame&)> out) {
    std::lock_guard l(m_);
    out_ = std::move(out);
}

void Sim::close() {
    if (timer_) timer_->stop();
    std::shared_ptr<can::BitRateGate> gate;
    can::SubscriptionId sub = 0;
    {
        std::lock_guard l(m_);
        gate.swap(gate_);
        sub = std::exchange(sub_, 0);
        if (gate) out_ = nullptr;  // a set_output() sink stays: there was no bus
    }
    if (!gate) return;
    // Outside the lock: unsubscribe waits for a running on_frame, which takes it.
    if (sub != 0) gate->unsubscribe(sub);
    gate->close();  // the gate only: the medium is the caller's
    std::lock_guard l(m_);
    refused_before_ += gate->refused();
}

bool Sim::attached() const {
    std::lock_guard l(m_);
    return gate_ != nullptr;
}

void Sim::send(const std::vector<can::Frame>& frames) {
    std::function<void(const can::Frame&)> out;
    {
        std::lock_guard l(m_);
        out = out_;  // on a bus: the gate drops what a controller at another bit rate cannot put on the wire
    }
    if (!out) return;
    for (const auto& f : frames) {
        try {
            out(f);
        } catch (const Error&) {
            // A full or closed bus: a real drive's frame is lost the same way.
        }
    }
}

// ---- time ------------------------------------------------------------------------------

motion::State Sim::state_locked() {
    return motion::State{motor_.pulse_position(), motor_.pulse_velocity(), 0, 0};
}

RampParams Sim::ramps_locked() const {
    const auto acc = regs_.count(kRegAccRamp) ? static_cast<double>(regs_.at(kRegAccRamp)) : cfg_.acc_ramp_ms;
    return RampParams{cfg_.n_max_rpm, acc, cfg_.dec_ramp_ms};
}

std::vector<can::Frame> Sim::advance_locked(Nanos now) {
    std::vector<can::Frame> out;
    // Cyclic frames in time order; the motor is advanced to each frame's time so
    // the value is the one of that instant.
    while (!slots_.empty()) {
        auto it = std::min_element(slots_.begin(), slots_.end(),
                                   [](const Slot& a, const Slot& b) { return a.next < b.next; });
        if (it->next > now) break;
        motor_.advance_to(std::max(it->next, motor_.time()));
        limits_locked();
        check_events_locked(out);
        const auto regid = it->regid;
        it->next += it->period;
        emit_reply_locked(regid, out);
    }
    motor_.advance_to(std::max(now, motor_.time()));
    limits_locked();
    check_events_locked(out);
    return out;
}

void Sim::limits_locked() {
    // The drive's limit reaction: a motion towards an active limit switch stops
    // (seen at the sim's evaluation times: at most one service period late).
    if (!motor_.moving()) return;
    const double v = motor_.pulse_velocity();
    if ((v > 0 && motor_.plus_limit_active()) || (v < 0 && motor_.minus_limit_active())) {
        motor_.halt();
        activity_ = Activity::Idle;
    }
}

Nanos Sim::service() {
    std::vector<can::Frame> out;
    Nanos next = -1;
    {
        std::lock_guard l(m_);
        out = advance_locked(clock_.now());
        for (const auto& s : slots_) next = next < 0 ? s.next : std::min(next, s.next);
        // While moving or with events on, look again within a millisecond.
        if (motor_.moving() || (mode_ & kModeEvents)) {
            const Nanos soon = clock_.now() + 1'000'000;
            next = next < 0 ? soon : std::min(next, soon);
        }
    }
    send(out);
    return next;
}

// ---- frames ------------------------------------------------------------------------------

void Sim::on_frame(const can::Frame& f) {
    std::vector<can::Frame> out;
    std::optional<std::map<std::uint8_t, std::int64_t>> stored;
    std::function<void(const std::map<std::uint8_t, std::int64_t>&)> cb;
    {
        std::lock_guard l(m_);
        if (f.extended || f.rtr || f.is_fd() || (f.flags & can::kFlagError) || f.id != rx_id_) {
            // B-U20: the drive reads its own receive id only.  Our own transmit id
            // and every other node's traffic land here too (one subscription for all ids).
            if (f.id != cfg_.tx_id) ++counters_.ignored;
            return;
        }
        ++counters_.frames_in;
        out = advance_locked(clock_.now());
        std::optional<ToDrive> t;
        try {
            t = decode_to_drive(f.payload());
        } catch (const FrameError&) {
            ++counters_.malformed;  // B-U03: DLC < 3 ignored
        }
        if (t) {
            handle_locked(*t, out);
            check_events_locked(out);
        }
        if (eeprom_dirty_ && eeprom_cb_) {
            eeprom_dirty_ = false;
            stored = eeprom_;
            cb = eeprom_cb_;
        }
    }
    send(out);
    if (cb) {
        try {
            cb(*stored);
        } catch (...) {
            // A host that cannot save its file must not take the drive down.
        }
    }
    if (timer_) timer_->poke();
}

void Sim::handle_locked(const ToDrive& t, std::vector<can::Frame>& out) {
    if (!t.is_request()) {
        write_locked(t.regid, t.value, t.value_bits);
        return;
    }
    const auto regid = t.request_regid();
    const auto interval = t.request_interval();
    const Register* r = table_.find(regid);
    if (r == nullptr || !r->readable()) {
        ++counters_.unknown;  // B-U22: no reply
        return;
    }
    auto slot = std::find_if(slots_.begin(), slots_.end(), [&](const Slot& s) { return s.regid == regid; });
    const Nanos now = clock_.now();
    if (interval == kIntervalOnce) {
        emit_reply_locked(regid, out);  // a cyclic entry keeps running (B-U07)
    } else if (interval == kIntervalStop) {
        if (slot != slots_.end()) slots_.erase(slot);  // not cyclic: nothing to stop
    } else {
        const Nanos period = static_cast<Nanos>(interval) * 1'000'000;
        if (slot != slots_.end()) {
            slot->period = period;  // a repeated request replaces the period
            slot->next = now + period;
        } else if (static_cast<int>(slots_.size()) < kMaxCyclic) {
            slots_.push_back({regid, period, now + period});
        } else {
            ++counters_.cyclic_refused;  // B-U08: a 9th register is ignored
            return;
        }
        emit_reply_locked(regid, out);  // the first frame at once
    }
}

void Sim::emit_reply_locked(std::uint8_t regid, std::vector<can::Frame>& out) {
    const Register* r = table_.find(regid);
    if (r == nullptr) return;
    const std::int64_t v = value_locked(regid);
    const auto bytes = encode_reply(regid, static_cast<std::uint32_t>(v), r->bits, cfg_.dummy);
    out.push_back(can::Frame::make(cfg_.tx_id, bytes));
    out.back().timestamp_ns = motor_.time();
    ++sent_[regid];
    ++counters_.frames_out;
}

void Sim::check_events_locked(std::vector<can::Frame>& out) {
    const std::uint32_t st = status_locked();
    const std::uint32_t changed = st ^ last_status_;
    last_status_ = st;
    if (!(mode_ & kModeEvents) || changed == 0) return;
    const auto mask = event_status_mask(static_cast<std::uint16_t>(regs_[kRegEventMask]));
    if ((changed & mask) == 0) return;
    // C-U02: the event carries the complete status, 32 bits (DLC 6).
    out.push_back(can::Frame::make(cfg_.tx_id, encode_reply(kRegStatus, st, 32, cfg_.dummy)));
    ++counters_.events_out;
    ++counters_.frames_out;
}

// ---- writes ------------------------------------------------------------------------------

void Sim::write_locked(std::uint8_t regid, std::uint32_t raw, int bits) {
    const Register* r = table_.find(regid);
    if (r == nullptr) {
        ++counters_.unknown;  // no NACK exists: ignored
        return;
    }
    if (!r->writable()) {
        ++counters_.refused;
        return;
    }
    // B-U03: a 16-bit register takes the low 16 bits of a 32-bit write; a 32-bit
    // register written with 16 bits sign-extends when signed.
    const std::int64_t v = r->from_raw(raw, std::min(bits, r->bits));
    if (v < r->lo() || v > r->hi()) {
        ++counters_.refused;  // out of range: ignored, no state change
        return;
    }
    switch (regid) {
        case kRegMode: {
            const auto old = mode_;
            mode_ = static_cast<std::uint16_t>(v);
            if (!(mode_ & kModeDisable)) err_warn_ &= ~kErrorBits;  // enabling again clears the errors
            if ((mode_ & kModeEvents) && !(old & kModeEvents)) last_status_ = status_locked();  // no frame at activation
            apply_enable_locked();
            if ((old & kModeDisable) && !(mode_ & kModeDisable)) analog_speed_locked();
            break;
        }
        case kRegRxId:
            rx_id_ = static_cast<std::uint32_t>(v);  // effective at once (B-U12)
            break;
        case kRegEeprom:
            // B-U13: both levels store every writable register (the set-points and
            // MODE too: the spec's reading; 002 does not restrict what is stored).
            for (const auto& row : table_.rows())
                if (row.writable() && row.regid != kRegEeprom) eeprom_[row.regid] = regs_[row.regid];
            eeprom_dirty_ = true;
            break;
        default: break;
    }
    if (regid == kRegRxId) regs_[regid] = rx_id_;
    else regs_[regid] = v;
    const bool enabled = (status_locked() & kStatusEna) != 0;
    switch (regid) {
        case kRegSpeedCmd:
            if (enabled) {
                activity_ = Activity::Speed;
                speed_locked(static_cast<double>(v), 1.0);
            }
            break;
        case kRegTorqueCmd:
            if (enabled) {
                activity_ = Activity::Torque;
                // No load: the rotor accelerates to N max at a rate proportional to the torque.
                if (v == 0) speed_locked(0, 1.0);
                else speed_locked(v > 0 ? kFull : -kFull, kFull / std::fabs(static_cast<double>(v)));
            }
            break;
        case kRegPosDest:
            if (enabled) {
                activity_ = Activity::Position;
                const auto p = ramps_locked();
                const double full = num_to_counts_per_s(kFull, p);
                motion::Limits lim;
                lim.max_velocity = full;
                lim.max_acceleration = full / std::max(p.acc_ramp_ms, 1.0) * 1000.0;
                lim.max_deceleration = full / std::max(p.dec_ramp_ms, 1.0) * 1000.0;
                motor_.command(motion::plan_trapezoid(state_locked(), static_cast<double>(v), lim));
            }
            break;
        default: break;
    }
}

void Sim::speed_locked(double num, double ramp_scale) {
    auto p = ramps_locked();
    p.acc_ramp_ms = std::min(p.acc_ramp_ms * ramp_scale, 32767.0);
    motor_.command(speed_profile(state_locked(), num, p, kHoldForever));
}

void Sim::apply_enable_locked() {
    if (!(status_locked() & kStatusEna) && motor_.moving()) {
        // The power stage is off: the sim stops the rotor where it is (no load model to coast).
        motor_.halt();
        activity_ = Activity::Idle;
    }
}

// ---- reads ---------------------------------------------------------------------------------

std::uint32_t Sim::status_locked() {
    std::uint32_t s = 0;
    if (!(mode_ & kModeDisable) && hw_enable_ && !(err_warn_ & kErrorBits)) s |= kStatusEna;
    if (motor_.plus_limit_active()) s |= kStatusLimPlus;
    if (motor_.minus_limit_active()) s |= kStatusLimMinus;
    if (cfg_.position_control) s |= kStatusPositionControl;
    if (cfg_.speed_control) s |= kStatusSpeedControl;
    if (calibrated_) s |= kStatusCal;
    const bool icns = icns_forced_ ? *icns_forced_
                                   : (activity_ == Activity::Torque &&
                                      std::llabs(regs_[kRegTorqueCmd]) > cfg_.torque_continuous_num);
    if (icns) s |= kStatusIcns;
    if (activity_ == Activity::Position && !motor_.moving() &&
        std::fabs(motor_.pulse_position() - static_cast<double>(regs_[kRegPosDest])) <= static_cast<double>(cfg_.tol_num))
        s |= kStatusTol;
    return s;
}

std::int64_t Sim::value_locked(std::uint8_t regid) {
    switch (regid) {
        case kRegStatus: return status_locked() & 0xFFFF;  // C-U02: 16 bits in a read reply
        case kRegErrWarn: return err_warn_;
        case kRegPosActual: {
            const double p = std::clamp(motor_.pulse_position(), -2147483647.0, 2147483647.0);
            return static_cast<std::int64_t>(std::llround(p));
        }
        case kRegCurrentActual: {
            // The drive delivers the command within the smaller of the motor and
            // device limits (§6.1); nothing while the power stage is off.
            if (!(status_locked() & kStatusEna)) return 0;
            const std::int64_t lim = current_limit_locked();
            return std::clamp<std::int64_t>(regs_[kRegCurrentCmd], -lim, lim);
        }
        case kRegDeviceCurrentMax: return static_cast<std::int64_t>(device_current(cfg_.device).i_max_num);
        case kRegAin1: return ain_[0];
        case kRegAin2: return ain_[1];
        case kRegSpeedActual: {
            const double num = motor_.pulse_velocity() / num_to_counts_per_s(1.0, ramps_locked());
            return static_cast<std::int64_t>(std::llround(std::clamp(num, -kFull, kFull)));
        }
        default: {
            auto it = regs_.find(regid);
            return it == regs_.end() ? 0 : it->second;
        }
    }
}

std::int64_t Sim::current_limit_locked() const {
    const auto it = regs_.find(kRegCurrentLimit);
    return effective_current_limit_num(device_current(cfg_.device), it == regs_.end() ? 0 : it->second);
}

// ---- inputs / introspection ----------------------------------------------------------------------

#define UNITEK_SIM_LOCKED(body)                        \
    std::vector<can::Frame> out_frames;                \
    {                                                  \
        std::lock_guard l(m_);                         \
        out_frames = advance_locked(clock_.now());     \
        body;                                          \
        check_events_locked(out_frames);               \
    }                                                  \
    send(out_frames)

void Sim::set_hardware_enable(bool on) {
    UNITEK_SIM_LOCKED(hw_enable_ = on; apply_enable_locked(); if (on) analog_speed_locked());
}

void Sim::force_limit(int direction, std::optional<bool> active) {
    if (direction != 1 && direction != -1) throw InvalidArgument("unitek sim force_limit: direction +1 or -1");
    UNITEK_SIM_LOCKED({
        motor_.force_switch(direction > 0 ? motion::Switch::PlusLimit : motion::Switch::MinusLimit, active);
        // A limit switch stops a motion towards it (the drive's own limit reaction).
        if (active.value_or(false) && motor_.moving() && motor_.pulse_velocity() * direction > 0) motor_.halt();
    });
}

void Sim::set_analog_input(int channel, double volts) {
    if (channel != 1 && channel != 2) throw InvalidArgument("unitek sim analog input: 1 (AIN1) or 2 (AIN2)");
    const std::int64_t num = analog_command_num(volts);
    UNITEK_SIM_LOCKED(ain_[channel - 1] = num; analog_speed_locked());
}

void Sim::analog_speed_locked() {
    // The analog input is the speed command when NDrive selects it; like SPEED_CMD,
    // it takes effect while the drive is enabled.
    if (cfg_.analog_command == 0 || !(status_locked() & kStatusEna)) return;
    activity_ = Activity::Speed;
    speed_locked(static_cast<double>(ain_[cfg_.analog_command - 1]), 1.0);
}

void Sim::set_calibrated(bool on) { UNITEK_SIM_LOCKED(calibrated_ = on); }

void Sim::force_icns(std::optional<bool> active) { UNITEK_SIM_LOCKED(icns_forced_ = active); }

void Sim::force_error(std::uint32_t bits) { UNITEK_SIM_LOCKED(err_warn_ |= bits; apply_enable_locked()); }

void Sim::power_cycle() {
    std::lock_guard l(m_);
    motor_.advance_to(std::max(clock_.now(), motor_.time()));
    motor_.halt();
    reset_ram_locked();
    for (const auto& [id, v] : eeprom_) regs_[id] = v;
    rx_id_ = static_cast<std::uint32_t>(regs_[kRegRxId]);
    // A stored MODE is in effect from power-up (disable, status events).  Stored
    // set-points read back but start no motion: the rotor is at rest until a
    // command is written (the reading taken; 002 does not say).
    mode_ = static_cast<std::uint16_t>(regs_[kRegMode]);
    last_status_ = status_locked();
}

std::uint32_t Sim::status() {
    std::lock_guard l(m_);
    motor_.advance_to(std::max(clock_.now(), motor_.time()));
    return status_locked();
}

std::int64_t Sim::value(std::uint8_t regid) {
    table_.at(regid);
    std::lock_guard l(m_);
    motor_.advance_to(std::max(clock_.now(), motor_.time()));
    return regid == kRegStatus ? status_locked() : value_locked(regid);
}

double Sim::position_num() {
    std::lock_guard l(m_);
    motor_.advance_to(std::max(clock_.now(), motor_.time()));
    return motor_.pulse_position();
}

double Sim::speed_num() {
    std::lock_guard l(m_);
    motor_.advance_to(std::max(clock_.now(), motor_.time()));
    return motor_.pulse_velocity() / num_to_counts_per_s(1.0, ramps_locked());
}

double Sim::bit_rate() const { return bit_timing_for_btr(cfg_.btr).bit_rate(); }

double Sim::bus_bit_rate() const {
    std::lock_guard l(m_);
    return gate_ ? gate_->medium_bit_rate() : 0.0;
}

std::uint32_t Sim::rx_id() const {
    std::lock_guard l(m_);
    return rx_id_;
}

std::vector<std::pair<std::uint8_t, int>> Sim::cyclic() const {
    std::lock_guard l(m_);
    std::vector<std::pair<std::uint8_t, int>> out;
    for (const auto& s : slots_) out.emplace_back(s.regid, static_cast<int>(s.period / 1'000'000));
    return out;
}

std::uint64_t Sim::sent(std::uint8_t regid) const {
    std::lock_guard l(m_);
    auto it = sent_.find(regid);
    return it == sent_.end() ? 0 : it->second;
}

SimCounters Sim::counters() const {
    std::lock_guard l(m_);
    SimCounters c = counters_;
    // Another bit rate: the controller decodes nothing (it answers with error frames); the gate counts.
    c.bit_rate_mismatch = refused_before_ + (gate_ ? gate_->refused() : 0);
    return c;
}

void Sim::on_eeprom_store(std::function<void(const std::map<std::uint8_t, std::int64_t>&)> cb) {
    std::lock_guard l(m_);
    eeprom_cb_ = std::move(cb);
}

std::map<std::uint8_t, std::int64_t> Sim::eeprom() const {
    std::lock_guard l(m_);
    return eeprom_;
}

void Sim::load_eeprom(const std::map<std::uint8_t, std::int64_t>& values) {
    {
        std::lock_guard l(m_);
        for (const auto& [id, v] : values) {
            const Register* r = table_.find(id);
            if (r == nullptr || !r->writable() || v < r->lo() || v > r->hi())
                throw InvalidArgument("unitek sim eeprom: register " + std::to_string(id) + " value out of place");
            eeprom_[id] = v;
        }
    }
    power_cycle();
}

}  // namespace motorbus::unitek

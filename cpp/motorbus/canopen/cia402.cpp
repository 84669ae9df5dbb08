#include "motorbus/runtime/interrupt.hpp"
#include "motorbus/canopen/cia402.hpp"

#include <thread>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

const char* to_string(Cia402State s) {
    switch (s) {
        case Cia402State::NotReadyToSwitchOn: return "NOT READY TO SWITCH ON";
        case Cia402State::SwitchOnDisabled: return "SWITCH ON DISABLED";
        case Cia402State::ReadyToSwitchOn: return "READY TO SWITCH ON";
        case Cia402State::SwitchedOn: return "SWITCHED ON";
        case Cia402State::OperationEnabled: return "OPERATION ENABLED";
        case Cia402State::QuickStopActive: return "QUICK STOP ACTIVE";
        case Cia402State::FaultReactionActive: return "FAULT REACTION ACTIVE";
        case Cia402State::Fault: return "FAULT";
        case Cia402State::Unknown: return "UNKNOWN";
    }
    return "UNKNOWN";
}

const char* to_string(OpMode m) {
    switch (m) {
        case OpMode::None: return "none";
        case OpMode::ProfilePosition: return "profile position";
        case OpMode::Velocity: return "velocity";
        case OpMode::ProfileVelocity: return "profile velocity";
        case OpMode::ProfileTorque: return "profile torque";
        case OpMode::Homing: return "homing";
        case OpMode::InterpolatedPosition: return "interpolated position";
        case OpMode::CyclicSyncPosition: return "cyclic synchronous position";
        case OpMode::CyclicSyncVelocity: return "cyclic synchronous velocity";
        case OpMode::CyclicSyncTorque: return "cyclic synchronous torque";
    }
    return "manufacturer";
}

std::optional<Cia402State> cia402_state_from_name(std::string_view name) {
    for (int i = 0; i <= static_cast<int>(Cia402State::Unknown); ++i)
        if (name == to_string(static_cast<Cia402State>(i))) return static_cast<Cia402State>(i);
    return std::nullopt;
}

Cia402State decode_statusword(std::uint16_t s) {
    switch (s & 0x4F) {
        case 0x00: return Cia402State::NotReadyToSwitchOn;
        case 0x40: return Cia402State::SwitchOnDisabled;
        case 0x0F: return Cia402State::FaultReactionActive;
        case 0x08: return Cia402State::Fault;
        default: break;
    }
    switch (s & 0x6F) {
        case 0x21: return Cia402State::ReadyToSwitchOn;
        case 0x23: return Cia402State::SwitchedOn;
        case 0x27: return Cia402State::OperationEnabled;
        case 0x07: return Cia402State::QuickStopActive;
        default: return Cia402State::Unknown;  // D3
    }
}

std::uint16_t statusword_bits(Cia402State s) {
    switch (s) {
        case Cia402State::NotReadyToSwitchOn: return 0x0000;
        case Cia402State::SwitchOnDisabled: return 0x0040;
        case Cia402State::ReadyToSwitchOn: return 0x0021;
        case Cia402State::SwitchedOn: return 0x0023;
        case Cia402State::OperationEnabled: return 0x0027;
        case Cia402State::QuickStopActive: return 0x0007;
        case Cia402State::FaultReactionActive: return 0x000F;
        case Cia402State::Fault: return 0x0008;
        case Cia402State::Unknown: break;
    }
    throw InvalidArgument("UNKNOWN has no statusword");
}

std::optional<Cia402Step> next_step(Cia402State from, Cia402State to) {
    using S = Cia402State;
    if (from == to || from == S::Unknown || from == S::NotReadyToSwitchOn ||
        from == S::FaultReactionActive)
        return std::nullopt;  // nothing to do, or the drive moves on by itself
    if (from == S::Fault) return Cia402Step{cw::kFaultReset, 15};
    if (from == S::QuickStopActive) return Cia402Step{cw::kDisableVoltage, 12};
    switch (to) {
        case S::OperationEnabled:
            if (from == S::SwitchOnDisabled) return Cia402Step{cw::kShutdown, 2};
            if (from == S::ReadyToSwitchOn) return Cia402Step{cw::kSwitchOn, 3};
            if (from == S::SwitchedOn) return Cia402Step{cw::kEnableOperation, 4};
            break;
        case S::SwitchedOn:
            if (from == S::SwitchOnDisabled) return Cia402Step{cw::kShutdown, 2};
            if (from == S::ReadyToSwitchOn) return Cia402Step{cw::kSwitchOn, 3};
            if (from == S::OperationEnabled) return Cia402Step{cw::kDisableOperation, 5};
            break;
        case S::ReadyToSwitchOn:
            if (from == S::SwitchOnDisabled) return Cia402Step{cw::kShutdown, 2};
            if (from == S::SwitchedOn) return Cia402Step{cw::kShutdown, 6};
            if (from == S::OperationEnabled) return Cia402Step{cw::kShutdown, 8};
            break;
        case S::SwitchOnDisabled:
            if (from == S::ReadyToSwitchOn) return Cia402Step{cw::kDisableVoltage, 7};
            if (from == S::SwitchedOn) return Cia402Step{cw::kDisableVoltage, 10};
            if (from == S::OperationEnabled) return Cia402Step{cw::kDisableVoltage, 9};
            break;
        default: break;
    }
    return std::nullopt;
}

// ---- host -----------------------------------------------------------------

Cia402Host::Cia402Host(SdoAccess& sdo, std::uint8_t node, Cia402HostOptions options)
    : sdo_(sdo), node_(node), opt_(options) {
    if (node == 0 || node > 127) throw InvalidArgument("CiA 402 host: node id must be 1-127");
}

void Cia402Host::use_statusword_pdo(PdoReceiver* rx) {
    if (rx) {
        bool mapped = false;
        for (std::size_t i = 0; i < rx->layout().size(); ++i)
            mapped |= rx->layout().entry(i).index == kStatusword && rx->layout().entry(i).bits == 16;
        if (!mapped) throw InvalidArgument("statusword PDO: 0x6041 (16 bits) is not mapped");
    }
    sw_pdo_ = rx;
}

void Cia402Host::use_controlword_writer(std::function<void(std::uint16_t)> fn) { cw_writer_ = std::move(fn); }

std::uint16_t Cia402Host::read_statusword() {
    if (sw_pdo_)
        if (auto v = sw_pdo_->value(kStatusword, 0)) return static_cast<std::uint16_t>(*v);
    return static_cast<std::uint16_t>(sdo_.read_uint(node_, kStatusword, 0));
}

void Cia402Host::write_controlword(std::uint16_t c) {
    if (cw_writer_)
        cw_writer_(c);
    else
        sdo_.write_u16(node_, kControlword, 0, c);
    last_cw_ = c;
}

void Cia402Host::fault_reset() {
    if (last_cw_ & cw::kFaultReset) write_controlword(static_cast<std::uint16_t>(last_cw_ & ~cw::kFaultReset));
    write_controlword(cw::kFaultReset);
}

std::uint16_t Cia402Host::wait_statusword(std::uint16_t mask, std::uint16_t value,
                                         std::optional<std::chrono::nanoseconds> timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout.value_or(opt_.timeout);
    while (true) {
        std::uint64_t seen = sw_pdo_ ? sw_pdo_->received() : 0;
        const std::uint16_t s = read_statusword();
        if ((s & mask) == value) return s;
        const auto now = std::chrono::steady_clock::now();
        if (now >= deadline)
            throw TimeoutError("CiA 402 node " + std::to_string(node_) + ": statusword 0x" +
                               [&] { char b[8]; std::snprintf(b, sizeof b, "%04X", s); return std::string(b); }() +
                               " (" + to_string(decode_statusword(s)) + ") did not reach the expected bits");
        if (sw_pdo_ && sw_pdo_->received() > 0) {
            // Event-driven: sleep until the next TPDO carrying the statusword.
            sw_pdo_->wait_newer(seen, std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - now));
        } else {
            interruptible_sleep_for(std::min<std::chrono::nanoseconds>(
                opt_.sdo_poll, std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - now)));
        }
    }
}

Cia402State Cia402Host::wait_state(Cia402State target, std::optional<std::chrono::nanoseconds> timeout) {
    const std::uint16_t mask =
        (target == Cia402State::NotReadyToSwitchOn || target == Cia402State::SwitchOnDisabled ||
         target == Cia402State::Fault || target == Cia402State::FaultReactionActive)
            ? 0x4F
            : 0x6F;
    wait_statusword(mask, statusword_bits(target), timeout);
    return target;
}

void Cia402Host::wait_leave(Cia402State cur, int transition) {
    const auto deadline = std::chrono::steady_clock::now() + opt_.timeout;
    while (true) {
        const std::uint64_t seen = sw_pdo_ ? sw_pdo_->received() : 0;
        if (decode_statusword(read_statusword()) != cur) return;
        const auto now = std::chrono::steady_clock::now();
        if (now >= deadline)
            throw TimeoutError(std::string("CiA 402 node ") + std::to_string(node_) + " stayed in " +
                               to_string(cur) + " (transition " + std::to_string(transition) + ")");
        const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - now);
        if (sw_pdo_ && seen > 0)
            sw_pdo_->wait_newer(seen, left);
        else
            interruptible_sleep_for(std::min(opt_.sdo_poll, left));
    }
}

void Cia402Host::go_to(Cia402State target) {
    if (target != Cia402State::OperationEnabled && target != Cia402State::SwitchedOn &&
        target != Cia402State::ReadyToSwitchOn && target != Cia402State::SwitchOnDisabled)
        throw InvalidArgument(std::string("CiA 402: cannot command state ") + to_string(target));
    bool reset_done = false;
    for (int guard = 0; guard < 12; ++guard) {
        const std::uint16_t s = read_statusword();
        const Cia402State cur = decode_statusword(s);
        if (cur == target) return;
        if (cur == Cia402State::Unknown)
            throw ProtocolError("CiA 402: statusword pattern not in the state table (UNKNOWN)",
                                {std::uint8_t(s), std::uint8_t(s >> 8)});
        if (cur == Cia402State::Fault && reset_done)
            throw DriveFault("CiA 402 node " + std::to_string(node_) + " is in FAULT");
        if (cur == Cia402State::NotReadyToSwitchOn || cur == Cia402State::FaultReactionActive) {
            wait_leave(cur, cur == Cia402State::NotReadyToSwitchOn ? 1 : 14);  // automatic
            continue;
        }
        auto step = next_step(cur, target);
        if (!step) throw InvalidArgument("CiA 402: no transition path");
        if (step->transition == 15) {
            fault_reset();
            reset_done = true;
        } else {
            write_controlword(step->controlword);
        }
        try {
            wait_leave(cur, step->transition);
        } catch (const TimeoutError&) {
            if (cur == Cia402State::Fault)
                throw DriveFault("CiA 402 node " + std::to_string(node_) + ": fault reset did not clear the fault");
            throw;
        }
    }
    throw TimeoutError("CiA 402: state machine did not settle");
}

void Cia402Host::set_mode(OpMode m) {
    sdo_.write_u8(node_, kModesOfOperation, 0, static_cast<std::uint8_t>(m));
    const auto deadline = std::chrono::steady_clock::now() + opt_.timeout;
    while (mode() != m) {
        if (std::chrono::steady_clock::now() >= deadline)
            throw TimeoutError(std::string("CiA 402: 0x6061 did not follow mode ") + to_string(m));
        interruptible_sleep_for(opt_.sdo_poll);
    }
}

OpMode Cia402Host::mode() {
    return static_cast<OpMode>(static_cast<std::int8_t>(sdo_.read_uint(node_, kModesOfOperationDisplay, 0)));
}

void Cia402Host::move_to(std::int32_t target, bool relative, bool immediate) {
    sdo_.write_u32(node_, kTargetPosition, 0, static_cast<std::uint32_t>(target));
    std::uint16_t base = cw::kEnableOperation;
    if (immediate) base |= cw::kChangeImmediately;
    if (relative) base |= cw::kRelative;
    // The drive must have dropped the previous acknowledge before a new edge counts.
    wait_statusword(sw::kSetPointAck, 0);
    write_controlword(static_cast<std::uint16_t>(base | cw::kNewSetPoint));
    const std::uint16_t s = wait_statusword(sw::kSetPointAck, sw::kSetPointAck);
    if (decode_statusword(s) == Cia402State::Fault) throw DriveFault("CiA 402: fault during set-point handshake");
    write_controlword(base);
}

void Cia402Host::wait_target_reached(std::optional<std::chrono::nanoseconds> timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout.value_or(opt_.timeout);
    while (true) {
        auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() < 0) left = std::chrono::nanoseconds(0);
        // Either target reached or a fault ends the wait; check both on each change.
        const std::uint16_t s = read_statusword();
        const auto st = decode_statusword(s);
        if (st == Cia402State::Fault || st == Cia402State::FaultReactionActive)
            throw DriveFault("CiA 402 node " + std::to_string(node_) + " faulted while moving");
        if (s & sw::kTargetReached) return;
        if (left.count() == 0) throw TimeoutError("CiA 402: target not reached in time");
        if (sw_pdo_ && sw_pdo_->received() > 0)
            sw_pdo_->wait_newer(sw_pdo_->received(), left);
        else
            interruptible_sleep_for(std::min(opt_.sdo_poll, left));
    }
}

void Cia402Host::set_velocity(std::int32_t velocity) {
    sdo_.write_u32(node_, kTargetVelocity, 0, static_cast<std::uint32_t>(velocity));
    write_controlword(static_cast<std::uint16_t>(cw::kEnableOperation | (last_cw_ & ~cw::kHalt & 0xFF70)));
}

void Cia402Host::home(std::optional<std::int8_t> method, std::optional<std::chrono::nanoseconds> timeout) {
    if (method) sdo_.write_u8(node_, kHomingMethod, 0, static_cast<std::uint8_t>(*method));
    write_controlword(cw::kEnableOperation);
    write_controlword(static_cast<std::uint16_t>(cw::kEnableOperation | cw::kNewSetPoint));
    const auto deadline = std::chrono::steady_clock::now() + timeout.value_or(opt_.timeout);
    while (true) {
        const std::uint16_t s = read_statusword();
        if (s & sw::kFollowingError) {
            write_controlword(cw::kEnableOperation);
            throw DriveFault("CiA 402: homing error (statusword bit 13)");
        }
        if ((s & (sw::kSetPointAck | sw::kTargetReached)) == (sw::kSetPointAck | sw::kTargetReached)) break;
        const auto st = decode_statusword(s);
        if (st == Cia402State::Fault || st == Cia402State::FaultReactionActive)
            throw DriveFault("CiA 402: fault during homing");
        auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) throw TimeoutError("CiA 402: homing did not complete in time");
        if (sw_pdo_ && sw_pdo_->received() > 0)
            sw_pdo_->wait_newer(sw_pdo_->received(), left);
        else
            interruptible_sleep_for(std::min(opt_.sdo_poll, left));
    }
    write_controlword(cw::kEnableOperation);
}

// ---- device ---------------------------------------------------------------

Cia402Device::Cia402Device() = default;

Cia402State Cia402Device::state() const {
    std::lock_guard l(m_);
    return state_;
}

std::uint16_t Cia402Device::controlword() const {
    std::lock_guard l(m_);
    return cw_;
}

std::uint16_t Cia402Device::statusword() const {
    std::lock_guard l(m_);
    std::uint16_t s = statusword_bits(state_);
    if (state_ == Cia402State::ReadyToSwitchOn || state_ == Cia402State::SwitchedOn ||
        state_ == Cia402State::OperationEnabled || state_ == Cia402State::QuickStopActive ||
        state_ == Cia402State::FaultReactionActive)
        s |= sw::kVoltageEnabled;
    s |= sw::kRemote;
    s |= extra_ & 0xFF80;
    if (mode_ == static_cast<std::int8_t>(OpMode::ProfilePosition)) {
        s &= static_cast<std::uint16_t>(~sw::kSetPointAck);
        if (ack_) s |= sw::kSetPointAck;
    }
    return s;
}

int Cia402Device::go(Cia402State to, int transition, std::optional<Change>& ch) {
    if (!ch) ch = Change{state_, to, transition};
    ch->to = to;
    ch->transition = transition;
    state_ = to;
    return transition;
}

void Cia402Device::notify(const std::optional<Change>& ch) {
    if (ch && on_state_change) on_state_change(ch->from, ch->to, ch->transition);
}

int Cia402Device::on_controlword(std::uint16_t c) {
    std::optional<Change> ch;
    int t = -1;
    bool setpoint_edge = false, quick_stop = false;
    std::int16_t qs_option = 0;
    {
        std::lock_guard l(m_);
        const std::uint16_t prev = cw_;
        cw_ = c;
        using S = Cia402State;
        if (c & cw::kFaultReset) {
            // Only the rising edge counts, and only in FAULT (transition 15).
            if (!(prev & cw::kFaultReset) && state_ == S::Fault) {
                error_code_ = 0;
                t = go(S::SwitchOnDisabled, 15, ch);
            }
        } else {
            const bool shutdown = (c & 0x87) == 0x06;
            const bool switch_on = (c & 0x8F) == 0x07;  // also "disable operation"
            const bool enable = (c & 0x8F) == 0x0F;
            const bool disable_voltage = (c & 0x82) == 0x00;
            const bool qs = (c & 0x86) == 0x02;
            switch (state_) {
                case S::SwitchOnDisabled:
                    if (shutdown) t = go(S::ReadyToSwitchOn, 2, ch);  // D1: nothing else moves it
                    break;
                case S::ReadyToSwitchOn:
                    if (switch_on) t = go(S::SwitchedOn, 3, ch);
                    else if (enable) {
                        go(S::SwitchedOn, 3, ch);
                        t = go(S::OperationEnabled, 4, ch);
                    } else if (disable_voltage || qs) t = go(S::SwitchOnDisabled, 7, ch);
                    break;
                case S::SwitchedOn:
                    if (enable) t = go(S::OperationEnabled, 4, ch);
                    else if (shutdown) t = go(S::ReadyToSwitchOn, 6, ch);
                    else if (disable_voltage || qs) t = go(S::SwitchOnDisabled, 10, ch);
                    break;
                case S::OperationEnabled:
                    if (switch_on) t = go(S::SwitchedOn, 5, ch);
                    else if (shutdown) t = go(S::ReadyToSwitchOn, 8, ch);
                    else if (disable_voltage) t = go(S::SwitchOnDisabled, 9, ch);
                    else if (qs) {
                        t = go(S::QuickStopActive, 11, ch);
                        quick_stop = true;
                        qs_option = quick_stop_option_;
                        if (quick_stop_option_ == 0) t = go(S::SwitchOnDisabled, 12, ch);  // no ramp
                    }
                    break;
                case S::QuickStopActive:
                    if (disable_voltage) t = go(S::SwitchOnDisabled, 12, ch);
                    else if (enable && quick_stop_option_ >= 5 && quick_stop_option_ <= 8)
                        t = go(S::OperationEnabled, 16, ch);
                    break;
                default: break;  // NotReady, FaultReactionActive, Fault: only automatic / reset
            }
            if (state_ == S::OperationEnabled) {
                const bool rising = (c & cw::kNewSetPoint) && !(prev & cw::kNewSetPoint);
                if (rising) setpoint_edge = true;
                if (!(c & cw::kNewSetPoint)) ack_ = false;
            } else {
                ack_ = false;
            }
        }
    }
    notify(ch);
    if (quick_stop && on_quick_stop) on_quick_stop(qs_option);
    if (setpoint_edge) {
        const bool accepted = on_new_setpoint ? on_new_setpoint(c) : true;
        std::lock_guard l(m_);
        if (accepted && (cw_ & cw::kNewSetPoint)) ack_ = true;
    }
    return t;
}

std::uint32_t Cia402Device::set_mode(std::int8_t m) {
    std::lock_guard l(m_);
    if (!supported_.count(m)) return 0x06090030;  // D4
    mode_ = m;
    ack_ = false;
    return 0;
}

std::int8_t Cia402Device::mode() const {
    std::lock_guard l(m_);
    return mode_;
}

void Cia402Device::set_supported_modes(std::set<std::int8_t> modes) {
    std::lock_guard l(m_);
    supported_ = std::move(modes);
}

std::uint32_t Cia402Device::set_abort_connection_option(std::int16_t v) {
    if (v > 3) return 0x06090030;
    std::lock_guard l(m_);
    abort_option_ = v;
    return 0;
}

std::uint32_t Cia402Device::set_quick_stop_option(std::int16_t v) {
    if (v > 8) return 0x06090030;
    std::lock_guard l(m_);
    quick_stop_option_ = v;
    return 0;
}

std::int16_t Cia402Device::quick_stop_option() const {
    std::lock_guard l(m_);
    return quick_stop_option_;
}

std::int16_t Cia402Device::abort_connection_option() const {
    std::lock_guard l(m_);
    return abort_option_;
}

void Cia402Device::fault(std::uint16_t code) {
    std::optional<Change> ch;
    {
        std::lock_guard l(m_);
        if (state_ == Cia402State::Fault || state_ == Cia402State::FaultReactionActive) return;
        error_code_ = code;
        ack_ = false;
        go(Cia402State::FaultReactionActive, 13, ch);
        if (fault_option_ == 0) go(Cia402State::Fault, 14, ch);
    }
    notify(ch);
}

void Cia402Device::fault_reaction_done() {
    std::optional<Change> ch;
    {
        std::lock_guard l(m_);
        if (state_ == Cia402State::FaultReactionActive) go(Cia402State::Fault, 14, ch);
    }
    notify(ch);
}

int Cia402Device::loss_of_master() {
    std::int16_t opt;
    {
        std::lock_guard l(m_);
        if (state_ != Cia402State::OperationEnabled) return -1;
        opt = abort_option_;
    }
    switch (opt) {
        case 0: return -1;
        case 2: return on_controlword(cw::kDisableVoltage);
        case 3: return on_controlword(cw::kQuickStop);
        default: fault(0x8130); return 13;  // 1 and manufacturer-specific: fault
    }
}

void Cia402Device::motion_stopped() {
    std::optional<Change> ch;
    {
        std::lock_guard l(m_);
        if (state_ == Cia402State::QuickStopActive && quick_stop_option_ >= 1 && quick_stop_option_ <= 4)
            go(Cia402State::SwitchOnDisabled, 12, ch);
        else if (state_ == Cia402State::FaultReactionActive)
            go(Cia402State::Fault, 14, ch);
    }
    notify(ch);
}

std::uint16_t Cia402Device::last_error_code() const {
    std::lock_guard l(m_);
    return error_code_;
}

void Cia402Device::set_status_bits(std::uint16_t mask, std::uint16_t value) {
    std::lock_guard l(m_);
    mask &= 0xFF80;  // the state bits belong to the state machine
    extra_ = static_cast<std::uint16_t>((extra_ & ~mask) | (value & mask));
}

bool Cia402Device::drive_enabled() const {
    std::lock_guard l(m_);
    return state_ == Cia402State::OperationEnabled || state_ == Cia402State::QuickStopActive ||
           state_ == Cia402State::FaultReactionActive;
}

}  // namespace motorbus::canopen

// The DMX-CAN's CANopen front end (manual 000 chapters 8 and 10): an SDO
// server (expedited only) over the object dictionary of Table 10.1 and the
// CiA DSP-402 state machine as §8 names it.  It owns no motion of its own: a
// set-point, a jog, a homing, a clear or a store become the same firmware
// commands the ASCII front end runs (Sim::command), on the same state.  That is
// what makes the simulator one drive with two front ends.
#include <cstdio>
#include <cstring>
#include <limits>

#include "motorbus/can/bit_rate_gate.hpp"
#include "motorbus/canopen/cia402.hpp"
#include "motorbus/drives/arcus/sim_core.hpp"

namespace motorbus::arcus {

using canopen::Cia402State;

namespace {

// SDO abort codes (CiA 301 §7.2.4.3.17); manual 000 lists none (B-A02).
constexpr std::uint32_t kAbortCommand = 0x05040001;    // segmented / block / unknown specifier
constexpr std::uint32_t kAbortWriteOnly = 0x06010001;  // read of 6060h
constexpr std::uint32_t kAbortReadOnly = 0x06010002;
constexpr std::uint32_t kAbortNoObject = 0x06020000;
constexpr std::uint32_t kAbortSizeHigh = 0x06070012;
constexpr std::uint32_t kAbortSizeLow = 0x06070013;
constexpr std::uint32_t kAbortNoSub = 0x06090011;
constexpr std::uint32_t kAbortRange = 0x06090030;
constexpr std::uint32_t kAbortDeviceState = 0x08000022;

constexpr std::int64_t kU32 = 0xFFFFFFFFll;
constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();

constexpr std::uint16_t kHalt = 1u << 8;
constexpr std::uint16_t kFaultReset = 1u << 7;

int type_size(const char* type) {
    if (!std::strcmp(type, "U8") || !std::strcmp(type, "I8")) return 1;
    if (!std::strcmp(type, "U16") || !std::strcmp(type, "I16")) return 2;
    if (!std::strcmp(type, "VISIBLE_STRING")) return 3;
    return 4;
}
bool type_signed(const char* type) { return type[0] == 'I'; }

// "NAME=value" / "Xvalue": a command line for the firmware interpreter.
std::string line(const char* name, std::int64_t value, const char* sep = "=") {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%s%s%lld", name, sep, static_cast<long long>(value));
    return buf;
}

}  // namespace

const std::vector<CanopenObject>& canopen_objects() {
    // clang-format off
    static const std::vector<CanopenObject> table = {
        {0x1000, 0, "Device type", "U32", "const", 0x0192, 0, 0, "", false},
        {0x1001, 0, "Error register", "U8", "ro", 0, 0, 0, "", false},
        {0x1008, 0, "Manufacturer device name", "VISIBLE_STRING", "ro", 0x434D44, 0, 0, "", false},  // "DMC"
        {0x1018, 0, "Identity: number of entries", "U8", "ro", 4, 0, 0, "", false},
        {0x1018, 1, "Vendor ID", "U32", "ro", 0, 0, 0, "", false},
        {0x1018, 2, "Product code", "U32", "ro", 0, 0, 0, "", false},
        {0x1018, 3, "Revision number", "U32", "ro", 112, 0, 0, "", false},
        {0x1018, 4, "Serial number", "U32", "ro", 0, 0, 0, "", false},
        {0x2000, 0, "Alarm/In-Position enable", "U8", "rw", 1, 0, 1, "", true},
        {0x2001, 0, "StepNLoop parameters: number of elements", "U8", "ro", 5, 0, 0, "", true},
        {0x2001, 1, "StepNLoop enable", "U32", "rw", 1, 0, 1, "", true},
        {0x2001, 2, "Max attempt", "U32", "rw", 10, 0, kU32, "attempts", true},
        {0x2001, 3, "Tolerance range", "U32", "rw", 10, 0, kU32, "pulses/counts", true},
        {0x2001, 4, "Idle tolerance range", "U32", "rw", 5, 0, kU32, "pulses/counts", true},
        {0x2001, 5, "Error range", "U32", "rw", 1000, 0, kU32, "pulses/counts", true},
        {0x2002, 0, "StepNLoop delta", "I32", "ro", 0, 0, 0, "counts", false},
        {0x2003, 0, "StepNLoop status", "U16", "ro", 0, 0, 0, "", false},
        {0x2004, 0, "Driver settings: number of elements", "U8", "ro", 4, 0, 0, "", true},
        {0x2004, 1, "Real-time current", "U16", "ro", 500, 0, 0, "mA", false},
        {0x2004, 2, "Run current", "U16", "rw", 1500, 100, 2500, "mA", true},
        {0x2004, 3, "Idle current", "U16", "rw", 500, 100, 2500, "mA", true},
        {0x2004, 4, "Idle time", "U16", "rw", 500, 1, 10000, "ms", true},
        {0x2005, 0, "Digital output boot state", "U8", "rw", 7, 0, 7, "", true},
        {0x2006, 0, "Enable output boot state", "U8", "rw", 0, 0, 1, "", true},
        {0x2007, 0, "Latch enable", "U8", "rw", 0, 0, 1, "", false},
        {0x2008, 0, "Latch status", "U8", "ro", 0, 0, 0, "", false},
        {0x2009, 0, "Latch positions: number of elements", "U8", "ro", 2, 0, 0, "", false},
        {0x2009, 1, "Latched pulse position", "I32", "ro", 0, 0, 0, "pulses", false},
        {0x2009, 2, "Latched encoder position", "I32", "ro", 0, 0, 0, "counts", false},
        {0x200A, 0, "Communication type", "U8", "rw", 2, 0, 2, "", true},
        {0x200B, 0, "Bit rate", "U8", "rw", 5, 1, 9, "code", true},
        {0x200C, 0, "Node ID", "U8", "rw", 1, 1, 127, "", true},
        {0x200D, 0, "Clear error", "U8", "rw", 0, 0, 1, "", false},
        {0x200E, 0, "Perform store", "U8", "rw", 0, 0, 1, "", false},
        {0x6040, 0, "Controlword", "U16", "rw", 0, 0, 0xFFFF, "", false},
        {0x6041, 0, "Statusword", "U16", "ro", 0x0240, 0, 0, "", false},
        {0x6060, 0, "Modes of operation", "I8", "wo", 0, -128, 127, "", false},
        {0x6061, 0, "Modes of operation display", "I8", "ro", 0, 0, 0, "", false},
        {0x6064, 0, "Position actual value", "I32", "ro", 0, 0, 0, "pulses/counts", false},
        {0x606C, 0, "Velocity actual value", "I32", "ro", 0, 0, 0, "pulses/counts per s", false},
        {0x607A, 0, "Target position", "I32", "rw", 0, kI32Min, kI32Max, "pulses/counts", false},
        {0x607C, 0, "Home offset", "I32", "rw", 0, kI32Min, kI32Max, "pulses/counts", true},
        {0x607E, 0, "Polarity", "U8", "rw", 0, 0, 255, "", true},
        {0x6081, 0, "Profile velocity", "U32", "rw", 1000, 0, kU32, "pulses/counts per s", false},
        {0x6082, 0, "End velocity", "U32", "rw", 100, 0, kU32, "pulses/counts per s", false},
        {0x6083, 0, "Profile acceleration", "U32", "rw", 300, 0, kI32Max, "ms", false},
        {0x6084, 0, "Profile deceleration", "U32", "rw", 300, 0, kI32Max, "ms", false},
        {0x6086, 0, "Motion profile type", "I16", "rw", 0, 0, 1, "", true},
        {0x6098, 0, "Homing method", "I8", "rw", 35, -128, 127, "", false},
        {0x6099, 0, "Homing speeds: number of elements", "U8", "ro", 2, 0, 0, "", false},
        {0x6099, 1, "Home switch speed", "U32", "rw", 1000, 0, kU32, "pulses/counts per s", false},
        {0x6099, 2, "Zero position speed", "U32", "rw", 100, 0, kU32, "pulses/counts per s", false},
        {0x609A, 0, "Homing acceleration", "U32", "rw", 300, 0, kU32, "ms", false},
        {0x60FD, 0, "Digital inputs", "U32", "ro", 0, 0, 0, "", false},
        {0x60FE, 0, "Digital outputs", "U32", "rw", 7 << 16, 0, kU32, "", false},
        {0x60FF, 0, "Target velocity", "I32", "rw", 0, kI32Min, kI32Max, "pulses/counts per s", false},
        {0x6402, 0, "Motor type", "U16", "ro", 768, 0, 0, "", false},
        {0x6502, 0, "Supported drive modes", "U32", "ro", 37, 0, 0, "", false},
    };
    // clang-format on
    return table;
}

namespace {

const CanopenObject* find_object(std::uint16_t index, std::uint8_t sub, bool& index_known) {
    index_known = false;
    for (const auto& o : canopen_objects()) {
        if (o.index != index) continue;
        index_known = true;
        if (o.sub == sub) return &o;
    }
    return nullptr;
}

bool homing_method_supported(std::int64_t m) {
    return m == 7 || m == 11 || (m >= 17 && m <= 20) || (m >= 33 && m <= 35);
}

can::Frame sdo_frame(int node, std::uint8_t cs, std::uint16_t index, std::uint8_t sub, std::uint32_t data) {
    const std::uint8_t b[8] = {cs,
                               static_cast<std::uint8_t>(index & 0xFF),
                               static_cast<std::uint8_t>(index >> 8),
                               sub,
                               static_cast<std::uint8_t>(data & 0xFF),
                               static_cast<std::uint8_t>((data >> 8) & 0xFF),
                               static_cast<std::uint8_t>((data >> 16) & 0xFF),
                               static_cast<std::uint8_t>((data >> 24) & 0xFF)};
    return can::Frame::make(0x580u + static_cast<std::uint32_t>(node), b);
}

}  // namespace

double canopen_bit_rate_bps(int code) {
    // Table 8.36 (no 25 kbit/s); 0 for a code outside 1..9.
    static constexpr double kBps[] = {0, 10e3, 20e3, 50e3, 100e3, 125e3, 250e3, 500e3, 800e3, 1e6};
    return code >= 1 && code <= 9 ? kBps[code] : 0.0;
}

// ---- serving ---------------------------------------------------------------------

double Sim::node_bit_rate() const {
    const double r = canopen_bit_rate_bps(bit_rate_code_.load());  // atomic: asked on the bus thread
    return r > 0 ? r : -1.0;
}

std::string Sim::describe() const { return "arcus sim node " + std::to_string(can_node_id()); }

bool Sim::attached() const {
    std::lock_guard lock(bus_mutex_);
    return bus_ != nullptr;
}

void Sim::attach(std::shared_ptr<can::Bus> medium) {
    if (!medium) throw InvalidArgument(describe() + " attach: bus is None");
    {
        std::lock_guard lock(bus_mutex_);
        if (bus_) throw already_attached();
        // The node hears and is heard only at its own bit rate (200Bh at the
        // last boot; issue 23 #4).  A code outside 1..9 matches no wire.
        std::shared_ptr<can::Bus> bus = gate_onto(std::move(medium));
        bus_ = bus;
        // Every SDO request id and NMT: the node-ID in effect changes at a power cycle.
        can::Filter sdo;
        sdo.id = 0x600;
        sdo.mask = 0x780;
        sdo.match_extended = true;
        auto handler = [this](const can::Frame& f) {
            try {
                send_frames(on_can_frame(f));
            } catch (const std::exception&) {
                // a closed bus or a bug in one request never takes the receive thread down
            }
        };
        subs_.push_back(bus->subscribe(sdo, handler));
        subs_.push_back(bus->subscribe_id(0x000, false, handler));
    }
    std::optional<can::Frame> boot_up;
    {
        std::lock_guard lock(mutex_);
        boot_up = boot_up_frame();
    }
    if (boot_up) send_frames({*boot_up});
}

void Sim::close() {
    std::shared_ptr<can::Bus> bus;
    std::vector<can::SubscriptionId> subs;
    {
        std::lock_guard lock(bus_mutex_);
        bus.swap(bus_);
        subs.swap(subs_);
    }
    if (!bus) return;
    for (auto id : subs) {
        try {
            bus->unsubscribe(id);
        } catch (const std::exception&) {
        }
    }
    bus->close();  // the gate only: the medium is the caller's
}

void Sim::send_frames(const std::vector<can::Frame>& frames) {
    if (frames.empty()) return;
    std::shared_ptr<can::Bus> bus;
    {
        std::lock_guard lock(bus_mutex_);
        bus = bus_;
    }
    if (!bus) return;
    for (const auto& f : frames) bus->send(f);
}

std::optional<can::Frame> Sim::boot_up_frame() const {
    if (s_->active_cm != 2) return std::nullopt;  // silent on CAN unless stored as CAN (B-A01)
    const std::uint8_t zero[1] = {0};
    return can::Frame::make(0x700u + static_cast<std::uint32_t>(s_->active_nid), zero);
}

int Sim::active_protocol() const {
    std::lock_guard lock(mutex_);
    return s_->active_cm;
}
int Sim::can_node_id() const {
    std::lock_guard lock(mutex_);
    return s_->active_nid;
}
int Sim::can_bit_rate() const {
    std::lock_guard lock(mutex_);
    return s_->active_br;
}

std::vector<can::Frame> Sim::on_can_frame(const can::Frame& frame) {
    bool reset = false;
    std::vector<can::Frame> out;
    {
        std::lock_guard lock(mutex_);
        out = canopen_frame(frame, reset);
    }
    if (reset) {
        // NMT reset node = a power cycle (B-A03); the boot-up follows.
        std::lock_guard lock(mutex_);
        boot();
        if (auto b = boot_up_frame()) out.push_back(*b);
    }
    return out;
}

// ---- SDO ------------------------------------------------------------------------------

std::vector<can::Frame> Sim::canopen_frame(const can::Frame& f, bool& reset) {
    State& s = *s_;
    reset = false;
    if (s.active_cm != 2 || f.extended || f.rtr) return {};
    if (f.id == 0x000) {
        // NMT: only "reset node" means something to this drive (B-A03).
        if (f.len == 2 && f.data[0] == 0x81 && (f.data[1] == 0 || f.data[1] == s.active_nid)) reset = true;
        return {};
    }
    if (f.id != 0x600u + static_cast<std::uint32_t>(s.active_nid)) return {};
    if (f.len != 8) return {};  // not an SDO request (CiA 301: always 8 bytes)
    const int node = s.active_nid;
    const Nanos now = clock_.now();
    SimEngine e(s, options_);
    CanopenState& co = s.co;
    if (co.state() == Cia402State::OperationEnabled && co.active_mode == 1 && co.setpoints.buffered() && !(co.cw & kHalt) &&
        s.job == Job::Target && s.motor->moving()) {
        // A set of set-points: the buffered one starts the instant the running
        // move ends (B-A12), even when nobody looked at the drive then.
        const Nanos end = s.motor->profile_start() +
                          static_cast<Nanos>(std::ceil(s.motor->profile().duration() * 1e9));
        if (end < now) {
            e.advance(end);
            at_ = s.motor->time();
            try {
                canopen_service();
            } catch (...) {
                at_.reset();
                throw;
            }
            at_.reset();
        }
    }
    e.advance(now);
    canopen_service();

    const std::uint8_t cs = f.data[0];
    const std::uint16_t index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
    const std::uint8_t sub = f.data[3];
    const std::uint32_t data = static_cast<std::uint32_t>(f.data[4]) | (static_cast<std::uint32_t>(f.data[5]) << 8) |
                               (static_cast<std::uint32_t>(f.data[6]) << 16) |
                               (static_cast<std::uint32_t>(f.data[7]) << 24);
    auto abort = [&](std::uint32_t code) { return std::vector<can::Frame>{sdo_frame(node, 0x80, index, sub, code)}; };

    switch (cs >> 5) {
        case 2: {  // initiate upload: every object fits in 4 bytes (B-A02)
            std::uint32_t value = 0;
            int size = 4;
            if (auto code = od_read(index, sub, value, size)) return abort(code);
            const auto reply = static_cast<std::uint8_t>(0x43 | ((4 - size) << 2));
            return {sdo_frame(node, reply, index, sub, value)};
        }
        case 1: {  // initiate download
            if (!(cs & 0x02)) return abort(kAbortCommand);  // segmented: "expedited only" (Fig. 10.0)
            const int size = (cs & 0x01) ? 4 - ((cs >> 2) & 3) : 0;
            if (auto code = od_write(index, sub, data, size)) return abort(code);
            canopen_service();
            return {sdo_frame(node, 0x60, index, sub, 0)};
        }
        case 4:  // abort transfer from the client: nothing is in progress
            return {};
        default:  // segments, block transfers, unknown specifiers
            return abort(kAbortCommand);
    }
}

namespace {
bool errors_latched(const State& s) { return s.minus_err || s.plus_err || s.snl.in_error(); }
}  // namespace

std::uint32_t Sim::od_read(std::uint16_t index, std::uint8_t sub, std::uint32_t& value, int& size) {
    State& s = *s_;
    SimEngine e(s, options_);
    const CanopenState& co = s.co;
    bool index_known = false;
    const CanopenObject* o = find_object(index, sub, index_known);
    if (!o) return index_known ? kAbortNoSub : kAbortNoObject;
    if (!std::strcmp(o->access, "wo")) return kAbortWriteOnly;  // 6060h (C-A05)
    size = type_size(o->type);
    const double pos_sign = (s.cfg.cpol & 0x80) ? -1.0 : 1.0;
    const double vel_sign = (s.cfg.cpol & 0x40) ? -1.0 : 1.0;
    const Nanos now = clock_.now();
    std::int64_t v = o->default_value;
    switch (index) {
        case 0x1001: v = errors_latched(s) ? 1 : 0; break;
        case 0x2000: v = s.cfg.edo; break;
        case 0x2001:
            if (sub == 1) v = s.cfg.sl;
            if (sub == 2) v = s.cfg.sla;
            if (sub == 3) v = s.cfg.slt;
            if (sub == 4) v = s.cfg.slm;
            if (sub == 5) v = s.cfg.sle;
            break;
        case 0x2002: v = e.delta(); break;
        case 0x2003: v = e.sls(); break;
        case 0x2004:
            if (sub == 1) v = e.current(now);
            if (sub == 2) v = s.cfg.curr;
            if (sub == 3) v = s.cfg.curi;
            if (sub == 4) v = s.cfg.curt;
            break;
        case 0x2005: v = s.cfg.doboot; break;
        case 0x2006: v = s.cfg.eoboot; break;
        case 0x2007: v = s.lt; break;
        case 0x2008: v = static_cast<int>(s.motor->latch_state()); break;
        case 0x2009:
            if (sub == 1) v = s.ltp;
            if (sub == 2) v = s.lte;
            break;
        case 0x200A: v = s.cfg.cm; break;
        case 0x200B: v = s.cfg.br; break;
        case 0x200C: v = s.cfg.nid; break;
        case 0x200D: v = co.clear_error; break;
        case 0x200E: v = co.store; break;
        case 0x6040: v = co.cw; break;
        case 0x6041: {
            const Cia402State st = co.state();
            std::uint16_t w = canopen::statusword_bits(st) | canopen::sw::kRemote;
            if (st != Cia402State::SwitchOnDisabled && st != Cia402State::Fault) w |= canopen::sw::kVoltageEnabled;
            const bool idle = !s.motor->moving() && s.job == Job::None;
            const bool oe = co.state() == Cia402State::OperationEnabled;
            bool reached = idle, bit12 = false, bit13 = false;
            if (oe && co.active_mode == 1) {
                reached = idle && !co.setpoints.buffered();
                bit12 = co.setpoints.acknowledged();
                bit13 = s.snl.in_error();  // following error: StepNLoop stall / range error
            } else if (oe && co.active_mode == 3) {
                const double target = vel_sign * co.target_velocity;
                const double vnow = s.motor->pulse_velocity();
                reached = (co.cw & kHalt) ? idle : std::abs(vnow - target) < 0.5 && !co.pv_pending;
                bit12 = std::abs(vnow) < 0.5;  // speed zero
            } else if (oe && co.active_mode == 6) {
                // A halted homing stands without attained or error: bits 10/12/13 = 1/0/0,
                // "interrupted" (CiA 402), so the host sees it at rest.
                const bool halted = (co.cw & kHalt) && idle;
                reached = co.homing_started ? (co.homing_attained || co.homing_error || halted) : idle;
                bit12 = co.homing_attained;
                bit13 = co.homing_error;
            }
            if (reached) w |= canopen::sw::kTargetReached;
            if (s.minus_err || s.plus_err || s.motor->minus_limit_active() || s.motor->plus_limit_active())
                w |= canopen::sw::kInternalLimit;
            if (bit12) w |= canopen::sw::kSetPointAck;
            if (bit13) w |= canopen::sw::kFollowingError;
            v = w;
            break;
        }
        case 0x6061: v = co.state() == Cia402State::OperationEnabled ? co.active_mode : co.mode; break;
        case 0x6064: v = std::llround(pos_sign * static_cast<double>(e.snl_on() ? e.encoder() : e.pulse())); break;
        case 0x606C: v = std::llround(vel_sign * s.motor->pulse_velocity()); break;
        case 0x607A: v = co.target_position; break;
        case 0x607C: v = s.cfg.hofs; break;
        case 0x607E: v = s.cfg.cpol; break;
        case 0x6081: v = co.profile_velocity; break;
        case 0x6082: v = co.end_velocity; break;
        case 0x6083: v = co.acceleration; break;
        case 0x6084: v = co.deceleration; break;
        case 0x6086: v = s.cfg.mpt; break;
        case 0x6098: v = co.homing_method; break;
        case 0x6099:
            if (sub == 1) v = co.home_switch_speed;
            if (sub == 2) v = co.home_zero_speed;
            break;
        case 0x609A: v = co.homing_acceleration; break;
        case 0x60FD: {
            const auto& m = *s.motor;
            v = (m.minus_limit_active() ? 1 : 0) | (m.plus_limit_active() ? 2 : 0) | (m.home_active() ? 4 : 0) |
                (static_cast<std::int64_t>(s.inputs & 63u) << 16);
            break;
        }
        case 0x60FE: v = e.outputs() << 16; break;
        case 0x60FF: v = co.target_velocity; break;
        default: break;  // constants: the table's value
    }
    value = static_cast<std::uint32_t>(static_cast<std::uint64_t>(v) & 0xFFFFFFFFull);
    if (size < 4) value &= (1u << (8 * size)) - 1u;
    return 0;
}

std::uint32_t Sim::od_write(std::uint16_t index, std::uint8_t sub, std::uint32_t raw, int size) {
    State& s = *s_;
    SimEngine e(s, options_);
    CanopenState& co = s.co;
    bool index_known = false;
    const CanopenObject* o = find_object(index, sub, index_known);
    if (!o) return index_known ? kAbortNoSub : kAbortNoObject;
    if (!std::strcmp(o->access, "ro") || !std::strcmp(o->access, "const")) return kAbortReadOnly;
    const int want = type_size(o->type);
    // 2004h is printed as U8 but holds up to 10000: 2- or 4-byte writes (C-A02).
    const bool wide_ok = index == 0x2004 && size == 4;
    if (size != 0 && size != want && !wide_ok) return size > want ? kAbortSizeHigh : kAbortSizeLow;
    const int bytes = size == 0 ? want : size;
    std::int64_t v = 0;
    if (bytes >= 4) {
        v = type_signed(o->type) ? static_cast<std::int64_t>(static_cast<std::int32_t>(raw)) : raw;
    } else {
        const std::uint32_t mask = (1u << (8 * bytes)) - 1u;
        const std::uint32_t u = raw & mask;
        v = u;
        if (type_signed(o->type) && (u & (1u << (8 * bytes - 1)))) v = static_cast<std::int64_t>(u) - (mask + 1ll);
    }
    if (v < o->low || v > o->high) return kAbortRange;
    const double pos_sign = (s.cfg.cpol & 0x80) ? -1.0 : 1.0;
    (void)pos_sign;
    auto cmd = [&](const std::string& c) { return command(c) == "OK"; };
    switch (index) {
        case 0x2000: cmd(line("EDO", v)); break;
        case 0x2001: {
            if (sub == 1) {
                // The firmware refuses SL only while moving: "not in the present device state".
                if (!cmd(line("SL", v))) return kAbortDeviceState;
                break;
            }
            // U32 objects: the whole 0..2^32-1 (the ASCII SLA/SLT/SLM/SLE stop at 2^31-1).
            std::int64_t* field[] = {nullptr, nullptr, &s.cfg.sla, &s.cfg.slt, &s.cfg.slm, &s.cfg.sle};
            *field[sub] = v;
            e.configure_snl();
            break;
        }
        case 0x2004: {
            static const char* names[] = {"", "", "CURR", "CURI", "CURT"};
            if (!cmd(line(names[sub], v))) return kAbortRange;
            break;
        }
        case 0x2005: cmd(line("DOBOOT", v)); break;
        case 0x2006: cmd(line("EOBOOT", v)); break;
        case 0x2007: cmd(line("LT", v)); break;
        // Read back at once, in effect only after a store and a power cycle (B-A05).
        case 0x200A: s.cfg.cm = v; break;
        case 0x200B: s.cfg.br = v; break;
        case 0x200C: s.cfg.nid = v; break;
        case 0x200D:
            if (v == 1) {
                // Clear "the motor and any and all error states" (Fig. 8.1).
                cmd("CLR");
                co.clear_error = options_.clear_ns > 0 ? 1 : 0;
                co.clear_until = clock_.now() + options_.clear_ns;
            }
            break;
        case 0x200E:
            if (v == 1) {
                cmd("STORE");  // Table 8.40's objects: the same flash as the ASCII STORE
                co.store = options_.store_ns > 0 ? 1 : 0;
                co.store_until = clock_.now() + options_.store_ns;
            }
            break;
        case 0x6040: controlword(static_cast<std::uint16_t>(v)); break;
        case 0x6060:
            if (v != 1 && v != 3 && v != 6) return kAbortRange;
            co.mode = static_cast<std::int8_t>(v);
            // In Operation enabled a new mode takes over only when the motor is idle (B-A10).
            if (co.state() == Cia402State::OperationEnabled && !s.motor->moving() && s.job == Job::None) {
                co.active_mode = co.mode;
                co.setpoints.reset();
                co.homing_started = co.homing_attained = co.homing_error = false;
                co.pv_pending = false;
            }
            break;
        case 0x607A: co.target_position = static_cast<std::int32_t>(v); break;
        case 0x607C: s.cfg.hofs = v; break;
        case 0x607E: s.cfg.cpol = v; break;
        case 0x6081: co.profile_velocity = static_cast<std::uint32_t>(v); break;
        case 0x6082: co.end_velocity = static_cast<std::uint32_t>(v); break;
        case 0x6083: co.acceleration = static_cast<std::uint32_t>(v); break;  // clamped at the move (B-A17)
        case 0x6084: co.deceleration = static_cast<std::uint32_t>(v); break;
        case 0x6086: s.cfg.mpt = v; break;
        case 0x6098:
            if (!homing_method_supported(v)) return kAbortRange;
            co.homing_method = static_cast<std::int8_t>(v);
            break;
        case 0x6099:
            (sub == 1 ? co.home_switch_speed : co.home_zero_speed) = static_cast<std::uint32_t>(v);
            break;
        case 0x609A: co.homing_acceleration = static_cast<std::uint32_t>(v); break;
        case 0x60FE: cmd(line("DO", (v >> 16) & 7)); break;  // DO1/DO3 stay dedicated while 2000h=1 + SNL
        case 0x60FF: {
            const std::int32_t before = co.target_velocity;
            co.target_velocity = static_cast<std::int32_t>(v);
            if (co.state() == Cia402State::OperationEnabled && co.active_mode == 3 && !(co.cw & kHalt)) {
                const bool moving = s.motor->moving() || s.job != Job::None;
                if (moving && before != co.target_velocity) {
                    // Same direction: change the speed on the fly (what ASCII SSPD does, in the
                    // window of the new speed).  A reversal or a stop: decelerate, then restart.
                    const double vel_sign = (s.cfg.cpol & 0x40) ? -1.0 : 1.0;
                    const double now_v = vel_sign * before, new_v = vel_sign * co.target_velocity;
                    bool changed = false;
                    if (s.job == Job::Jog && !s.stopping && s.arcus_profile && new_v != 0 && now_v * new_v > 0) {
                        const double pps = std::fabs(new_v) * (e.snl_on() ? e.slr() : 1.0);
                        if (pps >= 1 && pps <= 6'000'000) {
                            s.arcus.set_sspdm(arcus_window_for_hspd(pps).sspdm_first);
                            if (s.arcus.change_speed(e.arcus_time(), std::fabs(new_v)) == MotionReply::Ok) {
                                s.motor->revise(s.arcus.profile());
                                changed = true;
                            }
                        }
                    }
                    if (!changed) {
                        cmd("STOP");
                        co.pv_pending = true;
                    }
                } else if (!moving) {
                    co.pv_pending = true;
                }
            }
            break;
        }
        default: break;
    }
    return 0;
}

// ---- CiA 402 --------------------------------------------------------------------------

namespace {

// The ASCII speed/acceleration registers loaded from CANopen objects (units
// are the same: pulses or counts, ms).  The accel windows of Appendix A apply
// when the move starts (B-A17).
void load_profile(State& s, std::uint32_t high, std::uint32_t low, std::uint32_t acc, std::uint32_t dec) {
    s.hspd = std::clamp<std::int64_t>(high, 1, 6'000'000);
    s.lspd = std::clamp<std::int64_t>(std::min<std::int64_t>(low, s.hspd), 1, 6'000'000);
    s.acc = clamp_acc_ms(std::max<std::int64_t>(acc, 1), s.hspd, s.lspd);
    s.dec = clamp_acc_ms(std::max<std::int64_t>(dec, 1), s.hspd, s.lspd);
    s.scv = s.cfg.mpt == 1 ? 1 : 0;
}

}  // namespace

void Sim::controlword(std::uint16_t v) {
    State& s = *s_;
    CanopenState& co = s.co;
    const std::uint16_t prev = co.cw;
    co.cw = v;
    using S = Cia402State;
    const S before = co.state();
    co.device->on_controlword(v);
    const S after = co.state();
    if (before == S::Fault) {
        // Transition 15 (Fault -> Switch on disabled, "recovers from the fault"):
        // the reset clears the latched limit / StepNLoop errors as 200Dh does,
        // so a generic CiA 402 master (reset, shutdown, enable) gets the drive back.
        if (after == S::SwitchOnDisabled) {
            command("CLR");
            command("EO=0");
        }
        return;
    }
    if (v & kFaultReset) return;  // bit 7 outside FAULT: nothing (and no mode bits)
    auto enter_mode = [&] {
        co.active_mode = co.mode;
        co.setpoints.reset();
        co.homing_started = co.homing_attained = co.homing_error = false;
        co.pv_pending = false;  // PV runs on a 60FFh write or a halt release
    };
    auto exit_mode = [&] {
        co.setpoints.drop_buffered();
        co.pv_pending = false;
        if (s.motor->moving()) command("STOP");
    };
    // What the firmware does on each transition.
    if (before == S::ReadyToSwitchOn && (after == S::SwitchedOn || after == S::OperationEnabled)) {
        command("EO=1");  // 3: motor enabled
        if (after == S::OperationEnabled) enter_mode();  // 3 + 4
        return;
    }
    if (before == S::SwitchedOn) {
        if (after == S::SwitchOnDisabled || after == S::ReadyToSwitchOn) command("EO=0");  // 10, 6
        if (after == S::OperationEnabled) enter_mode();                                    // 4
        return;
    }
    if (before == S::OperationEnabled && after != S::OperationEnabled) {
        if (after == S::SwitchOnDisabled && (v & 0x06) == 0x02) {
            // Quick stop: an immediate stop (ASCII ABORT), then Switch on disabled (11 + 12, B-A11).
            command("ABORT");
            command("EO=0");
            co.setpoints.drop_buffered();
            co.pv_pending = false;
        } else if (after == S::SwitchOnDisabled) {  // 9: disable voltage
            command("EO=0");
            co.setpoints.drop_buffered();
            co.pv_pending = false;
        } else if (after == S::ReadyToSwitchOn) {  // 8: shutdown
            exit_mode();
            command("EO=0");
        } else {  // 5: switch on (disable operation)
            exit_mode();
        }
        return;
    }
    if (after != S::OperationEnabled) return;

    // Operation enabled: the mode's bits, through the handshake every CiA 402 drive shares.
    const bool idle = !s.motor->moving() && s.job == Job::None;
    const double pos_sign = (s.cfg.cpol & 0x80) ? -1.0 : 1.0;
    const double from = static_cast<double>(SimEngine(s, options_).pulse());
    const auto action = co.setpoints.on_controlword(prev, v, static_cast<canopen::OpMode>(co.active_mode), idle,
                                                    !errors_latched(s),  // B-A31: not acknowledged
                                                    pos_sign * co.target_position, from);
    switch (action) {
        case canopen::SetPointAction::Halt:
            // Halt: decelerate to a stop in every mode (B-A09); a halted PP/homing move is not resumed.
            if (s.motor->moving()) command("STOP");
            return;
        case canopen::SetPointAction::Resume:
            co.pv_pending = true;  // PV resumes at 60FFh
            return;
        case canopen::SetPointAction::Start: {
            // Idle: the set-point starts now (a relative one from where the axis is).
            load_profile(s, co.profile_velocity, co.end_velocity, co.acceleration, co.deceleration);
            const auto mm = s.inc_mode;
            s.inc_mode = 0;
            const bool ok = command(line("X", std::llround(co.setpoints.target()), "")) == "OK";
            s.inc_mode = mm;
            if (!ok) co.setpoints.refuse();
            return;
        }
        case canopen::SetPointAction::StartHoming: break;
        default: return;  // Buffer (C-A09: played after this move), Refuse, None
    }
    if (co.active_mode == 6 && !errors_latched(s) && idle) canopen_home();
}

// Homing mode, new set-point (bit 4): the DMX-CAN runs each CiA 402 method with one of
// its ASCII homing commands (manual 000 C-A06, C-A11), 607Ch as their end point.
void Sim::canopen_home() {
    State& s = *s_;
    CanopenState& co = s.co;
    co.homing_started = true;
    co.homing_attained = co.homing_error = false;
    const int method = co.homing_method;
    if (method == 35) {
        // The current position becomes home (no motion).
        command("PX=0");
        command("EX=0");
        co.homing_attained = true;
        return;
    }
    load_profile(s, co.home_switch_speed, co.home_zero_speed, co.homing_acceleration, co.homing_acceleration);
    // 607Ch in the drive's frame: 607Eh bit 7 reverses it like every
    // position value (B-A15), its sign kept (issue 23 #3).
    const double offset = ((s.cfg.cpol & 0x80) ? -1.0 : 1.0) * static_cast<double>(s.cfg.hofs);
    const int dir = (method == 7 || method == 17 || method == 19 || method == 33) ? 1 : -1;
    const std::int64_t lca = s.cfg.lca;
    // Limit homing moves away from the limit by the offset's size (C-A11: 607Ch
    // stands for LCA), at the zero-position speed; toward the limit is no option.
    s.cfg.lca = std::llabs(s.cfg.hofs);
    s.home_backoff_lspd = method == 17 || method == 18;
    // 7/11: "change direction and move by the home offset"; 33/34: "continue
    // moving by the home offset amount"; 19/20: from the home edge "move back
    // by the Home Offset amount".  That end point is zero.
    if (method == 7 || method == 11 || method == 19 || method == 20) s.home_final_target = -dir * offset;
    if (method == 33 || method == 34) s.home_final_target = dir * offset;
    // Manual 000's directions (C-A06): 17/33 positive, 18/34 negative.  19/20
    // run H: zero at the home edge, ramp down to the zero-position speed and
    // stop, then back to the offset from that edge.
    const char* c = method == 7    ? "ZH+"
                    : method == 11 ? "ZH-"
                    : method == 17 ? "L+"
                    : method == 18 ? "L-"
                    : method == 19 ? "H+"
                    : method == 20 ? "H-"
                    : method == 33 ? "Z+"
                                   : "Z-";
    if (command(c) != "OK") co.homing_error = true;
    s.cfg.lca = lca;
    s.home_final_target.reset();
    s.home_backoff_lspd = false;
    if (!s.motor->moving() && s.job == Job::None && !co.homing_error) {
        // Finished at once (a switch already active): decide now.
        const bool ok = !s.homing || s.homing->result() == motion::HomingResult::Done;
        co.homing_attained = ok;
        co.homing_error = !ok;
    }
}

// Lazily, at each request: what the firmware would have done by now.
void Sim::canopen_service() {
    State& s = *s_;
    CanopenState& co = s.co;
    const Nanos now = clock_.now();
    if (co.clear_error && now >= co.clear_until) co.clear_error = 0;
    if (co.store && now >= co.store_until) co.store = 0;
    const Cia402State st = co.state();
    const bool enabled = st == Cia402State::ReadyToSwitchOn || st == Cia402State::SwitchedOn ||
                         st == Cia402State::OperationEnabled || st == Cia402State::QuickStopActive;
    if (enabled && errors_latched(s)) {
        // A limit or StepNLoop error is a Fault until 200Dh clears it (B-A18, B-A22):
        // transitions 13 + 14, the motor already stopped by the firmware.
        co.device->fault(0);
        co.device->fault_reaction_done();
        co.setpoints.drop_buffered();
        co.pv_pending = false;
        if (co.homing_started && !co.homing_attained) co.homing_error = true;
        return;
    }
    if (st != Cia402State::OperationEnabled) return;
    const bool idle = !s.motor->moving() && s.job == Job::None;
    if (idle && co.mode != co.active_mode) {
        // A 6060h written while the motor ran takes over once it is idle (B-A10).
        co.active_mode = co.mode;
        co.setpoints.reset();
        co.homing_started = co.homing_attained = co.homing_error = false;
        co.pv_pending = false;
        return;
    }
    if (co.active_mode == 6 && co.homing_started && !co.homing_attained && !co.homing_error && idle) {
        const bool ok = s.homing && s.homing->result() == motion::HomingResult::Done;
        co.homing_attained = ok;
        co.homing_error = !ok && !(co.cw & kHalt);
    }
    if (!idle || (co.cw & kHalt)) return;
    if (co.active_mode == 1 && co.setpoints.buffered()) {
        const double target = *co.setpoints.take_buffered();
        load_profile(s, co.profile_velocity, co.end_velocity, co.acceleration, co.deceleration);
        const auto mm = s.inc_mode;
        s.inc_mode = 0;
        command(line("X", std::llround(target), ""));
        s.inc_mode = mm;
    }
    if (co.active_mode == 3 && co.pv_pending) {
        co.pv_pending = false;
        const double vel_sign = (s.cfg.cpol & 0x40) ? -1.0 : 1.0;
        const double v = vel_sign * co.target_velocity;
        if (v == 0) return;
        load_profile(s, static_cast<std::uint32_t>(std::llabs(co.target_velocity)), co.end_velocity,
                     co.acceleration, co.deceleration);
        command(v > 0 ? "J+" : "J-");
    }
}

}  // namespace motorbus::arcus

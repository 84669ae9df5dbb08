#include "motorbus/drives/cia402/sim.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "motorbus/errors.hpp"

namespace motorbus::cia402 {

using canopen::Access;
using canopen::DataType;
using canopen::VariablePtr;

namespace {
constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::uint32_t kSave = 0x65766173;  // "save" (CiA 301 1010h signature)
constexpr std::uint32_t kCannotStore = 0x08000020;

// Little-endian value of a remote write (the OD checked its size already).
std::int64_t value_of(const canopen::Variable& var, std::span<const std::uint8_t> d) {
    std::uint64_t raw = 0;
    for (std::size_t i = 0; i < d.size() && i < 8; ++i) raw |= std::uint64_t{d[i]} << (8 * i);
    const std::size_t n = d.size();
    const bool is_signed = var.type() == DataType::Integer8 || var.type() == DataType::Integer16 ||
                           var.type() == DataType::Integer32;
    if (is_signed && n > 0 && n < 8 && (raw >> (8 * n - 1)) & 1) raw |= ~std::uint64_t{0} << (8 * n);
    return static_cast<std::int64_t>(raw);
}

void put(canopen::Bytes& out, std::int64_t v, std::size_t size) {
    out.resize(size);
    for (std::size_t i = 0; i < size; ++i) out[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i));
}

// The process data of PP/PV that PDOs may carry (CiA 402's usual mappings).
bool mappable(std::uint16_t index) {
    switch (index) {
        case 0x6040: case 0x6041: case 0x6060: case 0x6061: case 0x6064: case 0x606C: case 0x607A: case 0x60FF:
            return true;
        default: return false;
    }
}
}  // namespace

const std::vector<ObjectRow>& objects() {
    using DT = DataType;
    using A = Access;
    static const std::vector<ObjectRow> rows = {
        {0x1000, 0, "Device type", DT::Unsigned32, A::RO, 0x00420192, {}, {}, "", false, "CiA 402 drive (servo + stepper)"},
        {0x1001, 0, "Error register", DT::Unsigned8, A::RO, 0, {}, {}, "", false, "CiA 301 error register"},
        {0x1008, 0, "Manufacturer device name", DT::VisibleString, A::RO, 0, {}, {}, "", false, "device name",
         "motorbus CiA 402 sim"},
        // Identity (CiA 301): vendor 0 = no CiA-assigned vendor (a simulator); serial = the node-ID.
        {0x1018, 1, "Vendor-ID", DT::Unsigned32, A::RO, 0, {}, {}, "", false, "identity: vendor"},
        {0x1018, 2, "Product code", DT::Unsigned32, A::RO, 0x402, {}, {}, "", false, "identity: product"},
        {0x1018, 3, "Revision number", DT::Unsigned32, A::RO, 0x00010000, {}, {}, "", false, "identity: revision"},
        {0x1018, 4, "Serial number", DT::Unsigned32, A::RO, 0, {}, {}, "", false, "identity: serial (the node-ID)"},
        {0x603F, 0, "Error code", DT::Unsigned16, A::RO, 0, {}, {}, "", false, "last fault's CiA 402 error code"},
        {0x6040, 0, "Controlword", DT::Unsigned16, A::RW, 0, {}, {}, "", false, "CiA 402 controlword"},
        {0x6041, 0, "Statusword", DT::Unsigned16, A::RO, 0, {}, {}, "", false, "CiA 402 statusword"},
        {0x6007, 0, "Abort connection option code", DT::Integer16, A::RW, 1, 0, 3, "", true,
         "what a lost master does: 1 fault, 2 disable voltage, 3 quick stop"},
        {0x605A, 0, "Quick stop option code", DT::Integer16, A::RW, 2, 0, 8, "", true, "quick stop reaction"},
        {0x6060, 0, "Modes of operation", DT::Integer8, A::RW, 0, {}, {}, "", false, "1 PP, 3 PV, 6 HM"},
        {0x6061, 0, "Modes of operation display", DT::Integer8, A::RO, 0, {}, {}, "", false, "the mode in effect"},
        {0x6064, 0, "Position actual value", DT::Integer32, A::RO, 0, {}, {}, "inc", false, "position"},
        {0x6065, 0, "Following error window", DT::Unsigned32, A::RW, 1000, 0, 0xFFFFFFFF, "inc", true,
         "a larger lag of the rotor behind the demand is a following error (fault 0x8611)"},
        {0x6067, 0, "Position window", DT::Unsigned32, A::RW, 10, 0, 0xFFFFFFFF, "inc", true,
         "a move within this of its target is at target"},
        {0x606C, 0, "Velocity actual value", DT::Integer32, A::RO, 0, {}, {}, "inc/s", false, "velocity"},
        {0x607A, 0, "Target position", DT::Integer32, A::RW, 0, {}, {}, "inc", false, "PP target"},
        {0x607C, 0, "Home offset", DT::Integer32, A::RW, 0, {}, {}, "inc", true, "position after homing"},
        {0x607D, 1, "Min position limit", DT::Integer32, A::RW, kI32Min, {}, {}, "inc", true,
         "software position limit: PP targets below are clipped to it"},
        {0x607D, 2, "Max position limit", DT::Integer32, A::RW, kI32Max, {}, {}, "inc", true,
         "software position limit: PP targets above are clipped to it"},
        {0x6081, 0, "Profile velocity", DT::Unsigned32, A::RW, 1000, 1, 10'000'000, "inc/s", true, "PP speed"},
        {0x6083, 0, "Profile acceleration", DT::Unsigned32, A::RW, 10000, 1, 100'000'000, "inc/s²", true,
         "PP/PV acceleration"},
        {0x6084, 0, "Profile deceleration", DT::Unsigned32, A::RW, 10000, 1, 100'000'000, "inc/s²", true,
         "PP/PV deceleration"},
        {0x6085, 0, "Quick stop deceleration", DT::Unsigned32, A::RW, 100000, 1, 100'000'000, "inc/s²", true,
         "deceleration of a quick stop"},
        {0x6086, 0, "Motion profile type", DT::Integer16, A::RW, 0, 0, 1, "", true, "0 linear ramp, 1 sin² ramp"},
        {0x6098, 0, "Homing method", DT::Integer8, A::RW, 19, {}, {}, "", true,
         "7, 11, 17-20, 33-35 (sim default 19: home switch)"},
        {0x6099, 1, "Speed during search for switch", DT::Unsigned32, A::RW, 5000, 1, 10'000'000, "inc/s", true,
         "homing"},
        {0x6099, 2, "Speed during search for zero", DT::Unsigned32, A::RW, 1000, 1, 10'000'000, "inc/s", true,
         "homing"},
        {0x609A, 0, "Homing acceleration", DT::Unsigned32, A::RW, 20000, 1, 100'000'000, "inc/s²", true, "homing"},
        {0x60FD, 0, "Digital inputs", DT::Unsigned32, A::RO, 0, {}, {}, "", false,
         "bit 0 negative limit, 1 positive, 2 home; bit 16 the simulator's quick-stop input"},
        {0x60FF, 0, "Target velocity", DT::Integer32, A::RW, 0, {}, {}, "inc/s", false, "PV target"},
        {0x6502, 0, "Supported drive modes", DT::Unsigned32, A::RO, 0b100101, {}, {}, "", false, "PP, PV, HM"},
    };
    return rows;
}

void SimOptions::validate() const {
    auto finite = [](double v, const char* what) {
        if (!std::isfinite(v)) throw InvalidArgument(std::string("cia402 sim option ") + what + ": not a finite number");
    };
    finite(steps_per_rev, "steps_per_rev");
    if (steps_per_rev <= 0) throw InvalidArgument("cia402 sim option steps_per_rev: must be > 0");
    finite(home.first, "home");
    finite(home.second, "home");
    if (home.first > home.second) throw InvalidArgument("cia402 sim option home: (lo, hi) with lo <= hi");
    if (minus_limit) finite(*minus_limit, "minus_limit");
    if (plus_limit) finite(*plus_limit, "plus_limit");
    if (minus_limit && plus_limit && *minus_limit >= *plus_limit)
        throw InvalidArgument("cia402 sim options minus_limit/plus_limit: the -limit must lie below the +limit");
    if (heartbeat_ms < 0 || heartbeat_ms > 65535)
        throw InvalidArgument("cia402 sim option heartbeat_ms: 0..65535 ms, not " + std::to_string(heartbeat_ms));
    finite(start_position, "start_position");
}

Sim::Sim(std::uint8_t node_id, std::shared_ptr<Clock> clock, SimOptions options)
    : Sim(node_id, *clock, std::move(options)) {
    clock_owner_ = std::move(clock);
}

Sim::Sim(std::uint8_t node_id, Clock& clock, SimOptions options)
    : node_id_(node_id), clock_(clock), options_(std::move(options)) {
    if (node_id < 1 || node_id > 127)
        throw InvalidArgument("cia402 sim: node-ID " + std::to_string(node_id) + " is outside 1..127");
    options_.validate();
    motion::MotorConfig cfg;
    cfg.steps_per_rev = options_.steps_per_rev;
    cfg.counts_per_rev = options_.steps_per_rev;
    cfg.home = motion::SwitchConfig{true, options_.home.first, options_.home.second, false};
    cfg.minus_limit = motion::SwitchConfig{options_.minus_limit.has_value(), options_.minus_limit.value_or(0), 0, false};
    cfg.plus_limit = motion::SwitchConfig{options_.plus_limit.has_value(), options_.plus_limit.value_or(0), 0, false};
    motor_ = std::make_unique<motion::MotorModel>(clock_, cfg);
    if (options_.start_position != 0) {
        motor_->set_pulse_position(options_.start_position);
        motor_->set_encoder(std::llround(options_.start_position));
    }
    axis_ = std::make_unique<canopen::Cia402Axis>(*motor_, clock_);
    od_ = std::make_shared<canopen::ObjectDictionary>();
    build_od();
}

Sim::~Sim() {
    close();
    // The dictionary may outlive the simulator (a Python reference to od): its hooks
    // reach this object, so they go first.
    for (auto index : od_->indices()) {
        auto obj = od_->object(index);
        if (!obj) continue;
        for (auto& [sub, var] : obj->subs) {
            var->set_read_hook(nullptr);
            var->set_write_hook(nullptr);
        }
    }
}

void add_objects(canopen::ObjectDictionary& od, std::uint8_t node_id) {
    for (const auto& r : objects()) {
        if (r.sub != 0 && !od.object(r.index)) od.add_record(r.index, r.index == 0x6099 ? "Homing speeds" : [&] {
            char buf[8];
            std::snprintf(buf, sizeof buf, "0x%04X", r.index);
            return std::string(buf);
        }());
        canopen::VariableSpec spec{.index = r.index, .subindex = r.sub, .name = r.name, .type = r.type,
                                   .access = r.access, .pdo_mappable = mappable(r.index)};
        if (r.text_default) {
            const std::string t = r.text_default;
            spec.default_value = canopen::Bytes(t.begin(), t.end());
        } else if (r.type == DataType::Unsigned8 || r.type == DataType::Unsigned16 || r.type == DataType::Unsigned32) {
            spec.default_value = static_cast<std::uint64_t>(r.default_value);
            if (r.low) spec.low_limit = canopen::Scalar{static_cast<std::uint64_t>(*r.low)};
            if (r.high) spec.high_limit = canopen::Scalar{static_cast<std::uint64_t>(*r.high)};
        } else {
            spec.default_value = r.default_value;
            if (r.low) spec.low_limit = canopen::Scalar{*r.low};
            if (r.high) spec.high_limit = canopen::Scalar{*r.high};
        }
        if (r.sub != 0)
            od.add_member(r.index, std::move(spec));
        else
            od.add_variable(std::move(spec));
    }
    od.at(0x1018, 4)->set_u64(node_id);
    od.add_record(0x1010, "Store parameters", canopen::ObjectCode::Array);
    od.add_member(0x1010, {.subindex = 1, .name = "Save all parameters", .type = DataType::Unsigned32,
                           .default_value = std::uint64_t{1}});
}

std::shared_ptr<canopen::ObjectDictionary> object_dictionary(std::uint8_t node_id) {
    auto od = std::make_shared<canopen::ObjectDictionary>();
    add_objects(*od, node_id);
    return od;
}

void Sim::build_od() {
    auto& od = *od_;
    add_objects(od, node_id_);

    // PDO mapping parameters as CiA 301 declares them: RECORDs (the PdoService adopts
    // what exists and would make ARRAYs, whose length a master such as canopen's
    // PdoMap.save() takes from sub-index 0 and then writes no entry at all).
    for (std::uint16_t base : {std::uint16_t{0x1600}, std::uint16_t{0x1A00}})
        for (std::uint16_t n = 0; n < 4; ++n) {
            const std::uint16_t index = base + n;
            od.add_record(index, base == 0x1600 ? "RPDO mapping parameter" : "TPDO mapping parameter");
            od.add_member(index, {.subindex = 0, .name = "Number of mapped objects", .type = DataType::Unsigned8,
                                  .access = Access::RW, .default_value = std::uint64_t{0}});
            for (std::uint8_t sub = 1; sub <= 8; ++sub)
                od.add_member(index, {.subindex = sub, .name = "Mapped object " + std::to_string(sub),
                                      .type = DataType::Unsigned32, .access = Access::RW,
                                      .default_value = std::uint64_t{0}});
        }

    canopen::Cia402Axis& ax = *axis_;
    // What the axis computes, read when the host looks.
    auto live = [&](std::uint16_t index, auto fn) {
        od.at(index, 0)->set_read_hook([fn](const canopen::Variable& var, canopen::Bytes& out) -> std::uint32_t {
            put(out, fn(), var.size());
            return 0;
        });
    };
    live(0x6041, [&ax] { return std::int64_t{ax.statusword()}; });
    live(0x6060, [&ax] { return std::int64_t{ax.mode()}; });  // the mode asked for is the mode in effect
    live(0x6061, [&ax] { return std::int64_t{ax.mode()}; });
    live(0x6064, [&ax] { return std::int64_t{ax.position()}; });
    live(0x606C, [&ax] { return std::int64_t{ax.velocity()}; });
    live(0x60FD, [&ax] { return std::int64_t{ax.digital_inputs()}; });
    live(0x603F, [&ax] { return std::int64_t{ax.error_code()}; });
    live(0x1001, [&ax] { return std::int64_t{ax.error_register()}; });

    // Writes the axis acts on.
    auto on_write = [&](std::uint16_t index, std::uint8_t sub, auto fn) {
        od.at(index, sub)->set_write_hook(
            [fn](const canopen::Variable& var, std::span<const std::uint8_t> d) -> std::uint32_t {
                return fn(value_of(var, d));
            });
    };
    on_write(0x6040, 0, [&ax](std::int64_t v) { ax.write_controlword(static_cast<std::uint16_t>(v)); return 0u; });
    on_write(0x6060, 0, [&ax](std::int64_t v) { return ax.set_mode(static_cast<std::int8_t>(v)); });
    on_write(0x6007, 0, [&ax](std::int64_t v) { return ax.set_abort_connection_option(static_cast<std::int16_t>(v)); });
    on_write(0x605A, 0, [&ax](std::int64_t v) { return ax.set_quick_stop_option(static_cast<std::int16_t>(v)); });
    on_write(0x6098, 0, [&ax](std::int64_t v) { return ax.set_homing_method(static_cast<std::int8_t>(v)); });
    on_write(0x60FF, 0, [&ax](std::int64_t v) { ax.set_target_velocity(static_cast<std::int32_t>(v)); return 0u; });
    on_write(0x1010, 1, [](std::int64_t v) { return static_cast<std::uint32_t>(v) == kSave ? 0u : kCannotStore; });
    for (auto [index, sub] : {std::pair<std::uint16_t, std::uint8_t>{0x607A, 0}, {0x607C, 0}, {0x607D, 1}, {0x607D, 2},
                              {0x6065, 0}, {0x6081, 0}, {0x6083, 0}, {0x6084, 0}, {0x6085, 0}, {0x6086, 0},
                              {0x6099, 1}, {0x6099, 2}, {0x609A, 0}})
        hook_setting(index, sub);
}

// A setting the axis reads: the dictionary keeps the value (plain SDO reads), the
// axis gets a copy on each write.
void Sim::hook_setting(std::uint16_t index, std::uint8_t sub) {
    canopen::Cia402Axis& ax = *axis_;
    od_->at(index, sub)->set_write_hook(
        [&ax, index, sub](const canopen::Variable& var, std::span<const std::uint8_t> d) -> std::uint32_t {
            const std::int64_t v = value_of(var, d);
            ax.update_settings([&](canopen::Cia402AxisSettings& s) {
                switch (index) {
                    case 0x607A: s.target_position = static_cast<std::int32_t>(v); break;
                    case 0x607C: s.home_offset = static_cast<std::int32_t>(v); break;
                    case 0x607D: (sub == 1 ? s.min_position : s.max_position) = static_cast<std::int32_t>(v); break;
                    case 0x6065: s.following_error_window = static_cast<std::uint32_t>(v); break;
                    case 0x6081: s.profile_velocity = static_cast<std::uint32_t>(v); break;
                    case 0x6083: s.profile_acceleration = static_cast<std::uint32_t>(v); break;
                    case 0x6084: s.profile_deceleration = static_cast<std::uint32_t>(v); break;
                    case 0x6085: s.quick_stop_deceleration = static_cast<std::uint32_t>(v); break;
                    case 0x6086: s.motion_profile_type = static_cast<std::int16_t>(v); break;
                    case 0x6099: (sub == 1 ? s.homing_speed_switch : s.homing_speed_zero) = static_cast<std::uint32_t>(v); break;
                    case 0x609A: s.homing_acceleration = static_cast<std::uint32_t>(v); break;
                    default: break;
                }
            });
            return 0;
        });
}

void Sim::publish_settings() {
    // An NMT reset restored the dictionary's defaults; the drive keeps what it was
    // given (as the Python simulator did), so the dictionary shows it again.
    const auto s = axis_->settings();
    auto& od = *od_;
    od.at(0x607A, 0)->set_i64(s.target_position);
    od.at(0x607C, 0)->set_i64(s.home_offset);
    od.at(0x607D, 1)->set_i64(s.min_position);
    od.at(0x607D, 2)->set_i64(s.max_position);
    od.at(0x6065, 0)->set_u64(s.following_error_window);
    od.at(0x6081, 0)->set_u64(s.profile_velocity);
    od.at(0x6083, 0)->set_u64(s.profile_acceleration);
    od.at(0x6084, 0)->set_u64(s.profile_deceleration);
    od.at(0x6085, 0)->set_u64(s.quick_stop_deceleration);
    od.at(0x6086, 0)->set_i64(s.motion_profile_type);
    od.at(0x6098, 0)->set_i64(s.homing_method);
    od.at(0x6099, 1)->set_u64(s.homing_speed_switch);
    od.at(0x6099, 2)->set_u64(s.homing_speed_zero);
    od.at(0x609A, 0)->set_u64(s.homing_acceleration);
    od.at(0x60FF, 0)->set_i64(s.target_velocity);
    od.at(0x1018, 4)->set_u64(node_id_);
}

// Nodes and services are made and destroyed without m_ held: their threads call
// into the simulator (hooks, the lost-heartbeat callback).
void Sim::attach(std::shared_ptr<can::Bus> bus) {
    if (!bus) throw InvalidArgument(describe() + " attach: bus is None");
    {
        std::lock_guard lock(m_);
        if (bus_ || attaching_) throw already_attached();
        attaching_ = true;
    }
    try {
        serve(*bus);
    } catch (...) {
        std::lock_guard lock(m_);
        attaching_ = false;
        throw;
    }
    std::lock_guard lock(m_);
    bus_ = std::move(bus);
    attaching_ = false;
}

void Sim::serve(can::Bus& bus) {
    canopen::LocalNodeOptions o;
    o.on_reset = [this](canopen::NmtCommand) { publish_settings(); };
    // The hooks are this file's C++ (the axis under its own lock, bounded work): the
    // requests are served on the bus thread, without a hand-off to the node's worker.
    o.sdo_inline = true;
    auto n = std::make_unique<canopen::LocalNode>(bus, node_id_, od_, o);
    auto hb = canopen::HeartbeatService::attach(
        *n, {.consumer_entries = 4, .producer_ms = static_cast<std::uint16_t>(options_.heartbeat_ms)});
    auto pdo = canopen::PdoService::attach(*n, {.rpdo_count = 4, .tpdo_count = 4});
    hb->on_lost = [this](std::uint8_t) {
        axis_->loss_of_master();
        lost_master_ = true;
    };
    std::lock_guard lock(m_);
    node_ = std::move(n);
    pdo_ = std::move(pdo);
    hb_ = std::move(hb);
}

void Sim::close() {
    axis_->halt_motor();
    std::unique_ptr<canopen::LocalNode> n;
    std::shared_ptr<canopen::PdoService> pdo;
    std::shared_ptr<canopen::HeartbeatService> hb;
    std::shared_ptr<can::Bus> bus;
    {
        std::lock_guard lock(m_);
        n = std::move(node_);
        pdo = std::move(pdo_);
        hb = std::move(hb_);
        bus = std::move(bus_);
    }
    if (hb) hb->on_lost = nullptr;
    if (n) n->close();
    pdo.reset();
    hb.reset();
    n.reset();  // before the bus it was subscribed to
}

void Sim::power_cycle() {
    std::shared_ptr<can::Bus> bus;
    {
        std::lock_guard lock(m_);
        bus = bus_;
    }
    close();
    axis_->reset();
    for (auto index : od_->indices()) {
        auto obj = od_->object(index);
        if (!obj) continue;
        for (auto& [sub, var] : obj->subs) var->reset_to_default();
    }
    od_->at(0x1018, 4)->set_u64(node_id_);
    lost_master_ = false;
    if (bus) attach(std::move(bus));
}

bool Sim::attached() const {
    std::lock_guard lock(m_);
    return node_ != nullptr;
}

std::shared_ptr<canopen::PdoService> Sim::pdo() const {
    std::lock_guard lock(m_);
    return pdo_;
}

std::shared_ptr<canopen::HeartbeatService> Sim::heartbeat() const {
    std::lock_guard lock(m_);
    return hb_;
}

}  // namespace motorbus::cia402

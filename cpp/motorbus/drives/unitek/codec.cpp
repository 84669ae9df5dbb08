#include "motorbus/drives/unitek/codec.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace motorbus::unitek {

namespace {
std::vector<std::uint8_t> copy(std::span<const std::uint8_t> d) { return {d.begin(), d.end()}; }

std::string lower(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string regid_text(std::uint8_t r) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02X", r);
    return buf;
}

std::uint32_t le(std::span<const std::uint8_t> d, std::size_t from, std::size_t n) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint32_t>(d[from + i]) << (8 * i);
    return v;
}

std::int64_t width_lo(int bits, bool s) { return s ? -(std::int64_t{1} << (bits - 1)) : 0; }
std::int64_t width_hi(int bits, bool s) {
    return s ? (std::int64_t{1} << (bits - 1)) - 1 : (std::int64_t{1} << bits) - 1;
}
}  // namespace

std::uint32_t event_status_mask(std::uint16_t mask) {
    // C-U01: the manual's three masks do not follow one bit mapping; keep them as a table.
    switch (mask) {
        case 0x0030: return kStatusCal | kStatusTol;
        case 0x0012: return kStatusLimPlus | kStatusLimMinus;
        case 0x0020: return kStatusIcns;
        default: return mask;
    }
}

std::int64_t Register::lo() const { return min > max ? width_lo(bits, is_signed) : min; }
std::int64_t Register::hi() const { return min > max ? width_hi(bits, is_signed) : max; }

std::int64_t Register::from_raw(std::uint32_t raw, int raw_bits) const {
    // A 32-bit reply of a 16-bit register (KERN_STATUS events) keeps all 32 bits.
    const int b = std::max(raw_bits, 0);
    if (b >= 32) {
        return is_signed ? static_cast<std::int64_t>(static_cast<std::int32_t>(raw)) : static_cast<std::int64_t>(raw);
    }
    const std::uint32_t m = (1u << b) - 1;
    raw &= m;
    if (is_signed && (raw & (1u << (b - 1)))) return static_cast<std::int64_t>(raw) - (std::int64_t{1} << b);
    return raw;
}

RegisterTable RegisterTable::builtin() {
    RegisterTable t;
    auto row = [&](std::uint8_t id, const char* name, int bits, bool s, Access a, Quantity q, const char* unit,
                   std::int64_t lo, std::int64_t hi, const char* what) {
        Register r;
        r.regid = id;
        r.name = name;
        r.bits = bits;
        r.is_signed = s;
        r.access = a;
        r.quantity = q;
        r.unit = unit;
        r.min = lo;
        r.max = hi;
        r.description = what;
        t.add(std::move(r));
    };
    using A = Access;
    using Q = Quantity;
    row(kRegSpeedActual, "SPEED_IST", 16, true, A::ReadOnly, Q::Speed, "rpm", -32767, 32767, "actual speed (ex 9)");
    row(kRegSpeedCmd, "SPEED_CMD", 16, true, A::ReadWrite, Q::Speed, "rpm", -32767, 32767, "speed command (ex 3)");
    row(kRegAccRamp, "ACC_RAMP", 16, false, A::ReadWrite, Q::Time, "ms", 0, 32767, "acceleration ramp (ex 6)");
    row(kRegStatus, "KERN_STATUS", 16, false, A::ReadOnly, Q::Raw, "", 1, 0, "device status (ex 8, ex 10)");
    row(kRegMode, "MODE", 16, false, A::WriteOnly, Q::Raw, "", 1, 0, "bit 2 disable, bit 4 status events (ex 2, ex 10)");
    row(kRegEventMask, "EVENT_MASK", 16, false, A::ReadWrite, Q::Raw, "", 1, 0, "status bits that trigger an event (ex 10-1)");
    row(kRegRxId, "CAN_ID_RX", 16, false, A::WriteOnly, Q::Raw, "", kRxIdMin, kRxIdMax, "receive id (ex 1)");
    row(kRegPosDest, "POS_DEST", 32, true, A::ReadWrite, Q::Position, "rev", -2147483647, 2147483647,
        "position command, 65536 per revolution (ex 4)");
    row(kRegEeprom, "EEPROM_WRITE", 16, false, A::WriteOnly, Q::Raw, "", 0, 1, "store parameters, level 0 or 1 (ex 7)");
    row(kRegTorqueCmd, "TORQUE_CMD", 16, true, A::ReadWrite, Q::Torque, "%", -32767, 32767, "torque command (ex 5)");
    row(kRegA8, "REG_A8", 16, false, A::ReadOnly, Q::Raw, "", 1, 0, "unnamed register of the §5.2 request examples");
    return t;
}

void RegisterTable::add(Register r) {
    if (r.regid == kRegRead) throw InvalidArgument("unitek register 0x3D: the read request, not a register");
    if (r.regid > 0xFD) throw InvalidArgument("unitek register " + regid_text(r.regid) + ": REGIDs are 0x00..0xFD");
    if (r.bits != 16 && r.bits != 32)
        throw InvalidArgument("unitek register " + regid_text(r.regid) + " bits: 16 or 32, not " + std::to_string(r.bits));
    if (r.name.empty()) throw InvalidArgument("unitek register " + regid_text(r.regid) + " name: empty");
    if (!std::isfinite(r.scale) || r.scale == 0)
        throw InvalidArgument("unitek register " + r.name + " scale: a finite non-zero number");
    if (r.min <= r.max && (r.min < width_lo(r.bits, r.is_signed) || r.max > width_hi(r.bits, r.is_signed)))
        throw InvalidArgument("unitek register " + r.name + " range: outside its " + std::to_string(r.bits) + "-bit " +
                              (r.is_signed ? "signed" : "unsigned") + " width");
    // A name names one register: a new row with a used name replaces that row.
    const std::string key = lower(r.name);
    for (auto it = rows_.begin(); it != rows_.end();) {
        if (it->first != r.regid && lower(it->second.name) == key) it = rows_.erase(it);
        else ++it;
    }
    rows_[r.regid] = std::move(r);
}

const Register* RegisterTable::find(std::uint8_t regid) const {
    auto it = rows_.find(regid);
    return it == rows_.end() ? nullptr : &it->second;
}

const Register* RegisterTable::find(const std::string& name) const {
    const std::string key = lower(name);
    for (const auto& [id, r] : rows_)
        if (lower(r.name) == key) return &r;
    return nullptr;
}

const Register& RegisterTable::at(std::uint8_t regid) const {
    if (auto* r = find(regid)) return *r;
    throw UnknownRegister("unitek: unknown register " + regid_text(regid) +
                              " (add it from your NDrive list: RegisterTable.add or a TOML file)",
                          regid);
}

const Register& RegisterTable::at(const std::string& name) const {
    if (auto* r = find(name)) return *r;
    throw UnknownRegister("unitek: unknown register " + name, 0);
}

std::vector<Register> RegisterTable::rows() const {
    std::vector<Register> out;
    for (const auto& [id, r] : rows_) out.push_back(r);
    return out;
}

void Scalings::validate() const {
    for (auto [name, v] : {std::pair{"n_max_rpm", n_max_rpm}, std::pair{"counts_per_rev", counts_per_rev},
                           std::pair{"i_max_num", i_max_num}, std::pair{"i_max_a", i_max_a}})
        if (!(v > 0) || !std::isfinite(v))
            throw InvalidArgument(std::string("unitek scalings ") + name + ": must be a positive number");
}

double Scalings::to_physical(const Register& r, std::int64_t num) const {
    const double n = static_cast<double>(num);
    switch (r.quantity) {
        case Quantity::Speed: return n / 32767.0 * n_max_rpm;
        case Quantity::Position: return n / counts_per_rev;
        case Quantity::Current: return n / i_max_num * i_max_a;
        case Quantity::Torque: return n / 32767.0 * 100.0;
        case Quantity::Time:
        case Quantity::Raw: return n * r.scale;
    }
    return n;
}

std::int64_t Scalings::to_num(const Register& r, double x) const {
    if (!std::isfinite(x)) throw InvalidArgument("unitek " + r.name + ": value must be finite");
    double n = x;
    switch (r.quantity) {
        case Quantity::Speed: n = x / n_max_rpm * 32767.0; break;
        case Quantity::Position: n = x * counts_per_rev; break;
        case Quantity::Current: n = x / i_max_a * i_max_num; break;
        case Quantity::Torque: n = x / 100.0 * 32767.0; break;
        case Quantity::Time:
        case Quantity::Raw: n = x / r.scale; break;
    }
    if (std::fabs(n) > 9.0e18) throw InvalidArgument("unitek " + r.name + ": value out of range");
    return static_cast<std::int64_t>(std::llround(n));
}

std::span<const DeviceCurrent> device_currents() {
    // §6.1: I 100 % (mV), num, A rms, A peak; max num = max A.
    static const std::array<DeviceCurrent, 3> table{{
        {"DS 205/405", 550, 110, 5, 7, 160, 10},
        {"DS 412", 800, 160, 12, 17, 230, 24},
        {"DS 420", 700, 140, 20, 28, 200, 40},
    }};
    return table;
}

std::int64_t continuous_current_num(const DeviceCurrent& d, double amps) {
    if (!std::isfinite(amps) || amps < 0) throw InvalidArgument("unitek current: a non-negative number of A");
    // The manual's own rule: rated num / rated A rms x the limit (110 / 5 x 2 A = 44).
    return static_cast<std::int64_t>(std::llround(d.i100_num / d.i_rms_a * amps));
}

const DeviceCurrent& device_current(const std::string& device) {
    for (const auto& d : device_currents())
        if (device == d.device) return d;
    throw InvalidArgument("unitek device: 'DS 205/405', 'DS 412' or 'DS 420', not '" + device + "'");
}

std::int64_t effective_current_limit_num(const DeviceCurrent& d, std::int64_t motor_limit_num) {
    if (motor_limit_num < 0)
        throw InvalidArgument("unitek motor current limit: " + std::to_string(motor_limit_num) + " num, not >= 0");
    return std::min(motor_limit_num, static_cast<std::int64_t>(d.i_max_num));
}

std::int64_t analog_command_num(double volts) {
    if (!std::isfinite(volts) || std::fabs(volts) > kAnalogMaxVolts)
        throw InvalidArgument("unitek analog input: " + std::to_string(volts) + " V is outside +/- 10 V");
    return static_cast<std::int64_t>(std::llround(volts * kAnalogNumPerVolt));
}

std::span<const BitTiming> bit_timings() {
    // §3.1: transmission rate NBT, setting value BTR, line length max.
    static const std::array<BitTiming, 5> table{{
        {1000, 0x4002, 20}, {500, 0x4025, 70}, {625, 0x4014, 70}, {250, 0x405C, 100}, {100, 0x4425, 500},
    }};
    return table;
}

namespace {
std::string btr_list() {
    std::string s;
    for (const auto& b : bit_timings()) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%s0x%04X (%d k)", s.empty() ? "" : ", ", b.btr, b.kbit_s);
        s += buf;
    }
    return s;
}
}  // namespace

const BitTiming& bit_timing_for_btr(std::uint16_t btr) {
    for (const auto& b : bit_timings())
        if (b.btr == btr) return b;
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", btr);
    throw InvalidArgument(std::string("unitek BTR ") + buf + ": not in the manual's table (" + btr_list() + ")");
}

const BitTiming& bit_timing_for_bit_rate(double bit_s) {
    for (const auto& b : bit_timings())
        if (b.bit_rate() == bit_s) return b;
    throw InvalidArgument("unitek bit rate " + std::to_string(static_cast<long long>(bit_s)) +
                          " bit/s: not in the manual's table (" + btr_list() + ")");
}

ToDrive decode_to_drive(std::span<const std::uint8_t> data) {
    const std::size_t n = data.size();
    if (n > 8) throw FrameError("unitek frame to the drive: DLC " + std::to_string(n) + " > 8", 8, copy(data));
    if (n == 0) throw FrameError("unitek frame to the drive: DLC 0, byte 0 (REGID) missing", 0, copy(data));
    if (n < 3)
        throw FrameError("unitek frame to the drive " + hex(data) + ": DLC " + std::to_string(n) + ", byte " +
                             std::to_string(n) + " (value " + (n == 1 ? "low" : "high") + " byte) missing",
                         static_cast<int>(n), copy(data));
    ToDrive t;
    t.regid = data[0];
    if (n <= 4) {  // DLC 3, and DLC 4 evaluated as 3 (B-U03)
        t.value = le(data, 1, 2);
        t.value_bits = 16;
    } else {  // DLC 5, and 6..8 evaluated as 5 (B-U02)
        t.value = le(data, 1, 4);
        t.value_bits = 32;
    }
    return t;
}

FromDrive decode_from_drive(std::span<const std::uint8_t> data) {
    const std::size_t n = data.size();
    if (n != 4 && n != 6) {
        // The byte at fault: the first missing one for a short frame, else the first extra one.
        const int at = n < 4 ? static_cast<int>(n) : (n == 5 ? 5 : 6);
        throw FrameError("unitek frame from the drive " + hex(data) + ": DLC " + std::to_string(n) +
                             " (a reply is 4 or 6 bytes: REGID, 16/32-bit value, dummy); byte " + std::to_string(at) +
                             (static_cast<std::size_t>(at) >= n ? " missing" : " unexpected"),
                         at, copy(data));
    }
    FromDrive f;
    f.regid = data[0];
    f.value_bits = n == 4 ? 16 : 32;
    f.value = le(data, 1, n == 4 ? 2 : 4);
    return f;
}

std::vector<std::uint8_t> encode_write(std::uint8_t regid, std::int64_t value, int bits) {
    if (bits != 16 && bits != 32) throw InvalidArgument("unitek write: bits 16 or 32, not " + std::to_string(bits));
    // Either reading of the bits (signed or unsigned) is accepted here; the table checks the sign.
    if (value < width_lo(bits, true) || value > width_hi(bits, false))
        throw InvalidArgument("unitek register " + regid_text(regid) + ": value " + std::to_string(value) +
                              " is outside a " + std::to_string(bits) + "-bit value");
    const auto u = static_cast<std::uint32_t>(value);
    std::vector<std::uint8_t> out{regid, static_cast<std::uint8_t>(u), static_cast<std::uint8_t>(u >> 8)};
    if (bits == 32) {
        out.push_back(static_cast<std::uint8_t>(u >> 16));
        out.push_back(static_cast<std::uint8_t>(u >> 24));
    }
    return out;
}

std::vector<std::uint8_t> encode_write(const Register& r, std::int64_t value) {
    if (!r.writable()) throw InvalidArgument("unitek register " + r.name + " (" + regid_text(r.regid) + "): read-only");
    if (value < r.lo() || value > r.hi())
        throw InvalidArgument("unitek register " + r.name + ": value " + std::to_string(value) + " is outside " +
                              std::to_string(r.lo()) + ".." + std::to_string(r.hi()));
    return encode_write(r.regid, value, r.bits);
}

std::vector<std::uint8_t> encode_request(std::uint8_t regid, std::uint8_t interval) {
    return {kRegRead, regid, interval};
}

std::vector<std::uint8_t> encode_cyclic(std::uint8_t regid, int interval_ms) {
    if (interval_ms < 1 || interval_ms > 254)
        throw InvalidArgument("unitek cyclic interval: 1..254 ms, not " + std::to_string(interval_ms));
    return encode_request(regid, static_cast<std::uint8_t>(interval_ms));
}

std::vector<std::uint8_t> encode_reply(std::uint8_t regid, std::uint32_t raw, int bits, std::uint8_t dummy) {
    if (bits != 16 && bits != 32) throw InvalidArgument("unitek reply: bits 16 or 32");
    std::vector<std::uint8_t> out{regid, static_cast<std::uint8_t>(raw), static_cast<std::uint8_t>(raw >> 8)};
    if (bits == 32) {
        out.push_back(static_cast<std::uint8_t>(raw >> 16));
        out.push_back(static_cast<std::uint8_t>(raw >> 24));
    }
    out.push_back(dummy);
    return out;
}

std::string hex(std::span<const std::uint8_t> data) {
    std::string s;
    char buf[4];
    for (std::size_t i = 0; i < data.size(); ++i) {
        std::snprintf(buf, sizeof buf, i ? " %02X" : "%02X", data[i]);
        s += buf;
    }
    return s;
}

}  // namespace motorbus::unitek

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "motorbus/errors.hpp"
#include "motorbus/motion/planner.hpp"
#include "toy/toy.hpp"

namespace motorbus::toy {

namespace {
// Joins text pieces with append (GCC 12's -Wrestrict misreads chains of operator+ on strings).
template <class... Parts>
std::string cat(const Parts&... parts) {
    std::string out;
    (out.append(std::string_view(parts)), ...);
    return out;
}
}  // namespace

const char* to_string(LastStop s) {
    switch (s) {
        case LastStop::None: return "NONE";
        case LastStop::Target: return "TARGET";
        case LastStop::Stop: return "STOP";
        case LastStop::Abort: return "ABORT";
        case LastStop::Disable: return "DISABLE";
        case LastStop::Fault: return "FAULT";
    }
    return "NONE";
}

namespace {

std::shared_ptr<Clock> or_real_clock(std::shared_ptr<Clock> clock) {
    return clock ? std::move(clock) : std::make_shared<RealClock>();
}

motion::MotorConfig motor_config() {
    motion::MotorConfig cfg;
    cfg.steps_per_rev = 200;
    cfg.counts_per_rev = 200;
    cfg.index_channel = false;  // no Z: a long move is not cut at every revolution
    return cfg;
}

bool parse_number(std::string_view text, double& out) {
    // from_chars: no locale, no exceptions, rejects trailing garbage.
    const char* end = text.data() + text.size();
    auto r = std::from_chars(text.data(), end, out);
    return r.ec == std::errc() && r.ptr == end && std::isfinite(out);
}

std::string reply(std::string_view body) { return cat(body, kReplyTerminator); }

}  // namespace

Sim::Sim(std::shared_ptr<Clock> clock, SimOptions options)
    : clock_(or_real_clock(std::move(clock))), opt_(options), motor_(*clock_, motor_config()) {
    if (opt_.address < 1 || opt_.address > 9)
        throw InvalidArgument(cat("toy sim address: 1..9, not ", std::to_string(opt_.address)));
    if (!(opt_.speed > 0) || !(opt_.accel > 0) || !std::isfinite(opt_.speed) || !std::isfinite(opt_.accel))
        throw InvalidArgument("toy sim speed and accel: finite and > 0");
    if (opt_.start_position != 0) motor_.set_pulse_position(opt_.start_position);
    // A MOVE that runs to its end has arrived; a later STOP/ABORT overwrites this.
    motor_.add_listener([this](const motion::MotorEvent& e) {
        if (e.kind == motion::MotorEvent::Kind::ProfileDone && last_ == LastStop::None && !jogging_)
            last_ = LastStop::Target;
    });
}

std::int64_t Sim::position() {
    std::lock_guard lock(mu_);
    motor_.update();
    return motor_.pulse_count();
}

bool Sim::moving() {
    std::lock_guard lock(mu_);
    motor_.update();
    return motor_.moving();
}

std::string Sim::on_line(std::string_view line) {
    // "@<address> <command>[ <argument>]"; another address or no '@': silent (multi-drop).
    if (line.size() < 4 || line[0] != '@' || line[2] != ' ') return "";
    if (line[1] != static_cast<char>('0' + opt_.address)) return "";
    std::string_view rest = line.substr(3);
    auto space = rest.find(' ');
    std::string_view cmd = rest.substr(0, space);
    std::string_view arg = space == std::string_view::npos ? std::string_view{} : rest.substr(space + 1);
    std::lock_guard lock(mu_);
    motor_.update();
    try {
        return reply(handle(cmd, arg));
    } catch (const std::exception& e) {  // a planner refusal: the drive's error reply, never a throw
        return reply(cat("ERR ", e.what()));
    }
}

void Sim::stop_at_accel() {
    motion::State now{motor_.pulse_position(), motor_.pulse_velocity(), 0, 0};
    if (!motor_.moving() || now.v == 0) {
        motor_.halt();
        return;
    }
    // Rest after the shortest ramp: the trapezoid to the stopping point only decelerates.
    double target = now.p + now.v * std::fabs(now.v) / (2 * opt_.accel);
    motion::Limits lim{std::fabs(now.v), opt_.accel};
    motor_.command(motion::plan_trapezoid(now, target, lim));
}

void Sim::set_fault_input(bool active) {
    std::lock_guard lock(mu_);
    motor_.update();
    fault_input_ = active;
    if (!active) return;
    if (motor_.moving()) last_ = LastStop::Fault;
    motor_.halt();
    fault_ = true;
    enabled_ = jogging_ = false;
}

std::string Sim::handle(std::string_view cmd, std::string_view arg) {
    if (cmd == "POS?") return std::to_string(motor_.pulse_count());
    if (cmd == "VEL?") return std::to_string(static_cast<long long>(std::llround(motor_.pulse_velocity())));
    if (cmd == "STATUS?") {
        const char* state = fault_ ? "FAULT" : !enabled_ ? "DISABLED" : motor_.moving() ? "MOVING" : "IDLE";
        return cat(state, " ", to_string(last_), homed_ ? " HOMED" : " UNHOMED");
    }
    if (cmd == "ENABLE") {
        if (fault_) return "ERR fault latched: CLEAR it first";
        enabled_ = true;
        return "OK";
    }
    if (cmd == "CLEAR") {
        if (fault_input_) return "ERR the fault input is still active";
        fault_ = false;
        return "OK";
    }
    if (cmd == "DISABLE") {
        if (motor_.moving()) last_ = LastStop::Disable;
        motor_.halt();
        enabled_ = jogging_ = false;
        return "OK";
    }
    if (cmd == "STOP" || cmd == "ABORT") {
        if (motor_.moving()) last_ = cmd == "STOP" ? LastStop::Stop : LastStop::Abort;
        if (cmd == "STOP") stop_at_accel(); else motor_.halt();
        jogging_ = false;
        return "OK";
    }
    if (cmd == "MOVE" || cmd == "JOG" || cmd == "HOME") return motion(cmd, arg);
    if (!cmd.empty() && cmd.back() == '?') return setting(cmd.substr(0, cmd.size() - 1), {});
    if (!arg.empty()) return setting(cmd, arg);
    return cat("ERR unknown command ", cmd.substr(0, 16));
}

std::string Sim::motion(std::string_view cmd, std::string_view arg) {
    if (fault_) return "ERR fault latched";
    if (!enabled_) return "ERR disabled";
    if (cmd == "HOME") {
        if (motor_.moving()) return "ERR moving";
        motor_.set_pulse_position(0);
        homed_ = true;
        return "OK";
    }
    double value = 0;
    if (!parse_number(arg, value)) return cat("ERR ", cmd, " takes a number");
    motion::State now{motor_.pulse_position(), motor_.pulse_velocity(), 0, 0};
    motion::Limits lim{opt_.speed, opt_.accel};
    if (cmd == "MOVE") {
        if (std::fabs(value) > 2e9) return "ERR MOVE target outside +-2e9 steps";
        last_ = LastStop::None;
        jogging_ = false;
        motor_.command(motion::plan_trapezoid(now, std::round(value), lim));
        return "OK";
    }
    if (std::fabs(value) > opt_.speed * 10) return "ERR JOG speed above 10 x SPEED";
    last_ = LastStop::None;
    lim.max_velocity = std::max(opt_.speed, std::fabs(value));
    jogging_ = true;
    motor_.command(motion::plan_velocity(now, value, lim, 1e6));  // "until STOP": 11 days
    return "OK";
}

std::string Sim::setting(std::string_view name, std::string_view arg) {
    struct Row {
        const char* name;
        double* value;
        double lo, hi;
    };
    double addr = opt_.address;
    const Row rows[] = {{"SPEED", &opt_.speed, 1, 100000},
                        {"ACCEL", &opt_.accel, 1, 1e7},
                        {"WINDOW", &window_, 0, 1000},
                        {"ADDR", nullptr, 1, 9}};
    for (const Row& r : rows) {
        if (name != r.name) continue;
        if (arg.empty()) return std::to_string(static_cast<long long>(std::llround(r.value ? *r.value : addr)));
        if (!r.value) return cat("ERR ", name, " is read-only");
        double v = 0;
        if (!parse_number(arg, v) || v != std::round(v)) return cat("ERR ", name, " takes an integer");
        if (v < r.lo || v > r.hi) return cat("ERR ", name, " outside its range");
        *r.value = v;
        return "OK";
    }
    return cat("ERR unknown command ", name.substr(0, 16));
}

}  // namespace motorbus::toy

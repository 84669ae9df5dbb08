#include "motorbus/drives/arcus/sim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "motorbus/drives/arcus/sim_commands.hpp"
#include "motorbus/drives/arcus/sim_core.hpp"

namespace motorbus::arcus {


// ------------------------------------------------------------------------------

Sim::Sim(Clock& clock, SimOptions options)
    : clock_(clock), options_(std::move(options)), s_(std::make_unique<State>()) {
    if (options_.address < 1 || options_.address > kMaxAddress)
        throw InvalidArgument("arcus sim address: must be 1..99");
    if (options_.response_type != 0 && options_.response_type != 1)
        throw InvalidArgument("arcus sim response_type: must be 0 or 1");
    if (options_.tick_ns <= 0) throw InvalidArgument("arcus sim tick_ns: must be > 0");
    s_->motor = std::make_unique<motion::MotorModel>(clock_, motor_config(options_));
    s_->motor->displace(options_.world.start_position);
    State* sp = s_.get();
    const SimOptions* op = &options_;
    s_->motor->add_listener([sp, op](const motion::MotorEvent& e) { SimEngine(*sp, *op).on_event(e); });
    if (options_.comm_type < 0 || options_.comm_type > 2)
        throw InvalidArgument("arcus sim comm_type: must be 0 (RS-232), 1 (RS-485) or 2 (CAN)");
    if (options_.node_id < 1 || options_.node_id > 127) throw InvalidArgument("arcus sim node_id: must be 1..127");
    if (options_.bit_rate < 1 || options_.bit_rate > 9)
        throw InvalidArgument("arcus sim bit_rate: a 200Bh code 1..9 (10k 20k 50k 100k 125k 250k 500k 800k 1M)");
    if (options_.store_ns < 0 || options_.clear_ns < 0)
        throw InvalidArgument("arcus sim store/clear duration: must be >= 0");
    std::lock_guard lock(mutex_);
    boot();
}

Sim::Sim(std::shared_ptr<Clock> clock, SimOptions options)
    : Sim((clock ? *clock : throw InvalidArgument("arcus sim: clock is null")), std::move(options)) {
    clock_owner_ = std::move(clock);
}

Sim::~Sim() { close(); }

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

}  // namespace

void Sim::power_cycle() {
    std::optional<can::Frame> boot_up;
    {
        std::lock_guard lock(mutex_);
        boot();
        boot_up = boot_up_frame();
    }
    if (boot_up) send_frames({*boot_up});
}

void Sim::boot() {
    State& s = *s_;
    const Nanos now = clock_.now();
    SimEngine(s, options_).advance(now);
    if (s.homing) s.homing.reset();
    if (s.homing_listener) s.motor->remove_listener(s.homing_listener);
    auto motor = std::move(s.motor);  // the shaft stays where it is
    unsigned inputs = s.inputs;
    bool blocked = s.blocked;
    // The flash outlives the power cycle, store file or not (issue 23 #1).
    const bool stored = s.stored;
    const Flash kept = s.flash;
    s = State{};
    s.motor = std::move(motor);
    s.inputs = inputs;
    s.blocked = blocked;
    s.flash.dn = options_.address;
    s.flash.rt = options_.response_type;
    s.flash.eoboot = options_.eo_boot ? 1 : 0;
    s.flash.sl = options_.snl ? 1 : 0;
    s.flash.cm = options_.comm_type;
    s.flash.nid = options_.node_id;
    s.flash.br = options_.bit_rate;
    if (options_.comm_type == 2) {
        // A unit set up for CANopen: the CANopen tables' defaults (Tables 8.11,
        // 8.21, where the ASCII persona follows Table 7.11; docs/drives/arcus.md).
        s.flash.slt = 10;
        s.flash.curr = 1500;
        s.flash.curi = 500;
    }
    load_flash(options_.store_path, s.flash);
    if (stored) {
        // What this simulator stored (the file, when there is one, holds the same).
        s.flash = kept;
        s.stored = true;
    }
    s.cfg = s.flash;
    s.active_address = static_cast<int>(std::clamp<std::int64_t>(s.cfg.dn, 1, 99));
    s.active_rt = s.cfg.rt ? 1 : 0;
    s.active_cm = static_cast<int>(std::clamp<std::int64_t>(s.cfg.cm, 0, 2));
    s.active_nid = static_cast<int>(std::clamp<std::int64_t>(s.cfg.nid, 1, 127));
    s.active_br = static_cast<int>(s.cfg.br);
    bit_rate_code_.store(s.active_br);
    s.eo = s.cfg.eoboot ? 1 : 0;
    s.user_do = s.cfg.doboot & 7;
    motion::MotorModel& m = *s.motor;
    m.halt();
    m.disarm_latch();
    SimEngine e(s, options_);
    e.apply_wiring();
    m.set_pulse_position(0);  // counters start at 0
    m.set_encoder(0);
    e.configure_snl();
    s.idle_since = now - s.cfg.curt * 1'000'000 - 1;
}

int Sim::address() const {
    std::lock_guard lock(mutex_);
    return s_->active_address;
}

std::string Sim::store_path() const { return options_.store_path; }

#define MOTORBUS_ARCUS_SYNC()            \
    std::lock_guard lock(mutex_);        \
    SimEngine e(*s_, options_);          \
    e.advance(clock_.now())

void Sim::set_input(int index, bool actuated) {
    if (index < 1 || index > 6) throw InvalidArgument("arcus sim input: index must be 1..6");
    MOTORBUS_ARCUS_SYNC();
    bool before = e.latch_in();
    unsigned bit = 1u << (index - 1);
    s_->inputs = actuated ? (s_->inputs | bit) : (s_->inputs & ~bit);
    auto& m = *s_->motor;
    if (!before && e.latch_in() && m.latch_state() == motion::MotorModel::LatchState::Armed) {
        m.trigger_latch();
        s_->ltp = std::llround(m.latched_pulse());
        s_->lte = m.latched_encoder();
    }
}

void Sim::force_home(std::optional<bool> actuated) {
    MOTORBUS_ARCUS_SYNC();
    s_->motor->force_switch(motion::Switch::Home, actuated);
}

void Sim::force_limit(int direction, std::optional<bool> actuated) {
    MOTORBUS_ARCUS_SYNC();
    s_->motor->force_switch(direction > 0 ? motion::Switch::PlusLimit : motion::Switch::MinusLimit, actuated);
}

void Sim::set_blocked(bool blocked) {
    MOTORBUS_ARCUS_SYNC();
    s_->blocked = blocked;
    e.apply_jam();
}

void Sim::disturb(double steps) {
    MOTORBUS_ARCUS_SYNC();
    const std::int64_t enc_prev = e.encoder();
    s_->motor->displace(steps);
    if (s_->motor->moving()) e.sample(enc_prev);
    else if (s_->job == Job::None) e.verify_position(/*idle=*/true);
}

double Sim::physical_position() const {
    MOTORBUS_ARCUS_SYNC();
    return s_->motor->physical_position();
}

std::int64_t Sim::pulse_position() {
    MOTORBUS_ARCUS_SYNC();
    return e.pulse();
}
std::int64_t Sim::encoder_position() {
    MOTORBUS_ARCUS_SYNC();
    return e.encoder();
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
    return s_->motor->moving();
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
        // Stored as CAN and power-cycled: the serial line is silent (B-A01).
        if (s_->active_cm == 2) return "";
        if (req->address != kBroadcast && req->address != s_->active_address) return "";
        std::string body = handle(*req);
        if (req->address == kBroadcast) return "";
        return format_reply(s_->active_address, body, s_->active_rt);
    } catch (const std::exception&) {
        return "";  // never let a bug in one command take the line down
    }
}

// The firmware's command interpreter, reached by the CANopen front end: both
// front ends end in the same commands on the same state.  mutex_ held.
std::string Sim::command(std::string_view cmd) {
    Request req;
    req.address = s_->active_address;
    req.command = std::string(cmd);
    return handle(req);
}

// Runs one command; returns the reply body.  mutex_ held.
std::string Sim::handle(const Request& req) {
    State& s = *s_;
    const Nanos now = at_.value_or(clock_.now());
    SimEngine(s, options_).advance(now);

    const std::string& cmd = req.command;
    auto pc = parse_command(cmd);
    if (!pc) return unknown_reply(cmd);
    if (!pc->index_valid) return std::string(error_text(ErrorCode::IndexOutOfRange));
    if (pc->info->motion && pc->op != ParsedCommand::Op::Query && s.motor->moving())
        return std::string(error_text(ErrorCode::Moving));
    // One handler per command and form, hung from the codec's table (sim_commands.cpp).
    return run_command(s, options_, now, *pc, cmd);
}

}  // namespace motorbus::arcus

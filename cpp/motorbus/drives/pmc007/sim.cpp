#include "motorbus/drives/pmc007/sim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "motorbus/canopen/emcy.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::pmc007 {
using canopen::Bytes;
using canopen::NmtState;

namespace {
// Reentrancy guard of publish(): setting a variable tells its listeners, which publish again.
thread_local bool t_publishing = false;

std::int64_t decode_le(std::span<const std::uint8_t> d, bool is_signed) {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < d.size() && i < 8; ++i) v |= std::uint64_t(d[i]) << (8 * i);
    if (is_signed && !d.empty() && d.size() < 8 && (d.back() & 0x80)) v |= ~std::uint64_t(0) << (8 * d.size());
    return static_cast<std::int64_t>(v);
}

bool valid_microstepping(std::int64_t v) {
    return v == 0 || v == 2 || v == 4 || v == 8 || v == 16 || v == 32 || v == 64 || v == 128 || v == 256;
}

// The node's timer drives the sim in real time (PDOs, heartbeat-visible state).
class Ticker : public canopen::NodeService {
public:
    explicit Ticker(Sim& sim) : sim_(sim) {}
    Nanos on_timer(canopen::LocalNode&, Nanos now) override {
        sim_.poll();
        // 2 ms while something changes by itself (a move, a program, a debounce),
        // else 20 ms: an idle node on a big bus costs little.
        return now + (sim_.active() ? 2'000'000 : 20'000'000);
    }

private:
    Sim& sim_;
};

// Objects whose value the device computes (published after every change).
constexpr std::pair<std::uint16_t, std::uint8_t> kLive[] = {
    {0x1001, 0}, {0x1002, 0}, {0x2007, 0}, {0x6000, 0}, {0x6001, 0}, {0x600C, 0}, {0x6012, 0}, {0x6022, 0},
    {0x6004, 0}, {0x601C, 0}, {0x6020, 0}, {0x6019, 2}, {0x6019, 3}, {0x6019, 5}};
}  // namespace

namespace {
// The one failure of a (re)start that is device behaviour: another node serves the ID.
bool id_taken(const std::exception& e) { return dynamic_cast<const canopen::NodeIdTaken*>(&e) != nullptr; }
}  // namespace

Sim::Sim(std::uint8_t node_id, Clock& clock, SimOptions options)
    : node_id_(node_id), clock_(clock), opt_(options), od_(build_pmc007_od(node_id, options.identity)), motor_(clock, [&] {
          motion::MotorConfig c;
          c.steps_per_rev = options.steps_per_rev;
          c.counts_per_rev = options.steps_per_rev;
          c.index_channel = false;  // the PMC007 reads no encoder index from the motor
          c.pull_out_speed = options.pull_out_speed;
          c.tick_ns = options.tick_ns;
          if (options.ext1_switch) c.home = {true, options.ext1_switch->first, options.ext1_switch->second, true};
          return c;
      }()) {
    // Factory "flash": the defaults of every ROM object.
    for (const auto& r : od_rows())
        if (r.storage == Storage::Rom) flash_[{r.index, r.sub}] = od_->at(r.index, r.sub)->default_bytes();
    // What load_power_up() visits, looked up once (the keys of flash_ never change).
    for (const auto& r : od_rows())
        power_up_.push_back({&r, od_->at(r.index, r.sub),
                             r.storage == Storage::Rom ? &flash_.at({r.index, r.sub}) : nullptr});
    for (const auto& r : od_rows()) {
        const bool pdo_area = r.index >= 0x1400 && r.index <= 0x1BFF;
        if (pdo_area || r.index == 0x1016 || r.index == 0x1017) continue;  // the generic services own them
        auto var = od_->at(r.index, r.sub);
        const std::uint16_t i = r.index;
        const std::uint8_t s = r.sub;
        if (canopen::writable(r.access))
            var->set_write_hook([this, i, s](const canopen::Variable&, std::span<const std::uint8_t> d) {
                return on_write(i, s, d);
            });
        var->add_change_listener([this](const canopen::Variable&) { publish(); });
    }
    published_ = {.error_register = od_->at(0x1001, 0),
                  .manufacturer_status = od_->at(0x1002, 0),
                  .system_control = od_->at(0x2007, 0),
                  .error_status = od_->at(0x6000, 0),
                  .controller_status = od_->at(0x6001, 0),
                  .motor_position = od_->at(0x600C, 0),
                  .gpio_value = od_->at(0x6012, 0),
                  .saved_position = od_->at(0x6022, 0),
                  .step_command = od_->at(0x6004, 0),
                  .absolute_command = od_->at(0x601C, 0),
                  .stop_command = od_->at(0x6020, 0),
                  .save_program = od_->at(0x6019, 3),
                  .run_instruction = od_->at(0x6019, 5),
                  .gpio_direction = od_->at(0x6011, 1),
                  .program_word = od_->at(0x6019, 2)};
    for (auto [i, s] : kLive)
        od_->at(i, s)->set_read_hook([this](const canopen::Variable& v, Bytes& out) -> std::uint32_t {
            poll();
            out = v.get();
            return 0;
        });
    motor_.add_listener([this](const motion::MotorEvent& e) { on_motor_event(e); });
    read_store();
    load_power_up(true);
}

Sim::Sim(std::uint8_t node_id, std::shared_ptr<Clock> clock, SimOptions options)
    : Sim(node_id, clock ? *clock : throw InvalidArgument("pmc007 sim: clock is None"), std::move(options)) {
    clock_owner_ = std::move(clock);
}

Sim::~Sim() { close(); }

std::string Sim::describe() const { return "pmc007 sim node " + std::to_string(node_id_.load()); }

std::string Sim::last_error() const {
    std::lock_guard lock(m_);
    return last_error_;
}

void Sim::record_node_error(const std::string& what) {
    std::lock_guard lock(m_);
    last_error_ = what;
}

canopen::LocalNodeOptions Sim::node_options() {
    canopen::LocalNodeOptions o;
    o.reset_restores_defaults = false;  // B-P27/B-P28: the device's own reset rules (on_reset)
    o.sdo_require_dlc8 = true;          // B-P06 [P]: SDO requests with DLC != 8 are ignored
    o.sdo.block_transfer = false;       // B-P05 [P]: no block transfer (05040001)
    o.on_reset = [this](canopen::NmtCommand c) { on_reset(c); };
    return o;
}

// Nodes and services are made and destroyed without the sim's lock held: their
// threads call into the sim (hooks, timer) and would otherwise wait on it while
// we wait on them.
void Sim::attach(std::shared_ptr<can::Bus> bus) {
    {
        std::lock_guard lock(m_);
        if (node_ || attaching_ || bus_) throw already_attached();
        // The node hears and is heard only at its 2003h baud in effect (issue 23 #11);
        // the gate owns the medium, so the caller need not keep it.
        gate_ = gate_onto(std::move(bus));
        attaching_ = true;
        bus_ = gate_.get();
    }
    std::unique_ptr<canopen::LocalNode> n;
    Services sv;
    try {
        n = std::make_unique<canopen::LocalNode>(*bus_, node_id_.load(), od_, node_options());
        sv = make_services(*n);
    } catch (...) {
        std::lock_guard lock(m_);
        attaching_ = false;
        bus_ = nullptr;
        if (gate_) old_gates_.push_back(std::move(gate_));  // `n` still holds it
        throw;
    }
    install_node(std::move(n), std::move(sv));
}

void Sim::install_node(std::unique_ptr<canopen::LocalNode> n, Services sv) {
    std::lock_guard lock(m_);
    node_ = std::move(n);
    pdo_ = std::move(sv.pdo);
    hb_ = std::move(sv.hb);
    ticker_ = std::move(sv.ticker);
    attaching_ = false;
}

Sim::Services Sim::make_services(canopen::LocalNode& n) {
    Services sv;
    canopen::PdoServiceOptions po;
    po.strict = false;  // B-P32: the manual's sequence changes a valid PDO in place
    po.rtr = canopen::PdoRtrPolicy::Never;  // B-P35 / C-P16: remote frames are not supported (003 §4.2)
    po.allow_restricted_cob_ids = true;     // B-P32 [D]: any COB-ID may be configured
    sv.pdo = canopen::PdoService::attach(n, po);
    apply_sync_cob_id(sv.pdo);
    // 1016h consumers: the manual documents no reaction to a lost heartbeat: EMCY 8130h only [P].
    sv.hb = canopen::HeartbeatService::attach(
        n, {.consumer_entries = 3, .producer_ms = 0, .error_behaviour_without_1029 = 1});
    // B-P30: every EMCY goes out through the device (1001h in byte 2, 1015h, 1003h).
    sv.pdo->on_emcy = [this](std::uint16_t code, bool active) { comm_error(code, active); };
    sv.hb->on_emcy = [this](std::uint16_t code) { comm_error(code, true); };
    sv.hb->on_event = [this](std::uint8_t, canopen::HeartbeatEvent ev, canopen::NodeState) {
        if (ev == canopen::HeartbeatEvent::Back || ev == canopen::HeartbeatEvent::Started) comm_error(0x8130, false);
    };
    sv.ticker = std::make_shared<Ticker>(*this);
    n.add_service(sv.ticker);
    return sv;
}

void Sim::schedule_node_id_switch() {
    // Called on the bus thread in the middle of the NMT reset: the node cannot be
    // replaced from there, so a helper thread does it once the reset is over.
    std::lock_guard lock(m_);
    if (!node_) return;
    if (renode_.joinable()) {
        if (!renode_done_) {
            // One switch at a time: the running one looks again when it is done.  This
            // comes before comparing with node_id_, which a running switch has not
            // updated yet: the new node answers (boot-up, SDO, NMT) from its constructor
            // on, so a reset can reach it while node_id_ still holds the old ID, and
            // "2002h == node_id_" would then wrongly read as "nothing to do".
            renode_again_ = true;
            return;
        }
        renode_.join();  // finished: reaping it does not wait
    }
    if (u(0x2002) == node_id_) return;
    renode_done_ = false;
    renode_again_ = false;
    renode_ = std::thread([this] {
        for (;;) {
            std::uint8_t id = 0;
            {
                std::lock_guard l(m_);
                renode_again_ = false;
                id = static_cast<std::uint8_t>(u(0x2002));
            }
            if (id != node_id_) switch_node_id(id);
            std::lock_guard l(m_);
            if (!renode_again_) {
                renode_done_ = true;
                return;
            }
        }
    });
}

void Sim::switch_node_id(std::uint8_t new_id) {
    canopen::LocalNode* old = nullptr;
    {
        std::lock_guard lock(m_);
        old = node_.get();
    }
    if (!old) return;
    for (int i = 0; i < 500 && old->nmt_state() != NmtState::PreOperational; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const std::uint8_t old_id = node_id_;
    // Predefined COB-IDs ($NODEID+...) follow the node-ID when they still hold the old default.
    std::vector<std::pair<const OdRow*, std::int64_t>> moved;
    for (const auto& r : od_rows())
        if (r.node_offset >= 0) {
            const std::int64_t cur = u(r.index, r.sub);
            if ((cur & 0x7FF) == r.node_offset + old_id) moved.push_back({&r, (cur & ~0x7FFLL) | (r.node_offset + new_id)});
        }
    od_->set_node_id(new_id);
    t_publishing = true;
    for (auto& [r, v] : moved) set(r->index, r->sub, v);
    t_publishing = false;
    std::unique_ptr<canopen::LocalNode> fresh;
    Services sv;
    try {
        fresh = std::make_unique<canopen::LocalNode>(*bus_, new_id, od_, node_options());
        sv = make_services(*fresh);  // the new node is PRE-OPERATIONAL with its boot-up sent
    } catch (const std::exception& e) {
        // Stay on the old ID (and put the COB-IDs back).  An ID taken on this bus is
        // the documented case; anything else is a fault: either way, last_error() says which.
        record_node_error(id_taken(e) ? "pmc007 sim node " + std::to_string(old_id) + ": node-ID " +
                                            std::to_string(new_id) + " is taken, stays on " + std::to_string(old_id)
                                      : "pmc007 sim node " + std::to_string(old_id) + ": switching to node-ID " +
                                            std::to_string(new_id) + " failed: " + e.what());
        od_->set_node_id(old_id);
        t_publishing = true;
        for (auto& [r, v] : moved) set(r->index, r->sub, (v & ~0x7FFLL) | (r->node_offset + old_id));
        t_publishing = false;
        return;
    }
    std::unique_ptr<canopen::LocalNode> gone;
    {
        std::lock_guard lock(m_);
        retired_.push_back(pdo_);
        retired_.push_back(hb_);
        retired_.push_back(ticker_);
        gone = std::move(node_);
        node_ = std::move(fresh);
        pdo_ = sv.pdo;
        hb_ = sv.hb;
        ticker_ = sv.ticker;
        node_id_ = new_id;
    }
    gone->close();
    std::lock_guard lock(m_);
    retired_.push_back(std::shared_ptr<canopen::LocalNode>(std::move(gone)));
}

bool Sim::attached() const {
    std::lock_guard lock(m_);
    return node_ != nullptr || (bus_ != nullptr && !attaching_);  // in the bootloader: off the bus, still attached
}

void Sim::serve_again() {
    can::Bus* bus = nullptr;
    {
        std::lock_guard lock(m_);
        if (!bus_ || node_ || attaching_) return;
        bus = bus_;
        attaching_ = true;
    }
    std::unique_ptr<canopen::LocalNode> n;
    Services sv;
    try {
        n = std::make_unique<canopen::LocalNode>(*bus, node_id_.load(), od_, node_options());  // boot-up sent
        sv = make_services(*n);
    } catch (const std::exception& e) {
        // [P] the ID is served by another node meanwhile: this one stays off the bus.  Any
        // other failure too, but it is no device behaviour: last_error() tells them apart.
        const std::string id = std::to_string(node_id_.load());
        std::lock_guard lock(m_);
        last_error_ = id_taken(e) ? "pmc007 sim node " + id + ": node-ID " + id + " is taken, stays off the bus"
                                  : "pmc007 sim node " + id + ": back on the bus failed: " + e.what();
        attaching_ = false;
        return;
    }
    install_node(std::move(n), std::move(sv));
}

void Sim::enter_bootloader() {
    std::shared_ptr<canopen::LocalNode> n;
    Services sv;
    {
        std::lock_guard lock(m_);
        if (!node_) return;
        n = std::shared_ptr<canopen::LocalNode>(std::move(node_));
        sv = {std::move(pdo_), std::move(hb_), std::move(ticker_)};
        emcy_queue_.clear();
    }
    // Closing joins the node's worker thread, which may be the one calling us (the
    // ticker's poll): a helper thread does it.  The node and its services are kept
    // (retired_): their hooks and listeners stay on the dictionary until a new node's
    // services replace them.
    n->set_nmt_state(NmtState::Stopped);  // silent from now on (no SDO, no PDO) while it closes
    if (boot_.joinable()) boot_.join();
    boot_ = std::thread([this, n, sv] {
        n->close();
        std::lock_guard lock(m_);
        retired_.push_back(sv.pdo);
        retired_.push_back(sv.hb);
        retired_.push_back(sv.ticker);
        retired_.push_back(n);
    });
}

void Sim::close() {
    if (renode_.joinable() && renode_.get_id() != std::this_thread::get_id()) renode_.join();
    if (boot_.joinable() && boot_.get_id() != std::this_thread::get_id()) boot_.join();
    std::unique_ptr<canopen::LocalNode> n;
    Services sv;
    {
        std::lock_guard lock(m_);
        n = std::move(node_);
        sv = {std::move(pdo_), std::move(hb_), std::move(ticker_)};
        bus_ = nullptr;
    }
    if (n) n->close();
    sv = {};  // destroyed without the lock (they unsubscribe from the bus)
    // Closed, not freed: retired nodes and services unsubscribe from it when they go.
    can::BitRateGate* gate = nullptr;
    {
        std::lock_guard lock(m_);
        gate = gate_.get();
        if (gate_) old_gates_.push_back(std::move(gate_));
    }
    if (gate) gate->close();
}

double baud_index_bps(int index) {
    // 003 §4.3.2: 0 20k, 1 25k, 2 50k, 3 100k, 4 125k, 5 250k, 6 500k, 7 800k, 8 1M.
    static constexpr double kBps[] = {20e3, 25e3, 50e3, 100e3, 125e3, 250e3, 500e3, 800e3, 1e6};
    return index >= 0 && index <= 8 ? kBps[index] : -1.0;  // -1: matches no wire
}

// ---- values -------------------------------------------------------------------

std::int64_t Sim::u(std::uint16_t i, std::uint8_t s) const {
    auto v = od_->at(i, s);
    const Bytes b = v->get();
    return decode_le(b, v->type() == canopen::DataType::Integer32);
}

void Sim::set(std::uint16_t i, std::uint8_t s, std::int64_t value) { set(od_->at(i, s), value); }

void Sim::set(const canopen::VariablePtr& v, std::int64_t value) {
    std::uint8_t b[8];  // every object set here is a number of at most 8 bytes
    const std::size_t n = std::min(v->size(), sizeof b);
    for (std::size_t k = 0; k < n; ++k) b[k] = static_cast<std::uint8_t>(std::uint64_t(value) >> (8 * k));
    // Only a change is stored: listeners (publish, PDO events) hear changes.
    if (!v->holds({b, n})) v->try_set({b, n});
}

void Sim::publish() {
    if (t_publishing) return;
    t_publishing = true;
    // Computed under the lock, stored after it: a store runs the objects' listeners.
    std::int64_t er = 0, status = 0, errors = 0, position_now = 0, saved = 0, step = 0, absolute = 0;
    std::int64_t gpio = 0, direction = 0, word = 0;
    {
        std::lock_guard lock(m_);
        status = controller_status();
        errors = errors_;
        er = error_register_locked();
        position_now = position();
        gpio = gpio_value();
        saved = saved_position_;
        step = last_step_;
        absolute = last_abs_;
        direction = u(0x6011, 1) & 0x7F;  // B-P24: bits 7-10 are fixed inputs
        const auto ptr = static_cast<std::size_t>(u(0x6019, 1));
        word = ptr < ram_program_.size() ? ram_program_[ptr] : 0;
    }
    const Published& p = published_;
    set(p.error_register, er);
    set(p.manufacturer_status, errors * 256 + status);
    set(p.system_control, 0);
    set(p.error_status, errors);
    set(p.controller_status, status);
    set(p.motor_position, position_now);
    set(p.gpio_value, gpio);
    set(p.saved_position, saved);
    set(p.step_command, step);
    set(p.absolute_command, absolute);
    set(p.stop_command, 0);
    set(p.save_program, 0);
    set(p.run_instruction, 0);
    set(p.gpio_direction, direction);
    set(p.program_word, word);
    t_publishing = false;
}

// ---- power / reset ----------------------------------------------------------------

// The store file: one line per ROM object "rom IIII SS hexbytes", "program w w ...",
// "position n".  Unknown or malformed lines are skipped (a damaged file = factory values).
void Sim::write_store_locked() {
    if (opt_.store_path.empty()) return;
    std::ostringstream out;
    for (const auto& [k, bytes] : flash_) {
        char head[24];
        std::snprintf(head, sizeof head, "rom %04X %02X ", k.first, k.second);
        out << head;
        for (auto b : bytes) {
            char h[4];
            std::snprintf(h, sizeof h, "%02X", b);
            out << h;
        }
        out << "\n";
    }
    out << "program";
    for (auto w : flash_program_) out << " " << w;
    out << "\nposition " << saved_position_ << "\n";
    const std::string tmp = opt_.store_path + ".tmp";
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) return;  // [P] a store that cannot be written keeps the RAM state only
        f << out.str();
    }
    std::rename(tmp.c_str(), opt_.store_path.c_str());
}

void Sim::read_store() {
    if (opt_.store_path.empty()) return;
    std::ifstream f(opt_.store_path, std::ios::binary);
    if (!f) return;
    std::string line;
    while (std::getline(f, line) && line.size() < 4096) {
        std::istringstream in(line);
        std::string word;
        in >> word;
        if (word == "rom") {
            std::string idx, sub, hex;
            in >> idx >> sub >> hex;
            try {
                const auto i = static_cast<std::uint16_t>(std::stoul(idx, nullptr, 16));
                const auto s = static_cast<std::uint8_t>(std::stoul(sub, nullptr, 16));
                auto it = flash_.find({i, s});
                if (it == flash_.end() || hex.size() != 2 * it->second.size()) continue;
                Bytes b;
                for (std::size_t k = 0; k < hex.size(); k += 2)
                    b.push_back(static_cast<std::uint8_t>(std::stoul(hex.substr(k, 2), nullptr, 16)));
                if (od_->at(i, s)->check_size_for_write(b.size()) == 0) it->second = b;
            } catch (const std::exception&) {
            }
        } else if (word == "program") {
            std::vector<std::uint32_t> w;
            std::uint64_t v;
            while (w.size() < kMaxProgram && in >> v) w.push_back(static_cast<std::uint32_t>(v));
            flash_program_ = w;
        } else if (word == "position") {
            std::int64_t v = 0;
            if (in >> v) saved_position_ = static_cast<std::int32_t>(v);
        }
    }
}

void Sim::load_power_up(bool cold) {
    std::uint16_t old_outputs = 0;
    {
        std::lock_guard lock(m_);
        old_outputs = static_cast<std::uint16_t>(u(0x6011, 1) & 0x7F);
        if (!cold && u(0x602A) == 1) {  // B-P17: written to EEPROM at power loss
            saved_position_ = static_cast<std::int32_t>(position());
            write_store_locked();
        }
        motor_.halt();
        errors_ = 0;
        latched_ = 0;
        speed_mode_running_ = false;
        last_step_ = 0;
        last_abs_ = 0;
        jammed_ = false;
        motor_.set_jammed(false);
        for (auto& p : pending_) p.reset();
        running_ = paused_ = flag_ = false;
        pc_ = counter_ = 0;
        reset_en_ = pause_en_ = false;
        program_fault_ = false;
        bootloader_ = bootloader_pending_ = false;
        ram_program_ = flash_program_;
        emcy_queue_.clear();
        emcy_error_ = false;
        comm_errors_.clear();
    }
    t_publishing = true;  // values below are loaded, not "changed by the host"
    for (const auto& [r, var, flash] : power_up_) {
        if (flash && (r->index == 0x1016 || r->index == 0x1017) && r->sub != 0)
            var->remote_write(*flash);  // through the heartbeat service's hooks
        else if (flash && !var->holds(*flash))  // only a change is stored (and heard)
            var->try_set(*flash);
        else if (!flash && !var->holds(var->default_bytes()))
            var->reset_to_default();
    }
    t_publishing = false;
    {
        std::lock_guard lock(m_);
        baud_index_ = static_cast<std::uint8_t>(u(0x2003));
        cpr_ = static_cast<std::uint16_t>(u(0x6021));  // B-P40: takes effect at power-up
        // [P] the output latches start released (high, 6012h bit 0) at power-up: the pins
        // that were or now are outputs are no longer driven low by the device.
        levels_ = static_cast<std::uint16_t>(levels_ | old_outputs | (u(0x6011, 1) & 0x7F));
        motor_.set_pulse_position(u(0x602A) == 1 ? saved_position_ : 0);
        if (u(0x6018, 2) == 1 && u(0x6018, 1) > 0) {  // B-P41 auto-run
            running_ = true;
            pc_ = 0;
        }
    }
    std::shared_ptr<canopen::PdoService> pdo;
    {
        std::lock_guard lock(m_);
        pdo = pdo_;
    }
    apply_sync_cob_id(pdo);  // 1005h as loaded (reset node / power-up)
    publish();
}

void Sim::apply_sync_cob_id(const std::shared_ptr<canopen::PdoService>& pdo) {
    if (pdo) pdo->engine().set_sync_cob_id(static_cast<std::uint32_t>(u(0x1005)));
}

void Sim::power_cycle() {
    if (boot_.joinable() && boot_.get_id() != std::this_thread::get_id()) boot_.join();
    canopen::LocalNode* n;
    bool from_bootloader = false;
    {
        std::lock_guard lock(m_);
        n = node_.get();
        from_bootloader = !n && bus_ && bootloader_;
    }
    load_power_up(false);
    if (from_bootloader) {
        // B-P39: re-power leaves the bootloader: the application starts again (boot-up, PRE-OPERATIONAL).
        serve_again();
        schedule_node_id_switch();
        std::thread t;
        {
            std::lock_guard lock(m_);
            t = std::move(renode_);
        }
        if (t.joinable()) t.join();
    } else if (n) {
        // As NMT reset node would: boot-up, pre-operational, PDO engine reloaded.
        n->set_nmt_state(NmtState::Initialising);
        n->send_boot_up();
        n->set_nmt_state(NmtState::PreOperational);
        schedule_node_id_switch();
        std::thread t;
        {
            std::lock_guard lock(m_);
            t = std::move(renode_);
        }
        if (t.joinable()) t.join();
    }
}

void Sim::reset_to_new() {
    {
        std::lock_guard lock(m_);
        if (node_ || attaching_ || bus_)
            throw InvalidArgument("pmc007 sim " + std::to_string(node_id_.load()) + ": reset_to_new while attached");
        // What the constructor starts from; load_power_up(true) then sets the rest.
        for (const auto& [r, var, flash] : power_up_)
            if (flash) *flash = var->default_bytes();
        flash_program_.clear();
        ram_program_.clear();
        levels_ = 0x7FF;
        saved_position_ = 0;
        emcy_sent_ = 0;
        last_emcy_ = -1;
        emcy_queue_.clear();
        emcy_error_ = false;
        reset_target_ = 0;
        baud_index_ = 4;
        motor_.reset();
    }
    read_store();
    load_power_up(true);
}

void Sim::on_reset(canopen::NmtCommand c) {
    if (c == canopen::NmtCommand::ResetNode) {
        load_power_up(false);  // B-P28: "re-enter power-on reset process"
    } else {
        std::lock_guard lock(m_);
        baud_index_ = static_cast<std::uint8_t>(u(0x2003));  // B-P27: the RAM values take effect
    }
    schedule_node_id_switch();  // B-P36: node-ID from 2002h (RAM on reset comm, flash on reset node)
}

// ---- state --------------------------------------------------------------------------

std::uint8_t Sim::error_status() {
    std::lock_guard lock(m_);
    return errors_;
}

std::uint8_t Sim::controller_status() {
    std::lock_guard lock(m_);
    return static_cast<std::uint8_t>(latched_ | (motor_.moving() ? st::kBusy : 0));
}

std::int32_t Sim::position() {
    std::lock_guard lock(m_);
    return static_cast<std::int32_t>(std::llround(motor_.pulse_position()));
}

double Sim::velocity() {
    std::lock_guard lock(m_);
    return motor_.moving() ? motor_.pulse_velocity() : 0.0;
}

bool Sim::active() {
    std::lock_guard lock(m_);
    if (motor_.moving() || running_ || bootloader_pending_ || !emcy_queue_.empty()) return true;
    for (const auto& p : pending_)
        if (p) return true;
    return false;
}

bool Sim::busy() {
    std::lock_guard lock(m_);
    return motor_.moving();
}

bool Sim::enabled() { return u(0x600E) == 1; }

std::uint16_t Sim::gpio_value() {
    std::lock_guard lock(m_);
    return static_cast<std::uint16_t>(~levels_ & 0x7FF);  // B-P24: 1 = low level
}

std::vector<std::uint32_t> Sim::flash_program() {
    std::lock_guard lock(m_);
    return flash_program_;
}
std::vector<std::uint32_t> Sim::ram_program() {
    std::lock_guard lock(m_);
    return ram_program_;
}
bool Sim::program_running() {
    std::lock_guard lock(m_);
    return running_;
}
std::uint32_t Sim::program_pointer() {
    std::lock_guard lock(m_);
    return pc_;
}
std::uint32_t Sim::program_counter_value() {
    std::lock_guard lock(m_);
    return counter_;
}

// ---- time ---------------------------------------------------------------------------

void Sim::poll() {
    bool to_bootloader = false;
    canopen::LocalNode* n = nullptr;
    {
        std::lock_guard lock(m_);
        update_locked();
        flush_emcy_locked();
        if (bootloader_pending_) {
            bootloader_pending_ = false;
            bootloader_ = true;
            to_bootloader = true;
            n = node_.get();
        }
    }
    publish();
    // B-P39: in the bootloader the application is gone until a power cycle: no NMT
    // command brings it back (the node leaves the bus).
    if (to_bootloader && n) enter_bootloader();
}

void Sim::update_locked() {
    const Nanos now = clock_.now();
    // Debounced input edges in time order (B-P23): an edge counts once the level
    // has been stable for 601Ah ms.  The model advances at most one debounce time
    // at a time, so an edge found on the way (a switch the motor runs into) is
    // acted on at its own instant.
    const Nanos debounce = Nanos(u(0x601A)) * 1'000'000;
    for (int guard = 0; guard < 1'000'000; ++guard) {
        if (running_ && !paused_ && !motor_.moving()) run_program_locked(motor_.time());
        Nanos target = now;
        if (debounce > 0 && opt_.ext1_switch) target = std::min(target, motor_.time() + debounce);
        for (const auto& p : pending_)
            if (p) target = std::min(target, p->t + debounce);
        // A running program resumes at the instant a move ends (WAIT 1,0), not at the next poll.
        const bool stop_at_move_end = running_ && !paused_ && motor_.moving();
        if (stop_at_move_end) {
            const Nanos end = motor_.profile_start() + Nanos(motor_.profile().duration() * 1e9) + 1;
            target = std::min(target, std::max(end, motor_.time()));
        }
        if (target > motor_.time()) motor_.advance_to(target);
        if (stop_at_move_end && !motor_.moving()) run_program_locked(target);
        bool any = false;
        for (int b = 0; b < 11; ++b) {
            if (pending_[b] && pending_[b]->t + debounce <= target) {
                const Pending p = *pending_[b];
                pending_[b].reset();
                input_edge_locked(b, p.high, p.t + debounce);
                any = true;
            }
        }
        if (!any && target >= now) break;
    }
    motor_.update();
    run_program_locked(now);
}

void Sim::level_change_locked(int bit, bool high, Nanos t) {
    const bool was = (levels_ >> bit) & 1;
    if (was == high) return;
    levels_ = static_cast<std::uint16_t>(high ? levels_ | (1u << bit) : levels_ & ~(1u << bit));
    if (pending_[bit]) {
        pending_[bit].reset();  // back to the old level within the debounce time: a glitch
        return;
    }
    if (u(0x601A) == 0)
        input_edge_locked(bit, high, t);
    else
        pending_[bit] = Pending{t, high};
}

void Sim::set_input(int bit, bool high) {
    if (bit < 0 || bit > 10) throw InvalidArgument("pmc007 sim: input bit must be 0..10, not " + std::to_string(bit));
    {
        std::lock_guard lock(m_);
        update_locked();
        level_change_locked(bit, high, clock_.now());
        update_locked();
    }
    publish();
}

void Sim::input_edge_locked(int bit, bool high, Nanos t) {
    // External stops (B-P22): EXT1 = port 7 / enable bit 0, EXT2 = port 8 / bit 1, EXT3 = ENC1 = port 9 / bit 4.
    int sel = -1;
    std::uint8_t latch = 0;
    if (bit == port::kExt1) sel = 0, latch = st::kExt1;
    if (bit == port::kExt2) sel = 1, latch = st::kExt2;
    if (bit == port::kEnc1) sel = 4, latch = st::kExt3;
    if (sel >= 0) {
        const bool enabled = (u(0x600F, 1) >> sel) & 1;
        const bool rising_mode = (u(0x600F, 2) >> sel) & 1;
        if (enabled && high == rising_mode) {
            motor_.halt(t);
            speed_mode_running_ = false;
            latched_ |= latch;
            emcy_locked(0xFF01);
        }
    }
    // GPI1 / GPI2 low pulses for RESET_EN / PAUSE_EN (B-P45): the falling edge.
    if (bit == 0 && !high && reset_en_) {
        motor_.halt(t);
        pc_ = reset_target_;
        running_ = true;
        paused_ = false;
    }
    if (bit == 1 && !high && pause_en_) paused_ = !paused_;
}

void Sim::set_jammed(bool jammed) {
    {
        std::lock_guard lock(m_);
        update_locked();
        jammed_ = jammed;
        motor_.set_jammed(jammed);
        update_locked();
    }
    publish();
}

void Sim::inject_error(std::uint8_t bits) {
    {
        std::lock_guard lock(m_);
        update_locked();
        bits &= 0x3F;
        const std::uint8_t rising = bits & ~errors_;
        errors_ |= bits;
        if (rising) {
            stop_now_locked();  // [P] a power-stage error stops the motor
            if (rising & err::kUvlo) emcy_locked(0x3200);
            if (rising & (err::kAoc | err::kBoc)) emcy_locked(0x2300);
            if (rising & (err::kAerr | err::kBerr)) emcy_locked(0x5000);
            if (rising & err::kTsd) emcy_locked(0x4200);
        }
    }
    publish();
}

void Sim::on_motor_event(const motion::MotorEvent& e) {
    // Called from motor_.update() with m_ held.
    using K = motion::MotorEvent::Kind;
    if (e.kind == K::Stalled) {
        const auto cfg = u(0x6017);
        if ((cfg >> 8) != 0) {  // B-P21: detection configured (threshold bits 8-15)
            latched_ |= st::kStall;
            emcy_locked(0xFF00);
            if (u(0x601B) == 1) {
                motor_.halt(e.t);
                speed_mode_running_ = false;
            }
        }
    } else if (e.kind == K::HomeOn || e.kind == K::HomeOff) {  // the switch on EXT1 (active low)
        level_change_locked(port::kExt1, e.kind == K::HomeOff, e.t);
    }
}

std::uint8_t Sim::error_register_locked() const {
    // 1001h [CiA]: bit 0 generic, 1 current, 2 voltage, 3 temperature.
    std::uint8_t er = 0;
    if (errors_) er |= 0x01;
    if (errors_ & (err::kAoc | err::kBoc)) er |= 0x02;
    if (errors_ & err::kUvlo) er |= 0x04;
    if (errors_ & err::kTsd) er |= 0x08;
    if (!comm_errors_.empty()) er |= 0x11;  // communication error [CiA]
    return er;
}

void Sim::emcy_locked(std::uint16_t code) {
    // 1003h history, newest first [CiA]: which errors the PMC007 logs is not documented;
    // the sim logs what it signals by EMCY (not the 0000h "all clear").
    if (code != 0) {
        const auto n = std::min<std::int64_t>(u(0x1003, 0) + 1, 7);
        for (std::uint8_t k = static_cast<std::uint8_t>(n); k > 1; --k) set(0x1003, k, u(0x1003, k - 1));
        set(0x1003, 1, code);
        set(0x1003, 0, n);
        emcy_error_ = true;
    }
    if (!node_ || node_->nmt_state() == NmtState::Stopped || node_->nmt_state() == NmtState::Initialising) return;
    // The frame carries the state at the time of the event [CiA]: byte 2 = 1001h, bytes 3-4 = 6000h/6001h.
    const std::uint8_t status = static_cast<std::uint8_t>(latched_ | (motor_.moving() ? st::kBusy : 0));
    emcy_queue_.push_back(canopen::encode_emcy(node_id_.load(), code, error_register_locked(), {errors_, status, 0, 0, 0}));
    // [P] a burst beyond what any inhibit time makes sense for keeps the newest frames.
    while (emcy_queue_.size() > 32) emcy_queue_.pop_front();
    flush_emcy_locked();
}

void Sim::flush_emcy_locked() {
    // 1015h [CiA]: an EMCY inside the inhibit time is delayed until it has passed, not dropped.
    while (!emcy_queue_.empty()) {
        if (!node_ || node_->nmt_state() == NmtState::Stopped || node_->nmt_state() == NmtState::Initialising) {
            emcy_queue_.clear();
            return;
        }
        const Nanos now = monotonic_ns();
        const Nanos inhibit = Nanos(u(0x1015)) * 100'000;  // 100 us units
        if (last_emcy_ >= 0 && now - last_emcy_ < inhibit) return;  // the ticker comes back (active())
        last_emcy_ = now;
        const can::Frame f = emcy_queue_.front();
        emcy_queue_.pop_front();
        try {
            node_->send(f);
            ++emcy_sent_;
        } catch (const std::exception&) {
        }
    }
}

void Sim::comm_error(std::uint16_t code, bool active) {
    {
        std::lock_guard lock(m_);
        if (active) {
            comm_errors_.insert(code);
            emcy_locked(code);
        } else if (comm_errors_.erase(code)) {
            emcy_if_cleared_locked();
        }
    }
    publish();
}

void Sim::emcy_if_cleared_locked() {
    // B-P30 [P]: EMCY 0000h when every error is clear again (6000h, the 6001h latches and
    // the communication errors).
    if (emcy_error_ && errors_ == 0 && comm_errors_.empty() &&
        (latched_ & (st::kExt1 | st::kExt2 | st::kStall | st::kExt3)) == 0) {
        emcy_error_ = false;
        emcy_locked(0x0000);
    }
}

// ---- motion ------------------------------------------------------------------------

bool Sim::refused_locked() const {
    // B-P08, B-P19, B-P20.
    return errors_ != 0 || (latched_ & (st::kExt1 | st::kExt2 | st::kStall | st::kExt3)) != 0 || u(0x600E) != 1;
}

ProfileParams Sim::params_locked(double speed) const {
    ProfileParams p;
    p.speed = speed;
    p.start_speed = double(u(0x6006));
    p.stop_speed = double(u(0x6007));
    p.accel_gear = int(u(0x6008));
    p.decel_gear = int(u(0x6009));
    p.microstepping = int(u(0x600A));
    return p;
}

std::uint32_t Sim::start_move_locked(std::int64_t delta) {
    if (delta == 0) return 0;
    double speed = std::fabs(double(u(0x6003)));
    if (speed <= 0) speed = double(u(0x6006));  // [P] no run speed set: the start speed
    if (speed <= 0) return 0;                   // [P] nothing to move with: accepted, no motion
    const motion::State s{motor_.pulse_position(), motor_.moving() ? motor_.pulse_velocity() : 0.0, 0, 0};
    motor_.command(position_profile(s, s.p + double(delta), params_locked(speed)));
    return 0;
}

void Sim::stop_now_locked() {
    motor_.halt();
    speed_mode_running_ = false;
}

std::uint32_t Sim::on_write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> d) {
    std::lock_guard lock(m_);
    update_locked();
    const auto* row = od_row(index, sub);
    const std::int64_t v = decode_le(d, row && row->type == canopen::DataType::Integer32);
    switch (index) {
        case 0x1003:
            if (v != 0) return kAbortValueRange;  // only 0 clears the history [CiA]
            for (std::uint8_t s = 1; s <= 7; ++s) od_->at(0x1003, s)->reset_to_default();
            return 0;
        case 0x2007:
            if (v == 1) {
                bootloader_pending_ = true;
            } else if (v == 2) {  // B-P37: every ROM object to flash
                for (const auto& r : od_rows())
                    if (r.storage == Storage::Rom) flash_[{r.index, r.sub}] = od_->at(r.index, r.sub)->get();
                write_store_locked();
            } else if (v == 3) {  // B-P38 / C-P19: factory values into the working copy only
                factory_reset_locked();
            } else {
                return kAbortValueRange;
            }
            return 0;
        case 0x1005:
            // COB-ID SYNC [CiA]: the PMC007 consumes SYNC (bit 30 "generates" = 0) on an
            // 11-bit id (standard frames only, 003 §4.2; bit 29 = 0).
            if ((v & 0x40000000) || (v & 0x20000000) || (v & 0x1FFFF800)) return kAbortValueRange;
            if (pdo_) pdo_->engine().set_sync_cob_id(static_cast<std::uint32_t>(v));
            return 0;
        case 0x6000:  // write 1 to clear
            errors_ &= static_cast<std::uint8_t>(~v);
            emcy_if_cleared_locked();
            return 0;
        case 0x6001:  // write 1 clears bits 0-2 (and the EXT3 latch); busy cannot be cleared
            latched_ &= static_cast<std::uint8_t>(~(v & (st::kExt1 | st::kExt2 | st::kStall | st::kExt3)));
            emcy_if_cleared_locked();
            return 0;
        case 0x6003: {  // B-P10: the sign sets the direction
            // A refused speed-mode write changes nothing, not even the direction.
            if (u(0x6005) == 1 && v != 0 && refused_locked()) return kAbortDeviceState;
            if (v > 0) od_->at(0x6002, 0)->try_set(Bytes{1});
            if (v < 0) od_->at(0x6002, 0)->try_set(Bytes{0});
            if (u(0x6005) == 1) {  // B-P12 speed mode: run at the new speed
                const motion::State s{motor_.pulse_position(), motor_.moving() ? motor_.pulse_velocity() : 0.0, 0, 0};
                const double speed = double(v);
                motor_.command(speed_profile(s, speed, params_locked(std::max(1.0, std::fabs(speed))),
                                                    speed == 0 ? 0.0 : 1e6));
                speed_mode_running_ = v != 0;
            }
            return 0;
        }
        case 0x6004: {
            if (refused_locked()) return kAbortDeviceState;          // B-P08 / B-P20
            if (motor_.moving() || u(0x6005) == 1) return 0;         // B-P07: ignored, acknowledged
            last_step_ = static_cast<std::uint32_t>(v);
            const std::int64_t n = static_cast<std::int64_t>(static_cast<std::uint32_t>(v));
            return start_move_locked(u(0x6002) == 1 ? n : -n);       // C-P01: 1 counts up
        }
        case 0x601C: {
            if (refused_locked()) return kAbortDeviceState;
            if (motor_.moving() || u(0x6005) == 1) return 0;
            last_abs_ = static_cast<std::int32_t>(v);
            return start_move_locked(v - position());                // B-P18
        }
        case 0x6005:
            if (v == 0 && u(0x6005) == 1 && motor_.moving()) {      // speed -> position: decelerate
                const motion::State s{motor_.pulse_position(), motor_.pulse_velocity(), 0, 0};
                motor_.command(speed_profile(s, 0.0, params_locked(std::max(1.0, std::fabs(s.v))), 0.0));
                speed_mode_running_ = false;
            }
            if (v == 1 && u(0x6005) == 0) {  // position -> speed: run at the current 6003h (B-P12)
                const double speed = double(u(0x6003));
                if (speed != 0) {
                    if (refused_locked()) return kAbortDeviceState;  // B-P20: as a 6003h write would be
                    const motion::State s{motor_.pulse_position(), motor_.moving() ? motor_.pulse_velocity() : 0.0, 0, 0};
                    motor_.command(speed_profile(s, speed, params_locked(std::fabs(speed)), 1e6));
                    speed_mode_running_ = true;
                }
            }
            return 0;
        case 0x600A: return valid_microstepping(v) ? 0 : kAbortValueRange;
        case 0x600C: motor_.set_pulse_position(double(v)); return 0;
        case 0x600E:
            if (v == 0) stop_now_locked();  // B-P20: released at once
            return 0;
        case 0x6012: {  // outputs only; 1 = drive low
            const auto dir = static_cast<std::uint16_t>(u(0x6011, 1) & 0x7F);
            levels_ = static_cast<std::uint16_t>((levels_ & ~dir) | (~v & dir));
            return 0;
        }
        case 0x6017: return (v & 1) ? kAbortValueRange : 0;
        case 0x6018:
            if (sub == 2) {  // [P] "offline exec": run now (and at power-up once saved)
                running_ = v == 1;
                pc_ = 0;
                paused_ = false;
                program_fault_ = false;
                run_program_locked(clock_.now());
            }
            return 0;
        case 0x6019:
            if (sub == 2) {
                const auto ptr = static_cast<std::size_t>(u(0x6019, 1));
                // [P] the pointer may read 100 (6019h:01 is 0-100), one past the 100 instructions:
                // there is no instruction there to write.
                if (ptr >= kMaxProgram) return kAbortDeviceState;
                if (ram_program_.size() <= ptr) ram_program_.resize(ptr + 1, 0);
                ram_program_[ptr] = static_cast<std::uint32_t>(v);
            } else if (sub == 3 && v == 1) {
                flash_program_ = ram_program_;
                write_store_locked();
            } else if (sub == 5 && v == 1) {
                const auto ptr = static_cast<std::size_t>(u(0x6019, 1));
                if (ptr < ram_program_.size()) exec_locked(ram_program_[ptr], true);
            }
            return 0;
        case 0x6020:  // B-P14; [P] the value must be 0 (06090030 otherwise)
            if (v != 0) return kAbortValueRange;
            stop_now_locked();
            return 0;
        case 0x6021:  // B-P40: one of the documented CPRs; in use from the next power-up
            return (v == 400 || v == 500 || v == 600 || v == 800 || v == 1000 || v == 1200 || v == 1600)
                       ? 0
                       : kAbortValueRange;
        default: return 0;
    }
}

void Sim::factory_reset_locked() {
    // Every ROM object to its factory value in the working copy (C-P19: flash untouched).
    // The objects a service owns take it through that service: the heartbeat producer and
    // consumers through their write hooks, the PDO parameters by rebuilding the engine
    // from the dictionary (a zero mapping word is no value the engine's hooks accept).
    for (const auto& r : od_rows()) {
        if (r.storage != Storage::Rom) continue;
        auto var = od_->at(r.index, r.sub);
        if ((r.index == 0x1016 || r.index == 0x1017) && canopen::writable(r.access))
            var->remote_write(var->default_bytes());
        else
            var->reset_to_default();
    }
    if (pdo_) pdo_->reload_from_dictionary();
    apply_sync_cob_id(pdo_);
}

// ---- offline program --------------------------------------------------------------

void Sim::run_program_locked(Nanos) {
    for (int guard = 0; guard < 1000 && running_ && !paused_; ++guard) {
        const auto count = static_cast<std::uint32_t>(u(0x6018, 1));
        if (pc_ >= count || pc_ >= ram_program_.size()) {
            running_ = false;
            return;
        }
        if (!exec_locked(ram_program_[pc_], false)) return;  // WAIT blocks
    }
}

bool Sim::exec_locked(std::uint32_t word, bool single) {
    auto ins = decode(word);
    if (!ins) {  // [P] unknown opcode: the program faults, pointer unchanged
        running_ = false;
        program_fault_ = true;
        return false;
    }
    const auto data = ins->data;
    std::uint32_t next = pc_ + 1;
    switch (ins->op) {
        case Opcode::ROT:  // B-P43: like 6004h, does not wait
            if (!refused_locked() && !motor_.moving()) {
                last_step_ = data;
                start_move_locked(u(0x6002) == 1 ? std::int64_t(data) : -std::int64_t(data));
            }
            break;
        case Opcode::MIC:
            if (valid_microstepping(data)) od_->at(0x600A, 0)->try_set(Bytes{std::uint8_t(data), std::uint8_t(data >> 8)});
            break;
        case Opcode::DIR: od_->at(0x6002, 0)->try_set(Bytes{std::uint8_t(data & 1)}); break;
        case Opcode::EXTEN: {
            const auto e = (u(0x600F, 1) & ~0x03) | (data ? 0x03 : 0);
            od_->at(0x600F, 1)->try_set(Bytes{std::uint8_t(e)});
            break;
        }
        case Opcode::FREE: od_->at(0x6005, 0)->try_set(Bytes{std::uint8_t(data & 1)}); break;
        case Opcode::CLR2: latched_ &= ~st::kExt2; emcy_if_cleared_locked(); break;
        case Opcode::CLR1: latched_ &= ~st::kExt1; emcy_if_cleared_locked(); break;
        case Opcode::VSET: {  // C-P13: abs(6003h) := data, the sign (direction) kept
            const std::int64_t sp = u(0x6002) == 1 ? std::int64_t(data) : -std::int64_t(data);
            Bytes b(4);
            for (int k = 0; k < 4; ++k) b[k] = std::uint8_t(std::uint64_t(sp) >> (8 * k));
            od_->at(0x6003, 0)->try_set(b);
            break;
        }
        case Opcode::ACC: od_->at(0x6008, 0)->try_set(Bytes{std::uint8_t(std::min<std::uint32_t>(data, 8))}); break;
        case Opcode::TRIG: {
            const auto e = (u(0x600F, 2) & ~0x03) | (data & 0x03);
            od_->at(0x600F, 2)->try_set(Bytes{std::uint8_t(e)});
            break;
        }
        case Opcode::CNTI: ++counter_; break;
        case Opcode::CNTC: counter_ = 0; break;
        case Opcode::JMP: next = data; break;
        case Opcode::JNE: if (!flag_) next = data; break;   // C-P09
        case Opcode::JEQ: if (flag_) next = data; break;
        case Opcode::WAIT: {
            // [P] option 1 = "motor busy": WAIT 1,0 waits for the end of the move; others are reserved.
            if (ins->option == 1 && !single) {
                const bool b = motor_.moving();
                if (b != (data != 0)) return false;
            }
            break;
        }
        case Opcode::OUT: {  // B-P46: GPO1..5 = ports 0..4; data is the 6012h bit (1 = low)
            const int bit = ins->option - 1;
            if (bit >= 0 && bit < 5) {
                levels_ = static_cast<std::uint16_t>(data ? levels_ & ~(1u << bit) : levels_ | (1u << bit));
            }
            break;
        }
        case Opcode::CMP: {
            // [P] option 1 internal counter, 2 all inputs as a bus value (6012h), 3 ext-stop latches
            // (6001h bits 0-1), 4..9 one input port (GPIO1..6 bit, 1 = low).
            std::uint32_t sel = 0;
            const auto g = static_cast<std::uint32_t>(~levels_ & 0x7FF);
            if (ins->option == 1) sel = counter_;
            else if (ins->option == 2) sel = g;
            else if (ins->option == 3) sel = latched_ & 0x03;
            else if (ins->option >= 4 && ins->option <= 9) sel = (g >> (ins->option - 4)) & 1;
            flag_ = sel == data;
            break;
        }
        case Opcode::RESET_EN: reset_en_ = ins->option != 0; reset_target_ = data; break;
        case Opcode::PAUSE_EN: pause_en_ = ins->option != 0; break;
    }
    if (!single) pc_ = next;
    return true;
}

}  // namespace motorbus::pmc007

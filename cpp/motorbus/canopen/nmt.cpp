#include "motorbus/runtime/interrupt.hpp"
#include "motorbus/canopen/nmt.hpp"

#include <cctype>

#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

const char* to_string(NmtCommand c) {
    switch (c) {
        case NmtCommand::Start: return "start";
        case NmtCommand::Stop: return "stop";
        case NmtCommand::EnterPreOperational: return "enter-pre-operational";
        case NmtCommand::ResetNode: return "reset-node";
        case NmtCommand::ResetCommunication: return "reset-communication";
    }
    return "unknown";
}

bool is_known_nmt_command(std::uint8_t cs) {
    return cs == 0x01 || cs == 0x02 || cs == 0x80 || cs == 0x81 || cs == 0x82;
}

std::optional<NmtCommand> nmt_command_for_state(std::string_view name) {
    // RESET COMMUNICATION would squash into a state-like word; compare with
    // the separators removed, as nmt_state_from_name does.
    std::string u;
    for (char c : name)
        if (c != '-' && c != '_' && c != ' ') u.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (u == "RESET" || u == "RESETNODE") return NmtCommand::ResetNode;
    if (u == "RESETCOMMUNICATION") return NmtCommand::ResetCommunication;
    auto s = nmt_state_from_name(name);
    if (!s) return std::nullopt;
    switch (*s) {
        case NmtState::Operational: return NmtCommand::Start;
        case NmtState::Stopped: return NmtCommand::Stop;
        case NmtState::PreOperational: return NmtCommand::EnterPreOperational;
        case NmtState::Initialising: return std::nullopt;  // reached by a reset, not commanded
    }
    return std::nullopt;
}

std::optional<NodeState> node_state_from_name(std::string_view name) {
    if (auto s = nmt_state_from_name(name)) return to_node_state(*s);
    std::string u;
    for (char c : name) u.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (u == "UNKNOWN") return NodeState::Unknown;
    return std::nullopt;
}

const char* to_string(NodeState s) {
    switch (s) {
        case NodeState::Initialising: return "INITIALISING";
        case NodeState::Stopped: return "STOPPED";
        case NodeState::Operational: return "OPERATIONAL";
        case NodeState::PreOperational: return "PRE-OPERATIONAL";
        case NodeState::Unknown: return "UNKNOWN";
    }
    return "UNKNOWN";
}

NodeState node_state_from_byte(std::uint8_t b) {
    switch (b) {
        case 0x00: return NodeState::Initialising;
        case 0x04: return NodeState::Stopped;
        case 0x05: return NodeState::Operational;
        case 0x7F: return NodeState::PreOperational;
        default: return NodeState::Unknown;
    }
}

can::Frame encode_nmt(NmtCommand command, std::uint8_t node_id) {
    if (node_id > kMaxNodeId)
        throw InvalidArgument("NMT node id " + std::to_string(node_id) +
                              " is outside 0-127 (0 = broadcast)");
    can::Frame f;
    f.id = kNmtCobId;
    f.len = 2;
    f.data[0] = static_cast<std::uint8_t>(command);
    f.data[1] = node_id;
    return f;
}

std::optional<NmtMessage> decode_nmt(const can::Frame& f) {
    if (f.id != kNmtCobId || f.extended || f.rtr || f.len != 2) return std::nullopt;  // N1
    if (f.data[1] > kMaxNodeId) return std::nullopt;                                   // N2
    if (!is_known_nmt_command(f.data[0])) return std::nullopt;                        // N4
    return NmtMessage{static_cast<NmtCommand>(f.data[0]), f.data[1]};
}

// ---- NmtSlave ---------------------------------------------------------------

NmtSlave::NmtSlave(std::uint8_t node_id) : node_id_(node_id) {
    if (node_id == 0 || node_id > kMaxNodeId)
        throw InvalidArgument("node id " + std::to_string(node_id) + " is outside 1-127");
}

void NmtSlave::set(NodeState s) {
    NodeState old = state_;
    state_ = s;
    if (old != s && on_state_change) on_state_change(old, s);
}

std::optional<NmtCommand> NmtSlave::on_frame(const can::Frame& f) {
    auto m = decode_nmt(f);
    if (!m || (m->node_id != 0 && m->node_id != node_id_)) {  // N3: 0 applies to all
        ++ignored_;
        return std::nullopt;
    }
    switch (m->command) {
        case NmtCommand::Start: set(NodeState::Operational); break;
        case NmtCommand::Stop: set(NodeState::Stopped); break;
        case NmtCommand::EnterPreOperational: set(NodeState::PreOperational); break;
        case NmtCommand::ResetNode:
        case NmtCommand::ResetCommunication:
            set(NodeState::Initialising);
            if (on_reset) on_reset(m->command);
            break;
    }
    return m->command;
}

// ---- NmtMaster --------------------------------------------------------------

NmtMaster::NmtMaster(can::Bus& bus, std::optional<std::uint8_t> own_node_id)
    : bus_(bus), own_(own_node_id) {
    if (own_ && (*own_ == 0 || *own_ > kMaxNodeId))
        throw InvalidArgument("master node id " + std::to_string(*own_) + " is outside 1-127");
    raw_.fill(-1);
    hb_sub_ = bus_.subscribe(can::Filter{kHeartbeatBase, 0x780, false, true},
                             [this](const can::Frame& f) { on_heartbeat(f); });
    if (own_) {
        nmt_sub_ = bus_.subscribe_id(kNmtCobId, false, [this](const can::Frame& f) {
            // N5: a master obeys nobody; count commands aimed at it.
            if (auto m = decode_nmt(f); m && (m->node_id == 0 || m->node_id == *own_))
                foreign_ignored_.fetch_add(1);
        });
    }
}

NmtMaster::~NmtMaster() {
    bus_.unsubscribe(hb_sub_);
    if (nmt_sub_) bus_.unsubscribe(nmt_sub_);
}

void NmtMaster::send(NmtCommand c, std::uint8_t node_id) { bus_.send(encode_nmt(c, node_id)); }

void NmtMaster::on_heartbeat(const can::Frame& f) {
    auto hb = decode_heartbeat(f);
    if (!hb) return;
    NodeState old, now;
    bool changed;
    {
        std::lock_guard l(mutex_);
        std::int16_t prev = raw_[hb->node_id];
        old = prev < 0 ? NodeState::Unknown : node_state_from_byte(static_cast<std::uint8_t>(prev));
        raw_[hb->node_id] = hb->raw_state;
        if (hb->is_boot_up()) ++boots_[hb->node_id];
        ++heard_[hb->node_id];
        now = hb->state;
        changed = prev != hb->raw_state || hb->is_boot_up();
    }
    // Every heartbeat wakes wait_for_heartbeat(); the callback is for changes.
    cv_.notify_all();
    if (!changed) return;
    if (on_state_change) on_state_change(hb->node_id, old, now);
}

NodeState NmtMaster::state(std::uint8_t node) const {
    if (node == 0 || node > kMaxNodeId) return NodeState::Unknown;
    std::lock_guard l(mutex_);
    return raw_[node] < 0 ? NodeState::Unknown : node_state_from_byte(static_cast<std::uint8_t>(raw_[node]));
}

std::optional<std::uint8_t> NmtMaster::raw_state(std::uint8_t node) const {
    if (node == 0 || node > kMaxNodeId) return std::nullopt;
    std::lock_guard l(mutex_);
    if (raw_[node] < 0) return std::nullopt;
    return static_cast<std::uint8_t>(raw_[node]);
}

bool NmtMaster::wait_for_state(std::uint8_t node, NodeState want, std::chrono::nanoseconds timeout) {
    if (node == 0 || node > kMaxNodeId) throw InvalidArgument("node id must be 1-127");
    std::unique_lock l(mutex_);
    return interruptible_wait_for(cv_, l, timeout, [&] {
        return raw_[node] >= 0 && node_state_from_byte(static_cast<std::uint8_t>(raw_[node])) == want;
    });
}

bool NmtMaster::wait_for_boot(std::uint8_t node, std::chrono::nanoseconds timeout) {
    if (node == 0 || node > kMaxNodeId) throw InvalidArgument("node id must be 1-127");
    std::unique_lock l(mutex_);
    const auto start = boots_[node];
    return interruptible_wait_for(cv_, l, timeout, [&] { return boots_[node] != start; });
}

std::optional<NodeState> NmtMaster::wait_for_heartbeat(std::uint8_t node, std::chrono::nanoseconds timeout) {
    if (node == 0 || node > kMaxNodeId) throw InvalidArgument("node id must be 1-127");
    std::unique_lock l(mutex_);
    const auto start = heard_[node];
    if (!interruptible_wait_for(cv_, l, timeout, [&] { return heard_[node] != start; })) return std::nullopt;
    return node_state_from_byte(static_cast<std::uint8_t>(raw_[node]));
}

NmtEventWait::NmtEventWait(std::shared_ptr<can::Bus> bus, std::uint8_t node, Want want, NodeState state,
                           std::shared_ptr<Completions> done, std::uint64_t token)
    : bus_(std::move(bus)), node_(node), want_(want), state_(state), done_(std::move(done)), token_(token) {
    if (!bus_) throw InvalidArgument("NmtEventWait: no bus");
    if (!done_) throw InvalidArgument("NmtEventWait: no Completions to complete on");
    if (node == 0 || node > kMaxNodeId) throw InvalidArgument("node id must be 1-127");
}

std::shared_ptr<NmtEventWait> NmtEventWait::start(std::shared_ptr<can::Bus> bus, std::uint8_t node, Want want,
                                                  NodeState state, std::shared_ptr<Completions> done,
                                                  std::uint64_t token) {
    auto w = std::make_shared<NmtEventWait>(std::move(bus), node, want, state, std::move(done), token);
    std::weak_ptr<NmtEventWait> self = w;
    w->sub_ = w->bus_->subscribe_id(kHeartbeatBase + w->node_, false, [self](const can::Frame& f) {
        if (auto s = self.lock()) s->on_frame(f);
    });
    return w;
}

void NmtEventWait::cancel() {
    can::SubscriptionId sub = sub_.exchange(0);
    if (sub) bus_->unsubscribe(sub);
}

NmtEventWait::~NmtEventWait() { cancel(); }

void NmtEventWait::on_frame(const can::Frame& f) {
    auto hb = decode_heartbeat(f);
    if (!hb) return;
    const bool match = want_ == Want::AnyHeartbeat || (want_ == Want::BootUp ? hb->is_boot_up() : hb->state == state_);
    if (!match || fired_.exchange(true)) return;
    done_->push(token_, std::string(to_string(hb->state)));
}

}  // namespace motorbus::canopen

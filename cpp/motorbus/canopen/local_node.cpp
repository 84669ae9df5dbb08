#include "motorbus/canopen/local_node.hpp"

#include <set>
#include <algorithm>
#include <cctype>
#include <cstring>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

const char* to_string(NmtState s) {
    switch (s) {
        case NmtState::Initialising: return "INITIALISING";
        case NmtState::Stopped: return "STOPPED";
        case NmtState::Operational: return "OPERATIONAL";
        case NmtState::PreOperational: return "PRE-OPERATIONAL";
    }
    return "UNKNOWN";
}

namespace {
// Upper case without the separators people use interchangeably.
std::string squash(std::string_view s) {
    std::string u;
    for (char c : s)
        if (c != '-' && c != '_' && c != ' ') u.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    return u;
}
}  // namespace

std::optional<NmtState> nmt_state_from_name(std::string_view name) {
    const std::string u = squash(name);
    if (u == "OPERATIONAL") return NmtState::Operational;
    if (u == "STOPPED") return NmtState::Stopped;
    if (u == "PREOPERATIONAL") return NmtState::PreOperational;
    if (u == "INITIALISING" || u == "INITIALIZING") return NmtState::Initialising;
    return std::nullopt;
}

namespace {
// (medium, node-ID) pairs served by a LocalNode in this process: two nodes
// with one ID on one bus (or on two endpoints of one virtual hub) would both
// answer every SDO request and NMT command.
std::mutex g_claims_mutex;
std::set<std::pair<const void*, std::uint8_t>> g_claims;
}  // namespace

void LocalNode::claim_node_id(can::Bus& bus, std::uint8_t node_id) {
    std::lock_guard lock(g_claims_mutex);
    if (!g_claims.emplace(bus.medium(), node_id).second)
        throw NodeIdTaken("LocalNode node_id: " + std::to_string(node_id) + " is already served on " +
                              bus.channel() + " (one LocalNode per node-ID per bus; close the other first)");
}

void LocalNode::release_node_id(can::Bus& bus, std::uint8_t node_id) {
    std::lock_guard lock(g_claims_mutex);
    g_claims.erase({bus.medium(), node_id});
}

LocalNode::LocalNode(can::Bus& bus, std::uint8_t node_id, std::shared_ptr<ObjectDictionary> od,
                     LocalNodeOptions options)
    : bus_(bus),
      node_id_(node_id),
      od_(od ? std::move(od) : throw InvalidArgument("LocalNode: an object dictionary is required")),
      options_(options),
      server_(*od_, options.sdo) {
    if (node_id == 0 || node_id > 127)  // N14
        throw InvalidArgument("LocalNode node_id: " + std::to_string(node_id) + ", must be 1-127");
    claim_node_id(bus_, node_id);  // one LocalNode per node-ID per medium
    try {
        if (od_->node_id() == 0) od_->set_node_id(node_id);
        subs_.push_back(bus_.subscribe_id(0x000, false, [this](const can::Frame& f) { on_nmt_frame(f); }));
        if (options_.serve_sdo)
            subs_.push_back(bus_.subscribe_id(sdo::kDefaultRequestBase + node_id, false,
                                              [this](const can::Frame& f) { on_sdo_frame(f); }));
    } catch (...) {
        for (auto s : subs_) bus_.unsubscribe(s);
        release_node_id(bus_, node_id);
        throw;
    }
    thread_ = std::thread([this] { worker(); });
    if (options_.send_boot_up) send_boot_up();
    transition(NmtState::PreOperational);
}

LocalNode::~LocalNode() { close(); }

void LocalNode::close() {
    if (closed_.exchange(true)) return;
    for (auto s : subs_) bus_.unsubscribe(s);
    release_node_id(bus_, node_id_);
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    std::vector<ServiceSlot> services;
    {
        std::lock_guard lock(mutex_);
        services.swap(services_);
    }
    for (auto& s : services) s.service->on_detach(*this);
}

void LocalNode::send(const can::Frame& frame) { bus_.send(frame); }

void LocalNode::send_boot_up() {
    const std::uint8_t zero = 0;
    try {
        bus_.send(can::Frame::make(0x700u + node_id_, std::span(&zero, 1)));
    } catch (const Error&) {
        // A closed or saturated bus must not stop the node from coming up.
    }
}

std::uint64_t LocalNode::add_state_listener(std::function<void(NmtState, NmtState)> cb) {
    std::lock_guard lock(mutex_);
    listeners_.emplace_back(next_listener_, std::move(cb));
    return next_listener_++;
}

void LocalNode::remove_state_listener(std::uint64_t handle) {
    std::lock_guard lock(mutex_);
    std::erase_if(listeners_, [&](auto& p) { return p.first == handle; });
}

void LocalNode::add_service(std::shared_ptr<NodeService> service) {
    if (!service) throw InvalidArgument("add_service: null service");
    {
        std::lock_guard lock(mutex_);
        services_.push_back({std::move(service), 0});
        woken_ = true;
    }
    cv_.notify_all();
}

void LocalNode::remove_service(const std::shared_ptr<NodeService>& service) {
    bool found = false;
    {
        std::lock_guard lock(mutex_);
        auto it = std::find_if(services_.begin(), services_.end(),
                               [&](auto& s) { return s.service == service; });
        if (it != services_.end()) {
            services_.erase(it);
            found = true;
        }
    }
    if (found) service->on_detach(*this);
}

void LocalNode::wake() {
    {
        std::lock_guard lock(mutex_);
        woken_ = true;
        for (auto& s : services_) s.deadline = 0;
    }
    cv_.notify_all();
}

void LocalNode::set_nmt_state(NmtState s) { transition(s); }

void LocalNode::transition(NmtState s) {
    std::lock_guard serial(transition_mutex_);
    const NmtState previous = state_.exchange(s);
    if (previous == s) return;
    if (s == NmtState::Stopped || s == NmtState::Initialising) {
        std::lock_guard lock(sdo_mutex_);
        server_.reset();  // SDO is not available while stopped (S17)
    }
    std::vector<std::function<void(NmtState, NmtState)>> ls;
    std::vector<std::shared_ptr<NodeService>> svcs;
    {
        std::lock_guard lock(mutex_);
        for (auto& [h, cb] : listeners_) ls.push_back(cb);
        for (auto& slot : services_) svcs.push_back(slot.service);
    }
    for (auto& svc : svcs) svc->on_nmt_state(*this, previous, s);
    for (auto& cb : ls) cb(previous, s);
}

void LocalNode::apply_nmt(NmtCommand c) {
    switch (c) {
        case NmtCommand::Start: return transition(NmtState::Operational);
        case NmtCommand::Stop: return transition(NmtState::Stopped);
        case NmtCommand::EnterPreOperational: return transition(NmtState::PreOperational);
        case NmtCommand::ResetNode:
        case NmtCommand::ResetCommunication: {
            transition(NmtState::Initialising);
            if (options_.reset_restores_defaults) {
                const std::uint16_t lo = c == NmtCommand::ResetNode ? 0x1000 : 0x1000;
                const std::uint16_t hi = c == NmtCommand::ResetNode ? 0x9FFF : 0x1FFF;
                for (auto idx : od_->indices()) {
                    if (idx < lo || idx > hi) continue;
                    if (auto obj = od_->object(idx))
                        for (auto& [sub, var] : obj->subs) var->reset_to_default();
                }
            }
            if (options_.on_reset) options_.on_reset(c);
            if (options_.send_boot_up) send_boot_up();
            return transition(NmtState::PreOperational);
        }
    }
}

void LocalNode::on_nmt_frame(const can::Frame& f) {
    if (f.rtr || f.len != 2 || (f.flags & can::kFlagLoopback)) {  // N1
        std::lock_guard lock(mutex_);
        ++nmt_ignored_;
        return;
    }
    const std::uint8_t cs = f.data[0], target = f.data[1];
    const bool known = cs == 0x01 || cs == 0x02 || cs == 0x80 || cs == 0x81 || cs == 0x82;
    if ((target != 0 && target != node_id_) || !known) {  // N2, N4 (N3: 0 = everyone)
        std::lock_guard lock(mutex_);
        ++nmt_ignored_;
        return;
    }
    {
        std::lock_guard lock(mutex_);
        ++nmt_commands_;
    }
    apply_nmt(static_cast<NmtCommand>(cs));
}

void LocalNode::send_sdo(const SdoServerMachine::Outbox& out) {
    for (const auto& p : out) {
        can::Frame f;
        f.id = sdo::kDefaultResponseBase + node_id_;
        f.len = 8;
        std::memcpy(f.data.data(), p.data(), 8);
        try {
            bus_.send(f);
        } catch (const Error&) {
            // Bus full or closed: the client will time out, as it would on a real bus.
        }
    }
}

void LocalNode::on_sdo_frame(const can::Frame& f) {
    if (f.rtr || (f.flags & (can::kFlagLoopback | can::kFlagError))) return;
    if (state_.load() == NmtState::Stopped || state_.load() == NmtState::Initialising) {  // S17
        std::lock_guard lock(mutex_);
        ++sdo_stopped_;
        return;
    }
    if (options_.sdo_require_dlc8 && f.len != 8) {
        std::lock_guard lock(mutex_);
        ++sdo_bad_dlc_;
        return;
    }
    {
        std::lock_guard lock(sdo_mutex_);
        if (options_.sdo_inline || server_.handles_inline(f.payload())) {
            // Mid-transfer frames are cheap and come back to back (block
            // sub-blocks), and a silent frame is followed at once by the next
            // request: a mailbox would add latency or drop them.
            sdo_out_.clear();
            server_.on_request(f.payload(), monotonic_ns(), sdo_out_);
            send_sdo(sdo_out_);
            return;
        }
    }
    {
        std::lock_guard lock(mutex_);
        if (mailbox_) {  // S18: single slot; the flood is dropped and counted
            ++dropped_;
            return;
        }
        mailbox_ = f;
    }
    cv_.notify_all();
}

void LocalNode::worker() {
    std::unique_lock lock(mutex_);
    while (!stopping_) {
        // The SDO server's deadline is read without mutex_ held: sdo_mutex_ is
        // never taken inside mutex_, so a write hook running under sdo_mutex_
        // (a PDO parameter written by SDO) may call wake(), which takes mutex_.
        lock.unlock();
        Nanos next = kNoDeadline;
        {
            std::lock_guard sl(sdo_mutex_);
            next = server_.next_deadline();
        }
        lock.lock();
        if (stopping_) break;
        for (auto& s : services_) next = std::min(next, s.deadline);
        auto ready = [&] { return stopping_ || mailbox_ || woken_; };
        if (next == kNoDeadline)
            cv_.wait(lock, ready);
        else
            cv_.wait_until(lock, std::chrono::steady_clock::time_point(std::chrono::nanoseconds(next)),
                           ready);
        if (stopping_) break;
        woken_ = false;
        std::optional<can::Frame> frame;
        frame.swap(mailbox_);
        lock.unlock();

        const Nanos now = monotonic_ns();
        {
            std::lock_guard sl(sdo_mutex_);
            sdo_out_.clear();
            if (frame && state_.load() != NmtState::Stopped)
                server_.on_request(frame->payload(), now, sdo_out_);
            if (now >= server_.next_deadline()) server_.on_timer(now, sdo_out_);
            send_sdo(sdo_out_);
        }

        lock.lock();
        std::vector<std::shared_ptr<NodeService>> due;
        for (auto& s : services_)
            if (s.deadline <= now) due.push_back(s.service);
        lock.unlock();
        for (auto& svc : due) {
            const Nanos nd = svc->on_timer(*this, monotonic_ns());
            std::lock_guard relock(mutex_);
            for (auto& s : services_)
                if (s.service == svc) s.deadline = nd;
        }
        lock.lock();
    }
}

LocalNodeCounters LocalNode::counters() const {
    LocalNodeCounters c;
    {
        std::lock_guard lock(sdo_mutex_);
        c.sdo = server_.counters();
    }
    std::lock_guard lock(mutex_);
    c.sdo.dropped = dropped_;
    c.nmt_commands = nmt_commands_;
    c.nmt_ignored = nmt_ignored_;
    c.sdo_while_stopped = sdo_stopped_;
    c.sdo_bad_dlc = sdo_bad_dlc_;
    return c;
}

}  // namespace motorbus::canopen

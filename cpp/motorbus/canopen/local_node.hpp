// LocalNode: a CANopen node we serve on a bus — its object dictionary over
// SDO (0x600+n -> 0x580+n), its boot-up message and a minimal NMT slave.
//
//   auto od = std::make_shared<ObjectDictionary>();
//   od->add_variable({.index = 0x6001, .name = "Status", .type = DataType::Unsigned8});
//   LocalNode node(*bus, 5, od);     // sends boot-up 0x705 [00], enters PRE-OPERATIONAL
//
// More services (PDO, heartbeat, EMCY...) attach with add_service(): they get
// NMT state changes and a timer on the node's worker thread, and reach the
// bus, the dictionary and the node-id through the LocalNode& they are given.
//
// Threading: NMT frames are handled on the bus receive thread.  SDO requests
// that may run application hooks (initiates, the final segment that commits a
// value) go through a single-slot mailbox to the node's worker thread, so a
// flood is dropped and counted (S18) and a slow hook never stalls the bus.
// Mid-transfer frames (segments, block acks, aborts) are O(1) and handled
// straight from the receive thread, so a sub-block is never lost.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/od.hpp"
#include "motorbus/canopen/sdo_server.hpp"

namespace motorbus::canopen {

// NMT states with their heartbeat/boot-up byte values (CiA 301 §7.2.8.3.2).
enum class NmtState : std::uint8_t {
    Initialising = 0x00,
    Stopped = 0x04,
    Operational = 0x05,
    PreOperational = 0x7F,
};
const char* to_string(NmtState s);
// The state for a name as to_string() spells it; case, '-', '_' and ' ' are
// ignored ("pre_operational" works) and INITIALIZING is accepted.  nullopt for
// anything else.
std::optional<NmtState> nmt_state_from_name(std::string_view name);

// NMT command specifiers (byte 0 of a COB-ID 0x000 frame).
enum class NmtCommand : std::uint8_t {
    Start = 0x01,
    Stop = 0x02,
    EnterPreOperational = 0x80,
    ResetNode = 0x81,
    ResetCommunication = 0x82,
};

// The node-ID is already served by another LocalNode on the same medium (one ID per
// bus, as on a wire): a distinct type, so a device that restarts under a new ID can
// tell "taken" from any other failure without reading the message.  Python sees an
// InvalidArgument.
struct NodeIdTaken : InvalidArgument {
    using InvalidArgument::InvalidArgument;
};

class LocalNode;

// A service living on a LocalNode.  All callbacks run with no node lock held.
class NodeService {
public:
    virtual ~NodeService() = default;
    // After an NMT transition (including Initialising -> PreOperational at boot).
    virtual void on_nmt_state(LocalNode& node, NmtState previous, NmtState now) {
        (void)node, (void)previous, (void)now;
    }
    // On the node's worker thread at (or after) the time the service asked for;
    // returns the next monotonic_ns() time it wants to run, or kNoDeadline.
    virtual Nanos on_timer(LocalNode& node, Nanos now) {
        (void)node, (void)now;
        return kNoDeadline;
    }
    // The node is shutting down (or the service is removed): release the bus.
    virtual void on_detach(LocalNode& node) { (void)node; }
};

struct LocalNodeOptions {
    SdoServerConfig sdo;
    bool send_boot_up = true;       // 0x700+n [00] at start and after a reset
    bool serve_sdo = true;
    // NMT reset node restores 0x2000-0x9FFF (and reset communication 0x1000-0x1FFF)
    // to their defaults before the new boot-up.
    bool reset_restores_defaults = true;
    // Called on the bus thread after an NMT reset node / reset communication
    // put the node in Initialising (and restored the defaults when asked), before
    // the boot-up: a device whose reset differs from CiA 301 (e.g. one that keeps
    // or reloads values from its own flash) applies it here.  Empty = nothing.
    std::function<void(NmtCommand)> on_reset{};
    // Ignore (and count in LocalNodeCounters::sdo_bad_dlc) SDO requests whose
    // DLC is not 8, for a device whose manual says so.  false = the CiA 301
    // lenience of SdoServerMachine (short frames parsed as far as they go).
    bool sdo_require_dlc8 = false;
    // Serve every SDO request on the bus receive thread, as mid-transfer frames
    // are, instead of through the worker's mailbox: for a device whose hooks are
    // short and never block (a C++ simulator), it saves a thread hand-off per
    // request.  false = the mailbox (a slow hook never stalls the bus; S18).
    bool sdo_inline = false;
};

struct LocalNodeCounters {
    SdoServerCounters sdo;
    std::uint64_t nmt_commands = 0;  // applied
    std::uint64_t nmt_ignored = 0;   // wrong DLC, other node, unknown command
    std::uint64_t sdo_while_stopped = 0;
    std::uint64_t sdo_bad_dlc = 0;  // dropped by LocalNodeOptions::sdo_require_dlc8
};

class LocalNode {
public:
    // Throws InvalidArgument for node_id 0 or > 127 (N14).
    LocalNode(can::Bus& bus, std::uint8_t node_id, std::shared_ptr<ObjectDictionary> od,
              LocalNodeOptions options = {});
    ~LocalNode();
    LocalNode(const LocalNode&) = delete;
    LocalNode& operator=(const LocalNode&) = delete;

    can::Bus& bus() { return bus_; }
    ObjectDictionary& od() { return *od_; }
    std::shared_ptr<ObjectDictionary> od_ptr() const { return od_; }
    std::uint8_t node_id() const { return node_id_; }
    NmtState nmt_state() const { return state_.load(); }

    // Local NMT transition (as if commanded); listeners and services are told.
    void set_nmt_state(NmtState s);
    // Listener for NMT transitions; returns a handle for remove_state_listener().
    std::uint64_t add_state_listener(std::function<void(NmtState previous, NmtState now)> cb);
    void remove_state_listener(std::uint64_t handle);

    void add_service(std::shared_ptr<NodeService> service);
    void remove_service(const std::shared_ptr<NodeService>& service);
    // A service's next deadline changed: run the timers again now.
    void wake();

    // Sends a frame from this node (e.g. a service's TPDO); throws like Bus::send.
    void send(const can::Frame& frame);
    // Boot-up message 0x700+n [00] (done automatically at start and on reset).
    void send_boot_up();

    LocalNodeCounters counters() const;
    // Stop serving (unsubscribe, join the worker, detach services).  Idempotent.
    void close();

private:
    static void claim_node_id(can::Bus& bus, std::uint8_t node_id);
    static void release_node_id(can::Bus& bus, std::uint8_t node_id);
    void on_sdo_frame(const can::Frame& f);
    void on_nmt_frame(const can::Frame& f);
    void apply_nmt(NmtCommand c);
    void transition(NmtState s);
    void worker();
    void send_sdo(const SdoServerMachine::Outbox& out);

    can::Bus& bus_;
    std::uint8_t node_id_;
    std::shared_ptr<ObjectDictionary> od_;
    LocalNodeOptions options_;
    std::atomic<NmtState> state_{NmtState::Initialising};

    mutable std::mutex sdo_mutex_;  // guards server_
    SdoServerMachine server_;
    SdoServerMachine::Outbox sdo_out_;

    mutable std::mutex mutex_;  // mailbox, services, listeners, worker control
    std::condition_variable cv_;
    std::optional<can::Frame> mailbox_;
    bool woken_ = false;
    bool stopping_ = false;
    std::uint64_t dropped_ = 0, nmt_commands_ = 0, nmt_ignored_ = 0, sdo_stopped_ = 0, sdo_bad_dlc_ = 0;
    struct ServiceSlot {
        std::shared_ptr<NodeService> service;
        Nanos deadline = 0;  // run once right after being added
    };
    std::vector<ServiceSlot> services_;
    std::vector<std::pair<std::uint64_t, std::function<void(NmtState, NmtState)>>> listeners_;
    std::uint64_t next_listener_ = 1;
    std::recursive_mutex transition_mutex_;  // serializes transitions and their callbacks

    std::vector<can::SubscriptionId> subs_;
    std::thread thread_;
    std::atomic<bool> closed_{false};
};

}  // namespace motorbus::canopen

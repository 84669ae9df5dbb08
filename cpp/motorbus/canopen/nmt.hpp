// NMT: the network-management command codec (COB-ID 0x000), the node states a
// heartbeat reports, a master that commands nodes and tracks their states, and
// the device-side NMT state machine a served node runs.
#pragma once
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/frame.hpp"
// NmtCommand and the LocalNode's NmtState (without UNKNOWN) come from here.
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/runtime/callback_slot.hpp"
#include "motorbus/runtime/completions.hpp"

namespace motorbus::canopen {

constexpr std::uint32_t kNmtCobId = 0x000;
constexpr std::uint8_t kMaxNodeId = 127;

const char* to_string(NmtCommand c);
bool is_known_nmt_command(std::uint8_t cs);
// The command that puts a node in the named state, in the vocabulary of the
// `canopen` package's `nmt.state = ...`: OPERATIONAL, PRE-OPERATIONAL, STOPPED,
// RESET (node), RESET COMMUNICATION.  Case, '-', '_' and ' ' are ignored.
std::optional<NmtCommand> nmt_command_for_state(std::string_view name);

// The state a remote node reported in its heartbeat.  Like NmtState but with
// Unknown: a byte outside the valid set (0x42...) or nothing heard yet is never
// assumed to be operational (N7).
enum class NodeState : std::uint8_t {
    Initialising = 0x00,  // the boot-up message
    Stopped = 0x04,
    Operational = 0x05,
    PreOperational = 0x7F,
    Unknown = 0xFF,  // nothing heard yet, or a byte outside the set above
};
const char* to_string(NodeState s);
// Maps the raw heartbeat byte; the toggle bit (node guarding) is not part of it.
NodeState node_state_from_byte(std::uint8_t b);
inline NodeState to_node_state(NmtState s) { return static_cast<NodeState>(s); }
// INITIALISING, STOPPED, OPERATIONAL, PRE-OPERATIONAL or UNKNOWN, spelled as
// nmt_state_from_name() accepts them; nullopt for anything else.
std::optional<NodeState> node_state_from_name(std::string_view name);

struct NmtMessage {
    NmtCommand command;
    std::uint8_t node_id;  // 0 = every node
};

can::Frame encode_nmt(NmtCommand command, std::uint8_t node_id);
// nullopt for anything that is not a valid NMT command frame: wrong id, RTR,
// DLC != 2 (N1), node id > 127 (N2), unknown command specifier (N4).
std::optional<NmtMessage> decode_nmt(const can::Frame& f);

// Device side: the NMT state a served node is in, driven by NMT frames.
// Pure logic: feed frames, read the state, get told about changes.
class NmtSlave {
public:
    // Throws InvalidArgument for node ids 0 or > 127 (N14: refuse to start).
    explicit NmtSlave(std::uint8_t node_id);
    std::uint8_t node_id() const { return node_id_; }
    NodeState state() const { return state_; }

    // After boot-up (power-on or reset) a node is pre-operational.
    void boot() { set(NodeState::PreOperational); }
    // Returns the command applied, nullopt when the frame was ignored
    // (not for us, malformed, unknown: N1-N4) -- ignored frames are counted.
    std::optional<NmtCommand> on_frame(const can::Frame& f);
    std::uint64_t ignored() const { return ignored_; }

    // Reset commands leave the node in Initialising; the owner re-inits its
    // application / communication area and then calls boot().
    std::function<void(NodeState old_state, NodeState new_state)> on_state_change;
    std::function<void(NmtCommand)> on_reset;

private:
    void set(NodeState s);
    std::uint8_t node_id_;
    NodeState state_ = NodeState::Initialising;
    std::uint64_t ignored_ = 0;
};

// Host side: sends NMT commands and tracks each node's state from its
// heartbeats and boot-up messages (0x700 + node).
class NmtMaster {
public:
    // `own_node_id` (1-127) when the master itself has a node id: NMT commands
    // aimed at it from elsewhere on the bus are ignored and counted (N5).
    explicit NmtMaster(can::Bus& bus, std::optional<std::uint8_t> own_node_id = std::nullopt);
    ~NmtMaster();
    NmtMaster(const NmtMaster&) = delete;
    NmtMaster& operator=(const NmtMaster&) = delete;

    // node_id 0 = broadcast.  Throws InvalidArgument for ids > 127.
    void send(NmtCommand c, std::uint8_t node_id);
    void start(std::uint8_t node) { send(NmtCommand::Start, node); }
    void stop(std::uint8_t node) { send(NmtCommand::Stop, node); }
    void enter_pre_operational(std::uint8_t node) { send(NmtCommand::EnterPreOperational, node); }
    void reset_node(std::uint8_t node) { send(NmtCommand::ResetNode, node); }
    void reset_communication(std::uint8_t node) { send(NmtCommand::ResetCommunication, node); }

    // Last state heard from `node` (Unknown when never heard).
    NodeState state(std::uint8_t node) const;
    std::optional<std::uint8_t> raw_state(std::uint8_t node) const;
    // Blocks until `node` reports `want` (heartbeat or boot-up); false on timeout.
    bool wait_for_state(std::uint8_t node, NodeState want, std::chrono::nanoseconds timeout);
    // Blocks until `node` sends its boot-up message; false on timeout.
    bool wait_for_boot(std::uint8_t node, std::chrono::nanoseconds timeout);
    // Blocks until the next heartbeat or boot-up of `node` (one sent after
    // this call started); returns the state it reported, nullopt on timeout.
    std::optional<NodeState> wait_for_heartbeat(std::uint8_t node, std::chrono::nanoseconds timeout);

    // Called on the bus thread when a node's reported state changes, and for
    // every boot-up message (old state may equal new state then).
    CallbackSlot<void(std::uint8_t node, NodeState old_state, NodeState new_state)> on_state_change;

    std::uint64_t foreign_commands_ignored() const { return foreign_ignored_.load(); }

private:
    void on_heartbeat(const can::Frame& f);
    can::Bus& bus_;
    std::optional<std::uint8_t> own_;
    mutable std::mutex mutex_;
    std::condition_variable cv_;
    std::array<std::int16_t, 128> raw_{};  // -1 = never heard
    std::array<std::uint32_t, 128> boots_{};
    std::array<std::uint64_t, 128> heard_{};  // heartbeats + boot-ups per node
    std::atomic<std::uint64_t> foreign_ignored_{0};
    can::SubscriptionId hb_sub_ = 0, nmt_sub_ = 0;
};

// One awaited NMT event of one node, for event loops (motorbus.canopen's *_async
// waits): the first heartbeat or boot-up of `node` -- the frames NmtMaster's waits
// count, decoded by decode_heartbeat -- that matches `want` completes `token` on
// the bus's receive thread with the state's name (std::string, as NmtMaster::state
// names it), without the GIL; the wait then stops listening.  cancel() (or the
// destructor) stops it too.  The wait holds the bus alive.
class NmtEventWait : public std::enable_shared_from_this<NmtEventWait> {
public:
    enum class Want { AnyHeartbeat, BootUp, State };
    static std::shared_ptr<NmtEventWait> start(std::shared_ptr<can::Bus> bus, std::uint8_t node, Want want,
                                               NodeState state, std::shared_ptr<Completions> done,
                                               std::uint64_t token);
    void cancel();
    ~NmtEventWait();

    // Use start(): the subscription needs the shared pointer.
    NmtEventWait(std::shared_ptr<can::Bus> bus, std::uint8_t node, Want want, NodeState state,
                 std::shared_ptr<Completions> done, std::uint64_t token);

private:
    void on_frame(const can::Frame& f);
    std::shared_ptr<can::Bus> bus_;
    std::uint8_t node_;
    Want want_;
    NodeState state_;
    std::shared_ptr<Completions> done_;
    std::uint64_t token_;
    std::atomic<bool> fired_{false};
    std::atomic<can::SubscriptionId> sub_{0};
};

}  // namespace motorbus::canopen

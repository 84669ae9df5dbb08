// Heartbeat producer (0x1017) and consumer (0x1016) of a served LocalNode,
// with the communication error behaviour of 0x1029:1 on a lost heartbeat.
//
//   auto hb = HeartbeatService::attach(node, {.consumer_entries = 4});
//   hb->on_lost = [&](std::uint8_t n) { drive.loss_of_master(); };   // D5
//
// 0x1017 and 0x1016 are created in the dictionary when absent; writes are
// validated (N12 duplicate node 0x06040043, N13 reserved bits 0x06090030) and
// take effect within 50 ms (the service re-checks its configuration on its timer
// rather than waking the node from inside the SDO write).  A lost heartbeat sends EMCY 0x8130 (N10) and applies
// 0x1029:1 when present (0 = to PRE-OPERATIONAL, 1 = no change, 2 = STOPPED),
// else the CiA default 0.
#pragma once
#include <functional>
#include <memory>
#include <mutex>

#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/runtime/callback_slot.hpp"

namespace motorbus::canopen {

struct HeartbeatServiceOptions {
    unsigned consumer_entries = 4;  // 0x1016 sub-entries created when 0x1016 is absent
    std::uint16_t producer_ms = 0;  // 0x1017 default when absent
    // The 0x1029:1 behaviour applied when the dictionary has no 0x1029 (0 = CiA 301's
    // default: to PRE-OPERATIONAL; 1 = no state change; 2 = to STOPPED), for a
    // device whose manual documents no reaction.
    std::uint8_t error_behaviour_without_1029 = 0;
};

class HeartbeatService : public NodeService {
public:
    static std::shared_ptr<HeartbeatService> attach(LocalNode& node, HeartbeatServiceOptions options = {});
    ~HeartbeatService() override;

    // Called on the node's worker thread (Lost) or the bus thread (others).
    CallbackSlot<void(std::uint8_t node)> on_lost;
    std::function<void(std::uint8_t node, HeartbeatEvent ev, NodeState state)> on_event;
    // The EMCY of a lost heartbeat (N10, code 0x8130), for a device that sends its EMCY
    // itself (its own error register, inhibit time, history).  Empty: the service sends
    // it from the node with error register 0x11.  Called on the node's worker thread.
    std::function<void(std::uint16_t code)> on_emcy;
    NodeHealth health(std::uint8_t node) const { return consumer_.health(node); }
    std::uint64_t heartbeats_sent() const;

    void on_nmt_state(LocalNode& node, NmtState previous, NmtState now) override;
    Nanos on_timer(LocalNode& node, Nanos now) override;
    void on_detach(LocalNode& node) override;

private:
    HeartbeatService(LocalNode& node, HeartbeatServiceOptions options);
    void install(const std::weak_ptr<HeartbeatService>& self);
    void apply_consumers();
    void lost(std::uint8_t node);
    LocalNode& node_;
    HeartbeatServiceOptions options_;
    RealClock clock_;
    HeartbeatConsumer consumer_;
    mutable std::mutex m_;
    Nanos period_ns_ = 0;
    Nanos next_ = -1;
    std::uint64_t sent_ = 0;
    std::vector<std::uint32_t> entries_;
    bool detached_ = false;
};

}  // namespace motorbus::canopen

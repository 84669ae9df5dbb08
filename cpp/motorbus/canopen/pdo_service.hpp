// The PDO engine attached to a LocalNode and its ObjectDictionary.
//
//   LocalNode node(*bus, 5, od);
//   auto pdo = PdoService::attach(node);   // 0x1400-0x1BFF appear in the OD
//
// The communication and mapping parameters become OD objects whose writes are
// validated by the engine (write hooks, abort codes of P7-P10); mapped
// application objects are read and written through the dictionary (so limits
// and hooks apply to RPDO data too); TPDOs follow the node's NMT state; value
// changes of mapped objects trigger event-driven TPDOs.
#pragma once
#include <functional>
#include <memory>
#include <vector>

#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/od.hpp"
#include "motorbus/canopen/pdo_engine.hpp"

namespace motorbus::canopen {

// PdoObjectAccess over an ObjectDictionary.
class OdPdoObjects : public PdoObjectAccess {
public:
    explicit OdPdoObjects(ObjectDictionary& od) : od_(od) {}
    std::uint32_t check_mapping(std::uint16_t index, std::uint8_t sub, std::uint8_t bits, bool tpdo) override;
    std::uint64_t read_value(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) override;
    void write_value(std::uint16_t index, std::uint8_t sub, std::uint8_t bits, std::uint64_t raw) override;
    std::uint64_t rejected_writes() const { return rejected_; }

private:
    ObjectDictionary& od_;
    std::atomic<std::uint64_t> rejected_{0};
};

struct PdoServiceOptions {
    unsigned rpdo_count = 4;
    unsigned tpdo_count = 4;
    unsigned max_mapped = 8;
    bool strict = true;  // see PdoEngineOptions::strict
    std::uint32_t sync_window_us = 0;
    PdoRtrPolicy rtr = PdoRtrPolicy::ByCobId;    // see PdoEngineOptions::rtr
    bool allow_restricted_cob_ids = false;       // see PdoEngineOptions
};

class PdoService : public NodeService {
public:
    static std::shared_ptr<PdoService> attach(LocalNode& node, PdoServiceOptions options = {});
    ~PdoService() override;

    PdoEngine& engine() { return *engine_; }
    // Rebuilds the engine from the dictionary's PDO parameters (as after a reset),
    // for a device that restored them there itself (e.g. a factory reset), and
    // reschedules the TPDO timers.
    void reload_from_dictionary();
    // EMCY raised by the engine (P1, P2, P11, N15, N16).  Default: send the
    // EMCY frame from the node (error register bit 4, communication error).
    std::function<void(std::uint16_t code, bool active)> on_emcy;

    void on_nmt_state(LocalNode& node, NmtState previous, NmtState now) override;
    Nanos on_timer(LocalNode& node, Nanos now) override;
    void on_detach(LocalNode& node) override;

private:
    PdoService(LocalNode& node, PdoServiceOptions options);
    void install(const std::weak_ptr<PdoService>& self);
    void reload();
    void wake_node();  // a PDO parameter changed: run the engine's timers now
    LocalNode& node_;
    PdoServiceOptions options_;
    RealClock clock_;
    OdPdoObjects objects_;
    std::unique_ptr<PdoEngine> engine_;
    can::SubscriptionId sub_ = 0;
    std::vector<std::pair<VariablePtr, std::uint64_t>> listeners_;
    std::mutex detach_m_;
    bool detached_ = false;
};

}  // namespace motorbus::canopen

// Network scanner: which nodes are on the bus, what they are.
//
// It listens for boot-up and heartbeat messages and probes every node id with
// expedited SDO uploads of 0x1000 (device type) and 0x1018:1-4 (identity),
// all nodes in parallel, so an empty network costs one SDO timeout rather than
// 127 of them.
#pragma once
#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/nmt.hpp"

namespace motorbus::canopen {

struct ScanOptions {
    std::uint8_t first = 1, last = 127;
    // Extra time to listen for heartbeats / boot-ups besides the probes.
    std::chrono::nanoseconds listen{std::chrono::milliseconds(0)};
    std::chrono::nanoseconds sdo_timeout{std::chrono::milliseconds(200)};
    bool probe_sdo = true;
    bool read_identity = true;
};

struct ScanResult {
    std::uint8_t node_id = 0;
    bool sdo_answered = false;   // any SDO reply (value or abort)
    bool heard_heartbeat = false;
    bool heard_boot_up = false;
    NodeState state = NodeState::Unknown;  // from the last heartbeat heard
    std::optional<std::uint32_t> device_type;      // 0x1000
    std::optional<std::uint32_t> vendor_id;        // 0x1018:1
    std::optional<std::uint32_t> product_code;     // 0x1018:2
    std::optional<std::uint32_t> revision;         // 0x1018:3
    std::optional<std::uint32_t> serial_number;    // 0x1018:4
    std::optional<std::uint32_t> device_type_abort;  // abort code when 0x1000 was refused
    // CiA 402 drives report profile 402 in the low 16 bits of 0x1000.
    std::uint16_t profile() const { return device_type ? std::uint16_t(*device_type & 0xFFFF) : 0; }
};

// Blocks for at most listen + (1 + 4 if identity) x sdo_timeout.  Results are
// sorted by node id; a node appears when it answered or was heard.
std::vector<ScanResult> scan_network(can::Bus& bus, const ScanOptions& options = {});

}  // namespace motorbus::canopen

// A poll source that captures a CANopen drive's TPDOs instead of asking by SDO
// (motorbus.Poller, mode "capture"): it subscribes to each TPDO's COB-ID on the
// bus, the bus receive thread unpacks every frame into CaptureSlots (no GIL, a
// short lock), and read() takes the latest values.  Configuring the drive to
// send them (mapping, transmission type, event timer, NMT start) is the drive
// kind's job (python/motorbus/drives/cia402.py); this class only listens.
//
// Row: out[0] the arrival time of the oldest value (monotonic ns, NaN until
// every TPDO arrived once), then one column per requested (TPDO, entry).
// read() throws LinkDown when the bus lost its link, ClosedError once closed.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/poll/capture.hpp"
#include "motorbus/poll/source.hpp"

namespace motorbus::canopen {

struct CapturedPdo {
    std::uint32_t cob_id = 0;              // 11-bit id the device sends the TPDO on
    std::vector<PdoMapEntry> mapping;      // as configured on the device (is_signed: sign-extend)
};

class PdoCaptureSource final : public poll::Source {
public:
    // `columns`: (pdo index into `pdos`, entry index into its mapping) per
    // value, in the order read() writes them.  InvalidArgument for an empty
    // list, a mapping over 64 bits or a column naming no entry.  `bus` must
    // outlive the source (the bindings keep it alive).
    PdoCaptureSource(can::Bus& bus, std::uint8_t node, std::vector<CapturedPdo> pdos,
                     std::vector<std::pair<std::size_t, std::size_t>> columns, Nanos max_age_ns);
    ~PdoCaptureSource() override;

    std::size_t columns() const override { return slots_.columns(); }
    void read(double* out) override;
    std::string describe() const override;
    std::uint64_t stale() const override { return slots_.stale(); }
    // Frames used / too short for their mapping.
    std::uint64_t received() const { return received_.load(); }
    std::uint64_t short_frames() const { return short_.load(); }
    // Stops listening (idempotent); read() keeps the last values.
    void close();

private:
    void on_frame(std::size_t pdo, const can::Frame& f);

    can::Bus& bus_;
    std::uint8_t node_;
    std::vector<CapturedPdo> pdos_;
    std::vector<PdoLayout> layouts_;
    // per PDO: which entries feed which slot
    std::vector<std::vector<std::pair<std::size_t, std::size_t>>> routes_;  // (entry, slot)
    poll::CaptureSlots slots_;
    std::vector<can::SubscriptionId> subs_;
    std::atomic<std::uint64_t> received_{0}, short_{0};
    std::atomic<bool> closed_{false};
};

}  // namespace motorbus::canopen

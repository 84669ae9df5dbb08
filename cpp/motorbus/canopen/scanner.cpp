#include "motorbus/canopen/scanner.hpp"

#include <array>
#include <condition_variable>
#include <mutex>

#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

namespace {

struct Probe {
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    bool outstanding = false;
    bool done = false;
    std::optional<std::uint32_t> value;
    std::optional<std::uint32_t> abort;
};

can::Frame upload_request(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
    can::Frame f;
    f.id = 0x600u + node;
    f.len = 8;
    f.data[0] = 0x40;  // initiate upload
    f.data[1] = static_cast<std::uint8_t>(index);
    f.data[2] = static_cast<std::uint8_t>(index >> 8);
    f.data[3] = sub;
    return f;
}

std::uint32_t le32(const std::uint8_t* p, unsigned n) {
    std::uint32_t v = 0;
    for (unsigned i = 0; i < n; ++i) v |= std::uint32_t(p[i]) << (8 * i);
    return v;
}

}  // namespace

std::vector<ScanResult> scan_network(can::Bus& bus, const ScanOptions& o) {
    if (o.first == 0 || o.last > kMaxNodeId || o.first > o.last)
        throw InvalidArgument("scan range must be within 1-127");
    std::mutex m;
    std::condition_variable cv;
    std::array<ScanResult, 128> res{};
    std::array<Probe, 128> probe{};
    std::array<bool, 128> seen{};
    for (unsigned n = 0; n < 128; ++n) res[n].node_id = static_cast<std::uint8_t>(n);

    auto hb_sub = bus.subscribe(can::Filter{kHeartbeatBase, 0x780, false, true}, [&](const can::Frame& f) {
        auto hb = decode_heartbeat(f);
        if (!hb || hb->node_id < o.first || hb->node_id > o.last) return;
        std::lock_guard l(m);
        auto& r = res[hb->node_id];
        seen[hb->node_id] = true;
        if (hb->is_boot_up())
            r.heard_boot_up = true;
        else
            r.heard_heartbeat = true;
        r.state = hb->state;
    });
    auto sdo_sub = bus.subscribe(can::Filter{0x580, 0x780, false, true}, [&](const can::Frame& f) {
        const unsigned node = f.id - 0x580;
        if (f.rtr || node < o.first || node > o.last || f.len < 4) return;  // short replies: not ours
        std::lock_guard l(m);
        auto& p = probe[node];
        if (!p.outstanding) return;  // unsolicited or late
        const std::uint16_t idx = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
        if (idx != p.index || f.data[3] != p.sub) return;  // another client's transfer
        const std::uint8_t cmd = f.data[0];
        res[node].sdo_answered = true;
        seen[node] = true;
        if (cmd == 0x80) {
            p.abort = f.len >= 8 ? le32(&f.data[4], 4) : 0x08000000u;
        } else if ((cmd & 0xE0) == 0x40 && (cmd & 0x02)) {  // expedited upload response
            const unsigned n = (cmd & 0x01) ? 4 - ((cmd >> 2) & 3) : 4;
            const unsigned avail = f.len > 4 ? f.len - 4u : 0u;
            p.value = le32(&f.data[4], std::min(n, avail));
        }
        // Segmented replies are not expected for 32-bit objects: the node is there, value unknown.
        p.outstanding = false;
        p.done = true;
        cv.notify_all();
    });

    auto run_round = [&](auto&& which, std::uint16_t index, std::uint8_t sub) {
        std::vector<std::uint8_t> nodes;
        {
            std::lock_guard l(m);
            for (unsigned n = o.first; n <= o.last; ++n)
                if (which(static_cast<std::uint8_t>(n))) {
                    probe[n] = Probe{index, sub, true, false, {}, {}};
                    nodes.push_back(static_cast<std::uint8_t>(n));
                }
        }
        if (nodes.empty()) return;
        const auto deadline = std::chrono::steady_clock::now() + o.sdo_timeout;
        for (auto n : nodes) {
            try {
                bus.send(upload_request(n, index, sub), o.sdo_timeout);
            } catch (const TimeoutError&) {
                std::lock_guard l(m);
                probe[n].outstanding = false;
            }
        }
        std::unique_lock l(m);
        cv.wait_until(l, deadline, [&] {
            for (auto n : nodes)
                if (probe[n].outstanding) return false;
            return true;
        });
        for (auto n : nodes) probe[n].outstanding = false;  // late replies are ignored
    };

    const auto listen_until = std::chrono::steady_clock::now() + o.listen;
    try {
        if (o.probe_sdo) {
            run_round([](std::uint8_t) { return true; }, 0x1000, 0);
            {
                std::lock_guard l(m);
                for (unsigned n = o.first; n <= o.last; ++n) {
                    if (probe[n].value) res[n].device_type = probe[n].value;
                    if (probe[n].abort) res[n].device_type_abort = probe[n].abort;
                }
            }
            if (o.read_identity) {
                std::optional<std::uint32_t> ScanResult::*fields[4] = {
                    &ScanResult::vendor_id, &ScanResult::product_code, &ScanResult::revision,
                    &ScanResult::serial_number};
                for (std::uint8_t s = 1; s <= 4; ++s) {
                    run_round([&](std::uint8_t n) { return res[n].sdo_answered; }, 0x1018, s);
                    std::lock_guard l(m);
                    for (unsigned n = o.first; n <= o.last; ++n)
                        if (probe[n].value && probe[n].index == 0x1018) res[n].*fields[s - 1] = probe[n].value;
                }
            }
        }
        std::unique_lock l(m);
        cv.wait_until(l, listen_until, [] { return false; });
    } catch (...) {
        bus.unsubscribe(sdo_sub);
        bus.unsubscribe(hb_sub);
        throw;
    }
    bus.unsubscribe(sdo_sub);
    bus.unsubscribe(hb_sub);
    std::vector<ScanResult> out;
    std::lock_guard l(m);
    for (unsigned n = o.first; n <= o.last; ++n)
        if (seen[n]) out.push_back(res[n]);
    return out;
}

}  // namespace motorbus::canopen

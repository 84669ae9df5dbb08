// Test support for the canopen services tests: an in-process hub whose
// endpoints deliver every sent frame synchronously to all other endpoints,
// so tests are deterministic without threads.
#pragma once
#include <memory>
#include <mutex>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/errors.hpp"

namespace svc_test {

class Hub;

class HubBus final : public motorbus::can::Bus {
public:
    HubBus(Hub& hub, std::string name) : Bus(std::move(name)), hub_(hub) {}
    ~HubBus() override { close(); }
    void deliver(const motorbus::can::Frame& f) { dispatch(f); }
    std::vector<motorbus::can::Frame> sent;  // everything this endpoint sent

protected:
    void do_send(const motorbus::can::Frame& f, motorbus::can::Deadline) override;
    void do_close() override {}

private:
    Hub& hub_;
};

class Hub {
public:
    std::shared_ptr<HubBus> open(std::string name = "ep") {
        auto b = std::make_shared<HubBus>(*this, std::move(name));
        std::lock_guard l(m_);
        eps_.push_back(b);
        return b;
    }
    // A frame sent from inside a receive callback is queued and delivered after
    // the current one, so dispatches never nest (as with a real receive thread).
    void route(HubBus* from, const motorbus::can::Frame& f) {
        {
            std::lock_guard l(m_);
            log.push_back(f);
            pending_.emplace_back(from, f);
            if (delivering_) return;
            delivering_ = true;
        }
        while (true) {
            std::pair<HubBus*, motorbus::can::Frame> next;
            std::vector<std::shared_ptr<HubBus>> eps;
            {
                std::lock_guard l(m_);
                if (pending_.empty()) {
                    delivering_ = false;
                    return;
                }
                next = pending_.front();
                pending_.erase(pending_.begin());
                eps = eps_;
            }
            for (auto& e : eps)
                if (e.get() != next.first && !e->closed()) e->deliver(next.second);
        }
    }
    std::vector<motorbus::can::Frame> log;  // every frame on the wire

private:
    std::mutex m_;
    std::vector<std::shared_ptr<HubBus>> eps_;
    std::vector<std::pair<HubBus*, motorbus::can::Frame>> pending_;
    bool delivering_ = false;
};

inline void HubBus::do_send(const motorbus::can::Frame& f, motorbus::can::Deadline) {
    sent.push_back(f);
    hub_.route(this, f);
}

inline motorbus::can::Frame frame(std::uint32_t id, std::vector<std::uint8_t> d, bool rtr = false) {
    motorbus::can::Frame f;
    f.id = id;
    f.rtr = rtr;
    f.len = static_cast<std::uint8_t>(d.size());
    for (std::size_t i = 0; i < d.size() && i < f.data.size(); ++i) f.data[i] = d[i];
    return f;
}

inline std::vector<std::uint8_t> bytes(const motorbus::can::Frame& f) {
    auto p = f.payload();
    return {p.begin(), p.end()};
}

}  // namespace svc_test

#include "motorbus/drives/unitek/poll_source.hpp"

#include <algorithm>
#include <cstdio>

#include "motorbus/errors.hpp"

namespace motorbus::unitek {
namespace {

std::string hex_id(std::uint32_t id) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%03X", static_cast<unsigned>(id));
    return buf;
}

void check_regids(const Client& client, const std::vector<std::uint8_t>& regids, const char* what) {
    if (regids.empty()) throw InvalidArgument(std::string(what) + ": at least one register");
    for (auto r : regids) {
        const Register& reg = client.table().at(r);  // UnknownRegister
        if (!reg.readable())
            throw InvalidArgument(std::string(what) + ": register " + reg.name + " is write-only");
    }
}

}  // namespace

PollSource::PollSource(Client& client, std::vector<std::uint8_t> regids)
    : client_(client), regids_(std::move(regids)) {
    check_regids(client_, regids_, "unitek poll source");
}

void PollSource::read(double* out) {
    for (std::size_t i = 0; i < regids_.size(); ++i) out[i] = static_cast<double>(client_.read(regids_[i]));
}

std::string PollSource::describe() const { return "unitek rx " + hex_id(client_.rx_id()); }

CaptureSource::CaptureSource(Client& client, can::Bus& bus, std::vector<std::uint8_t> regids, int interval_ms,
                             Nanos max_age_ns)
    : client_(client), bus_(bus), regids_(std::move(regids)), interval_ms_(interval_ms),
      t_(regids_.size()), v_(regids_.size()) {
    check_regids(client_, regids_, "unitek capture source");
    if (interval_ms < 1 || interval_ms > 254)
        throw InvalidArgument("unitek capture source: interval_ms 1..254, not " + std::to_string(interval_ms));
    const auto existing = client_.streams();
    try {
        for (auto r : regids_) {
            auto it = std::find_if(existing.begin(), existing.end(), [&](const auto& s) { return s->regid == r; });
            if (it != existing.end()) {
                streams_.push_back(*it);  // a user's stream: share it, keep its interval
                interval_ms_ = std::max(interval_ms_, (*it)->interval_ms.load());
            } else {
                // A small ring: only its newest sample is read here.
                streams_.push_back(client_.subscribe(r, interval_ms, 256));
                owned_.push_back(r);
            }
        }
    } catch (...) {
        close();
        throw;
    }
    max_age_ = max_age_ns > 0 ? max_age_ns : Nanos(3) * interval_ms_ * 1'000'000 + 2'000'000;
}

CaptureSource::~CaptureSource() { close(); }

void CaptureSource::close() {
    if (closed_.exchange(true)) return;
    for (auto r : owned_) {
        try {
            client_.unsubscribe(r);
        } catch (const Error&) {
            // the link or the client is gone: the drive stops with it
        }
    }
}

void CaptureSource::read(double* out) {
    // Without this a dead link would give the last values forever.
    switch (bus_.state()) {
        // A lost link (adapter unplugged, server gone) turns the bus bus-off, as a real bus-off
        // does: either way nothing more arrives, and Bus::send() would refuse with LinkDown.
        case can::BusState::BusOff:
        case can::BusState::LinkDown:
            throw LinkDown("unitek capture: bus " + bus_.channel() + " is down (link lost or bus-off)");
        case can::BusState::Closed: throw ClosedError("unitek capture: the bus is closed (" + bus_.channel() + ")");
        default: break;
    }
    for (std::size_t i = 0; i < streams_.size(); ++i) {
        const RingBuffer& ring = streams_[i]->ring;
        const std::uint64_t n = ring.count();  // acquire: the sample n-1 is complete
        if (n == 0) {
            t_[i] = -1;
            continue;
        }
        const std::size_t slot = static_cast<std::size_t>((n - 1) % ring.capacity());
        t_[i] = ring.times()[slot];
        v_[i] = static_cast<double>(ring.values()[slot]);
    }
    if (poll::CaptureSlots::fill(t_.data(), v_.data(), streams_.size(), monotonic_ns(), max_age_, out))
        stale_.fetch_add(1, std::memory_order_relaxed);
}

std::string CaptureSource::describe() const {
    return "unitek capture rx " + hex_id(client_.rx_id()) + " every " + std::to_string(interval_ms_) + " ms";
}

}  // namespace motorbus::unitek

// SdoAccess implemented with our SdoClient (sdo_client.hpp): BusSdoAccess keeps
// one client per node id, created on first use; ClientSdoAccess wraps a client
// the caller already has (one node).  Errors are the client's own (SdoAbortError,
// SdoTimeout, ...).
#pragma once
#include <array>
#include <memory>
#include <mutex>

#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/canopen/sdo_access.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::canopen {

class BusSdoAccess : public SdoAccess {
public:
    explicit BusSdoAccess(can::Bus& bus, SdoClientOptions options = {}) : bus_(bus), options_(options) {}

    SdoClient& client(std::uint8_t node) {
        if (node == 0 || node > 127) throw InvalidArgument("SDO node id must be 1-127");
        std::lock_guard l(m_);
        auto& c = clients_[node];
        if (!c) c = std::make_unique<SdoClient>(bus_, node, options_);
        return *c;
    }
    void download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                  std::span<const std::uint8_t> data) override {
        client(node).download(index, sub, data);
    }
    std::vector<std::uint8_t> upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub) override {
        return client(node).upload(index, sub);
    }

private:
    can::Bus& bus_;
    SdoClientOptions options_;
    std::mutex m_;
    std::array<std::unique_ptr<SdoClient>, 128> clients_{};
};

// SdoAccess bound to an existing client of one node (the node argument must match).
class ClientSdoAccess : public SdoAccess {
public:
    ClientSdoAccess(SdoClient& client, std::uint8_t node) : client_(client), node_(node) {}
    void download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                  std::span<const std::uint8_t> data) override {
        check(node);
        client_.download(index, sub, data);
    }
    std::vector<std::uint8_t> upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub) override {
        check(node);
        return client_.upload(index, sub);
    }

private:
    void check(std::uint8_t node) const {
        if (node != node_) throw InvalidArgument("this SDO client talks to node " + std::to_string(node_));
    }
    SdoClient& client_;
    std::uint8_t node_;
};

}  // namespace motorbus::canopen

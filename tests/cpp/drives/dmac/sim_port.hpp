// Test helper: an in-memory serial Port wired to LineDevices (the DMAC
// simulators), so the client runs against the simulator without a pty.  Bytes
// can also be injected to play a hostile peer.
#pragma once
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/errors.hpp"
#include "motorbus/serial/line_device.hpp"
#include "motorbus/serial/port.hpp"

namespace dmac_test {

class SimPort : public motorbus::serial::Port {
public:
    // Optional filter applied to each reply before it reaches the host (fault injection).
    std::function<std::string(const std::string& request, const std::string& reply)> tamper;

    void attach(std::shared_ptr<motorbus::serial::LineDevice> d) { devices_.push_back(std::move(d)); }

    void write(std::span<const std::uint8_t> bytes) override {
        std::lock_guard lock(m_);
        if (closed_) throw motorbus::LinkDown("SimPort closed");
        in_.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
        written_.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
        std::size_t cr;
        while ((cr = in_.find('\r')) != std::string::npos) {
            std::string line = in_.substr(0, cr);
            in_.erase(0, cr + 1);
            std::string reply;
            for (auto& d : devices_) reply += d->on_line(line);
            if (tamper) reply = tamper(line, reply);
            out_ += reply;
        }
    }
    std::size_t read(std::span<std::uint8_t> buf, motorbus::serial::Duration timeout) override {
        {
            std::lock_guard lock(m_);
            if (!out_.empty()) {
                std::size_t n = std::min(buf.size(), out_.size());
                std::memcpy(buf.data(), out_.data(), n);
                out_.erase(0, n);
                return n;
            }
        }
        if (timeout.count() != 0)
            std::this_thread::sleep_for(timeout.count() < 0 ? std::chrono::milliseconds(1)
                                                            : std::min<motorbus::serial::Duration>(timeout, std::chrono::milliseconds(1)));
        return 0;
    }
    void flush_input() override {
        std::lock_guard lock(m_);
        out_.clear();
    }
    void close() override {
        std::lock_guard lock(m_);
        closed_ = true;
    }
    std::string name() const override { return "simport"; }

    void inject(const std::string& bytes) {
        std::lock_guard lock(m_);
        out_ += bytes;
    }
    std::string written() {
        std::lock_guard lock(m_);
        return written_;
    }

private:
    std::mutex m_;
    std::vector<std::shared_ptr<motorbus::serial::LineDevice>> devices_;
    std::string in_, out_, written_;
    bool closed_ = false;
};

}  // namespace dmac_test

// An in-memory serial line for tests: bytes written are split at CR and handed
// to every LineDevice on the "line" (RS-485 multi-drop); their replies become
// readable.  Hooks let a test corrupt replies or inject stray bytes.
#pragma once
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "motorbus/serial/line_device.hpp"
#include "motorbus/serial/port.hpp"

namespace arcus_test {

class DevicePort : public motorbus::serial::Port {
public:
    explicit DevicePort(std::vector<motorbus::serial::LineDevice*> devices) : devices_(std::move(devices)) {}

    void write(std::span<const std::uint8_t> bytes) override {
        std::lock_guard lk(m_);
        written += std::string(bytes.begin(), bytes.end());
        for (auto b : bytes) {
            char c = static_cast<char>(b);
            if (c == '\r') {
                for (auto* d : devices_) {
                    std::string r = d->on_line(line_);
                    if (mangle) r = mangle(r);
                    if (!silent) out_.insert(out_.end(), r.begin(), r.end());
                }
                line_.clear();
            } else if (line_.size() < 4096) {
                line_ += c;
            }
        }
        cv_.notify_all();
    }
    std::size_t read(std::span<std::uint8_t> buf, motorbus::serial::Duration timeout) override {
        std::unique_lock lk(m_);
        cv_.wait_for(lk, timeout, [&] { return !out_.empty(); });
        std::size_t n = 0;
        while (n < buf.size() && !out_.empty()) {
            buf[n++] = static_cast<std::uint8_t>(out_.front());
            out_.pop_front();
        }
        return n;
    }
    void flush_input() override {
        std::lock_guard lk(m_);
        out_.clear();
    }
    void close() override {}
    std::string name() const override { return "device-port"; }

    // Bytes that appear on the line as if a device sent them.
    void inject(const std::string& bytes) {
        std::lock_guard lk(m_);
        out_.insert(out_.end(), bytes.begin(), bytes.end());
        cv_.notify_all();
    }

    std::function<std::string(const std::string&)> mangle;  // rewrite each reply
    bool silent = false;                                    // swallow replies (timeouts)
    std::string written;                                    // everything the host sent

private:
    std::vector<motorbus::serial::LineDevice*> devices_;
    std::mutex m_;
    std::condition_variable cv_;
    std::string line_;
    std::deque<char> out_;
};

}  // namespace arcus_test

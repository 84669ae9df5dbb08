// Serves simulated LineDevices on a pty (or any Port), the way they would sit
// on a real RS-232/RS-485 line: a client opens slave_path() with pyserial or a
// TtyPort and talks to them byte for byte.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/serial/line_device.hpp"
#include "motorbus/serial/port.hpp"

namespace motorbus::serial {

struct LineServerCounters {
    std::uint64_t bytes_in = 0;
    std::uint64_t bytes_out = 0;
    std::uint64_t lines = 0;            // complete request lines handed to the devices
    std::uint64_t overlong_lines = 0;   // request lines longer than every device accepts
    std::uint64_t replies = 0;          // non-empty replies written
    std::uint64_t device_errors = 0;    // a device broke its no-throw promise (reply dropped)
    std::uint64_t dropped_replies = 0;  // the client stopped reading; reply not written
};

class PtyLineServer {
public:
    // Creates a pty and serves `devices` on it.  baud > 0 paces the line like a
    // real UART at that rate (10 bit times per byte, both directions), so
    // round-trip benchmarks over a pty resemble the wire; 0 = as fast as possible.
    explicit PtyLineServer(std::vector<std::shared_ptr<LineDevice>> devices = {}, unsigned baud = 0);
    // Serves on a port someone else opened (a real tty, one side of a pty).
    // The server does not close it; stopping takes up to one poll period (20 ms).
    PtyLineServer(std::shared_ptr<Port> port, std::vector<std::shared_ptr<LineDevice>> devices,
                  unsigned baud = 0);
    ~PtyLineServer();
    PtyLineServer(const PtyLineServer&) = delete;
    PtyLineServer& operator=(const PtyLineServer&) = delete;

    // A paced pty line (baud > 0) that also checks the client's speed: bytes
    // sent while the client's side of the pty is set to another rate arrive
    // garbled, as a UART at the wrong rate reads framing errors, so devices
    // never answer them (what discovery meets on a real line).  Off by default.
    void set_enforce_baud(bool on) { enforce_baud_.store(on); }
    bool enforce_baud() const { return enforce_baud_.load(); }
    // Adds a device to the multi-drop line; every device sees every line.
    void attach(std::shared_ptr<LineDevice> device);
    // The path a client opens ("" when serving on an existing port).
    const std::string& slave_path() const;
    // The pty (null when serving on an existing port).
    PtyPair* pty() const { return pty_.get(); }
    // Stops the thread and closes the pty.  Idempotent.
    void close();
    bool running() const { return !stopped_.load(); }
    unsigned baud() const { return baud_; }
    LineServerCounters counters() const;

private:
    void start();
    void run();
    void rebuild_framer_locked();
    void write_paced(const std::string& bytes);

    std::unique_ptr<PtyPair> pty_;
    std::shared_ptr<Port> port_;
    bool owns_port_ = false;
    unsigned baud_ = 0;
    std::atomic<bool> enforce_baud_{false};
    std::string no_path_;

    std::mutex devices_mutex_;
    std::vector<std::shared_ptr<LineDevice>> devices_;
    bool devices_changed_ = true;

    std::atomic<bool> stop_{false};
    std::atomic<bool> stopped_{false};
    std::mutex close_mutex_;
    std::thread thread_;

    struct Counters {
        std::atomic<std::uint64_t> bytes_in{0}, bytes_out{0}, lines{0}, overlong_lines{0}, replies{0},
            device_errors{0}, dropped_replies{0};
    } c_;
};

}  // namespace motorbus::serial

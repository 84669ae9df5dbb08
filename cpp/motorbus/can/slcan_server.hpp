// SlcanServer: serves any motorbus Bus as an SLCAN adapter on a serial port
// (by default a fresh pty), so python-can's `slcan` interface, slcand or any
// SLCAN tool can join that bus through `pty_path()`.
//
// It answers commands like a Lawicel CANUSB (see AdapterSession), forwards
// bus frames as t/T/r/R lines only while the channel is open (with a 4-hex ms
// timestamp after `Z1`), and transmits received t/T/r/R lines onto the bus,
// answering `z`/`Z` when the bus took the frame and BEL when it did not.
// Frames waiting for a slow SLCAN reader sit in a bounded queue; past it they
// are dropped, counted, and reported in the next `F` as data overrun +
// receive FIFO full, the way a real adapter reports it.
#pragma once
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/slcan_codec.hpp"
#include "motorbus/serial/port.hpp"

namespace motorbus::can {

struct SlcanServerOptions {
    slcan::AdapterIdentity identity;
    std::size_t queue_size = 65536;  // bus frames waiting to be written to the SLCAN peer
    Duration bus_send_timeout = std::chrono::milliseconds(100);
    Duration write_timeout = std::chrono::seconds(1);  // peer not reading: drop the batch
};

// Throws InvalidArgument naming the field: queue_size 0, a negative duration,
// an identity the V/N replies cannot carry (V or N and exactly 4 printable
// characters, as an adapter answers).
void check_options(const SlcanServerOptions& options);

struct SlcanServerStats {
    std::uint64_t commands = 0;
    std::uint64_t invalid_commands = 0;   // answered BEL because malformed/unknown/refused
    std::uint64_t transmitted = 0;        // frames put on the bus for the peer
    std::uint64_t transmit_failed = 0;    // bus refused them (answered BEL)
    std::uint64_t forwarded = 0;          // bus frames written to the peer
    std::uint64_t forward_dropped = 0;    // queue full or peer not reading
    bool open = false;
};

class SlcanServer {
public:
    // Creates a pty; peers open pty_path().
    explicit SlcanServer(std::shared_ptr<Bus> bus, SlcanServerOptions options = {});
    // Serves on an existing port (e.g. a real UART wired to an SLCAN host).
    SlcanServer(std::shared_ptr<Bus> bus, std::shared_ptr<serial::Port> port,
                SlcanServerOptions options = {});
    ~SlcanServer();
    SlcanServer(const SlcanServer&) = delete;
    SlcanServer& operator=(const SlcanServer&) = delete;

    const std::string& pty_path() const { return pty_path_; }  // empty with an external port
    SlcanServerStats stats() const;
    bool is_open() const { return open_.load(); }
    void close();

private:
    void start();
    void reader();
    void writer();
    void on_command(const slcan::Command& c);
    void on_bus_frame(const Frame& f);
    void write_bytes(const std::string& bytes);

    std::shared_ptr<Bus> bus_;
    SlcanServerOptions opts_;
    std::unique_ptr<serial::PtyPair> pty_;
    std::shared_ptr<serial::Port> port_;
    std::string pty_path_;
    SubscriptionId sub_ = 0;

    slcan::CommandDecoder decoder_;  // reader thread
    slcan::AdapterSession session_;  // reader thread
    std::atomic<bool> open_{false};
    std::atomic<bool> timestamps_{false};
    std::atomic<std::uint8_t> latched_flags_{0};
    const Nanos epoch_ns_ = monotonic_ns();

    std::mutex write_mutex_;
    mutable std::mutex mutex_;
    std::condition_variable cv_;
    std::vector<Frame> queue_;
    bool stop_ = false;
    SlcanServerStats stats_;

    std::once_flag close_once_;
    std::thread reader_, writer_;
};

}  // namespace motorbus::can

// socketcand client: a CAN bus reached over TCP (linux-can/socketcand, or our
// SocketcandServer), in raw mode.
//
//   auto bus = open_socketcand("gateway.local", 29536, "can0");
//   bus->send(Frame::make(0x123, bytes));
//
// One receive thread reads the TCP stream, parses elements and dispatches
// frames.  Sends are encoded into a bounded transmit buffer: when the peer
// stops reading, send() blocks until its timeout (back-pressure) instead of
// buffering without limit.  An idle link is probed with `< echo >` and kernel
// TCP keepalive; no bytes for keepalive_misses x keepalive_period means the
// peer is gone (half-open TCP, K13): the bus turns bus-off and send() throws
// LinkDown.  EOF or a socket error does the same at once.
#pragma once
#include <atomic>
#include <condition_variable>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/socketcand_codec.hpp"
#include "motorbus/can/socketcand_net.hpp"

namespace motorbus::can {

struct SocketcandOptions : BusOptions {
    Duration connect_timeout = std::chrono::seconds(3);
    Duration handshake_timeout = std::chrono::seconds(3);  // hi / open / rawmode replies
    Duration keepalive_period = std::chrono::seconds(1);   // < echo > when idle; 0 = off
    int keepalive_misses = 3;                              // silent periods before LinkDown
    bool tcp_keepalive = true;                             // SO_KEEPALIVE as a second net
    std::size_t tx_buffer_bytes = 256 * 1024;              // unsent bytes before send() blocks
    std::size_t max_element = socketcand::kDefaultMaxElement;
};

// Throws InvalidArgument naming the field: keepalive_misses < 1, an empty
// transmit buffer (every send() would wait for room that never comes), a
// max_element a frame element cannot fit in, a negative duration.
void check_options(const SocketcandOptions& options);

class SocketcandBus final : public Bus {
public:
    // Connects and completes the handshake (< hi >, < open CHANNEL >, < ok >,
    // < rawmode >, < ok >).  Throws LinkDown (refused, closed, channel refused),
    // TimeoutError (no reply in time) or ProtocolError (unexpected reply).
    SocketcandBus(const std::string& host, std::uint16_t port, const std::string& channel,
                  const SocketcandOptions& options = {});
    ~SocketcandBus() override;

    bool link_up() const { return !link_down_.load(); }
    // Why the link went down (empty while it is up).
    std::string link_down_reason() const;
    // The last `< error ... >` message the server sent (e.g. a refused send).
    std::string last_server_error() const;
    socketcand::ParserStats parser_stats() const;
    const std::string& host() const { return host_; }
    std::uint16_t port() const { return port_; }

protected:
    void do_send(const Frame& frame, Deadline deadline) override;
    void do_close() override;

private:
    void handshake(const std::string& channel, Deadline deadline);
    void rx_loop();
    void handle(const socketcand::Element& e, Nanos now);
    std::vector<Frame> rx_batch_;  // frames parsed from one read, dispatched together
    // Appends one encoded element to the unsent bytes.
    void enqueue(const std::string_view element);
    // Writes what the socket takes now, as the one writer.  `wait_turn`: block
    // for another writer instead of leaving the bytes to it.  False on a socket error.
    bool write_some(bool wait_turn);
    void mark_link_down(const std::string& why);
    void account_parser();

    const SocketcandOptions opts_;
    const std::string host_;
    const std::uint16_t port_;
    net::Fd sock_;
    net::Wakeup wake_;
    std::atomic<bool> stop_{false};
    std::atomic<bool> link_down_{false};
    mutable std::mutex info_mutex_;
    std::string link_down_reason_;
    std::string last_server_error_;

    // Transmit path.  Senders append to pending_ under tx_mutex_ (held only
    // for the append); the socket is written by one writer at a time, under
    // write_mutex_, from writing_, so a sender never waits behind a system call.
    std::mutex tx_mutex_;
    std::condition_variable tx_space_cv_;  // unsent bytes went out
    std::string pending_;                  // tx_mutex_
    Deadline last_send_deadline_{};        // tx_mutex_
    std::mutex write_mutex_;
    std::string writing_;                  // write_mutex_
    std::size_t writing_off_ = 0;          // write_mutex_
    std::atomic<std::size_t> unsent_{0};   // bytes in pending_ and writing_
    std::atomic<bool> tx_pending_{false};  // unsent bytes wait for the receive thread

    socketcand::ElementParser parser_;  // receive thread only (and the handshake before it)
    socketcand::ParserStats parser_seen_;  // what has been counted into Bus counters
    mutable std::mutex stats_mutex_;
    socketcand::ParserStats stats_snapshot_;
    std::vector<Frame> early_frames_;  // frames that arrived together with the final < ok >
    std::atomic<Nanos> last_rx_ns_{0};
    std::thread rx_thread_;
};

std::shared_ptr<SocketcandBus> open_socketcand(const std::string& host, std::uint16_t port,
                                               const std::string& channel,
                                               const SocketcandOptions& options = {});

}  // namespace motorbus::can

// socketcand server (raw mode): exposes any motorbus Bus over TCP, so
// python-can's `socketcand` interface, socketcandcl, Kayak or our own
// SocketcandBus can join it.
//
//   auto server = std::make_shared<SocketcandServer>(open_virtual("bench"));
//   // clients connect to 127.0.0.1:server->port(), channel = any name
//
// Each TCP client is its own node on the bus, as with a real socketcand on a
// CAN interface: a frame a client sends goes onto the bus and to every other
// connected client; frames from the bus go to every client.
//
// Hostile clients (HOSTILE_INPUTS 2.8): unknown commands get
// `< error unknown command >` (K9), a bad `< send >` gets `< error REASON >`
// instead of silence (K10), a send the bus cannot take right now is retried
// with backoff and then reported with `< error ... >` while the session stays
// up (K11), a connection idle too long or stuck mid-element is closed (K14),
// and a client that reads slower than the bus talks loses its oldest frames,
// counted, instead of growing memory or stalling the bus (K15).
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/socketcand_codec.hpp"
#include "motorbus/can/socketcand_net.hpp"

namespace motorbus::can {

struct SocketcandServerOptions {
    std::string host = "127.0.0.1";
    std::uint16_t port = 0;          // 0 = pick a free port (see SocketcandServer::port())
    std::string channel;             // the name clients must open; empty = accept any name
    std::size_t max_clients = 64;
    std::size_t client_queue = 4096;  // frames waiting for one client before the oldest drops (K15)
    // K14.  idle_timeout is off by default: python-can clients that only
    // listen never send a byte, and they are legitimate.
    Duration idle_timeout = Duration::zero();
    Duration element_timeout = std::chrono::seconds(2);  // from '<' to its '>'
    Duration open_timeout = std::chrono::seconds(10);    // connect to `< open >`
    // K11: how long a client's send may be retried while the bus refuses it.
    Duration bus_send_budget = std::chrono::milliseconds(20);
    std::size_t max_element = socketcand::kDefaultMaxElement;
    int socket_send_buffer = 0;  // SO_SNDBUF for client sockets in bytes; 0 = kernel default
};

// Throws InvalidArgument naming the field: max_clients or client_queue 0, a
// channel name no client could open, a max_element out of range, a negative
// duration or send buffer.
void check_options(const SocketcandServerOptions& options);

struct SocketcandServerStats {
    std::uint64_t clients_accepted = 0;
    std::uint64_t clients_active = 0;
    std::uint64_t clients_refused = 0;        // over max_clients or unknown channel
    std::uint64_t timeouts = 0;               // connections closed by K14 timeouts
    std::uint64_t frames_to_bus = 0;          // client sends put on the bus
    std::uint64_t frames_to_clients = 0;      // frame elements written to clients
    std::uint64_t queue_drops = 0;            // frames dropped for slow clients (K15)
    std::uint64_t bus_send_retries = 0;       // K11 retries
    std::uint64_t bus_send_failures = 0;      // sends reported back with < error >
    std::uint64_t error_replies = 0;          // every < error ... > we sent
    std::uint64_t bad_elements = 0;           // malformed elements from clients
};

class SocketcandServer {
public:
    SocketcandServer(std::shared_ptr<Bus> bus, SocketcandServerOptions options = {});
    ~SocketcandServer();
    SocketcandServer(const SocketcandServer&) = delete;
    SocketcandServer& operator=(const SocketcandServer&) = delete;

    std::uint16_t port() const { return port_; }
    const std::string& host() const { return opts_.host; }
    SocketcandServerStats stats() const;
    // Per-client frames dropped for slowness, in accept order of the clients still connected.
    std::vector<std::uint64_t> client_drops() const;
    // Disconnects every client and stops listening.  The bus stays open.  Idempotent.
    void close();

private:
    struct Conn;
    void io_loop();
    void accept_clients();
    bool service_input(Conn& c, Nanos now);
    void handle(Conn& c, const socketcand::Element& e);
    void client_send(Conn& c, const Frame& f);
    void reply(Conn& c, std::string_view element);
    void reply_error(Conn& c, std::string_view message);
    void fill_output(Conn& c);
    bool flush(Conn& c);
    // Queues `f` for every raw-mode client except `except` (frames from the bus: nullptr).
    void broadcast(const Frame& f, const Conn* except);

    std::shared_ptr<Bus> bus_;
    SocketcandServerOptions opts_;
    std::uint16_t port_ = 0;
    net::Fd listen_;
    net::Wakeup wake_;
    std::atomic<bool> stop_{false};
    std::atomic<bool> io_sleeping_{false};   // the I/O thread is (about to be) in poll()
    std::atomic<bool> work_pending_{false};  // a client queue got frames since the last look
    std::once_flag close_once_;
    SubscriptionId sub_ = 0;
    Nanos wall_offset_ns_ = 0;  // realtime - monotonic, for socketcand's wall-clock timestamps

    mutable std::mutex conns_mutex_;  // guards the list; the I/O thread alone changes it
    std::vector<std::shared_ptr<Conn>> conns_;

    struct Counters {
        std::atomic<std::uint64_t> clients_accepted{0}, clients_refused{0}, timeouts{0},
            frames_to_bus{0}, frames_to_clients{0}, bus_send_retries{0}, bus_send_failures{0},
            error_replies{0}, bad_elements{0};
    } counters_;
    std::atomic<std::uint64_t> queue_drops_{0};
    std::uint64_t frames_to_bus_unpublished_ = 0;  // I/O thread only; see service_input
    std::thread io_thread_;
};

}  // namespace motorbus::can

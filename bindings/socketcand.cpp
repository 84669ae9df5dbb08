// Bindings for the TCP and kernel CAN backends: socketcand client and server,
// SocketCAN raw sockets.  Thin: argument conversion and GIL release only.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "can_filters.hpp"
#include "common.hpp"
#include "motorbus/can/socketcan_bus.hpp"
#include "motorbus/can/socketcand_bus.hpp"
#include "motorbus/can/socketcand_server.hpp"
#include "motorbus/errors.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::can;
using motorbus::py_helpers::Record;
using motorbus::py_helpers::seconds_to_ns;
using motorbus::py_helpers::interruptible_wait;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::not_none;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::finite_forever;
using motorbus::py_helpers::Forever;

namespace {

// Python seconds -> Duration; None -> `none_value`; inf -> forever only where
// `none_value` is itself "no limit" (a finite 31 years), else InvalidArgument.
Duration seconds_or(const py::object& t, const char* name, Duration none_value, Forever forever) {
    if (t.is_none()) return none_value;
    return finite_forever(duration_arg(t, name, forever));
}


}  // namespace

static void bind_socketcand_bus(py::module_& m) {
    using socketcand::ParserStats;
    Record<ParserStats>(m, "SocketcandParserStats", "The socketcand parser's view (SocketcandBus.parser_stats), read-only.")
        .field("elements", &ParserStats::elements, "well-formed elements delivered")
        .field("bad_elements", &ParserStats::bad_elements, "complete elements refused")
        .field("overlong", &ParserStats::overlong, "elements abandoned at the length cap")
        .field("interrupted", &ParserStats::interrupted, "elements cut short by a new '<'")
        .field("discarded_bytes", &ParserStats::discarded_bytes, "non-blank bytes outside any element");

    using Stats = SocketcandServerStats;
    Record<Stats>(m, "SocketcandServerStats", "SocketcandServer statistics, read-only.")
        .field("clients_accepted", &Stats::clients_accepted)
        .field("clients_active", &Stats::clients_active)
        .field("clients_refused", &Stats::clients_refused, "over max_clients or unknown channel")
        .field("timeouts", &Stats::timeouts, "connections closed by a timeout")
        .field("frames_to_bus", &Stats::frames_to_bus, "client sends put on the bus")
        .field("frames_to_clients", &Stats::frames_to_clients, "frame elements written to clients")
        .field("queue_drops", &Stats::queue_drops, "frames dropped for slow clients")
        .field("bus_send_retries", &Stats::bus_send_retries)
        .field("bus_send_failures", &Stats::bus_send_failures, "sends reported back with < error >")
        .field("error_replies", &Stats::error_replies, "every < error ... > sent")
        .field("bad_elements", &Stats::bad_elements, "malformed elements from clients");

    py::class_<SocketcandBus, Bus, std::shared_ptr<SocketcandBus>>(
        m, "SocketcandBus", "A CAN bus reached through a socketcand server (raw mode).")
        // Fast paths: try without giving up the GIL first (a frame is usually
        // already queued, and a send usually fits the buffer); release it only
        // when the call really has to wait.
        .def("send",
             [](SocketcandBus& b, const Frame& f, const py::object& timeout) {
                 auto t = seconds_to_ns(timeout);
                 try {
                     b.send(f, Duration::zero());
                     return;
                 } catch (const motorbus::TimeoutError&) {
                 }
                 // Ctrl-C live while the server is not reading (the wait is sliced).
                 blocking_call([&] { b.send(f, t.count() < 0 ? std::chrono::hours(24 * 365) : t); });
             },
             py::arg("frame"), py::arg("timeout") = 1.0)
        .def("recv",
             [](SocketcandBus& b, const py::object& timeout) -> std::optional<Frame> {
                 if (auto f = b.recv(Duration::zero())) return f;
                 auto t = seconds_to_ns(timeout);
                 if (t.count() == 0) return std::nullopt;
                 return interruptible_wait(t, [&](std::chrono::nanoseconds d) { return b.recv(d); });
             },
             py::arg("timeout") = py::none())
        .def_property_readonly("link_up", &SocketcandBus::link_up)
        .def_property_readonly("link_down_reason", &SocketcandBus::link_down_reason)
        .def_property_readonly("last_server_error", &SocketcandBus::last_server_error)
        .def_property_readonly("parser_stats", &SocketcandBus::parser_stats, "SocketcandParserStats (a snapshot)")
        .def_property_readonly("host", &SocketcandBus::host)
        .def_property_readonly("port", &SocketcandBus::port);

    m.def(
        "open_socketcand",
        [](const std::string& host, std::uint16_t port, const std::string& channel, bool receive_own,
           std::size_t rx_queue_size, const py::object& connect_timeout,
           const py::object& handshake_timeout, const py::object& keepalive, int keepalive_misses,
           bool tcp_keepalive, std::size_t tx_buffer_bytes) {
            SocketcandOptions o;
            o.receive_own = receive_own;
            o.rx_queue_size = rx_queue_size;
            o.connect_timeout = seconds_or(connect_timeout, "connect_timeout", std::chrono::hours(1), Forever::Allowed);
            o.handshake_timeout = seconds_or(handshake_timeout, "handshake_timeout", std::chrono::hours(1), Forever::Allowed);
            o.keepalive_period = seconds_or(keepalive, "keepalive", Duration::zero(), Forever::Refused);
            o.keepalive_misses = keepalive_misses;
            o.tcp_keepalive = tcp_keepalive;
            o.tx_buffer_bytes = tx_buffer_bytes;
            // Connect and handshake poll in slices: Ctrl-C returns at once.
            return blocking_call([&] { return open_socketcand(host, port, channel, o); });
        },
        py::arg("host"), py::arg("port"), py::arg("channel"), py::arg("receive_own") = false,
        py::arg("rx_queue_size") = 65536, py::arg("connect_timeout") = 3.0,
        py::arg("handshake_timeout") = 3.0, py::arg("keepalive") = 1.0,
        py::arg("keepalive_misses") = 3, py::arg("tcp_keepalive") = true,
        py::arg("tx_buffer_bytes") = 256 * 1024,
        "Connect to a socketcand server and open CHANNEL in raw mode. keepalive: seconds between "
        "< echo > probes on an idle link (None = off); the link is declared down after "
        "keepalive_misses silent periods.");
}

static void bind_socketcand_server(py::module_& m) {
    py::class_<SocketcandServer, std::shared_ptr<SocketcandServer>>(
        m, "SocketcandServer",
        "Serve a motorbus Bus over TCP with the socketcand protocol (raw mode). Each client is a "
        "node on the bus: its frames go to the bus and to the other clients.")
        .def(py::init([](std::shared_ptr<Bus> bus, const std::string& host, std::uint16_t port,
                         const std::string& channel, std::size_t max_clients,
                         std::size_t client_queue, const py::object& idle_timeout,
                         const py::object& element_timeout, const py::object& open_timeout,
                         const py::object& bus_send_budget) {
                 not_none(bus, "bus");
                 SocketcandServerOptions o;
                 o.host = host;
                 o.port = port;
                 o.channel = channel;
                 o.max_clients = max_clients;
                 o.client_queue = client_queue;
                 o.idle_timeout = seconds_or(idle_timeout, "idle_timeout", Duration::zero(), Forever::Refused);
                 o.element_timeout = seconds_or(element_timeout, "element_timeout", std::chrono::hours(24 * 365), Forever::Allowed);
                 o.open_timeout = seconds_or(open_timeout, "open_timeout", std::chrono::hours(24 * 365), Forever::Allowed);
                 o.bus_send_budget = seconds_or(bus_send_budget, "bus_send_budget", Duration::zero(), Forever::Refused);
                 py::gil_scoped_release nogil;
                 return std::make_shared<SocketcandServer>(std::move(bus), o);
             }),
             py::arg("bus"), py::arg("host") = "127.0.0.1", py::arg("port") = 0,
             py::arg("channel") = "", py::arg("max_clients") = 64, py::arg("client_queue") = 4096,
             py::arg("idle_timeout") = py::none(), py::arg("element_timeout") = 2.0,
             py::arg("open_timeout") = 10.0, py::arg("bus_send_budget") = 0.02)
        .def_property_readonly("port", &SocketcandServer::port)
        .def_property_readonly("host", &SocketcandServer::host)
        .def_property_readonly("stats", &SocketcandServer::stats, "SocketcandServerStats (a snapshot)")
        .def_property_readonly("client_drops", &SocketcandServer::client_drops)
        .def("close", &SocketcandServer::close, py::call_guard<py::gil_scoped_release>())
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](SocketcandServer& s, py::args) {
            py::gil_scoped_release nogil;
            s.close();
        })
        .def("__repr__", [](const SocketcandServer& s) {
            return "SocketcandServer(" + s.host() + ":" + std::to_string(s.port()) + ")";
        });
}

static void bind_socketcan(py::module_& m) {
    py::class_<SocketCanBus, Bus, std::shared_ptr<SocketCanBus>>(
        m, "SocketCanBus", "A Linux AF_CAN raw socket (can0, vcan0, ...).");

    m.def(
        "open_socketcan",
        [](const std::string& iface, bool receive_own, std::size_t rx_queue_size,
           const py::object& kernel_filters, bool error_frames, bool fd) {
            SocketCanOptions o;
            o.receive_own = receive_own;
            o.rx_queue_size = rx_queue_size;
            o.kernel_filters = motorbus::py_helpers::filters_from_py(kernel_filters);
            o.error_frames = error_frames;
            o.fd = fd;
            py::gil_scoped_release nogil;
            return open_socketcan(iface, o);
        },
        py::arg("iface"), py::arg("receive_own") = false, py::arg("rx_queue_size") = 65536,
        py::arg("kernel_filters") = py::none(), py::arg("error_frames") = true,
        py::arg("fd") = false,
        "Open a SocketCAN interface. kernel_filters: python-can style dicts "
        "{'can_id', 'can_mask', 'extended'} applied in the kernel (CAN_RAW_FILTER).");

    m.def("socketcan_unavailable_reason",
          []() -> py::object {
              auto why = socketcan::unavailable_reason();
              if (!why) return py::none();
              return py::str(*why);
          },
          "None when AF_CAN raw sockets work on this machine, else why not.");
}

void bind_socketcand(py::module_& m) {
    bind_socketcand_bus(m);
    bind_socketcand_server(m);
    bind_socketcan(m);
}

// Bindings for SLCAN: open_slcan() -> SlcanBus, SlcanServer (an SLCAN adapter
// on a pty serving any Bus), and the pure codec for tests and fuzzing.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "motorbus/can/slcan_bus.hpp"
#include "motorbus/can/slcan_codec.hpp"
#include "motorbus/can/slcan_server.hpp"
#include "motorbus/errors.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::can;
using motorbus::py_helpers::seconds_to_ns;

namespace {

Duration secs(double s) {
    if (!(s >= 0)) throw InvalidArgument("duration: must be >= 0 seconds");
    return std::chrono::nanoseconds(static_cast<std::int64_t>(s * 1e9));
}

py::dict stats_dict(const SlcanStats& s) {
    py::dict d;
    d["acks"] = s.acks;
    d["nacks"] = s.nacks;
    d["ack_timeouts"] = s.ack_timeouts;
    d["echoes_suppressed"] = s.echoes_suppressed;
    d["link_downs"] = s.link_downs;
    d["reconnects"] = s.reconnects;
    d["partial_lines_dropped"] = s.partial_lines_dropped;
    d["status_replies"] = s.status_replies;
    d["last_status"] = s.last_status;
    d["link_up"] = s.link_up;
    d["version"] = s.version;
    d["serial_number"] = s.serial_number;
    return d;
}

py::dict server_stats_dict(const SlcanServerStats& s) {
    py::dict d;
    d["commands"] = s.commands;
    d["invalid_commands"] = s.invalid_commands;
    d["transmitted"] = s.transmitted;
    d["transmit_failed"] = s.transmit_failed;
    d["forwarded"] = s.forwarded;
    d["forward_dropped"] = s.forward_dropped;
    d["open"] = s.open;
    return d;
}

py::dict event_dict(const slcan::Event& e) {
    py::dict d;
    d["kind"] = slcan::to_string(e.kind);
    switch (e.kind) {
        case slcan::EventKind::Frame:
            d["frame"] = e.frame;
            d["timestamp_ms"] = e.timestamp_ms ? py::object(py::int_(*e.timestamp_ms)) : py::none();
            break;
        case slcan::EventKind::TxAck: d["extended"] = e.extended; break;
        case slcan::EventKind::Status:
            d["status"] = e.status;
            d["state"] = to_string(e.state);
            break;
        case slcan::EventKind::ErrorReport: d["error_bits"] = e.error_bits; break;
        case slcan::EventKind::StateReport:
            d["state"] = to_string(e.state);
            d["rx_errors"] = e.rx_errors;
            d["tx_errors"] = e.tx_errors;
            break;
        default: break;
    }
    if (!e.text.empty()) d["text"] = py::bytes(e.text.data(), e.text.size());
    return d;
}

}  // namespace

void bind_slcan(py::module_& m) {
    py::class_<SlcanBus, Bus, std::shared_ptr<SlcanBus>>(
        m, "SlcanBus", "A CAN bus through an SLCAN (Lawicel) adapter on a serial port.")
        .def("flush_tx",
             [](SlcanBus& b, double timeout) {
                 auto t = secs(timeout);
                 py::gil_scoped_release nogil;
                 b.flush_tx(t);
             },
             py::arg("timeout") = 1.0,
             "Wait until the adapter answered every command; ProtocolError if it refused frames.")
        .def("query_status",
             [](SlcanBus& b, double timeout) {
                 auto t = secs(timeout);
                 py::gil_scoped_release nogil;
                 return b.query_status(t);
             },
             py::arg("timeout") = 1.0, "Send `F`, return the status flags (bus state is updated).")
        .def_property_readonly("stats", [](const SlcanBus& b) { return stats_dict(b.stats()); })
        .def_property_readonly("link_up", &SlcanBus::link_up);

    m.def("open_slcan",
          [](const std::string& path, unsigned bitrate, bool timestamps, bool echo_suppression,
             bool listen_only, bool wait_for_acks, std::size_t tx_window, double ack_timeout,
             double open_timeout, double status_poll, unsigned tty_baud, const py::object& btr,
             bool receive_own, std::size_t rx_queue_size, double tx_coalesce) {
              SlcanOptions o;
              o.timestamps = timestamps;
              o.echo_suppression = echo_suppression;
              o.listen_only = listen_only;
              o.wait_for_acks = wait_for_acks;
              o.tx_window = tx_window;
              o.ack_timeout = secs(ack_timeout);
              o.open_timeout = secs(open_timeout);
              o.status_poll = secs(status_poll);
              o.tty_baud = tty_baud;
              o.tx_coalesce = secs(tx_coalesce);
              if (!btr.is_none()) {
                  auto v = btr.cast<unsigned>();
                  if (v > 0xFFFF) throw InvalidArgument("btr: BTR0<<8|BTR1 must be 0-0xFFFF");
                  o.btr = static_cast<std::uint16_t>(v);
              }
              o.bus.receive_own = receive_own;
              o.bus.rx_queue_size = rx_queue_size;
              py::gil_scoped_release nogil;
              return open_slcan(path, bitrate, o);
          },
          py::arg("path"), py::arg("bitrate") = 500000, py::arg("timestamps") = false,
          py::arg("echo_suppression") = false, py::arg("listen_only") = false,
          py::arg("wait_for_acks") = true, py::arg("tx_window") = 16, py::arg("ack_timeout") = 1.0,
          py::arg("open_timeout") = 1.0, py::arg("status_poll") = 0.0, py::arg("tty_baud") = 115200,
          py::arg("btr") = py::none(), py::arg("receive_own") = false,
          py::arg("rx_queue_size") = 65536, py::arg("tx_coalesce") = 20e-6,
          "Open an SLCAN adapter at `path` (C, Sn, [Z1], O) as a Bus; reconnects after unplug.");

    py::class_<SlcanServer, std::shared_ptr<SlcanServer>>(
        m, "SlcanServer",
        "Serve a Bus as an SLCAN adapter on a new pty; SLCAN tools open `pty_path`.")
        .def(py::init([](std::shared_ptr<Bus> bus, std::size_t queue_size, const std::string& version,
                         const std::string& serial_number, double bus_send_timeout,
                         const py::object& port, unsigned baud) {
                 SlcanServerOptions o;
                 o.queue_size = queue_size;
                 o.identity.version = version;
                 o.identity.serial = serial_number;
                 o.bus_send_timeout = secs(bus_send_timeout);
                 std::string path = port.is_none() ? std::string() : port.cast<std::string>();
                 py::gil_scoped_release nogil;
                 if (path.empty()) return std::make_shared<SlcanServer>(std::move(bus), o);
                 return std::make_shared<SlcanServer>(std::move(bus), serial::open_port(path, baud), o);
             }),
             py::arg("bus"), py::arg("queue_size") = 65536, py::arg("version") = "V1013",
             py::arg("serial_number") = "NMB01", py::arg("bus_send_timeout") = 0.1,
             py::arg("port") = py::none(), py::arg("baud") = 115200,
             "Serve `bus` on a new pty, or on the serial device `port` (a UART wired to an SLCAN host).")
        .def_property_readonly("pty_path",
                               [](const SlcanServer& s) -> py::object {
                                   if (s.pty_path().empty()) return py::none();  // serving a real port
                                   return py::str(s.pty_path());
                               })
        .def_property_readonly("is_open", &SlcanServer::is_open)
        .def_property_readonly("stats", [](const SlcanServer& s) { return server_stats_dict(s.stats()); })
        .def("close", &SlcanServer::close, py::call_guard<py::gil_scoped_release>())
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](SlcanServer& s, py::args) {
            py::gil_scoped_release nogil;
            s.close();
        });

    // Pure codec, for tests and fuzzing from Python.
    m.def("slcan_encode",
          [](const Frame& f, const py::object& timestamp_ms) {
              std::optional<std::uint16_t> ts;
              if (!timestamp_ms.is_none()) {
                  auto v = timestamp_ms.cast<unsigned>();
                  if (v > slcan::kMaxTimestamp) throw InvalidArgument("slcan timestamp: must be 0-59999 ms");
                  ts = static_cast<std::uint16_t>(v);
              }
              return py::bytes(slcan::encode_frame(f, ts));
          },
          py::arg("frame"), py::arg("timestamp_ms") = py::none(),
          "The SLCAN line for `frame` (t/T/r/R, CR included).");

    py::class_<slcan::StreamDecoder>(m, "SlcanDecoder",
                                     "Incremental adapter->host SLCAN decoder (bounded, never raises).")
        .def(py::init<>())
        .def("feed",
             [](slcan::StreamDecoder& d, const py::bytes& data) {
                 std::string_view s = data;
                 py::list out;
                 d.feed(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()),
                        [&](const slcan::Event& e) { out.append(event_dict(e)); });
                 return out;
             },
             py::arg("data"), "Feed bytes; returns a list of event dicts (kind, frame, status, ...).")
        .def("discard_partial", &slcan::StreamDecoder::discard_partial)
        .def_property_readonly("pending", &slcan::StreamDecoder::pending)
        .def_property_readonly("counters", [](const slcan::StreamDecoder& d) {
            const auto& c = d.counters();
            py::dict r;
            r["frames"] = c.frames;
            r["rx_errors"] = c.rx_errors;
            r["rx_over_errors"] = c.rx_over_errors;
            r["ignored"] = c.ignored;
            r["dropped_partial"] = c.dropped_partial;
            return r;
        });
}

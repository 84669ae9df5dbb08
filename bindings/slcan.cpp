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
using motorbus::py_helpers::Record;
using motorbus::py_helpers::seconds_to_ns;
using motorbus::py_helpers::arg_cast;
using motorbus::py_helpers::not_none;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::finite_forever;
using motorbus::py_helpers::Forever;

namespace {



// A decoded event that owns its line bytes (Event::text is only valid during
// the decoder's callback).
struct EventRecord {
    slcan::Event event;
    std::string text;
};

}  // namespace

static void bind_slcan_records(py::module_& m) {
    Record<SlcanStats>(m, "SlcanStats", "SLCAN link statistics (SlcanBus.stats), read-only.")
        .field("acks", &SlcanStats::acks, "CR / z / Z answering a command")
        .field("nacks", &SlcanStats::nacks, "BEL answering a command (or unsolicited)")
        .field("ack_timeouts", &SlcanStats::ack_timeouts, "commands never answered within ack_timeout")
        .field("echoes_suppressed", &SlcanStats::echoes_suppressed)
        .field("link_downs", &SlcanStats::link_downs)
        .field("reconnects", &SlcanStats::reconnects, "successful re-opens after a link down")
        .field("partial_lines_dropped", &SlcanStats::partial_lines_dropped)
        .field("status_replies", &SlcanStats::status_replies)
        .field("last_status", &SlcanStats::last_status, "last `F` flags")
        .field("link_up", &SlcanStats::link_up)
        .field("version", &SlcanStats::version, "last `V` reply, e.g. 'V1013'")
        .field("serial_number", &SlcanStats::serial_number, "last `N` reply");

    Record<SlcanServerStats>(m, "SlcanServerStats", "SlcanServer statistics, read-only.")
        .field("commands", &SlcanServerStats::commands)
        .field("invalid_commands", &SlcanServerStats::invalid_commands,
               "answered BEL because malformed/unknown/refused")
        .field("transmitted", &SlcanServerStats::transmitted, "frames put on the bus for the peer")
        .field("transmit_failed", &SlcanServerStats::transmit_failed, "the bus refused them (answered BEL)")
        .field("forwarded", &SlcanServerStats::forwarded, "bus frames written to the peer")
        .field("forward_dropped", &SlcanServerStats::forward_dropped, "queue full or peer not reading")
        .field("open", &SlcanServerStats::open);

    Record<slcan::DecoderCounters>(m, "SlcanDecoderCounters", "SlcanDecoder counters, read-only.")
        .field("frames", &slcan::DecoderCounters::frames)
        .field("rx_errors", &slcan::DecoderCounters::rx_errors, "malformed lines")
        .field("rx_over_errors", &slcan::DecoderCounters::rx_over_errors, "lines longer than 32 bytes")
        .field("ignored", &slcan::DecoderCounters::ignored, "unknown or unsupported non-frame lines")
        .field("dropped_partial", &slcan::DecoderCounters::dropped_partial,
               "partial lines dropped by discard_partial()");

    py::enum_<slcan::EventKind>(m, "SlcanEventKind", "What an adapter->host SLCAN line was.")
        .value("FRAME", slcan::EventKind::Frame)
        .value("OK", slcan::EventKind::Ok)
        .value("NACK", slcan::EventKind::Nack)
        .value("TX_ACK", slcan::EventKind::TxAck)
        .value("STATUS", slcan::EventKind::Status)
        .value("VERSION", slcan::EventKind::Version)
        .value("SERIAL", slcan::EventKind::Serial)
        .value("ERROR_REPORT", slcan::EventKind::ErrorReport)
        .value("STATE_REPORT", slcan::EventKind::StateReport)
        .value("UNKNOWN", slcan::EventKind::Unknown)
        .value("MALFORMED", slcan::EventKind::Malformed)
        .value("OVERFLOW", slcan::EventKind::Overflow);

    // Fields that do not apply to an event's kind hold their defaults (0, False, None).
    Record<EventRecord>(m, "SlcanEvent", "One decoded adapter->host SLCAN line, read-only.")
        .prop("kind", [](const EventRecord& r) { return r.event.kind; })
        .prop("frame", [](const EventRecord& r) -> std::optional<Frame> {
            if (r.event.kind != slcan::EventKind::Frame) return std::nullopt;
            return r.event.frame;
        }, "the frame (FRAME), else None")
        .prop("timestamp_ms", [](const EventRecord& r) { return r.event.timestamp_ms; },
              "adapter timestamp of a FRAME (Z1), else None")
        .prop("extended", [](const EventRecord& r) { return r.event.extended; }, "TX_ACK: `Z` (extended)")
        .prop("status", [](const EventRecord& r) { return r.event.status; }, "STATUS: the `F` flags")
        .prop("state", [](const EventRecord& r) { return std::string(to_string(r.event.state)); },
              "STATUS / STATE_REPORT: bus state, as Bus.state")
        .prop("error_bits", [](const EventRecord& r) { return r.event.error_bits; }, "ERROR_REPORT")
        .prop("rx_errors", [](const EventRecord& r) { return r.event.rx_errors; }, "STATE_REPORT")
        .prop("tx_errors", [](const EventRecord& r) { return r.event.tx_errors; }, "STATE_REPORT")
        .prop("text", [](const EventRecord& r) { return py::bytes(r.text); }, "the line's bytes (no terminator)");
}

static void bind_slcan_bus(py::module_& m) {
    py::class_<SlcanBus, Bus, std::shared_ptr<SlcanBus>>(
        m, "SlcanBus", "A CAN bus through an SLCAN (Lawicel) adapter on a serial port.")
        .def("flush_tx",
             [](SlcanBus& b, const py::object& timeout) {
                 auto t = finite_forever(duration_arg(timeout, "timeout", Forever::Allowed));
                 blocking_call([&] { b.flush_tx(t); });
             },
             py::arg("timeout") = 1.0,
             "Wait until the adapter answered every command (None = forever; Ctrl-C interrupts); "
             "ProtocolError if it refused frames.")
        .def("query_status",
             [](SlcanBus& b, const py::object& timeout) {
                 auto t = finite_forever(duration_arg(timeout, "timeout", Forever::Allowed));
                 return blocking_call([&] { return b.query_status(t); });
             },
             py::arg("timeout") = 1.0, "Send `F`, return the status flags (bus state is updated).")
        .def_property_readonly("stats", &SlcanBus::stats, "SlcanStats (a snapshot)")
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
              o.ack_timeout = duration_arg(ack_timeout, "ack_timeout");
              o.open_timeout = duration_arg(open_timeout, "open_timeout");
              o.status_poll = duration_arg(status_poll, "status_poll");
              o.tty_baud = tty_baud;
              o.tx_coalesce = duration_arg(tx_coalesce, "tx_coalesce");
              if (!btr.is_none()) {
                  auto v = arg_cast<unsigned>(btr, "btr", "an int 0-0xFFFF or None");
                  if (v > 0xFFFF) throw InvalidArgument("btr: BTR0<<8|BTR1 must be 0-0xFFFF");
                  o.btr = static_cast<std::uint16_t>(v);
              }
              o.bus.receive_own = receive_own;
              o.bus.rx_queue_size = rx_queue_size;
              // The open sequence waits for the adapter in slices: Ctrl-C returns at once.
              return blocking_call([&] { return open_slcan(path, bitrate, o); });
          },
          py::arg("path"), py::arg("bitrate") = 500000, py::arg("timestamps") = false,
          py::arg("echo_suppression") = false, py::arg("listen_only") = false,
          py::arg("wait_for_acks") = true, py::arg("tx_window") = 16, py::arg("ack_timeout") = 1.0,
          py::arg("open_timeout") = 1.0, py::arg("status_poll") = 0.0, py::arg("tty_baud") = 115200,
          py::arg("btr") = py::none(), py::arg("receive_own") = false,
          py::arg("rx_queue_size") = 65536, py::arg("tx_coalesce") = 20e-6,
          "Open an SLCAN adapter at `path` (C, Sn, [Z1], O) as a Bus; bitrate 0 keeps the adapter's rate (no Sn); reconnects after unplug.");

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
                 o.bus_send_timeout = duration_arg(bus_send_timeout, "bus_send_timeout");
                 not_none(bus, "bus");
                 std::string path = port.is_none() ? std::string() : arg_cast<std::string>(port, "port", "a device path or None");
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
        .def_property_readonly("stats", &SlcanServer::stats, "SlcanServerStats (a snapshot)")
        .def("close", &SlcanServer::close, py::call_guard<py::gil_scoped_release>())
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](SlcanServer& s, py::args) {
            py::gil_scoped_release nogil;
            s.close();
        });
}

static void bind_slcan_codec(py::module_& m) {
    // Pure codec, for tests and fuzzing from Python.
    m.def("slcan_encode",
          [](const Frame& f, const py::object& timestamp_ms) {
              std::optional<std::uint16_t> ts;
              if (!timestamp_ms.is_none()) {
                  auto v = arg_cast<unsigned>(timestamp_ms, "timestamp_ms", "an int 0-59999 or None");
                  // Past 65535 it stays out of range: the core refuses more than 59999 ms.
                  ts = static_cast<std::uint16_t>(std::min<unsigned>(v, std::numeric_limits<std::uint16_t>::max()));
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
                 std::vector<EventRecord> out;
                 d.feed(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()),
                        [&](const slcan::Event& e) {
                            out.push_back({e, std::string(e.text)});
                            out.back().event.text = {};
                        });
                 return out;
             },
             py::arg("data"), "Feed bytes; returns the decoded SlcanEvents.")
        .def("discard_partial", &slcan::StreamDecoder::discard_partial)
        .def_property_readonly("pending", &slcan::StreamDecoder::pending)
        .def_property_readonly("counters", &slcan::StreamDecoder::counters, py::return_value_policy::copy,
                               "SlcanDecoderCounters (a snapshot)");
}

void bind_slcan(py::module_& m) {
    bind_slcan_records(m);
    bind_slcan_bus(m);
    bind_slcan_codec(m);
}

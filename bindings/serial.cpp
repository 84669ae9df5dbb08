// Bindings for cpp/motorbus/serial: ports, the line link, line devices and the
// pty line server.  Every call that can block releases the GIL; the server
// thread takes it back only to call a Python LineDevice.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "errors.hpp"
#include "common.hpp"
#include "motorbus/errors.hpp"
#include "motorbus/serial/echo_device.hpp"
#include "motorbus/serial/line_device.hpp"
#include "motorbus/serial/line_server.hpp"
#include "motorbus/serial/port.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::serial;
using motorbus::py_helpers::seconds_to_ns;

namespace {

// str (UTF-8), bytes, bytearray or memoryview -> raw bytes.
std::string bytes_arg(const py::handle& h, const char* what) {
    if (py::isinstance<py::str>(h)) return h.cast<std::string>();
    if (py::isinstance<py::bytes>(h)) return h.cast<std::string>();
    if (py::isinstance<py::bytearray>(h) || py::isinstance<py::memoryview>(h))
        return py::bytes(py::reinterpret_borrow<py::object>(h)).cast<std::string>();
    throw InvalidArgument(std::string(what) + ": expected str or bytes, got " +
                          py::str(py::type::handle_of(h).attr("__name__")).cast<std::string>());
}

py::bytes to_py(const std::string& s) { return py::bytes(s.data(), s.size()); }

// A Python subclass of LineDevice.  The server thread calls these without the
// GIL, so each takes it; a Python exception must not escape into the server
// (the contract says devices never throw), so it is reported as unraisable.
class PyLineDevice : public LineDevice {
public:
    std::string on_line(std::string_view line) override {
        py::gil_scoped_acquire gil;
        try {
            py::function f = py::get_override(static_cast<const LineDevice*>(this), "on_line");
            if (!f) return {};
            return reply(f(py::bytes(line.data(), line.size())));
        } catch (py::error_already_set& e) {
            e.discard_as_unraisable("motorbus LineDevice.on_line");
        } catch (const std::exception&) {
        }
        return {};
    }
    std::string request_terminator() const override {
        py::gil_scoped_acquire gil;
        try {
            py::function f = py::get_override(static_cast<const LineDevice*>(this), "request_terminator");
            if (f) return bytes_arg(f(), "request_terminator");
        } catch (py::error_already_set& e) {
            e.discard_as_unraisable("motorbus LineDevice.request_terminator");
        } catch (const std::exception&) {
        }
        return LineDevice::request_terminator();
    }
    std::size_t max_request() const override {
        py::gil_scoped_acquire gil;
        try {
            py::function f = py::get_override(static_cast<const LineDevice*>(this), "max_request");
            if (f) return f().cast<std::size_t>();
        } catch (py::error_already_set& e) {
            e.discard_as_unraisable("motorbus LineDevice.max_request");
        } catch (const std::exception&) {
        }
        return LineDevice::max_request();
    }
    std::string on_overlong() override {
        py::gil_scoped_acquire gil;
        try {
            py::function f = py::get_override(static_cast<const LineDevice*>(this), "on_overlong");
            if (f) return reply(f());
        } catch (py::error_already_set& e) {
            e.discard_as_unraisable("motorbus LineDevice.on_overlong");
        } catch (const std::exception&) {
        }
        return LineDevice::on_overlong();
    }

private:
    static std::string reply(const py::object& r) {
        if (r.is_none()) return {};
        return bytes_arg(r, "LineDevice reply");
    }
};

// The Python-facing server: also owns the Python device objects so a Python
// subclass lives as long as the thread that calls it.
class PyLineServer {
public:
    PyLineServer(const std::vector<py::object>& devices, unsigned baud, std::shared_ptr<Port> port) {
        std::vector<std::shared_ptr<LineDevice>> devs;
        for (const auto& d : devices) devs.push_back(d.cast<std::shared_ptr<LineDevice>>());
        keep_ = devices;
        py::gil_scoped_release nogil;
        server_ = port ? std::make_unique<PtyLineServer>(std::move(port), std::move(devs), baud)
                       : std::make_unique<PtyLineServer>(std::move(devs), baud);
    }
    ~PyLineServer() {
        if (!server_) return;
        // The thread may be waiting for the GIL to call a Python device.
        if (PyGILState_Check()) {
            py::gil_scoped_release nogil;
            server_->close();
        } else {
            server_->close();
        }
    }
    void attach(const py::object& device) {
        auto d = device.cast<std::shared_ptr<LineDevice>>();
        keep_.push_back(device);
        py::gil_scoped_release nogil;
        server_->attach(std::move(d));
    }
    void close() {
        py::gil_scoped_release nogil;
        server_->close();
    }
    PtyLineServer& get() { return *server_; }

private:
    std::unique_ptr<PtyLineServer> server_;
    std::vector<py::object> keep_;
};

py::dict link_counters(const LineCounters& c) {
    py::dict d;
    d["bytes_in"] = c.bytes_in;
    d["bytes_out"] = c.bytes_out;
    d["requests"] = c.requests;
    d["replies"] = c.replies;
    d["timeouts"] = c.timeouts;
    d["stale_bytes"] = c.stale_bytes;
    d["overlong_lines"] = c.overlong_lines;
    d["echo_bytes"] = c.echo_bytes;
    d["echo_mismatches"] = c.echo_mismatches;
    return d;
}

py::dict server_counters(const LineServerCounters& c) {
    py::dict d;
    d["bytes_in"] = c.bytes_in;
    d["bytes_out"] = c.bytes_out;
    d["lines"] = c.lines;
    d["overlong_lines"] = c.overlong_lines;
    d["replies"] = c.replies;
    d["device_errors"] = c.device_errors;
    d["dropped_replies"] = c.dropped_replies;
    return d;
}

std::chrono::nanoseconds nonneg_seconds(double s, const char* what) {
    if (!(s >= 0) || s > 1e6) throw InvalidArgument(std::string(what) + ": must be in [0, 1e6] seconds");
    return std::chrono::nanoseconds(static_cast<std::int64_t>(s * 1e9));
}

}  // namespace

namespace {
void fill_reply_too_long(py::object& exc, const ReplyTooLong& e) {
    exc.attr("data") = py::bytes(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size());
}
}  // namespace

void bind_serial(py::module_& m) {
    // ReplyTooLong(ProtocolError): a distinct class so callers can catch it alone.
    py_errors::add_error_classes(m, {{"ReplyTooLong", {"ProtocolError"},
        "A reply exceeded max_line; it was discarded up to its terminator. .data holds its first bytes."}});
    py_errors::translate<ReplyTooLong, fill_reply_too_long>(m.attr("ReplyTooLong"));

    py::class_<Port, std::shared_ptr<Port>>(m, "Port", "A bidirectional byte stream (serial port, pty side).")
        .def(
            "write",
            [](Port& p, const py::object& data) {
                std::string b = bytes_arg(data, "write");
                py::gil_scoped_release nogil;
                p.write({reinterpret_cast<const std::uint8_t*>(b.data()), b.size()});
            },
            py::arg("data"), "Writes all bytes (blocking). LinkDown if the peer is gone.")
        .def(
            "read",
            [](Port& p, std::size_t size, const py::object& timeout) {
                if (size == 0 || size > (1u << 20)) throw InvalidArgument("read size: must be in [1, 1048576]");
                auto t = seconds_to_ns(timeout);
                std::string buf(size, '\0');
                std::size_t n;
                {
                    py::gil_scoped_release nogil;
                    n = p.read({reinterpret_cast<std::uint8_t*>(buf.data()), buf.size()}, t);
                }
                return py::bytes(buf.data(), n);
            },
            py::arg("size") = 4096, py::arg("timeout") = py::none(),
            "Returns what is available (b'' on timeout); waits up to `timeout` s for the first byte "
            "(None = forever). LinkDown on EOF/EIO.")
        .def("flush_input", &Port::flush_input, py::call_guard<py::gil_scoped_release>())
        .def("drain", &Port::drain, py::call_guard<py::gil_scoped_release>())
        .def("close", &Port::close, py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("name", &Port::name)
        .def("__enter__", [](std::shared_ptr<Port> p) { return p; })
        .def("__exit__", [](Port& p, py::args) {
            py::gil_scoped_release nogil;
            p.close();
        });

    py::class_<TtyPort, Port, std::shared_ptr<TtyPort>>(m, "TtyPort",
                                                        "A termios serial device in raw 8N1 mode.")
        .def(py::init<const std::string&, unsigned>(), py::arg("path"), py::arg("baud") = 0,
             py::call_guard<py::gil_scoped_release>())
        .def_property("baud", &TtyPort::baud, &TtyPort::set_baud)
        .def("set_baud", &TtyPort::set_baud, py::arg("baud"))
        .def(
            "set_write_timeout",
            [](TtyPort& p, const py::object& t) { p.set_write_timeout(seconds_to_ns(t)); },
            py::arg("timeout"))
        .def_property_readonly("is_open", &TtyPort::is_open);

    py::class_<PtyPair, std::shared_ptr<PtyPair>>(m, "PtyPair",
                                                  "A raw pseudo-terminal: .port is ours, .slave_path is for a peer.")
        .def(py::init<>())
        .def_property_readonly("slave_path", &PtyPair::slave_path)
        .def_property_readonly("port", &PtyPair::master)
        .def("open_slave", &PtyPair::open_slave, py::arg("baud") = 0, py::call_guard<py::gil_scoped_release>())
        .def("release_slave", &PtyPair::release_slave)
        .def("close", &PtyPair::close, py::call_guard<py::gil_scoped_release>())
        .def("__enter__", [](std::shared_ptr<PtyPair> p) { return p; })
        .def("__exit__", [](PtyPair& p, py::args) {
            py::gil_scoped_release nogil;
            p.close();
        });

    m.def("open_port", &open_port, py::arg("path"), py::arg("baud") = 0,
          py::call_guard<py::gil_scoped_release>(), "Opens a serial device at `baud` (0 = keep the current speed).");

    py::class_<LineLink, std::shared_ptr<LineLink>>(m, "LineLink", "Request/reply line framing on a Port.")
        .def(py::init([](std::shared_ptr<Port> port, const py::object& request_terminator,
                         const py::object& reply_terminators, std::size_t max_line, const py::object& reply_timeout,
                         bool flush_before_request, bool echo_suppression, double turnaround) {
                 LineOptions o;
                 o.request_terminator = bytes_arg(request_terminator, "request_terminator");
                 o.reply_terminators.clear();
                 if (py::isinstance<py::str>(reply_terminators) || py::isinstance<py::bytes>(reply_terminators)) {
                     o.reply_terminators.push_back(bytes_arg(reply_terminators, "reply_terminators"));
                 } else {
                     for (auto t : reply_terminators) o.reply_terminators.push_back(bytes_arg(t, "reply_terminators"));
                 }
                 o.max_line = max_line;
                 o.reply_timeout = seconds_to_ns(reply_timeout);
                 o.flush_before_request = flush_before_request;
                 o.echo_suppression = echo_suppression;
                 o.turnaround = nonneg_seconds(turnaround, "turnaround");
                 return std::make_shared<LineLink>(std::move(port), std::move(o));
             }),
             py::arg("port"), py::arg("request_terminator") = "\r",
             py::arg("reply_terminators") = std::vector<std::string>{"\r\n"}, py::arg("max_line") = 256,
             py::arg("reply_timeout") = 0.5, py::arg("flush_before_request") = true,
             py::arg("echo_suppression") = false, py::arg("turnaround") = 0.0)
        .def(
            "transact",
            [](LineLink& l, const py::object& request, const py::object& timeout) {
                std::string req = bytes_arg(request, "request");
                std::optional<std::chrono::nanoseconds> t;
                if (!timeout.is_none()) t = seconds_to_ns(timeout);
                std::string reply;
                {
                    py::gil_scoped_release nogil;
                    reply = l.transact(req, t);
                }
                return to_py(reply);
            },
            py::arg("request"), py::arg("timeout") = py::none(),
            "Sends request + terminator and returns the reply without its terminator. "
            "timeout None = the link's reply_timeout.")
        .def(
            "send",
            [](LineLink& l, const py::object& request) {
                std::string req = bytes_arg(request, "request");
                py::gil_scoped_release nogil;
                l.send(req);
            },
            py::arg("request"))
        .def(
            "read_line",
            [](LineLink& l, const py::object& timeout) -> py::object {
                auto t = timeout.is_none() ? l.options().reply_timeout : seconds_to_ns(timeout);
                std::optional<std::string> line;
                {
                    py::gil_scoped_release nogil;
                    line = l.read_line(t);
                }
                if (!line) return py::none();
                return to_py(*line);
            },
            py::arg("timeout") = py::none(),
            "One line (e.g. unsolicited) or None on timeout; a partial line stays buffered.")
        .def_property_readonly("counters", [](const LineLink& l) { return link_counters(l.counters()); })
        .def_property_readonly("port", [](LineLink& l) { return &l.port(); }, py::return_value_policy::reference_internal)
        .def_property_readonly("max_line", [](const LineLink& l) { return l.options().max_line; })
        .def_property_readonly("request_terminator",
                               [](const LineLink& l) { return to_py(l.options().request_terminator); })
        .def_property_readonly("reply_terminators", [](const LineLink& l) {
            py::list out;
            for (const auto& t : l.options().reply_terminators) out.append(to_py(t));
            return out;
        });

    py::class_<LineDevice, PyLineDevice, std::shared_ptr<LineDevice>>(
        m, "LineDevice",
        "A simulated serial device. Subclass and override on_line(line: bytes) -> bytes|str|None "
        "(reply with its terminator; empty/None = silent).")
        .def(py::init<>())
        .def(
            "on_line",
            [](LineDevice& d, const py::object& line) {
                std::string l = bytes_arg(line, "line");
                std::string r;
                {
                    py::gil_scoped_release nogil;
                    r = d.on_line(l);
                }
                return to_py(r);
            },
            py::arg("line"))
        .def("request_terminator", [](const LineDevice& d) { return to_py(d.request_terminator()); })
        .def("max_request", &LineDevice::max_request)
        .def("on_overlong", [](LineDevice& d) { return to_py(d.on_overlong()); });

    py::class_<EchoLineDevice, LineDevice, std::shared_ptr<EchoLineDevice>>(
        m, "EchoLineDevice", "C++ device answering prefix + line + reply_terminator (benchmarks, smoke tests).")
        .def(py::init([](const py::object& prefix, const py::object& reply_terminator,
                         const py::object& request_terminator) {
                 return std::make_shared<EchoLineDevice>(bytes_arg(prefix, "prefix"),
                                                         bytes_arg(reply_terminator, "reply_terminator"),
                                                         bytes_arg(request_terminator, "request_terminator"));
             }),
             py::arg("prefix") = "", py::arg("reply_terminator") = "\r\n", py::arg("request_terminator") = "\r");

    py::class_<PyLineServer>(m, "PtyLineServer",
                             "Serves LineDevices on a pty (multi-drop); clients open .slave_path.")
        .def(py::init<const std::vector<py::object>&, unsigned, std::shared_ptr<Port>>(),
             py::arg("devices") = std::vector<py::object>{}, py::arg("baud") = 0, py::arg("port") = nullptr)
        .def("attach", &PyLineServer::attach, py::arg("device"))
        .def("close", &PyLineServer::close)
        .def_property_readonly("slave_path", [](PyLineServer& s) { return s.get().slave_path(); })
        .def_property_readonly("baud", [](PyLineServer& s) { return s.get().baud(); })
        .def_property_readonly("running", [](PyLineServer& s) { return s.get().running(); })
        .def_property_readonly("counters", [](PyLineServer& s) { return server_counters(s.get().counters()); })
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](PyLineServer& s, py::args) { s.close(); });
}

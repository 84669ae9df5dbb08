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
#include "motorbus/serial/remote_port.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::serial;
using motorbus::py_helpers::Record;
using motorbus::py_helpers::seconds_to_ns;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::finite_forever;
using motorbus::py_helpers::Forever;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::interruptible_wait;
using motorbus::py_helpers::arg_iterable;

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


}  // namespace

namespace {
void fill_reply_too_long(py::object& exc, const ReplyTooLong& e) {
    exc.attr("data") = py::bytes(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size());
}
}  // namespace

static void bind_serial_records(py::module_& m) {
    // ReplyTooLong(ProtocolError): a distinct class so callers can catch it alone.
    py_errors::add_error_classes({{"ReplyTooLong", {"ProtocolError"},
        "A reply exceeded max_line; it was discarded up to its terminator. .data holds its first bytes."}});
    py_errors::translate<ReplyTooLong, fill_reply_too_long>(py_errors::error_class("ReplyTooLong"));

    Record<LineCounters>(m, "LineCounters", "LineLink counters, read-only.")
        .field("bytes_in", &LineCounters::bytes_in, "read from the port (echo and stale bytes included)")
        .field("bytes_out", &LineCounters::bytes_out, "written, terminators included")
        .field("requests", &LineCounters::requests, "transact() + send() calls that wrote")
        .field("replies", &LineCounters::replies, "lines returned by transact()/read_line()")
        .field("timeouts", &LineCounters::timeouts, "transact() calls that got no complete reply")
        .field("stale_bytes", &LineCounters::stale_bytes, "discarded by the flush before a request")
        .field("overlong_lines", &LineCounters::overlong_lines, "replies longer than max_line (ReplyTooLong)")
        .field("echo_bytes", &LineCounters::echo_bytes, "own bytes skipped by echo suppression")
        .field("echo_mismatches", &LineCounters::echo_mismatches, "expected echo did not arrive as sent");

    Record<LineServerCounters>(m, "LineServerCounters", "PtyLineServer counters, read-only.")
        .field("bytes_in", &LineServerCounters::bytes_in)
        .field("bytes_out", &LineServerCounters::bytes_out)
        .field("lines", &LineServerCounters::lines, "complete request lines handed to the devices")
        .field("overlong_lines", &LineServerCounters::overlong_lines, "request lines longer than every device accepts")
        .field("replies", &LineServerCounters::replies, "non-empty replies written")
        .field("device_errors", &LineServerCounters::device_errors, "a device broke its no-throw promise (reply dropped)")
        .field("dropped_replies", &LineServerCounters::dropped_replies, "the client stopped reading; reply not written");
}

static void bind_ports(py::module_& m) {
    py::class_<Port, std::shared_ptr<Port>>(m, "Port", R"doc(A bidirectional byte stream (a serial device or one side of a pty).

    write(data)                 blocks until all bytes are written; LinkDown if the peer is gone
    read(size=4096, timeout=None) -> bytes   b'' on timeout; timeout None = wait forever
    flush_input()               drops unread input
    drain()                     waits until written bytes left the UART (no-op on a pty)
    close()                     wakes blocked readers/writers, which raise ClosedError
)doc")
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
                auto n = interruptible_wait(t, [&](std::chrono::nanoseconds d) -> std::optional<std::size_t> {
                    std::size_t got = p.read({reinterpret_cast<std::uint8_t*>(buf.data()), buf.size()}, d);
                    if (got == 0) return std::nullopt;
                    return got;
                });
                return py::bytes(buf.data(), n.value_or(0));
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
                                                        R"doc(A termios serial device in raw 8N1 mode: TtyPort(path, baud=0).

    baud=0 keeps the current speed.  Standard rates use the B* constants; any
    other rate (e.g. 250000) goes through termios2/BOTHER and raises
    InvalidArgument if the driver refuses it.  `.baud` reads/sets the speed.
)doc")
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
                                                  R"doc(A raw pseudo-terminal pair for tests.

    .port        our side (a Port)
    .slave_path  e.g. '/dev/pts/7', for a peer: serial.Serial(path), can.Bus('slcan', channel=path)
    open_slave(baud=0) -> TtyPort   a second motorbus port on the slave
    release_slave()  drop the pair's own hold on the slave: once every peer has
                     closed it, reads on .port raise LinkDown (an unplugged adapter)
)doc")
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

    py::class_<TcpPort, Port, std::shared_ptr<TcpPort>>(m, "TcpPort", R"doc(A serial line behind a gateway, raw TCP: open_port("socket://host:port").

    Bytes pass unchanged; the gateway (e.g. ser2net's `accepter: tcp,...`) owns the
    line settings, so open_port's baud is ignored.  A dropped connection raises
    LinkDown naming host:port; close() wakes a blocked read with ClosedError.
)doc")
        .def_property_readonly("peer", &TcpPort::peer, "'host:port'")
        .def_property_readonly("is_open", &TcpPort::is_open);

    py::class_<Rfc2217Port, TcpPort, std::shared_ptr<Rfc2217Port>>(m, "Rfc2217Port",
                                                                  R"doc(A serial line behind an RFC 2217 (Telnet COM-PORT-OPTION) gateway: open_port("rfc2217://host:port", baud).

    The baud and 8N1 are sent to the gateway (e.g. ser2net's `accepter:
    telnet(rfc2217),tcp,...`), which sets them on its serial port; each is
    waited for.  baud=0 asks the gateway for its current rate.  `.baud`
    reads the rate the gateway acknowledged and sets a new one.
)doc")
        .def_property("baud", &Rfc2217Port::baud,
                      [](Rfc2217Port& p, unsigned baud) {
                          py::gil_scoped_release nogil;
                          p.set_baud(baud);
                      })
        .def("set_baud", &Rfc2217Port::set_baud, py::arg("baud"), py::call_guard<py::gil_scoped_release>());

    m.def("open_port", &open_port, py::arg("path"), py::arg("baud") = 0, py::call_guard<py::gil_scoped_release>(),
          "Opens a serial device at `baud` (0 = keep the current speed), or a line behind a serial gateway:\n"
          "'socket://host:port' (raw TCP, baud ignored) or 'rfc2217://host:port' (baud sent to the gateway).");
}

static void bind_line_link(py::module_& m) {
    py::class_<LineLink, std::shared_ptr<LineLink>>(m, "LineLink", R"doc(Request/reply line framing on a Port.

    LineLink(port, request_terminator="\r", reply_terminators=["\r\n"], max_line=256,
             reply_timeout=0.5, flush_before_request=True, echo_suppression=False,
             turnaround=0.0)

    transact(request, timeout=None) -> bytes
        Drops stale input (flush_before_request), writes request + terminator,
        waits `turnaround` s (RS-485 direction switch), skips the exact echo of
        our own bytes (echo_suppression), then reads until ANY reply terminator,
        reassembling replies split across reads.  Returns the reply without its
        terminator.  timeout None = reply_timeout.  TimeoutError discards the
        partial reply; ReplyTooLong when the reply exceeds max_line (the rest is
        discarded up to the terminator).  Concurrent calls are serialized.
    send(request)              write without waiting (broadcasts)
    read_line(timeout=None) -> bytes | None   one line (unsolicited); None on timeout
    counters -> LineCounters   .bytes_in .bytes_out .requests .replies .timeouts
                               .stale_bytes .overlong_lines .echo_bytes .echo_mismatches
)doc")
        .def(py::init([](std::shared_ptr<Port> port, const py::object& request_terminator,
                         const py::object& reply_terminators, std::size_t max_line, const py::object& reply_timeout,
                         bool flush_before_request, bool echo_suppression, double turnaround) {
                 LineOptions o;
                 o.request_terminator = bytes_arg(request_terminator, "request_terminator");
                 o.reply_terminators.clear();
                 if (py::isinstance<py::str>(reply_terminators) || py::isinstance<py::bytes>(reply_terminators)) {
                     o.reply_terminators.push_back(bytes_arg(reply_terminators, "reply_terminators"));
                 } else {
                     for (auto t : arg_iterable(reply_terminators, "reply_terminators", "str, bytes or a list of them"))
                         o.reply_terminators.push_back(bytes_arg(t, "reply_terminators"));
                 }
                 o.max_line = max_line;
                 o.reply_timeout = seconds_to_ns(reply_timeout, "reply_timeout");
                 o.flush_before_request = flush_before_request;
                 o.echo_suppression = echo_suppression;
                 o.turnaround = duration_arg(turnaround, "turnaround");
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
                reply = blocking_call([&] { return l.transact(req, t); });
                return to_py(reply);
            },
            py::arg("request"), py::arg("timeout") = py::none(),
            "Sends request + terminator and returns the reply without its terminator. "
            "timeout None = the link's reply_timeout.")
        .def(
            "transact_async",
            [](LineLink& l, const py::object& request, std::shared_ptr<Completions> done, std::uint64_t token,
               const py::object& timeout) {
                std::string req = bytes_arg(request, "request");
                std::optional<std::chrono::nanoseconds> t;
                if (!timeout.is_none()) t = seconds_to_ns(timeout);
                l.transact_async(std::move(req), t, std::move(done), token);
            },
            py::arg("request"), py::arg("completions"), py::arg("token"), py::arg("timeout") = py::none(),
            "transact() for an event loop: returns at once; the reply (bytes) or the error arrives in "
            "`completions` under `token`, from the link's own worker thread (motorbus.aio.transact awaits it).")
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
                line = blocking_call([&] { return l.read_line(t); });
                if (!line) return py::none();
                return to_py(*line);
            },
            py::arg("timeout") = py::none(),
            "One line (e.g. unsolicited) or None on timeout; a partial line stays buffered.")
        .def(
            "set_trace",
            [](LineLink& l, const py::object& callback) {
                if (callback.is_none()) {
                    l.set_trace({});
                    return;
                }
                if (!PyCallable_Check(callback.ptr())) throw InvalidArgument("set_trace: a callable or None");
                py_helpers::PyCallable f(py::reinterpret_borrow<py::function>(callback));
                l.set_trace([f](char direction, const std::string& text) {
                    // Plain C++ values: PyCallable converts them once it holds the GIL
                    // (the data as a list of byte values; the Python side makes bytes of it).
                    f(std::string(1, direction), std::vector<std::uint8_t>(text.begin(), text.end()));
                });
            },
            py::arg("callback"),
            "A protocol trace: callback(direction, data) with '>' and each request written (a list of byte values, without "
            "its terminator), '<' and each reply line read, '!' and a note when a request got no reply in "
            "time; on the transacting thread (it must not use this link).  None turns it off.")
        .def_property_readonly("counters", &LineLink::counters, "LineCounters (a snapshot)")
        .def_property_readonly("port", [](LineLink& l) { return &l.port(); }, py::return_value_policy::reference_internal)
        .def_property_readonly("max_line", [](const LineLink& l) { return l.options().max_line; })
        .def_property_readonly("request_terminator",
                               [](const LineLink& l) { return to_py(l.options().request_terminator); })
        .def_property_readonly("reply_terminators", [](const LineLink& l) {
            py::list out;
            for (const auto& t : l.options().reply_terminators) out.append(to_py(t));
            return out;
        });
}

static void bind_line_devices(py::module_& m) {
    py::class_<LineDevice, PyLineDevice, std::shared_ptr<LineDevice>>(
        m, "LineDevice",
        R"doc(A simulated serial device; subclass it (call super().__init__()).

    on_line(line: bytes) -> bytes | str | None
        One request without its terminator; return the exact reply bytes,
        terminator included.  None/b'' = stay silent (not addressed).
        Exceptions are reported as unraisable and the device stays silent.
    request_terminator() -> bytes | str     default "\r"
    max_request() -> int                    default 256
    on_overlong() -> bytes | str | None     reply to an over-long request (default silent)

    Called from the server thread with the GIL held.
)doc")
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
                             R"doc(Serves LineDevices on a pty, like drives on one RS-485 line.

    PtyLineServer(devices=[], baud=0, port=None)

    Every complete request line goes to EVERY device (each decides whether it
    is addressed); replies are written in device order.  Request lines longer
    than a device's max_request() get its on_overlong() reply, and the line
    resyncs at the next terminator.  baud > 0 paces both directions at 10 bit
    times per byte, so a pty behaves like a real line for benchmarks.  port=
    serves on an existing Port instead of a new pty (slave_path is then "").
    Use as a context manager or call close(); counters is a LineServerCounters.
)doc")
        .def(py::init<const std::vector<py::object>&, unsigned, std::shared_ptr<Port>>(),
             py::arg("devices") = std::vector<py::object>{}, py::arg("baud") = 0, py::arg("port") = nullptr)
        .def("attach", &PyLineServer::attach, py::arg("device"))
        .def_property(
            "enforce_baud", [](PyLineServer& s) { return s.get().enforce_baud(); },
            [](PyLineServer& s, bool on) { s.get().set_enforce_baud(on); },
            "With baud > 0: requests sent at another rate arrive garbled (no device answers them).")
        .def("close", &PyLineServer::close)
        .def_property_readonly("slave_path", [](PyLineServer& s) { return s.get().slave_path(); })
        .def_property_readonly("baud", [](PyLineServer& s) { return s.get().baud(); })
        .def_property_readonly("running", [](PyLineServer& s) { return s.get().running(); })
        .def_property_readonly("counters", [](PyLineServer& s) { return s.get().counters(); },
                               "LineServerCounters (a snapshot)")
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](PyLineServer& s, py::args) { s.close(); });
}

void bind_serial(py::module_& m) {
    bind_serial_records(m);
    bind_ports(m);
    bind_line_link(m);
    bind_line_devices(m);
}

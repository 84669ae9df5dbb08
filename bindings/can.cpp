// Bindings for cpp/motorbus/can: Frame, Filter, Bus and the bus backends.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "can_filters.hpp"
#include "common.hpp"
#include "completions.hpp"
#include "motorbus/can/async_receiver.hpp"
#include "motorbus/can/bus.hpp"
#include "motorbus/can/external_bus.hpp"
#include "motorbus/can/log.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/can/frame.hpp"
#include "motorbus/errors.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::can;
using motorbus::py_helpers::PyCallable;
using motorbus::py_helpers::Record;
using motorbus::py_helpers::seconds_to_ns;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::finite_forever;
using motorbus::py_helpers::Forever;
using motorbus::py_helpers::interruptible_wait;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::arg_cast;
using motorbus::py_helpers::arg_iterable;
using motorbus::py_helpers::not_none;

namespace {

py::bytes frame_data(const Frame& f) {
    auto p = f.payload();
    return py::bytes(reinterpret_cast<const char*>(p.data()), p.size());
}

Frame frame_from_py(std::uint32_t id, const py::object& data, bool extended, bool rtr,
                    const py::object& dlc) {
    std::string bytes;
    if (!data.is_none()) {
        if (py::isinstance<py::bytes>(data) || py::isinstance<py::bytearray>(data) ||
            py::hasattr(data, "__buffer__") || py::isinstance<py::memoryview>(data)) {
            bytes = py::bytes(data).cast<std::string>();
        } else {
            // any iterable of ints 0..255
            for (auto item : arg_iterable(data, "frame data", "bytes or an iterable of ints 0-255")) {
                int v = arg_cast<int>(item, "frame data", "ints 0-255");
                if (v < 0 || v > 255)
                    throw InvalidArgument("frame data: byte value " + std::to_string(v) +
                                          " is outside 0-255");
                bytes.push_back(static_cast<char>(v));
            }
        }
    }
    int rtr_dlc = dlc.is_none() ? -1 : arg_cast<int>(dlc, "frame dlc", "an int 0-8 or None");
    // -1 is the core's "not given" (None here): an explicit negative DLC is wrong,
    // not a request for the default (Frame(rtr=True, dlc=-1) used to pass as DLC 0).
    if (!dlc.is_none() && rtr_dlc < 0)
        throw InvalidArgument("frame dlc: " + std::to_string(rtr_dlc) + ", must be 0-8 (or None)");
    if (!rtr && rtr_dlc >= 0 && static_cast<std::size_t>(rtr_dlc) != bytes.size())
        throw InvalidArgument("frame dlc: " + std::to_string(rtr_dlc) + " does not match " +
                              std::to_string(bytes.size()) + " data bytes");
    return Frame::make(id,
                       std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
                       extended, rtr, rtr_dlc);
}

}  // namespace

static void bind_frames(py::module_& m) {
    py::class_<Frame>(m, "Frame", "A CAN frame. Invalid fields are refused at construction.")
        .def(py::init(&frame_from_py), py::arg("id"), py::arg("data") = py::bytes(),
             py::arg("extended") = false, py::arg("rtr") = false, py::arg("dlc") = py::none())
        .def_readonly("id", &Frame::id)
        .def_readonly("extended", &Frame::extended)
        .def_readonly("rtr", &Frame::rtr)
        .def_property_readonly("dlc", [](const Frame& f) { return f.len; })
        .def_property_readonly("data", &frame_data)
        .def_readwrite("timestamp_ns", &Frame::timestamp_ns)
        .def_readonly("flags", &Frame::flags)
        .def_property_readonly("is_fd", &Frame::is_fd)
        .def_property_readonly("is_error", [](const Frame& f) { return bool(f.flags & kFlagError); })
        .def_property_readonly("is_loopback",
                               [](const Frame& f) { return bool(f.flags & kFlagLoopback); })
        .def("__eq__", [](const Frame& a, const Frame& b) { return a.same_content(b); })
        .def("__hash__", [](const Frame& f) {
            return py::hash(py::make_tuple(f.id, f.extended, f.rtr, frame_data(f)));
        })
        .def("__str__", &Frame::to_string)
        .def("__repr__", [](const Frame& f) {
            return "Frame(" + f.to_string() + (f.extended ? ", extended" : "") + ")";
        });
    m.def("wire_bits_worst_case", &wire_bits_worst_case, py::arg("frame"),
          "Bits a classic frame occupies on the wire with worst-case stuffing, incl. intermission.");

    Record<BusCounters>(m, "BusCounters", "A bus's counters (Bus.counters), read-only.")
        .field("rx_frames", &BusCounters::rx_frames, "frames received from the medium")
        .field("tx_frames", &BusCounters::tx_frames, "frames handed to the medium")
        .field("rx_dropped", &BusCounters::rx_dropped, "received frames dropped because the recv() queue was full")
        .field("tx_dropped", &BusCounters::tx_dropped, "frames the medium lost (fault injection, adapter NACK)")
        .field("overruns", &BusCounters::overruns, "adapter/medium reported overrun or line too long")
        .field("parse_errors", &BusCounters::parse_errors, "malformed input from the medium, discarded")
        .field("bus_errors", &BusCounters::bus_errors, "error frames / BEL / error states reported")
        .field("ignored", &BusCounters::ignored, "well-formed input not used (status lines etc.)")
        .field("rx_bits", &BusCounters::rx_bits, "wire bits of the frames received (worst-case stuffing; own echoes left out)")
        .field("tx_bits", &BusCounters::tx_bits, "wire bits of the frames sent (worst-case stuffing)");
}

static void bind_buses(py::module_& m) {
    py::class_<Bus, std::shared_ptr<Bus>>(m, "Bus", "A CAN bus endpoint (open one with open_bus).")
        .def("send",
             [](Bus& b, const Frame& f, const py::object& timeout) {
                 auto t = finite_forever(seconds_to_ns(timeout));
                 // A blocking call: a send waiting on a full queue returns to
                 // Python for Ctrl-C every kInterruptSlice.
                 blocking_call([&] { b.send(f, t); });
             },
             py::arg("frame"), py::arg("timeout") = 1.0)
        .def("recv",
             [](Bus& b, const py::object& timeout) {
                 auto t = seconds_to_ns(timeout);
                 return interruptible_wait(t, [&](std::chrono::nanoseconds d) { return b.recv(d); });
             },
             py::arg("timeout") = py::none())
        .def("recv_many",
             [](Bus& b, std::size_t max, const py::object& timeout) {
                 auto t = seconds_to_ns(timeout);
                 auto got = interruptible_wait(t, [&](std::chrono::nanoseconds d) -> std::optional<std::vector<Frame>> {
                     auto v = b.recv_many(max, d);
                     if (v.empty()) return std::nullopt;
                     return v;
                 });
                 return got ? std::move(*got) : std::vector<Frame>{};
             },
             py::arg("max") = 1024, py::arg("timeout") = py::none(),
             "Up to max frames, oldest first: waits like recv() for the first, then takes what is "
             "already queued. An empty list after timeout.")
        .def("_recv_or_wait",
             [](Bus& b, std::size_t max, std::shared_ptr<Completions> done, std::uint64_t token) {
                 not_none(done, "completions");
                 return b.recv_or_wait(max, std::move(done), token);
             },
             py::arg("max"), py::arg("completions"), py::arg("token"),
             "recv() for an event loop (Bus.arecv): up to max queued frames, or [] and a waiter completed "
             "with a list of Frames (or recv()'s error) under token.")
        .def("_cancel_wait",
             [](Bus& b, const std::shared_ptr<Completions>& done, std::uint64_t token) {
                 return b.cancel_wait(done.get(), token);
             },
             py::arg("completions"), py::arg("token"),
             "Withdraws a _recv_or_wait waiter: False when it already completed.")
        .def("set_filters",
             [](Bus& b, const py::object& filters) {
                 b.set_filters(motorbus::py_helpers::filters_from_py(filters));
             },
             py::arg("filters") = py::none())
        .def("subscribe",
             [](Bus& b, py::function cb, const py::object& id, const py::object& mask,
                bool extended) {
                 PyCallable call(std::move(cb));
                 FrameCallback fn = [call](const Frame& f) { call(f); };
                 if (id.is_none()) return b.subscribe(Filter{}, std::move(fn));
                 if (mask.is_none()) return b.subscribe_id(id.cast<std::uint32_t>(), extended, std::move(fn));
                 return b.subscribe(Filter{id.cast<std::uint32_t>(), mask.cast<std::uint32_t>(),
                                           extended, true},
                                    std::move(fn));
             },
             py::arg("callback"), py::arg("id") = py::none(), py::arg("mask") = py::none(),
             py::arg("extended") = false,
             "Call callback(frame) on the bus thread for matching frames; returns a handle.")
        .def("unsubscribe", &Bus::unsubscribe, py::arg("handle"),
             py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("state", [](const Bus& b) { return to_string(b.state()); })
        .def_property_readonly("counters", &Bus::counters, "BusCounters (a snapshot)")
        .def_property_readonly("channel", &Bus::channel)
        .def_property_readonly("closed", &Bus::closed)
        .def("close", &Bus::close, py::call_guard<py::gil_scoped_release>())
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](Bus& b, py::args) {
            py::gil_scoped_release nogil;
            b.close();
        });

    py::class_<VirtualBus, Bus, std::shared_ptr<VirtualBus>>(m, "VirtualBus",
                                                           "Endpoint on an in-process virtual CAN bus.")
        .def("set_faults",
             [](VirtualBus& b, unsigned drop_every, double drop_probability,
                double corrupt_probability, double delay, std::uint64_t seed) {
                 FaultOptions f;
                 f.drop_every = drop_every;
                 f.drop_probability = drop_probability;
                 f.corrupt_probability = corrupt_probability;
                 f.delay_ns = duration_arg(delay, "delay").count();
                 f.seed = seed;
                 b.set_faults(f);
             },
             py::arg("drop_every") = 0, py::arg("drop_probability") = 0.0,
             py::arg("corrupt_probability") = 0.0, py::arg("delay") = 0.0,
             py::arg("seed") = 0x5eed,
             "Faults applied to frames this endpoint sends (delay in seconds).")
        .def("set_bus_off", &VirtualBus::set_bus_off, py::arg("off") = true)
        .def_property_readonly("bitrate", &VirtualBus::bitrate);

    m.def("open_virtual",
          [](const std::string& name, double bitrate, std::size_t tx_queue, std::size_t rx_queue_size,
             bool receive_own, double rx_spin) {
              VirtualOptions o;
              o.bitrate = bitrate;
              o.tx_queue = tx_queue;
              o.rx_queue_size = rx_queue_size;
              o.receive_own = receive_own;
              o.rx_spin = std::chrono::duration_cast<std::chrono::microseconds>(duration_arg(rx_spin, "rx_spin"));
              return open_virtual(name, o);
          },
          py::arg("name"), py::arg("bitrate") = 0.0, py::arg("tx_queue") = 64,
          py::arg("rx_queue_size") = 65536, py::arg("receive_own") = false, py::arg("rx_spin") = 20e-6,
          "Joins the in-process hub NAME.  rx_spin: seconds the endpoint's receive thread polls for "
          "the next frame before sleeping (0 = always sleep).");

    py::class_<ExternalBus, Bus, std::shared_ptr<ExternalBus>>(
        m, "ExternalBus", "A bus fed by Python code (the python-can bridge is built on it).")
        .def(py::init([](const std::string& channel, py::function send, py::object close,
                         bool receive_own) {
                 PyCallable send_call(std::move(send));
                 ExternalBus::SendFn fn = [send_call](const Frame& f, Deadline d) {
                     py::gil_scoped_acquire gil;
                     double left = std::chrono::duration<double>(d - std::chrono::steady_clock::now()).count();
                     send_call.call(f, left > 0 ? left : 0.0);  // Python exceptions reach the sender
                 };
                 ExternalBus::CloseFn cfn;
                 if (!close.is_none()) {
                     PyCallable c(close.cast<py::function>());
                     cfn = [c]() { c(); };
                 }
                 BusOptions o;
                 o.receive_own = receive_own;
                 return std::make_shared<ExternalBus>(channel, std::move(fn), std::move(cfn), o);
             }),
             py::arg("channel"), py::arg("send"), py::arg("close") = py::none(),
             py::arg("receive_own") = false)
        .def("feed", &ExternalBus::feed, py::arg("frame"), py::call_guard<py::gil_scoped_release>())
        .def("feed_parse_error", &ExternalBus::feed_parse_error);
}

static void bind_async_receiver(py::module_& m) {
    // A completion's batch of frames (Bus._recv_or_wait, AsyncReceiver) becomes a list of Frames.
    motorbus::py_completions::convertible<std::vector<Frame>>();
    Record<AsyncReceiverCounters>(m, "AsyncReceiverCounters", "A frame stream's counters, read-only.")
        .field("received", &AsyncReceiverCounters::received, "frames that passed the filters")
        .field("overflows", &AsyncReceiverCounters::overflows, "of those, dropped (the newest) with the queue full")
        .field("wakeups", &AsyncReceiverCounters::wakeups, "completions pushed: one per burst the loop waited for");
    py::class_<AsyncReceiver, std::shared_ptr<AsyncReceiver>>(
        m, "AsyncReceiver",
        "A bus's frames for an event loop (Bus.frames): its own subscription, filters and bounded queue.")
        .def(py::init([](std::shared_ptr<Bus> bus, const py::object& filters, std::size_t queue) {
                 not_none(bus, "bus");
                 // Destroyed without the GIL: its close() waits for the bus's dispatch, which may be
                 // running another subscriber's Python callback (waiting for the GIL).
                 auto* rx = new AsyncReceiver(std::move(bus), motorbus::py_helpers::filters_from_py(filters), queue);
                 return std::shared_ptr<AsyncReceiver>(rx, [](AsyncReceiver* p) {
                     if (Py_IsInitialized() && PyGILState_Check()) {
                         py::gil_scoped_release nogil;
                         delete p;
                     } else {
                         delete p;
                     }
                 });
             }),
             py::arg("bus"), py::arg("filters") = py::none(), py::arg("queue") = 1024)
        .def("take_or_arm",
             [](AsyncReceiver& r, std::size_t max, std::shared_ptr<Completions> done, std::uint64_t token) {
                 not_none(done, "completions");
                 return r.take_or_arm(max, std::move(done), token);
             },
             py::arg("max"), py::arg("completions"), py::arg("token"),
             "Up to max queued frames, or [] and armed: the next frames complete token as a list of Frames.")
        .def("take", &AsyncReceiver::take, py::arg("max") = 1024)
        .def("disarm", &AsyncReceiver::disarm)
        .def("close", &AsyncReceiver::close, py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("ended", &AsyncReceiver::ended)
        .def_property_readonly("queued", &AsyncReceiver::queued)
        .def_property_readonly("capacity", &AsyncReceiver::capacity)
        .def_property_readonly("counters", &AsyncReceiver::counters);
}

static void bind_logs(py::module_& m) {
    // ---- logs -------------------------------------------------------------
    py::class_<LogEntry>(m, "LogEntry", "One logged frame: time (s), channel, direction.")
        .def_readonly("frame", &LogEntry::frame)
        .def_readonly("time", &LogEntry::time)
        .def_readonly("channel", &LogEntry::channel)
        .def_readonly("rx", &LogEntry::rx)
        .def("__repr__", [](const LogEntry& e) { return "LogEntry(" + format_candump_line(e) + ")"; });
    py::enum_<LogFormat>(m, "LogFormat", "Log file formats: candump (.log) and Vector ASC (.asc).")
        .value("CANDUMP", LogFormat::Candump)
        .value("ASC", LogFormat::Asc);
    // None = from the file name; a LogFormat; or its name ('candump'/'log', 'asc').
    auto fmt = [](const py::object& f) -> std::optional<LogFormat> {
        if (f.is_none()) return std::nullopt;
        if (py::isinstance<LogFormat>(f)) return f.cast<LogFormat>();
        auto s = arg_cast<std::string>(f, "log format", "a LogFormat, 'candump' or 'asc'");
        if (auto v = log_format_from_name(s)) return v;
        throw InvalidArgument("log format: '" + s + "' (expected 'candump' or 'asc')");
    };
    py::class_<Recorder>(m, "Recorder", "Writes every frame a bus receives to a candump or ASC log.")
        .def(py::init([fmt](std::shared_ptr<Bus> bus, const std::string& path, const py::object& format,
                            const std::string& channel) {
                 not_none(bus, "bus");
                 return std::make_unique<Recorder>(std::move(bus), path, fmt(format), channel);
             }),
             py::arg("bus"), py::arg("path"), py::arg("format") = py::none(), py::arg("channel") = "can0")
        .def("log_sent", &Recorder::log_sent, py::arg("frame"))
        .def("stop", &Recorder::stop, py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("count", &Recorder::count)
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](Recorder& r, py::args) {
            py::gil_scoped_release nogil;
            r.stop();
        });
    m.def("read_log", [](const std::string& path) {
        std::size_t bad = 0;
        auto v = read_log(path, &bad);
        return py::make_tuple(v, bad);
    }, py::arg("path"), "Reads a candump (.log) or ASC (.asc) file: (entries, bad_line_count).");
    m.def("parse_candump_line", &parse_candump_line, py::arg("line"));
    m.def("play", [](Bus& bus, const std::vector<LogEntry>& entries, double speed) {
        return motorbus::py_helpers::blocking_call([&] { return play(bus, entries, speed); });  // Ctrl-C stops it
    }, py::arg("bus"), py::arg("entries"), py::arg("speed") = 1.0,
       "Replays entries onto bus: speed 1.0 = original timing, 0 = as fast as possible.");
}

void bind_can(py::module_& m) {
    bind_frames(m);
    bind_buses(m);
    bind_async_receiver(m);
    bind_logs(m);
}

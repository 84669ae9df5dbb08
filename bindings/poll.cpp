// Bindings for cpp/motorbus/poll: PollSource (base of the sources other areas
// bind), PollGroup (one poll thread), PollStats.  The thread runs without the
// GIL; take() copies the new rows out of the ring into fresh numpy arrays
// with the GIL released for the copy.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "motorbus/poll/poll_group.hpp"

namespace py = pybind11;
using namespace motorbus;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::Record;

void bind_poll(py::module_& m) {
    py::class_<poll::Source, std::shared_ptr<poll::Source>>(
        m, "PollSource", "What one drive gives a PollGroup per sample (made by the drive kind's poll_fields).")
        .def_property_readonly("columns", &poll::Source::columns)
        .def_property_readonly("stale", &poll::Source::stale,
                               "reads that found pushed data too old or missing (0 for sources that ask)")
        .def("__repr__", [](const poll::Source& s) {
            return "<PollSource " + s.describe() + ", " + std::to_string(s.columns()) + " columns>";
        });

    Record<poll::PollStats>(m, "PollStats", "Counters and timing of one PollGroup (times in ns).")
        .field("samples", &poll::PollStats::samples, "samples read")
        .field("missed", &poll::PollStats::missed, "deadlines skipped entirely (NaN rows in the data)")
        .field("late", &poll::PollStats::late, "samples whose reads ran past the next deadline")
        .field("overflowed", &poll::PollStats::overflowed, "rows lost because the reader fell a ring behind")
        .field("stale", &poll::PollStats::stale,
               "capture sources' reads that found pushed data older than its period allows (or none yet)")
        .field("period_ns", &poll::PollStats::period_ns)
        .field("period_error_p50_ns", &poll::PollStats::period_error_p50)
        .field("period_error_p99_ns", &poll::PollStats::period_error_p99)
        .field("period_error_max_ns", &poll::PollStats::period_error_max)
        .field("wake_latency_p50_ns", &poll::PollStats::wake_latency_p50)
        .field("wake_latency_p99_ns", &poll::PollStats::wake_latency_p99)
        .field("wake_latency_max_ns", &poll::PollStats::wake_latency_max)
        .field("read_time_p50_ns", &poll::PollStats::read_time_p50)
        .field("read_time_p99_ns", &poll::PollStats::read_time_p99)
        .field("read_time_max_ns", &poll::PollStats::read_time_max)
        .field("running", &poll::PollStats::running)
        .field("realtime", &poll::PollStats::realtime, "SCHED_FIFO asked for and granted")
        .field("error_type", &poll::PollStats::error_type, "'LinkDown', 'TimeoutError'... ('' if none)")
        .field("error", &poll::PollStats::error, "why the group stopped on its own ('' if it did not)");

    py::class_<poll::PollGroup>(m, "PollGroup",
                                "One poll thread: reads its sources every period into a preallocated ring.")
        .def(py::init([](std::vector<std::shared_ptr<poll::Source>> sources, const py::object& period,
                         std::size_t capacity, const py::object& spin, bool realtime, int priority,
                         std::int64_t start_ns) {
                 poll::PollOptions o;
                 o.period_ns = duration_arg(period, "period").count();
                 o.spin_ns = duration_arg(spin, "spin").count();
                 o.capacity = capacity;
                 o.realtime = realtime;
                 o.priority = priority;
                 o.start_ns = start_ns;
                 return std::make_unique<poll::PollGroup>(std::move(sources), o);
             }),
             py::arg("sources"), py::arg("period"), py::arg("capacity") = 1 << 16, py::arg("spin") = 0.0,
             py::arg("realtime") = false, py::arg("priority") = 50, py::arg("start_ns") = 0,
             // The sources hold references to native clients the Python objects own.
             py::keep_alive<1, 2>())
        .def("start", &poll::PollGroup::start)
        .def("stop", &poll::PollGroup::stop, py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("columns", &poll::PollGroup::columns)
        .def_property_readonly("capacity", [](poll::PollGroup& g) { return g.ring().capacity(); })
        .def_property_readonly("running", &poll::PollGroup::running)
        .def_property_readonly("stats", &poll::PollGroup::stats)
        .def("notify_when",
             [](poll::PollGroup& g, std::size_t rows, std::shared_ptr<Completions> done, std::uint64_t token) {
                 motorbus::py_helpers::not_none(done, "completions");
                 return g.notify_when(rows, std::move(done), token);
             },
             py::arg("rows"), py::arg("completions"), py::arg("token"),
             "For an event loop: False, and token completes (with the unread row count) once the ring holds "
             "rows unread rows or the thread ended; True when that is already so.")
        .def("cancel_notify", &poll::PollGroup::cancel_notify)
        .def("take", [](poll::PollGroup& g) {
            auto& ring = g.ring();
            const std::size_t n = ring.available();  // more may arrive: take at most n
            py::array_t<std::int64_t> k(static_cast<py::ssize_t>(n)), t(static_cast<py::ssize_t>(n));
            py::array_t<double> v({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(ring.columns())});
            std::int64_t* kp = k.mutable_data();
            std::int64_t* tp = t.mutable_data();
            double* vp = v.mutable_data();
            std::size_t got;
            {
                py::gil_scoped_release nogil;
                got = ring.take(kp, tp, vp, n);
            }
            return py::make_tuple(k, t, v, got);
        }, "The rows written since the last take(): (deadline index int64[n], t int64 ns[n], "
           "values float64[n, columns], m); only the first m rows are valid (m < n after an overflow).");
}

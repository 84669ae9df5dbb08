// Bindings for cpp/motorbus/runtime: clocks.
#include <pybind11/pybind11.h>

#include "motorbus/runtime/clock.hpp"

namespace py = pybind11;
using namespace motorbus;

void bind_runtime(py::module_& m) {
    m.def("monotonic_ns", &monotonic_ns, "The monotonic clock frame timestamps use (ns).");
    py::class_<Clock, std::shared_ptr<Clock>>(m, "Clock")
        .def("now", &Clock::now, "Current time in ns.")
        .def("sleep_until", &Clock::sleep_until, py::arg("t_ns"),
             py::call_guard<py::gil_scoped_release>())
        .def("cancel", &Clock::cancel)
        .def_property_readonly("simulated", &Clock::simulated);
    py::class_<RealClock, Clock, std::shared_ptr<RealClock>>(m, "RealClock").def(py::init<>());
    py::class_<SimClock, Clock, std::shared_ptr<SimClock>>(m, "SimClock")
        .def(py::init<Nanos>(), py::arg("start_ns") = 0)
        .def("advance", &SimClock::advance, py::arg("dt_ns"))
        .def("set", &SimClock::set, py::arg("t_ns"));
}

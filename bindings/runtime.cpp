// Bindings for cpp/motorbus/runtime: clocks.
#include <pybind11/pybind11.h>

#include "common.hpp"
#include "errors.hpp"
#include "motorbus/runtime/clock.hpp"

namespace py = pybind11;
using namespace motorbus;

void bind_runtime(py::module_& m) {
    // Safety net for argument conversions no helper names (common.hpp arg_cast):
    // a pybind11 cast failure inside a call is a bad argument, not a RuntimeError.
    static py::handle invalid_argument = py::object(motorbus::py_errors::error_class("InvalidArgument")).release();
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const py::cast_error& e) {
            PyErr_SetString(invalid_argument.ptr(), e.what());
        }
    });
    m.def("monotonic_ns", &monotonic_ns, "The monotonic clock frame timestamps use (ns).");
    py::class_<Clock, std::shared_ptr<Clock>>(m, "Clock")
        .def("now", &Clock::now, "Current time in ns.")
        .def("sleep_until",
             [](Clock& c, Nanos t) { return motorbus::py_helpers::blocking_call([&] { return c.sleep_until(t); }); },
             py::arg("t_ns"), "Wait until clock time t_ns; False if cancel() ended the wait. Ctrl-C interrupts.")
        .def("cancel", &Clock::cancel)
        .def_property_readonly("simulated", &Clock::simulated);
    py::class_<RealClock, Clock, std::shared_ptr<RealClock>>(m, "RealClock").def(py::init<>());
    py::class_<SimClock, Clock, std::shared_ptr<SimClock>>(m, "SimClock")
        .def(py::init<Nanos>(), py::arg("start_ns") = 0)
        .def("advance", &SimClock::advance, py::arg("dt_ns"))
        .def("set", &SimClock::set, py::arg("t_ns"));
}

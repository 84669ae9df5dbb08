// Bindings of the out-of-tree "toy" kind (tests/plugin_kind/cpp/toy): its simulator
// (a LineDevice: a PtyLineServer serves it) and its client over a LineLink.  CMake
// finds this file through MOTORBUS_EXTRA_VENDOR_DIRS and calls bind_toy from the
// generated bind_drives: no shared file names the kind.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "toy/toy.hpp"

namespace py = pybind11;
using namespace motorbus;

void bind_toy(py::module_& m) {
    auto rel = py::call_guard<py::gil_scoped_release>();
    py::enum_<toy::LastStop>(m, "LastStop", "How the toy drive's last motion ended (STATUS? second word).")
        .value("NONE", toy::LastStop::None)
        .value("TARGET", toy::LastStop::Target)
        .value("STOP", toy::LastStop::Stop)
        .value("ABORT", toy::LastStop::Abort)
        .value("DISABLE", toy::LastStop::Disable)
        .value("FAULT", toy::LastStop::Fault);
    py::class_<toy::Status>(m, "Status", "STATUS? parsed, read-only.")
        .def_readonly("enabled", &toy::Status::enabled)
        .def_readonly("moving", &toy::Status::moving)
        .def_readonly("fault", &toy::Status::fault)
        .def_readonly("homed", &toy::Status::homed)
        .def_readonly("last_stop", &toy::Status::last_stop);
    py::class_<toy::Sim, serial::LineDevice, std::shared_ptr<toy::Sim>>(
        m, "Sim", "A simulated toy stepper (a LineDevice: serve it with PtyLineServer); motion on a MotorModel.")
        .def(py::init([](std::shared_ptr<Clock> clock, int address, double speed, double accel,
                         double start_position) {
                 toy::SimOptions o;
                 o.address = address;
                 o.speed = speed;
                 o.accel = accel;
                 o.start_position = start_position;
                 return std::make_shared<toy::Sim>(std::move(clock), o);
             }),
             py::arg("clock") = nullptr, py::arg("address") = 1, py::arg("speed") = 4000.0,
             py::arg("accel") = 40000.0, py::arg("start_position") = 0.0)
        .def_property_readonly("address", &toy::Sim::address)
        .def_property_readonly("position", &toy::Sim::position, "Steps, caught up with the clock.")
        .def_property_readonly("moving", &toy::Sim::moving)
        .def("set_fault_input", &toy::Sim::set_fault_input, py::arg("active"),
             py::call_guard<py::gil_scoped_release>(), "The drive's fault input (an overtemperature, say).");
    py::class_<toy::Client, std::shared_ptr<toy::Client>>(m, "Client",
                                                          "The toy protocol on a LineLink, one address.")
        .def(py::init<std::shared_ptr<serial::LineLink>, int>(), py::arg("link"), py::arg("address"))
        .def_property_readonly("address", &toy::Client::address)
        .def_property_readonly("link", &toy::Client::link)
        .def("move_to", &toy::Client::move_to, py::arg("target"), rel)
        .def("jog", &toy::Client::jog, py::arg("velocity"), rel)
        .def("stop", &toy::Client::stop, rel)
        .def("abort", &toy::Client::abort, rel)
        .def("enable", &toy::Client::enable, rel)
        .def("disable", &toy::Client::disable, rel)
        .def("clear", &toy::Client::clear, rel)
        .def("home", &toy::Client::home, rel)
        .def("get", &toy::Client::get, py::arg("name"), rel)
        .def("set", &toy::Client::set, py::arg("name"), py::arg("value"), rel)
        .def("position", &toy::Client::position, rel)
        .def("velocity", &toy::Client::velocity, rel)
        .def("status", &toy::Client::status, rel)
        .def("command", &toy::Client::command, py::arg("text"), rel);
}

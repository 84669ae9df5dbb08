// Bindings for can::SimulatedDevice (cpp/motorbus/can/sim_device.hpp), bound
// once: every CAN simulator is py::class_<Sim, SimulatedDevice, shared_ptr<Sim>>
// (built with py_helpers::make_sim, sim_device.hpp here), so Python sees one
// attach(bus) / close() / attached / describe() / power_cycle() / node_bit_rate
// on each, and a bus handed to attach() lives as long as the simulator needs it.
#include <pybind11/pybind11.h>

#include <memory>

#include "motorbus/can/sim_device.hpp"

namespace py = pybind11;
using motorbus::can::SimulatedDevice;

void bind_sim_device(py::module_& m) {
    // Released: attach and close subscribe/unsubscribe on the bus and join the
    // device's threads, which may be waiting for the GIL (a Python subscriber).
    auto rel = py::call_guard<py::gil_scoped_release>();
    py::class_<SimulatedDevice, std::shared_ptr<SimulatedDevice>>(
        m, "SimulatedDevice",
        "A simulated CAN device: attach(bus) serves it on a bus (kept alive until close()), close() takes "
        "it off (idempotent); attach again to serve it anew.  Also a context manager (closes on exit).")
        .def("attach", &SimulatedDevice::attach, py::arg("bus"), rel,
             "Serve on `bus`; the simulator keeps it alive until close().  InvalidArgument if already attached.")
        .def("close", &SimulatedDevice::close, rel, "Off the bus (idempotent); attach() may follow.")
        .def_property_readonly("attached", &SimulatedDevice::attached)
        .def("describe", &SimulatedDevice::describe, "'<kind> sim <address>', as errors name it.")
        .def("power_cycle", &SimulatedDevice::power_cycle, rel,
             "Power off and on: stored settings take effect, volatile ones are lost.")
        .def_property_readonly("node_bit_rate", &SimulatedDevice::node_bit_rate,
                               "bit/s the simulated controller runs at (0: takes the wire's; < 0: matches no wire)")
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](SimulatedDevice& d, py::args) {
            py::gil_scoped_release nogil;
            d.close();
        });
}

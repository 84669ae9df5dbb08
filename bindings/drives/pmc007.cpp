// Bindings for cpp/motorbus/drives/pmc007: so far its profile model.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "motorbus/drives/pmc007/profile.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::motion;
using namespace motorbus::pmc007;

void bind_pmc007(py::module_& m) {
    m.def("pmc007_gear_acceleration", &pmc007_gear_acceleration, py::arg("gear"));
    m.def("pmc007_microsteps", &pmc007_microsteps, py::arg("setting"));
    m.def("pmc007_convert_position", &pmc007_convert_position, py::arg("position"), py::arg("from_setting"),
          py::arg("to_setting"));
    py::class_<Pmc007ProfileParams>(m, "Pmc007ProfileParams")
        .def(py::init([](double speed, double start_speed, double stop_speed, int ag, int dg, int micro) {
                 Pmc007ProfileParams p{speed, start_speed, stop_speed, ag, dg, micro};
                 p.validate();
                 return p;
             }),
             py::arg("speed") = 1000.0, py::arg("start_speed") = 400.0, py::arg("stop_speed") = 0.0,
             py::arg("accel_gear") = 0, py::arg("decel_gear") = 0, py::arg("microstepping") = 0)
        .def_readwrite("speed", &Pmc007ProfileParams::speed)
        .def_readwrite("start_speed", &Pmc007ProfileParams::start_speed)
        .def_readwrite("stop_speed", &Pmc007ProfileParams::stop_speed)
        .def_readwrite("accel_gear", &Pmc007ProfileParams::accel_gear)
        .def_readwrite("decel_gear", &Pmc007ProfileParams::decel_gear)
        .def_readwrite("microstepping", &Pmc007ProfileParams::microstepping);
    m.def("pmc007_position_profile", &pmc007_position_profile, py::arg("start"), py::arg("target"), py::arg("params"));
    m.def("pmc007_speed_profile", &pmc007_speed_profile, py::arg("start"), py::arg("speed"), py::arg("params"),
          py::arg("hold") = 0.0);

}

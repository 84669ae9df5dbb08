// Bindings for cpp/motorbus/drives/unitek: so far its profile model.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "motorbus/drives/unitek/profile.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::motion;
using namespace motorbus::unitek;

void bind_unitek(py::module_& m) {
    py::class_<UnitekRampParams>(m, "UnitekRampParams")
        .def(py::init([](double nmax, double acc, double dec) {
                 UnitekRampParams p{nmax, acc, dec};
                 p.validate();
                 return p;
             }),
             py::arg("n_max_rpm") = 3000.0, py::arg("acc_ramp_ms") = 1000.0, py::arg("dec_ramp_ms") = 1000.0)
        .def_readwrite("n_max_rpm", &UnitekRampParams::n_max_rpm)
        .def_readwrite("acc_ramp_ms", &UnitekRampParams::acc_ramp_ms)
        .def_readwrite("dec_ramp_ms", &UnitekRampParams::dec_ramp_ms);
    m.def("unitek_speed_profile", &unitek_speed_profile, py::arg("start"), py::arg("speed_num"), py::arg("params"),
          py::arg("hold") = 0.0);

}

// motorbus._core: one bindings file per C++ area; this file only wires them up.
// Bindings stay thin: argument conversion, GIL release, nothing else.
//
// The generic areas are listed here in dependency order (a class is bound
// before the classes that derive from it).  The vendors come last, each from
// its own bindings/drives/<vendor>.cpp; CMake generates bind_drives() from the
// files it finds, so adding a vendor edits nothing here.
#include <pybind11/pybind11.h>

#include "drive_bindings.inc"

namespace py = pybind11;

void bind_errors(py::module_& m);
void bind_runtime(py::module_& m);
void bind_poll(py::module_& m);
void bind_can(py::module_& m);
void bind_sim_device(py::module_& m);
void bind_slcan(py::module_& m);
void bind_socketcand(py::module_& m);
void bind_serial(py::module_& m);
void bind_canopen(py::module_& m);
void bind_canopen_services(py::module_& m);
void bind_motion(py::module_& m);

PYBIND11_MODULE(_core, m) {
    m.doc() = "motorbus C++ core";
    bind_errors(m);
    bind_runtime(m);
    bind_poll(m);
    bind_can(m);
    bind_sim_device(m);  // before the vendors' simulators, which derive from it
    bind_slcan(m);
    bind_socketcand(m);
    bind_serial(m);
    bind_canopen(m);
    bind_canopen_services(m);
    bind_motion(m);
    bind_drives(m);
}

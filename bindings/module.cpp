// motorbus._core: one bindings file per C++ area; this file only wires them up.
// Bindings stay thin: argument conversion, GIL release, nothing else.
//
// The generic areas are listed here in dependency order (a class is bound
// before the classes that derive from it).  The vendors come last, each from
// its own bindings/drives/<vendor>.cpp; CMake generates bind_drives() from the
// files it finds, so adding a vendor edits nothing here.
#include <pybind11/pybind11.h>

namespace py = pybind11;

// One submodule of _core per area and per vendor (motorbus._core.can,
// motorbus._core.<vendor>), entered in sys.modules so that
// `from motorbus._core.can import Frame` imports it like a package's module.
static py::module_ submodule(py::module_& parent, const char* name) {
    py::module_ sub = parent.def_submodule(name);
    py::module_::import("sys").attr("modules")[sub.attr("__name__")] = sub;
    return sub;
}

#include "drive_bindings.inc"  // bind_drives(m): one submodule per vendor, made by submodule()

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
    m.doc() = "motorbus C++ core: the errors at top level, one submodule per area and per vendor";
    bind_errors(m);  // top level: every area raises them (docs/architecture.md, "The _core module map")
    py::module_ runtime = submodule(m, "runtime");
    bind_runtime(runtime);
    py::module_ poll = submodule(m, "poll");
    bind_poll(poll);
    py::module_ can = submodule(m, "can");  // the CAN bus, its transports and simulated CAN devices
    bind_can(can);
    bind_sim_device(can);  // before the vendors' simulators, which derive from it
    bind_slcan(can);
    bind_socketcand(can);
    py::module_ serial = submodule(m, "serial");
    bind_serial(serial);
    py::module_ canopen = submodule(m, "canopen");
    bind_canopen(canopen);
    bind_canopen_services(canopen);
    py::module_ motion = submodule(m, "motion");
    bind_motion(motion);
    bind_drives(m);
}

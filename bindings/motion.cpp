// Bindings for cpp/motorbus/motion (filled in by the motion work).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_motion(py::module_& m) {
    (void)m;
}

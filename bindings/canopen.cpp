// Bindings for cpp/motorbus/canopen (filled in by the canopen work).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_canopen(py::module_& m) {
    (void)m;
}

// Bindings for the canopen_services work (filled in by it).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_canopen_services(py::module_& m) {
    (void)m;
}

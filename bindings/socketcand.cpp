// Bindings for the socketcand work (filled in by it).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_socketcand(py::module_& m) {
    (void)m;
}

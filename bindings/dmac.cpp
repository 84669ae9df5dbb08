// Bindings for cpp/motorbus/dmac (filled in by the dmac work).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_dmac(py::module_& m) {
    (void)m;
}

// Bindings for cpp/motorbus/arcus (filled in by the arcus work).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_arcus(py::module_& m) {
    (void)m;
}

// Bindings for cpp/motorbus/serial (filled in by the serial work).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_serial(py::module_& m) {
    (void)m;
}

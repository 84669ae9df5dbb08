// The core error types (cpp/motorbus/errors.hpp) as Python exceptions.  Each
// also derives from the matching built-in (ValueError, TimeoutError,
// ConnectionError) so generic `except` clauses keep working.
#include "errors.hpp"

#include <string>

#include "motorbus/errors.hpp"

namespace py = pybind11;

namespace motorbus::py_errors {

namespace {
// The top-level _core module: every error class lives there (set by bind_errors,
// which runs first; the module lives as long as the interpreter).
PyObject* g_root = nullptr;
}  // namespace

py::object error_class(const char* name) {
    return py::reinterpret_borrow<py::module_>(g_root).attr(name);
}

void add_error_classes(std::initializer_list<ErrorClass> table, const char* module_name) {
    py::module_ root = py::reinterpret_borrow<py::module_>(g_root);
    py::module_ builtins = py::module_::import("builtins");
    for (const ErrorClass& row : table) {
        py::list bases;
        for (const char* b : row.bases)
            bases.append(py::hasattr(root, b) ? root.attr(b) : builtins.attr(b));
        const std::string qualified = std::string(module_name) + "." + row.name;
        PyObject* cls = PyErr_NewExceptionWithDoc(qualified.c_str(), row.doc, py::tuple(bases).ptr(), nullptr);
        if (cls == nullptr) throw py::error_already_set();
        root.attr(row.name) = py::reinterpret_steal<py::object>(cls);
    }
}

}  // namespace motorbus::py_errors

namespace {
void fill_bytes(py::object& exc, const motorbus::ProtocolError& e) {
    exc.attr("data") = py::bytes(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size());
}
}  // namespace

void bind_errors(py::module_& m) {
    using namespace motorbus;
    using py_errors::translate;
    py_errors::g_root = m.ptr();
    py_errors::add_error_classes({
        {"MotorbusError", {"RuntimeError"}, "Base of every error motorbus raises on purpose."},
        {"InvalidArgument", {"MotorbusError", "ValueError"}, "A value that can never be valid; the message names the field."},
        {"TimeoutError", {"MotorbusError", "TimeoutError"}, "A blocking call did not complete within its timeout."},
        {"ProtocolError", {"MotorbusError"}, "A peer sent bytes that break the protocol; .data holds them."},
        {"LinkDown", {"MotorbusError", "ConnectionError"}, "The link to the peer is gone."},
        {"ClosedError", {"MotorbusError"}, "The bus or port was closed."},
        {"DriveFault", {"MotorbusError"}, "The drive reported a fault or rejected a command."},
    });
    m.attr("ProtocolError").attr("data") = py::bytes();
    // Base first: later registrations are tried first, so the derived types win.
    translate<Error>(m.attr("MotorbusError"));
    translate<InvalidArgument>(m.attr("InvalidArgument"));
    translate<motorbus::TimeoutError>(m.attr("TimeoutError"));
    translate<ProtocolError, fill_bytes>(m.attr("ProtocolError"));
    translate<LinkDown>(m.attr("LinkDown"));
    translate<ClosedError>(m.attr("ClosedError"));
    translate<DriveFault>(m.attr("DriveFault"));
}

// Maps the C++ error types (cpp/motorbus/errors.hpp) to Python exceptions.
// Each also derives from the matching built-in (ValueError, TimeoutError,
// ConnectionError) so generic `except` clauses keep working.
#include <pybind11/eval.h>
#include <pybind11/pybind11.h>

#include "motorbus/errors.hpp"

namespace py = pybind11;

namespace {
py::handle g_protocol_error;
}

void bind_errors(py::module_& m) {
    using namespace motorbus;
    auto base = py::exception<Error>(m, "MotorbusError", PyExc_RuntimeError);
    // Multiple bases: build the classes in Python so they inherit from both.
    py::dict ns;
    ns["MotorbusError"] = base;
    py::exec(R"(
class InvalidArgument(MotorbusError, ValueError):
    "A value that can never be valid; the message names the field."
class TimeoutError(MotorbusError, TimeoutError):
    "A blocking call did not complete within its timeout."
class ProtocolError(MotorbusError):
    "A peer sent bytes that break the protocol; .data holds them."
    data = b""
class LinkDown(MotorbusError, ConnectionError):
    "The link to the peer is gone."
class ClosedError(MotorbusError):
    "The bus or port was closed."
class DriveFault(MotorbusError):
    "The drive reported a fault or rejected a command."
)", ns, ns);
    for (const char* n : {"InvalidArgument", "TimeoutError", "ProtocolError", "LinkDown",
                          "ClosedError", "DriveFault"}) {
        py::object cls = ns[n];
        cls.attr("__module__") = "motorbus";
        m.attr(n) = cls;
    }
    base.attr("__module__") = "motorbus";
    g_protocol_error = py::object(ns["ProtocolError"]).release();
    static py::handle invalid = py::object(ns["InvalidArgument"]).release();
    static py::handle timeout = py::object(ns["TimeoutError"]).release();
    static py::handle link = py::object(ns["LinkDown"]).release();
    static py::handle closed = py::object(ns["ClosedError"]).release();
    static py::handle fault = py::object(ns["DriveFault"]).release();

    // Translators run most-recently-registered first; derived types first here
    // is handled by catching them explicitly in order.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InvalidArgument& e) {
            PyErr_SetString(invalid.ptr(), e.what());
        } catch (const motorbus::TimeoutError& e) {
            PyErr_SetString(timeout.ptr(), e.what());
        } catch (const ProtocolError& e) {
            py::object exc = py::reinterpret_borrow<py::object>(g_protocol_error)(e.what());
            exc.attr("data") = py::bytes(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size());
            PyErr_SetObject(g_protocol_error.ptr(), exc.ptr());
        } catch (const LinkDown& e) {
            PyErr_SetString(link.ptr(), e.what());
        } catch (const ClosedError& e) {
            PyErr_SetString(closed.ptr(), e.what());
        } catch (const DriveFault& e) {
            PyErr_SetString(fault.ptr(), e.what());
        }
    });
}

// One way for every bindings file to give a C++ error type its Python class.
//
// A table row names the class, its bases and its doc; `add_error_classes`
// creates them (motorbus.<name>, no Python source inside C++) and
// `translate<E, Fill>` maps the C++ type E to its class, with `Fill` copying
// the type's fields (the offending bytes, an abort code...) onto the instance.
// pybind11 tries the most recently registered translator first, so a file
// registers base types before the types derived from them.
#pragma once
#include <pybind11/pybind11.h>

#include <exception>
#include <initializer_list>

namespace motorbus::py_errors {
namespace py = pybind11;

struct ErrorClass {
    const char* name;                          // motorbus.<name>
    std::initializer_list<const char*> bases;  // classes of _core first, then builtins
    const char* doc;
};

// Creates each class of `table` at the top level of _core, whichever area or
// vendor submodule declares it (its __module__ = `module_name`): the errors are one
// table, caught everywhere; look them up with error_class(name).
void add_error_classes(std::initializer_list<ErrorClass> table, const char* module_name = "motorbus");

// The error class `name` of _core's top level (created by add_error_classes).
py::object error_class(const char* name);

template <class E, auto Fill = nullptr>
struct Translator {
    static inline py::handle cls;
    static void run(std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const E& e) {
            py::object exc = py::reinterpret_borrow<py::object>(cls)(e.what());
            if constexpr (Fill != nullptr) Fill(exc, e);
            PyErr_SetObject(cls.ptr(), exc.ptr());
        }
    }
};

// Maps C++ E to the Python class `cls` (kept alive for the interpreter's life).
template <class E, auto Fill = nullptr>
void translate(py::handle cls) {
    Translator<E, Fill>::cls = cls.inc_ref();
    py::register_exception_translator(&Translator<E, Fill>::run);
}

}  // namespace motorbus::py_errors

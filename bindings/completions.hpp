// Completions in Python: how a C++ completion value becomes a Python object.
//
// A completion-based entry point (an SDO transfer, a line transaction, a bus
// receive) pushes a plain C++ value into a motorbus::Completions; the loop's
// drain converts the batch here, on the loop thread, with the GIL it already
// holds.  Each bindings file registers the C++ types its entry points produce
// (py_completions::convertible<T>()); bytes-like values come out as bytes.
#pragma once
#include <pybind11/pybind11.h>

#include <any>
#include <typeindex>

namespace motorbus::py_completions {
namespace py = pybind11;

using Converter = py::object (*)(const std::any&);
void register_converter(std::type_index type, Converter convert);

template <class T>
void convertible() {
    register_converter(typeid(T), [](const std::any& a) { return py::cast(std::any_cast<const T&>(a)); });
}

// The value as Python: None for an empty value; TypeError for a type nobody registered.
py::object to_python(const std::any& value);

}  // namespace motorbus::py_completions

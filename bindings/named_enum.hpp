// C++ enums bound as py::enum_ that the Python API may also name with a string.
//
// A native client may take a manual's words ("ON", "sc"...) as well as the enum
// members: the C++ enum is bound once with its names (named_enum), and a
// function taking it declares its parameter as EnumOrName<E> (shown as
// `<Enum> | str` in the stubs) and converts with enum_arg<E>.  The names are the
// bound enum's own, matched in any case, plus a few aliases; an unknown name
// or another type raises InvalidArgument naming the argument and the choices.
// The enum also converts by itself: <Enum>("on") is <Enum>.ON.
#pragma once
#include <pybind11/pybind11.h>
#include <pybind11/typing.h>

#include <cctype>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common.hpp"

namespace motorbus::py_helpers {

template <class E>
using EnumOrName = pybind11::typing::Union<E, pybind11::str>;

template <class E>
struct EnumNames {
    inline static std::string what;     // the argument, for errors: "POWER", "radix"...
    inline static std::string choices;  // "ON, OFF or SC"
    inline static std::vector<std::pair<std::string, E>> names;  // upper case; members, then aliases
};

inline std::string upper(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return out;
}

template <class E>
E enum_from_name(std::string_view name) {
    const std::string key = upper(name);
    for (const auto& [n, v] : EnumNames<E>::names)
        if (n == key) return v;
    throw InvalidArgument(EnumNames<E>::what + ": '" + std::string(name) + "' is not " + EnumNames<E>::choices);
}

// A member of the bound enum, or one of its names.
template <class E>
E enum_arg(const pybind11::handle& h) {
    if (pybind11::isinstance<E>(h)) return h.cast<E>();
    if (pybind11::isinstance<pybind11::str>(h)) return enum_from_name<E>(h.cast<std::string>());
    throw InvalidArgument(EnumNames<E>::what + ": expected " + EnumNames<E>::choices + ", got " + py_type_name(h));
}

// Binds E as `py_name` with `members` (Python name, value) and registers them,
// with `aliases`, as the names enum_arg<E> takes.  `what` names the argument.
template <class E>
pybind11::enum_<E> named_enum(pybind11::handle scope, const char* py_name, const char* doc, const char* what,
                              std::initializer_list<std::pair<const char*, E>> members,
                              std::initializer_list<std::pair<const char*, E>> aliases = {}) {
    pybind11::enum_<E> e(scope, py_name, doc);
    EnumNames<E>::what = what;
    EnumNames<E>::names.clear();
    std::string choices;
    std::size_t i = 0;
    for (const auto& [n, v] : members) {
        e.value(n, v);
        EnumNames<E>::names.emplace_back(upper(n), v);
        choices += (i == 0 ? "" : i + 1 == members.size() ? " or " : ", ") + std::string(n);
        ++i;
    }
    for (const auto& [n, v] : aliases) EnumNames<E>::names.emplace_back(upper(n), v);
    EnumNames<E>::choices = choices;
    e.def(pybind11::init([](const std::string& name) { return enum_from_name<E>(name); }), pybind11::arg("name"));
    return e;
}

// A method taking E, bound to take EnumOrName<E>: converted with the GIL held,
// run with it released (the method talks to a device).
template <class C, class E>
auto enum_method(void (C::*f)(E)) {
    return [f](C& c, const EnumOrName<E>& arg) {
        const E v = enum_arg<E>(arg);
        pybind11::gil_scoped_release nogil;
        (c.*f)(v);
    };
}

}  // namespace motorbus::py_helpers

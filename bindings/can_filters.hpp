// python-can style acceptance filters ({"can_id", "can_mask", "extended"}) to
// motorbus Filters; shared by every bindings file that takes filters.
#pragma once
#include <pybind11/pybind11.h>

#include <vector>

#include "common.hpp"
#include "motorbus/can/frame.hpp"

namespace motorbus::py_helpers {

inline std::vector<can::Filter> filters_from_py(const pybind11::object& filters) {
    namespace py = pybind11;
    std::vector<can::Filter> out;
    if (filters.is_none()) return out;
    for (auto h : arg_iterable(filters, "filters", "a list of {'can_id', 'can_mask', 'extended'} dicts")) {
        if (!py::isinstance<py::dict>(h))
            throw InvalidArgument("filters: each filter must be a dict with 'can_id', got " + py_type_name(h));
        auto d = py::reinterpret_borrow<py::dict>(h);
        if (!d.contains("can_id")) throw InvalidArgument("filters: a filter without 'can_id'");
        can::Filter f;
        f.id = arg_cast<std::uint32_t>(d["can_id"], "filters: can_id", "an int 0-0x1FFFFFFF");
        f.mask = d.contains("can_mask") ? arg_cast<std::uint32_t>(d["can_mask"], "filters: can_mask", "an int")
                                        : can::kMaxExtendedId;
        if (d.contains("extended") && !d["extended"].is_none()) {
            f.match_extended = true;
            f.extended = arg_cast<bool>(d["extended"], "filters: extended", "a bool");
        }
        out.push_back(f);
    }
    return out;
}

}  // namespace motorbus::py_helpers

// python-can style acceptance filters ({"can_id", "can_mask", "extended"}) to
// motorbus Filters; shared by every bindings file that takes filters.
#pragma once
#include <pybind11/pybind11.h>

#include <vector>

#include "motorbus/can/frame.hpp"

namespace motorbus::py_helpers {

inline std::vector<can::Filter> filters_from_py(const pybind11::object& filters) {
    namespace py = pybind11;
    std::vector<can::Filter> out;
    if (filters.is_none()) return out;
    for (auto h : filters) {
        auto d = py::reinterpret_borrow<py::dict>(h);
        can::Filter f;
        f.id = d["can_id"].cast<std::uint32_t>();
        f.mask = d.contains("can_mask") ? d["can_mask"].cast<std::uint32_t>() : can::kMaxExtendedId;
        if (d.contains("extended") && !d["extended"].is_none()) {
            f.match_extended = true;
            f.extended = d["extended"].cast<bool>();
        }
        out.push_back(f);
    }
    return out;
}

}  // namespace motorbus::py_helpers

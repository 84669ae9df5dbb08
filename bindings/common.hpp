// Small helpers shared by the bindings files.
#pragma once
#include <pybind11/pybind11.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace motorbus::py_helpers {
namespace py = pybind11;

// Python timeouts are float seconds; None means "wait forever" (-1 ns).
inline std::chrono::nanoseconds seconds_to_ns(const py::object& t) {
    if (t.is_none()) return std::chrono::nanoseconds(-1);
    double s = t.cast<double>();
    if (std::isnan(s)) throw py::value_error("timeout: NaN is not a duration");
    if (s < 0) s = 0;
    if (s > 1e9) return std::chrono::nanoseconds(-1);
    return std::chrono::nanoseconds(static_cast<std::int64_t>(s * 1e9));
}

// Holds a Python callable so it can be called and released from C++ threads:
// the GIL is taken for the call and for the final decref.
class PyCallable {
public:
    explicit PyCallable(py::function f) : f_(new py::function(std::move(f)), Release{}) {}
    template <class... A>
    void operator()(A&&... args) const {
        py::gil_scoped_acquire gil;
        try {
            (*f_)(std::forward<A>(args)...);
        } catch (py::error_already_set& e) {
            // An exception in a user callback must not kill the I/O thread.
            e.discard_as_unraisable("motorbus callback");
        }
    }

    // Calls with the GIL held by the caller; Python exceptions propagate as
    // error_already_set (for paths where the C++ caller must see the failure).
    template <class... A>
    py::object call(A&&... args) const {
        return (*f_)(std::forward<A>(args)...);
    }

private:
    struct Release {
        void operator()(py::function* p) const {
            if (!Py_IsInitialized()) return;  // interpreter gone: leak rather than crash
            py::gil_scoped_acquire gil;
            delete p;
        }
    };
    std::shared_ptr<py::function> f_;
};

// A C++ counters/status struct bound as a read-only Python class whose
// __repr__ lists every field:
//     Record<BusCounters>(m, "BusCounters", "doc").field("rx_frames", &BusCounters::rx_frames)...;
// (fields are def_readonly; `prop` adds a computed read-only attribute).
template <class T>
class Record {
public:
    Record(py::handle scope, const char* name, const char* doc)
        : cls_(scope, name, doc), names_(std::make_shared<std::vector<const char*>>()) {
        auto names = names_;
        std::string cls_name = name;
        cls_.def("__repr__", [names, cls_name](py::handle self) {
            std::string out = cls_name + "(";
            for (std::size_t i = 0; i < names->size(); ++i) {
                if (i) out += ", ";
                out += (*names)[i];
                out += "=";
                out += py::repr(self.attr((*names)[i])).template cast<std::string>();
            }
            return out + ")";
        });
    }
    template <class D>
    Record& field(const char* name, const D T::*pm, const char* doc = "") {
        cls_.def_readonly(name, pm, doc);
        names_->push_back(name);
        return *this;
    }
    template <class F>
    Record& prop(const char* name, F&& getter, const char* doc = "") {
        cls_.def_property_readonly(name, std::forward<F>(getter), doc);
        names_->push_back(name);
        return *this;
    }
    py::class_<T>& cls() { return cls_; }

private:
    py::class_<T> cls_;
    std::shared_ptr<std::vector<const char*>> names_;
};

}  // namespace motorbus::py_helpers

// Small helpers shared by the bindings files.
#pragma once
#include <pybind11/pybind11.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

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


}  // namespace motorbus::py_helpers

// Small helpers shared by the bindings files.
#pragma once
#include <pybind11/pybind11.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "motorbus/runtime/interrupt.hpp"

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

// ---- blocking calls: GIL released, Ctrl-C live, safe at interpreter exit ----------
//
// Every call that may block goes through blocking_call() (an opaque C++ wait)
// or interruptible_wait() (a wait the binding can slice itself).  On the main
// thread (the only one Python delivers signals to) the wait wakes every
// kInterruptSlice (50 ms), takes the GIL and runs PyErr_CheckSignals(): a
// pending KeyboardInterrupt (or whatever a signal handler raised) abandons the
// wait and propagates.  C++ waits inside the core see the same check through
// motorbus::InterruptScope (cpp/motorbus/runtime/interrupt.hpp).
//
// A thread that comes back from C++ while the interpreter finalizes (a daemon
// thread in recv(None) at exit) must not take the GIL: CPython would end the
// thread from inside the GIL request (pthread_exit), whose forced unwind through
// a destructor aborts the process ("terminate called").  Such a thread parks
// until the process is gone instead.

inline bool interpreter_finalizing() {
#if PY_VERSION_HEX >= 0x030D0000
    return Py_IsFinalizing() != 0;
#else
    return _Py_IsFinalizing() != 0;
#endif
}

[[noreturn]] inline void park_until_exit() {
    for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
}

// Thrown through C++ frames by the interrupt check; the Python error is set.
struct PythonErrorPending {};

inline void check_python_signals() {
    if (interpreter_finalizing()) park_until_exit();
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw PythonErrorPending{};
}

inline bool on_main_python_thread() {
    // Caller holds the GIL.  threading.main_thread() never changes.
    static const unsigned long main_ident =
        py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
    return PyThread_get_thread_ident() == main_ident;
}

// Releases the GIL; reacquire() takes it back, or parks the thread if the
// interpreter finalizes.  reacquire() is an ordinary call, not a destructor: a
// thread already queued for the GIL when finalization starts is ended by CPython
// with a forced unwind, which may pass through ordinary frames (and pybind11's
// dispatcher rethrows it) but aborts the process in a noexcept one.
class GilRelease {
public:
    GilRelease() : state_(PyEval_SaveThread()) {}
    void reacquire() {
        if (!state_) return;
        PyThreadState* s = state_;
        state_ = nullptr;
        if (interpreter_finalizing()) park_until_exit();
        PyEval_RestoreThread(s);
    }
    ~GilRelease() { reacquire(); }  // only if a path forgot reacquire()
    GilRelease(const GilRelease&) = delete;
    GilRelease& operator=(const GilRelease&) = delete;

private:
    PyThreadState* state_;
};

// Runs fn() (a wait inside the C++ core) with the GIL released and Ctrl-C live.
template <class F>
decltype(auto) blocking_call(F&& fn) {
    using R = std::invoke_result_t<F&>;
    const bool main = on_main_python_thread();
    GilRelease nogil;
    auto run = [&]() -> R {
        if (!main) return fn();
        InterruptScope interrupt(&check_python_signals);
        return fn();
    };
    try {
        if constexpr (std::is_void_v<R>) {
            run();
            nogil.reacquire();
        } else {
            R r = run();
            nogil.reacquire();
            return r;
        }
    } catch (const PythonErrorPending&) {
        nogil.reacquire();
        throw py::error_already_set();
    } catch (...) {
        nogil.reacquire();
        throw;
    }
}

// A wait the binding slices itself: slice(d) waits at most d (>= 0, or the
// whole `timeout` off the main thread, negative = forever) and returns a
// std::optional, nullopt for "nothing yet".  Returns nullopt after `timeout`
// (negative = never).
template <class Slice>
auto interruptible_wait(std::chrono::nanoseconds timeout, Slice&& slice) {
    using Result = std::invoke_result_t<Slice&, std::chrono::nanoseconds>;
    return blocking_call([&]() -> Result {
        if (!interruptible()) return slice(timeout);
        using SC = std::chrono::steady_clock;
        const bool forever = timeout.count() < 0;
        const auto deadline = forever ? SC::time_point::max() : SC::now() + timeout;
        for (;;) {
            std::chrono::nanoseconds d = kInterruptSlice;
            if (!forever) d = std::min<std::chrono::nanoseconds>(d, std::max(deadline - SC::now(), SC::duration::zero()));
            if (Result r = slice(d)) return r;
            if (!forever && SC::now() >= deadline) return Result{};
            interruption_point();
        }
    });
}

// A member function bound as a blocking call: .def("read_u8", &Blocking<&SdoClient::read_u8>::call, ...).
template <auto M>
struct Blocking;
template <class C, class R, class... A, R (C::*M)(A...)>
struct Blocking<M> {
    static R call(C& self, A... a) {
        return blocking_call([&]() -> R { return (self.*M)(std::forward<A>(a)...); });
    }
};

// Holds a Python callable so it can be called and released from C++ threads:
// the GIL is taken for the call and for the final decref.
class PyCallable {
public:
    explicit PyCallable(py::function f) : f_(new py::function(std::move(f)), Release{}) {}
    template <class... A>
    void operator()(A&&... args) const {
        if (interpreter_finalizing()) return;  // taking the GIL now would end this thread
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

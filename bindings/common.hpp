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

#include "motorbus/errors.hpp"
#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::py_helpers {
namespace py = pybind11;

// ---- durations: one rule for every Python duration (seconds) -------------------
//
//   * a number of seconds >= 0 (int, float, anything with __float__);
//   * NaN, negative, or not a number: InvalidArgument naming the argument;
//   * Forever::Allowed (the timeout of a blocking call, which Ctrl-C can end):
//     None, inf and anything above kMaxSeconds wait forever -> kForever (-1 ns,
//     the core's "no deadline"); use finite_forever() for an API that adds the
//     duration to the current time;
//   * Forever::Refused (periods, delays, server-side and poll intervals): None,
//     inf and anything above kMaxSeconds are InvalidArgument.
enum class Forever : bool { Refused, Allowed };
inline constexpr double kMaxSeconds = 1e9;  // ~31.7 years: seconds * 1e9 stays far inside int64 ns
inline constexpr std::chrono::nanoseconds kForever{-1};
inline constexpr std::chrono::nanoseconds kFiniteForever{static_cast<std::int64_t>(kMaxSeconds * 1e9)};

inline std::chrono::nanoseconds duration_arg(double s, const char* name, Forever forever = Forever::Refused) {
    if (std::isnan(s)) throw InvalidArgument(std::string(name) + ": NaN is not a duration");
    if (s < 0) throw InvalidArgument(std::string(name) + ": must be >= 0 seconds, got " + std::to_string(s));
    if (s > kMaxSeconds) {
        if (forever == Forever::Allowed) return kForever;
        throw InvalidArgument(std::string(name) + (std::isinf(s) ? ": must be finite" : ": too large (at most 1e9 seconds)"));
    }
    return std::chrono::nanoseconds(static_cast<std::int64_t>(s * 1e9));
}

inline std::chrono::nanoseconds duration_arg(const py::handle& v, const char* name, Forever forever = Forever::Refused) {
    if (v.is_none()) {
        if (forever == Forever::Allowed) return kForever;
        throw InvalidArgument(std::string(name) + ": None is not a duration here (a number of seconds)");
    }
    const double s = PyFloat_AsDouble(v.ptr());
    if (s == -1.0 && PyErr_Occurred()) {
        const bool overflow = PyErr_ExceptionMatches(PyExc_OverflowError);
        PyErr_Clear();
        if (overflow) return duration_arg(std::numeric_limits<double>::infinity(), name, forever);
        throw InvalidArgument(std::string(name) + ": expected a number of seconds, got " +
                              py::str(py::type::handle_of(v).attr("__name__")).cast<std::string>());
    }
    return duration_arg(s, name, forever);
}

// kForever -> a duration an API can add to the current time.
inline std::chrono::nanoseconds finite_forever(std::chrono::nanoseconds d) { return d.count() < 0 ? kFiniteForever : d; }

// A blocking call's timeout: None/inf = forever (-1 ns).  Kept for the vendor bindings.
inline std::chrono::nanoseconds seconds_to_ns(const py::object& t, const char* name = "timeout") {
    return duration_arg(t, name, Forever::Allowed);
}

// ---- typed argument errors --------------------------------------------------------
//
// A bad argument raises InvalidArgument naming it (see docs/architecture.md);
// pybind11's "incompatible function arguments" TypeError stays only for what
// overload resolution rejects.  Functions taking py::object convert with these.

inline std::string py_type_name(const py::handle& h) {
    return py::str(py::type::handle_of(h).attr("__name__")).cast<std::string>();
}

// h.cast<T>(), or InvalidArgument("<name>: expected <expected>, got <type>").
template <class T>
T arg_cast(const py::handle& h, const char* name, const char* expected) {
    try {
        return h.cast<T>();
    } catch (const py::cast_error&) {
    } catch (const py::error_already_set& e) {
        if (!e.matches(PyExc_TypeError) && !e.matches(PyExc_OverflowError) && !e.matches(PyExc_ValueError)) throw;
    }
    throw InvalidArgument(std::string(name) + ": expected " + expected + ", got " + py_type_name(h) +
                          (py::isinstance<py::int_>(h) || py::isinstance<py::float_>(h) ? " " + py::repr(h).cast<std::string>() : ""));
}

// An iterable argument, or InvalidArgument naming it.
inline py::iterable arg_iterable(const py::handle& h, const char* name, const char* expected) {
    if (!py::isinstance<py::iterable>(h) || py::isinstance<py::str>(h) || py::isinstance<py::bytes>(h))
        throw InvalidArgument(std::string(name) + ": expected " + expected + ", got " + py_type_name(h));
    return py::reinterpret_borrow<py::iterable>(h);
}

// pybind11 turns None into a null holder: refuse it before anything dereferences it.
template <class P>
const P& not_none(const P& p, const char* name) {
    if (!p) throw InvalidArgument(std::string(name) + ": None (an object is required)");
    return p;
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

// Bindings for cpp/motorbus/runtime: clocks.
#include <pybind11/pybind11.h>

#include <typeindex>
#include <unordered_map>

#include "common.hpp"
#include "errors.hpp"
#include "completions.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/runtime/completions.hpp"

namespace py = pybind11;
using namespace motorbus;

namespace motorbus::py_completions {
namespace {
std::unordered_map<std::type_index, Converter>& converters() {
    static std::unordered_map<std::type_index, Converter> table;
    return table;
}
}  // namespace

void register_converter(std::type_index type, Converter convert) { converters()[type] = convert; }

py::object to_python(const std::any& value) {
    if (!value.has_value()) return py::none();
    auto it = converters().find(value.type());
    if (it == converters().end())
        throw py::type_error(std::string("motorbus: no Python form for a completion of C++ type ") + value.type().name());
    return it->second(value);
}
}  // namespace motorbus::py_completions

namespace {
// A failed completion's error, raised in Python by rethrow(): the exception goes
// through pybind11's usual translation, so it is the motorbus error class the
// blocking call would have raised.
struct CompletionFailure {
    std::exception_ptr error;
    void rethrow() const { std::rethrow_exception(error); }
};

void bind_completions(py::module_& m) {
    namespace pc = motorbus::py_completions;
    pc::convertible<bool>();
    pc::convertible<int>();
    pc::convertible<std::int32_t>();
    pc::convertible<std::uint32_t>();
    pc::convertible<std::int64_t>();
    pc::convertible<std::uint64_t>();
    pc::convertible<float>();
    pc::convertible<double>();
    pc::convertible<std::string>();
    pc::register_converter(typeid(std::vector<std::uint8_t>), [](const std::any& a) -> py::object {
        const auto& b = std::any_cast<const std::vector<std::uint8_t>&>(a);
        return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
    });
    py::class_<CompletionFailure>(m, "CompletionFailure")
        .def("rethrow", &CompletionFailure::rethrow, "Raises the operation's error.");
    py::class_<Completions, std::shared_ptr<Completions>>(
        m, "Completions",
        "Finished operations for one event loop: a queue and the eventfd the loop watches "
        "(motorbus.aio drains it; see cpp/motorbus/runtime/completions.hpp).")
        .def(py::init<>())
        .def("fileno", &Completions::fd)
        .def("drain",
             [](Completions& c) {
                 auto batch = c.drain();
                 py::list out(batch.size());
                 std::size_t i = 0;
                 for (auto& x : batch) {
                     py::object failure = x.error ? py::cast(CompletionFailure{x.error}) : py::none();
                     py::object value = x.error ? py::none() : pc::to_python(x.value);
                     out[i++] = py::make_tuple(x.token, std::move(value), std::move(failure));
                 }
                 return out;
             },
             "[(token, value, failure or None)] of everything queued, oldest first.")
        .def("notify", &Completions::notify, "Wakes the loop without a completion.")
        .def("push_none", [](Completions& c, std::uint64_t token) { c.push(token, {}); }, py::arg("token"),
             "Queues an empty completion (tests; Python threads deliver their results another way).")
        .def_property_readonly("pending", &Completions::pending)
        .def_property_readonly("pushed", &Completions::pushed)
        .def_property_readonly("wakeups", &Completions::wakeups)
        .def("set_wakeup",
             [](Completions& c, py::object f) {
                 if (f.is_none()) {
                     c.set_wakeup({});
                     return;
                 }
                 // Only for loops that cannot watch a descriptor: this takes the GIL
                 // once per burst (not per completion), on the pushing thread.
                 auto holder = std::shared_ptr<py::object>(new py::object(std::move(f)), [](py::object* o) {
                     if (!Py_IsInitialized()) return;     // the interpreter is gone: leak, do not touch it
                     py::gil_scoped_acquire gil;
                     delete o;
                 });
                 c.set_wakeup([holder] {
                     if (!Py_IsInitialized()) return;
                     py::gil_scoped_acquire gil;
                     try {
                         (*holder)();
                     } catch (py::error_already_set& e) {
                         e.discard_as_unraisable("motorbus Completions wake-up");
                     }
                 });
             },
             py::arg("function"), "A function called at each wake-up (loops without add_reader); None = none.");
}
}  // namespace

void bind_runtime(py::module_& m) {
    // Safety net for argument conversions no helper names (common.hpp arg_cast):
    // a pybind11 cast failure inside a call is a bad argument, not a RuntimeError.
    static py::handle invalid_argument = py::object(motorbus::py_errors::error_class("InvalidArgument")).release();
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const py::cast_error& e) {
            PyErr_SetString(invalid_argument.ptr(), e.what());
        }
    });
    bind_completions(m);
    m.def("monotonic_ns", &monotonic_ns, "The monotonic clock frame timestamps use (ns).");
    py::class_<Clock, std::shared_ptr<Clock>>(m, "Clock")
        .def("now", &Clock::now, "Current time in ns.")
        .def("sleep_until",
             [](Clock& c, Nanos t) { return motorbus::py_helpers::blocking_call([&] { return c.sleep_until(t); }); },
             py::arg("t_ns"), "Wait until clock time t_ns; False if cancel() ended the wait. Ctrl-C interrupts.")
        .def("cancel", &Clock::cancel)
        .def_property_readonly("simulated", &Clock::simulated);
    py::class_<RealClock, Clock, std::shared_ptr<RealClock>>(m, "RealClock").def(py::init<>());
    py::class_<SimClock, Clock, std::shared_ptr<SimClock>>(m, "SimClock")
        .def(py::init<Nanos>(), py::arg("start_ns") = 0)
        .def("advance", &SimClock::advance, py::arg("dt_ns"))
        .def("set", &SimClock::set, py::arg("t_ns"));
}

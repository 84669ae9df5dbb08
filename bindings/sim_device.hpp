// What the bindings of every simulated CAN device (can::SimulatedDevice) share.
#pragma once
#include <pybind11/pybind11.h>

#include <memory>
#include <utility>

namespace motorbus::py_helpers {

// A simulator held by Python, destroyed without the GIL: its destructor closes
// it, which joins its threads and the bus callbacks it runs, and those may be
// waiting for the GIL (a Python callback, an SDO client in the same process).
// `Sim` derives from can::SimulatedDevice; bind it with a std::shared_ptr holder
// so that py::class_<Sim, can::SimulatedDevice, std::shared_ptr<Sim>> shares the
// one attach / close / attached binding of the base.
template <class Sim, class... Args>
std::shared_ptr<Sim> make_sim(Args&&... args) {
    return std::shared_ptr<Sim>(new Sim(std::forward<Args>(args)...), [](Sim* p) {
        if (Py_IsInitialized() && PyGILState_Check()) {
            pybind11::gil_scoped_release nogil;
            delete p;
        } else {
            delete p;
        }
    });
}

}  // namespace motorbus::py_helpers

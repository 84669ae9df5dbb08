// Bindings for cpp/motorbus/drives/cia402: the generic CiA 402 simulator and its
// object table.  Conversions and GIL release only.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "motorbus/drives/cia402/sim.hpp"
#include "sim_device.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::cia402;

namespace {
// The type codes of the Python objects table ("U32", "I8", "VISIBLE_STRING").
const char* type_code(canopen::DataType t) {
    switch (t) {
        case canopen::DataType::Unsigned8: return "U8";
        case canopen::DataType::Unsigned16: return "U16";
        case canopen::DataType::Unsigned32: return "U32";
        case canopen::DataType::Integer8: return "I8";
        case canopen::DataType::Integer16: return "I16";
        case canopen::DataType::Integer32: return "I32";
        default: return canopen::type_name(t);
    }
}

py::object default_of(const ObjectRow& r) {
    if (r.text_default) return py::str(r.text_default);
    return py::int_(r.default_value);
}
py::object opt(const std::optional<std::int64_t>& v) { return v ? py::object(py::int_(*v)) : py::object(py::none()); }
}  // namespace

void bind_cia402(py::module_& m) {
    m.def("objects", [] {
        py::list out;
        for (const auto& r : objects())
            out.append(py::make_tuple(r.index, r.sub, r.name, type_code(r.type), canopen::access_name(r.access),
                                      default_of(r), opt(r.low), opt(r.high), r.unit, r.persists, r.description));
        return out;
    }, "The generic CiA 402 simulator's objects: (index, sub, name, type, access, default, low, high, unit, "
       "persists, description).");
    m.def("object_dictionary", &object_dictionary, py::arg("node_id") = 1,
          "The same objects as a typed canopen.ObjectDictionary (types, access, limits, defaults, codecs): what the "
          "generic Drive adapter reads and writes by.");

    auto rel = py::call_guard<py::gil_scoped_release>();
    // attach / close / attached / describe / power_cycle: the SimulatedDevice base's.
    py::class_<Sim, can::SimulatedDevice, std::shared_ptr<Sim>>(m, "Sim",
        "A simulated CiA 402 drive served by a LocalNode (see cpp/motorbus/drives/cia402/sim.hpp).")
        .def(py::init([](int node_id, std::shared_ptr<Clock> clock, double steps_per_rev,
                         std::pair<double, double> home, std::optional<double> minus_limit,
                         std::optional<double> plus_limit, std::uint16_t heartbeat_ms, double start_position) {
                 if (node_id < 1 || node_id > 127)
                     throw InvalidArgument("cia402 sim: node-ID " + std::to_string(node_id) + " is outside 1..127");
                 SimOptions o{steps_per_rev, home, minus_limit, plus_limit, heartbeat_ms, start_position};
                 if (!clock) clock = std::make_shared<RealClock>();
                 return py_helpers::make_sim<Sim>(std::uint8_t(node_id), std::move(clock), o);
             }),
             py::arg("node_id"), py::arg("clock") = nullptr, py::kw_only(), py::arg("steps_per_rev") = 3200.0,
             py::arg("home") = std::pair<double, double>{1000, 1400}, py::arg("minus_limit") = -100000.0,
             py::arg("plus_limit") = 100000.0, py::arg("heartbeat_ms") = 0, py::arg("start_position") = 0.0)
        .def_property_readonly("node_id", &Sim::node_id)
        .def_property_readonly("od", &Sim::od_ptr)
        .def_property_readonly("pdo", &Sim::pdo)
        .def_property_readonly("heartbeat", &Sim::heartbeat)
        .def_property_readonly("lost_master", &Sim::lost_master,
                               "True once the master's heartbeat was lost (6007h applied).")
        .def_property_readonly("position", [](Sim& s) {
            py::gil_scoped_release nogil;
            return s.position();
        })
        .def_property_readonly("last_setpoint_ns", &Sim::last_setpoint_ns,
                               "Clock time (ns) of the last profile-position set-point the drive took, or None.")
        .def_property_readonly("state", [](Sim& s) { return std::string(canopen::to_string(s.axis().state())); })
        .def("inject_fault", &Sim::inject_fault, py::arg("error_code") = 0x5441, rel,
             "The drive detects a fault (default 0x5441 interlock): the motor stops, FAULT, 603Fh holds the code.")
        .def("force_limit", &Sim::force_limit, py::arg("direction"), py::arg("active") = true, rel,
             "The +limit (+1) or -limit (-1) switch closes whatever the position: a motion toward it stops.")
        .def("jam", &Sim::jam, py::arg("jammed") = true, rel,
             "The rotor blocks: past 6065h the drive faults with 0x8611 (statusword bit 13).")
        .def("set_stop_input", &Sim::set_stop_input, py::arg("active") = true, rel,
             "The quick-stop input (60FDh bit 16): its rising edge quick-stops a moving drive.");
}

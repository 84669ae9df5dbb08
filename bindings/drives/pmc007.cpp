// Bindings for cpp/motorbus/drives/pmc007: the profile model, the object
// dictionary table (the one source of the sim's OD and the shipped EDS), the
// offline-program codec and the simulator.  Conversions and GIL release only.
#include <cstdio>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "motorbus/drives/pmc007/od_table.hpp"
#include "motorbus/drives/pmc007/profile.hpp"
#include "motorbus/drives/pmc007/program.hpp"
#include "motorbus/drives/pmc007/sim.hpp"
#include "../sim_device.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::motion;
using namespace motorbus::pmc007;

namespace {

}  // namespace

void bind_pmc007(py::module_& m) {
    m.def("gear_acceleration", &gear_acceleration, py::arg("gear"));
    m.def("microsteps", &microsteps, py::arg("setting"));
    m.def("convert_position", &convert_position, py::arg("position"), py::arg("from_setting"),
          py::arg("to_setting"));
    py::class_<ProfileParams>(m, "ProfileParams")
        .def(py::init([](double speed, double start_speed, double stop_speed, int ag, int dg, int micro) {
                 ProfileParams p{speed, start_speed, stop_speed, ag, dg, micro};
                 p.validate();
                 return p;
             }),
             py::arg("speed") = 1000.0, py::arg("start_speed") = 400.0, py::arg("stop_speed") = 0.0,
             py::arg("accel_gear") = 0, py::arg("decel_gear") = 0, py::arg("microstepping") = 0)
        .def_readwrite("speed", &ProfileParams::speed)
        .def_readwrite("start_speed", &ProfileParams::start_speed)
        .def_readwrite("stop_speed", &ProfileParams::stop_speed)
        .def_readwrite("accel_gear", &ProfileParams::accel_gear)
        .def_readwrite("decel_gear", &ProfileParams::decel_gear)
        .def_readwrite("microstepping", &ProfileParams::microstepping);
    m.def("position_profile", &position_profile, py::arg("start"), py::arg("target"), py::arg("params"));
    m.def("speed_profile", &speed_profile, py::arg("start"), py::arg("speed"), py::arg("params"),
          py::arg("hold") = 0.0);

    // ---- the object dictionary table ----
    // Handed up as the typed dictionary itself (canopen.ObjectDictionary: types, access,
    // limits, defaults and the C++ codecs of each entry): the host profile (Pmc007)
    // reads and writes by it; nothing about a type is said again in Python.
    m.def("object_dictionary", [](std::uint8_t node_id) { return build_pmc007_od(node_id); },
          py::arg("node_id") = 5,
          "The PMC007 dictionary (every row of the table), defaults evaluated for `node_id`.");
    py::enum_<Storage>(m, "Storage", "How an object behaves over reset node / power-up (B-P37).")
        .value("ROM", Storage::Rom, "saved to flash by 2007h = 2, reloaded at reset node")
        .value("RAM", Storage::Ram, "back to the default at reset node / power-up")
        .value("CONST", Storage::Const, "never changes");
    m.def("storage", [](std::uint16_t index, std::uint8_t sub) {
              const OdRow* r = od_row(index, sub);
              if (!r) {
                  char where[16];
                  std::snprintf(where, sizeof where, "%04Xh:%02X", index, sub);
                  throw InvalidArgument(std::string("pmc007: no object ") + where);
              }
              return r->storage;
          }, py::arg("index"), py::arg("subindex") = 0, "The table's storage class of one object (B-P37).");
    m.def("eds", &eds, "The EDS text generated from the table (node-ID as $NODEID).");

    // ---- offline program codec ----
    m.def("assemble", [](const std::string& text) { return assemble(text); }, py::arg("text"),
          "Mnemonic text -> 32-bit words (the spec's reading of the encoding).");
    m.def("disassemble", [](const std::vector<std::uint32_t>& w) { return disassemble(w); }, py::arg("words"));

    // ---- the simulator ----
    auto rel = py::call_guard<py::gil_scoped_release>();
    // attach / close / attached / describe / power_cycle: the SimulatedDevice base's.
    py::class_<Sim, can::SimulatedDevice, std::shared_ptr<Sim>>(m, "Sim",
                                                              "A simulated CQPUSI PMC007 CANopen node (see sim.hpp).")
        .def(py::init([](int node_id, std::shared_ptr<Clock> clock, double steps_per_rev, double pull_out_speed,
                         std::optional<std::pair<double, double>> ext1_switch, std::string store_path,
                         std::uint32_t vendor_id, std::uint32_t product_code, std::uint32_t revision,
                         std::uint32_t serial) {
                 if (node_id < 1 || node_id > 127)
                     throw InvalidArgument("pmc007 sim: node-ID must be 1..127, not " + std::to_string(node_id));
                 SimOptions o;
                 o.steps_per_rev = steps_per_rev;
                 o.pull_out_speed = pull_out_speed;
                 o.ext1_switch = ext1_switch;
                 o.store_path = std::move(store_path);
                 o.identity = {vendor_id, product_code, revision, serial};
                 if (!clock) clock = std::make_shared<RealClock>();
                 return py_helpers::make_sim<Sim>(std::uint8_t(node_id), std::move(clock), o);
             }),
             py::arg("node_id") = 5, py::arg("clock") = nullptr, py::arg("steps_per_rev") = 200.0,
             py::arg("pull_out_speed") = 0.0, py::arg("ext1_switch") = py::none(),
             py::arg("store_path") = "", py::arg("vendor_id") = 0u, py::arg("product_code") = 7u,
             py::arg("revision") = 0x00010000u, py::arg("serial") = 1u)
        .def_property_readonly("last_error", &Sim::last_error,
                               "why the last node-ID switch or return to the bus failed ('' if none did)")
        .def("poll", &Sim::poll, rel)
        .def_property_readonly("node_id", &Sim::node_id)
        .def_property_readonly("error_status", &Sim::error_status)
        .def_property_readonly("controller_status", &Sim::controller_status)
        .def_property_readonly("position", &Sim::position)
        .def_property_readonly("velocity", &Sim::velocity)
        .def_property_readonly("busy", &Sim::busy)
        .def_property_readonly("enabled", &Sim::enabled)
        .def_property_readonly("gpio_value", &Sim::gpio_value)
        .def_property_readonly("active_baud_index", &Sim::active_baud_index)
        .def_property_readonly("active_encoder_cpr", &Sim::active_encoder_cpr,
                               "The encoder CPR in use: 6021h as it was at the last power-up or reset node (B-P40).")
        .def_property_readonly("od", &Sim::od_ptr)
        .def_property_readonly("flash_program", &Sim::flash_program)
        .def_property_readonly("ram_program", &Sim::ram_program)
        .def_property_readonly("program_running", &Sim::program_running)
        .def_property_readonly("program_pointer", &Sim::program_pointer)
        .def_property_readonly("program_counter", &Sim::program_counter_value)
        .def_property_readonly("emcy_sent", &Sim::emcy_sent)
        .def_property_readonly("in_bootloader", &Sim::in_bootloader)
        .def("set_jammed", &Sim::set_jammed, py::arg("jammed"))
        .def("set_input", &Sim::set_input, py::arg("bit"), py::arg("high"), rel,
             "Electrical level of input port `bit` (6012h bit 0..10; 7 EXT1, 8 EXT2, 9 ENC1/EXT3).")
        .def("inject_error", &Sim::inject_error, py::arg("bits"), rel, "Latch 6000h error bits (EMCY sent).");
}

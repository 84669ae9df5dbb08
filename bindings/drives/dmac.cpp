// Bindings for cpp/motorbus/drives/dmac: Sim (a LineDevice), Client,
// the global SYNCHRO commands, interpolation streaming and a few codec helpers.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "errors.hpp"
#include "named_enum.hpp"
#include "motorbus/drives/dmac/client.hpp"
#include "motorbus/drives/dmac/codec.hpp"
#include "motorbus/drives/dmac/poll_source.hpp"
#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/serial/line_device.hpp"
#include "motorbus/serial/port.hpp"
#include "motorbus/drives/dmac/profile.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::dmac;
using motorbus::py_helpers::Record;
using motorbus::py_helpers::enum_arg;
using motorbus::py_helpers::EnumOrName;
using motorbus::py_helpers::enum_method;
using motorbus::py_helpers::named_enum;

namespace {


Var var_arg(const std::string& name) {
    auto v = find_variable(name);
    if (!v) throw InvalidArgument("DMAC variable: '" + name + "' is not a DMAC variable name or mnemonic");
    return *v;
}

std::function<void(Duration)> sleep_arg(const py::object& f) {
    if (f.is_none()) return {};
    motorbus::py_helpers::PyCallable cb(f.cast<py::function>());
    return [cb](Duration d) { cb(static_cast<double>(d.count()) / 1e9); };
}

template <class T>
std::function<void(Client&, T)> dmac_setter(void (Client::*f)(T)) {
    return [f](Client& c, T v) {
        py::gil_scoped_release nogil;
        (c.*f)(v);
    };
}

}  // namespace

namespace {
// The vendor's profile model (and homing), bound with the vendor.
void bind_dmac_motion(py::module_& m) {
    using namespace motorbus::motion;
    // ---- DMAC ------------------------------------------------------------------
    py::class_<ProfileParams>(m, "ProfileParams")
        .def(py::init([](std::int32_t hs, std::int32_t ls, std::int32_t ati, std::int32_t dti, bool sc) {
                 ProfileParams p{hs, ls, ati, dti, sc};
                 p.validate();
                 return p;
             }),
             py::arg("high_speed") = 60000, py::arg("low_speed") = 6000, py::arg("accel_time_ms") = 1000,
             py::arg("decel_time_ms") = 1000, py::arg("s_curve") = false)
        .def_readwrite("high_speed", &ProfileParams::high_speed)
        .def_readwrite("low_speed", &ProfileParams::low_speed)
        .def_readwrite("accel_time_ms", &ProfileParams::accel_time_ms)
        .def_readwrite("decel_time_ms", &ProfileParams::decel_time_ms)
        .def_readwrite("s_curve", &ProfileParams::s_curve);
    m.def("ramp_time", &ramp_time, py::arg("params"), py::arg("v_from"), py::arg("v_to"));
    m.def("position_profile", &position_profile, py::arg("start"), py::arg("target"), py::arg("params"));
    m.def("speed_profile", &speed_profile, py::arg("start"), py::arg("speed"), py::arg("params"),
          py::arg("hold") = 0.0);
    py::class_<Motion>(m, "Motion")
        .def(py::init<ProfileParams, double>(), py::arg("params") = ProfileParams{}, py::arg("position") = 0.0)
        .def("set_params", &Motion::set_params)
        .def("move_to", &Motion::move_to, py::arg("t"), py::arg("target"))
        .def("move_on", &Motion::move_on, py::arg("t"), py::arg("offset"))
        .def("move_speed", &Motion::move_speed, py::arg("t"), py::arg("speed"))
        .def("stop", &Motion::stop, py::arg("t"))
        .def_property_readonly("profile", &Motion::profile, py::return_value_policy::copy)
        .def("moving", &Motion::moving, py::arg("t"));

}
}  // namespace

namespace {
void fill_rejected(py::object& exc, const CommandRejected& e) { exc.attr("error") = e.error; }
}  // namespace

static void bind_dmac_client_commands(py::class_<Client, std::shared_ptr<Client>>& cls);
static void bind_dmac_streaming(py::module_& m);

static void bind_dmac_codec(py::module_& m) {
    bind_dmac_motion(m);
    // ---- errors ---------------------------------------------------------------
    py_errors::add_error_classes({
        {"DmacUnknownCommand", {"DriveFault"},
         "The DMAC rejected a command as undefined (#ERROR bit 12), or a peer answered '?'."},
        {"DmacCommandRejected", {"DriveFault"},
         "The DMAC refused a parameter (#ERROR bit 7 limit, bit 8 computation); .error holds #ERROR."},
    });
    py_errors::translate<UnknownCommand>(py_errors::error_class("DmacUnknownCommand"));
    py_errors::translate<CommandRejected, fill_rejected>(py_errors::error_class("DmacCommandRejected"));

    // ---- codec helpers ---------------------------------------------------------------
    // The enums the client and the simulator take; each also accepts its names
    // as strings, in any case (named_enum.hpp).
    named_enum<Radix>(m, "Radix", "How a DMAC value is written: +123, h0000007B or b00000000 ... 01111011.",
                      "radix", {{"DEC", Radix::Dec}, {"HEX", Radix::Hex}, {"BIN", Radix::Bin}},
                      {{"d", Radix::Dec}, {"", Radix::Dec}, {"h", Radix::Hex}, {"b", Radix::Bin}});
    named_enum<StopWhat>(m, "StopWhat", "What STOP / HALT stop: everything, the movement (MOUV) or the sequence (SEQ).",
                         "what", {{"ALL", StopWhat::All}, {"MOVEMENT", StopWhat::Movement}, {"SEQUENCE", StopWhat::Sequence}},
                         {{"MOUV", StopWhat::Movement}, {"SEQ", StopWhat::Sequence}});
    named_enum<PowerMode>(m, "PowerMode", "POWER ON, OFF (freewheel) or SC (short-circuited coils).", "POWER",
                          {{"ON", PowerMode::On}, {"OFF", PowerMode::Off}, {"SC", PowerMode::ShortCircuit}});
    named_enum<EndStops>(m, "EndStops", "HARD_ENDS: which hard end-stop inputs stop the motor.", "HARD_ENDS",
                         {{"OFF", EndStops::Off}, {"ALL", EndStops::All}, {"POS", EndStops::Positive},
                          {"NEG", EndStops::Negative}});
    named_enum<Polarity>(m, "Polarity", "INVERSE_POLARITY: which of the inputs and outputs are inverted.",
                         "INVERSE_POLARITY", {{"OFF", Polarity::Off}, {"ALL", Polarity::All}, {"IN", Polarity::Inputs},
                                              {"OUT", Polarity::Outputs}});
    // SYNCHRO's words (dmac_synchro refuses the other keywords).
    named_enum<Keyword>(m, "Keyword", "The keywords of the DMAC command language.", "SYNCHRO",
                        {{"ON", Keyword::On}, {"OFF", Keyword::Off}, {"SC", Keyword::Sc}, {"ALL", Keyword::All},
                         {"POS", Keyword::Pos}, {"NEG", Keyword::Neg}, {"IN", Keyword::In}, {"OUT", Keyword::Out},
                         {"MOUV", Keyword::Mouv}, {"SEQ", Keyword::Seq}, {"TOP", Keyword::Top},
                         {"INTERPOL", Keyword::Interpol}});
    Record<ReadReply>(m, "ReadReply", "One parsed 'aa#MNE[.bit]=value' reply (parse_read_reply), read-only.")
        .field("address", &ReadReply::address)
        .field("mnemonic", &ReadReply::mnemonic, "'#ATI'")
        .field("bit", &ReadReply::bit, "0 for a whole-variable read")
        .field("value", &ReadReply::value)
        .field("radix", &ReadReply::radix);
    Record<VarInfo>(m, "VariableInfo", "One DMAC variable (variable()), read-only.")
        .field("name", &VarInfo::name, "'#ACCEL_TIME'")
        .field("mnemonic", &VarInfo::mnemonic, "'#ATI'")
        .field("stored", &VarInfo::stored, "survives power cycle / MODULE_RESET")
        .field("read_only", &VarInfo::read_only)
        .field("factory", &VarInfo::factory, "value after MODULE_RESET ALL (stored) or reset (volatile)")
        .field("min", &VarInfo::min, "lowest value a write accepts")
        .field("max", &VarInfo::max, "highest value a write accepts")
        .field("dmac34_only", &VarInfo::dmac34_only, "exists on the DMAC34 only");
    Record<VersionInfo>(m, "VersionInfo", "A parsed REQUEST_VERSION banner (Client.request_version()), read-only.")
        .field("address", &VersionInfo::address)
        .field("version", &VersionInfo::version, "1 in v1.7")
        .field("release", &VersionInfo::release, "7 in v1.7")
        .field("code", &VersionInfo::code, "'H142'")
        .field("model", &VersionInfo::model, "from the code table, e.g. 'DMAC34 standard'")
        .field("ident", &VersionInfo::ident, "the text between the quotes")
        .field("manufacturer", &VersionInfo::manufacturer)
        .field("product", &VersionInfo::product)
        .field("serial", &VersionInfo::serial)
        .field("manufacturing_date", &VersionInfo::manufacturing_date)
        .field("revision_date", &VersionInfo::revision_date)
        .field("phase", &VersionInfo::phase, "'6A'")
        .field("boot", &VersionInfo::boot, "'v1.1'");
    m.def("format_value", [](std::int32_t v, const EnumOrName<Radix>& r) { return format_value(v, enum_arg<Radix>(r)); },
          py::arg("value"), py::arg("radix") = Radix::Dec,
          "'+123', 'h0000007B' or 'b00000000 ... 01111011'; radix is a Radix or 'dec'/'hex'/'bin'.");
    m.def(
        "parse_read_reply", [](const py::bytes& b) { return parse_read_reply(std::string(b)); },
        py::arg("reply"), "Parses 'aa#MNE[.bit]=value' strictly into a ReadReply; None when it breaks the grammar.");
    m.def("status_names", [](std::uint32_t s) { return status_names(s); }, py::arg("status"));
    m.def("error_names", [](std::uint32_t e) { return error_names(e); }, py::arg("error"));
    m.def("variable", [](const std::string& name) { return var_info(var_arg(name)); }, py::arg("name"),
          "The VariableInfo of a variable, by full name or mnemonic ('#ACCEL_TIME', 'ATI').");
}

static void bind_dmac_sim(py::module_& m) {
    // ---- simulator -----------------------------------------------------------------
    named_enum<Sim::Sensor>(m, "Sensor", "The temperature sensors of a module (Sim.set_temperature).",
                            "sensor", {{"CPU", Sim::Sensor::Cpu}, {"DRIVER", Sim::Sensor::Driver},
                                       {"MOTOR", Sim::Sensor::Motor}});
    Record<SimState>(m, "SimState", "A snapshot of a Sim (Sim.state()), read-only.")
        .field("now_ms", &SimState::now_ms, "device time (ms)")
        .field("position", &SimState::position, "#POSITION (1/10000 rev)")
        .field("speed", &SimState::speed, "#SPEED (0.01 rpm, signed)")
        .field("status", &SimState::status, "#STATUS bits")
        .field("error", &SimState::error, "#ERROR bits")
        .field("line", &SimState::line, "sequencer line running (0 = stopped)")
        .field("sequencer_running", &SimState::sequencer_running)
        .field("fifo_count", &SimState::fifo_count, "interpolation segments queued")
        .field("interpolating", &SimState::interpolating)
        .field("power", &SimState::power, "the motor is powered");
    py::class_<Sim, serial::LineDevice, std::shared_ptr<Sim>>(
        m, "Sim",
        "A simulated DMAC module (a LineDevice: serve it with PtyLineServer). Device time runs on `clock` "
        "(a SimClock in tests); nothing runs in the background.")
        .def(py::init([](std::shared_ptr<Clock> clock, int address, const std::string& model,
                         const py::bytes& request_terminator, const py::bytes& reply_terminator,
                         std::int32_t supply_voltage, std::int32_t baudrate, std::optional<double> positive_end_switch,
                         std::optional<double> negative_end_switch, bool end_switch_active_low,
                         std::optional<double> reference_switch) {
                 SimOptions o;
                 o.address = address;
                 auto mdl = parse_model(model);
                 if (!mdl) throw InvalidArgument("model: '" + model + "' is not DMAC17, DMAC23-1/2 or DMAC34-1/2");
                 o.model = *mdl;
                 o.request_terminator = request_terminator;
                 o.reply_terminator = reply_terminator;
                 if (o.request_terminator.empty() || o.reply_terminator.empty())
                     throw InvalidArgument("terminators: must not be empty");
                 o.supply_voltage_mv = supply_voltage;
                 o.baudrate = baudrate;
                 if (positive_end_switch)
                     o.positive_end_switch = motion::SwitchConfig{true, *positive_end_switch, 0, end_switch_active_low};
                 if (negative_end_switch)
                     o.negative_end_switch = motion::SwitchConfig{true, *negative_end_switch, 0, end_switch_active_low};
                 if (reference_switch)
                     o.reference_switch = motion::SwitchConfig{true, *reference_switch, 1e15, false};
                 return std::make_shared<Sim>(std::move(clock), o);
             }),
             py::arg("clock") = nullptr, py::arg("address") = 0, py::arg("model") = "DMAC34-1",
             py::arg("request_terminator") = py::bytes("\r"), py::arg("reply_terminator") = py::bytes("\r\n"),
             py::arg("supply_voltage") = 32000, py::arg("baudrate") = 38400,
             py::arg("positive_end_switch") = py::none(), py::arg("negative_end_switch") = py::none(),
             py::arg("end_switch_active_low") = false, py::arg("reference_switch") = py::none())
        .def("poll", &Sim::poll, py::call_guard<py::gil_scoped_release>(), "Catch up with the clock.")
        .def("state", &Sim::state, py::call_guard<py::gil_scoped_release>(), "A SimState snapshot.")
        .def("read", [](Sim& s, const std::string& var) { return s.read(var_arg(var)); }, py::arg("variable"),
             py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("address", &Sim::address)
        .def_property_readonly("baudrate", &Sim::baudrate)
        .def_property_readonly("reply_terminator", [](const Sim& s) { return py::bytes(s.options().reply_terminator); })
        .def("sequence_line", &Sim::sequence_line, py::arg("n"))
        .def("set_input", &Sim::set_input, py::arg("n"), py::arg("active"), py::call_guard<py::gil_scoped_release>())
        .def("set_analog", &Sim::set_analog, py::arg("channel"), py::arg("mv"))
        .def("set_supply_voltage", &Sim::set_supply_voltage, py::arg("mv"), py::call_guard<py::gil_scoped_release>(),
             "Supply voltage in mV; outside the model's range latches undervoltage/overvoltage and stops the motor.")
        .def("set_temperature", [](Sim& s, const EnumOrName<Sim::Sensor>& which, std::int32_t tenths) {
                 const Sim::Sensor w = enum_arg<Sim::Sensor>(which);
                 py::gil_scoped_release nogil;
                 s.set_temperature(w, tenths);
             }, py::arg("sensor"), py::arg("tenths_c"),
             "Temperature in 0.1 degC; CPU > 120 degC or driver/motor > 85 degC latches a thermal fault.")
        .def("inject_error", &Sim::inject_error, py::arg("bit"), py::call_guard<py::gil_scoped_release>(),
             "Sets an #ERROR bit; fault bits 2..5 also stop the motor as the real fault does.")
        .def("physical_outputs", &Sim::physical_outputs, py::call_guard<py::gil_scoped_release>())
        .def("power_cycle", &Sim::power_cycle, py::call_guard<py::gil_scoped_release>())
        .def_static("chain_ultrasync", &Sim::chain_ultrasync, py::arg("modules"),
                    "Wire IN6/OUT1 of these modules into one UltraSYNC chain (5.11), before serving them: "
                    "with #INTERPOL_MODE:=-1 a segment ends when it is finished on every chained module.")
        .def("set_speed_limit", &Sim::set_speed_limit, py::arg("inc_per_s"),
             py::call_guard<py::gil_scoped_release>(),
             "A mechanical limit (friction, a brake): an interpolation segment faster than this "
             "(increments/s) lasts |offset|/limit instead of #INTERPOL_TIME. 0 = none.")
        .def_property_readonly("lines_handled", &Sim::lines_handled)
        .def_property_readonly("lines_rejected", &Sim::lines_rejected);
}

static void bind_dmac_client(py::module_& m) {
    // ---- client --------------------------------------------------------------------
    Record<ClientCounters>(m, "ClientCounters", "Client counters (Client.counters), read-only.")
        .field("transactions", &ClientCounters::transactions)
        .field("stray_lines", &ClientCounters::stray_lines, "lines that were not the awaited reply (late, misrouted)")
        .field("xon_errors", &ClientCounters::xon_errors, "MOVE_INTERPOL refused: FIFO full")
        .field("device_resets", &ClientCounters::device_resets, "version banners seen unsolicited");
    using C = Client;
    auto rel = py::call_guard<py::gil_scoped_release>();
    // Readings and simple settings are properties (the native facade convention).
    auto ro = [](auto f) {
        return [f](C& c) {
            py::gil_scoped_release nogil;
            return (c.*f)();
        };
    };
    auto wo = [](auto f) { return dmac_setter(f); };
    py::class_<C, std::shared_ptr<C>> cls(m, "Client",
                                          "Typed DMAC commands over a LineLink (one client per module address).");
    cls.def(py::init([](std::shared_ptr<serial::LineLink> link, int address, int baud, bool verify,
                         const py::object& timeout, const py::object& sleep) {
                 ClientOptions o;
                 o.address = address;
                 o.baud = baud;
                 o.verify = verify;
                 if (!timeout.is_none()) o.timeout = motorbus::py_helpers::seconds_to_ns(timeout);
                 o.sleep = sleep_arg(sleep);
                 return std::make_shared<C>(std::move(link), o);
             }),
             py::arg("link"), py::arg("address") = 0, py::kw_only(), py::arg("baud") = 38400, py::arg("verify") = true,
             py::arg("timeout") = py::none(), py::arg("sleep") = py::none())
        .def_property_readonly("address", &C::address)
        .def_property_readonly("counters", &C::counters)
        .def("command", [](C& c, const std::string& cmd) { c.command(cmd); }, py::arg("command"), rel)
        .def("raw", [](C& c, const std::string& f, bool expect) {
            std::string r;
            {
                py::gil_scoped_release nogil;
                r = c.raw(f, expect);
            }
            return py::bytes(r);
        },
             py::arg("frame"), py::arg("expect_reply") = true)
        .def("read", [](C& c, const std::string& v, const EnumOrName<Radix>& r) {
                 Var var = var_arg(v);
                 Radix rx = enum_arg<Radix>(r);
                 py::gil_scoped_release nogil;
                 return c.read(var, rx);
             }, py::arg("variable"), py::arg("radix") = Radix::Dec,
             "READ a variable; radix is a Radix or 'dec'/'hex'/'bin' (default Radix.DEC).")
        .def("read_bit", [](C& c, const std::string& v, int bit) { return c.read_bit(var_arg(v), bit); },
             py::arg("variable"), py::arg("bit"), rel)
        .def("write", [](C& c, const std::string& v, std::int32_t x) { c.write(var_arg(v), x); }, py::arg("variable"),
             py::arg("value"), rel)
        .def("write_bit", [](C& c, const std::string& v, int bit, bool x) { c.write_bit(var_arg(v), bit, x); },
             py::arg("variable"), py::arg("bit"), py::arg("value"), rel)
        .def_property(
            "position",
            [](C& c) {
                py::gil_scoped_release nogil;
                return c.position();
            },
            [](C& c, std::int32_t p) {
                py::gil_scoped_release nogil;
                c.set_position(p);
            },
            "#POSITION (1/10000 rev); assigning re-homes the axis.")
        .def("set_position", &C::set_position, py::arg("position"), rel)
        .def_property_readonly("speed", ro(&C::speed), "#SPEED, measured (0.01 rpm, signed).")
        .def_property_readonly("profile_speed", ro(&C::profile_speed), "#PROFILE_SPEED, computed (0.01 rpm).")
        .def_property_readonly("status", [](C& c) {
            std::uint32_t raw;
            {
                py::gil_scoped_release nogil;
                raw = c.status().raw;
            }
            return py::module_::import("motorbus.drives.dmac").attr("DmacStatus")(raw);
        }, "#STATUS as a DmacStatus (enum.IntFlag).")
        .def_property_readonly("error", [](C& c) {
            std::uint32_t raw;
            {
                py::gil_scoped_release nogil;
                raw = c.error().raw;
            }
            return py::module_::import("motorbus.drives.dmac").attr("DmacErrorWord")(raw);
        }, "#ERROR as a DmacErrorWord (enum.IntFlag); clear_error() acknowledges it.")
        .def("clear_error", &C::clear_error, rel)
        .def_property_readonly("is_dmac34", ro(&C::is_dmac34), "The module is a DMAC34 (from REQUEST_VERSION, cached).")
        .def_property_readonly("inputs", ro(&C::inputs), "#INPUT (bit 0 = IN1).")
        .def_property("outputs", ro(&C::outputs), wo(&C::set_outputs), "#OUTPUT (bit 0 = OUT1).")
        .def("set_output", &C::set_output, py::arg("n"), py::arg("on"), rel)
        .def_property_readonly("supply_voltage", ro(&C::supply_voltage), "#SUPPLY_VOLTAGE (mV).")
        .def_property_readonly("cpu_temperature", ro(&C::cpu_temperature), "#CPU_TEMPERATURE (0.1 degC).")
        .def_property_readonly("capture", ro(&C::capture), "#CAPTURE: #POSITION at the last IN5 rising edge.")
        .def_property_readonly("interpol_count", ro(&C::interpol_count), "#INTERPOL_COUNT (segments queued).")
        .def_property_readonly("line", ro(&C::line), "#LINE: sequencer line running (0 = stopped).")
        .def("set_profile", &C::set_profile, py::arg("high_speed") = py::none(), py::arg("low_speed") = py::none(),
             py::arg("accel_ms") = py::none(), py::arg("decel_ms") = py::none(), rel,
             "#HIGH_SPEED / #LOW_SPEED (0.01 rpm), #ACCEL_TIME / #DECEL_TIME (ms) in one frame.")
        .def_property("high_speed", [](C& c) { py::gil_scoped_release g; return c.read(Var::HighSpeed); },
                      [](C& c, std::int32_t v) { py::gil_scoped_release g; c.write(Var::HighSpeed, v); },
                      "#HIGH_SPEED (0.01 rpm).")
        .def_property("low_speed", [](C& c) { py::gil_scoped_release g; return c.read(Var::LowSpeed); },
                      [](C& c, std::int32_t v) { py::gil_scoped_release g; c.write(Var::LowSpeed, v); },
                      "#LOW_SPEED (0.01 rpm).")
        .def_property("accel_time", [](C& c) { py::gil_scoped_release g; return c.read(Var::AccelTime); },
                      [](C& c, std::int32_t v) { py::gil_scoped_release g; c.write(Var::AccelTime, v); },
                      "#ACCEL_TIME (ms).")
        .def_property("decel_time", [](C& c) { py::gil_scoped_release g; return c.read(Var::DecelTime); },
                      [](C& c, std::int32_t v) { py::gil_scoped_release g; c.write(Var::DecelTime, v); },
                      "#DECEL_TIME (ms).")
        .def_property("torque_ratio", ro(&C::torque_ratio), wo(&C::set_torque_ratio), "#TORQUE_RATIO (%).")
        .def("soft_limits", &C::soft_limits, rel, "(#NEGATIVE_END, #POSITIVE_END)")
        .def("set_soft_limits", &C::set_soft_limits, py::arg("negative"), py::arg("positive"), rel)
        .def_property("output_config", ro(&C::output_config), wo(&C::set_output_config), "#OUTPUT_CONFIG.")
        .def_property("line_delay", ro(&C::line_delay), wo(&C::set_line_delay), "#LINE_DELAY (us).")
        .def_property("on_reset", ro(&C::on_reset), wo(&C::set_on_reset), "#ON_RESET (sequencer line, 0 = none).")
        .def("set_interpolation", &C::set_interpolation, py::arg("time_ms"), py::arg("fifo_size"),
             py::arg("mode") = 0, rel)
        .def("analog_input", &C::analog_input, py::arg("channel"), rel)
        .def("set_analog_output", &C::set_analog_output, py::arg("channel"), py::arg("mv"), rel)
        .def_property_readonly("driver_temperature", ro(&C::driver_temperature), "#DRIVER_TEMPERATURE (DMAC34, 0.1 degC).")
        .def_property_readonly("motor_temperature", ro(&C::motor_temperature), "#MOTOR_TEMPERATURE (DMAC34, 0.1 degC).")
        .def("user_var", &C::user_var, py::arg("n"), rel)
        .def("set_user_var", &C::set_user_var, py::arg("n"), py::arg("value"), rel)
        .def("memorized_var", &C::memorized_var, py::arg("n"), rel)
        .def("set_memorized_var", &C::set_memorized_var, py::arg("n"), py::arg("value"), rel)
        .def("timer", &C::timer, py::arg("n"), rel)
        .def("set_timer", &C::set_timer, py::arg("n"), py::arg("ms"), rel);
    bind_dmac_client_commands(cls);
}

void bind_dmac(py::module_& m) {
    bind_dmac_codec(m);
    bind_dmac_sim(m);
    bind_dmac_client(m);
    bind_dmac_streaming(m);
}

// Motion, settings in keywords, sequences and interpolation.
static void bind_dmac_client_commands(py::class_<Client, std::shared_ptr<Client>>& cls) {
    using C = Client;
    auto rel = py::call_guard<py::gil_scoped_release>();
    cls.def("move_to", &C::move_to, py::arg("position"), rel)
        .def("move_on", &C::move_on, py::arg("offset"), rel)
        .def("move_speed", &C::move_speed, py::arg("speed"), rel)
        .def("stop", enum_method(&C::stop), py::arg("what") = StopWhat::All)
        .def("halt", enum_method(&C::halt), py::arg("what") = StopWhat::All)
        .def("power", enum_method(&C::power), py::arg("mode"))
        .def("brake", &C::brake, py::arg("on"), rel)
        .def("hard_ends", enum_method(&C::hard_ends), py::arg("which"))
        .def("soft_ends", &C::soft_ends, py::arg("on"), rel)
        .def("s_curve", &C::s_curve, py::arg("on"), rel)
        .def("optimized_current", &C::optimized_current, py::arg("on"), rel)
        .def("inverse_polarity", enum_method(&C::inverse_polarity), py::arg("which"))
        .def("reference", &C::reference, py::arg("on"), rel)
        .def("module_reset", &C::module_reset, py::arg("factory") = false, rel)
        .def("set_address", &C::set_address, py::arg("address"), rel)
        .def("set_baudrate", &C::set_baudrate, py::arg("baud"), rel)
        .def("request_version", &C::request_version, rel, "REQUEST_VERSION, parsed into a VersionInfo.")
        .def("wait_idle", [](C& c, const py::object& timeout, const py::object& poll) {
            using namespace motorbus::py_helpers;
            auto t = duration_arg(timeout, "timeout", Forever::Allowed);
            auto p = duration_arg(poll, "poll");
            return blocking_call([&] { return c.wait_idle(t, p); });
        }, py::arg("timeout"), py::arg("poll") = 0.01,
             "Polls #STATUS until not busy; returns the position. TimeoutError after `timeout` s "
             "(None = wait forever; Ctrl-C interrupts).")
        .def("upload_sequence", &C::upload_sequence, py::arg("lines"), py::arg("first") = 1,
             py::arg("verify_readback") = true, rel)
        .def("read_sequence_line", &C::read_sequence_line, py::arg("n"), rel)
        .def("read_sequence", &C::read_sequence, py::arg("first"), py::arg("last"), rel)
        .def("start_sequence", &C::start_sequence, py::arg("line") = 1, rel)
        .def("stop_sequence", &C::stop_sequence, rel)
        .def("step", &C::step, py::arg("line") = py::none(), rel)
        .def("move_interpol", &C::move_interpol, py::arg("offset"), rel,
             "Queues one segment; returns the FIFO level, or None when the FIFO was full (XON_ERROR).");
}

static void bind_dmac_streaming(py::module_& m) {
    using C = Client;
    m.def("synchro", [](std::shared_ptr<serial::LineLink> link, const EnumOrName<Keyword>& what) {
        Keyword k = enum_arg<Keyword>(what);
        py::gil_scoped_release nogil;
        synchro(*link, k);
    }, py::arg("link"), py::arg("what"), "Global SYNCHRO ON|OFF|TOP|INTERPOL (no reply).");

    Record<StreamStats>(m, "StreamStats", "What stream_interpolation did, read-only.")
        .field("segments", &StreamStats::segments, "segments queued per axis")
        .field("frames", &StreamStats::frames, "MOVE_INTERPOL frames sent (all axes, retries included)")
        .field("xon_errors", &StreamStats::xon_errors, "refusals on a full FIFO")
        .field("min_level_after_start", &StreamStats::min_level_after_start,
               "lowest FIFO level seen once moving (0 = underrun)")
        .field("underruns", &StreamStats::underruns, "times an axis reported an empty FIFO before the end");
    m.def("stream_interpolation",
          [](std::vector<std::shared_ptr<C>> axes, const std::vector<std::vector<long long>>& segments,
             int interpol_time_ms, int fifo_size, const py::object& sleep, const py::object& backoff) {
              std::vector<C*> raw;
              for (auto& a : axes) raw.push_back(a.get());
              StreamOptions o;
              o.interpol_time_ms = interpol_time_ms;
              o.fifo_size = fifo_size;
              o.sleep = sleep_arg(sleep);
              if (!backoff.is_none()) o.backoff = motorbus::py_helpers::seconds_to_ns(backoff);
              StreamStats s;
              {
                  py::gil_scoped_release nogil;
                  s = stream_interpolation(raw, segments, o);
              }
              return s;
          },
          py::arg("axes"), py::arg("segments"), py::arg("interpol_time_ms") = 100, py::arg("fifo_size") = 64,
          py::arg("sleep") = py::none(), py::arg("backoff") = py::none(),
          "Streams segments[k][axis] to every axis, starting them with SYNCHRO INTERPOL.");

    // A PollSource reading `names` (e.g. ["POSITION", "SPEED", "STATUS"]) each sample,
    // with a client of its own on the drive's LineLink (motorbus.Poller).
    m.def("poll_source",
          [](std::shared_ptr<serial::LineLink> link, int address, std::vector<std::string> names, int baud,
             const py::object& timeout) -> std::shared_ptr<poll::Source> {
              motorbus::py_helpers::not_none(link, "link");
              ClientOptions o;
              o.address = address;
              o.baud = baud;
              if (!timeout.is_none()) o.timeout = motorbus::py_helpers::seconds_to_ns(timeout);
              return std::make_shared<PollSource>(std::move(link), std::move(o), std::move(names));
          },
          py::arg("link"), py::arg("address"), py::arg("names"), py::arg("baud") = 38400,
          py::arg("timeout") = py::none());
}

// Bindings for cpp/motorbus/drives/arcus: codec helpers, the simulator (a
// LineDevice for PtyLineServer) and the client.  python/motorbus/drives/arcus.py
// adds the Pythonic layer (enums, context manager, make_sim).
#include <pybind11/eval.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "motorbus/drives/arcus/client.hpp"
#include "motorbus/drives/arcus/codec.hpp"
#include "motorbus/drives/arcus/sim.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::arcus;
using motorbus::py_helpers::seconds_to_ns;

namespace {

py::bytes to_py(const std::string& s) { return py::bytes(s.data(), s.size()); }

std::string bytes_or_str(const py::handle& h, const char* what) {
    if (py::isinstance<py::bytes>(h)) return h.cast<std::string>();
    if (py::isinstance<py::str>(h)) return h.cast<std::string>();
    throw InvalidArgument(std::string(what) + ": expected str or bytes");
}

// Python classes per Table 11.1 reply, all subclasses of ArcusError(DriveFault).
py::handle g_error_classes[9];
py::handle g_arcus_error;

constexpr ErrorCode kCodes[9] = {ErrorCode::UnknownCommand, ErrorCode::BadSspd,        ErrorCode::EnableRs485,
                                 ErrorCode::IndexOutOfRange, ErrorCode::MotorNotMoving, ErrorCode::Moving,
                                 ErrorCode::ScvOn,           ErrorCode::SpeedOutOfRange, ErrorCode::StateError};

void register_errors(py::module_& m) {
    py::dict ns;
    ns["DriveFault"] = m.attr("DriveFault");
    py::exec(R"PY(
class ArcusError(DriveFault):
    "An Arcus drive refused a command with a Table 11.1 reply. .code, .reply, .command."
    code = ""
    reply = ""
    command = ""
class ArcusUnknownCommand(ArcusError):
    "?<command>: the controller did not understand the command."
class ArcusBadSspd(ArcusError):
    "?Bad SSPD Command"
class ArcusEnableRs485(ArcusError):
    "?Enable RS-485 Mode"
class ArcusIndexOutOfRange(ArcusError):
    "?Index out of Range"
class ArcusMotorNotMoving(ArcusError):
    "?Motor is not moving (T without a target move)"
class ArcusMoving(ArcusError):
    "?Moving (a move or position change while outputting pulses)"
class ArcusScvOn(ArcusError):
    "?SCV ON (SSPD with S-curve enabled)"
class ArcusSpeedOutOfRange(ArcusError):
    "?Speed out of range (SSPD outside the SSPDM window)"
class ArcusStateError(ArcusError):
    "?State Error (a move while a limit or StepNLoop error is latched; CLR clears it)"
)PY",
             ns, ns);
    const char* names[9] = {"ArcusUnknownCommand", "ArcusBadSspd",        "ArcusEnableRs485",
                            "ArcusIndexOutOfRange", "ArcusMotorNotMoving", "ArcusMoving",
                            "ArcusScvOn",           "ArcusSpeedOutOfRange", "ArcusStateError"};
    py::object base = ns["ArcusError"];
    base.attr("__module__") = "motorbus";
    m.attr("ArcusError") = base;
    g_arcus_error = base.release();
    for (int i = 0; i < 9; ++i) {
        py::object cls = ns[names[i]];
        cls.attr("__module__") = "motorbus";
        m.attr(names[i]) = cls;
        g_error_classes[i] = cls.release();
    }
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const ArcusError& e) {
            py::handle cls = g_arcus_error;
            for (int i = 0; i < 9; ++i)
                if (kCodes[i] == e.code) cls = g_error_classes[i];
            py::object exc = py::reinterpret_borrow<py::object>(cls)(e.what());
            exc.attr("code") = std::string(error_name(e.code));
            exc.attr("reply") = e.reply;
            exc.attr("command") = e.command;
            PyErr_SetObject(cls.ptr(), exc.ptr());
        }
    });
}

SimOptions sim_options(int address, int response_type, const std::string& store_path, bool eo_boot, bool snl,
                       std::pair<double, double> home, std::optional<double> minus_limit,
                       std::optional<double> plus_limit, double z_position, double start_position, double tick) {
    SimOptions o;
    o.address = address;
    o.response_type = response_type;
    o.store_path = store_path;
    o.eo_boot = eo_boot;
    o.snl = snl;
    o.world.home_lo = home.first;
    o.world.home_hi = home.second;
    o.world.minus_limit = minus_limit;
    o.world.plus_limit = plus_limit;
    o.world.z_position = z_position;
    o.world.start_position = start_position;
    if (!(tick > 0) || tick > 1) throw InvalidArgument("tick: must be in (0, 1] seconds");
    o.tick_ns = static_cast<std::int64_t>(tick * 1e9);
    return o;
}

}  // namespace

void bind_arcus(py::module_& m) {
    register_errors(m);

    m.attr("ARCUS_MAX_REPLY") = kMaxReply;
    m.attr("ARCUS_MAX_REQUEST") = kMaxRequest;
    m.def("arcus_build_request", [](int address, const std::string& cmd) { return to_py(build_request(address, cmd)); },
          py::arg("address"), py::arg("command"), "b'@NN<command>\\r' (validated).");
    m.def(
        "arcus_parse_reply",
        [](const py::object& raw) {
            auto r = parse_reply(bytes_or_str(raw, "reply"));
            return py::make_tuple(r.address ? py::cast(*r.address) : py::none(), r.body);
        },
        py::arg("raw"), "(address or None, body) of one reply without its NUL; ProtocolError on bytes it never sends.");
    m.def(
        "arcus_commands",
        [] {
            py::list out;
            for (const auto& c : command_table()) {
                py::dict d;
                d["name"] = std::string(c.name);
                d["query"] = bool(c.forms & kQuery);
                d["set"] = bool(c.forms & kSet);
                d["action"] = bool(c.forms & kAction);
                d["argument"] = bool(c.forms & kArgument);
                d["indexed"] = c.index_max;
                d["motion"] = c.motion;
                d["stored"] = c.stored;
                d["description"] = std::string(c.description);
                out.append(d);
            }
            return out;
        },
        "The command table (Table 11.0 plus the commands the sections describe).");
    m.def(
        "arcus_acc_range", [](std::int64_t hspd, std::int64_t lspd) {
            return std::make_pair(min_acc_ms(hspd), max_acc_ms(hspd, lspd));
        },
        py::arg("hspd"), py::arg("lspd"),
        "(min, max) ACC in ms the drive accepts for HSPD/LSPD (Table A.0; max truncated to 10 ms like the "
        "manual's examples).");

    py::class_<Sim, serial::LineDevice, std::shared_ptr<Sim>>(
        m, "ArcusSim", "A simulated Arcus DMX-CAN answering ASCII lines (a LineDevice for PtyLineServer).")
        .def(py::init([](std::shared_ptr<Clock> clock, int address, int response_type, const std::string& store_path,
                         bool eo_boot, bool snl, std::pair<double, double> home, std::optional<double> minus_limit,
                         std::optional<double> plus_limit, double z_position, double start_position, double tick) {
                 if (!clock) clock = std::make_shared<RealClock>();
                 return std::make_shared<Sim>(clock, sim_options(address, response_type, store_path, eo_boot, snl,
                                                                  home, minus_limit, plus_limit, z_position,
                                                                  start_position, tick));
             }),
             py::arg("clock") = nullptr, py::arg("address") = 1, py::arg("response_type") = 0,
             py::arg("store_path") = "", py::arg("eo_boot") = false, py::arg("snl") = true,
             py::arg("home") = std::pair<double, double>{8000, 8400}, py::arg("minus_limit") = -400000.0,
             py::arg("plus_limit") = 400000.0, py::arg("z_position") = 1600.0, py::arg("start_position") = 0.0,
             py::arg("tick") = 1e-4)
        .def(
            "on_line", [](Sim& s, const py::object& line) {
                std::string l = bytes_or_str(line, "line");
                std::string r;
                {
                    py::gil_scoped_release nogil;
                    r = s.on_line(l);
                }
                return to_py(r);
            },
            py::arg("line"), "One request line without CR -> the reply bytes (NUL included; b'' = silent).")
        .def_property_readonly("address", &Sim::address)
        .def_property_readonly("store_path", &Sim::store_path)
        .def("power_cycle", &Sim::power_cycle, py::call_guard<py::gil_scoped_release>())
        .def("set_input", &Sim::set_input, py::arg("index"), py::arg("actuated"),
             py::call_guard<py::gil_scoped_release>(), "DI1..DI6 (DI2 is the latch input).")
        .def("force_home", &Sim::force_home, py::arg("actuated"), py::call_guard<py::gil_scoped_release>())
        .def("force_limit", &Sim::force_limit, py::arg("direction"), py::arg("actuated"),
             py::call_guard<py::gil_scoped_release>())
        .def("set_blocked", &Sim::set_blocked, py::arg("blocked"), py::call_guard<py::gil_scoped_release>())
        .def("disturb", &Sim::disturb, py::arg("steps"), py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("physical_position", &Sim::physical_position)
        .def_property_readonly("pulse_position", &Sim::pulse_position)
        .def_property_readonly("encoder_position", &Sim::encoder_position)
        .def_property_readonly("motor_status", &Sim::motor_status)
        .def_property_readonly("snl_status", &Sim::snl_status)
        .def_property_readonly("busy", &Sim::busy);

    using C = Client;
    auto rel = py::call_guard<py::gil_scoped_release>();
    py::class_<C, std::shared_ptr<C>> c(m, "ArcusClientBase",
                                        "Typed client for one DMX-CAN address on a LineLink (see ArcusClient).");
    c.def(py::init([](std::shared_ptr<serial::LineLink> link, int address, const py::object& timeout,
                      int query_retries) {
              ClientOptions o;
              o.address = address;
              if (!timeout.is_none()) o.timeout = seconds_to_ns(timeout);
              o.query_retries = query_retries;
              return std::make_shared<C>(std::move(link), o);
          }),
          py::arg("link"), py::arg("address") = 1, py::arg("timeout") = py::none(), py::arg("query_retries") = 1)
        .def_property_readonly("address", &C::address)
        .def_property_readonly("counters",
                               [](const C& cl) {
                                   auto k = cl.counters();
                                   py::dict d;
                                   d["requests"] = k.requests;
                                   d["timeouts"] = k.timeouts;
                                   d["retries"] = k.retries;
                                   d["protocol_errors"] = k.protocol_errors;
                                   d["device_errors"] = k.device_errors;
                                   d["noise_lines"] = k.noise_lines;
                                   return d;
                               })
        .def("command", &C::command, py::arg("command"), py::arg("idempotent") = false, rel)
        .def("query", &C::query, py::arg("name"), rel)
        .def("set", &C::set, py::arg("name"), py::arg("value"), rel)
        .def("action", &C::action, py::arg("name"), rel)
        .def_static(
            "broadcast", [](serial::LineLink& link, const std::string& cmd) { C::broadcast(link, cmd); },
            py::arg("link"), py::arg("command"), rel)
        .def("id", &C::id, rel)
        .def("version", &C::version, rel)
        .def("device_name", &C::device_name, rel)
        .def("set_device_name", &C::set_device_name, py::arg("address"), rel)
        .def("response_type", &C::response_type, rel)
        .def("set_response_type", &C::set_response_type, py::arg("rt"), rel)
        .def("store", &C::store, rel)
        .def("position", &C::position, rel)
        .def("set_position", &C::set_position, py::arg("position"), rel)
        .def("encoder", &C::encoder, rel)
        .def("set_encoder", &C::set_encoder, py::arg("counts"), rel)
        .def("delta", &C::delta, rel)
        .def("speed", &C::speed, rel)
        .def("status_raw", [](C& cl) { return cl.status().raw; }, rel)
        .def("snl_status_raw", [](C& cl) { return static_cast<int>(cl.snl_status()); }, rel)
        .def("moving", &C::moving, rel)
        .def("high_speed", &C::high_speed, rel)
        .def("set_high_speed", &C::set_high_speed, py::arg("pps"), rel)
        .def("low_speed", &C::low_speed, rel)
        .def("set_low_speed", &C::set_low_speed, py::arg("pps"), rel)
        .def("acceleration", &C::acceleration, rel)
        .def("set_acceleration", &C::set_acceleration, py::arg("ms"), rel)
        .def("deceleration", &C::deceleration, rel)
        .def("set_deceleration", &C::set_deceleration, py::arg("ms"), rel)
        .def("unique_deceleration", &C::unique_deceleration, rel)
        .def("set_unique_deceleration", &C::set_unique_deceleration, py::arg("on"), rel)
        .def("s_curve", &C::s_curve, rel)
        .def("set_s_curve", &C::set_s_curve, py::arg("on"), rel)
        .def("speed_window", &C::speed_window, rel)
        .def("set_speed_window", &C::set_speed_window, py::arg("sspdm"), rel)
        .def("absolute_mode", &C::absolute_mode, rel)
        .def("incremental_mode", &C::incremental_mode, rel)
        .def("incremental", &C::incremental, rel)
        .def("move", &C::move, py::arg("target"), rel)
        .def("change_target", &C::change_target, py::arg("target"), rel)
        .def("change_speed", &C::change_speed, py::arg("pps"), rel)
        .def("jog", &C::jog, py::arg("direction"), rel)
        .def("stop", &C::stop, rel)
        .def("abort", &C::abort, rel)
        .def("clear", &C::clear, rel)
        .def("clear_snl", &C::clear_snl, rel)
        .def(
            "home",
            [](C& cl, const std::string& method, int direction) {
                HomeMethod hm;
                if (method == "H") hm = HomeMethod::H;
                else if (method == "HL") hm = HomeMethod::HL;
                else if (method == "ZH") hm = HomeMethod::ZH;
                else if (method == "Z") hm = HomeMethod::Z;
                else if (method == "L") hm = HomeMethod::L;
                else throw InvalidArgument("home method: one of H, HL, ZH, Z, L");
                if (direction != 1 && direction != -1) throw InvalidArgument("home direction: +1 or -1");
                py::gil_scoped_release nogil;
                cl.home(hm, direction);
            },
            py::arg("method"), py::arg("direction"))
        .def("home_correction", &C::home_correction, rel)
        .def("set_home_correction", &C::set_home_correction, py::arg("steps"), rel)
        .def("return_to_zero", &C::return_to_zero, rel)
        .def("set_return_to_zero", &C::set_return_to_zero, py::arg("on"), rel)
        .def("limit_correction", &C::limit_correction, rel)
        .def("set_limit_correction", &C::set_limit_correction, py::arg("steps"), rel)
        .def(
            "wait_idle",
            [](C& cl, const py::object& timeout, double poll) {
                auto t = seconds_to_ns(timeout);
                py::gil_scoped_release nogil;
                cl.wait_idle(t, std::chrono::nanoseconds(static_cast<std::int64_t>(poll * 1e9)));
            },
            py::arg("timeout"), py::arg("poll") = 0.005)
        .def("enabled", &C::enabled, rel)
        .def("enable", &C::enable, py::arg("on") = true, rel)
        .def("enabled_at_boot", &C::enabled_at_boot, rel)
        .def("set_enabled_at_boot", &C::set_enabled_at_boot, py::arg("on"), rel)
        .def("current", &C::current, rel)
        .def("run_current", &C::run_current, rel)
        .def("set_run_current", &C::set_run_current, py::arg("ma"), rel)
        .def("idle_current", &C::idle_current, rel)
        .def("set_idle_current", &C::set_idle_current, py::arg("ma"), rel)
        .def("idle_time", &C::idle_time, rel)
        .def("set_idle_time", &C::set_idle_time, py::arg("ms"), rel)
        .def("digital_inputs", &C::digital_inputs, rel)
        .def("digital_input", &C::digital_input, py::arg("n"), rel)
        .def("digital_outputs", &C::digital_outputs, rel)
        .def("set_digital_outputs", &C::set_digital_outputs, py::arg("value"), rel)
        .def("digital_output", &C::digital_output, py::arg("n"), rel)
        .def("set_digital_output", &C::set_digital_output, py::arg("n"), py::arg("on"), rel)
        .def("outputs_at_boot", &C::outputs_at_boot, rel)
        .def("set_outputs_at_boot", &C::set_outputs_at_boot, py::arg("value"), rel)
        .def("alarm_outputs", &C::alarm_outputs, rel)
        .def("set_alarm_outputs", &C::set_alarm_outputs, py::arg("on"), rel)
        .def("polarity", &C::polarity, rel)
        .def("set_polarity", &C::set_polarity, py::arg("bits"), rel)
        .def("enable_latch", &C::enable_latch, py::arg("on") = true, rel)
        .def("latch_status_raw", [](C& cl) { return static_cast<int>(cl.latch_status()); }, rel)
        .def("latched_position", &C::latched_position, rel)
        .def("latched_encoder", &C::latched_encoder, rel)
        .def("sync_on", &C::sync_on, rel)
        .def("sync_off", &C::sync_off, rel)
        .def("sync_position", &C::sync_position, rel)
        .def("set_sync_position", &C::set_sync_position, py::arg("position"), rel)
        .def("sync_condition_raw", [](C& cl) { return static_cast<int>(cl.sync_condition()); }, rel)
        .def(
            "set_sync_condition_raw",
            [](C& cl, int v) {
                if (v < 1 || v > 3) throw InvalidArgument("SYNC: 1 (equal), 2 (less), 3 (greater)");
                py::gil_scoped_release nogil;
                cl.set_sync_condition(static_cast<SyncCondition>(v));
            },
            py::arg("condition"))
        .def("sync_status_raw", [](C& cl) { return static_cast<int>(cl.sync_status()); }, rel)
        .def("snl_enabled", &C::snl_enabled, rel)
        .def("set_snl_enabled", &C::set_snl_enabled, py::arg("on"), rel)
        .def("snl_tolerance", &C::snl_tolerance, rel)
        .def("set_snl_tolerance", &C::set_snl_tolerance, py::arg("counts"), rel)
        .def("snl_error_range", &C::snl_error_range, rel)
        .def("set_snl_error_range", &C::set_snl_error_range, py::arg("counts"), rel)
        .def("snl_max_attempts", &C::snl_max_attempts, rel)
        .def("set_snl_max_attempts", &C::set_snl_max_attempts, py::arg("n"), rel)
        .def("snl_idle_tolerance", &C::snl_idle_tolerance, rel)
        .def("set_snl_idle_tolerance", &C::set_snl_idle_tolerance, py::arg("counts"), rel)
        .def("comm_mode", &C::comm_mode, rel)
        .def("set_comm_mode", &C::set_comm_mode, py::arg("mode"), rel)
        .def("baud_code", &C::baud_code, rel)
        .def("set_baud_code", &C::set_baud_code, py::arg("code"), rel)
        .def("can_bit_rate_code", &C::can_bit_rate_code, rel)
        .def("set_can_bit_rate_code", &C::set_can_bit_rate_code, py::arg("code"), rel)
        .def("node_id", &C::node_id, rel)
        .def("set_node_id", &C::set_node_id, py::arg("node_id"), rel);
}

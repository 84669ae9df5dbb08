// Bindings for cpp/motorbus/drives/arcus: codec helpers, the simulator (a
// LineDevice for PtyLineServer) and the client.  python/motorbus/drives/arcus.py
// adds the Pythonic layer (enums, context manager, make_sim).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "sim_device.hpp"
#include "errors.hpp"
#include "named_enum.hpp"
#include "motorbus/drives/arcus/canopen_od.hpp"
#include "motorbus/drives/arcus/client.hpp"
#include "motorbus/drives/arcus/codec.hpp"
#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/drives/arcus/homing.hpp"
#include "motorbus/drives/arcus/poll_source.hpp"
#include "motorbus/drives/arcus/profile.hpp"
#include "motorbus/motion/motor_model.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::arcus;
using motorbus::py_helpers::Record;
using motorbus::py_helpers::enum_arg;
using motorbus::py_helpers::EnumOrName;
using motorbus::py_helpers::named_enum;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::Forever;
using motorbus::py_helpers::seconds_to_ns;

namespace {

py::bytes to_py(const std::string& s) { return py::bytes(s.data(), s.size()); }

std::string bytes_or_str(const py::handle& h, const char* what) {
    if (py::isinstance<py::bytes>(h)) return h.cast<std::string>();
    if (py::isinstance<py::str>(h)) return h.cast<std::string>();
    throw InvalidArgument(std::string(what) + ": expected str or bytes");
}

// One Python class per Table 11.1 reply, all subclasses of ReplyError(DriveFault).
struct ReplyClass {
    ErrorCode code;
    const char* name;
};
constexpr ReplyClass kReplyClasses[] = {
    {ErrorCode::UnknownCommand, "ArcusUnknownCommand"}, {ErrorCode::BadSspd, "ArcusBadSspd"},
    {ErrorCode::EnableRs485, "ArcusEnableRs485"},       {ErrorCode::IndexOutOfRange, "ArcusIndexOutOfRange"},
    {ErrorCode::MotorNotMoving, "ArcusMotorNotMoving"}, {ErrorCode::Moving, "ArcusMoving"},
    {ErrorCode::ScvOn, "ArcusScvOn"},                   {ErrorCode::SpeedOutOfRange, "ArcusSpeedOutOfRange"},
    {ErrorCode::StateError, "ArcusStateError"}};
py::handle g_reply_class[std::size(kReplyClasses)];
py::handle g_arcus_error;

void register_errors() {
    py_errors::add_error_classes({
        {"ArcusError", {"DriveFault"}, "An Arcus drive refused a command with a Table 11.1 reply. .code, .reply, .command."},
        {"ArcusUnknownCommand", {"ArcusError"}, "?<command>: the controller did not understand the command."},
        {"ArcusBadSspd", {"ArcusError"}, "?Bad SSPD Command"},
        {"ArcusEnableRs485", {"ArcusError"}, "?Enable RS-485 Mode"},
        {"ArcusIndexOutOfRange", {"ArcusError"}, "?Index out of Range"},
        {"ArcusMotorNotMoving", {"ArcusError"}, "?Motor is not moving (T without a target move)"},
        {"ArcusMoving", {"ArcusError"}, "?Moving (a move or position change while outputting pulses)"},
        {"ArcusScvOn", {"ArcusError"}, "?SCV ON (SSPD with S-curve enabled)"},
        {"ArcusSpeedOutOfRange", {"ArcusError"}, "?Speed out of range (SSPD outside the SSPDM window)"},
        {"ArcusStateError", {"ArcusError"},
         "?State Error (a move while a limit or StepNLoop error is latched; CLR clears it)"},
    });
    g_arcus_error = py::object(py_errors::error_class("ArcusError")).release();
    for (std::size_t i = 0; i < std::size(kReplyClasses); ++i)
        g_reply_class[i] = py::object(py_errors::error_class(kReplyClasses[i].name)).release();
    // The class depends on the reply code, so this translator picks it itself.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const ReplyError& e) {
            py::handle cls = g_arcus_error;
            for (std::size_t i = 0; i < std::size(kReplyClasses); ++i)
                if (kReplyClasses[i].code == e.code) cls = g_reply_class[i];
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
                       std::optional<double> plus_limit, double z_position, double start_position, double tick,
                       int comm_type = 0, int node_id = 1, double store_time = 0, double clear_time = 0,
                       int bit_rate = 5) {
    SimOptions o;
    o.comm_type = comm_type;
    o.node_id = node_id;
    o.bit_rate = bit_rate;
    if (!(store_time >= 0) || !(clear_time >= 0) || store_time > 60 || clear_time > 60)
        throw InvalidArgument("store_time/clear_time: must be in [0, 60] seconds");
    o.store_ns = static_cast<std::int64_t>(store_time * 1e9);
    o.clear_ns = static_cast<std::int64_t>(clear_time * 1e9);
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
    o.tick_ns = duration_arg(tick, "tick").count();
    return o;
}

}  // namespace

namespace {
// The vendor's profile model (and homing), bound with the vendor.
void bind_arcus_motion(py::module_& m) {
    using namespace motorbus::motion;
    // ---- Arcus -----------------------------------------------------------------
    py::class_<ArcusSpeedWindow>(m, "SpeedWindow")
        .def_readonly("number", &ArcusSpeedWindow::number)
        .def_readonly("sspdm_first", &ArcusSpeedWindow::sspdm_first)
        .def_readonly("sspdm_last", &ArcusSpeedWindow::sspdm_last)
        .def_readonly("hspd_low", &ArcusSpeedWindow::hspd_low)
        .def_readonly("hspd_high", &ArcusSpeedWindow::hspd_high)
        .def_readonly("min_lspd", &ArcusSpeedWindow::min_lspd)
        .def_readonly("min_acc_ms", &ArcusSpeedWindow::min_acc_ms)
        .def_readonly("delta", &ArcusSpeedWindow::delta);
    m.def("speed_windows", [] {
        const auto& w = arcus_speed_windows();
        return std::vector<ArcusSpeedWindow>(w.begin(), w.end());
    });
    m.def("window_for_hspd", &arcus_window_for_hspd, py::arg("hspd_pps"), py::return_value_policy::copy);
    m.def("window_for_sspdm", &arcus_window_for_sspdm, py::arg("sspdm"), py::return_value_policy::copy);
    m.def("max_acc_ms", &arcus_max_acc_ms, py::arg("hspd_pps"), py::arg("lspd_pps"));
    py::class_<ProfileParams>(m, "ProfileParams")
        .def(py::init([](double hspd, double lspd, double acc_ms, double dec_ms, bool edec, bool scv, double ratio) {
                 return ProfileParams{hspd, lspd, acc_ms, dec_ms, edec, scv, ratio};
             }),
             py::arg("hspd") = 1000.0, py::arg("lspd") = 100.0, py::arg("acc_ms") = 300.0, py::arg("dec_ms") = 300.0,
             py::arg("edec") = false, py::arg("scv") = false, py::arg("snl_ratio") = 1.0)
        .def_readwrite("hspd", &ProfileParams::hspd)
        .def_readwrite("lspd", &ProfileParams::lspd)
        .def_readwrite("acc_ms", &ProfileParams::acc_ms)
        .def_readwrite("dec_ms", &ProfileParams::dec_ms)
        .def_readwrite("edec", &ProfileParams::edec)
        .def_readwrite("scv", &ProfileParams::scv)
        .def_readwrite("snl_ratio", &ProfileParams::snl_ratio);
    m.def("effective", [](const ProfileParams& p) {
        auto e = arcus_effective(p);
        return py::make_tuple(e.params, e.window ? e.window->number : 0, e.adjustments);
    }, py::arg("params"), "(effective params, window number, [adjustments]) after Appendix A.");
    m.def("check_strict", &arcus_check_strict, py::arg("params"));
    m.attr("MAX_MOVE_DISTANCE") = kArcusMaxMoveDistance;
    py::enum_<Phase>(m, "Phase", "Where an Motion is in its move (MST bits 0..2).")
        .value("IDLE", Phase::Idle)
        .value("ACCEL", Phase::Accel)
        .value("CONST", Phase::Const, "at constant speed")
        .value("DECEL", Phase::Decel);
    py::class_<Motion>(m, "Motion")
        .def(py::init<ProfileParams, int>(), py::arg("params") = ProfileParams{}, py::arg("sspdm") = 0)
        .def("set_params", [](Motion& a, const ProfileParams& p) { return a.set_params(p).params; })
        .def("set_sspdm", &Motion::set_sspdm)
        .def_property_readonly("effective", [](const Motion& a) { return a.effective().params; })
        .def("move", [](Motion& a, double pos, double target) { return arcus_reply_text(a.move(pos, target)); },
             py::arg("position"), py::arg("target"), "X: returns '' or the drive's error reply.")
        .def("jog", [](Motion& a, double pos, int dir) { return arcus_reply_text(a.jog(pos, dir)); })
        .def("change_target",
             [](Motion& a, double t, double target) { return arcus_reply_text(a.change_target(t, target)); },
             py::arg("t"), py::arg("target"))
        .def("change_speed",
             [](Motion& a, double t, double v) { return arcus_reply_text(a.change_speed(t, v)); },
             py::arg("t"), py::arg("hspd"))
        .def("stop", &Motion::stop, py::arg("t"))
        .def("abort", &Motion::abort, py::arg("t"))
        .def_property_readonly("profile", &Motion::profile, py::return_value_policy::copy)
        .def("moving", &Motion::moving, py::arg("t"))
        .def("phase", &Motion::phase, py::arg("t"), "The Phase at time t (MST bits 0..2).");

    py::class_<HomingOptions>(m, "HomingOptions")
        .def(py::init([](double hca, double lca, bool rz) { return HomingOptions{hca, lca, rz}; }),
             py::arg("hca") = 0.0, py::arg("lca") = 1000.0, py::arg("rz") = false);
    named_enum<Homing::Method>(m, "HomingMethod", "The routines Homing runs on a MotorModel.",
                               "ArcusHoming.start method", {{"H", Homing::Method::H}, {"HL", Homing::Method::HL},
                                                            {"L", Homing::Method::L}, {"Z", Homing::Method::Z},
                                                            {"ZH", Homing::Method::ZH}});
    py::class_<Homing>(m, "Homing")
        .def(py::init<MotorModel&, ProfileParams, HomingOptions>(), py::arg("motor"), py::arg("params"),
             py::arg("options") = HomingOptions{}, py::keep_alive<1, 2>())
        .def("start", [](Homing& h, const EnumOrName<Homing::Method>& method, int dir) {
            h.start(enum_arg<Homing::Method>(method), dir);
        }, py::arg("method"), py::arg("direction"))
        .def("abort", &Homing::abort)
        .def_property_readonly("running", &Homing::running)
        .def_property_readonly("result", [](const Homing& h) { return static_cast<int>(h.result()); })
        .def_property_readonly("snl_status", &Homing::snl_status);
}
}  // namespace

static void bind_arcus_codec(py::module_& m) {
    bind_arcus_motion(m);
    register_errors();

    m.attr("MAX_REPLY") = kMaxReply;
    m.attr("MAX_REQUEST") = kMaxRequest;
    m.def("build_request", [](int address, const std::string& cmd) { return to_py(build_request(address, cmd)); },
          py::arg("address"), py::arg("command"), "b'@NN<command>\\r' (validated).");
    m.def(
        "parse_reply",
        [](const py::object& raw) {
            auto r = parse_reply(bytes_or_str(raw, "reply"));
            return py::make_tuple(r.address ? py::cast(*r.address) : py::none(), r.body);
        },
        py::arg("raw"), "(address or None, body) of one reply without its NUL; ProtocolError on bytes it never sends.");
    auto text = [](std::string_view CommandInfo::*f) {
        return [f](const CommandInfo& c) { return std::string(c.*f); };
    };
    auto form = [](unsigned bit) { return [bit](const CommandInfo& c) { return bool(c.forms & bit); }; };
    Record<CommandInfo>(m, "CommandInfo", "One row of the Arcus command table (commands()), read-only.")
        .prop("name", text(&CommandInfo::name))
        .prop("query", form(kQuery), "answers the bare name (\"HSPD\" -> value)")
        .prop("set", form(kSet), "takes NAME=value")
        .prop("action", form(kAction), "a bare command answering OK (\"J+\")")
        .prop("argument", form(kArgument), "takes a value glued to the name (\"X1000\")")
        .field("indexed", &CommandInfo::index_max, "highest 1-based index (DI6 -> 6), 0 when not indexed")
        .field("motion", &CommandInfo::motion, "refused with ?Moving / ?State Error when busy or in error")
        .field("stored", &CommandInfo::stored, "written to flash by STORE (Table 7.10)")
        .prop("description", text(&CommandInfo::description));
    m.def(
        "commands",
        [] {
            auto t = command_table();
            return std::vector<CommandInfo>(t.begin(), t.end());
        },
        "The command table (Table 11.0 plus the commands the sections describe).");
    m.def(
        "acc_range", [](std::int64_t hspd, std::int64_t lspd) {
            return std::make_pair(min_acc_ms(hspd), max_acc_ms(hspd, lspd));
        },
        py::arg("hspd"), py::arg("lspd"),
        "(min, max) ACC in ms the drive accepts for HSPD/LSPD (Table A.0; max truncated to 10 ms like the "
        "manual's examples).");
}

static void bind_arcus_sim(py::module_& m) {
    // One drive, two faces: a LineDevice for its serial line, a SimulatedDevice (attach / close /
    // attached / describe / power_cycle, the base's binding) for its CAN port.
    py::class_<Sim, serial::LineDevice, can::SimulatedDevice, std::shared_ptr<Sim>>(
        m, "Sim",
        "A simulated Arcus DMX-CAN: answers ASCII lines (a LineDevice for PtyLineServer) and, attached to a "
        "CAN bus, CANopen (a SimulatedDevice).")
        .def(py::init([](std::shared_ptr<Clock> clock, int address, int response_type, const std::string& store_path,
                         bool eo_boot, bool snl, std::pair<double, double> home, std::optional<double> minus_limit,
                         std::optional<double> plus_limit, double z_position, double start_position, double tick,
                         int comm_type, int node_id, double store_time, double clear_time, int bit_rate) {
                 if (!clock) clock = std::make_shared<RealClock>();
                 return py_helpers::make_sim<Sim>(clock, sim_options(address, response_type, store_path, eo_boot, snl,
                                                                  home, minus_limit, plus_limit, z_position,
                                                                  start_position, tick, comm_type, node_id,
                                                                  store_time, clear_time, bit_rate));
             }),
             py::arg("clock") = nullptr, py::arg("address") = 1, py::arg("response_type") = 0,
             py::arg("store_path") = "", py::arg("eo_boot") = false, py::arg("snl") = true,
             py::arg("home") = std::pair<double, double>{8000, 8400}, py::arg("minus_limit") = -400000.0,
             py::arg("plus_limit") = 400000.0, py::arg("z_position") = 1600.0, py::arg("start_position") = 0.0,
             py::arg("tick") = 1e-4, py::arg("comm_type") = 0, py::arg("node_id") = 1, py::arg("store_time") = 0.0,
             py::arg("clear_time") = 0.0, py::arg("bit_rate") = 5)
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
        .def_property_readonly("busy", &Sim::busy)
        // The CANopen front end (one drive, two front ends): attach / close are the SimulatedDevice's.
        .def("on_can_frame", &Sim::on_can_frame, py::arg("frame"), py::call_guard<py::gil_scoped_release>(),
             "One CAN frame in, the frames the drive answers out (what attach runs per frame).")
        .def_property_readonly("active_protocol", &Sim::active_protocol,
                               "Communication type in effect: 0 RS-232, 1 RS-485, 2 CAN (200Ah at the last boot).")
        .def_property_readonly("can_node_id", &Sim::can_node_id)
        .def_property_readonly("can_bit_rate", &Sim::can_bit_rate);

    m.def("canopen_object_dictionary", &canopen_object_dictionary,
          "Table 10.1 as a typed canopen.ObjectDictionary (types, access, limits, defaults, codecs): what the "
          "arcus-canopen client reads and writes by, and the source of the shipped EDS.");
    m.def("canopen_objects", [] {
        py::list out;
        for (const auto& o : canopen_objects())
            out.append(py::make_tuple(o.index, o.sub, o.name, o.type, o.access, o.default_value, o.low, o.high,
                                      o.unit, o.persists));
        return out;
    }, "The DMX-CAN object dictionary the simulator serves (Table 10.1): (index, sub, name, type, access, "
       "default, low, high, unit, persists) tuples.");
}

static void bind_arcus_client(py::module_& m) {
    // The home command's method; ArcusClientBase.home takes it or its name ("HL").
    named_enum<HomeMethod>(m, "HomeMethod", "The homing routines: H, HL, ZH, Z, L (Table 11.0; + or - is the direction).",
                           "home method", {{"H", HomeMethod::H}, {"HL", HomeMethod::HL}, {"ZH", HomeMethod::ZH},
                                           {"Z", HomeMethod::Z}, {"L", HomeMethod::L}});
    Record<ClientCounters>(m, "ClientCounters", "ArcusClient counters (ArcusClient.counters), read-only.")
        .field("requests", &ClientCounters::requests)
        .field("timeouts", &ClientCounters::timeouts)
        .field("retries", &ClientCounters::retries, "queries sent again after a timeout")
        .field("protocol_errors", &ClientCounters::protocol_errors)
        .field("device_errors", &ClientCounters::device_errors, "Table 11.1 error replies")
        .field("noise_lines", &ClientCounters::noise_lines, "lines of non-printable bytes skipped (A10)");

    using C = Client;
    auto rel = py::call_guard<py::gil_scoped_release>();
    // Property accessors release the GIL like the methods (each is a line transaction).
    auto get = [rel](auto f) { return py::cpp_function(f, rel); };
    auto put = [rel](auto f) { return py::cpp_function(f, py::is_setter(), rel); };
    py::class_<C, std::shared_ptr<C>> c(m, "ClientBase",
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
        .def_property_readonly("counters", &C::counters)
        .def("command", &C::command, py::arg("command"), py::arg("idempotent") = false, rel)
        .def("query", &C::query, py::arg("name"), rel)
        .def("set", &C::set, py::arg("name"), py::arg("value"), rel)
        .def("action", &C::action, py::arg("name"), rel)
        .def_static(
            "broadcast", [](serial::LineLink& link, const std::string& cmd) { C::broadcast(link, cmd); },
            py::arg("link"), py::arg("command"), rel)
        // Readings: read-only properties; simple settings: read/write
        // properties; commands and anything with arguments: methods.  The
        // enum-valued readings are bound as _*_raw and wrapped into Python
        // enums by motorbus.drives.arcus.ArcusClient.
        .def_property_readonly("id", get(&C::id))
        .def_property_readonly("version", get(&C::version))
        .def_property_readonly("device_name", get(&C::device_name))
        .def("set_device_name", &C::set_device_name, py::arg("address"), rel,
             "DN=DMCnn (takes effect after store() and a power cycle).")
        .def_property("response_type", get(&C::response_type), put(&C::set_response_type))
        .def("store", &C::store, rel)
        .def_property_readonly("position", get(&C::position))
        .def("set_position", &C::set_position, py::arg("position"), rel)
        .def_property_readonly("encoder", get(&C::encoder))
        .def("set_encoder", &C::set_encoder, py::arg("counts"), rel)
        .def_property_readonly("delta", get(&C::delta))
        .def_property_readonly("speed", get(&C::speed))
        .def_property_readonly("_status_raw", get([](C& cl) { return cl.status().raw; }))
        .def_property_readonly("_snl_status_raw", get([](C& cl) { return static_cast<int>(cl.snl_status()); }))
        .def_property_readonly("moving", get(&C::moving))
        .def_property("high_speed", get(&C::high_speed), put(&C::set_high_speed))
        .def_property("low_speed", get(&C::low_speed), put(&C::set_low_speed))
        .def_property("acceleration", get(&C::acceleration), put(&C::set_acceleration))
        .def_property("deceleration", get(&C::deceleration), put(&C::set_deceleration))
        .def_property("unique_deceleration", get(&C::unique_deceleration), put(&C::set_unique_deceleration))
        .def_property("s_curve", get(&C::s_curve), put(&C::set_s_curve))
        .def_property("speed_window", get(&C::speed_window), put(&C::set_speed_window))
        .def("absolute_mode", &C::absolute_mode, rel)
        .def("incremental_mode", &C::incremental_mode, rel)
        .def_property_readonly("incremental", get(&C::incremental))
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
            [](C& cl, const EnumOrName<HomeMethod>& method, int direction) {
                const HomeMethod hm = enum_arg<HomeMethod>(method);
                py::gil_scoped_release nogil;
                cl.home(hm, direction);
            },
            py::arg("method"), py::arg("direction"))
        .def_property("home_correction", get(&C::home_correction), put(&C::set_home_correction))
        .def_property("return_to_zero", get(&C::return_to_zero), put(&C::set_return_to_zero))
        .def_property("limit_correction", get(&C::limit_correction), put(&C::set_limit_correction))
        .def(
            "wait_idle",
            [](C& cl, const py::object& timeout, const py::object& poll) {
                auto t = duration_arg(timeout, "timeout", Forever::Allowed);  // None/inf = forever
                auto p = duration_arg(poll, "poll");
                blocking_call([&] { cl.wait_idle(t, p); });  // Ctrl-C interrupts the polling
            },
            py::arg("timeout"), py::arg("poll") = 0.005)
        .def_property("enabled", get(&C::enabled), put(&C::enable))
        .def("enable", &C::enable, py::arg("on") = true, rel)
        .def("disable", [](C& cl) { cl.enable(false); }, rel)
        .def_property("enabled_at_boot", get(&C::enabled_at_boot), put(&C::set_enabled_at_boot))
        .def_property_readonly("current", get(&C::current))
        .def_property("run_current", get(&C::run_current), put(&C::set_run_current))
        .def_property("idle_current", get(&C::idle_current), put(&C::set_idle_current))
        .def_property("idle_time", get(&C::idle_time), put(&C::set_idle_time))
        .def_property_readonly("digital_inputs", get(&C::digital_inputs))
        .def("digital_input", &C::digital_input, py::arg("n"), rel)
        .def_property("digital_outputs", get(&C::digital_outputs), put(&C::set_digital_outputs))
        .def("digital_output", &C::digital_output, py::arg("n"), rel)
        .def("set_digital_output", &C::set_digital_output, py::arg("n"), py::arg("on"), rel)
        .def_property("outputs_at_boot", get(&C::outputs_at_boot), put(&C::set_outputs_at_boot))
        .def_property("alarm_outputs", get(&C::alarm_outputs), put(&C::set_alarm_outputs))
        .def_property("polarity", get(&C::polarity), put(&C::set_polarity))
        .def("enable_latch", &C::enable_latch, py::arg("on") = true, rel)
        .def_property_readonly("_latch_status_raw", get([](C& cl) { return static_cast<int>(cl.latch_status()); }))
        .def_property_readonly("latched_position", get(&C::latched_position))
        .def_property_readonly("latched_encoder", get(&C::latched_encoder))
        .def("sync_on", &C::sync_on, rel)
        .def("sync_off", &C::sync_off, rel)
        .def_property("sync_position", get(&C::sync_position), put(&C::set_sync_position))
        .def_property(
            "_sync_condition_raw", get([](C& cl) { return static_cast<int>(cl.sync_condition()); }),
            py::cpp_function(
                [](C& cl, int v) {
                    if (v < 1 || v > 3)
                        throw InvalidArgument("SYNC: 1 (equal), 2 (less), 3 (greater), not " + std::to_string(v));
                    py::gil_scoped_release nogil;
                    cl.set_sync_condition(static_cast<SyncCondition>(v));
                },
                py::is_setter()))
        .def_property_readonly("_sync_status_raw", get([](C& cl) { return static_cast<int>(cl.sync_status()); }))
        .def_property("snl_enabled", get(&C::snl_enabled), put(&C::set_snl_enabled))
        .def_property("snl_tolerance", get(&C::snl_tolerance), put(&C::set_snl_tolerance))
        .def_property("snl_error_range", get(&C::snl_error_range), put(&C::set_snl_error_range))
        .def_property("snl_max_attempts", get(&C::snl_max_attempts), put(&C::set_snl_max_attempts))
        .def_property("snl_idle_tolerance", get(&C::snl_idle_tolerance), put(&C::set_snl_idle_tolerance))
        .def_property("snl_ratio", get(&C::snl_ratio), put(&C::set_snl_ratio))
        .def_property("comm_mode", get(&C::comm_mode), put(&C::set_comm_mode))
        .def_property("baud_code", get(&C::baud_code), put(&C::set_baud_code))
        .def_property("can_bit_rate_code", get(&C::can_bit_rate_code), put(&C::set_can_bit_rate_code))
        .def_property("node_id", get(&C::node_id), put(&C::set_node_id));
}

static void bind_arcus_poll(py::module_& m) {
    // A PollSource querying `names` (e.g. ["EX", "PS", "MST"]) each sample, with a
    // client of its own on the drive's LineLink (motorbus.Poller).
    m.def("poll_source",
          [](std::shared_ptr<serial::LineLink> link, int address, std::vector<std::string> names,
             const py::object& timeout, int query_retries) -> std::shared_ptr<poll::Source> {
              py_helpers::not_none(link, "link");
              ClientOptions o;
              if (!timeout.is_none()) o.timeout = seconds_to_ns(timeout);
              o.query_retries = query_retries;
              return std::make_shared<PollSource>(std::move(link), address, std::move(names), o);
          },
          py::arg("link"), py::arg("address"), py::arg("names"), py::arg("timeout") = py::none(),
          py::arg("query_retries") = 1);
}

void bind_arcus(py::module_& m) {
    bind_arcus_codec(m);
    bind_arcus_sim(m);
    bind_arcus_client(m);
    bind_arcus_poll(m);
}

// Bindings for cpp/motorbus/motion: planners, profiles, the CiA 402 profile,
// StepNLoop, the motor model and the homing engine (vendor profile models bind
// with their vendor).  Thin: conversions only; the Python
// conveniences live in python/motorbus/motion.py.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "errors.hpp"
#include "motorbus/motion/cia402_profile.hpp"
#include "motorbus/motion/homing.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/stepnloop.hpp"
#include "motorbus/motion/steps.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::motion;
using motorbus::py_helpers::Record;

namespace {
void fill_limit(py::object& exc, const LimitExceeded& e) {
    exc.attr("limit") = e.limit;
    exc.attr("requested") = e.requested;
    exc.attr("allowed") = e.allowed;
    exc.attr("excess") = e.excess();
}

py::tuple state_tuple(const State& s) { return py::make_tuple(s.p, s.v, s.a, s.j); }

py::array_t<double> vec_to_array(const std::vector<double>& v) {
    py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}
}  // namespace

static void bind_planners(py::module_& m) {
    // ---- errors ----------------------------------------------------------------
    py_errors::add_error_classes({{"LimitExceeded", {"InvalidArgument"},
        "A motion request beyond a limit: .limit names it, .requested/.allowed/.excess quantify it."}});
    py_errors::translate<LimitExceeded, fill_limit>(py_errors::error_class("LimitExceeded"));

    // ---- profiles and planners -------------------------------------------------
    py::class_<State>(m, "MotionState")
        .def(py::init([](double p, double v, double a, double j) { return State{p, v, a, j}; }), py::arg("p") = 0.0,
             py::arg("v") = 0.0, py::arg("a") = 0.0, py::arg("j") = 0.0)
        .def_readwrite("p", &State::p)
        .def_readwrite("v", &State::v)
        .def_readwrite("a", &State::a)
        .def_readwrite("j", &State::j)
        .def("__repr__", [](const State& s) {
            return "MotionState(p=" + std::to_string(s.p) + ", v=" + std::to_string(s.v) +
                   ", a=" + std::to_string(s.a) + ", j=" + std::to_string(s.j) + ")";
        });
    py::class_<Limits>(m, "Limits")
        .def(py::init([](double v, double a, double d, double j) { return Limits{v, a, d, j}; }),
             py::arg("max_velocity"), py::arg("max_acceleration"), py::arg("max_deceleration") = 0.0,
             py::arg("max_jerk") = 0.0)
        .def_readwrite("max_velocity", &Limits::max_velocity)
        .def_readwrite("max_acceleration", &Limits::max_acceleration)
        .def_readwrite("max_deceleration", &Limits::max_deceleration)
        .def_readwrite("max_jerk", &Limits::max_jerk);
    py::enum_<RampShape>(m, "RampShape")
        .value("TRAPEZOID", RampShape::Trapezoid)
        .value("SCURVE", RampShape::SCurve)
        .value("SIN2", RampShape::Sin2);

    py::class_<Profile>(m, "Profile", "A planned motion: position/velocity/acceleration/jerk at any time.")
        .def_property_readonly("duration", &Profile::duration)
        .def_property_readonly("start_position", &Profile::start_position)
        .def_property_readonly("end_position", &Profile::end_position)
        .def_property_readonly("final_velocity", [](const Profile& p) { return p.final_state().v; })
        .def_property_readonly("segment_count", [](const Profile& p) { return p.segments().size(); })
        .def("at", [](const Profile& p, double t) { return state_tuple(p.at(t)); }, py::arg("t"),
             "(p, v, a, j) at time t (s).")
        .def("position", &Profile::position, py::arg("t"))
        .def("velocity", &Profile::velocity, py::arg("t"))
        .def("acceleration", &Profile::acceleration, py::arg("t"))
        .def("jerk", &Profile::jerk, py::arg("t"))
        .def("sample", &Profile::sample, py::arg("n"), "n x 5 array: t, p, v, a, j over [0, duration].")
        .def("sample_at", &Profile::sample_at, py::arg("t"))
        .def("first_crossing", &Profile::first_crossing, py::arg("level"), py::arg("t_from") = 0.0)
        .def("max_abs_velocity", &Profile::max_abs_velocity)
        .def("max_abs_acceleration", &Profile::max_abs_acceleration)
        .def("max_abs_jerk", &Profile::max_abs_jerk)
        .def("segments",
             [](const Profile& p) {
                 py::list out;
                 for (const auto& s : p.segments())
                     out.append(py::make_tuple(s.t0, s.duration, state_tuple(s.start),
                                               s.kind == Segment::Kind::Cubic ? "cubic" : "exp"));
                 return out;
             })
        .def("step_times",
             [](const Profile& p, Nanos t0, std::size_t max_steps) {
                 StepTimes st;
                 {
                     py::gil_scoped_release rel;
                     st = step_times(p, t0, max_steps);
                 }
                 py::array_t<std::int64_t> t(static_cast<py::ssize_t>(st.size()));
                 py::array_t<std::int8_t> d(static_cast<py::ssize_t>(st.size()));
                 std::copy(st.t_ns.begin(), st.t_ns.end(), t.mutable_data());
                 std::copy(st.dir.begin(), st.dir.end(), d.mutable_data());
                 return py::make_tuple(t, d);
             },
             py::arg("t0_ns") = 0, py::arg("max_steps") = 100'000'000,
             "Integer step times (ns, int64) and directions (int8) for positions in steps.")
        .def("step_times_seconds",
             [](const Profile& p, std::size_t max_steps) { return vec_to_array(step_times_seconds(p, max_steps)); },
             py::arg("max_steps") = 100'000'000);

    // The 3-argument overload first: converting a defaulted enum argument costs
    // more than the plan itself.
    m.def("plan_trapezoid", [](const State& s, double t, const Limits& l) { return plan_trapezoid(s, t, l); },
          py::arg("start"), py::arg("target"), py::arg("limits"));
    m.def("plan_trapezoid", &plan_trapezoid, py::arg("start"), py::arg("target"), py::arg("limits"),
          py::arg("shape"));
    m.def("plan_velocity", &plan_velocity, py::arg("start"), py::arg("target_velocity"), py::arg("limits"),
          py::arg("hold") = 0.0, py::arg("shape") = RampShape::Trapezoid);
    m.def("plan_jerk_limited_velocity", &plan_jerk_limited_velocity, py::arg("start"), py::arg("target_velocity"),
          py::arg("limits"), py::arg("hold") = 0.0);
    m.def("plan_jerk_limited", &plan_jerk_limited, py::arg("start"), py::arg("target"), py::arg("limits"));
    m.def("plan_synchronized", &plan_synchronized, py::arg("start"), py::arg("target"), py::arg("limits"),
          py::arg("shape") = RampShape::Trapezoid);
    m.def("plan_synchronized_jerk_limited", &plan_synchronized_jerk_limited, py::arg("start"), py::arg("target"),
          py::arg("limits"));
    m.def("synchronized_jerk_limited_durations",
          [](py::array_t<double, py::array::c_style | py::array::forcecast> cases) {
              if (cases.ndim() != 2 || cases.shape(1) != 15) throw InvalidArgument("cases must be N x 15");
              return vec_to_array(synchronized_jerk_limited_durations(std::span(cases.data(), cases.size())));
          },
          py::arg("cases"), "Rows: 3 axes x (p0, target, vmax, amax, jmax); the common duration of each row.");
    m.def("plan_straight_line", &plan_straight_line, py::arg("start"), py::arg("target"), py::arg("limits"),
          py::arg("shape") = RampShape::Trapezoid);
    m.def("split_interpolation", &split_interpolation, py::arg("axes"), py::arg("period_ms"));
    m.def("jerk_limited_durations",
          [](py::array_t<double, py::array::c_style | py::array::forcecast> cases) {
              if (cases.ndim() != 2 || cases.shape(1) != 7) throw InvalidArgument("cases must be N x 7");
              return vec_to_array(jerk_limited_durations(std::span(cases.data(), cases.size())));
          },
          py::arg("cases"), "Rows: p0, v0, a0, target, vmax, amax, jmax; the duration of each row's plan.");
}

static void bind_stepnloop(py::module_& m) {
    // ---- StepNLoop -------------------------------------------------------------
    py::class_<SnlConfig>(m, "SnlConfig")
        .def(py::init<>())
        .def_readwrite("enabled", &SnlConfig::enabled)
        .def_readwrite("tolerance", &SnlConfig::tolerance)
        .def_readwrite("error_range", &SnlConfig::error_range)
        .def_readwrite("max_attempts", &SnlConfig::max_attempts)
        .def_readwrite("idle_tolerance", &SnlConfig::idle_tolerance)
        .def_readwrite("ratio", &SnlConfig::ratio);
    py::enum_<SnlActivity>(m, "SnlActivity", "What kind of motion StepNLoop.begin() starts.")
        .value("MOVE", SnlActivity::Move)
        .value("JOG", SnlActivity::Jog)
        .value("HOME", SnlActivity::Home)
        .value("ZHOME", SnlActivity::ZHome)
        .value("LIMIT_HOME", SnlActivity::LimitHome)
        .value("STOP", SnlActivity::Stop)
        .value("ABORT", SnlActivity::Abort);
    py::class_<StepNLoop>(m, "StepNLoop")
        .def(py::init<SnlConfig>(), py::arg("config") = SnlConfig{})
        .def("configure", &StepNLoop::configure)
        .def("begin", &StepNLoop::begin, py::arg("activity"))
        .def("begin", [](StepNLoop& s, const std::string& what) {
            auto a = snl_activity_from_name(what);
            if (!a) throw InvalidArgument("StepNLoop.begin: unknown activity '" + what + "'");
            return s.begin(*a);
        }, py::arg("activity"), "The activity by name: 'move', 'jog', 'home', 'zhome', 'limit_home', 'stop', 'abort'.")
        .def("monitor", [](StepNLoop& s, double d) { auto r = s.monitor(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("motion_done", [](StepNLoop& s, double d) { auto r = s.motion_done(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("idle_check", [](StepNLoop& s, double d) { auto r = s.idle_check(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("limit_hit", &StepNLoop::limit_hit)
        .def("clear", &StepNLoop::clear)
        .def_property_readonly("status", [](const StepNLoop& s) { return static_cast<int>(s.status()); })
        .def_property_readonly("status_name", [](const StepNLoop& s) { return snl_status_name(s.status()); })
        .def_property_readonly("attempts", &StepNLoop::attempts);
}

static void bind_cia402_profiles(py::module_& m) {
    // ---- CiA 402 ------------------------------------------------
    py::class_<Cia402ProfileParams>(m, "Cia402ProfileParams")
        .def(py::init([](double v, double a, double d, double qs, int type, double vmax) {
                 Cia402ProfileParams p;
                 p.profile_velocity = v;
                 p.profile_acceleration = a;
                 p.profile_deceleration = d;
                 p.quick_stop_deceleration = qs;
                 p.motion_profile_type = static_cast<std::int16_t>(type);
                 p.max_profile_velocity = vmax;
                 p.validate();
                 return p;
             }),
             py::arg("profile_velocity") = 1000.0, py::arg("profile_acceleration") = 10000.0,
             py::arg("profile_deceleration") = 10000.0, py::arg("quick_stop_deceleration") = 100000.0,
             py::arg("motion_profile_type") = 0, py::arg("max_profile_velocity") = 0.0)
        .def_readwrite("profile_velocity", &Cia402ProfileParams::profile_velocity)
        .def_readwrite("profile_acceleration", &Cia402ProfileParams::profile_acceleration)
        .def_readwrite("profile_deceleration", &Cia402ProfileParams::profile_deceleration)
        .def_readwrite("quick_stop_deceleration", &Cia402ProfileParams::quick_stop_deceleration)
        .def_readwrite("motion_profile_type", &Cia402ProfileParams::motion_profile_type)
        .def_readwrite("max_profile_velocity", &Cia402ProfileParams::max_profile_velocity);
    m.def("cia402_position_profile", &cia402_position_profile, py::arg("start"), py::arg("target"), py::arg("params"));
    m.def("cia402_velocity_profile", &cia402_velocity_profile, py::arg("start"), py::arg("target_velocity"),
          py::arg("params"), py::arg("hold") = 0.0);
    m.def("cia402_quick_stop_profile", &cia402_quick_stop_profile, py::arg("start"), py::arg("params"));
    py::class_<Cia402ProfilePosition>(m, "Cia402ProfilePosition")
        .def(py::init<Cia402ProfileParams, double>(), py::arg("params") = Cia402ProfileParams{}, py::arg("position") = 0.0)
        .def("new_setpoint", &Cia402ProfilePosition::new_setpoint, py::arg("t"), py::arg("target"),
             py::arg("relative") = false, py::arg("change_immediately") = false, py::arg("change_on_setpoint") = false)
        .def("halt", &Cia402ProfilePosition::halt, py::arg("t"))
        .def_property_readonly("profile", &Cia402ProfilePosition::profile, py::return_value_policy::copy)
        .def("target_reached", &Cia402ProfilePosition::target_reached, py::arg("t"))
        .def_property_readonly("setpoint_pending", &Cia402ProfilePosition::setpoint_pending);
}

static void bind_motor_model(py::module_& m) {
    // ---- motor model and homing -------------------------------------------------
    py::class_<SwitchConfig>(m, "SwitchConfig")
        .def(py::init([](bool present, double lo, double hi, bool active_low) { return SwitchConfig{present, lo, hi, active_low}; }),
             py::arg("present") = true, py::arg("lo") = 0.0, py::arg("hi") = 0.0, py::arg("active_low") = true)
        .def_readwrite("present", &SwitchConfig::present)
        .def_readwrite("lo", &SwitchConfig::lo)
        .def_readwrite("hi", &SwitchConfig::hi)
        .def_readwrite("active_low", &SwitchConfig::active_low);
    py::class_<MotorConfig>(m, "MotorConfig")
        .def(py::init<>())
        .def_readwrite("steps_per_rev", &MotorConfig::steps_per_rev)
        .def_readwrite("counts_per_rev", &MotorConfig::counts_per_rev)
        .def_readwrite("index_position", &MotorConfig::index_position)
        .def_readwrite("index_width_steps", &MotorConfig::index_width_steps)
        .def_readwrite("index_channel", &MotorConfig::index_channel)
        .def_readwrite("home", &MotorConfig::home)
        .def_readwrite("minus_limit", &MotorConfig::minus_limit)
        .def_readwrite("plus_limit", &MotorConfig::plus_limit)
        .def_readwrite("pull_out_speed", &MotorConfig::pull_out_speed)
        .def_readwrite("max_acceleration", &MotorConfig::max_acceleration)
        .def_readwrite("tick_ns", &MotorConfig::tick_ns);
    using Kind = MotorEvent::Kind;
    py::enum_<Kind>(m, "MotorEventKind", "What a MotorEvent reports.")
        .value("HOME_ON", Kind::HomeOn)
        .value("HOME_OFF", Kind::HomeOff)
        .value("MINUS_LIMIT_ON", Kind::MinusLimitOn)
        .value("MINUS_LIMIT_OFF", Kind::MinusLimitOff)
        .value("PLUS_LIMIT_ON", Kind::PlusLimitOn)
        .value("PLUS_LIMIT_OFF", Kind::PlusLimitOff)
        .value("INDEX", Kind::IndexPulse)
        .value("STALLED", Kind::Stalled)
        .value("RECOVERED", Kind::Recovered)
        .value("LATCHED", Kind::Latched)
        .value("PROFILE_DONE", Kind::ProfileDone);
    Record<MotorEvent>(m, "MotorEvent", "One MotorModel event (MotorModel.add_listener), read-only.")
        .field("kind", &MotorEvent::kind)
        .field("t_ns", &MotorEvent::t, "exact time of the event (ns)")
        .field("physical", &MotorEvent::physical, "rotor position at t (steps)")
        .field("pulse", &MotorEvent::pulse, "pulse position at t")
        .field("encoder", &MotorEvent::encoder)
        .field("direction", &MotorEvent::direction, "sign of the commanded velocity at t (0 at rest)")
        ;
    py::class_<MotorModel>(m, "MotorModel")
        .def(py::init([](std::shared_ptr<Clock> clock, MotorConfig cfg) {
                 if (!clock) throw InvalidArgument("MotorModel needs a clock");
                 return std::make_unique<MotorModel>(*clock, cfg);
             }),
             py::arg("clock"), py::arg("config") = MotorConfig{}, py::keep_alive<1, 2>())
        .def("command", [](MotorModel& mm, const Profile& p, std::optional<Nanos> start) { mm.command(p, start); },
             py::arg("profile"), py::arg("start_ns") = py::none())
        .def("halt", [](MotorModel& mm) { mm.halt(); })
        .def("update", &MotorModel::update)
        .def("advance_to", &MotorModel::advance_to, py::arg("t_ns"))
        .def("add_listener", [](MotorModel& mm, std::function<void(MotorEvent)> cb) {
            // By value: Python gets its own copy, which it may keep.
            return mm.add_listener([cb = std::move(cb)](const MotorEvent& e) { cb(e); });
        }, py::arg("callback"), "callback(MotorEvent) for every event, called from update().")
        .def("remove_listener", &MotorModel::remove_listener)
        .def_property_readonly("moving", &MotorModel::moving)
        .def_property_readonly("pulse_position", &MotorModel::pulse_position)
        .def_property_readonly("pulse_count", &MotorModel::pulse_count)
        .def_property_readonly("physical_position", &MotorModel::physical_position)
        .def_property_readonly("encoder", &MotorModel::encoder)
        .def_property_readonly("velocity", &MotorModel::velocity)
        .def_property_readonly("commanded_velocity", &MotorModel::commanded_velocity)
        .def_property_readonly("pulse_velocity", &MotorModel::pulse_velocity)
        .def_property_readonly("stalled", &MotorModel::stalled)
        .def_property_readonly("slip", &MotorModel::slip)
        .def("set_pulse_position", &MotorModel::set_pulse_position)
        .def("set_encoder", &MotorModel::set_encoder)
        .def_property_readonly("home_active", &MotorModel::home_active)
        .def_property_readonly("minus_limit_active", &MotorModel::minus_limit_active)
        .def_property_readonly("plus_limit_active", &MotorModel::plus_limit_active)
        .def_property_readonly("index_active", &MotorModel::index_active)
        .def("set_jammed", &MotorModel::set_jammed)
        .def("arm_latch", &MotorModel::arm_latch)
        .def("trigger_latch", &MotorModel::trigger_latch)
        .def_property_readonly("latch_state", [](const MotorModel& mm) { return static_cast<int>(mm.latch_state()); })
        .def_property_readonly("latched_pulse", &MotorModel::latched_pulse)
        .def_property_readonly("latched_encoder", &MotorModel::latched_encoder);
    py::class_<Cia402HomingParams>(m, "Cia402HomingParams")
        .def(py::init([](int method, double s1, double s2, double acc, double off) {
                 return Cia402HomingParams{method, s1, s2, acc, off};
             }),
             py::arg("method") = 17, py::arg("speed_switch") = 1000.0, py::arg("speed_zero") = 100.0,
             py::arg("acceleration") = 10000.0, py::arg("home_offset") = 0.0);
    py::class_<Cia402Homing>(m, "Cia402Homing")
        .def(py::init<MotorModel&, Cia402HomingParams>(), py::arg("motor"), py::arg("params"), py::keep_alive<1, 2>())
        .def("start", &Cia402Homing::start)
        .def("abort", &Cia402Homing::abort)
        .def_property_readonly("attained", &Cia402Homing::attained)
        .def_property_readonly("error", &Cia402Homing::error)
        .def_property_readonly("result", [](const Cia402Homing& h) { return static_cast<int>(h.result()); })
        .def_static("supported", &Cia402Homing::supported);
}

void bind_motion(py::module_& m) {
    bind_planners(m);
    bind_stepnloop(m);
    bind_cia402_profiles(m);
    bind_motor_model(m);
}

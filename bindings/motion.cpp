// Bindings for cpp/motorbus/motion: planners, profiles, drive profile models,
// StepNLoop, the motor model and homing.  Thin: conversions only; the Python
// conveniences live in python/motorbus/motion.py.
#include <pybind11/eigen.h>
#include <pybind11/eval.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "motorbus/motion/arcus_profile.hpp"
#include "motorbus/motion/cia402_profile.hpp"
#include "motorbus/motion/pmc007_profile.hpp"
#include "motorbus/motion/unitek_profile.hpp"
#include "motorbus/motion/dmac_profile.hpp"
#include "motorbus/motion/homing.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/stepnloop.hpp"
#include "motorbus/motion/steps.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::motion;

namespace {
py::handle g_limit_exceeded;

py::tuple state_tuple(const State& s) { return py::make_tuple(s.p, s.v, s.a, s.j); }

py::array_t<double> vec_to_array(const std::vector<double>& v) {
    py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}
}  // namespace

void bind_motion(py::module_& m) {
    // ---- errors ----------------------------------------------------------------
    py::dict ns;
    ns["InvalidArgument"] = m.attr("InvalidArgument");
    py::exec(R"(
class LimitExceeded(InvalidArgument):
    "A motion request beyond a limit: .limit names it, .requested/.allowed/.excess quantify it."
    limit = ""
    requested = 0.0
    allowed = 0.0
    excess = 0.0
)", ns, ns);
    py::object le = ns["LimitExceeded"];
    le.attr("__module__") = "motorbus";
    m.attr("LimitExceeded") = le;
    g_limit_exceeded = le.release();
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const LimitExceeded& e) {
            py::object exc = py::reinterpret_borrow<py::object>(g_limit_exceeded)(e.what());
            exc.attr("limit") = e.limit;
            exc.attr("requested") = e.requested;
            exc.attr("allowed") = e.allowed;
            exc.attr("excess") = e.excess();
            PyErr_SetObject(g_limit_exceeded.ptr(), exc.ptr());
        }
    });

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
    m.def(
        "synchronized_jerk_limited_durations",
        [](py::array_t<double, py::array::c_style | py::array::forcecast> cases) {
            // Rows: 3 axes x (p0, target, vmax, amax, jmax) = 15 columns; the common duration.
            if (cases.ndim() != 2 || cases.shape(1) != 15) throw InvalidArgument("cases must be N x 15");
            auto c = cases.unchecked<2>();
            py::array_t<double> out(cases.shape(0));
            double* o = out.mutable_data();
            for (py::ssize_t i = 0; i < cases.shape(0); ++i) {
                std::vector<double> s(3), t(3);
                std::vector<Limits> l(3);
                for (int k = 0; k < 3; ++k) {
                    s[k] = c(i, 5 * k);
                    t[k] = c(i, 5 * k + 1);
                    l[k] = Limits{c(i, 5 * k + 2), c(i, 5 * k + 3), 0, c(i, 5 * k + 4)};
                }
                o[i] = plan_synchronized_jerk_limited(s, t, l)[0].duration();
            }
            return out;
        },
        py::arg("cases"));
    m.def("plan_straight_line", &plan_straight_line, py::arg("start"), py::arg("target"), py::arg("limits"),
          py::arg("shape") = RampShape::Trapezoid);
    m.def("split_interpolation", &split_interpolation, py::arg("axes"), py::arg("period_ms"));
    m.def(
        "jerk_limited_durations",
        [](py::array_t<double, py::array::c_style | py::array::forcecast> cases) {
            // Batch duration query (rows: p0, v0, a0, target, vmax, amax, jmax) for
            // interop tests and benchmarks without per-call Python overhead.
            if (cases.ndim() != 2 || cases.shape(1) != 7) throw InvalidArgument("cases must be N x 7");
            const auto n = cases.shape(0);
            py::array_t<double> out(n);
            auto c = cases.unchecked<2>();
            double* o = out.mutable_data();
            for (py::ssize_t i = 0; i < n; ++i) {
                Limits lim{c(i, 4), c(i, 5), 0, c(i, 6)};
                o[i] = plan_jerk_limited(State{c(i, 0), c(i, 1), c(i, 2), 0}, c(i, 3), lim).duration();
            }
            return out;
        },
        py::arg("cases"));

    // ---- Arcus -----------------------------------------------------------------
    py::class_<ArcusSpeedWindow>(m, "ArcusSpeedWindow")
        .def_readonly("number", &ArcusSpeedWindow::number)
        .def_readonly("sspdm_first", &ArcusSpeedWindow::sspdm_first)
        .def_readonly("sspdm_last", &ArcusSpeedWindow::sspdm_last)
        .def_readonly("hspd_low", &ArcusSpeedWindow::hspd_low)
        .def_readonly("hspd_high", &ArcusSpeedWindow::hspd_high)
        .def_readonly("min_lspd", &ArcusSpeedWindow::min_lspd)
        .def_readonly("min_acc_ms", &ArcusSpeedWindow::min_acc_ms)
        .def_readonly("delta", &ArcusSpeedWindow::delta);
    m.def("arcus_speed_windows", [] {
        const auto& w = arcus_speed_windows();
        return std::vector<ArcusSpeedWindow>(w.begin(), w.end());
    });
    m.def("arcus_window_for_hspd", &arcus_window_for_hspd, py::arg("hspd_pps"), py::return_value_policy::copy);
    m.def("arcus_window_for_sspdm", &arcus_window_for_sspdm, py::arg("sspdm"), py::return_value_policy::copy);
    m.def("arcus_max_acc_ms", &arcus_max_acc_ms, py::arg("hspd_pps"), py::arg("lspd_pps"));
    py::class_<ArcusProfileParams>(m, "ArcusProfileParams")
        .def(py::init([](double hspd, double lspd, double acc_ms, double dec_ms, bool edec, bool scv, double ratio) {
                 return ArcusProfileParams{hspd, lspd, acc_ms, dec_ms, edec, scv, ratio};
             }),
             py::arg("hspd") = 1000.0, py::arg("lspd") = 100.0, py::arg("acc_ms") = 300.0, py::arg("dec_ms") = 300.0,
             py::arg("edec") = false, py::arg("scv") = false, py::arg("snl_ratio") = 1.0)
        .def_readwrite("hspd", &ArcusProfileParams::hspd)
        .def_readwrite("lspd", &ArcusProfileParams::lspd)
        .def_readwrite("acc_ms", &ArcusProfileParams::acc_ms)
        .def_readwrite("dec_ms", &ArcusProfileParams::dec_ms)
        .def_readwrite("edec", &ArcusProfileParams::edec)
        .def_readwrite("scv", &ArcusProfileParams::scv)
        .def_readwrite("snl_ratio", &ArcusProfileParams::snl_ratio);
    m.def("arcus_effective", [](const ArcusProfileParams& p) {
        auto e = arcus_effective(p);
        return py::make_tuple(e.params, e.window ? e.window->number : 0, e.adjustments);
    }, py::arg("params"), "(effective params, window number, [adjustments]) after Appendix A.");
    m.def("arcus_check_strict", &arcus_check_strict, py::arg("params"));
    m.attr("ARCUS_MAX_MOVE_DISTANCE") = kArcusMaxMoveDistance;
    py::class_<ArcusMotion>(m, "ArcusMotion")
        .def(py::init<ArcusProfileParams, int>(), py::arg("params") = ArcusProfileParams{}, py::arg("sspdm") = 0)
        .def("set_params", [](ArcusMotion& a, const ArcusProfileParams& p) { return a.set_params(p).params; })
        .def("set_sspdm", &ArcusMotion::set_sspdm)
        .def_property_readonly("effective", [](const ArcusMotion& a) { return a.effective().params; })
        .def("move", [](ArcusMotion& a, double pos, double target) { return arcus_reply_text(a.move(pos, target)); },
             py::arg("position"), py::arg("target"), "X: returns '' or the drive's error reply.")
        .def("jog", [](ArcusMotion& a, double pos, int dir) { return arcus_reply_text(a.jog(pos, dir)); })
        .def("change_target",
             [](ArcusMotion& a, double t, double target) { return arcus_reply_text(a.change_target(t, target)); },
             py::arg("t"), py::arg("target"))
        .def("change_speed",
             [](ArcusMotion& a, double t, double v) { return arcus_reply_text(a.change_speed(t, v)); },
             py::arg("t"), py::arg("hspd"))
        .def("stop", &ArcusMotion::stop, py::arg("t"))
        .def("abort", &ArcusMotion::abort, py::arg("t"))
        .def_property_readonly("profile", &ArcusMotion::profile, py::return_value_policy::copy)
        .def("moving", &ArcusMotion::moving, py::arg("t"))
        .def("phase", [](const ArcusMotion& a, double t) {
            switch (a.phase(t)) {
                case ArcusPhase::Accel: return "accel";
                case ArcusPhase::Const: return "const";
                case ArcusPhase::Decel: return "decel";
                default: return "idle";
            }
        }, py::arg("t"));

    // ---- DMAC ------------------------------------------------------------------
    py::class_<DmacProfileParams>(m, "DmacProfileParams")
        .def(py::init([](std::int32_t hs, std::int32_t ls, std::int32_t ati, std::int32_t dti, bool sc) {
                 DmacProfileParams p{hs, ls, ati, dti, sc};
                 p.validate();
                 return p;
             }),
             py::arg("high_speed") = 60000, py::arg("low_speed") = 6000, py::arg("accel_time_ms") = 1000,
             py::arg("decel_time_ms") = 1000, py::arg("s_curve") = false)
        .def_readwrite("high_speed", &DmacProfileParams::high_speed)
        .def_readwrite("low_speed", &DmacProfileParams::low_speed)
        .def_readwrite("accel_time_ms", &DmacProfileParams::accel_time_ms)
        .def_readwrite("decel_time_ms", &DmacProfileParams::decel_time_ms)
        .def_readwrite("s_curve", &DmacProfileParams::s_curve);
    m.def("dmac_ramp_time", &dmac_ramp_time, py::arg("params"), py::arg("v_from"), py::arg("v_to"));
    m.def("dmac_position_profile", &dmac_position_profile, py::arg("start"), py::arg("target"), py::arg("params"));
    m.def("dmac_speed_profile", &dmac_speed_profile, py::arg("start"), py::arg("speed"), py::arg("params"),
          py::arg("hold") = 0.0);
    py::class_<DmacMotion>(m, "DmacMotion")
        .def(py::init<DmacProfileParams, double>(), py::arg("params") = DmacProfileParams{}, py::arg("position") = 0.0)
        .def("set_params", &DmacMotion::set_params)
        .def("move_to", &DmacMotion::move_to, py::arg("t"), py::arg("target"))
        .def("move_on", &DmacMotion::move_on, py::arg("t"), py::arg("offset"))
        .def("move_speed", &DmacMotion::move_speed, py::arg("t"), py::arg("speed"))
        .def("stop", &DmacMotion::stop, py::arg("t"))
        .def_property_readonly("profile", &DmacMotion::profile, py::return_value_policy::copy)
        .def("moving", &DmacMotion::moving, py::arg("t"));

    // ---- StepNLoop -------------------------------------------------------------
    py::class_<SnlConfig>(m, "SnlConfig")
        .def(py::init<>())
        .def_readwrite("enabled", &SnlConfig::enabled)
        .def_readwrite("tolerance", &SnlConfig::tolerance)
        .def_readwrite("error_range", &SnlConfig::error_range)
        .def_readwrite("max_attempts", &SnlConfig::max_attempts)
        .def_readwrite("idle_tolerance", &SnlConfig::idle_tolerance)
        .def_readwrite("ratio", &SnlConfig::ratio);
    py::class_<StepNLoop>(m, "StepNLoop")
        .def(py::init<SnlConfig>(), py::arg("config") = SnlConfig{})
        .def("configure", &StepNLoop::configure)
        .def("begin", [](StepNLoop& s, const std::string& what) {
            static const std::pair<const char*, SnlActivity> map[] = {
                {"move", SnlActivity::Move}, {"jog", SnlActivity::Jog}, {"home", SnlActivity::Home},
                {"zhome", SnlActivity::ZHome}, {"limit_home", SnlActivity::LimitHome},
                {"stop", SnlActivity::Stop}, {"abort", SnlActivity::Abort}};
            for (const auto& [n, a] : map)
                if (what == n) return s.begin(a);
            throw InvalidArgument("StepNLoop.begin: unknown activity '" + what + "'");
        }, py::arg("activity"))
        .def("monitor", [](StepNLoop& s, double d) { auto r = s.monitor(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("motion_done", [](StepNLoop& s, double d) { auto r = s.motion_done(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("idle_check", [](StepNLoop& s, double d) { auto r = s.idle_check(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("limit_hit", &StepNLoop::limit_hit)
        .def("clear", &StepNLoop::clear)
        .def_property_readonly("status", [](const StepNLoop& s) { return static_cast<int>(s.status()); })
        .def_property_readonly("status_name", [](const StepNLoop& s) { return snl_status_name(s.status()); })
        .def_property_readonly("attempts", &StepNLoop::attempts);

    // ---- PMC007, CiA 402, UNITEK ------------------------------------------------
    m.def("pmc007_gear_acceleration", &pmc007_gear_acceleration, py::arg("gear"));
    m.def("pmc007_microsteps", &pmc007_microsteps, py::arg("setting"));
    m.def("pmc007_convert_position", &pmc007_convert_position, py::arg("position"), py::arg("from_setting"),
          py::arg("to_setting"));
    py::class_<Pmc007ProfileParams>(m, "Pmc007ProfileParams")
        .def(py::init([](double speed, double start_speed, double stop_speed, int ag, int dg, int micro) {
                 Pmc007ProfileParams p{speed, start_speed, stop_speed, ag, dg, micro};
                 p.validate();
                 return p;
             }),
             py::arg("speed") = 1000.0, py::arg("start_speed") = 400.0, py::arg("stop_speed") = 0.0,
             py::arg("accel_gear") = 0, py::arg("decel_gear") = 0, py::arg("microstepping") = 0)
        .def_readwrite("speed", &Pmc007ProfileParams::speed)
        .def_readwrite("start_speed", &Pmc007ProfileParams::start_speed)
        .def_readwrite("stop_speed", &Pmc007ProfileParams::stop_speed)
        .def_readwrite("accel_gear", &Pmc007ProfileParams::accel_gear)
        .def_readwrite("decel_gear", &Pmc007ProfileParams::decel_gear)
        .def_readwrite("microstepping", &Pmc007ProfileParams::microstepping);
    m.def("pmc007_position_profile", &pmc007_position_profile, py::arg("start"), py::arg("target"), py::arg("params"));
    m.def("pmc007_speed_profile", &pmc007_speed_profile, py::arg("start"), py::arg("speed"), py::arg("params"),
          py::arg("hold") = 0.0);

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

    py::class_<UnitekRampParams>(m, "UnitekRampParams")
        .def(py::init([](double nmax, double acc, double dec) {
                 UnitekRampParams p{nmax, acc, dec};
                 p.validate();
                 return p;
             }),
             py::arg("n_max_rpm") = 3000.0, py::arg("acc_ramp_ms") = 1000.0, py::arg("dec_ramp_ms") = 1000.0)
        .def_readwrite("n_max_rpm", &UnitekRampParams::n_max_rpm)
        .def_readwrite("acc_ramp_ms", &UnitekRampParams::acc_ramp_ms)
        .def_readwrite("dec_ramp_ms", &UnitekRampParams::dec_ramp_ms);
    m.def("unitek_speed_profile", &unitek_speed_profile, py::arg("start"), py::arg("speed_num"), py::arg("params"),
          py::arg("hold") = 0.0);

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
        .def_readwrite("home", &MotorConfig::home)
        .def_readwrite("minus_limit", &MotorConfig::minus_limit)
        .def_readwrite("plus_limit", &MotorConfig::plus_limit)
        .def_readwrite("pull_out_speed", &MotorConfig::pull_out_speed)
        .def_readwrite("max_acceleration", &MotorConfig::max_acceleration)
        .def_readwrite("tick_ns", &MotorConfig::tick_ns);
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
        .def("add_listener", [](MotorModel& mm, std::function<void(py::dict)> cb) {
            return mm.add_listener([cb](const MotorEvent& e) {
                static const char* names[] = {"home_on", "home_off", "minus_limit_on", "minus_limit_off",
                                              "plus_limit_on", "plus_limit_off", "index", "stalled",
                                              "recovered", "latched", "profile_done"};
                py::dict d;
                d["kind"] = names[static_cast<int>(e.kind)];
                d["t_ns"] = e.t;
                d["physical"] = e.physical;
                d["pulse"] = e.pulse;
                d["encoder"] = e.encoder;
                d["direction"] = e.direction;
                cb(d);
            });
        }, py::arg("callback"), "callback(dict) for every event, called from update().")
        .def("remove_listener", &MotorModel::remove_listener)
        .def_property_readonly("moving", &MotorModel::moving)
        .def_property_readonly("pulse_position", &MotorModel::pulse_position)
        .def_property_readonly("pulse_count", &MotorModel::pulse_count)
        .def_property_readonly("physical_position", &MotorModel::physical_position)
        .def_property_readonly("encoder", &MotorModel::encoder)
        .def_property_readonly("velocity", &MotorModel::velocity)
        .def_property_readonly("commanded_velocity", &MotorModel::commanded_velocity)
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
    py::class_<ArcusHomingOptions>(m, "ArcusHomingOptions")
        .def(py::init([](double hca, double lca, bool rz) { return ArcusHomingOptions{hca, lca, rz}; }),
             py::arg("hca") = 0.0, py::arg("lca") = 1000.0, py::arg("rz") = false);
    py::class_<ArcusHoming>(m, "ArcusHoming")
        .def(py::init<MotorModel&, ArcusProfileParams, ArcusHomingOptions>(), py::arg("motor"), py::arg("params"),
             py::arg("options") = ArcusHomingOptions{}, py::keep_alive<1, 2>())
        .def("start", [](ArcusHoming& h, const std::string& method, int dir) {
            static const std::pair<const char*, ArcusHoming::Method> map[] = {
                {"H", ArcusHoming::Method::H}, {"HL", ArcusHoming::Method::HL}, {"L", ArcusHoming::Method::L},
                {"Z", ArcusHoming::Method::Z}, {"ZH", ArcusHoming::Method::ZH}};
            for (const auto& [n, mm] : map)
                if (method == n) return h.start(mm, dir);
            throw InvalidArgument("ArcusHoming.start: method is H, HL, L, Z or ZH, not '" + method + "'");
        }, py::arg("method"), py::arg("direction"))
        .def("abort", &ArcusHoming::abort)
        .def_property_readonly("running", &ArcusHoming::running)
        .def_property_readonly("result", [](const ArcusHoming& h) { return static_cast<int>(h.result()); })
        .def_property_readonly("snl_status", &ArcusHoming::snl_status);
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
